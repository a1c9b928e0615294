"""Batches as CI jobs and shell pipelines run them (issue 15): streams in and out, one
bad path never sinks a batch, signals, and the crash that once lost a whole batch."""

from __future__ import annotations

import json
import subprocess
from fractions import Fraction

import pytest

from tests.conftest import ROOT
from tests.test_cli import singcheck

DATA = ROOT / "tests" / "data" / "batch"
DELTA = str(DATA / "linear-delta-decimal.yaml")


# -- the region step's crash on a linear Delta's plane z = -2/5 ------------------------


def test_separators_of_fibre_points_closer_than_a_double_ulp():
    """Two fibre points 5e-17 apart (the linear Delta's plane z = -2/5): each separator
    lies strictly between consecutive points, checked exactly against the balls."""
    from flint import arb, fmpq

    from singcheck.algebra.intervals import working_precision
    from singcheck.spaces.plane_adjacency import separators

    with working_precision(200):
        a = arb("-0.866025408514986947466435412038 +/- 1.21e-31")
        b = arb("-0.866025408514986897853545875265 +/- 1.64e-31")
        points = [a, b, -b, -a]
    seps = separators(points)  # at the default precision, as the caller does
    assert len(seps) == len(points) + 1
    with working_precision(200):
        for s, p, nxt in zip(seps, points, seps[1:], strict=False):
            q = arb(fmpq(s.numerator, s.denominator))
            r = arb(fmpq(nxt.numerator, nxt.denominator))
            assert q < p < r, (s, p, nxt)


def test_simplest_between_refuses_an_empty_interval():
    from singcheck.spaces.cad import simplest_between

    assert simplest_between(Fraction(1, 3), Fraction(1, 2)) == Fraction(2, 5)
    with pytest.raises(ValueError):
        simplest_between(Fraction(1, 2), Fraction(1, 2))


@pytest.mark.slow
def test_linear_delta_path_at_constant_z_gets_its_region(tmp_path):
    """The path of the bug report's kind: the plane z = -2/5 is decomposed, the path
    named in one region with 8 IK solutions; 8 checked here at t = 0 by hand."""
    out = singcheck("run", DELTA, str(DATA / "delta-short.yaml"), "--backend", "flint",
                    "--format", "json", "-q", env={"SINGCHECK_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    (t,) = json.loads(out.stdout)["trajectories"]
    assert t["workspace"]["one_region"] is True and t["workspace"]["region"]
    # independent count at the start pose (0, 0, -2/5): r = z ± sqrt(L² - d²) per rail
    import math

    rails = [(2, 0), (-1, 0.8660254 * 2), (-1, -0.8660254 * 2)]
    count = 1
    for ax, ay in rails:
        d2 = ax * ax + ay * ay
        roots = [-0.4 + sign * math.sqrt(9 - d2) for sign in (1, -1)]
        count *= sum(-3 < r < 3 for r in roots)
    assert t["workspace"]["ik_counts"] == [count] == [8]


# -- input: standard input, several documents, unique names ---------------------------

ORTHO = str(ROOT / "robots" / "orthoglide.yaml")
PAPER = {"heart1": "singular", "heart2": "singularity-free", "helix": "singularity-free"}


def _stream(*names: str) -> str:
    return "".join("---\n" + (ROOT / "trajectories" / f"{n}.yaml").read_text()
                   for n in names)


def singcheck_in(stdin: str, *args: str, env: dict | None = None):
    import os
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "singcheck", *args], input=stdin,
                          capture_output=True, text=True, cwd=ROOT, timeout=300,
                          env={**os.environ, **(env or {})})


