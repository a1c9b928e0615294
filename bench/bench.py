"""make bench: singcheck against its two contenders, same inputs, one process.

Prints tables (contender, median, min, max, times relative to singcheck, right answer?),
says which speed targets the printed run meets, and writes bench/results.json.  On each
path every contender runs round-robin with singcheck (one run of each per round), so a
noisy spell of the machine falls on all of them alike.  The contenders:

* the **certified alternative without elimination** (bench/contender.py): interval
  branch-and-bound over t on det A along each feasible working mode, Merlet's approach,
  with Arb balls; its answers are checked against singcheck's;
* the **sampling check** people use today: det A along the working mode at N points of
  the path (vectorised NumPy), looking for sign changes.  Fast, and it can miss
  singularities.
"""

from __future__ import annotations

import json
import os
import platform
import random
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

#: glibc's malloc thresholds, fixed for the whole bench (it re-executes itself with them).
#: By default glibc raises them only after a large block is freed, so the NumPy scans' 80 kB
#: arrays were given back to the system and faulted in again on every call — or not,
#: depending on what ran earlier in the process (a forked projection, whose large pickle was
#: freed here, made the 10⁴ scan 0.61 ms; an in-process one left it at 0.87 ms).  High
#: thresholds are the scans' best case, and singcheck's own time does not change with
#: them (1.36 against 1.34 ms on heart 1), so every contender runs in one known state that
#: favours the sampling check.
MALLOC_ENV = {"MALLOC_MMAP_THRESHOLD_": "4194304", "MALLOC_TRIM_THRESHOLD_": "67108864"}

if __name__ == "__main__" and any(os.environ.get(k) != v for k, v in MALLOC_ENV.items()):
    os.execve(sys.executable, [sys.executable, *sys.argv], {**os.environ, **MALLOC_ENV})

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from contender import contender  # noqa: E402
from generate import waypoints_yaml, write, write_stream  # noqa: E402
from peak_rss import run_measured  # noqa: E402
from scaling import print_scaling, scaling_rows  # noqa: E402

from singcheck.algebra.radicals import angle_names  # noqa: E402
from singcheck.certify.classification import certify_path  # noqa: E402
from singcheck.certify.path import build_path  # noqa: E402
from singcheck.certify.pieces import certify_trajectory  # noqa: E402
from singcheck.elimination.cas import get_backend  # noqa: E402
from singcheck.elimination.projection import project_robot  # noqa: E402
from singcheck.model.robot import build_model  # noqa: E402
from singcheck.report.plots import numpy_polynomial  # noqa: E402
from singcheck.spec.files import load_robot, load_trajectory, parse_trajectory  # noqa: E402

REPEAT = int(os.environ.get("BENCH_REPEAT", "15"))
#: the engine singcheck is timed with: ``auto``, what ``singcheck run`` does (the interval
#: engine first, the exact one corroborating it; both run on every path below)
ENGINE = os.environ.get("BENCH_ENGINE", "auto")
#: the seed of the rounds' orders (:func:`interleaved`); BENCH_FIXED_ORDER=1 runs every
#: round in the listed order instead, as the bench did before (for comparison)
ROUND_ORDER_SEED = 17
FIXED_ORDER = os.environ.get("BENCH_FIXED_ORDER") == "1"


def times(fn, repeat: int = REPEAT) -> list[tuple[float, float]]:
    """(wall, CPU) seconds of ``repeat`` runs of one contender."""
    return interleaved([fn], repeat)[0]


def cpu_median(ts: list[tuple[float, float]]) -> float:
    return statistics.median(c for _, c in ts)


