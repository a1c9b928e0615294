"""Batch scaling, side by side (issue 32): the same generated hearts through ``--jobs 1``,
``--jobs N`` and an N-worker dask LocalCluster, round-robin, one run of each per round.

    python bench/scaling.py [PATHS] [ROUNDS] [WORKERS]   (defaults 2000, 3, 2)

Each run is one ``singcheck run robots/orthoglide.yaml - --format jsonl --no-regions``
process reading the stream on stdin (the projection cache warmed first); paths/s is
the paths over the run's whole wall time (start-up included).  The ratios are taken
within a round (runs next to each other, so a busy spell of a shared machine falls on
all of them alike), and each is quoted as the median and the range over the rounds.
The targets: ``--jobs N`` at least 0.9·N times ``--jobs 1`` (1.8 for N = 2), the
cluster at least 0.9 times ``--jobs N``.  :func:`scaling_rows` is what ``make bench``
prints and writes to bench/results.json.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from generate import write_stream  # noqa: E402
from peak_rss import run_measured  # noqa: E402

JOBS_TARGET = 0.9  # --jobs N against N × --jobs 1 (issue 32: 1.8 on 2 cores)
DASK_TARGET = 0.9  # the cluster against --jobs N at the same worker count


def _run(cmd: list[str], stream: Path, env: dict) -> dict:
    with stream.open("rb") as stdin, tempfile.TemporaryFile() as out:
        start = time.perf_counter()
        code, peak_mb, cpu = run_measured(cmd, cwd=ROOT, env=env, stdin=stdin, stdout=out,
                                          stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - start
        out.seek(0)
        lines = sum(1 for line in out if json.loads(line)["verdict"])
    return {"wall_s": wall, "cpu_s": cpu, "exit_code": code, "lines": lines,
            "peak_rss_mb": peak_mb}


def scaling_rows(paths: int = 2000, rounds: int = 3, workers: int = 2) -> dict:
    """The runs and the per-round ratios: ``{"runs": [...], "ratios": {...}}``."""
    exe = [sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml", "-", "-q",
           "--format", "jsonl", "--no-regions", "--backend", "flint"]
    runners = [("--jobs 1", ["--jobs", "1"]), (f"--jobs {workers}", ["--jobs", str(workers)])]
    cluster = None
    try:
        from distributed import LocalCluster

        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address="127.0.0.1:0")
        runners.append((f"dask {workers} workers", ["--scheduler", cluster.scheduler_address]))
    except ImportError:  # the dask extra is missing: no cluster run
        pass
    runs: list[dict] = []
    try:
        with tempfile.TemporaryDirectory() as tmp:
            env = {**os.environ, "SINGCHECK_CACHE_DIR": tmp}
            subprocess.run([*exe[:5], "trajectories/heart1.yaml", "-q"], cwd=ROOT, env=env,
                           capture_output=True)  # warm the projection cache
            stream = write_stream(Path(tmp) / f"paths-{paths}.yaml", paths)
            for r in range(rounds):
                order = runners[r % len(runners):] + runners[:r % len(runners)]
                for what, extra in order:
                    row = _run([*exe, *extra], stream, env)
                    runs.append({"round": r, "runner": what, "paths": paths,
                                 "paths_per_s": paths / row["wall_s"],
                                 "load_average": os.getloadavg()[0], **row})
    finally:
        if cluster is not None:
            cluster.close()

    def per_round(top: str, bottom: str) -> list[float]:
        rate = {(x["round"], x["runner"]): x["paths_per_s"] for x in runs}
        return [rate[r, top] / rate[r, bottom] for r in range(rounds)
                if (r, top) in rate and (r, bottom) in rate]

    ratios = {f"--jobs {workers} / --jobs 1": per_round(f"--jobs {workers}", "--jobs 1")}
    if cluster is not None:
        ratios[f"dask {workers} workers / --jobs {workers}"] = per_round(
            f"dask {workers} workers", f"--jobs {workers}")
    return {"paths": paths, "rounds": rounds, "workers": workers, "runs": runs,
            "ratios": ratios, "targets": _targets(ratios, workers)}


def _targets(ratios: dict, workers: int) -> list[dict]:
    out = []
    for what, values in ratios.items():
        if not values:
            continue
        goal = JOBS_TARGET * workers if what.endswith("--jobs 1") else DASK_TARGET
        median = statistics.median(values)
        out.append({"target": f"{what} >= {goal:.2f}", "value": median,
                    "min": min(values), "max": max(values), "met": median >= goal})
    return out


def print_scaling(result: dict) -> None:
    print(f"\nbatch scaling: {result['paths']} generated hearts on stdin, jsonl, "
          f"--no-regions, {result['rounds']} rounds, round-robin (wall time: mind the load)")
    for runner in dict.fromkeys(r["runner"] for r in result["runs"]):
        mine = [r for r in result["runs"] if r["runner"] == runner]
        rates = [r["paths_per_s"] for r in mine]
        print(f"  {runner:20} {statistics.median(rates):7.1f} paths/s "
              f"(range {min(rates):.1f}-{max(rates):.1f}), CPU "
              f"{statistics.median(r['cpu_s'] for r in mine):6.2f} s, peak RSS "
              f"{max(r['peak_rss_mb'] for r in mine):6.1f} MB, lines "
              f"{sorted({r['lines'] for r in mine})}")
    for t in result["targets"]:
        print(f"  {'MET    ' if t['met'] else 'NOT MET'}  {t['target']}: median "
              f"{t['value']:.2f} (rounds {t['min']:.2f}-{t['max']:.2f})")
    loads = [r["load_average"] for r in result["runs"]]
    print(f"  load average during the runs: {min(loads):.1f}-{max(loads):.1f} on "
          f"{os.cpu_count()} cores")


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:]]
    print_scaling(scaling_rows(*args))
