"""Hostile input never crashes, hangs or lies: one regression test per finding of the
hostile run (issue 16) — deep nesting, huge numbers, costly small specs, huge CAS
output, planted cache files, forged cache entries, signals, ``-o`` targets, missing
extras, undecided boxes."""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import stat
import subprocess
import sys
import textwrap
import threading
import time
from fractions import Fraction
from pathlib import Path

import pytest

from tests.conftest import ROBOTS, ROOT, TRAJECTORIES

ORTHO = str(ROBOTS / "orthoglide.yaml")
BIGLIDE = str(ROBOTS / "biglide.yaml")


def run_cli(monkeypatch, capsys, *args: str) -> tuple[int, str, str]:
    """The console entry point in-process: (exit status, stdout, stderr)."""
    from singcheck.cli.commands import main

    monkeypatch.setattr(sys, "argv", ["singcheck", *args])
    monkeypatch.delenv("SINGCHECK_DEBUG", raising=False)
    with pytest.raises(SystemExit) as exit_:
        main()
    out = capsys.readouterr()
    return int(exit_.value.code or 0), out.out, out.err


def trajectory(tmp_path: Path, pose: dict[str, str], rng: str = "0, 1",
               name: str = "t") -> str:
    path = tmp_path / f"{name}.yaml"
    lines = [f"name: {name}", "parameter: t", f"range: [{rng}]", "pose:"]
    lines += [f"  {k}: {v}" for k, v in pose.items()]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


