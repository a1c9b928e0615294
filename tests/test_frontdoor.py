"""What a newcomer meets first (issue #30): set-up that waits for apt's lock, angles in
degrees, short reprs in a notebook, CSV on stdin with a column map, the messages a
first run prints, and the JSON Schemas editors and CI validate against."""

from __future__ import annotations

import json
import subprocess
from fractions import Fraction

from tests.conftest import ROBOTS, ROOT, TRAJECTORIES
from tests.test_cli import singcheck

ORTHO = str(ROBOTS / "orthoglide.yaml")


def test_make_setup_waits_for_another_apt_instead_of_failing():
    out = subprocess.run(["make", "-n", "cas", "browser"], capture_output=True, text=True,
                         cwd=ROOT, env={"PATH": "/usr/bin:/bin"}, check=True).stdout
    calls = [part for part in out.split("$SUDO ")[1:] if part.startswith("apt-get")]
    assert len(calls) == 4  # update and install, for the CAS and for Chromium
    assert all(c.startswith("apt-get -o DPkg::Lock::Timeout=600 ") for c in calls)


# --- degrees -------------------------------------------------------------------------

def test_degrees_are_exact_multiples_of_pi():
    from singcheck.spec.grammar import compile_constant, parse

    for text, pi in [("30 deg", Fraction(1, 6)), ("-90 deg", Fraction(-1, 2)),
                     ("135 deg", Fraction(3, 4)), ("0.5 deg", Fraction(1, 360)),
                     ("1/2*180 deg", Fraction(1, 2))]:
        value = compile_constant(parse(text))
        assert value.rational == 0 and value.pi_coefficient == pi, text


def test_angle_joint_limits_in_degrees_equal_the_radians(tmp_path):
    from singcheck.spec.files import load_robot

    text = (ROBOTS / "five-bar.yaml").read_text()
    assert "joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}" in text
    degrees = tmp_path / "five-bar-deg.yaml"
    degrees.write_text(text.replace("joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}",
                                    "joint_limits: {th1: [60 deg, 180 deg], "
                                    "th2: [0 deg, 120 deg]}"))
    assert load_robot(degrees).joint_limits == load_robot(ROBOTS / "five-bar.yaml").joint_limits


def test_a_pose_angle_in_degrees_is_certified_like_radians(tmp_path):
    paths = tmp_path / "paths.yaml"
    paths.write_text("name: deg\nparameter: t\nrange: [0, 1]\n"
                     "pose: {x: 2 + t, y: 1, phi: 30 deg}\n---\n"
                     "name: rad\nparameter: t\nrange: [0, 1]\n"
                     "pose: {x: 2 + t, y: 1, phi: pi/6}\n")
    out = singcheck("run", str(ROBOTS / "3-rpr.yaml"), str(paths), "--format", "jsonl",
                    "--no-regions", "-q", "--backend", "flint")
    assert out.returncode == 0, out.stderr
    deg, rad = (json.loads(line) for line in out.stdout.splitlines())
    for key in ("verdict", "reason", "candidates", "working_modes"):
        assert deg[key] == rad[key]
    assert deg["verdict"] == "singularity-free"


def test_deg_after_a_name_is_still_an_error(tmp_path):
    robot = tmp_path / "r.yaml"
    robot.write_text((ROBOTS / "five-bar.yaml").read_text().replace(
        "th2: [0, 2*pi/3]", "th2: [0, e deg]"))
    out = singcheck("run", str(robot), str(TRAJECTORIES / "five-bar-free.yaml"))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1
    assert "r.yaml:" in out.stderr and "deg" in out.stderr


# --- short reprs -----------------------------------------------------------------------

def test_reprs_are_one_short_line():
    import singcheck

    robot = singcheck.load_robot(ORTHO, backend="flint", cache=False)
    path = singcheck.load_trajectory(str(TRAJECTORIES / "heart1.yaml"), robot)
    report = singcheck.check(robot, path, regions=False)
    assert repr(robot) == ("<Robot orthoglide: joints rho1, rho2, rho3; pose x, y, z; "
                           "ξ(X) of degree 16 (flint)>")
    assert repr(robot.model) == ("<RobotModel orthoglide: 3 legs, det A of degree 3, "
                                 "det B of degree 3>")
    assert repr(robot.spec) == "<RobotSpec orthoglide: joints rho1, rho2, rho3; pose x, y, z>"
    assert repr(path) == "<TrajectorySpec heart1: t in [-pi, pi]>"
    assert repr(report) == ("<Report heart1: singular: working mode +++ is singular at "
                            "t ≈ 0.977817>")
    assert repr(report.certificate) == "<TrajectoryReport heart1: singular, 4 candidate(s)>"