def _cpu() -> float:
    """CPU seconds used so far by this process and its finished children."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def _round_orders(count: int, repeat: int):
    """Each round's order of the ``count`` contenders: a permutation drawn from a fixed
    seed (the same orders on every run), or the listed order with BENCH_FIXED_ORDER."""
    orders = random.Random(ROUND_ORDER_SEED)
    for _ in range(repeat):
        order = list(range(count))
        if not FIXED_ORDER:
            orders.shuffle(order)
        yield order


def interleaved(fns: list, repeat: int = REPEAT) -> list[list[tuple[float, float]]]:
    """(wall, CPU) seconds of several contenders run round-robin (one run of each per
    round), so that a noisy spell of the machine falls on all of them alike; one list
    per contender.  CPU time counts what the run itself used (a subprocess's too), so
    other developers' processes on the shared cores do not inflate it: the targets
    are judged on it.

    Each round runs the contenders in its own order (a permutation drawn from a fixed
    seed: the same orders on every run), so that none is always timed right after the
    same one.  In a fixed order the 10⁴-point scan always ran right after the 10³-point
    scan, the same code on the same polynomials, which warmed it, and singcheck always
    right after the 10⁵-point scan, whose arrays evicted its code and data from the
    caches: on heart 1 that order made the scan's median 6-10 % lower and singcheck's
    a few % higher than in varied orders (docs/speed.md)."""
    out: list[list[tuple[float, float]]] = [[] for _ in fns]
    for order in _round_orders(len(fns), repeat):
        for i in order:
            cpu, start = _cpu(), time.perf_counter()
            fns[i]()
            out[i].append((time.perf_counter() - start, _cpu() - cpu))
    return out


#: runs of one contender in a row per sample of the per-path table (:func:`in_blocks`)
BLOCK = max(2, int(os.environ.get("BENCH_BLOCK", "5")))


def in_blocks(fns: list, repeat: int = REPEAT, size: int = BLOCK
              ) -> tuple[list[list[tuple[float, float]]], list[list[tuple[float, float]]]]:
    """(warm, cold): per contender, the (wall, CPU) seconds of each block's runs after
    its first (their mean: code and data in the caches, as for every path of a batch but
    the first) and of each block's first run (right after another contender, whose code
    and arrays — the 10⁵-point scan's 800 kB — evicted them: a lone path's case).  A
    block is ``size`` runs of one contender in a row; the blocks go round-robin, each
    round in its own order as in :func:`interleaved`, so a noisy spell of the machine
    falls on all of them alike.  Single runs alone mixed the two cases: on heart 2
    singcheck's median read 1.01x the branch-and-bound's, its warm runs 0.84x
    (docs/speed.md)."""
    warm: list[list[tuple[float, float]]] = [[] for _ in fns]
    cold: list[list[tuple[float, float]]] = [[] for _ in fns]
    for order in _round_orders(len(fns), repeat):
        for i in order:
            runs = []
            for _ in range(size):
                cpu, start = _cpu(), time.perf_counter()
                fns[i]()
                runs.append((time.perf_counter() - start, _cpu() - cpu))
            cold[i].append(runs[0])
            rest = runs[1:]
            warm[i].append((sum(w for w, _ in rest) / len(rest),
                            sum(c for _, c in rest) / len(rest)))
    return warm, cold


def stats(ts: list) -> dict:
    """Medians and extremes; with (wall, CPU) pairs, the CPU ones as ``cpu_*``."""
    if ts and isinstance(ts[0], tuple):
        wall, cpu = [w for w, _ in ts], [c for _, c in ts]
        return {**stats(wall), "cpu_median_s": statistics.median(cpu),
                "cpu_min_s": min(cpu), "cpu_max_s": max(cpu)}
    return {"median_s": statistics.median(ts), "min_s": min(ts), "max_s": max(ts),
            "runs": len(ts)}


# -- the sampling contender -------------------------------------------------------

class SamplingScan:
    """det A along one working mode at n points, vectorised; sign changes are 'found'.

    The robot's ring variables in the model's order: a pose coordinate's value, an
    angle's cos and sin (3-RPR), a prismatic joint's branch (-b ± √D)/(2a), a revolute
    joint's (cos θ, sin θ) branch σ (W cos θ = -a d + σ b √Δ, W sin θ = -b d - σ a √Δ,
    singcheck's labels)."""

    def __init__(self, path, mode_label: str) -> None:
        model = path.projection.model
        names = model.context.names()
        self.nvars = len(names)
        self.range = (float(path.trajectory.range.start), float(path.trajectory.range.end))
        self.pose = [(tuple(names.index(n) for n in angle_names(v)) if v in model.spec.angles
                      else (names.index(v),), numpy_polynomial(p))
                     for v, p in zip(model.pose, path.phi, strict=True)]
        self.legs = [(leg.leg.kind, leg.leg.joint_index,
                      [numpy_polynomial(c) for c in leg.coefficients], sign)
                     for leg, sign in zip(path.legs, mode_label, strict=True)]
        self.det_a = numpy_polynomial(model.det_A)
        # the path's ring: t, s = sin t, c = cos t, then any square root a limit brought
        # in (the 5-bar's pi/3 gives sqrt(3)), a constant
        ring = path.phi[0].context().names()
        self.surds = [float(Fraction(v[5:-1])) ** 0.5 for v in ring[3:]]

    def __call__(self, n: int) -> list[float]:
        t = np.linspace(*self.range, n)
        tsc = [t, np.sin(t), np.cos(t), *(np.full(n, r) for r in self.surds)]
        values = [np.zeros(n)] * self.nvars
        for slots, f in self.pose:
            x = f(tsc)
            if len(slots) == 1:
                values[slots[0]] = x
            else:
                values[slots[0]], values[slots[1]] = np.cos(x), np.sin(x)
        for kind, index, coeffs, sign in self.legs:
            parts = [f(tsc) for f in coeffs]
            if kind == "revolute":
                a, b, d = parts
                w = a * a + b * b
                root = np.sqrt(w - d * d) * (1 if sign == "+" else -1)
                values[index] = (-a * d + b * root) / w
                values[index + 1] = (-b * d - a * root) / w
            elif len(parts) == 2:
                values[index] = -parts[1] / parts[0]
            else:
                a, b, c = parts
                root = np.sqrt(b * b - 4 * a * c)
                values[index] = (-b + (root if sign == "+" else -root)) / (2 * a)
        d = self.det_a(values)
        s = np.sign(d)
        idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
        return list((t[idx] + t[idx + 1]) / 2)


def found_all(found: list[float], truth: list[float], spacing: float) -> bool:
    return len(found) == len(truth) and all(
        any(abs(f - x) <= spacing for f in found) for x in truth)


# -- the runs -------------------------------------------------------------------------

# (robot, trajectory file relative to the repository, label); the long paths are the
# paper's over [-10π, 10π], bench/paths/
PATHS = (("orthoglide", "trajectories/heart1.yaml", "heart 1"),
         ("orthoglide", "trajectories/heart2.yaml", "heart 2"),
         ("orthoglide", "trajectories/helix.yaml", "helix"),
         ("orthoglide", "bench/paths/heart-8h.yaml", "8-harmonic heart"),
         ("orthoglide", "bench/paths/heart1-long.yaml", "heart 1, [-10π, 10π]"),
         ("orthoglide", "bench/paths/heart2-long.yaml", "heart 2, [-10π, 10π]"),
         ("orthoglide", "bench/paths/helix-long.yaml", "helix, [-10π, 10π]"),
         ("biglide", "trajectories/biglide-double-cross.yaml", "biglide, crosses twice"),
         ("biglide", "trajectories/biglide-graze.yaml", "biglide, grazes"),
         ("five-bar", "trajectories/five-bar-cross.yaml", "5-bar, crosses"),
         ("five-bar", "trajectories/five-bar-free.yaml", "5-bar, free"),
         ("3-rpr", "trajectories/3-rpr-cross.yaml", "3-RPR, crosses"),
         ("3-rpr", "trajectories/3-rpr-free.yaml", "3-RPR, free"),
         ("orthoglide", "trajectories/leaves-workspace.yaml", "leaves the workspace"),
         ("orthoglide", "bench/paths/leaves-limits.yaml", "leaves the joint limits"))
SHORT = ("heart 1", "heart 2", "helix", "8-harmonic heart")
LONG = ("heart 1, [-10π, 10π]", "heart 2, [-10π, 10π]", "helix, [-10π, 10π]")
#: issue 27: the bundled 5-bar and 3-RPR paths and the infeasible Orthoglide paths, where
#: singcheck must take at most 1.0x the elimination-free peer (``bench.py peer``)
PEER = ("5-bar, crosses", "5-bar, free", "3-RPR, crosses", "3-RPR, free",
        "leaves the workspace", "leaves the joint limits")