@pytest.fixture
def cache_env(tmp_path, monkeypatch):
    """A private cache and cache key for the test."""
    monkeypatch.setenv("SINGCHECK_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    from singcheck.elimination import cache

    cache._KEYS.clear()
    yield tmp_path / "cache"
    cache._KEYS.clear()


def one_line_error(code: int, err: str, expected_code: int, phrase: str) -> None:
    assert code == expected_code, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert phrase in err, err


# -- 1. deep nesting ------------------------------------------------------------------


@pytest.mark.parametrize("pose_x, phrase", [
    ("[" * 1000, "nested more than 16 levels"),
    ("(" * 300 + "t" + ")" * 300, "nested more than 64 levels"),
    ("t" + "^t" * 200, "nested more than 64 levels"),
    ("sin(" * 100 + "t" + ")" * 100, "nested more than 64 levels"),
])
def test_deep_nesting_is_a_one_line_spec_error(tmp_path, monkeypatch, capsys, cache_env,
                                               pose_x, phrase):
    spec = trajectory(tmp_path, {"x": pose_x, "y": "0", "z": "1"})
    code, _, err = run_cli(monkeypatch, capsys, "run", ORTHO, spec, "-q", "--backend", "flint")
    one_line_error(code, err, 2, phrase)


def test_long_sign_runs_and_sums_parse_without_recursion():
    """1000 signs are one sign; a sum of 900 terms and a product of 1000 factors are
    regrouped into shallow trees — checked against exact arithmetic done here."""
    from singcheck.spec.grammar import compile_constant, parse

    assert compile_constant(parse("-" * 1001 + "7")).rational == -7
    assert compile_constant(parse("-" * 1000 + "7")).rational == 7
    terms = [Fraction(k, k + 1) * (-1) ** k for k in range(1, 900)]
    text = "".join(f"{'-' if q < 0 else '+'}{abs(q.numerator)}/{q.denominator}"
                   for q in terms)
    assert compile_constant(parse(text)).rational == sum(terms)
    text = "*".join(["3/2"] * 500) + "/" + "/".join(["3"] * 500)
    assert compile_constant(parse("1*" + text)).rational == Fraction(1, 2 ** 500)
    # a - b + c and a / b * c keep their left-to-right meaning
    assert compile_constant(parse("10 - 4 + 3 - 2")).rational == 7
    assert compile_constant(parse("12 / 4 * 3 / 9 * 2")).rational == 2


# -- 2. numbers -------------------------------------------------------------------------


@pytest.mark.parametrize("pose, phrase", [
    ({"x": "t^1e5000", "y": "0", "z": "1"}, "the number 1e5000 is too large"),
    ({"x": "1e999999999", "y": "0", "z": "1"}, "the number 1e999999999 is too large"),
    ({"x": "sin(t)", "y": "cos(t)", "z": "1.0e+308"}, "the number 1.0e+308 is too large"),
    ({"x": "0." + "0" * 200 + "1", "y": "0", "z": "1"}, "is too large"),
    ({"x": "7" * 5000, "y": "0", "z": "1"}, "(5000 characters) is too large"),
    ({"x": "t^" + "9" * 5000, "y": "0", "z": "1"}, "is too large"),
])
def test_huge_number_literals_are_refused_up_front(tmp_path, monkeypatch, capsys, cache_env,
                                                    pose, phrase):
    spec = trajectory(tmp_path, pose)
    start = time.monotonic()
    code, _, err = run_cli(monkeypatch, capsys, "run", ORTHO, spec, "-q", "--backend", "flint")
    one_line_error(code, err, 2, phrase)
    assert time.monotonic() - start < 10
    assert len(err) < 400


def test_number_literals_within_the_bound_stay_exact():
    from singcheck.spec.grammar import MAX_LITERAL_BITS, compile_constant, parse

    assert compile_constant(parse("1e150")).rational == 10 ** 150
    assert compile_constant(parse("2.5e-3")).rational == Fraction(1, 400)
    assert compile_constant(parse("0.000")).rational == 0
    big = str(2 ** MAX_LITERAL_BITS - 1)
    assert compile_constant(parse(big)).rational == 2 ** MAX_LITERAL_BITS - 1
    from singcheck.spec.grammar import ExprError

    with pytest.raises(ExprError, match="too large"):
        parse(str(2 ** MAX_LITERAL_BITS))


# -- 4. CAS output --------------------------------------------------------------------


def test_a_huge_coefficient_between_valid_markers_is_a_backend_error(orthoglide):
    from singcheck.elimination.cas.scripts import BEGIN, END, parse_result
    from singcheck.elimination.projection import singularity_surface_request
    from singcheck.errors import BackendError

    request = singularity_surface_request(orthoglide)
    label = request.label
    stdout = f"{BEGIN} {label} 1\n{'7' * 3_000_000}*v4^2+1\n{END} {label}\n"
    start = time.monotonic()
    with pytest.raises(BackendError, match="3000000 digits"):
        parse_result("Singular", stdout, "", request)
    assert time.monotonic() - start < 5
    for bad_count in ("²", "9" * 5000):
        with pytest.raises(BackendError, match="malformed marker"):
            parse_result("Singular", f"{BEGIN} {label} {bad_count}\n1\n{END} {label}\n", "",
                         request)
    with pytest.raises(BackendError, match="exponent"):
        parse_result("Singular", f"{BEGIN} {label} 1\nv4^99999999999\n{END} {label}\n", "",
                     request)


def fake_cas(tmp_path: Path, body: str) -> Path:
    """A directory holding a fake ``Singular`` (a Python script) for PATH."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(exist_ok=True)
    exe = bin_dir / "Singular"
    exe.write_text(f"#!{sys.executable}\n" + textwrap.dedent(body))
    exe.chmod(0o755)
    return bin_dir


VERSION = """\
import sys
if "--version" in sys.argv:
    print("Singular for x86_64-Linux version 4.3.1 (fake)")
    sys.exit(0)
"""


def test_a_cas_printing_without_end_is_stopped_at_the_output_bound(tmp_path, monkeypatch):
    from singcheck.elimination.cas import process
    from singcheck.errors import BackendError

    monkeypatch.setattr(process, "MAX_OUTPUT_BYTES", 2**20)
    start = time.monotonic()
    with pytest.raises(BackendError, match="printed more than"):
        process.run_program([sys.executable, "-c", "import sys\nwhile True: "
                             "sys.stdout.write('7' * 65536)"], timeout=60)
    assert time.monotonic() - start < 30


# -- 5. cache files ---------------------------------------------------------------------


def _entries(cache_dir: Path) -> list[Path]:
    return sorted(p for p in cache_dir.glob("*/*.json"))


@pytest.mark.parametrize("fault", ["fifo", "dev-zero", "nested", "huge", "directory"])
def test_a_planted_cache_entry_is_a_miss_and_is_replaced(tmp_path, monkeypatch, capsys,
                                                         cache_env, fault):
    args = ("run", ORTHO, str(TRAJECTORIES / "heart2.yaml"), "-q", "--backend", "sympy",
            "--format", "json")
    code, out, err = run_cli(monkeypatch, capsys, *args)
    assert code == 0, err
    expected = json.loads(out)["singularity_surface_degree"]
    (entry,) = [p for p in _entries(cache_env)
                if "singularity_surface" in p.read_text()]
    entry.unlink()
    if fault == "fifo":
        os.mkfifo(entry)
    elif fault == "dev-zero":
        entry.symlink_to("/dev/zero")
    elif fault == "nested":
        entry.write_text("[" * 100_000 + "]" * 100_000)
    elif fault == "huge":
        with open(entry, "wb") as f:
            f.truncate(65 * 2**20)  # sparse: past the bound without using the disk
    else:
        entry.mkdir()
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, *args)
    assert code == 0 and "Traceback" not in err, err
    assert json.loads(out)["singularity_surface_degree"] == expected
    assert time.monotonic() - start < 60
    if fault != "directory":  # replaced by a good regular entry, read on the next run
        assert stat.S_ISREG(os.lstat(entry).st_mode)
        from singcheck.elimination.cache import FORMAT, read_entry

        assert read_entry(entry, FORMAT, entry.stem)["label"] == "singularity_surface"


# -- 6. cache poisoning -------------------------------------------------------------------


class WrongBackend:
    """Answers every request with x (a wrong ξ), counting its calls."""

    name = "wrong"

    def __init__(self):
        self.calls = 0

    def version(self) -> str:
        return "1"

    def eliminate(self, request):
        from singcheck.elimination.requests import EliminationResult

        self.calls += 1
        x = request.kept_context().gens()[0]
        return EliminationResult(request, (x,), "wrong", self.name)


def test_a_wrong_answer_is_never_cached(orthoglide, cache_env):
    from singcheck.elimination.cache import CachedBackend, EliminationCache
    from singcheck.elimination.cas import get_backend
    from singcheck.elimination.projection import project_robot, singularity_surface_request
    from singcheck.errors import BackendError

    cache = EliminationCache(cache_env)
    wrong = WrongBackend()
    for _ in range(2):
        with pytest.raises(BackendError, match="re-check"):
            project_robot(orthoglide, CachedBackend(wrong, cache))
    assert wrong.calls == 2 and _entries(cache_env) == []  # asked again: nothing stored
    # a wrong entry that is in the cache anyway (written with the key) is a miss, then
    # replaced by the right answer
    request = singularity_surface_request(orthoglide)
    key = cache.key(CachedBackend(wrong, cache)._identity(request), "flint",
                    get_backend("flint").version())
    cache.store(key, wrong.eliminate(request))
    projection = project_robot(orthoglide, CachedBackend(get_backend("flint"), cache))
    assert cache.stats.corrupted == 1
    # the right ξ: degree 16, vanishing on the sphere x² + y² + z² = 4 (all legs aligned)
    xi = projection.singularity_surface
    assert xi.total_degree() == 16
    assert xi(2, 0, 0) == 0 and xi(0, 0, 2) == 0 and xi(0, 0, 0) != 0
    again = CachedBackend(get_backend("flint"), EliminationCache(cache_env))
    project_robot(orthoglide, again)
    assert again.cache.stats.hits == 1 and again.cache.stats.corrupted == 0


def _exact_value(p, point) -> Fraction:
    """p at a rational point, with Fractions (independent of FLINT's evaluation)."""
    total = Fraction(0)
    for exps, c in p.terms():
        term = Fraction(int(c.p), int(c.q))
        for x, e in zip(point, exps, strict=True):
            term *= Fraction(x) ** int(e)
        total += term
    return total


def _merged_into_other_signs(payload: dict, cad, victim: int) -> dict:
    """The forger's best relabelling: region ``victim``'s cells given to a region whose
    factor signs differ, then all renumbered 1…N in the order of their first cell, as
    the real numbering is (so only the signs betray it)."""
    from singcheck.spaces.region_map import RegionMap

    region_map = RegionMap.from_payload(payload)
    samples = {c.index: c.sample for c in cad.cells}

    def signs(number):
        index = min(i for i, n in region_map.numbers.items() if n == number)
        return tuple((v > 0) - (v < 0) for f in region_map.factors
                     for v in [_exact_value(f, samples[index])])

    other = next(n for n in sorted(set(region_map.numbers.values()))
                 if signs(n) != signs(victim))
    merged = {i: other if n == victim else n for i, n in region_map.numbers.items()}
    renumber: dict[int, int] = {}
    for index in sorted(merged):
        renumber.setdefault(merged[index], len(renumber) + 1)
    return {**payload, "cells": [[list(i), renumber[n]] for i, n in sorted(merged.items())]}


def _forgeries(payload: dict, cad) -> dict[str, tuple[dict, str]]:
    """Forged payloads, each with the check that must catch it."""
    def swapped(a, b):
        return {**payload, "cells": [[i, {a: b, b: a}.get(n, n)] for i, n in payload["cells"]]}

    flipped = payload["factors"][0]
    flipped = flipped[1:] if flipped.startswith("-") else "-" + flipped  # not -f: - binds
    flipped_level = [list(level) for level in payload["levels"]]
    flipped_level[0][0] = flipped_level[0][0] + "+1"
    return {
        "labels of R9 and R10 swapped": (swapped(9, 10), "not numbered 1, 2"),
        "R9 merged into another region, renumbered": (
            _merged_into_other_signs(payload, cad, 9), "different signs"),
        "a factor changed": ({**payload, "factors": [flipped, *payload["factors"][1:]]},
                             "factors are not"),
        "a projection level changed": ({**payload, "levels": flipped_level},
                                       "projection levels are not"),
        "a cell dropped": ({**payload, "cells": payload["cells"][1:]}, "cells are not"),
    }


def test_each_forgery_of_a_region_map_fails_its_check(orthoglide_projection):
    """heart 2 lies in R9 of the plane z = 1 (README); entries forged by someone who
    holds the cache key (so their HMAC is right) fail the check against the inputs."""
    from singcheck.spaces.analysis import (
        WORKSPACE,
        analyse,
        decomposition,
        select_surfaces,
        workspace_variety,
    )
    from singcheck.spaces.region_map import RegionMap

    fixed = {"z": Fraction(1)}
    components, _ = select_surfaces(workspace_variety(orthoglide_projection), WORKSPACE,
                                    "auto", 2)
    model = orthoglide_projection.model
    true_map = RegionMap.of(analyse(WORKSPACE, model, components, fixed))
    cad = decomposition(model.pose, components, fixed)[2]
    assert true_map.verify(cad) == ""
    payload = true_map.payload()
    forgeries = _forgeries(payload, cad)
    for what, (forged, phrase) in forgeries.items():
        assert forged != payload, what
        problem = RegionMap.from_payload(forged).verify(cad)
        assert phrase in problem, (what, problem)


def test_a_forged_region_map_is_detected_and_recomputed(tmp_path, monkeypatch, capsys,
                                                        cache_env):
    """The forger holds the key (the HMAC is right): the entry is checked against its
    inputs, the forgery is reported and recomputed, and heart 2 is in R9 again."""
    args = ("run", ORTHO, str(TRAJECTORIES / "heart2.yaml"), "-q", "--backend", "flint",
            "--format", "json")
    code, out, err = run_cli(monkeypatch, capsys, *args)
    assert code == 0, err
    assert json.loads(out)["trajectories"][0]["workspace"]["region"].startswith("R9 ")
    (entry,) = (cache_env / "regions").glob("*.json")
    honest = entry.read_bytes()
    doc = json.loads(honest)
    swapped = {9: 10, 10: 9}
    doc["payload"]["cells"] = [[i, swapped.get(n, n)] for i, n in doc["payload"]["cells"]]
    from singcheck.elimination.cache import write_entry
    from singcheck.spaces import path_regions
    from singcheck.spaces.region_map import FORMAT

    write_entry(entry, FORMAT, doc["key"], doc["payload"])  # sealed with the real key
    assert entry.read_bytes() != honest
    path_regions._SUBSPACES.clear()
    code, out, err = run_cli(monkeypatch, capsys, *(a for a in args if a != "-q"))
    assert code == 0, err
    assert json.loads(out)["trajectories"][0]["workspace"]["region"].startswith("R9 ")
    assert "the cached region map failed its check (its regions are not numbered" in err
    assert json.loads(entry.read_bytes())["payload"] == json.loads(honest)["payload"]


def test_a_region_map_forged_without_the_key_is_recomputed(tmp_path, monkeypatch, capsys,
                                                           cache_env):
    """An entry whose numbers were changed and whose checksum was recomputed by a
    forger without the user's key is not believed either."""
    args = ("run", ORTHO, str(TRAJECTORIES / "heart2.yaml"), "-q", "--backend", "flint",
            "--format", "json")
    code, out, err = run_cli(monkeypatch, capsys, *args)
    assert code == 0, err
    (entry,) = (cache_env / "regions").glob("*.json")
    doc = json.loads(entry.read_text())
    doc["payload"]["cells"] = [[index, 10 if n == 9 else n]
                               for index, n in doc["payload"]["cells"]]
    import hashlib
    import hmac

    forged_key = b"0" * 64  # the forger does not have the user's key
    doc["hmac"] = hmac.new(forged_key, json.dumps(doc["payload"], sort_keys=True).encode(),
                           hashlib.sha256).hexdigest()
    entry.write_text(json.dumps(doc))
    from singcheck.spaces import path_regions

    path_regions._SUBSPACES.clear()
    code, out, err = run_cli(monkeypatch, capsys, *args)
    assert code == 0, err
    assert json.loads(out)["trajectories"][0]["workspace"]["region"].startswith("R9 ")


# -- 7. signals ---------------------------------------------------------------------------

SETSID_CAS = VERSION + """\
import os, subprocess, sys, time
pids = os.environ["FAKE_PIDS"]
child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(300)"],
                         start_new_session=True)  # setsid(): out of the CAS's group
with open(pids, "w") as f:
    f.write(f"{os.getpid()} {child.pid}\\n")
if os.environ.get("FAKE_HANG"):
    time.sleep(300)
sys.exit(3)
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _pids_written(path: Path, proc: subprocess.Popen) -> list[int]:
    """The pids a fake wrote to ``path`` (one line), waiting for it while ``proc`` runs."""
    deadline = time.monotonic() + 60
    while not (path.exists() and path.read_text().endswith("\n")):
        assert time.monotonic() < deadline and proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    return [int(pid) for pid in path.read_text().split()]


def _fake_env(tmp_path: Path, hang: bool) -> dict:
    bin_dir = fake_cas(tmp_path, SETSID_CAS)
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    return {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}", "TMPDIR": str(tmp),
            "FAKE_PIDS": str(tmp_path / "pids"), "SINGCHECK_CACHE_DIR": str(tmp_path / "c"),
            "XDG_CONFIG_HOME": str(tmp_path / "config"), "PYTHONPATH": str(ROOT),
            **({"FAKE_HANG": "1"} if hang else {})}


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_kill_the_cas_and_its_setsid_grandchild(tmp_path, sig):
    env = _fake_env(tmp_path, hang=True)
    proc = subprocess.Popen([sys.executable, "-m", "singcheck", "run", ORTHO,
                             str(TRAJECTORIES / "heart1.yaml"), "--backend", "singular",
                             "-q"], env=env, cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    cas, grandchild = _pids_written(tmp_path / "pids", proc)
    assert _alive(cas) and _alive(grandchild)
    assert os.getsid(grandchild) == grandchild != os.getpgid(cas)  # escaped the group
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err
    time.sleep(0.2)
    assert not _alive(cas) and not _alive(grandchild)
    assert list((tmp_path / "tmp").iterdir()) == []  # no /tmp/singcheck-* left


def test_a_setsid_grandchild_does_not_outlive_a_finished_cas(tmp_path):
    env = _fake_env(tmp_path, hang=False)
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", ORTHO,
                          str(TRAJECTORIES / "heart1.yaml"), "--backend", "singular", "-q"],
                         env=env, cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 4, out.stderr  # the fake printed no result
    cas, grandchild = map(int, (tmp_path / "pids").read_text().split())
    time.sleep(0.2)
    assert not _alive(cas) and not _alive(grandchild)
    assert list((tmp_path / "tmp").iterdir()) == []


# the fake CAS forks a helper in its group and a grandchild that leaves it with setsid,
# each carrying a marker in its command line, then hangs
MARKED_CAS = VERSION + """\
import os, subprocess, sys, time
marker = os.environ["FAKE_MARKER"]
sleep = [sys.executable, "-c", "import time; time.sleep(300)", marker]
subprocess.Popen(sleep)
setsid = subprocess.Popen(sleep, start_new_session=True)
with open(os.environ["FAKE_PIDS"], "w") as f:
    f.write(f"{os.getpid()} {setsid.pid}\\n")
time.sleep(300)
"""

# run_program from a worker thread (as a Dask worker or an API user's thread would)
THREAD_DRIVER = """\
import sys, threading
from singcheck.elimination.cas.process import run_program
worker = threading.Thread(target=run_program, args=(sys.argv[1:], 600))
worker.start()
worker.join()
"""


def _marked(marker: str) -> list[int]:
    """The live processes whose command line holds ``marker`` (scanning /proc)."""
    out = []
    for name in os.listdir("/proc"):
        if name.isdigit() and _alive(int(name)):
            try:
                with open(f"/proc/{name}/cmdline", "rb") as f:
                    if marker.encode() in f.read():
                        out.append(int(name))
            except OSError:
                pass
    return out


@pytest.mark.parametrize("caller", ["cli", "thread"])
def test_a_sigkilled_singcheck_leaves_no_cas_process(tmp_path, caller):
    """SIGKILL of singcheck cannot be handled; the guard the kernel signals
    (PR_SET_PDEATHSIG) kills the CAS, its helper and its setsid'd grandchild, and (L1)
    removes the CAS's $TMPDIR/singcheck-* directory, which singcheck no longer can."""
    marker = str(tmp_path)  # in the guard's, the fake's and its children's command lines
    env = {**_fake_env(tmp_path, hang=True), "FAKE_MARKER": marker}
    fake_cas(tmp_path, MARKED_CAS)
    if caller == "cli":
        argv = [sys.executable, "-m", "singcheck", "run", ORTHO,
                str(TRAJECTORIES / "heart1.yaml"), "--backend", "singular", "-q"]
    else:
        argv = [sys.executable, "-c", THREAD_DRIVER, str(tmp_path / "bin" / "Singular")]
    proc = subprocess.Popen(argv, env=env, cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    try:
        cas, grandchild = _pids_written(tmp_path / "pids", proc)
        deadline = time.monotonic() + 10
        while len(_marked(marker)) < 4:  # the guard, the fake, its helper, its grandchild
            assert time.monotonic() < deadline, _marked(marker)
            time.sleep(0.05)
        assert os.getsid(grandchild) == grandchild != os.getsid(cas)
        proc.kill()
        proc.wait()
        deadline = time.monotonic() + 5
        while _marked(marker):
            assert time.monotonic() < deadline, f"survived SIGKILL: {_marked(marker)}"
            time.sleep(0.05)
        if caller == "cli":
            while list((tmp_path / "tmp").iterdir()):
                assert time.monotonic() < deadline, list((tmp_path / "tmp").iterdir())
                time.sleep(0.05)
    finally:  # never leave a process behind, even when the test fails
        proc.kill()
        proc.wait()
        for pid in _marked(marker):
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)


# -- memory: each CAS process runs under an address-space bound ---------------------------

# asks for 8 GiB of address space (malloc, untouched: it costs no memory when granted)
GREEDY_CAS = VERSION + """\
import ctypes, sys
malloc = ctypes.CDLL(None).malloc
malloc.restype = ctypes.c_void_p
if not malloc(ctypes.c_size_t(8 << 30)):
    sys.exit("   ? error: no more memory")  # what Singular prints
print("granted")
"""


@pytest.mark.parametrize("limit, code, phrase", [
    ("256M", 4, "Singular ran out of memory under the bound of 256 MiB per CAS process"),
    ("none", 4, "0 'begin' markers"),  # no bound: granted, then no result
])
def test_a_cas_over_its_memory_bound_is_a_one_line_backend_error(tmp_path, limit, code,
                                                                 phrase):
    env = {**_fake_env(tmp_path, hang=False), "SINGCHECK_MEMORY_LIMIT": limit}
    fake_cas(tmp_path, GREEDY_CAS)
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", ORTHO,
                          str(TRAJECTORIES / "heart1.yaml"), "--backend", "singular", "-q"],
                         env=env, cwd=ROOT, capture_output=True, text=True, timeout=120)
    one_line_error(out.returncode, out.stderr, code, phrase)