def test_a_multi_document_stream_on_stdin_in_jsonl(tmp_path):
    """Three documents on stdin: three JSON lines, nothing else on stdout, each the
    trajectory object plus the robot, with the paper's verdicts."""
    out = singcheck_in(_stream("heart1", "heart2", "helix"), "run", ORTHO, "-", "--format",
                       "jsonl", "--backend", "flint", "--no-regions",
                       env={"SINGCHECK_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 1, out.stderr  # heart 1 is singular
    lines = out.stdout.splitlines()
    assert len(lines) == 3 and out.stdout.endswith("\n")
    docs = [json.loads(line) for line in lines]
    assert {d["name"]: d["verdict"] for d in docs} == PAPER
    for d in docs:
        assert d["robot"]["name"] == "orthoglide" and d["path"] == "<stdin>"
        assert "workspace" not in d  # --no-regions
        assert isinstance(d["time_s"], float)  # the seconds it took (issue #30)
    heart1 = next(d for d in docs if d["name"] == "heart1")
    assert [round(c["t"], 2) for c in heart1["candidates"]] == [-1.51, -0.98, 0.98, 1.51]


def test_a_file_of_several_documents_and_a_file_of_one(tmp_path):
    many = tmp_path / "many.yaml"
    many.write_text(_stream("heart1", "heart2"))
    out = singcheck("run", ORTHO, str(many), str(ROOT / "trajectories" / "helix.yaml"),
                    "--format", "json", "--backend", "flint", "-q",
                    env={"SINGCHECK_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 1, out.stderr
    docs = json.loads(out.stdout)["trajectories"]
    assert [(d["name"], d["verdict"]) for d in docs] == list(PAPER.items())  # input order


def test_names_must_be_unique_in_a_run(tmp_path):
    out = singcheck_in(_stream("heart1", "heart2"), "run", ORTHO, "-",
                       str(ROOT / "trajectories" / "heart1.yaml"), "--backend", "flint")
    assert out.returncode == 2
    assert out.stdout == ""
    err = out.stderr.strip()
    assert err.count("\n") == 0 and "Traceback" not in err
    assert "heart1.yaml:" in err and "'heart1' is already used by <stdin>:" in err


def test_an_error_in_a_later_document_names_the_line_and_the_document():
    text = _stream("heart1") + "---\nname: bad\nparameter: t\nrange: [0, 1]\npose:\n" \
        "  x: t\n  y: 0\n  z: sin(t\n"
    out = singcheck_in(text, "run", ORTHO, "-", "--backend", "flint")
    assert out.returncode == 2
    line = len(_stream("heart1").splitlines()) + 8
    assert out.stderr.startswith(f"singcheck: error: <stdin>:{line}: pose.z:")
    assert "(document 2)" in out.stderr


# -- output: JUnit XML for CI ----------------------------------------------------------


def test_junit_parsed_back_by_a_ci_parser(tmp_path):
    """junitparser (what CI report tools use) reads the file: one suite for the robot,
    a case per trajectory, a failure for the singular heart 1 with its singular times,
    an error for a trajectory stopped by its time limit."""
    from junitparser import Error, Failure, JUnitXml

    report = tmp_path / "report.xml"
    out = singcheck("run", ORTHO, *(str(ROOT / "trajectories" / f"{n}.yaml") for n in PAPER),
                    str(DATA / "slow.yaml"), "--format", "junit", "-o", str(report),
                    "--backend", "flint", "--time-limit", "2", "--no-regions", "-q",
                    env={"SINGCHECK_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 1, out.stderr
    assert out.stdout == ""
    xml = JUnitXml.fromfile(str(report))
    (suite,) = list(xml)
    assert suite.name == "orthoglide"
    assert (suite.tests, suite.failures, suite.errors) == (4, 1, 1)
    cases = {case.name: case for case in suite}
    assert set(cases) == {*PAPER, "slow"}
    (failure,) = cases["heart1"].result
    assert isinstance(failure, Failure)
    # the paper's S3 and S4 (Table 1): t ≈ 0.98 and 1.51 on mode +++
    times = [float(x) for x in failure.message.split("≈")[1].split(",")]
    assert [round(x, 2) for x in times] == [0.98, 1.51]
    (error,) = cases["slow"].result
    assert isinstance(error, Error) and "time limit" in error.message
    assert cases["heart2"].result == [] and cases["helix"].result == []
    assert cases["slow"].time >= 2 and all(c.time < 2 for n, c in cases.items() if n != "slow")


# -- one path never sinks a batch -----------------------------------------------------


@pytest.mark.slow
def test_one_path_past_the_time_limit_and_the_others_come_back_right(tmp_path):
    import time

    start = time.monotonic()
    out = singcheck("run", ORTHO, str(ROOT / "trajectories" / "heart1.yaml"),
                    str(DATA / "slow.yaml"), str(ROOT / "trajectories" / "heart2.yaml"),
                    "--format", "jsonl", "--backend", "flint", "--time-limit", "2", "-q",
                    "--jobs", "1", env={"SINGCHECK_CACHE_DIR": str(tmp_path)})
    elapsed = time.monotonic() - start
    assert out.returncode == 1, out.stderr  # the worst outcome: heart 1 is singular
    docs = {d["name"]: d for d in map(json.loads, out.stdout.splitlines())}
    assert docs["slow"]["verdict"] == "unknown"
    assert "time limit (2 s)" in docs["slow"]["reason"]
    assert docs["heart1"]["verdict"] == "singular" and docs["heart2"]["verdict"] == \
        "singularity-free"
    assert elapsed < 60  # unbounded, the slow path runs for minutes


def _fail_on(name: str, monkeypatch):
    from singcheck import api

    real = api.check

    def check(robot, trajectory, **options):
        if trajectory.name == name:
            raise ZeroDivisionError("Fraction(1, 0)")
        return real(robot, trajectory, **options)

    monkeypatch.setattr(api, "check", check)


@pytest.fixture(scope="module")
def orthoglide_robot():
    import singcheck as sc

    return sc.load_robot(ORTHO, backend="flint", cache=False)


@pytest.mark.parametrize("jobs", [1, 2])
def test_an_internal_error_is_that_paths_result(orthoglide_robot, tmp_path, monkeypatch, jobs):
    """A bug on one path: that path is an error with the reason, the others are
    certified (in one process, and in forked workers)."""
    import sys

    sys.path.insert(0, str(ROOT / "bench"))
    from generate import write

    from singcheck import api
    from singcheck.spec.files import load_trajectories

    paths = write(tmp_path, 6)
    specs = load_trajectories(paths, orthoglide_robot.spec)
    expected = [api.check(orthoglide_robot, s, regions=False).verdict for s in specs]
    _fail_on(specs[2].name, monkeypatch)
    docs = list(api.check_batch(orthoglide_robot, specs, regions=False, jobs=jobs))
    assert [d["name"] for d in docs] == [s.name for s in specs]
    assert docs[2]["verdict"] == "error"
    assert docs[2]["error"] == {"kind": "internal", "message": "ZeroDivisionError: Fraction(1, 0)"}
    assert [d["verdict"] for i, d in enumerate(docs) if i != 2] == \
        [v for i, v in enumerate(expected) if i != 2]


def test_the_batch_exits_with_its_worst_outcome(monkeypatch, capsys):
    """An error on one path: the others are printed, and the exit status is 70."""
    import sys

    from singcheck.cli import commands as cli

    _fail_on("heart2", monkeypatch)
    monkeypatch.setattr(sys, "argv", ["singcheck", "run", ORTHO,
                                      str(ROOT / "trajectories" / "heart1.yaml"),
                                      str(ROOT / "trajectories" / "heart2.yaml"),
                                      "--format", "jsonl", "--backend", "flint", "-q",
                                      "--no-cache", "--no-regions"])
    with pytest.raises(SystemExit) as exit_:
        cli.main()
    assert exit_.value.code == 70
    docs = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(d["name"], d["verdict"]) for d in docs] == [("heart1", "singular"),
                                                         ("heart2", "error")]
    assert [cli._worst(c) for c in ([0, 3], [3, 1], [1, 4], [4, 70], [])] == [3, 1, 4, 70, 0]


def test_the_hard_time_limit_stops_a_loop_without_checkpoints():
    import time

    from singcheck.api import hard_time_limit
    from singcheck.budget import TimeLimitExceeded

    start = time.monotonic()
    with pytest.raises(TimeLimitExceeded), hard_time_limit(0.1):
        while True:
            pass
    assert time.monotonic() - start < 5


def test_robots_and_trajectories_pickle_exactly(orthoglide_robot):
    """What a Dask cluster ships: the unpickled robot and path give the same report."""
    import pickle

    import singcheck as sc
    from singcheck.algebra import pickling  # noqa: F401  (installs the reducers)

    heart1 = sc.load_trajectory(str(ROOT / "trajectories" / "heart1.yaml"), orthoglide_robot)
    robot2, heart2 = pickle.loads(pickle.dumps((orthoglide_robot, heart1)))
    assert robot2.singularity_surface == orthoglide_robot.singularity_surface
    assert sc.check(robot2, heart2).to_dict() == sc.check(orthoglide_robot, heart1).to_dict()


def test_polynomials_pickle_exactly_whatever_their_variable_names():
    """Polynomials cross a fork or a cluster as FLINT's text in renamed variables: names
    with operators in them (cos(phi), sqrt(3), an angle function) and names that are
    prefixes of others (s, sqrt(3)) come back term by term, as do huge fractions, the
    zero polynomial and integer polynomials."""
    import pickle
    from fractions import Fraction

    from flint import fmpq, fmpq_mpoly_ctx, fmpz_mpoly_ctx

    from singcheck.algebra import pickling  # noqa: F401  (installs the reducers)

    names = ("t", "s", "c", "sqrt(3)", "cos(t^2 + 1/2*pi)", "sin(t^2 + 1/2*pi)", "x*y", "v0")
    ctx = fmpq_mpoly_ctx.get(names, "lex")
    t, s, c, r3, cg, sg, xy, v0 = ctx.gens()
    big = fmpq(3**80 + 1, 2**70 * 7)
    p = (big * r3 * cg - fmpq(7, 3) * sg**3 * t + s * c - xy * v0 + 1) ** 4
    expected = {tuple(int(e) for e in k): Fraction(int(v.p), int(v.q))
                for k, v in p.to_dict().items()}
    back = pickle.loads(pickle.dumps(p))
    assert back.context() is ctx
    assert {tuple(int(e) for e in k): Fraction(int(v.p), int(v.q))
            for k, v in back.to_dict().items()} == expected
    assert pickle.loads(pickle.dumps(ctx.from_dict({}))).is_zero()
    zctx = fmpz_mpoly_ctx.get(("a", "ab"), "lex")
    a, ab = zctx.gens()
    q = -7 * a**3 * ab + 2 * ab**12 - 5
    assert pickle.loads(pickle.dumps(q)).to_dict() == q.to_dict()


# -- signals: what was streamed stays valid, -o writes nothing partial -----------------


def _generated(tmp_path, count: int) -> list[str]:
    import sys

    sys.path.insert(0, str(ROOT / "bench"))
    from generate import write

    return [str(p) for p in write(tmp_path / "paths", count)]


@pytest.mark.parametrize("sig, group", [("SIGTERM", False), ("SIGHUP", False),
                                        ("SIGINT", True)])
def test_a_signal_mid_batch_leaves_valid_jsonl_lines(tmp_path, sig, group):
    """Stopped mid-batch (forked workers busy), singcheck exits 130; every line it wrote
    is a whole JSON object, and no worker printed a traceback.  Ctrl-C reaches the whole
    process group (``group``), workers included."""
    import os
    import signal
    import subprocess
    import sys
    import time

    def as_a_foreground_job():  # (a suite started in the background inherits
        # SIGINT ignored, as POSIX shells give background jobs: Ctrl-C is the foreground's)
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    paths = _generated(tmp_path, 40)
    proc = subprocess.Popen([sys.executable, "-m", "singcheck", "run", ORTHO, *paths,
                             str(DATA / "slow.yaml"), "--format", "jsonl", "--jobs", "2",
                             "--backend", "flint", "--no-regions"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT,
                            env={**os.environ, "SINGCHECK_CACHE_DIR": str(tmp_path)},
                            start_new_session=group, preexec_fn=as_a_foreground_job)
    first = proc.stdout.readline()  # a result streamed: the batch is under way
    time.sleep(0.5)
    if group:
        os.killpg(proc.pid, getattr(signal, sig))
    else:
        proc.send_signal(getattr(signal, sig))
    rest = proc.stdout.read()  # (communicate() would skip what readline buffered)
    err = proc.stderr.read()
    proc.wait(timeout=60)
    assert proc.returncode == 130, err
    lines = (first + rest).decode().splitlines()
    assert 1 <= len(lines) < 41  # the slow path never finished
    for line in lines:
        assert line.startswith("{") and line.endswith("}"), (line[:200], line[-200:])
        assert json.loads(line)["verdict"] in ("singular", "singularity-free", "infeasible")
    text = err.decode()
    assert "interrupted" in text
    assert "Traceback" not in text and "ForkPoolWorker" not in text


def test_a_signal_leaves_no_output_file(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "results.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "singcheck", "run", ORTHO,
                             str(ROOT / "trajectories" / "heart1.yaml"), str(DATA / "slow.yaml"),
                             "--format", "jsonl", "-o", str(out), "--jobs", "1",
                             "--backend", "flint", "--no-regions"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT,
                            env={**os.environ, "SINGCHECK_CACHE_DIR": str(tmp_path)})
    err = b""
    for line in proc.stderr:  # progress notes: heart 1 is done, the slow path running
        err += line
        if b"heart1" in line:
            break
    time.sleep(0.5)
    proc.send_signal(signal.SIGTERM)
    _, rest = proc.communicate(timeout=60)
    assert proc.returncode == 130, err + rest
    assert not out.exists() and list(tmp_path.glob(".results.jsonl*")) == []


# -- Dask ------------------------------------------------------------------------------


@pytest.fixture
def local_cluster():
    """A dask.distributed cluster of two worker processes, on loopback only, closed after
    the test that asked for it: kept for the module, its I/O loop's allocations fell
    into the memory that a later test of this module traces (82 KB against its 64 KB
    bound, in one CI run of four)."""
    import distributed  # the dask extra (make setup installs it)

    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address="127.0.0.1:0")
    yield cluster
    cluster.close()


@pytest.mark.slow
def test_the_dask_run_gives_the_local_verdicts(local_cluster, tmp_path, orthoglide_robot):
    """Generated heart-like paths on the cluster (SINGCHECK_SCHEDULER): the verdicts of
    a local run of the API, each path once; jsonl in completion order, json in input
    order."""
    from singcheck import api
    from singcheck.spec.files import load_trajectories

    paths = _generated(tmp_path, 30)
    local = {d["name"]: d for d in api.check_batch(
        orthoglide_robot, load_trajectories(paths, orthoglide_robot.spec), regions=False)}
    env = {"SINGCHECK_CACHE_DIR": str(tmp_path),
           "SINGCHECK_SCHEDULER": local_cluster.scheduler_address}
    lines = singcheck("run", ORTHO, *paths, "--format", "jsonl", "--backend", "flint",
                      "--no-regions", "-q", env=env)
    assert lines.returncode == 1, lines.stderr
    streamed = [json.loads(line) for line in lines.stdout.splitlines()]
    assert sorted(d["name"] for d in streamed) == sorted(local)
    for d in streamed:
        del d["robot"]
        assert isinstance(d.pop("time_s"), float)  # each line's own seconds
        assert d == {k: v for k, v in local[d["name"]].items() if k != "time_s"}
    doc = singcheck("run", ORTHO, *paths, "--format", "json", "--backend", "flint", "-q",
                    env=env)
    assert [t["name"] for t in json.loads(doc.stdout)["trajectories"]] == list(local)
    assert {t["name"]: t["verdict"] for t in json.loads(doc.stdout)["trajectories"]} == \
        {n: d["verdict"] for n, d in local.items()}


def _diagnostics(dask_worker) -> dict:
    """On a worker or nanny: which periodic diagnostics run, the memory monitor's
    period (ms), and the garbage collector's first threshold."""
    import gc

    from singcheck.cluster import DIAGNOSTICS

    callbacks = dask_worker.periodic_callbacks
    out = {n: callbacks[n].is_running() for n in DIAGNOSTICS if n in callbacks}
    out["gc"] = gc.get_threshold()[0]
    if "memory_monitor" in callbacks:
        out["memory_monitor"] = callbacks["memory_monitor"].callback_time
    return out


def _scheduler_diagnostics(dask_scheduler=None) -> dict:
    return _diagnostics(dask_scheduler)


def test_a_dask_batch_pauses_the_workers_diagnostics_and_restores_them(
        local_cluster, tmp_path, orthoglide_robot):
    """While a batch runs, every worker's and nanny's profiler, tick and system monitor,
    and the scheduler's tick and monitor, are paused, the memory monitor polls every
    second (not 100 ms) and the garbage collector's first threshold is the command
    line's own; once the batch has ended, or is stopped early, they are as they were."""
    import gc

    from distributed import Client

    from singcheck.cluster import check_on_cluster
    from singcheck.collector import FIRST_THRESHOLD as GC_THRESHOLD
    from singcheck.spec.files import load_trajectories

    specs = list(load_trajectories(_generated(tmp_path, 12), orthoglide_robot.spec))
    # the nannies live in this process, whose collector an earlier test may have tuned
    # (the command line run in-process raises it): Python's default for this test
    threshold = gc.get_threshold()
    gc.set_threshold(700, *threshold[1:])
    try:
        with Client(local_cluster.scheduler_address) as client:
            def every(nanny: bool) -> list[dict]:
                return list(client.run(_diagnostics, nanny=nanny).values())

            before = every(False) + every(True)
            assert len(before) == 4 and all(d["profile"] for d in before[:2])
            assert all(d["tick"] and d["monitor"] and d["memory_monitor"] == 100
                       for d in before)
            assert all(d["gc"] < GC_THRESHOLD for d in before)
            scheduler = client.run_on_scheduler(_scheduler_diagnostics)
            assert scheduler["tick"] and scheduler["monitor"]
            for stop_early in (False, True):
                results = check_on_cluster(local_cluster.scheduler_address, orthoglide_robot,
                                           specs, regions=False)
                first = next(results)
                assert first["verdict"] in ("singular", "singularity-free", "infeasible")
                during = every(False) + every(True)
                assert all(not any(v for k, v in d.items() if k not in ("memory_monitor", "gc"))
                           and d["memory_monitor"] == 1000 and d["gc"] == GC_THRESHOLD
                           for d in during), during
                paused = client.run_on_scheduler(_scheduler_diagnostics)
                assert not paused["tick"] and not paused["monitor"], paused
                if stop_early:
                    results.close()  # (the CLI's Ctrl-C, or a consumer that stops)
                else:
                    assert len(list(results)) == len(specs) - 1
                assert every(False) + every(True) == before
                assert client.run_on_scheduler(_scheduler_diagnostics) == scheduler
    finally:
        gc.set_threshold(*threshold)


def test_the_region_statement_is_bounded_by_the_time_limit():
    """The helix's region needs the 3-D workspace decomposed (seconds, no cache here):
    with a 0.5 s limit the certified verdict stands and the region statement is left out
    with the reason, promptly."""
    import time

    import singcheck as sc

    robot = sc.load_robot(ORTHO, backend="flint", cache=False)
    helix = sc.load_trajectory(str(ROOT / "trajectories" / "helix.yaml"), robot)
    start = time.monotonic()
    report = sc.check(robot, helix, time_limit=0.5)
    assert time.monotonic() - start < 3  # unbounded, the decomposition takes 5 s or more
    assert report.verdict == "singularity-free"
    doc = report.to_dict()
    assert "workspace" not in doc
    assert "time limit (0.5 s) reached while naming the workspace region" in doc["reason"]


def test_the_api_reads_several_documents(orthoglide_robot, tmp_path):
    import singcheck as sc

    many = tmp_path / "many.yaml"
    many.write_text(_stream("heart1", "heart2"))
    specs = sc.load_trajectories([many], orthoglide_robot)
    assert [s.name for s in specs] == ["heart1", "heart2"]
    assert [sc.check(orthoglide_robot, s, regions=False).verdict for s in specs] == \
        ["singular", "singularity-free"]


def test_forked_workers_die_with_a_sigkilled_singcheck(tmp_path):
    """SIGKILL cannot be handled: the workers ask the kernel for their own SIGKILL when
    the parent goes (PR_SET_PDEATHSIG) instead of computing on as orphans."""
    import os
    import subprocess
    import sys
    import time

    paths = _generated(tmp_path, 40)
    proc = subprocess.Popen([sys.executable, "-m", "singcheck", "run", ORTHO, *paths,
                             str(DATA / "slow.yaml"), "--format", "jsonl", "--jobs", "2",
                             "--backend", "flint", "--no-regions"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, cwd=ROOT,
                            env={**os.environ, "SINGCHECK_CACHE_DIR": str(tmp_path)})

    def workers() -> list[int]:
        out = []
        for name in os.listdir("/proc"):
            try:
                with open(f"/proc/{name}/stat", "rb") as f:
                    fields = f.read().rsplit(b")", 1)[1].split()
            except (OSError, IndexError):
                continue
            if int(fields[1]) == proc.pid and fields[0] != b"Z":
                out.append(int(name))
        return out

    forked: list[int] = []
    try:
        proc.stdout.readline()  # a result streamed: the workers are busy
        forked = workers()
        assert forked
        proc.kill()
        proc.wait()
        deadline = time.monotonic() + 5
        while any(os.path.exists(f"/proc/{pid}") and _running(pid) for pid in forked):
            assert time.monotonic() < deadline, "a worker survived its parent's SIGKILL"
            time.sleep(0.05)
    finally:  # never leave a worker behind, even when the test fails
        proc.kill()
        proc.wait()
        for pid in forked:
            if _running(pid):
                os.kill(pid, 9)


def _running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except OSError:
        return False


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_bad_document_mid_stream_is_its_own_result(orthoglide_robot, tmp_path, jobs):
    """Documents read lazily and parsed by the workers: the bad one in the middle is an
    error naming its file, line and document; the others keep their order and come
    back as certified one by one, each spec parsed here."""
    from singcheck import api
    from singcheck.spec.files import parse_trajectory, read_documents

    good = [f"---\nname: p{i}\nparameter: t\nrange: [0, 1]\npose:\n  x: {i}/5 + t/2\n"
            "  y: 1/4\n  z: 1\n" for i in range(6)]
    bad = "---\nname: bad\nparameter: t\nrange: [0, 1]\npose: [1, 2]\n"
    stream = tmp_path / "stream.yaml"
    stream.write_text("".join(good[:3]) + bad + "".join(good[3:]))
    docs = list(api.check_batch(orthoglide_robot, read_documents([stream]), regions=False,
                                jobs=jobs))
    assert [d["name"] for d in docs] == ["p0", "p1", "p2", "bad", "p3", "p4", "p5"]
    line = len("".join(good[:3]).splitlines()) + 5
    assert docs[3]["verdict"] == "error" and docs[3]["error"]["kind"] == "spec"
    assert docs[3]["error"]["message"].startswith(f"{stream}:{line}: pose: ")
    assert docs[3]["error"]["message"].endswith("(document 4)")
    for d, text in zip(docs[:3] + docs[4:], good, strict=True):
        spec = parse_trajectory(text, "x.yaml", orthoglide_robot.spec)
        assert d["verdict"] == api.check(orthoglide_robot, spec, regions=False).verdict


# -- memory: flat in the number of paths -----------------------------------------------


def _lines_stream(path, count: int):
    """``count`` straight-line paths of the Orthoglide at z = 1 (cheap to certify: the
    test is about what the batch holds), as one stream of YAML documents."""
    with path.open("w") as f:
        for i in range(count):
            f.write(f"---\nname: line-{i}\nparameter: t\nrange: [0, 1]\npose:\n"
                    f"  x: {i % 7}/10 + t/{i % 5 + 2}\n  y: {i % 3 + 1}/4\n  z: 1\n")
    return path


def _peak_rss_mb(args: list[str], stdin_path, env: dict) -> tuple[float, int, int]:
    """Peak resident memory (MB) of a singcheck process and its workers, measured from a
    small launcher (bench/peak_rss.py: started straight from pytest, the figure would
    be at least pytest's own size); its exit status, and the number of JSON lines."""
    import os
    import sys
    import tempfile

    if str(ROOT / "bench") not in sys.path:
        sys.path.insert(0, str(ROOT / "bench"))
    from peak_rss import run_measured

    with stdin_path.open("rb") as stdin, tempfile.TemporaryFile() as out:
        code, peak_mb, _ = run_measured([sys.executable, "-m", "singcheck", *args],
                                        cwd=ROOT, stdin=stdin, stdout=out,
                                        stderr=subprocess.DEVNULL,
                                        env={**os.environ, **env})
        out.seek(0)
        lines = sum(1 for line in out if json.loads(line)["name"].startswith("line-"))
    return peak_mb, code, lines


def test_memory_stays_flat_from_500_to_5000_paths_on_stdin(tmp_path):
    """500 and then 5,000 paths streamed through one command each (stdin, jsonl,
    --no-regions, two forked workers): every path comes back, and the peak memory of
    the command grows by less than 5 MB (parsed all up front, as before this test, the
    5,000 peaked 11 MB above the 500; streamed, 0.8 MB: the names kept for uniqueness)."""
    env = {"SINGCHECK_CACHE_DIR": str(tmp_path)}
    args = ["run", ORTHO, "-", "--format", "jsonl", "--no-regions", "--backend", "flint",
            "-q", "--jobs", "2"]
    small, code, lines = _peak_rss_mb(args, _lines_stream(tmp_path / "small.yaml", 500), env)
    assert (code, lines) == (1, 500)  # some lines cross the singularity surface
    large, code, lines = _peak_rss_mb(args, _lines_stream(tmp_path / "large.yaml", 5000), env)
    assert (code, lines) == (1, 5000)
    assert large - small < 5, (small, large)
    assert small < 200, small  # the command's own peak, not the launcher's parent's


def _killing(monkeypatch, killer):
    """``api.check_safely`` SIGKILLs its process (as the OOM killer would) for a path
    ``killer(name)`` names; two paths a task, two tasks a worker.  Returns the real one."""
    import os
    import signal

    from singcheck import api

    real = api.check_safely

    def check_safely(robot, trajectory, **options):
        if killer(trajectory.name):
            os.kill(os.getpid(), signal.SIGKILL)
        return real(robot, trajectory, **options)

    monkeypatch.setattr(api, "check_safely", check_safely)
    monkeypatch.setattr(api, "CHUNK", 2)
    monkeypatch.setattr(api, "MAX_CHUNK", 2)
    monkeypatch.setattr(api, "TASKS_PER_WORKER", 2)
    return real


def _twelve_paths(tmp_path):
    stream = tmp_path / "stream.yaml"
    stream.write_text("".join(f"---\nname: p{i}\nparameter: t\nrange: [0, 1]\npose:\n"
                              f"  x: {i}/20 + t/2\n  y: 1/4\n  z: 1\n" for i in range(12)))
    return stream


def _killing_batch(orthoglide_robot, tmp_path, monkeypatch, killer):
    """A 12-path batch in 2 workers, one path a task, where ``killer(name)`` says whether
    checking that path SIGKILLs its worker (as the OOM killer would)."""
    from singcheck import api
    from singcheck.spec.files import read_documents

    _killing(monkeypatch, killer)
    stream = _twelve_paths(tmp_path)
    docs = list(api.check_batch(orthoglide_robot, read_documents([stream]), regions=False,
                                jobs=2))
    assert [d["name"] for d in docs] == [f"p{i}" for i in range(12)]
    expected = [api.check(orthoglide_robot, d.parse(orthoglide_robot.spec),
                          regions=False).verdict for d in read_documents([stream])]
    return docs, expected


def test_a_path_that_kills_its_worker_twice_is_its_own_error(orthoglide_robot, tmp_path,
                                                             monkeypatch):
    """B1: a worker SIGKILLed mid-task broke the pool, and every task in flight became an
    ``internal`` error (exit 70).  Each broken task is run again alone, then path by path:
    only the path that kills its worker every time is an error; every other path,
    whichever task it shared, is certified."""
    docs, expected = _killing_batch(orthoglide_robot, tmp_path, monkeypatch,
                                    lambda name: name == "p1")
    assert docs[1]["verdict"] == "error"
    assert docs[1]["error"]["kind"] == "worker-died", docs[1]
    assert docs[1]["error"]["message"].startswith("its worker process died twice"), docs[1]
    assert [d["verdict"] for i, d in enumerate(docs) if i != 1] == \
        [v for i, v in enumerate(expected) if i != 1]


def test_a_batch_whose_path_kills_its_worker_twice_exits_4_not_70(tmp_path, monkeypatch,
                                                                  capsys):
    """Issue 31: that path's ``error`` (kind ``worker-died``) is no bug of singcheck: the
    batch exits as for a backend past its memory bound (4, docs/outputs.md), the other
    paths' lines complete, and stderr says nothing of an internal error."""
    from tests.test_hardening import run_cli

    _killing(monkeypatch, lambda name: name == "p1")
    code, out, err = run_cli(monkeypatch, capsys, "run", str(ORTHO), str(_twelve_paths(tmp_path)),
                             "--jobs", "2", "--no-regions", "--backend", "flint", "-q",
                             "--format", "jsonl")
    lines = [json.loads(line) for line in out.splitlines()]
    assert code == 4, err
    assert len(lines) == 12 and "internal error" not in err, err
    dead = [d for d in lines if d["verdict"] == "error"]
    assert [(d["name"], d["error"]["kind"]) for d in dead] == [("p1", "worker-died")]


def test_a_worker_killed_once_loses_no_path(orthoglide_robot, tmp_path, monkeypatch):
    """B1: a worker killed once (by someone else, while checking p3): its task and the
    others in flight are run again, and every path is certified."""
    flag = tmp_path / "killed-once"

    def once(name: str) -> bool:
        if name != "p3" or flag.exists():
            return False
        flag.write_text("")
        return True

    docs, expected = _killing_batch(orthoglide_robot, tmp_path, monkeypatch, once)
    assert flag.exists()
    assert [d["verdict"] for d in docs] == expected


# -- JUnit against the schema CI tools check reports with -------------------------------

JUNIT_XSD = ROOT / "tests" / "data" / "junit-report.xsd"  # ours: the format CI readers accept

#: x² + z² = 10 > l² = 4 all along: the second leg's equation x² + (y − ρ2)² + z² = l²
#: has no real root, so no working mode is feasible anywhere on the path
OUTSIDE = "name: outside\nparameter: t\nrange: [0, 1]\npose:\n  x: 3\n  y: t\n  z: 1\n"


def test_junit_validates_against_the_schema(tmp_path, monkeypatch):
    """A batch with every kind of result (singular, free, infeasible, unknown past its
    time limit, a bad document and a repeated name past the documents read up front)
    gives JUnit XML that the JUnit schema accepts, and that junitparser (the reader of the
    GitHub test-report actions) reads back with the counts of the verdicts known here:
    2 failures, 3 errors in 6 cases."""
    import sys

    import xmlschema
    from junitparser import Error, Failure, JUnitXml

    from singcheck import api
    from singcheck.cli import commands as cli

    monkeypatch.setattr(api, "LOOKAHEAD", 3)  # the bad documents come later: results
    many = tmp_path / "many.yaml"
    bad = "name: bad\nparameter: t\nrange: [0, 1]\npose:\n  x: t\n  y: 0\n  z: sin(t\n"
    many.write_text(_stream("heart1", "heart2") + "---\n" + OUTSIDE + "---\n" +
                    (DATA / "slow.yaml").read_text() + "---\n" + bad + _stream("heart2"))
    report = tmp_path / "report.xml"
    monkeypatch.setattr(sys, "argv", ["singcheck", "run", ORTHO, str(many), "--format",
                                      "junit", "-o", str(report), "--backend", "flint",
                                      "--time-limit", "2", "--no-regions", "--jobs", "1",
                                      "-q", "--no-cache"])
    with pytest.raises(SystemExit) as exit_:
        cli.main()
    assert exit_.value.code == 2  # the worst outcome: a bad document
    xmlschema.XMLSchema(str(JUNIT_XSD)).validate(str(report))  # raises when invalid
    (suite,) = list(JUnitXml.fromfile(str(report)))
    assert (suite.tests, suite.failures, suite.errors) == (6, 2, 3)
    results = [(case.name, [type(r).__name__ for r in case.result]) for case in suite]
    assert results == [("heart1", ["Failure"]), ("heart2", []), ("outside", ["Failure"]),
                       ("slow", ["Error"]), ("bad", ["Error"]), ("heart2", ["Error"])]
    cases = list(suite)
    assert isinstance(cases[2].result[0], Failure) and \
        cases[2].result[0].message.startswith("infeasible")
    assert isinstance(cases[4].result[0], Error)
    line = len((_stream("heart1", "heart2") + "---\n" + OUTSIDE + "---\n" +
                (DATA / "slow.yaml").read_text()).splitlines()) + 8
    assert f"many.yaml:{line}: pose.z:" in cases[4].result[0].message
    assert "(document 5)" in cases[4].result[0].message
    assert "'heart2' is already used by" in cases[5].result[0].message


def test_junit_omits_a_property_this_run_does_not_know():
    """ξ not expanded (the rotary Delta): the document's singularity_surface_degree is
    null, and the JUnit properties leave it out rather than print Python's ``None``."""
    import xml.etree.ElementTree as ET

    from singcheck.report.junit import junit_xml

    xml = junit_xml({"name": "rotary-delta"}, [], {"backend": "flint",
                                                   "singularity_surface_degree": None})
    props = {p.get("name"): p.get("value") for p in ET.fromstring(xml.split("\n", 1)[1])
             .iter("property")}
    assert props == {"backend": "flint"}


def test_the_schema_test_can_fail():
    """The schema refuses what CI readers would: a testcase without a name, a time with
    more decimals than Surefire writes, an attribute they do not know, a negative count."""
    import xmlschema

    schema = xmlschema.XMLSchema(str(JUNIT_XSD))
    good = '<testsuite name="s" tests="1" failures="0" errors="0" time="0.5">' \
        '<testcase name="c" time="0.5"/></testsuite>'
    assert schema.is_valid(good)
    assert not schema.is_valid(good.replace(' name="c"', ""))
    assert not schema.is_valid(good.replace('time="0.5">', 'time="0.123456">'))
    assert not schema.is_valid(good.replace('<testcase name="c"', '<testcase file="f" name="c"'))
    assert not schema.is_valid(good.replace('failures="0"', 'failures="-1"'))


# -- issue 32: the parent cuts the stream, the workers read, check and format ------------

#: past api.LOOKAHEAD (the documents parsed up front), where the workers read the spans
MIXED_COUNT = 130
BAD_AT = 110  # a document whose YAML is broken
REPEATED_AT = 120  # a name used before (by the document at 7)
QUOTED_AT = 115  # a quoted name: the quick scan leaves it to YAML, in the parent


def _mixed_stream(path):
    """MIXED_COUNT straight-line documents (cheap to certify) with a broken one, a repeated
    name and a quoted name past the first api.LOOKAHEAD; each document 8 lines long."""
    docs = []
    for i in range(MIXED_COUNT):
        name = {REPEATED_AT: "line-7", QUOTED_AT: f'"line {i}"'}.get(i, f"line-{i}")
        z = "[1" if i == BAD_AT else "1"  # an unclosed flow sequence: not YAML
        docs.append(f"---\nname: {name}\nparameter: t\nrange: [0, 1]\npose:\n"
                    f"  x: {i % 7}/10 + t/{i % 5 + 2}\n  y: {i % 3 + 1}/4\n  z: {z}\n")
    path.write_text("".join(docs))
    return path


def test_the_quick_scan_cuts_what_yaml_reads(tmp_path):
    """read_documents(spans=True): the same documents, numbers, lines and names as the
    composed reading; plain names are spans (a regular file's byte range, standard
    input's bytes), and each span composes to the composed reading's document."""
    from singcheck.spec.files import Document, Span, read_documents

    stream = _mixed_stream(tmp_path / "mixed.yaml")
    composed = list(read_documents([stream]))
    scanned = list(read_documents([stream], spans=True))
    assert len(scanned) == len(composed) == MIXED_COUNT
    for i, (s, c) in enumerate(zip(scanned, composed, strict=True)):
        assert (s.path, s.number, s.line) == (c.path, c.number, c.line), i
        # the broken one: the scan reads its name line, YAML reads no name
        assert s.name == (f"line-{BAD_AT}" if i == BAD_AT else c.name), i
        if i == QUOTED_AT:  # not a plain word: composed here, as before
            assert isinstance(s, Document) and s.name == f"line {QUOTED_AT}"
        elif i == REPEATED_AT:  # the repeated name is found by the scan, here
            assert isinstance(s, Document) and "already used by" in s.error.message
            assert s.error.message == c.error.message
        else:
            assert isinstance(s, Span) and s.source == str(stream) and s.data is None
            read = s.document()
            assert (read.text, read.name, read.name_line) == (c.text, c.name, c.name_line)
            assert (read.error is None) == (c.error is None) == (i != BAD_AT)
            assert read.label == c.label
    assert str(scanned[BAD_AT].document().error) == str(composed[BAD_AT].error)


def test_a_name_line_that_is_not_the_name_key_is_refused_not_misread(tmp_path):
    """A line starting with 'name:' inside a multi-line quoted value, the real name given
    another way: the worker's YAML disagrees with the quick scan, and says so (the name
    the scan kept for uniqueness would be wrong)."""
    from singcheck.spec.files import Span, read_documents

    stream = tmp_path / "odd.yaml"
    stream.write_text('---\n"name": real\ndescription: "two\nname: fake\n  end"\n'
                      "parameter: t\nrange: [0, 1]\npose:\n  x: t\n  y: 1/4\n  z: 1\n")
    (span,) = read_documents([stream], spans=True)
    assert isinstance(span, Span) and span.name == "fake"
    error = span.document().error
    assert error is not None and "line 4 reads as the name 'fake'" in error.message


def _mixed_run(tmp_path, fmt: str, runner: str, cluster=None):
    env = {"SINGCHECK_CACHE_DIR": str(tmp_path / "cache")}
    args = ["run", ORTHO, str(tmp_path / "mixed.yaml"), "--format", fmt, "--backend",
            "flint", "--no-regions", "-q"]
    if runner == "dask":
        args += ["--scheduler", cluster.scheduler_address]
    else:
        args += ["--jobs", runner]
    out = singcheck(*args, env=env)
    assert out.returncode == 2, out.stderr  # the broken document's outcome: a spec error
    return out.stdout


@pytest.mark.parametrize("runner", ["1", "2", pytest.param("dask", marks=pytest.mark.slow)])
def test_a_mixed_batch_gives_the_same_results_whatever_runs_it(tmp_path, runner, request,
                                                               orthoglide_robot):
    """MIXED_COUNT documents with a broken one, a repeated name and a quoted name past
    the documents parsed up front: --jobs 1, --jobs 2 and a 2-worker Dask cluster give
    each path the verdict of api.check, the errors of the composed reading (the
    stream's lines, the document's number), json in input order and jsonl the same
    objects (but time_s and the robot)."""
    from singcheck import api
    from singcheck.spec.files import read_documents

    stream = _mixed_stream(tmp_path / "mixed.yaml")
    composed = list(read_documents([stream]))
    cluster = request.getfixturevalue("local_cluster") if runner == "dask" else None
    lines = [json.loads(line) for line in
             _mixed_run(tmp_path, "jsonl", runner, cluster).splitlines()]
    doc = json.loads(_mixed_run(tmp_path, "json", runner, cluster))["trajectories"]
    names = [d.label for d in composed]
    assert names[BAD_AT] == f"{stream}:{8 * BAD_AT + 1}"  # no name read: FILE:LINE
    assert [d["name"] for d in doc] == names  # input order
    assert sorted(d["name"] for d in lines) == sorted(names)  # each once, in any order
    for d in lines:
        del d["robot"]
        assert isinstance(d.pop("time_s"), float)
    assert sorted(json.dumps(d, sort_keys=True) for d in lines) == \
        sorted(json.dumps(d, sort_keys=True) for d in doc)
    for i in (BAD_AT, REPEATED_AT):
        assert doc[i]["verdict"] == "error" and doc[i]["error"]["kind"] == "spec"
        assert doc[i]["error"]["message"] == str(composed[i].error)
        assert doc[i]["error"]["message"].endswith(f"(document {i + 1})")
    assert doc[REPEATED_AT]["error"]["message"].startswith(f"{stream}:{8 * REPEATED_AT + 2}: ")
    assert f"already used by {stream}:{8 * 7 + 2}" in doc[REPEATED_AT]["error"]["message"]
    line = int(doc[BAD_AT]["error"]["message"].split(":")[1])
    assert 8 * BAD_AT + 1 <= line <= 8 * BAD_AT + 9, doc[BAD_AT]  # in (or just past) it
    expected = [api.check(orthoglide_robot, d.parse(orthoglide_robot.spec),
                          regions=False).verdict
                for i, d in enumerate(composed) if i not in (BAD_AT, REPEATED_AT)]
    assert [d["verdict"] for i, d in enumerate(doc) if i not in (BAD_AT, REPEATED_AT)] == \
        expected


def test_a_dask_task_that_killed_its_workers_is_those_paths_error(orthoglide_robot):
    """Dask re-runs a task whose worker died and gives up with KilledWorker: the task's
    paths get ``worker-died`` (exit 4, as a --jobs worker killed twice), while any other
    failure of a task stays ``internal``."""
    from dataclasses import replace

    from distributed import KilledWorker

    from singcheck.api import load_trajectory
    from singcheck.cluster import _results

    heart = load_trajectory(ROOT / "trajectories" / "heart1.yaml", orthoglide_robot)
    p0, p1, p2 = (replace(heart, name=f"p{i}") for i in range(3))

    class Future:
        def __init__(self, key, error):
            self.key, self.error = key, error

        def result(self):
            raise self.error

        def release(self):
            pass

    class Worker:  # (what KilledWorker names: the last worker the task ran on)
        address = "tcp://127.0.0.1:1"

    class Tasks:
        line = None

        def __init__(self):
            from singcheck.api import _TaskSizes

            self.sizes = _TaskSizes(2)
            self.completed = [Future("a", KilledWorker("singcheck-0-0", Worker(), 3)),
                              Future("b", RuntimeError("boom"))]
            self.chunks = {"a": (0, [p0, p1]), "b": (2, [p2])}

        def next(self):
            pass

    docs = list(_results(Tasks(), ordered=True))
    assert "KilledWorker" in docs[0]["error"]["message"]
    assert [(d["name"], d["error"]["kind"]) for d in docs] == [
        ("p0", "worker-died"), ("p1", "worker-died"), ("p2", "internal")]


# -- issue 32: the parent's memory stays flat however many paths -----------------------


def _straight_lines(path, count: int, first: int = 0):
    """``count`` straight-line documents named line-FIRST … (cheap to certify), each 8
    lines long."""
    path.write_text("".join(f"---\nname: line-{i}\nparameter: t\nrange: [0, 1]\npose:\n"
                            f"  x: {i % 7}/10 + t/{i % 5 + 2}\n  y: {i % 3 + 1}/4\n  z: 1\n"
                            for i in range(first, first + count)))
    return path


def _traced_growth(items, marks: tuple[int, int]) -> tuple[int, int]:
    """The memory tracemalloc traces in this process after the first and the second mark
    of ``items`` (each one dropped once seen), and how many there were."""
    import gc
    import tracemalloc

    at, count = {}, 0
    tracemalloc.start()
    try:
        for count, _ in enumerate(items, 1):
            if count in marks:
                gc.collect()
                at[count] = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    return at[marks[1]] - at[marks[0]], count


def test_the_parent_keeps_no_name_per_path_of_a_long_stream(tmp_path):
    """The documents of a stream are cut in this process, their names kept for their
    uniqueness: past the first NAMES_IN_MEMORY they go to disk, and 6,000 more
    documents leave this process's memory as it was (it grew by some 170 bytes a name)."""
    from singcheck.spec import files

    stream = _straight_lines(tmp_path / "long.yaml", 8000 + 10)
    grown, count = _traced_growth(files.read_documents([stream], spans=True), (2000, 8000))
    assert count == 8010
    assert grown < 64 * 1024, grown  # 6,000 names were about 1 MB
    assert files.NAMES_IN_MEMORY < 2000  # (else the marks measure the names in memory)


def _error(document) -> str | None:
    error = getattr(document, "error", None)  # a span has none: it is not composed here
    return error and error.message


def test_a_name_repeated_past_the_names_kept_in_memory_is_found(tmp_path, monkeypatch):
    """The names past NAMES_IN_MEMORY (on disk) are unique in the run as the first ones:
    the same documents, and the same errors naming where the name was first used,
    whichever holds the first use."""
    from singcheck.spec import files

    stream = _mixed_stream(tmp_path / "mixed.yaml")
    again = _straight_lines(tmp_path / "again.yaml", 3, first=60)  # line-60 … on disk
    kept = [(d.name, _error(d))
            for d in files.read_documents([stream, again], spans=True)]
    monkeypatch.setattr(files, "NAMES_IN_MEMORY", 5)  # line-7 and line-60 … on disk
    spilled = [(d.name, _error(d))
               for d in files.read_documents([stream, again], spans=True)]
    assert spilled == kept
    repeated = [message for _, message in kept if message and "already used" in message]
    assert len(repeated) == 4
    assert f"already used by {stream}:{8 * 7 + 2}" in repeated[0]
    assert f"already used by {stream}:{8 * 60 + 2}" in repeated[1]


def test_names_stay_in_memory_when_the_disk_fails(monkeypatch):
    """A database that cannot be made, or that fails once it holds names: every name
    stays checked, in memory (as before issue 32)."""
    import sqlite3

    from singcheck.spec.files import _Names

    def failing(names):
        raise sqlite3.OperationalError("unable to open database file")

    names = _Names(in_memory=2)
    monkeypatch.setattr(_Names, "_open", failing)
    assert [names.claim(f"p{i}", "a.yaml", i) for i in range(5)] == [None] * 5
    assert names.claim("p3", "b.yaml", 9) == ("a.yaml", 3) and len(names) == 5
    monkeypatch.undo()

    names = _Names(in_memory=2)
    assert [names.claim(f"p{i}", "a.yaml", i) for i in range(5)] == [None] * 5
    assert len(names) == 2 and names.claim("p4", "b.yaml", 9) == ("a.yaml", 4)

    class Full:  # the disk filled up: no row written any more, those written still read
        def __init__(self, db):
            self.db, self.total_changes = db, db.total_changes

        def execute(self, sql, *args):
            if sql.startswith("INSERT"):
                raise sqlite3.OperationalError("database or disk is full")
            return self.db.execute(sql, *args)

        def close(self):
            self.db.close()

    names.db = Full(names.db)
    assert names.claim("p5", "a.yaml", 5) is None
    assert names.db is None and len(names) == 6  # the 3 on disk came back
    assert names.claim("p3", "b.yaml", 9) == ("a.yaml", 3)
    assert names.claim("p6", "a.yaml", 6) is None and names.db is None and len(names) == 7


@pytest.mark.slow
def test_a_long_streamed_batch_leaves_the_parent_as_it_was(tmp_path, monkeypatch,
                                                          orthoglide_robot):
    """The whole parent of a streamed --jobs 2 batch (the stream cut into spans, the
    lines the workers wrote gathered, unordered as jsonl runs it): 4,000 more paths
    leave its traced memory as it was (each kept some 170 bytes before issue 32)."""
    import tracemalloc

    from singcheck import api
    from singcheck.report.trajectory import JsonLine, robot_json
    from singcheck.spec.files import read_documents

    def untraced_worker():  # the workers do not trace: only this process is measured
        tracemalloc.stop()
        real()

    real = api._worker_signals
    monkeypatch.setattr(api, "_worker_signals", untraced_worker)
    stream = _straight_lines(tmp_path / "long.yaml", 5000 + 200)
    batch = api.check_batch(orthoglide_robot, read_documents([stream], spans=True), jobs=2,
                            regions=False, ordered=False,
                            line=JsonLine(robot_json(orthoglide_robot.projection)))
    verdicts = set()
    grown, count = _traced_growth((verdicts.add(r["verdict"]) for r in batch), (1000, 5000))
    assert count == 5200 and verdicts <= {"singular", "singularity-free", "infeasible"}
    assert grown < 256 * 1024, grown  # the 4,000 names were about 680 KB


def test_task_sizes_follow_the_pace_and_share_the_end():
    """A forked batch's tasks: CHUNK trajectories before any has finished, then what
    takes about TASK_SECONDS at the pace seen (fast paths: MAX_CHUNK; a path of a
    second: one), and once the input has ended at most a (2·jobs)-th of what is left."""
    from singcheck import api

    now = [0.0]
    sizes = api._TaskSizes(2)
    sizes.clock, sizes.start = (lambda: now[0]), 0.0
    assert sizes.next() == api.CHUNK
    now[0] = 0.5
    sizes.finished(500)  # 2 workers, 2 ms a path
    assert sizes.next() == api.MAX_CHUNK
    assert sizes.next(left=40) == 10  # the end: 40 left, shared by 2 workers
    assert sizes.next(left=3) == 1
    slow = api._TaskSizes(2)
    slow.clock, slow.start = (lambda: now[0]), 0.0
    slow.finished(1)  # one path in 0.5 s on 2 workers: a second each
    assert slow.next() == 1
    mid = api._TaskSizes(4)
    mid.clock, mid.start = (lambda: now[0]), 0.0
    mid.finished(100)  # 20 ms a path: a task of 0.25 s holds 12
    assert mid.next() == 12


def test_distributed_is_imported_without_its_optional_modules_which_stay_importable():
    """The batch's command imports dask.distributed without NumPy and Jinja2 (30% of
    its import time, before the workers' first task); both import afterwards."""
    import subprocess
    import sys

    code = ("import sys; from singcheck.cluster import _import_distributed; "
            "_import_distributed(); import distributed; "
            "print('numpy' in sys.modules, 'jinja2' in sys.modules); "
            "import numpy, jinja2; print(numpy.zeros(2).sum())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout.split()
    assert out == ["False", "False", "0.0"]


def test_dask_tasks_start_small_grow_with_the_pace_and_share_the_end(monkeypatch):
    """The cluster's submitter: FIRST_CHUNK trajectories a task until some have
    finished, then what takes TASK_SECONDS at the pace seen (at most CHUNK), and once the
    input has ended a share of what is left per worker thread (at least TAIL)."""
    import distributed

    from singcheck import cluster
    from singcheck.api import _TaskSizes

    class Completed(list):
        add = list.append

    class Client:
        loop = None

        def __init__(self):
            self.sizes = []

        def submit(self, function, shipped, chunk, *args, key, pure):
            self.sizes.append(len(chunk))
            return type("Future", (), {"key": key})()

    monkeypatch.setattr(distributed, "as_completed", lambda loop: Completed())
    now = [0.0]
    sizes = _TaskSizes(2, cluster.FIRST_CHUNK, cluster.CHUNK, cluster.TASK_SECONDS,
                       cluster.TAIL)
    sizes.clock, sizes.start = (lambda: now[0]), 0.0
    client = Client()
    tasks = cluster._Submitter(client, None, iter(range(1000)), {}, False, 8, sizes)
    assert client.sizes == [cluster.FIRST_CHUNK] * 8
    now[0] = 0.064
    sizes.finished(32)  # 2 threads, 4 ms a path: a task of 0.5 s holds 125
    tasks.next()
    assert client.sizes[-1] == min(cluster.CHUNK, 125)
    while sizes.ahead or not sizes.ended:
        tasks.next()
    assert sum(client.sizes) == 1000
    tail = client.sizes[9:]
    assert tail == sorted(tail, reverse=True) and tail[-1] >= cluster.TAIL
    assert max(tail[1:]) <= -(-(1000 - 128 - 125) // 4)