def load(robot: str, trajectory: str, backend: str = "flint"):
    model = build_model(load_robot(ROOT / "robots" / f"{robot}.yaml"))
    projection = project_robot(model, get_backend(backend))
    path = ROOT / trajectory if "/" in trajectory else \
        ROOT / "trajectories" / f"{trajectory}.yaml"
    spec = load_trajectory(path, model.spec)
    return projection, spec


def truth_of(report, mode: str) -> list[float]:
    return [float(c.t.mid()) for c in report.candidates if mode in c.singular_modes]


def agrees(answer, report, tolerance: float = 1e-9) -> bool:
    """The contender's answer is singcheck's: same verdict, same feasible modes, and in
    each of them the same singular times (balls within a few tolerances)."""
    feasible = [m.label for m in report.modes if m.feasible]
    if answer.verdict != report.verdict or sorted(answer.feasible) != sorted(feasible):
        return False
    for mode in feasible:
        ours = sorted(answer.singular_times.get(mode, []), key=lambda b: b.mid())
        theirs = truth_of(report, mode)
        if len(ours) != len(theirs) or any(abs(float(a.mid()) - b) > 4 * tolerance
                                           for a, b in zip(ours, theirs, strict=True)):
            return False
    return True


def compare(robot: str, trajectory: str, label: str, backends: bool = True) -> list[dict]:
    """singcheck, the branch-and-bound contender and the sampling scans on one path (and,
    on heart 1 with ``backends``, singcheck with each CAS's projection)."""
    projection, spec = load(robot, trajectory)
    model = projection.model
    report = certify_path(build_path(projection, spec, ENGINE))
    answer = contender(model, spec)
    mode = next((m.label for m in report.modes if m.feasible), None)
    truth = truth_of(report, mode) if mode is not None else []
    sizes = (10**3, 10**4, 10**5)
    if mode is None:  # an infeasible path: no working mode to scan along
        print(f"{label}: no feasible working mode ({report.verdict}): no sampling scan")
        scan, sizes = None, ()
    else:
        scan = SamplingScan(build_path(projection, spec), mode)
        width = scan.range[1] - scan.range[0]
    # each run of singcheck and of the peer gets the path read anew (its own polynomial
    # objects): what either caches per path object must not carry over to the next run,
    # as it does not from one path of a batch to the next
    source = ROOT / trajectory if "/" in trajectory else \
        ROOT / "trajectories" / f"{trajectory}.yaml"
    ours, theirs = (iter([load_trajectory(source, model.spec)
                          for _ in range(REPEAT * BLOCK)]) for _ in range(2))
    timings, cold = in_blocks([lambda: certify_path(build_path(projection, next(ours), ENGINE)),
                               lambda: contender(model, next(theirs)),
                               *[lambda n=n: scan(n) for n in sizes]])
    right = agrees(answer, report)
    case = {"case": label, "path": f"{robot}/{Path(trajectory).stem}"}
    rows = [{**case, "contender": "singcheck (certified)", **stats(timings[0]),
             "found": report.verdict != "unknown", "verdict": report.verdict,
             "singular_times": truth},
            {**case, "contender": "branch-and-bound (certified)", **stats(timings[1]),
             "found": right, "verdict": answer.verdict, "boxes": answer.boxes,
             "agrees_with_singcheck": right}]
    for n, ts in zip(sizes, timings[2:], strict=True):
        found = scan(n)
        rows.append({**case, "contender": f"NumPy sampling, {n:.0e}", **stats(ts),
                     "found": found_all(found, truth, 2 * width / (n - 1)),
                     "sign_changes": len(found)})
    if backends and (robot, Path(trajectory).stem) == ("orthoglide", "heart1"):
        rows += [{**case, **r} for r in backend_rows(projection.model, spec, truth)]
    for row, ts in zip(rows, cold, strict=False):  # (the backend rows: no cold runs)
        row["cold_cpu_median_s"] = cpu_median(ts)
    base, base_cold = rows[0]["cpu_median_s"], rows[0]["cold_cpu_median_s"]
    for row in rows:
        own = row.get("cpu_median_s", row["median_s"])
        row["ratio_to_singcheck"] = own / base
        row["singcheck_over_it"] = base / own
        if "cold_cpu_median_s" in row:
            row["cold_ratio_to_singcheck"] = row["cold_cpu_median_s"] / base_cold
    return rows


def backend_rows(model, spec, truth) -> list[dict]:
    """singcheck on each backend, projection included (no cache): the whole certificate."""
    rows = []
    for name in ("flint", "singular", "macaulay2", "sympy"):
        try:
            backend = get_backend(name)
        except Exception:  # a missing CAS: no row (the projection table says why)
            continue

        def once(backend=backend):
            return certify_path(build_path(project_robot(model, backend), spec, ENGINE))

        report = once()
        mode = next(m.label for m in report.modes if m.feasible)
        rows.append({"contender": f"singcheck + {name} projection",
                     **stats(times(once, 3 if name == "sympy" else REPEAT)),
                     "found": truth_of(report, mode) == truth, "verdict": report.verdict})
    return rows


def projection_rows() -> list[dict]:
    model = build_model(load_robot(ROOT / "robots" / "orthoglide.yaml"))
    rows = []
    for name in ("flint", "singular", "macaulay2", "sympy"):
        try:
            backend = get_backend(name)
        except Exception as e:  # a missing CAS is a row, not a crash
            rows.append({"backend": name, "error": str(e)})
            continue
        repeat = 3 if name == "sympy" else REPEAT
        rows.append({"backend": name, **stats(times(lambda b=backend: project_robot(model, b),
                                                    repeat))})
    return rows