def test_a_bad_memory_bound_is_a_usage_error(tmp_path):
    env = {**_fake_env(tmp_path, hang=False), "SINGCHECK_MEMORY_LIMIT": "lots"}
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", ORTHO,
                          str(TRAJECTORIES / "heart1.yaml"), "--backend", "singular", "-q"],
                         env=env, cwd=ROOT, capture_output=True, text=True, timeout=120)
    one_line_error(out.returncode, out.stderr, 2, "SINGCHECK_MEMORY_LIMIT='lots'")


# in-process backends run in a forked child, under the same bounds


def _greedy_eliminate(self, request):
    """Asks for 8 GiB of address space (untouched: free when granted), then hangs."""
    import ctypes

    malloc = ctypes.CDLL(None).malloc
    malloc.restype = ctypes.c_void_p
    if not malloc(ctypes.c_size_t(8 << 30)):
        raise MemoryError
    time.sleep(300)


def _aborting_eliminate(self, request):
    """Dies the way GMP does when an allocation fails."""
    os.write(2, b"GNU MP: Cannot allocate memory (size=4294967296)\n")
    os.abort()


def _endless_eliminate(self, request):
    while True:  # one long call that no checkpoint interrupts
        sum(range(10_000))


@pytest.mark.parametrize("backend", ["flint", "sympy"])
@pytest.mark.parametrize("eliminate, env, code, phrase", [
    (_endless_eliminate, {}, 3, "unknown: time limit (1 s, --timeout): the {} backend did "
                                "not finish and was stopped"),
    (_greedy_eliminate, {"SINGCHECK_MEMORY_LIMIT": "256M"}, 4,
     "the {} backend ran out of memory under the bound of 256 MiB"),
    (_aborting_eliminate, {}, 4, "the {} backend died of SIGABRT under the bound of"),
])
def test_in_process_projection_is_bounded_in_time_and_memory(
        tmp_path, monkeypatch, capsys, cache_env, backend, eliminate, env, code, phrase):
    from singcheck.elimination.cas import flint_backend, sympy_backend

    for cls in (flint_backend.FlintBackend, sympy_backend.SympyBackend):
        monkeypatch.setattr(cls, "eliminate", eliminate)  # the forked child inherits it
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    start = time.monotonic()
    code_, _, err = run_cli(monkeypatch, capsys, "run", ORTHO,
                            str(TRAJECTORIES / "heart1.yaml"), "--backend", backend,
                            "--timeout", "1", "-q")
    one_line_error(code_, err, code, phrase.format(backend))
    assert time.monotonic() - start < 20


