"""Every backend gives the same answers; a warm cache answers without the CAS."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from singcheck.cli import commands as cli
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_cas import _backend
from tests.test_cli import ORTHO, singcheck, traj

ALL = [traj(n) for n in ("heart1", "heart2", "helix")]
DATA_ROBOTS = ROBOTS.parent / "tests" / "data" / "robots"


def _summary(doc: dict) -> list:
    out = []
    for t in doc["trajectories"]:
        out.append((
            t["name"], t["verdict"],
            [(round(c["t"], 10), c["status"], c["singular_modes"]) for c in t["candidates"]],
            [(m["label"], m["status"]) for m in t["working_modes"]],
        ))
    return out


@pytest.fixture(scope="module")
def reference():
    out = singcheck("run", ORTHO, *ALL, "--backend", "sympy", "--no-cache", "--format", "json")
    assert out.returncode == 1, out.stderr
    return json.loads(out.stdout)


@pytest.mark.parametrize("name", ["singular", "macaulay2", "flint"])
def test_every_backend_gives_the_same_verdicts_candidates_and_classes(name, reference):
    if name != "flint":
        _backend(name)  # fails in CI when the CAS is missing, skips loudly elsewhere
    out = singcheck("run", ORTHO, *ALL, "--backend", name, "--no-cache", "--format", "json")
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["backend"] == name
    assert _summary(doc) == _summary(reference)


def test_a_warm_cache_runs_no_cas_process(tmp_path, monkeypatch):
    _backend("singular")
    monkeypatch.setenv("SINGCHECK_CACHE_DIR", str(tmp_path))
    args = ["run", ORTHO, traj("heart1"), "--backend", "singular", "--format", "json"]
    first = CliRunner().invoke(cli.cli, args)
    assert first.exit_code == 1, first.output

    from singcheck.elimination.cas import external, process

    def no_cas(*a, **k):
        raise AssertionError("a CAS process was started despite a warm cache")

    monkeypatch.setattr(process, "run_program", no_cas)  # external imports it when it runs
    external.cas_version.cache_clear()  # forget the in-process memo: only the disk remains
    second = CliRunner().invoke(cli.cli, args)
    assert second.exit_code == 1, second.output
    assert json.loads(second.stdout)["trajectories"] == json.loads(first.stdout)["trajectories"]


def test_backends_command_lists_all_four():
    out = singcheck("backends", "--format", "json")
    assert out.returncode == 0
    infos = {i["name"]: i for i in json.loads(out.stdout)}
    assert set(infos) == {"singular", "macaulay2", "sympy", "flint"}
    assert infos["sympy"]["found"] is True
    missing = singcheck("backends", env={"PATH": "/nonexistent"})
    assert "missing" in missing.stdout and "apt-get install singular" in missing.stdout


# Issue 12: a robot with revolute actuators (the 5-bar, bundled) and one with an
# orientation whose ξ needs an elimination (a small bar robot: the bundled 3-RPR and
# Gough–Stewart need none, and the 3-PRR's ξ of degree 32 takes Singular's resultant
# chain about 4 s: test_cas.py).  Each backend agrees with FLINT's answer, or refuses in
# one line that names a backend that can; the refusals known today are listed, any other
# one fails.
ANGLES = {
    "five-bar": (ROBOTS / "five-bar.yaml", TRAJECTORIES / "five-bar-cross.yaml"),
    "2-prr-bar": (DATA_ROBOTS / "2-prr-bar.yaml", DATA_ROBOTS / "2-prr-bar-turn.yaml"),
}
KNOWN_REFUSALS = {("sympy", "five-bar")}  # its Gröbner basis does not finish on the angles


@pytest.fixture(scope="module")
def angle_references():
    out = {}
    for case, (robot, path) in ANGLES.items():
        run = singcheck("run", str(robot), str(path), "--backend", "flint", "--no-cache",
                        "--format", "json")
        assert run.returncode == 1, run.stderr  # both paths cross a singularity
        out[case] = json.loads(run.stdout)
    return out


@pytest.mark.parametrize("case", sorted(ANGLES))
@pytest.mark.parametrize("name", ["singular", "macaulay2", "sympy"])
def test_backends_agree_on_a_revolute_robot_and_one_with_orientation(name, case,
                                                                     angle_references):
    if name != "sympy":
        _backend(name)
    robot, path = ANGLES[case]
    out = singcheck("run", str(robot), str(path), "--backend", name, "--no-cache", "--format",
                    "json")
    if (name, case) in KNOWN_REFUSALS:
        assert out.returncode == 4, out.stderr
        (line,) = [x for x in out.stderr.splitlines() if "error" in x]  # one line
        assert "cannot eliminate" in line and "flint" in line, line
        return
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["backend"] == name
    assert _summary(doc) == _summary(angle_references[case])
    assert any(c["status"] == "real" for c in doc["trajectories"][0]["candidates"])


def test_auto_hands_a_request_the_cas_does_not_finish_to_flint(monkeypatch):
    """``auto`` gives the external CAS AUTO_CAS_SECONDS per request, then the in-process
    flint backend (the stacked Orthoglide: Singular past 600 s, flint 0.4 s).  With a
    budget no CAS can meet, ξ comes from flint, re-checked, the same surface as flint's
    own, and the method says why; a backend asked for by name keeps its whole timeout."""
    from singcheck import api
    from singcheck.algebra.polynomials import squarefree_part
    from singcheck.elimination import cas

    _backend("singular")  # (skips, loudly, where Singular is absent; fails in CI)
    monkeypatch.setattr(cas, "AUTO_CAS_SECONDS", 1e-3)
    robot = api.load_robot(str(ROBOTS / "orthoglide.yaml"), backend="auto", cache=False)
    method = robot.projection.method
    assert method.endswith("singular did not finish within 0.001 s (auto)"), method
    flint = api.load_robot(str(ROBOTS / "orthoglide.yaml"), backend="flint", cache=False)
    assert squarefree_part(robot.projection.singularity_surface) == \
        squarefree_part(flint.projection.singularity_surface)
    report = api.check(robot, api.load_trajectory(str(TRAJECTORIES / "heart1.yaml"), robot),
                       regions=False)
    assert report.verdict == "singular"
    assert cas.get_backend("singular", timeout=5).timeout == 5
