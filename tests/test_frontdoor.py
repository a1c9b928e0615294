"""What a newcomer meets first (issue #30): set-up that waits for apt's lock, angles in
degrees, short reprs in a notebook, CSV on stdin with a column map, the messages a
first run prints, and the JSON Schemas editors and CI validate against."""

from __future__ import annotations

import json
import subprocess
from fractions import Fraction

import pytest

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


# --- CSV on stdin, column maps and units -----------------------------------------------

PLAIN = "t,x,y,z\n0,0.25,0.6,1\n1,0.9,1.1,1\n2,1.2,0.3,1\n"
MILLIMETRES = ("time,X_mm,Y_mm,Z_mm,speed\n0,250,600,1000,3\n1,900,1100,1000,4\n"
               "2,1200,300,1000,5\n")


def run_stdin(text: str, *args: str) -> subprocess.CompletedProcess:
    import os
    import sys

    return subprocess.run([sys.executable, "-m", "singcheck", "run", ORTHO, *args,
                           "--no-regions", "-q", "--backend", "flint"], input=text,
                          capture_output=True, text=True, cwd=ROOT, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})


def test_a_csv_on_stdin_without_csv_says_how_to_read_it():
    out = run_stdin(PLAIN, "-")
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.strip().splitlines() == [
        "singcheck: error: <stdin>:1: expected a mapping (key: value), got a single value "
        "(is it a CSV table of poses? name it *.csv or run with --csv)"]


def test_csv_on_stdin_gives_the_same_answer_as_the_file(tmp_path):
    path = tmp_path / "plain.csv"
    path.write_text(PLAIN)
    from_file = singcheck("run", ORTHO, str(path), "--format", "jsonl", "--no-regions", "-q",
                          "--backend", "flint")
    from_stdin = run_stdin(PLAIN, "-", "--csv", "--format", "jsonl")
    assert from_file.returncode == from_stdin.returncode == 1, from_stdin.stderr
    a, b = json.loads(from_file.stdout), json.loads(from_stdin.stdout)
    assert (a["name"], b["name"], b["path"]) == ("plain", "stdin", "<stdin>")
    assert a["verdict"] == b["verdict"] == "singular"
    assert a["candidates"] == b["candidates"] and a["working_modes"] == b["working_modes"]


def test_a_column_map_with_units_reads_a_foreign_table_exactly(tmp_path):
    from singcheck.spec.files import load_robot
    from singcheck.spec.paths import CsvFormat, parse_csv

    robot = load_robot(ORTHO)
    table = CsvFormat("linear", (("t", "time"), ("x", "X_mm"), ("y", "Y_mm"), ("z", "Z_mm")),
                      (("x", Fraction(1, 1000)), ("y", Fraction(1, 1000)),
                       ("z", Fraction(1, 1000))))
    mapped = parse_csv(MILLIMETRES, "mm.csv", robot, table)
    plain = parse_csv(PLAIN, "plain.csv", robot, "linear")
    assert [p.pose for p in mapped.pieces] == [p.pose for p in plain.pieces]
    assert mapped.parameter == "t" and mapped.global_range == plain.global_range
    # the same through the command line, stdin and a file alike
    out = run_stdin(MILLIMETRES, "-", "--csv", "--columns", "t=time,x=X_mm,y=Y_mm,z=Z_mm",
                    "--scale", "x=1/1000,y=0.001,z=1e-3", "--format", "jsonl")
    assert out.returncode == 1, out.stderr
    line = json.loads(out.stdout)
    assert line["verdict"] == "singular" and line["parameter"] == "t"


def test_without_a_map_a_foreign_table_is_refused_with_the_column():
    out = run_stdin(MILLIMETRES, "-", "--csv")
    assert out.returncode == 2
    assert out.stderr.strip() == (
        "singcheck: error: <stdin>:1: column 'X_mm' is not a pose variable of robot "
        "orthoglide (pose: x, y, z; to pick and rename columns: --columns x=X_mm,...)")