def space_rows() -> list[dict]:
    """Workspace / joint-space analyses (issue 6): decomposition, counts, regions."""
    from fractions import Fraction

    from singcheck.spaces.analysis import (
        JOINTSPACE,
        WORKSPACE,
        analyse,
        jointspace_variety,
        select_surfaces,
        workspace_variety,
    )

    backend = get_backend("flint")
    rows = []
    for robot, space, fixed in (("orthoglide", WORKSPACE, {}),
                                ("orthoglide", WORKSPACE, {"z": Fraction(1)}),
                                ("orthoglide", JOINTSPACE, {}),
                                ("orthoglide", JOINTSPACE, {"rho3": Fraction(2)}),
                                ("skew-biglide", WORKSPACE, {}),
                                ("linear-delta", JOINTSPACE, {"r3": Fraction(-1)})):
        model = build_model(load_robot(ROOT / "robots" / f"{robot}.yaml"))
        components = (workspace_variety(project_robot(model, backend)) if space == WORKSPACE
                      else jointspace_variety(model, backend))
        free = len(model.pose) - len(fixed)
        components, _ = select_surfaces(components, space, "auto", free)
        last = {}

        def work(model=model, space=space, components=components, fixed=fixed, last=last):
            last["a"] = analyse(space, model, components, fixed)

        ts = times(work, 3)
        a = last["a"]
        where = ", ".join(f"{k}={v}" for k, v in fixed.items()) or "full"
        rows.append({"robot": robot, "space": space, "slice": where, "cells": len(a.cells),
                     "regions": None if a.regions is None else len(a.regions.regions),
                     "counts": sorted({c.count for c in a.cells if c.within_limits},
                                      key=lambda c: -1 if c is None else c),
                     **{k: round(v, 4) for k, v in a.timings.items()}, **stats(ts)})
    return rows


def cli_rows() -> list[dict]:
    exe = [sys.executable, "-m", "singcheck"]
    # warm: the elimination cache filled and Python's bytecode cache written, as after any
    # first run of an installed singcheck (so PYTHONDONTWRITEBYTECODE is not passed on)
    base_env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as cache:
        env = {**base_env, "SINGCHECK_CACHE_DIR": cache}
        args = [*exe, "run", "robots/orthoglide.yaml", "trajectories/heart1.yaml",
                "--format", "json"]
        flint_only = [sys.executable, "-c", "import flint"]
        for cmd in (args, flint_only):
            subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True)  # warm
        warm, bare = interleaved([
            lambda: subprocess.run(args, cwd=ROOT, env=env, capture_output=True),
            lambda: subprocess.run(flint_only, cwd=ROOT, env=env, capture_output=True)])
        with tempfile.TemporaryDirectory() as out:
            paths = write(Path(out), 1000)
            cmd = [*exe, "run", "robots/orthoglide.yaml", *map(str, paths), "-q",
                   "--format", "json", "--jobs", str(os.cpu_count() or 1)]
            start = time.perf_counter()
            batch = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
            batch_s = time.perf_counter() - start
    verdicts: dict[str, int] = {}
    for t in json.loads(batch.stdout)["trajectories"]:
        verdicts[t["verdict"]] = verdicts.get(t["verdict"], 0) + 1
    return [{"what": "singcheck run orthoglide heart1 --format json, warm, whole process",
             **stats(warm)},
            {"what": "python -c 'import flint', same rounds", **stats(bare)},
            {"what": f"1000 heart-like trajectories, --jobs {os.cpu_count()}",
             "median_s": batch_s, "min_s": batch_s, "max_s": batch_s, "runs": 1,
             "verdicts": verdicts}]


def _timed_run(cmd: list[str], stdin_path: Path, env: dict) -> dict:
    """One singcheck process: wall time, the jsonl lines it streamed, its verdicts, and
    the CPU seconds and peak resident memory of it and its forked workers (measured from
    a small launcher, bench/peak_rss.py: a child of this big process would report at
    least this process's size; a Dask cluster's workers are not its children: their CPU
    is not counted)."""
    with stdin_path.open("rb") as stdin, tempfile.TemporaryFile() as out:
        start = time.perf_counter()
        code, peak_mb, cpu = run_measured(cmd, cwd=ROOT, env=env, stdin=stdin, stdout=out,
                                          stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - start
        out.seek(0)
        verdicts: dict[str, int] = {}
        for line in out:
            v = json.loads(line)["verdict"]
            verdicts[v] = verdicts.get(v, 0) + 1
    return {"wall_s": wall, "cpu_s": cpu, "exit_code": code, "verdicts": verdicts,
            "peak_rss_mb": peak_mb}


#: issue 32's side-by-side scaling run: paths, rounds, workers (BENCH_SCALING=2000,3,2)
SCALING = tuple(int(n) for n in os.environ.get("BENCH_SCALING", "2000,3,2").split(","))
BATCH_COUNTS = tuple(int(n) for n in os.environ.get("BENCH_BATCH", "1000,10000").split(","))
BATCH_TARGET = 200  # paths per second, 10,000 paths with --no-regions (issue 15)
FLAT_MB = 10  # "memory flat": peak RSS grows less than this from the fewest paths to the most


def batch_rows(counts=BATCH_COUNTS) -> list[dict]:
    """Generated heart-like paths streamed through one command (stdin, --format jsonl,
    --no-regions): --jobs 2, and a 2-worker dask LocalCluster (process workers, loopback).
    Each row is one run (a 10,000-path run is long enough to time once; repeating it
    would make `make bench` take many minutes); peak memory at 1,000 and 10,000 paths
    shows whether it stays flat."""
    exe = [sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml", "-", "-q",
           "--format", "jsonl", "--no-regions", "--backend", "flint"]
    rows = []
    cluster = None
    try:
        from distributed import LocalCluster

        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address="127.0.0.1:0")
    except ImportError:  # the dask extra is missing: no cluster rows
        pass
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "SINGCHECK_CACHE_DIR": tmp}
        subprocess.run([*exe[:5], "trajectories/heart1.yaml", "-q"], cwd=ROOT, env=env,
                       capture_output=True)  # warm the projection cache
        for n in counts:
            stream = write_stream(Path(tmp) / f"paths-{n}.yaml", n)
            runs = [("--jobs 2", ["--jobs", "2"])]
            if cluster is not None:
                runs.append(("2-worker LocalCluster", ["--scheduler",
                                                       cluster.scheduler_address]))
            for what, extra in runs:
                row = _timed_run([*exe, *extra], stream, env)
                rows.append({"what": f"{n} paths, jsonl, {what}", "runner": what,
                             "paths": n, "paths_per_s": n / row["wall_s"], **row})
    if cluster is not None:
        cluster.close()
    return rows