FORKED_DRIVER = """\
import os, sys, time
from singcheck.elimination.cas.isolated import run_forked

def hang(path):
    with open(path, "w") as f:
        f.write(f"{os.getpid()}\\n")
    time.sleep(300)

run_forked(hang, sys.argv[1], 600, "hang")
"""


def test_the_forked_child_dies_with_a_sigkilled_singcheck(tmp_path):
    pid_file = tmp_path / "pid"
    proc = subprocess.Popen([sys.executable, "-c", FORKED_DRIVER, str(pid_file)], cwd=ROOT,
                            env={**os.environ, "PYTHONPATH": str(ROOT)})
    child = None
    try:
        (child,) = _pids_written(pid_file, proc)
        assert _alive(child)
        proc.kill()
        proc.wait()
        deadline = time.monotonic() + 5
        while _alive(child):
            assert time.monotonic() < deadline, "the forked child survived SIGKILL"
            time.sleep(0.05)
    finally:
        proc.kill()
        proc.wait()
        if child and _alive(child):
            os.kill(child, signal.SIGKILL)


def test_without_a_memory_bound_the_greedy_child_gets_its_memory(monkeypatch):
    """The other side of the test above: the 8 GiB are granted without the bound (so it
    is the bound that refused them), and the child then runs into the time limit."""
    from singcheck.budget import TimeLimitExceeded
    from singcheck.elimination.cas.isolated import run_forked

    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "none")
    with pytest.raises(TimeLimitExceeded):
        run_forked(lambda r: _greedy_eliminate(None, r), None, 1.0, "greedy")


# -- in-process when an a-priori bound proves the elimination small ------------------------


def _one_norm_bits(p) -> int:
    """Bits of the 1-norm of p's primitive integer multiple, from its coefficients."""
    coeffs = [Fraction(int(c.p), int(c.q)) for c in p.coeffs()]
    den = 1
    for c in coeffs:
        den = den * c.denominator // math.gcd(den, c.denominator)
    ints = [int(c * den) for c in coeffs]
    g = math.gcd(*ints)
    return sum(abs(x) // g for x in ints).bit_length()


def _dense(ctx, box, bits, seed, extra=None):
    import itertools
    import random

    rng = random.Random(seed)
    terms = {e: rng.randrange(-2**bits, 2**bits)
             for e in itertools.product(*(range(d + 1) for d in box))}
    return ctx.from_dict({**terms, **(extra or {})})


def _chains():
    """(g, legs) of the bundled robots' projections (prismatic and revolute legs, √3) and
    of a dense random chain, whose intermediates fill their degree boxes."""
    from flint import fmpq_mpoly_ctx

    from singcheck.elimination.projection import singularity_surface_request
    from singcheck.elimination.requests import leg_structure
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    out = []
    for name in ("3-prr", "five-bar", "orthoglide", "linear-delta", "skew-biglide"):
        model = build_model(load_robot(ROBOTS / f"{name}.yaml"))
        out.append((name, *leg_structure(singularity_surface_request(model))))
    ctx = fmpq_mpoly_ctx.get(("x", "y", "u", "v"), "lex")
    g = _dense(ctx, (6, 6, 3, 2), 60, 1)
    legs = [("u", _dense(ctx, (2, 2, 0, 0), 20, 2, {(0, 0, 2, 0): 1})),
            ("v", _dense(ctx, (1, 2, 0, 0), 20, 3, {(0, 0, 0, 2): 3}))]
    out.append(("dense", g, legs))
    return out


@pytest.mark.parametrize("name, g, legs", _chains(), ids=lambda x: x if isinstance(x, str) else "")
def test_the_norm_chain_bound_holds_for_every_polynomial_the_chain_forms(
        monkeypatch, name, g, legs):
    """Every resultant or revolute norm the chain forms (what it hands to squarefree_part)
    and every squarefree part has at most the bound's terms and coefficient bits (the
    1-norm of its primitive integer multiple, recomputed here)."""
    from singcheck.elimination import requests

    terms, bits = requests.norm_chain_bound(g, legs)
    seen = []
    original = requests.squarefree_part

    def recording(p):
        out = original(p)
        seen.extend([p, out])
        return out

    monkeypatch.setattr(requests, "squarefree_part", recording)
    seen.append(requests.norm_chain(g, legs))
    assert seen
    for p in seen:
        assert len(p) <= terms, name
        assert _one_norm_bits(p) <= bits, name
    if name == "dense":  # a dense chain fills its box: the bound is not vacuous
        assert max(len(p) for p in seen) * 2 > terms


def test_a_request_proven_small_runs_without_a_fork_and_any_other_in_one(monkeypatch):
    """The 3-PRR's ξ (proven at most 714,425 terms of 292 bits: 1.1 GB by the memory
    bound's count) is computed in this process with the default --timeout and an 8 GiB
    bound; with --timeout below a minute, or a memory bound too small for its proof, in
    a forked child; the same ξ either way (24,389 terms), and its re-check passes."""
    from singcheck.elimination.cas import get_backend
    from singcheck.elimination.projection import project_robot
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    model = build_model(load_robot(ROBOTS / "3-prr.yaml"))
    forks = []
    real_fork = os.fork

    def counting_fork():
        forks.append(1)
        return real_fork()

    monkeypatch.setattr(os, "fork", counting_fork)
    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "8G")
    xi = project_robot(model, get_backend("flint")).singularity_surface
    assert not forks
    assert len(xi) == 24389
    assert project_robot(model, get_backend("flint", timeout=5)).singularity_surface == xi
    assert len(forks) == 1  # the flint result is the norm: the re-check forks no other
    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "512M")
    assert project_robot(model, get_backend("flint")).singularity_surface == xi
    assert len(forks) == 2


# -- 8. -o targets ------------------------------------------------------------------------


def _run_to(monkeypatch, capsys, target: str) -> tuple[int, str, str]:
    return run_cli(monkeypatch, capsys, "run", ORTHO, str(TRAJECTORIES / "heart2.yaml"),
                   "-q", "--backend", "flint", "--format", "json", "-o", target)


def test_output_to_a_fifo_is_written_in_place(tmp_path, monkeypatch, capsys, cache_env):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    code, _, err = _run_to(monkeypatch, capsys, str(fifo))
    reader.join(timeout=60)
    assert code == 0, err
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert json.loads(got[0])["trajectories"][0]["verdict"] == "singularity-free"


def test_output_through_a_symlink_writes_its_target(tmp_path, monkeypatch, capsys, cache_env):
    real = tmp_path / "real.json"
    real.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    code, _, err = _run_to(monkeypatch, capsys, str(link))
    assert code == 0, err
    assert link.is_symlink() and json.loads(real.read_text())["exit_code"] == 0


def test_output_to_a_character_device_is_not_replaced(tmp_path, monkeypatch, capsys,
                                                      cache_env):
    if os.geteuid() == 0:  # a private copy of /dev/null, so a bug cannot harm the system's
        device = tmp_path / "null"
        os.mknod(device, stat.S_IFCHR | 0o666, os.stat("/dev/null").st_rdev)
    else:  # without root, /dev/null itself cannot be replaced anyway
        device = Path("/dev/null")
    code, out, err = _run_to(monkeypatch, capsys, str(device))
    assert code == 0, err
    assert stat.S_ISCHR(os.lstat(device).st_mode) and out == ""
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".null")] == []


def test_output_to_dev_full_reports_the_write_error(monkeypatch, capsys, cache_env):
    code, _, err = _run_to(monkeypatch, capsys, "/dev/full")
    one_line_error(code, err, 2, "No space left on device")
    assert stat.S_ISCHR(os.lstat("/dev/full").st_mode)


