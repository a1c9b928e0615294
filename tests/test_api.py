"""The public Python API: what a program gets without the command line."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import singcheck
from tests.test_cli import ORTHO, traj


@pytest.fixture(scope="module")
def orthoglide():
    return singcheck.load_robot(ORTHO, backend="flint", cache=False)


def test_heart1_through_the_api_matches_the_command_line(orthoglide):
    heart1 = singcheck.load_trajectory(traj("heart1"), orthoglide)
    report = singcheck.check(orthoglide, heart1)
    assert report.verdict == "singular"
    # the paper's four candidates, two of them real (S3, S4 at t > 0)
    assert [round(float(c.t.mid()), 2) for c in report.candidates] == [-1.51, -0.98, 0.98, 1.51]
    assert [c.status for c in report.candidates] == ["spurious", "spurious", "real", "real"]
    feasible = [m.label for m in report.working_modes if m.feasible]
    assert feasible == ["+++"]
    doc = report.to_dict()
    cli = subprocess.run([sys.executable, "-m", "singcheck", "run", ORTHO, traj("heart1"),
                          "--backend", "flint", "--no-cache", "--format", "json", "-q"],
                         capture_output=True, text=True, timeout=300)
    assert cli.returncode == 1, cli.stderr
    (from_cli,) = json.loads(cli.stdout)["trajectories"]
    assert doc == json.loads(json.dumps(from_cli))


def test_check_prints_nothing(orthoglide, capsys):
    singcheck.check(orthoglide, singcheck.load_trajectory(traj("heart2"), orthoglide))
    out, err = capsys.readouterr()
    assert out == "" and err == ""


def test_a_second_check_reuses_the_projection(orthoglide, monkeypatch):
    """No backend run and no cache read once the robot is loaded."""
    from singcheck import api
    from singcheck.elimination import cache, projection
    from singcheck.elimination.cas import flint_backend

    def forbidden(*args, **kwargs):
        raise AssertionError("the projection was computed or read again")

    monkeypatch.setattr(api, "project_robot", forbidden)
    monkeypatch.setattr(projection, "project_robot", forbidden)
    monkeypatch.setattr(flint_backend.FlintBackend, "eliminate", forbidden)
    monkeypatch.setattr(cache, "read_entry", forbidden)
    for name in ("heart1", "heart2"):
        report = singcheck.check(orthoglide, singcheck.load_trajectory(traj(name), orthoglide),
                                 regions=False)
        assert report.verdict in ("singular", "singularity-free")


def test_options_are_keyword_arguments(orthoglide):
    helix = singcheck.load_trajectory(traj("helix"), orthoglide)
    report = singcheck.check(orthoglide, helix, tolerance=1e-6, regions=False, time_limit=600)
    assert report.verdict == "singularity-free"
    assert "workspace" not in report.to_dict()
    with pytest.raises(TypeError):
        singcheck.check(orthoglide, helix, 1e-6)


def test_a_time_limit_gives_unknown_with_the_reason(orthoglide):
    helix = singcheck.load_trajectory(traj("helix"), orthoglide)
    report = singcheck.check(orthoglide, helix, time_limit=1e-9)
    assert report.verdict == "unknown"
    assert "time limit" in report.reason
    assert report.to_dict()["verdict"] == "unknown"


def test_import_singcheck_is_cheap():
    """The API loads on first use: importing the package pulls in no stage."""
    code = ("import sys, singcheck; "
            "print(sorted(m for m in sys.modules if m.startswith('singcheck')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "['singcheck', 'singcheck.version']"