def batch_targets(rows: list[dict]) -> list[dict]:
    """The batch targets on this run: throughput of the largest batch, per runner, and
    memory flat from the smallest batch to the largest."""
    out = []
    for runner in dict.fromkeys(r["runner"] for r in rows):
        mine = sorted((r for r in rows if r["runner"] == runner), key=lambda r: r["paths"])
        small, large = mine[0], mine[-1]
        out.append({"target": f"{large['paths']} paths, {runner}: >= {BATCH_TARGET} paths/s",
                    "value": large["paths_per_s"],
                    "met": large["paths_per_s"] >= BATCH_TARGET})
        if large is not small:
            growth = large["peak_rss_mb"] - small["peak_rss_mb"]
            out.append({"target": f"{runner}: peak RSS grows < {FLAT_MB} MB from "
                                  f"{small['paths']} to {large['paths']} paths",
                        "value": growth, "met": growth < FLAT_MB})
    return out


def print_batch(rows: list[dict]) -> None:
    print("\nbatches: generated heart-like paths on stdin, --format jsonl --no-regions, one "
          "run each (wall time: mind the machine's load)")
    for r in rows:
        print(f"  {r['what']:42} {r['wall_s']:8.2f} s  {r['paths_per_s']:7.1f} paths/s  "
              f"CPU {r['cpu_s']:7.2f} s  "
              f"peak RSS {r['peak_rss_mb']:6.1f} MB  exit {r['exit_code']}  {r['verdicts']}")
    for g in batch_targets(rows):
        print(f"  {'MET    ' if g['met'] else 'NOT MET'}  {g['target']}: {g['value']:.1f}")


def growth_rows() -> list[dict]:
    """Certification time per trajectory, singcheck and the branch-and-bound contender
    round-robin, as the path gains harmonics; then robots of growing size."""
    rows = []
    model = build_model(load_robot(ROOT / "robots" / "orthoglide.yaml"))
    projection = project_robot(model, get_backend("flint"))
    with tempfile.TemporaryDirectory() as out:
        for k in range(1, 9):
            paths = write(Path(out) / str(k), 3, harmonics=k, seed=k)
            specs = [load_trajectory(p, model.spec) for p in paths]
            # every run reads its 3 paths anew (as compare() does)
            mine, peers = (iter([[load_trajectory(p, model.spec) for p in paths]
                                 for _ in range(9)]) for _ in range(2))
            ours, theirs = interleaved(
                [lambda m=mine: [certify_path(build_path(projection, s, ENGINE))
                                 for s in next(m)],
                 lambda p=peers: [contender(model, s) for s in next(p)]], 9)
            reports = [certify_path(build_path(projection, s, ENGINE)) for s in specs]
            answers = [contender(model, s) for s in specs]
            right = sum(agrees(a, r) for a, r in zip(answers, reports, strict=True))
            # the contender's unknown (a graze, a limit touched at a singular point) is no
            # disagreement of two certificates: count it apart
            undecided = sum(a.verdict == "unknown" != r.verdict
                            for a, r in zip(answers, reports, strict=True))
            rows.append({"axis": "harmonics", "size": k,
                         "mu_degree": max(int(build_path(projection, s).mu.total_degree())
                                 for s in specs),  # (auto's report may hold no μ)
                         "median_s": cpu_median(ours) / 3,
                         "contender_median_s": cpu_median(theirs) / 3,
                         "contender_agrees": f"{right}/3" + (f", {undecided} unknown to it"
                                                             if undecided else "")})
    for robot, trajectory in (("skew-biglide", "skew-biglide-ellipse"),
                              ("orthoglide", "heart1"),
                              ("stacked-orthoglide", "stacked-heart")):
        m = build_model(load_robot(ROOT / "robots" / f"{robot}.yaml"))
        backend = get_backend("flint")
        proj_t = times(lambda m=m, backend=backend: project_robot(m, backend), 3)
        projection = project_robot(m, backend)
        spec = load_trajectory(ROOT / "trajectories" / f"{trajectory}.yaml", m.spec)
        cert_t = times(lambda p=projection, s=spec: certify_path(build_path(p, s, ENGINE)), 3)
        rows.append({"axis": "robot", "size": len(m.joints), "robot": robot,
                     "trajectory": trajectory,
                     "xi_degree": int(projection.singularity_surface.total_degree()),
                     "projection_s": cpu_median(proj_t),
                     "median_s": cpu_median(cert_t)})
    return rows


def peer_targets(paths: list[dict]) -> list[dict]:
    """Issue 27: on the bundled 5-bar and 3-RPR paths and the infeasible Orthoglide
    paths, singcheck's CPU median at most 1.0x the elimination-free peer's (the
    branch-and-bound, same rounds); the peer's agreement is said alongside."""
    out = []
    for label in PEER:
        mine = {r["contender"]: r for r in paths if r["case"] == label}
        if not mine:
            continue
        ours, peer = mine["singcheck (certified)"], mine["branch-and-bound (certified)"]
        ratio = ours["cpu_median_s"] / peer["cpu_median_s"]
        out.append({"target": f"{label}: singcheck <= 1.0x the branch-and-bound",
                    "value": ratio, "limit": 1.0, "met": ratio <= 1.0,
                    "peer_agrees": peer["agrees_with_singcheck"]})
    return out