def test_output_into_a_missing_directory_is_an_error(tmp_path, monkeypatch, capsys, cache_env):
    target = tmp_path / "missing" / "out.json"
    code, _, err = _run_to(monkeypatch, capsys, str(target))
    one_line_error(code, err, 2, "does not exist")
    assert not (tmp_path / "missing").exists()


# -- 9. missing extras --------------------------------------------------------------------


@pytest.mark.parametrize("args, extra", [
    (("plot", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "--out", "figs"), "plot"),
    (("plot", str(ROBOTS / "skew-biglide.yaml"), "--regions", "workspace", "--out", "f"),
     "plot"),
    (("plot", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "--format", "html", "--out", "f"),
     "html"),
    (("run", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "--plot", "figs"), "plot"),
])
def test_plot_without_its_extra_names_the_extra(tmp_path, monkeypatch, capsys, args, extra):
    import importlib.util

    real = importlib.util.find_spec

    def find_spec(name, *a, **k):
        if name.split(".")[0] in ("matplotlib", "skimage", "plotly"):
            return None
        return real(name, *a, **k)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(monkeypatch, capsys, *args)
    one_line_error(code, err, 2, f"pip install 'singcheck[{extra}]'")
    assert not (tmp_path / "figs").exists()


# -- 10. undecided boxes when no mode is feasible -----------------------------------------


def test_undecided_boxes_and_a_known_root_are_kept_when_no_mode_is_feasible(
        tmp_path, monkeypatch, capsys, cache_env):
    """On the biglide (ξ vanishes where y = 0) the path y = t·sin t touches y = 0 at t = 0
    without crossing, and x = 10 puts it outside every joint's limits: μ has a double
    root at t = 0, exactly known.  Every mode is proven infeasible, so μ is not looked
    at: the report claims no candidate list (root isolation "none"), rather than a
    list with the root at 0 dropped.  Isolated, the root is kept with its boxes."""
    spec = trajectory(tmp_path, {"x": "10", "y": "t*sin(t)"}, "-1, 1")
    code, out, err = run_cli(monkeypatch, capsys, "run", BIGLIDE, spec, "-q", "--backend",
                             "flint", "--format", "json")
    assert code == 1, err
    (doc,) = json.loads(out)["trajectories"]
    assert doc["verdict"] == "infeasible"
    assert "outside" in doc["reason"]
    assert doc["root_isolation"].startswith("none")
    assert doc["candidates"] == [] and doc["undecided"] == []
    from flint import fmpq_mpoly_ctx

    from singcheck.algebra.trig import LinearInPi, TimeRange
    from singcheck.roots.isolation import isolate_real_roots

    t, s, c = fmpq_mpoly_ctx.get(("t", "s", "c"), "lex").gens()
    iso = isolate_real_roots(t * s, TimeRange(LinearInPi(-1), LinearInPi(1)), 1e-9)
    assert [(float(r.t.lower()), float(r.t.upper())) for r in iso.roots] == [(0.0, 0.0)]
    # an undecided box is kept when no mode is feasible (all([]) is true: it was dropped)
    from types import SimpleNamespace

    from singcheck.certify.classification import _clear_undecided
    from singcheck.certify.working_modes import INFEASIBLE

    modes = [SimpleNamespace(status=INFEASIBLE, label=label) for label in ("++", "+-")]
    assert _clear_undecided(None, modes, SimpleNamespace(t=None)) is False


# -- 3. costly small specs: refused up front, or stopped at the time limit --------------


def test_a_path_whose_mu_would_explode_is_refused_up_front(tmp_path, monkeypatch, capsys,
                                                           cache_env):
    """Refused before composing; in a batch that is this trajectory's result (verdict
    error, kind spec), the others still complete, and the exit status is 2."""
    spec = trajectory(tmp_path, {"x": "(sin(t)+cos(t)+t)^64", "y": "0", "z": "1"})
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "run", ORTHO, spec,
                             str(TRAJECTORIES / "heart2.yaml"), "-q", "--backend", "flint",
                             "--format", "json", "--engine", "exact")
    assert code == 2 and "Traceback" not in err, err
    costly, heart2 = json.loads(out)["trajectories"]
    assert costly["verdict"] == "error" and costly["error"]["kind"] == "spec"
    assert "too costly" in costly["reason"] and heart2["verdict"] == "singularity-free"
    assert time.monotonic() - start < 30


def test_mu_size_bound_holds_for_a_composed_path(orthoglide_projection):
    """The a-priori bound is an upper bound of what composition gives (checked on a path
    mixing t, sin and cos, composed here)."""
    from singcheck.certify.path import compose_pose, mu_size_bound
    from singcheck.spec.grammar import compile_trajectory_coordinate, parse

    phi = tuple(compile_trajectory_coordinate(parse(text), "t", {}) for text in
                ("(sin(t) + cos(t) + t)^3", "t^2 - sin(2*t)", "1"))
    xi = orthoglide_projection.singularity_surface
    deg_t, deg_sc, terms = mu_size_bound(xi, phi, ("x", "y", "z"))
    mu = compose_pose(xi, phi, ("x", "y", "z"))
    assert len(mu) <= terms
    assert mu.degrees()[0] <= deg_t and mu.degrees()[1] + mu.degrees()[2] <= deg_sc


def test_the_crude_composition_bound_is_above_the_estimate_and_the_result(
        orthoglide_projection):
    """The crude bound that lets μ skip the exact estimate is above it (work and both
    degrees) and above what composing gives, on paths mixing t, sin and cos; then
    substituting a constant coordinate first gives the same μ."""
    from singcheck.algebra.composition import composition_work, crude_work
    from singcheck.certify.path import _compose_mu, _pose_args, compose_pose
    from singcheck.spec.grammar import compile_trajectory_coordinate, parse

    xi = orthoglide_projection.surface_on_circles
    for texts in (("(sin(t) + cos(t) + t)^3", "t^2 - sin(2*t)", "1"),
                  ("8/7*sin(t)^3", "13/14*cos(t) - 5/14*cos(2*t)", "1"),
                  ("sin(3*t)/2", "t/5", "cos(t)")):
        phi = tuple(compile_trajectory_coordinate(parse(text), "t", {}) for text in texts)
        args = _pose_args(xi, phi, ("x", "y", "z"))[1]
        crude, exact = crude_work(xi, args), composition_work(xi, args)
        assert all(c >= e for c, e in zip(crude, exact, strict=True)), (texts, crude, exact)
        mu = _compose_mu(xi, phi, ("x", "y", "z"), None)
        assert mu.degrees()[0] <= crude[1] and mu.degrees()[1] + mu.degrees()[2] <= crude[2]
        assert mu == compose_pose(xi, phi, ("x", "y", "z"))  # no shortcut: the same μ


@pytest.mark.parametrize("robot, pose, rng", [
    # cos(50*t): degree 800 in tan(t/2), the most the root-isolation bound admits
    (ORTHO, {"x": "3*sin(t) + cos(50*t)", "y": "0", "z": "1"}, "0, 1"),
    (BIGLIDE, {"x": "sin(100*t)", "y": "t"}, "0, 1"),
    (ORTHO, {"x": "sin(t)", "y": "cos(t)", "z": "t/20"}, "-1000000, 1000000"),
    # found by the fuzz campaign: 10^5 periods of the half-angle roots ran 286 s
    (str(ROBOTS / "skew-biglide.yaml"), {"x": "-sin(t)", "y": "-sin(t)"}, "-27/2, 1000000"),
])
def test_costly_paths_stop_at_the_time_limit(tmp_path, cache_env, robot, pose, rng):
    from singcheck import api

    machine = api.load_robot(robot, backend="flint")
    spec = api.load_trajectory(trajectory(tmp_path, pose, rng), machine)
    start = time.monotonic()
    report = api.check(machine, spec, time_limit=3)  # admitted: within every a-priori bound
    elapsed = time.monotonic() - start
    assert elapsed < 3 + 10, elapsed
    if report.verdict == "unknown":
        assert "time limit" in report.reason
    else:  # finished in time: then it must be a proven answer
        assert report.certificate is not None


@pytest.mark.parametrize("robot, pose", [
    (ORTHO, {"x": "3*sin(t) + cos(50*t)", "y": "0", "z": "1"}),
    (BIGLIDE, {"x": "sin(100*t)", "y": "t"}),
    (BIGLIDE, {"x": "sin(100*t)", "y": "t + 1/1000"}),
])
def test_costly_paths_end_unknown_at_the_command_lines_time_limit(
        tmp_path, monkeypatch, capsys, cache_env, robot, pose):
    spec = trajectory(tmp_path, pose)
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "run", robot, spec, "-q", "--backend",
                             "flint", "--time-limit", "3", "--format", "json")
    assert code in (0, 1, 2, 3), err
    assert "Traceback" not in err
    (doc,) = json.loads(out)["trajectories"]
    assert code != 2, doc  # admitted: within every a-priori bound
    if code == 3:  # stopped; or decided in time (the biglide meets y = 0 at t = 0 exactly)
        assert doc["verdict"] == "unknown" and "time limit" in doc["reason"]
    assert time.monotonic() - start < 3 + 15