@pytest.mark.parametrize("args, words", [
    (["--columns", "time"], "--columns: expected NAME=VALUE, got 'time'"),
    (["--columns", "x=X_mm,x=Y_mm"], "--columns: x is given twice"),
    (["--scale", "x=pi"], "'pi' is not a non-zero rational number"),
    (["--scale", "x=0"], "'0' is not a non-zero rational number"),
    (["--scale", "x=1/"], "--scale: x: "),
    (["--columns", "t=time,x=X,y=Y_mm,z=Z_mm"], "<stdin>:1: no column 'X' for x"),
    (["--columns", "t=time,u=speed"], "only one of them, the parameter"),
    (["--columns", "t=time,x=X_mm,y=Y_mm,z=Z_mm", "--scale", "w=2"], "the scale names 'w'"),
])
def test_bad_column_maps_are_one_line_and_exit_2(args, words):
    out = run_stdin(MILLIMETRES, "-", "--csv", *args)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert words in out.stderr, out.stderr


# --- messages a first run prints -------------------------------------------------------

@pytest.mark.parametrize("pose, straight", [
    ("{x: t, y: 1/2, z: 1 - t/3}", True),
    ("{x: sin(t), y: 1/2, z: 1}", False),
    ("{x: t^2, y: 1/2, z: 1}", False),
])
def test_too_costly_says_what_is_too_costly(tmp_path, pose, straight):
    from singcheck.certify.path import _too_costly
    from singcheck.spec.files import load_robot, load_trajectory

    path = tmp_path / "p.yaml"
    path.write_text(f"name: p\nparameter: t\nrange: [0, 1]\npose: {pose}\n")
    message = str(_too_costly("μ(t) would have 10^9 terms", load_trajectory(
        path, load_robot(ORTHO))))
    assert message.startswith(f"{path}:4: pose: too costly: μ(t) would have 10^9 terms: ")
    assert ("the cost is the robot's" in message) is straight
    assert ("lower the degrees" in message) is not straight


def test_a_one_piece_path_names_no_segment(tmp_path):
    """A k·π·t path is certified as one rescaled piece: its reasons and proofs say
    nothing of 'segment 1' (they did, 7 times, in this JSON)."""
    path = tmp_path / "pit.yaml"
    path.write_text("name: pit\nparameter: t\nrange: [0, 1]\n"
                    "pose: {x: 1/2 + cos(2*pi*t)/4, y: 1, z: 1}\n")
    out = singcheck("run", ORTHO, str(path), "--backend", "flint", "--no-regions", "-q",
                    "--format", "json")
    assert out.returncode in (0, 1), out.stderr
    (doc,) = json.loads(out.stdout)["trajectories"]
    assert len(doc["segments"]) == 1 and doc["segments"][0]["time_scale"]
    assert "segment 1" not in out.stdout
    assert any(m["reason"] for m in doc["working_modes"])  # reasons are still there


def test_a_fifty_row_csv_is_summarised_not_listed(tmp_path):
    path = tmp_path / "fifty.csv"
    path.write_text("t,x,y,z\n" + "".join(f"{i},{0.3 + i / 100:.2f},1,1\n"
                                          for i in range(50)))
    out = singcheck("run", ORTHO, str(path), "--backend", "flint", "--no-regions", "-q",
                    "--interpolation", "linear")
    assert out.returncode in (0, 1), out.stderr
    lines = [line for line in out.stdout.splitlines() if "segments:" in line]
    assert lines == ["  segments: 49 pieces (1: [0, 1]; …; 49: [48, 49]), roots by exact "
                     "univariate"]


def test_reasons_do_not_repeat_the_verdict(tmp_path):
    from singcheck.report.trajectory import error_json, time_limited_json
    from singcheck.spec.files import load_robot, load_trajectory

    spec = load_trajectory(TRAJECTORIES / "heart1.yaml", load_robot(ORTHO))
    stopped = time_limited_json(spec, "unknown: time limit (2 s) reached")
    assert (stopped["verdict"], stopped["reason"]) == ("unknown", "time limit (2 s) reached")
    failed = error_json(spec, "backend", "Singular failed")
    assert (failed["verdict"], failed["reason"]) == ("error", "Singular failed")
    # and through the command line: the JSON reason, the table's verdict line
    path = tmp_path / "slow.yaml"
    path.write_text("name: slow\nparameter: t\nrange: [0, 1]\n"
                    "pose: {x: cos(12*t)/2, y: sin(11*t)/2, z: -2}\n")
    rotary = str(ROBOTS / "rotary-delta.yaml")
    out = singcheck("run", rotary, str(path), "--backend", "flint", "--time-limit", "0.2",
                    "--format", "json", "-q")
    assert out.returncode == 3, out.stderr
    (doc,) = json.loads(out.stdout)["trajectories"]
    assert doc["reason"] == "time limit (0.2 s) reached"
    table = singcheck("run", rotary, str(path), "--backend", "flint", "--time-limit", "0.2",
                      "-q")
    assert "verdict unknown: time limit (0.2 s) reached" in table.stdout
    assert "unknown: unknown" not in table.stdout