def targets(paths: list[dict], cli: list[dict], growth: list[dict]) -> list[dict]:
    """Issue 17's speed targets, checked on the figures of this run (the growth rows:
    singcheck's median per trajectory over the branch-and-bound's, same rounds)."""
    def median(label: str, contender: str) -> float:
        return next(r["cpu_median_s"] for r in paths
                    if r["case"] == label and r["contender"] == contender)

    out = []
    for label in SHORT + LONG:
        limit = 1.0 if label in SHORT else 0.5
        ratio = median(label, "singcheck (certified)") / median(
            label, "branch-and-bound (certified)")
        out.append({"target": f"{label}: singcheck <= {limit}x the branch-and-bound",
                    "value": ratio, "limit": limit, "met": ratio <= limit})
    for label in ("biglide, crosses twice", "biglide, grazes"):  # issue 32: every path
        ratio = median(label, "singcheck (certified)") / median(
            label, "branch-and-bound (certified)")
        out.append({"target": f"{label}: singcheck <= 1.0x the branch-and-bound",
                    "value": ratio, "limit": 1.0, "met": ratio <= 1.0})
    out += peer_targets(paths)
    ratio = median("heart 1", "singcheck (certified)") / median("heart 1",
                                                                "NumPy sampling, 1e+04")
    out.append({"target": "heart 1: singcheck <= 2x the 10^4-point NumPy scan",
                "value": ratio, "limit": 2.0, "met": ratio <= 2.0})
    out.append({"target": "heart 1: singcheck <= 1.5x the 10^4-point NumPy scan (issue 32)",
                "value": ratio, "limit": 1.5, "met": ratio <= 1.5})
    ratio = cli[0]["cpu_median_s"] / cli[1]["cpu_median_s"]
    out.append({"target": "warm CLI run <= 2.5x python -c 'import flint'",
                "value": ratio, "limit": 2.5, "met": ratio <= 2.5})
    for r in growth:
        if r["axis"] == "harmonics":
            ratio = r["median_s"] / r["contender_median_s"]
            out.append({"target": f"growth, harmonics {r['size']} (3 generated paths): "
                                  "singcheck <= 1.0x the branch-and-bound",
                        "value": ratio, "limit": 1.0, "met": ratio <= 1.0})
    return out