def test_near_double_roots_of_huge_size_are_separated():
    """x² + Bx + C with roots a and a + 2⁻¹⁰, a = -2²⁴⁵ (what the workspace decomposition
    of a robot with the constant (2147483648-364349)^8 meets): the isolating intervals
    are halved until they are apart, however many rounds that takes (it took more than
    the former cap of 200)."""
    from flint import fmpq, fmpq_poly

    from singcheck.spaces.cad import separated_roots

    a = fmpq(-(2 ** 245))
    b = a + fmpq(1, 2 ** 10)
    roots = separated_roots(fmpq_poly([a * b, -(a + b), 1]))
    assert len(roots) == 2 and roots[0].hi < roots[1].lo
    assert roots[0].lo <= a <= roots[0].hi and roots[1].lo <= b <= roots[1].hi


#: a biglide whose second rod is (2147483648-364349)^8 long (finding 3: its workspace
#: decomposition hung); tests/test_budgets.py bounds that decomposition's time
BIG_CONSTANT = """\
name: big
joints: [p, q]
pose: [x, y]
constraints:
  - (x - p)^2 + y^2 - 4
  - (x - q)^2 + y^2 - (2147483648-364349)^8
joint_limits: {p: [-4, 4], q: [-4, 4]}
"""


def test_a_robot_with_a_huge_constant_is_decided(tmp_path, monkeypatch, capsys, cache_env):
    robot = tmp_path / "big.yaml"
    robot.write_text(BIG_CONSTANT)
    spec = trajectory(tmp_path, {"x": "t", "y": "1/2 + t/4"})
    code, out, err = run_cli(monkeypatch, capsys, "run", str(robot), spec, "-q", "--backend",
                             "flint", "--format", "json")
    assert code == 1 and "Traceback" not in err, err
    (doc,) = json.loads(out)["trajectories"]
    # q = x ± √(C - y²) with C ≈ 2^247: far outside [-4, 4] from the start
    assert doc["verdict"] == "infeasible" and "q is outside [-4, 4]" in doc["reason"]


# -- found by the fuzz campaign -------------------------------------------------------------


def test_a_triple_root_at_t_0_of_the_half_angle_polynomial(tmp_path, monkeypatch, capsys,
                                                           cache_env):
    """On the biglide (ξ vanishes where y = 0), y = (9/14)·sin(t)³ gives M(u) = c·u³,
    which deflates to a root v = 0 of N(v) = c·v: Arb's cube root of 0 is NaN, which gave
    exit 70.  The roots are t = kπ, exactly: here 0, π and 2π."""
    import math

    spec = trajectory(tmp_path, {"x": "2*sin(2*t) + cos(t)", "y": "sin(t)^3 - 5/14*sin(t)^3"},
                      "-45/54, 2*pi")
    code, out, err = run_cli(monkeypatch, capsys, "run", BIGLIDE, spec, "-q", "--backend",
                             "flint", "--format", "json")
    assert code in (0, 1, 3) and "Traceback" not in err, err
    (doc,) = json.loads(out)["trajectories"]
    intervals = [c["t_interval"] for c in doc["candidates"]]
    if doc["verdict"] == "infeasible":  # μ is not looked at then: isolate it here
        from fractions import Fraction

        from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange
        from singcheck.roots.isolation import isolate_real_roots

        y = 9 * TRIG.gens()[1] ** 3 / 14  # the path's y; ξ of the biglide is y·(…)
        iso = isolate_real_roots(y, TimeRange(LinearInPi(Fraction(-45, 54)),
                                              LinearInPi(Fraction(0), Fraction(2))), 1e-9)
        intervals = [(float(r.t.lower()), float(r.t.upper())) for r in iso.roots]
    assert len(intervals) == 3
    for (lo, hi), root in zip(intervals, (0.0, math.pi, 2 * math.pi), strict=True):
        assert lo <= root <= hi and hi - lo < 1e-8


def test_an_angle_with_a_huge_multiple_of_t_is_refused(tmp_path, monkeypatch, capsys,
                                                       cache_env):
    """Found by the campaign: the 3-PRR's angle phi = -t/1e-49 (an integer multiple of t
    of 50 digits) reached FLINT's Chebyshev polynomial of that degree (OverflowError, an
    internal error). It gets the bound of sin(k*t) in a coordinate: exit 2, one line."""
    spec = trajectory(tmp_path, {"x": "1", "y": "0",
                                 "phi": "-t / 0." + "0" * 48 + "1"})
    code, out, err = run_cli(monkeypatch, capsys, "run", str(ROBOTS / "3-prr.yaml"), spec,
                             "-q", "--backend", "flint", "--format", "json")
    assert code == 2, err
    (doc,) = json.loads(out)["trajectories"]
    assert doc["verdict"] == "error"
    assert "multiple of t above 256" in doc["reason"] and "pose.phi" in doc["reason"]
    assert "OverflowError" not in out + err


# -- second round (issue 31) ---------------------------------------------------------------

RPR3 = str(ROBOTS / "3-rpr.yaml")


@pytest.mark.parametrize("form", ["csv-linear", "csv-cubic", "segments"])
def test_a_3rpr_path_of_pieces_crossing_at_its_join_is_decided(tmp_path, monkeypatch, capsys,
                                                               cache_env, form):
    """E1: the join test of the region statement got a surface in the 3-RPR's path ring
    (t, s, c and phi's cos and sin) and unpacked its exponents as three (exit 70).  Both
    pieces meet r1 = 1/2 exactly at the join t = 1 (x, y = 1/2, 0): one crossing."""
    if form == "segments":
        path = tmp_path / "e1.yaml"
        path.write_text("name: e1\nparameter: t\nsegments:\n"
                        "  - range: [0, 1]\n    pose: {x: 1 - t/2, y: 1 - t, phi: t/10}\n"
                        "  - range: [1, 2]\n    pose: {x: t/2, y: t - 1, phi: t/10}\n")
        extra = []
    else:
        path = tmp_path / "e1.csv"
        path.write_text("t,x,y,phi\n0,1,1,0\n1,0.5,0,0.1\n2,1,1,0.2\n")
        extra = ["--interpolation", form.split("-")[1]]
    code, out, err = run_cli(monkeypatch, capsys, "run", RPR3, str(path), "-q", "--backend",
                             "flint", "--format", "json", *extra)
    assert code == 0, err
    (doc,) = json.loads(out)["trajectories"]
    assert doc["verdict"] == "singularity-free", doc
    crossings = doc["workspace"]["crossings"]
    assert [c["surfaces"] for c in crossings] == [["r1 = 1/2 (min)"]], crossings
    assert crossings[0]["t_interval"] == [1.0, 1.0]


def test_the_join_test_is_undecided_outside_the_trig_ring():
    """sum_is_zero is exact on Q[t, sin t, cos t] only: a polynomial of a path ring with an
    angle's variables is undecided (None), not an unpacking error."""
    from singcheck.algebra.radicals import path_ring
    from singcheck.algebra.trig import LinearInPi
    from singcheck.algebra.trig_values import sum_is_zero

    ring = path_ring([], [("cos(phi)", "sin(phi)")])
    t, s, c, cphi, sphi = ring.gens()
    assert sum_is_zero([(cphi ** 2 + sphi ** 2 - 1, LinearInPi(Fraction(1)))]) is None
    assert sum_is_zero([(t * 0, LinearInPi(Fraction(1)))]) is None


HOSTILE_NAMES = ["../escape", "/tmp/abs", "..", ".hidden", "a\0b", "L" * 3000,
                 "héllo δ/ψ", "\u202e", "a/b", "a_b", "A_B", "$^$"]


def test_every_hostile_name_becomes_a_file_name_inside_its_directory(tmp_path):
    """S1: one helper makes every file name derived from input; each stays in its
    directory, is a name the file system takes, and two names never share a stem."""
    from singcheck.atomic import MAX_STEM_BYTES, safe_file_name

    taken: set[str] = set()
    stems = [safe_file_name(name, taken) for name in HOSTILE_NAMES]
    assert len({s.casefold() for s in stems}) == len(stems), stems
    for stem in stems:
        assert "/" not in stem and "\0" not in stem and not stem.startswith("."), stem
        assert len(stem.encode("utf-8")) <= MAX_STEM_BYTES + 4
        target = (tmp_path / f"{stem}-jointspace.svg")
        assert target.resolve().parent == tmp_path.resolve()
        target.write_text("x")  # the file system takes it
    assert safe_file_name("héllo δ") == "héllo_δ"
    long_a, long_b = safe_file_name("L" * 3000), safe_file_name("L" * 2999 + "M")
    assert long_a != long_b
    assert safe_file_name("a/b", set()) == safe_file_name("a/b", set())  # stable


