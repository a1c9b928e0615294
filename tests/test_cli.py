"""The command line as users and CI jobs run it: real processes, real exit codes."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROBOTS, ROOT, TRAJECTORIES

ORTHO = str(ROBOTS / "orthoglide.yaml")
BIGLIDE = str(ROBOTS / "skew-biglide.yaml")


def traj(name: str) -> str:
    return str(TRAJECTORIES / f"{name}.yaml")


def singcheck(*args: str, env: dict | None = None, cwd=None) -> subprocess.CompletedProcess:
    full_env = {**os.environ, **(env or {})}
    return subprocess.run([sys.executable, "-m", "singcheck", *args], capture_output=True,
                          text=True, env=full_env, cwd=cwd or ROOT, timeout=300)


@pytest.fixture(scope="module")
def heart1_json(tmp_path_factory):
    cache = tmp_path_factory.mktemp("cache")
    out = singcheck("run", ORTHO, traj("heart1"), "--format", "json", "--backend", "sympy",
                    env={"SINGCHECK_CACHE_DIR": str(cache)})
    return out


def test_heart1_json_document(heart1_json):
    assert heart1_json.returncode == 1, heart1_json.stderr
    doc = json.loads(heart1_json.stdout)
    assert doc["schema_version"] == 1 and doc["exit_code"] == 1
    assert doc["robot"]["joints"] == ["rho1", "rho2", "rho3"]
    (t,) = doc["trajectories"]
    assert t["name"] == "heart1" and t["verdict"] == "singular"
    assert [c["status"] for c in t["candidates"]] == ["spurious", "spurious", "real", "real"]
    for c in t["candidates"]:
        lo, hi = c["t_interval"]
        assert lo <= c["t"] <= hi and hi - lo <= 2e-9
        assert set(c["pose"]) == {"x", "y", "z"}
    assert t["candidates"][3]["singular_modes"] == ["+++"]
    assert t["candidates"][3]["joints"]["+++"]["rho1"] == pytest.approx(2.832, abs=1e-3)
    modes = {m["label"]: m for m in t["working_modes"]}
    assert len(modes) == 8 and modes["+++"]["feasible"] is True
    assert [m for m in modes.values() if m["feasible"]] == [modes["+++"]]
    assert modes["+++"]["singular_times"] == pytest.approx([0.9778, 1.5119], abs=1e-4)
    assert set(modes["+++"]["joints_at_start"]) == {"rho1", "rho2", "rho3"}
    assert "Traceback" not in heart1_json.stderr


def test_json_t_interval_encloses_the_root_exactly(heart1_json):
    # the root t* of mu: check the sign of mu's defining det A in the +++ mode changes
    # across the reported interval, independently, with mpmath at 50 digits
    import mpmath

    mpmath.mp.dps = 50
    doc = json.loads(heart1_json.stdout)
    c = doc["trajectories"][0]["candidates"][3]

    def det_a(t):
        s, co = mpmath.sin(t), mpmath.cos(t)
        x = mpmath.mpf(8) / 7 * s**3
        y = (mpmath.mpf(13) / 14 * co - mpmath.mpf(5) / 14 * mpmath.cos(2 * t)
             - mpmath.mpf(1) / 10 * mpmath.cos(3 * t) - mpmath.mpf(1) / 14 * mpmath.cos(4 * t))
        z = 1
        r1 = x + mpmath.sqrt(4 - y**2 - z**2)
        r2 = y + mpmath.sqrt(4 - x**2 - z**2)
        r3 = z + mpmath.sqrt(4 - x**2 - y**2)
        return -r1 * r2 * r3 + r1 * r2 * z + r1 * r3 * y + r2 * r3 * x

    lo, hi = c["t_interval"]
    assert det_a(mpmath.mpf(lo)) * det_a(mpmath.mpf(hi)) < 0


def test_heart2_and_helix_exit_0():
    out = singcheck("run", ORTHO, traj("heart2"), traj("helix"), "--backend", "sympy", "-q")
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("singularity-free") == 2
    assert out.stderr == ""


def test_one_singular_trajectory_makes_the_batch_exit_1():
    out = singcheck("run", ORTHO, traj("heart2"), traj("heart1"), "--backend", "sympy")
    assert out.returncode == 1
    assert "verdict singular" in out.stdout and "verdict singularity-free" in out.stdout
    assert "heart1: singular" in out.stderr  # progress goes to stderr


def test_table_lists_candidates_and_the_verdict():
    out = singcheck("run", ORTHO, traj("heart1"), "--backend", "sympy", "-v")
    assert out.returncode == 1
    text = out.stdout
    for t in ("-1.51191309", "-0.977816937", "0.977816937", "1.51191309"):
        assert t in text
    assert text.count("spurious") == 2 and "real" in text
    assert "elimination" in text or "sign change" in text  # -v shows the proofs


def test_planar_robot_crossing_and_free():
    out = singcheck("run", BIGLIDE, traj("skew-biglide-ellipse"), "--format", "json",
                    "--backend", "sympy")
    assert out.returncode == 1
    (t,) = json.loads(out.stdout)["trajectories"]
    assert t["verdict"] == "singular"
    assert [m["label"] for m in t["working_modes"] if m["feasible"]] == ["++"]
    assert sorted(c["status"] for c in t["candidates"]) == ["real", "real", "spurious",
                                                            "spurious"]
    out = singcheck("run", BIGLIDE, traj("skew-biglide-circle"), "--format", "json",
                    "--backend", "sympy")
    assert out.returncode == 0
    (t,) = json.loads(out.stdout)["trajectories"]
    assert [m["label"] for m in t["working_modes"] if m["feasible"]] == ["++", "+-"]
    assert all(c["status"] == "spurious" for c in t["candidates"])


def test_run_names_the_real_dimension_of_the_workspace_it_decomposes(tmp_path):
    """A path of the biglide (pose x, y) moving in x and y lies in its 2-D workspace, one
    with y fixed in a line of it: the progress line says so (it said "in 3-D")."""
    for name, pose, where in (("plane", "{x: t/10, y: 1 + t/10}", "in 2-D"),
                              ("line", "{x: t/10, y: 1}", "y = 1; 1-D")):
        path = tmp_path / f"{name}.yaml"
        path.write_text(f"name: {name}\nparameter: t\nrange: [0, 1]\npose: {pose}\n")
        out = singcheck("run", str(ROBOTS / "biglide.yaml"), str(path), "--backend", "flint",
                        env={"SINGCHECK_CACHE_DIR": str(tmp_path / name)})
        assert out.returncode == 0, out.stderr
        assert f"decomposing the workspace ({where}) into regions" in out.stderr


BAD_CLI = [
    (["run", ORTHO, "missing.yaml"], "missing.yaml: cannot read the file"),
    (["run", "nowhere.yaml", "x.yaml"], "nowhere.yaml: cannot read the file"),
    (["run", ORTHO, BIGLIDE], "unknown key in a trajectory spec"),
    (["run", ORTHO], "Missing argument"),
    (["run", ORTHO, traj("heart1"), "--tolerance", "-1"], "Invalid value"),
    (["run", ORTHO, traj("heart1"), "--format", "xml"], "Invalid value"),
    (["frobnicate"], "No such command"),
]


@pytest.mark.parametrize("args, phrase", BAD_CLI, ids=[p for _, p in BAD_CLI])
def test_usage_and_input_errors_exit_2_with_one_line(args, phrase):
    out = singcheck(*args)
    assert out.returncode == 2
    assert phrase in out.stderr
    assert "Traceback" not in out.stderr and out.stdout == ""


def test_bad_trajectory_file_names_file_line_and_key(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: b\nparameter: t\nrange: [0, 1]\npose:\n  x: sin(t)\n  y: 1\n"
                   "  z: tan(t + 1)\n")
    out = singcheck("run", ORTHO, str(bad))
    assert out.returncode == 2
    (line,) = out.stderr.strip().splitlines()
    assert line.startswith(f"singcheck: error: {bad}:7: pose.z:")
    assert "unknown function 'tan'" in line


def test_forcing_a_missing_backend_exits_4_with_a_hint():
    out = singcheck("run", ORTHO, traj("heart1"), "--backend", "singular",
                    env={"PATH": "/nonexistent"})
    assert out.returncode == 4
    assert "Singular was not found" in out.stderr and "apt-get install singular" in out.stderr
    out = singcheck("run", ORTHO, traj("heart1"), env={"PATH": "/nonexistent",
                                                        "SINGCHECK_BACKEND": "macaulay2"})
    assert out.returncode == 4 and "M2 was not found" in out.stderr


def test_auto_says_which_backend_it_picked():
    out = singcheck("run", ORTHO, traj("heart2"), env={"PATH": "/nonexistent"})
    assert out.returncode == 0
    assert "backend: sympy" in out.stderr


def test_output_file_is_written_whole(tmp_path):
    target = tmp_path / "report.json"
    out = singcheck("run", ORTHO, traj("heart2"), "--format", "json", "-o", str(target),
                    "--backend", "sympy")
    assert out.returncode == 0 and out.stdout == ""
    assert json.loads(target.read_text())["trajectories"][0]["verdict"] == "singularity-free"
    bad = tmp_path / "never.json"
    out = singcheck("run", ORTHO, "missing.yaml", "-o", str(bad))
    assert out.returncode == 2 and not bad.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["report.json"]


def test_help_teaches_exit_codes_and_examples():
    out = singcheck("run", "--help")
    assert out.returncode == 0
    for phrase in ("Exit status", "130", "--format json", "singularity-free", "--backend"):
        assert phrase in out.stdout


def test_ctrl_c_exits_130(monkeypatch, capsys):
    from singcheck.cli import commands as cli

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "_run", interrupted)
    monkeypatch.setattr(sys, "argv", ["singcheck", "run", ORTHO, traj("heart1")])
    with pytest.raises(SystemExit) as exit_:
        cli.main()
    assert exit_.value.code == 130
    assert "interrupted" in capsys.readouterr().err


def test_an_internal_error_is_one_line_not_a_traceback(monkeypatch, capsys):
    from singcheck.cli import commands as cli

    def broken(*args, **kwargs):
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(cli, "_run", broken)
    monkeypatch.setattr(sys, "argv", ["singcheck", "run", ORTHO, traj("heart1")])
    monkeypatch.delenv("SINGCHECK_DEBUG", raising=False)
    with pytest.raises(SystemExit) as exit_:
        cli.main()
    assert exit_.value.code == 70
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error: ZeroDivisionError: boom" in err


def test_floats_in_json_round_outward():
    from flint import arb, fmpq

    from singcheck.algebra.intervals import endpoints

    lo, hi = endpoints(arb(fmpq(1, 3)))
    assert lo < 1 / 3 < hi or (lo <= 1 / 3 <= hi and lo < hi)
    assert math.isfinite(lo) and math.isfinite(hi)


def test_readme_commands_exist():
    readme = (ROOT / "README.md").read_text()
    makefile = (ROOT / "Makefile").read_text()
    assert "make demo" in readme and "make test" in readme
    assert "\ndemo:" in makefile and "\ntest:" in makefile
    ci = (ROOT / ".ci" / "run").read_text()
    assert "make test" in ci and "make demo" in ci
    assert Path(ROOT / "robots" / "orthoglide.yaml").exists()


def test_a_batch_in_parallel_gives_the_same_answers_as_one_process(tmp_path):
    sys.path.insert(0, str(ROOT / "bench"))
    from generate import write

    paths = [str(p) for p in write(tmp_path, 12, harmonics=4, seed=7)]
    common = ["run", ORTHO, *paths, "--format", "json", "--backend", "sympy"]
    serial = singcheck(*common, "--jobs", "1")
    parallel = singcheck(*common, "--jobs", "2")
    assert serial.returncode == parallel.returncode
    assert json.loads(serial.stdout)["trajectories"] == json.loads(parallel.stdout)["trajectories"]
    assert "certified" in parallel.stderr or "12/12" in parallel.stderr
    verdicts = {t["verdict"] for t in json.loads(serial.stdout)["trajectories"]}
    assert verdicts <= {"singular", "singularity-free", "infeasible"}


@pytest.mark.parametrize(("count", "verbose", "listed"), [(5, False, 5), (7, False, 4),
                                                          (7, True, 7)])
def test_the_table_lists_a_few_undecided_stretches_and_counts_the_rest(
        heart1_json, count, verbose, listed):
    """A hexapod from its home pose leaves 63 undecided stretches: the table lists the
    first MAX_UNDECIDED_SHOWN − 1 and counts the rest (all of them with -v)."""
    import io

    from rich.console import Console

    from singcheck.report.trajectory import render_tables

    report = json.loads(heart1_json.stdout)
    doc = report["trajectories"][0]
    doc["undecided"] = [{"t_interval": [k / 10, k / 10 + 0.01], "reason": f"reason {k}"}
                        for k in range(count)]
    out = io.StringIO()
    render_tables(Console(file=out, width=200), report["robot"], [doc], verbose)
    text = out.getvalue()
    assert [k for k in range(count) if f"reason {k}\n" in text] == list(range(listed))
    more = f"… and {count - listed} more undecided stretch(es)"
    assert (more in text) == (listed < count)