def spline_rows() -> list[dict]:
    """A 100-waypoint natural cubic spline through the Orthoglide's workspace: reading it
    (the exact spline) and certifying its 99 pieces, wall-clock and CPU seconds."""
    model = build_model(load_robot(ROOT / "robots" / "orthoglide.yaml"))
    projection = project_robot(model, get_backend("flint"))
    text = waypoints_yaml(100)
    walls, cpus, report = [], [], None
    for _ in range(max(3, REPEAT // 3)):
        wall, cpu = time.perf_counter(), time.process_time()
        report = certify_trajectory(projection, parse_trajectory(text, "spline-100.yaml",
                                                                 model.spec))
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return [{"case": "orthoglide/spline-100 (99 cubic pieces)", **stats(walls),
             "cpu_median_s": statistics.median(cpus), "verdict": report.verdict,
             "candidates": len(report.candidates)}]


#: issue 27: 2000-row CSV tables of poses (bench/csv_paths.py), default options
LONG_CSV = ("bench/paths/heart-2000.csv", "bench/paths/circle-drift-2000.csv")
LONG_CSV_TARGET = 10.0  # seconds of wall-clock time per path, 2 cores, default options


def long_csv_rows(runs: int = 3) -> list[dict]:
    """Each long CSV through ``singcheck run robots/orthoglide.yaml PATH --format json``
    (default options: cubic spline, --engine auto, regions), ``runs`` times, the files
    alternating: wall-clock and CPU seconds of the whole process, its verdict and what
    backed it (the corroboration's status and how many pieces the exact engine saw)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    out: dict[str, dict] = {p: {"walls": [], "cpus": []} for p in LONG_CSV}
    for _ in range(runs):
        for path in LONG_CSV:
            cmd = [sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml", path,
                   "--format", "json"]
            with tempfile.TemporaryFile() as stdout:
                start = time.perf_counter()
                code, _, cpu = run_measured(cmd, cwd=ROOT, env=env, stdout=stdout,
                                            stderr=subprocess.DEVNULL)
                wall = time.perf_counter() - start
                stdout.seek(0)
                (doc,) = json.loads(stdout.read())["trajectories"]
            row = out[path]
            row["walls"].append(wall)
            row["cpus"].append(cpu)
            row.update(exit_code=code, verdict=doc["verdict"],
                       corroboration=doc["corroboration"]["status"],
                       detail=doc["corroboration"]["detail"][:300])
    return [{"case": path, **stats(r.pop("walls")), "cpu_median_s": statistics.median(
        r.pop("cpus")), "target_s": LONG_CSV_TARGET, **r} for path, r in out.items()]


def print_long_csv(rows: list[dict]) -> None:
    print("\nlong CSV paths (issue 27): singcheck run, default options, whole process")
    for r in rows:
        met = "met" if r["median_s"] <= r["target_s"] else "NOT met"
        print(f"  {r['case']:38} median {r['median_s']:6.2f} s wall ({met}: "
              f"{r['target_s']:g} s), {r['cpu_median_s']:6.2f} s CPU; {r['verdict']}, "
              f"corroboration {r['corroboration']}")


#: issue 12's robots: (robot, its paths, target per path in seconds, projection cached)
ROBOT_PATHS = (
    ("five-bar", ("five-bar-cross", "five-bar-free"), 0.050),
    ("3-rpr", ("3-rpr-cross", "3-rpr-free"), 0.050),
    ("3-prr", ("3-prr-cross", "3-prr-free"), 0.050),
    ("linear-delta", ("linear-delta-cross", "linear-delta-free"), 0.200),
    ("rotary-delta", ("rotary-delta-cross", "rotary-delta-free"), 0.200),
    ("gough-stewart", ("gough-stewart-translate", "gough-stewart-rotate"), 5.0),
)


def robot_rows() -> list[dict]:
    """Certification time per path of each bundled robot of issue 12 (flint, in-process):
    with the projection cached (done once, as ``run`` does from its cache) and not cached
    (projection included: its elimination as a user's run does it, in this process when
    an a-priori bound proves it small, else in a forked child; and, for comparison, with
    the backend called directly, never forked)."""
    from singcheck.elimination.cas.flint_backend import FlintBackend

    rows = []
    for robot, paths, target in ROBOT_PATHS:
        model = build_model(load_robot(ROOT / "robots" / f"{robot}.yaml"))
        backend = get_backend("flint")
        projection = project_robot(model, backend)
        repeat = max(3, REPEAT // 3) if robot == "gough-stewart" else REPEAT
        for name in paths:
            spec = load_trajectory(ROOT / "trajectories" / f"{name}.yaml", model.spec)
            report = certify_path(build_path(projection, spec, ENGINE))
            cached, uncached, unforked = interleaved(
                [lambda p=projection, s=spec: certify_path(build_path(p, s, ENGINE)),
                 *(lambda s=spec, m=model, b=b: certify_path(
                     build_path(project_robot(m, b), s, ENGINE))
                   for b in (backend, FlintBackend()))],
                repeat)
            c, u = stats(cached), stats(uncached)
            rows.append({"robot": robot, "trajectory": name, "verdict": report.verdict,
                         "target_s": target, "cached": c, "uncached": u,
                         "uncached_no_fork": stats(unforked),
                         "met": max(c["cpu_median_s"], u["cpu_median_s"]) <= target})
    return rows


def robot_lines(rows: list[dict]) -> list[str]:
    """One line per bundled robot and path: CPU medians cached and not cached, the target
    (a path, projection included or not) and whether this run met it."""
    out = [f"  {'robot':14} {'trajectory':24} {'verdict':17} {'cached ms':>9} "
           f"{'not cached':>10} {'(no fork)':>9} {'target ms':>9}  met?"]
    for r in rows:
        c, u = r["cached"]["cpu_median_s"], r["uncached"]["cpu_median_s"]
        n = r["uncached_no_fork"]["cpu_median_s"]
        out.append(f"  {r['robot']:14} {r['trajectory']:24} {r['verdict']:17} {ms(c)} "
                   f" {ms(u)} {ms(n)} {ms(r['target_s'])}  {'yes' if r['met'] else 'NO'}")
    return out


def machine() -> dict:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
            "platform": platform.platform()}


def ms(x: float) -> str:
    return f"{1000 * x:9.2f}"


def print_paths(rows: list[dict]) -> None:
    print(f"{'path':24} {'contender':32} {'CPU ms':>9} {'min CPU':>9} {'wall ms':>9} "
          f"{'vs singcheck':>12} {'cold CPU ms':>11} {'cold vs':>8}  right answer?")
    for r in rows:
        right = "yes" if r["found"] else "NO"
        if "verdict" in r and r["contender"] != "singcheck (certified)":
            right += f" ({r['verdict']})"
        elif "verdict" in r:
            right += f" ({r['verdict']}, {len(r['singular_times'])} singular times)"
        cold = (f"{ms(r['cold_cpu_median_s']):>11} {r['cold_ratio_to_singcheck']:7.2f}x"
                if "cold_cpu_median_s" in r else f"{'':11} {'':8}")
        print(f"{r['case']:24} {r['contender']:32} {ms(r['cpu_median_s'])} "
              f"{ms(r['cpu_min_s'])} {ms(r['median_s'])} {r['ratio_to_singcheck']:11.2f}x"
              f" {cold}  {right}")
    print(f"(each sample: a block of {BLOCK} runs of one contender in a row, blocks "
          "round-robin; CPU and wall: medians over the blocks of the mean of each block's "
          "runs after its first (warm caches, as for the paths of a batch); cold: the "
          "median of the blocks' first runs, right after another contender; vs singcheck: "
          "its median CPU time / singcheck's; right answer: singcheck decided; "
          "branch-and-bound: same verdict and singular times as singcheck; sampling: sign "
          "changes at exactly singcheck's singular times)")


def main() -> None:
    order = "every round in the listed order" if FIXED_ORDER else \
        f"each round in its own order (seed {ROUND_ORDER_SEED})"
    results = {"machine": machine(), "repeat": REPEAT, "round_order": order}
    print(f"machine: {results['machine']['cpu']}, {results['machine']['cores']} cores, "
          f"Python {results['machine']['python']}, load average {os.getloadavg()[0]:.1f} "
          f"at the start; medians of {REPEAT} round-robin runs (per path: of {REPEAT} "
          f"rounds of blocks of {BLOCK} runs), {order}; glibc malloc "
          "thresholds fixed high (the sampling scans' best case)\n")
    results["paths"] = rows = []
    for robot, trajectory, label in PATHS:
        rows += compare(robot, trajectory, label)
    print_paths(rows)
    results["robots"] = robots = robot_rows()
    print(f"\nbundled robots (issue 12): certification per path, flint, CPU medians of "
          f"{REPEAT} round-robin runs (children's CPU included), projection cached / not "
          "cached (its elimination as run does it: in this process when proven small, "
          "else in a forked child; no fork: the backend called directly, for comparison); "
          "met: cached and not cached within the target")
    print("\n".join(robot_lines(robots)))
    results["spline"] = spline = spline_rows()
    print("\nwaypoints: read and certify, whole path (spline built exactly)")
    for r in spline:
        print(f"  {r['case']:42} median {ms(r['median_s'])} ms wall, "
              f"{ms(r['cpu_median_s'])} ms CPU; {r['verdict']}, {r['candidates']} candidates")
    results["long_csv"] = long_csv = long_csv_rows()
    print_long_csv(long_csv)
    results["projection"] = proj = projection_rows()
    print("\nprojection of the Orthoglide (ξ, workspace and joint-limit surfaces), no cache")
    for r in proj:
        if "error" in r:
            print(f"  {r['backend']:10} unavailable: {r['error']}")
        else:
            print(f"  {r['backend']:10} median CPU {ms(r['cpu_median_s'])} ms  wall "
                  f"{ms(r['median_s'])} ms")
    results["spaces"] = spaces = space_rows()
    print("\nworkspace / joint-space analysis (in-process, flint backend, median of 3)")
    for r in spaces:
        regions = "" if r["regions"] is None else f", {r['regions']} regions"
        print(f"  {r['robot']:13} {r['space']:10} {r['slice']:8} {r['cells']:4} cells"
              f"{regions}, counts {r['counts']}: median {ms(r['median_s'])} ms "
              f"(CAD {ms(r['decomposition_s'])}, counts {ms(r['counting_s'])}, regions "
              f"{ms(r['regions_s'])})")
    results["command_line"] = cli = cli_rows()
    print("\ncommand line")
    for r in cli:
        cpu = f"median CPU {ms(r['cpu_median_s'])} ms, " if "cpu_median_s" in r else ""
        print(f"  {r['what']:66} {cpu}wall {ms(r['median_s'])} ms" +
              (f"  {r['verdicts']}" if "verdicts" in r else ""))
    results["batch"] = batch = batch_rows()
    results["batch_targets"] = batch_targets(batch)
    print_batch(batch)
    results["scaling"] = scaling = scaling_rows(*SCALING)
    print_scaling(scaling)
    from user_inputs import print_rows
    from user_inputs import rows as input_rows

    results["user_inputs"] = inputs = input_rows()
    print_rows(inputs)
    results["growth"] = growth = growth_rows()
    print("\ngrowth: certification CPU time per trajectory (projection cached), singcheck and "
          "the branch-and-bound round-robin")
    for r in growth:
        if r["axis"] == "harmonics":
            print(f"  harmonics {r['size']}: μ degree {r['mu_degree']:4}  singcheck "
                  f"{ms(r['median_s'])} ms  branch-and-bound {ms(r['contender_median_s'])} ms"
                  f" ({r['median_s'] / r['contender_median_s']:.2f}x)"
                  f"  (agrees with singcheck on {r['contender_agrees']})")
        else:
            print(f"  {r['robot']:20} {r['size']} joints, ξ degree {r['xi_degree']:3}: "
                  f"projection {ms(r['projection_s'])} ms, certify {ms(r['median_s'])} ms")
    print("  path length, [-10π, 10π] over [-π, π] (or the helix's [0, 20]):")
    for short, long in zip(SHORT, LONG, strict=False):
        def med(label, who):
            return next(r["cpu_median_s"] for r in rows
                        if r["case"] == label and r["contender"] == who)
        print(f"    {short:8} singcheck {med(long, 'singcheck (certified)') / med(short, 'singcheck (certified)'):5.2f}x"  # noqa: E501
              f"  branch-and-bound {med(long, 'branch-and-bound (certified)') / med(short, 'branch-and-bound (certified)'):5.2f}x")  # noqa: E501
    results["targets"] = goals = targets(rows, cli, growth)
    print("\ntargets (issue 17), on this run:")
    for g in goals:
        print(f"  {'MET    ' if g['met'] else 'NOT MET'}  {g['target']}: {g['value']:.2f}x")
    met = sum(g["met"] for g in goals)
    print(f"  {met} of {len(goals)} targets met")
    out = ROOT / "bench" / "results.json"
    out.write_text(json.dumps(results, indent=2) + "\n")
    print(f"\nwritten: {out.relative_to(ROOT)}")


def batch_only() -> None:
    """``python bench/bench.py batch``: only the batch rows, merged into results.json."""
    out = ROOT / "bench" / "results.json"
    results = json.loads(out.read_text()) if out.exists() else {"machine": machine()}
    results["batch"] = batch_rows()
    results["batch_targets"] = batch_targets(results["batch"])
    print_batch(results["batch"])
    out.write_text(json.dumps(results, indent=2) + "\n")


def long_csv_only() -> None:
    """``python bench/bench.py csv``: only the long CSV rows, merged into results.json."""
    out = ROOT / "bench" / "results.json"
    results = json.loads(out.read_text()) if out.exists() else {"machine": machine()}
    results["long_csv"] = long_csv_rows()
    print_long_csv(results["long_csv"])
    out.write_text(json.dumps(results, indent=2) + "\n")


def scaling_only() -> None:
    """``python bench/bench.py scaling``: only the scaling rounds, merged into
    results.json."""
    out = ROOT / "bench" / "results.json"
    results = json.loads(out.read_text()) if out.exists() else {"machine": machine()}
    results["scaling"] = scaling_rows(*SCALING)
    print_scaling(results["scaling"])
    out.write_text(json.dumps(results, indent=2) + "\n")


def user_inputs_only() -> None:
    """``python bench/bench.py inputs``: only the inputs issue 27 listed as refused or
    stalled, merged into results.json."""
    from user_inputs import print_rows, rows

    out = ROOT / "bench" / "results.json"
    results = json.loads(out.read_text()) if out.exists() else {"machine": machine()}
    results["user_inputs"] = rows()
    print_rows(results["user_inputs"])
    out.write_text(json.dumps(results, indent=2) + "\n")


def peer_only() -> None:
    """``python bench/bench.py peer``: singcheck against the elimination-free peer and
    the sampling scans on issue 27's paths (5-bar, 3-RPR, infeasible Orthoglide) and
    heart 1 (without its per-backend rows); the rows merged into results.json's "paths"
    (a row of the same path and contender replaced), the targets into "peer_targets"."""
    print(f"load average {os.getloadavg()[0]:.2f} at the start; medians of {REPEAT} "
          "round-robin runs\n")
    rows = []
    for robot, trajectory, label in PATHS:
        if label in PEER or label == "heart 1":
            rows += compare(robot, trajectory, label, backends=False)
    print_paths(rows)
    goals = peer_targets(rows)
    print("\ntargets (issue 27), on this run:")
    for g in goals:
        print(f"  {'MET    ' if g['met'] else 'NOT MET'}  {g['target']}: {g['value']:.2f}x"
              f"  (peer agrees with singcheck: {'yes' if g['peer_agrees'] else 'NO'})")
    print(f"  {sum(g['met'] for g in goals)} of {len(goals)} targets met; load average "
          f"{os.getloadavg()[0]:.2f} at the end")
    out = ROOT / "bench" / "results.json"
    results = json.loads(out.read_text()) if out.exists() else {"machine": machine()}
    # a row replaces the one of the same path and contender (heart 1's backend rows,
    # not rerun here, stay)
    new = {(r["case"], r["contender"]) for r in rows}
    results["paths"] = [r for r in results.get("paths", [])
                        if (r["case"], r["contender"]) not in new] + rows
    results["peer_targets"] = goals
    out.write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    if sys.argv[1:] == ["batch"]:
        batch_only()
    elif sys.argv[1:] == ["csv"]:
        long_csv_only()
    elif sys.argv[1:] == ["scaling"]:
        scaling_only()
    elif sys.argv[1:] == ["inputs"]:
        user_inputs_only()
    elif sys.argv[1:] == ["peer"]:
        peer_only()
    else:
        main()