@pytest.mark.slow
def test_figures_of_hostile_names_stay_in_the_figure_directory(tmp_path, monkeypatch, capsys,
                                                               cache_env):
    """S1: ``run --plot DIR`` and ``plot --out DIR`` wrote ``name: ../escape`` beside DIR
    and an absolute name at that path; '$^$' in a title stopped matplotlib (exit 70).
    Now every figure is in DIR, and a/b and a_b both keep their figures."""
    names = ["../escape", str(tmp_path / "abs"), "a/b", "a_b", "$^$"]
    docs = [f'name: {json.dumps(n)}\nparameter: t\nrange: [0, 1]\npose: {{x: t, y: 1}}\n'
            for n in names]
    spec = tmp_path / "hostile.yaml"
    spec.write_text("---\n".join(docs))
    figures = tmp_path / "deep" / "figs"
    code, _, err = run_cli(monkeypatch, capsys, "run", BIGLIDE, str(spec), "-q", "--backend",
                           "flint", "--plot", str(figures))
    assert code == 0, err
    outside = [p for p in tmp_path.rglob("*") if p.is_file()
               and figures not in p.parents and p != spec and cache_env not in p.parents
               and "config" not in p.parts]
    assert outside == []
    stems = {p.name.rsplit("-", 1)[0] for p in figures.iterdir()}
    assert len(stems) == len(names) and {"a_b", "a_b-2", "_escape"} <= stems, stems
    assert len(list(figures.iterdir())) == 10 * len(names)
    # plot --out alike, one file per trajectory
    files = [tmp_path / f"p{i}.yaml" for i in range(3)]
    for file, doc in zip(files, docs, strict=False):
        file.write_text(doc)
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "singcheck", "plot", BIGLIDE, *map(str, files),
                           "--out", str(out), "-q", "--backend", "flint"],
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 30 and all(Path(line).parent == out for line in lines), lines
    assert len(list(out.iterdir())) == 30


@pytest.mark.parametrize("row, phrase", [
    ("9" * 308 + ",0.9,1.1,1", "t: the number 9999999999…999999 (308 characters) is too "
                               "large (at most 512 bits)"),
    ("1,0.9,1.1," + "1" * 200, "z: the number"),
    ("1,1/" + "7" * 200 + ",1.1,1", "x: the number"),
    ("1,1e-400,1.1,1", "x: the number 1e-400 is too large"),
    ("1/0,0.9,1.1,1", "t: '1/0' divides by zero"),
])
def test_csv_cells_obey_the_bounds_of_spec_numbers(tmp_path, monkeypatch, capsys, cache_env,
                                                   row, phrase):
    """E2: a CSV time cell of 308 digits overflowed a float in the cover of one period
    (exit 70); the same number as a YAML range end was a clean exit 2.  A cell now goes
    through the spec grammar's number bound, before its value is built."""
    path = tmp_path / "e2.csv"
    path.write_text(f"t,x,y,z\n0,0.25,0.6,1\n{row}\n")
    code, _, err = run_cli(monkeypatch, capsys, "run", ORTHO, str(path), "-q", "--backend",
                           "flint")
    one_line_error(code, err, 2, phrase)
    assert "e2.csv:3:" in err


def _long_csv(path: Path, rows: int = 5000) -> Path:
    lines = ["t,x,y,z"] + [f"{i},{0.5 + 0.3 * math.cos(i / 50):.4f},"
                           f"{0.5 + 0.3 * math.sin(i / 50):.4f},1" for i in range(rows)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_the_time_limit_counts_from_reading_the_document(tmp_path, monkeypatch, capsys,
                                                          cache_env):
    """H1: a 5,000-row CSV's exact cubic spline was solved while the document was parsed,
    before any limit applied (11 s under --time-limit 2).  Parsing is now the first stage
    of the trajectory's check: unknown at the limit, within a second."""
    path = _long_csv(tmp_path / "long.csv")
    run_cli(monkeypatch, capsys, "run", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "-q",
            "--backend", "flint", "--no-regions")  # the projection, cached: not timed
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "run", ORTHO, str(path), "-q", "--backend",
                             "flint", "--time-limit", "2", "--format", "json")
    elapsed = time.monotonic() - start
    assert code == 3, err
    (doc,) = json.loads(out)["trajectories"]
    assert doc["verdict"] == "unknown" and "time limit (2 s)" in doc["reason"], doc
    assert elapsed < 3.0, elapsed


def test_a_document_parsed_by_a_worker_counts_its_parsing(tmp_path, orthoglide_projection):
    """The same for a document parsed by a batch's worker (check_item), and the parsing's
    seconds count against the check that follows it."""
    from singcheck import api
    from singcheck.spec.files import read_documents

    model = orthoglide_projection.model
    orthoglide_robot = api.Robot(model.spec, model, orthoglide_projection)
    (document,) = read_documents([str(_long_csv(tmp_path / "long.csv"))], "cubic")
    start = time.monotonic()
    doc = api.check_item(orthoglide_robot, document, time_limit=1.0, regions=False)
    assert time.monotonic() - start < 2.0
    assert doc["verdict"] == "unknown" and "while reading it" in doc["reason"], doc
    (short,) = read_documents([str(_long_csv(tmp_path / "short.csv", 300))], "cubic")
    parsed = api.parse_within(short, orthoglide_robot.spec, 100)
    assert parsed.spec is not None
    parsed.seconds = 100.0  # as if its parsing had taken the whole limit
    doc = api.check_item(orthoglide_robot, parsed, time_limit=100.0, regions=False)
    assert doc["verdict"] == "unknown" and doc["time_s"] >= 100, doc
    assert "time limit (100 s) reached" in doc["reason"], doc


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 0), (signal.SIGHUP, 0),
                                         (signal.SIGTERM, -signal.SIGTERM)])
def test_a_worker_signalled_while_starting_is_silent(tmp_path, sig, status):
    """J1: a worker signalled between its fork and its initializer (which sets its own
    handlers) ran the parent's handlers and printed 'Exception in initializer …
    KeyboardInterrupt'.  Workers are forked with the signals held, and the initializer
    releases them once its handlers are set: Ctrl-C and a hangup are ignored, SIGTERM
    ends the worker, silently."""
    from singcheck import api

    err = tmp_path / "stderr"
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)  # as singcheck's
    try:
        with api.held_signals():
            pid = os.fork()
            if pid == 0:  # the worker, signalled before its initializer runs
                try:
                    fd = os.open(err, os.O_WRONLY | os.O_CREAT)
                    os.dup2(fd, 2)
                    os.kill(os.getpid(), sig)
                    api._WORKER["parent"] = os.getppid()
                    api._worker_signals()
                    os._exit(0)
                except BaseException as e:  # the test fails: say why
                    os.write(2, f"{type(e).__name__}\n".encode())
                    os._exit(3)
    finally:
        signal.signal(signal.SIGTERM, previous)
    _, wait_status = os.waitpid(pid, 0)
    code = os.waitstatus_to_exitcode(wait_status)
    assert code == status, err.read_text()
    assert err.read_text() == ""


@pytest.mark.parametrize("address, phrase", [
    ("foo", "missing port number"),
    ("tcp://127.0.0.1", "missing port number"),
    ("http://x:y", "unknown address scheme 'http'"),
    ("tcp://h:0", "no port in 1-65535"),
])
def test_a_malformed_scheduler_address_is_a_usage_error_at_once(tmp_path, monkeypatch, capsys,
                                                                cache_env, address, phrase):
    """D1: a malformed --scheduler address gave exit 70, a ``Client.__del__`` traceback
    and a 60 s stall; it is refused before any work: exit 2, one line."""
    pytest.importorskip("distributed")
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "run", ORTHO, str(TRAJECTORIES / "heart1.yaml"),
                             "-q", "--backend", "flint", "--scheduler", address)
    one_line_error(code, err, 2, phrase)
    assert f"--scheduler {address}: not a scheduler address" in err and out == ""
    assert time.monotonic() - start < 5


def _address_space_of(limit: int):
    """A preexec_fn: the child (singcheck) runs under a hard RLIMIT_AS of ``limit``."""
    def set_limit():
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return set_limit


