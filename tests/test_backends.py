"""Every backend gives the same answers; a warm cache answers without the CAS."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from singcheck.cli import commands as cli
from tests.test_cas import _backend
from tests.test_cli import ORTHO, singcheck, traj

ALL = [traj(n) for n in ("heart1", "heart2", "helix")]


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

    monkeypatch.setattr(process, "run_program", no_cas)
    monkeypatch.setattr(external, "run_program", no_cas)
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