def test_jsonl_lines_carry_their_time():
    out = singcheck("run", ORTHO, str(TRAJECTORIES / "heart1.yaml"),
                    str(TRAJECTORIES / "heart2.yaml"), "--format", "jsonl", "--no-regions",
                    "-q", "--backend", "flint")
    assert out.returncode == 1, out.stderr
    lines = [json.loads(line) for line in out.stdout.splitlines()]
    assert sorted(d["name"] for d in lines) == ["heart1", "heart2"]
    for d in lines:
        assert isinstance(d["time_s"], float) and 0 < d["time_s"] < 60
    whole = singcheck("run", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "--format", "json",
                      "--no-regions", "-q", "--backend", "flint")
    assert "time_s" not in json.loads(whole.stdout)["trajectories"][0]


def test_run_help_explains_the_mode_labels():
    out = singcheck("run", "--help")
    assert out.returncode == 0
    text = " ".join(out.stdout.split())
    assert "Working modes (+++, +-, ooo, ...): one character per leg" in text
    assert "o the only branch of a leg linear in its joint" in text
    assert "+ the branch with +√D" in text and "- the other branch" in text


def test_html_with_plotly_from_its_cdn_is_smaller(tmp_path):
    pytest.importorskip("plotly")
    common = ["plot", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "--format", "html", "-q",
              "--backend", "flint"]
    inline = singcheck(*common, "--out", str(tmp_path / "inline"))
    cdn = singcheck(*common, "--plotly", "cdn", "--out", str(tmp_path / "cdn"))
    assert inline.returncode == cdn.returncode == 0, cdn.stderr
    big = (tmp_path / "inline" / "singcheck.html").read_text()
    small = (tmp_path / "cdn" / "singcheck.html").read_text()
    assert 'src="https://cdn.plot.ly/plotly-' in small
    assert "cdn.plot.ly/plotly" not in big.split("<body>")[0]
    assert len(small) < len(big) - 4_000_000  # plotly.js is about 4.8 MB
    assert small.count("Plotly.newPlot") == big.count("Plotly.newPlot") > 0


def test_plot_names_the_verdict_once_when_a_path_runs_out_of_time(tmp_path):
    pytest.importorskip("matplotlib")
    path = tmp_path / "slow.yaml"
    path.write_text("name: slow\nparameter: t\nrange: [0, 1]\n"
                    "pose: {x: cos(12*t)/2, y: sin(11*t)/2, z: -2}\n")
    out = singcheck("plot", str(ROBOTS / "rotary-delta.yaml"), str(path), "--out",
                    str(tmp_path / "figures"), "--backend", "flint", "--time-limit", "0.2",
                    "-q")
    assert out.returncode == 3
    assert out.stderr.strip().splitlines() == [
        "singcheck: slow: unknown: time limit (0.2 s) reached (--time-limit): no figure"]


def test_a_column_map_applies_to_the_csv_tables_of_a_run_not_to_its_yaml(tmp_path):
    table = tmp_path / "mm.csv"
    table.write_text(MILLIMETRES)
    out = singcheck("run", ORTHO, str(TRAJECTORIES / "heart2.yaml"), str(table),
                    "--columns", "t=time,x=X_mm,y=Y_mm,z=Z_mm", "--scale",
                    "x=1/1000,y=1/1000,z=1/1000", "--format", "jsonl", "--no-regions", "-q",
                    "--backend", "flint")
    assert out.returncode == 1, out.stderr
    verdicts = {d["name"]: d["verdict"] for d in map(json.loads, out.stdout.splitlines())}
    assert verdicts == {"heart2": "singularity-free", "mm": "singular"}