def test_a_hard_ulimit_v_bounds_the_cas_under_it(tmp_path):
    """F1: under ``ulimit -v`` below the default bound (half the machine's memory), the
    CAS's setrlimit could not raise the hard limit: Singular did not start ('not allowed
    to raise maximum limit'), flint's child 'exited with status 1'.  The bound is now
    set under the inherited limit, and a CAS over it says to raise ``ulimit -v``."""
    env = _fake_env(tmp_path, hang=False)
    env.pop("SINGCHECK_MEMORY_LIMIT", None)
    fake_cas(tmp_path, GREEDY_CAS)
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", ORTHO,
                          str(TRAJECTORIES / "heart1.yaml"), "--backend", "singular", "-q"],
                         env=env, cwd=ROOT, capture_output=True, text=True, timeout=120,
                         preexec_fn=_address_space_of(2 * 2**30))
    one_line_error(out.returncode, out.stderr, 4,
                   "Singular ran out of memory under the bound of 2 GiB (ulimit -v) per CAS "
                   "process; raise the address-space limit singcheck runs under (ulimit -v)")


def test_the_memory_bound_stays_under_the_inherited_limit(monkeypatch):
    from singcheck.elimination.cas import limits

    monkeypatch.setattr(limits, "inherited_limit", lambda: 3 * 2**30)
    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "8G")
    assert limits.memory_limit() == 3 * 2**30
    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "1G")
    assert limits.memory_limit() == 2**30
    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "none")
    assert limits.memory_limit() == 3 * 2**30  # none of ours: the inherited one holds
    assert "ulimit -v" in limits.raise_hint(3 * 2**30)
    monkeypatch.setattr(limits, "inherited_limit", lambda: 0)
    assert limits.memory_limit() == 0
    assert "SINGCHECK_MEMORY_LIMIT" in limits.raise_hint(2**30)


def test_output_to_a_fifo_nobody_reads_is_an_error_not_a_hang(tmp_path, monkeypatch, capsys,
                                                              cache_env):
    """H2: ``-o`` onto a FIFO with no reader blocked in open() for ever.  It is opened
    without blocking, retried for FIFO_WAIT seconds, then one line, exit 2."""
    from singcheck import atomic

    monkeypatch.setattr(atomic, "FIFO_WAIT", 0.5)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    start = time.monotonic()
    code, _, err = _run_to(monkeypatch, capsys, str(fifo))
    one_line_error(code, err, 2, "no process reads this FIFO (waited 0.5 s for one)")
    assert time.monotonic() - start < 10
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def _replay_header(case: Path) -> dict[str, str]:
    """The ``# key: value`` lines at the top of a corpus file (``#   …``: a line of the
    value above)."""
    header = {}
    for line in case.read_text().splitlines():
        if not line.startswith("# "):
            break
        if line.startswith("#   "):
            continue
        key, _, value = line[2:].partition(":")
        header[key.strip()] = value.strip()
    return header


CRASHES = [pytest.param(p, id=p.name, marks=[pytest.mark.slow] if "slow" in _replay_header(p)
                        else [])
           for p in sorted((ROOT / "tests" / "data" / "crashes").iterdir())
           if p.suffix in (".yaml", ".csv")]


@pytest.mark.parametrize("case", CRASHES)
def test_the_crash_corpus(tmp_path, monkeypatch, capsys, cache_env, case):
    """Every input that once crashed singcheck or ran past its time limit (the fuzz
    campaigns' and the hostile runs' findings, tests/data/crashes/) now ends with an
    exit status 0-3, no traceback, within its time limit, writing only where told.
    A case with ``# within: S`` (an overrun the campaign found) must end within S
    seconds past its ``--time-limit``, with a proven verdict or unknown (0, 1, 3)."""
    header = _replay_header(case)
    args = header.get("args", "").replace("{tmp}", str(tmp_path)).split()
    limit = float(args[args.index("--time-limit") + 1]) if "--time-limit" in args else 60
    robot = str(ROBOTS / f"{header['robot']}.yaml")
    from singcheck import api

    api.load_robot(robot, backend="flint")  # the projection, cached
    loading = []  # reading it back from the cache is not the trajectory's time either
    robot_from_spec = api.robot_from_spec

    def timed(*a, **k):
        began = time.monotonic()
        try:
            return robot_from_spec(*a, **k)
        finally:
            loading.append(time.monotonic() - began)

    monkeypatch.setattr(api, "robot_from_spec", timed)
    start = time.monotonic()
    code, _, err = run_cli(monkeypatch, capsys, "run", robot, str(case), "-q", "--backend",
                           "flint", "--format", "json", *args)
    elapsed = time.monotonic() - start - sum(loading)
    assert code in ((0, 1, 3) if "within" in header else (0, 1, 2, 3)), err
    assert "Traceback" not in err and "internal error" not in err, err
    # the region maps of a new subspace, at most
    within = float(header["within"].split()[0]) if "within" in header else 3
    assert elapsed < limit + within, elapsed
    written = [p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file()
               and cache_env not in p.parents and tmp_path / "config" not in p.parents]
    assert all(p.parts[0] == "figures" for p in written), written  # only where told


def test_plot_reads_a_trajectory_within_its_time_limit(tmp_path, cache_env):
    """H1 for ``plot``: the 5,000-row CSV's spline is read under --time-limit too: no
    figure for it, one line, exit 3, at the limit."""
    path = _long_csv(tmp_path / "long.csv")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    start = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "singcheck", "plot", ORTHO, str(path),
                           "--out", str(tmp_path / "out"), "-q", "--backend", "flint",
                           "--time-limit", "1"], env=env, cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 3, done.stderr
    assert "unknown: time limit (1 s) reached (while reading it" in done.stderr
    assert done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert time.monotonic() - start < 1 + 4  # the start-up, the cached projection


# -- a robot singular at every pose in some mode: the elimination ideal is zero --------------

_ONE_RAIL = """\
name: linear-delta-one-rail
joints: [r1, r2, r3]
pose: [x, y, z]
parameters: {{R: 1, l: 3/2, s3: sqrt(3)}}
constraints:
  - (x - R)^2 + y^2 + (z - r1)^2 - l^2
  - (x + R/2)^2 + (y + s3/2*R)^2 + (z - r2)^2 - l^2
  - (x + R/2)^2 + (y + s3/2*R)^2 + (z - r3)^2 - l^2
joint_limits: {{r1: [1/4, 3], r2: [1/4, 3], r3: {r3}}}
"""


def _one_rail_det(t, signs: str):
    """det A of the one-rail linear Delta along linear-delta-free.yaml at t in the mode
    ``signs`` (each leg's branch r = z ± √(l² - d²)), at 50 digits from the geometry:
    the rows (x - aᵢ, y - bᵢ, z - rᵢ), times 8."""
    import mpmath as mp

    mp.mp.dps = 50
    s3 = mp.sqrt(3)
    x, y, z = -mp.mpf(1) / 4 + t / 2, mp.mpf(1) / 4, t / 4
    rails = [(1, 0), (-mp.mpf(1) / 2, -s3 / 2), (-mp.mpf(1) / 2, -s3 / 2)]
    rows, joints = [], []
    for (a, b), sign in zip(rails, signs, strict=True):
        h = mp.sqrt(mp.mpf(9) / 4 - (x - a) ** 2 - (y - b) ** 2)
        r = z + h if sign == "+" else z - h
        joints.append(r)
        rows.append([x - a, y - b, z - r])
    return 8 * mp.det(mp.matrix(rows)), joints


@pytest.mark.parametrize("r3, verdict, mode", [("[1/4, 3]", "singular", "+++"),
                                              ("[-3, -1/4]", "singularity-free", "++-")])
def test_a_robot_singular_everywhere_in_some_mode_gets_a_verdict(tmp_path, r3, verdict, mode):
    """Legs 2 and 3 on one rail (the fuzz's mutation of the linear Delta, found on 16
    cores): whichever the pose, the modes with r2 = r3 are singular, so eliminating the
    joints leaves the zero ideal.  That was exit 4 ("came back empty"); the robot is
    well formed, and each path now gets its verdict per mode.  The oracle (50 digits):
    in the one feasible mode the joints stay inside the limits, and det A is 0 all along
    (r2 = r3) when both legs take the same branch, bounded away from 0 otherwise."""
    from singcheck import api

    robot_file = tmp_path / "one-rail.yaml"
    robot_file.write_text(_ONE_RAIL.format(r3=r3))
    robot = api.load_robot(robot_file, backend="flint")
    assert "whole workspace" in robot.projection.not_expanded
    report = api.check(robot, api.load_trajectory(TRAJECTORIES / "linear-delta-free.yaml",
                                                  robot), regions=False)
    assert report.verdict == verdict
    assert [m.label for m in report.working_modes if m.feasible] == [mode]
    lo, hi = (0.25, 3) if r3 == "[1/4, 3]" else (-3, -0.25)
    import mpmath as mp

    for k in range(11):
        det, (r1, r2, r3_) = _one_rail_det(mp.mpf(k) / 10, mode)
        assert 0.25 < r1 < 3 and 0.25 < r2 < 3 and lo < r3_ < hi
        assert abs(det) < mp.mpf(10) ** -40 if verdict == "singular" else abs(det) > 0.1
