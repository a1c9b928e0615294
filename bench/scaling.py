"""Batch scaling, side by side (issue 32): the same generated hearts through ``--jobs 1``,
``--jobs N`` and an N-worker dask LocalCluster, round-robin, one run of each per round.

    python bench/scaling.py [PATHS] [ROUNDS] [WORKERS]   (defaults 2000, 3, 2)

WORKERS is one count or several, comma-separated (``1,2,4,8,16`` on a 16-core machine:
``--jobs`` at each count, the cluster at the largest).  Each run is one ``singcheck run
robots/orthoglide.yaml - --format jsonl --no-regions`` process reading the stream on
stdin (the projection cache warmed first); paths/s is the paths over the run's whole
wall time (start-up included), and the parent's own CPU seconds are sampled apart from
its workers' (the parent reads and cuts the stream and writes the lines: the part that
does not scale).  The ratios are taken within a round (runs next to each other, so a
busy spell of a shared machine falls on all of them alike), and each is quoted as the
median and the range over the rounds.  The targets: ``--jobs 2`` at least 1.8 times
``--jobs 1``, ``--jobs N`` at least 0.85·N times for more, the cluster at least 0.9
times ``--jobs N``.  :func:`scaling_rows` is what ``make bench`` prints and writes to
bench/results.json; ``bench/many_cores.sh`` is the prepared run for a lent 16-core
machine.
"""

from __future__ import annotations

import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from generate import write_stream  # noqa: E402
from peak_rss import run_measured  # noqa: E402

JOBS_TARGET = 0.85  # --jobs N against N × --jobs 1, up to 16 cores (issue 32)
JOBS_TARGET_2 = 1.8  # --jobs 2 against --jobs 1 (issue 32, on 2 cores)
DASK_TARGET = 0.9  # the cluster against --jobs N at the same worker count


def _run(cmd: list[str], stream: Path, env: dict) -> dict:
    with stream.open("rb") as stdin, tempfile.TemporaryFile() as out:
        start = time.perf_counter()
        parent_cpu = [0.0]
        parent_rss: list[float] = []
        with ThreadPoolExecutor(1) as pool:
            sampled = pool.submit(_sample_parent, parent_cpu, parent_rss)
            code, peak_mb, cpu = run_measured(cmd, cwd=ROOT, env=env, stdin=stdin, stdout=out,
                                              stderr=subprocess.DEVNULL)
            # the run's end, before the sampler's last sleep (up to SAMPLE_S) is waited for
            wall = time.perf_counter() - start
            parent_cpu.append(None)  # stop the sampler
            sampled.result()
        out.seek(0)
        lines = sum(1 for line in out if json.loads(line)["verdict"])
    return {"wall_s": wall, "cpu_s": cpu, "parent_cpu_s": parent_cpu[0], "exit_code": code,
            "lines": lines, "peak_rss_mb": peak_mb,
            "parent_peak_rss_mb": max(parent_rss, default=None)}


class _Cluster:
    """A Dask cluster of its own processes (``dask scheduler``, ``dask worker``), started
    once and warmed by one run, then stopped (SIGSTOP) while the ``--jobs`` runs go and
    resumed (SIGCONT) for its own: a long-lived cluster's warm workers, and none of its
    CPU taken from the other runs.  (A LocalCluster kept in this process, idle during
    the ``--jobs`` runs, took CPU from them: jobs 2 ÷ jobs 1 read 1.59 with it, 1.88
    without; one started per Dask run counted its workers' imports: Dask ÷ jobs 2 read
    0.78 instead of 0.95.)"""

    def __init__(self, workers: int, exe: list[str], stream: Path, env: dict) -> None:
        import socket

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        self.address = f"tcp://127.0.0.1:{port}"
        dask = Path(sys.executable).with_name("dask")
        if dask.exists():
            scheduler, worker = [str(dask), "scheduler"], [str(dask), "worker"]
        else:  # installed without its scripts (pip --target on a lent machine)
            scheduler = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
            worker = [sys.executable, "-m", "distributed.cli.dask_worker"]
        quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                     start_new_session=True, env=env)
        self.procs = [subprocess.Popen([*scheduler, "--host", "127.0.0.1", "--port",
                                        str(port), "--dashboard-address", "127.0.0.1:0"],
                                       **quiet)]
        self.procs.append(subprocess.Popen([*worker, self.address, "--nworkers",
                                            str(workers), "--nthreads", "1",
                                            "--dashboard-address", "127.0.0.1:0"], **quiet))
        self.run(exe, stream, env)  # connect and warm the workers (not recorded)
        self.pause()

    def _signal(self, sig) -> None:
        for p in self.procs:
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:
                pass

    def pause(self) -> None:
        self._signal(signal.SIGSTOP)

    def run(self, exe: list[str], stream: Path, env: dict) -> dict:
        self._signal(signal.SIGCONT)
        try:
            for _ in range(300):  # the workers registered (the first time)
                probe = subprocess.run([sys.executable, "-c", _WORKERS, self.address],
                                       capture_output=True, text=True, env=env)
                if probe.stdout.strip().isdigit() and int(probe.stdout) > 0:
                    break
                time.sleep(0.2)
            return _run([*exe, "--scheduler", self.address], stream, env)
        finally:
            self.pause()

    def close(self) -> None:
        self._signal(signal.SIGCONT)
        self._signal(signal.SIGTERM)
        for p in self.procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)


_WORKERS = ("import sys; from distributed import Client; "
            "c = Client(sys.argv[1], timeout=30); print(len(c.scheduler_info()['workers']));"
            " c.close()")


def _sample_parent(box: list, rss: list) -> None:
    """The CPU seconds (user + system) of the ``singcheck`` process alone, without its
    workers, sampled until ``box`` gets a second item (the last sample before it exits:
    low by at most one period of its work); its resident size (MB) at each sample into
    ``rss``.

    The process is looked for (every 20 ms) until found, then only it is read, every
    SAMPLE_S: walking every child of this process and theirs at each sample (the
    cluster's scheduler, nannies and workers among them) took about a tenth of a core,
    from every run alike but most from the cluster's (2,000 hearts, 2 rounds: Dask 331
    paths/s sampled so, 398 unsampled; ``--jobs 2`` 391 and 453)."""
    try:
        import psutil
    except ImportError:  # no sampling: the row says None
        box[0] = None
        return
    me, found = psutil.Process(), None
    while len(box) == 1:
        try:
            if found is None:
                found = next((proc for launcher in me.children()
                              if "peak_rss.py" in " ".join(launcher.cmdline())
                              for proc in launcher.children()
                              if "singcheck" in proc.cmdline()), None)
            if found is not None:
                t = found.cpu_times()
                box[0] = t.user + t.system
                rss.append(found.memory_info().rss / 2**20)
        except psutil.Error:  # gone between listing and reading
            pass
        time.sleep(0.02 if found is None else SAMPLE_S)


#: seconds between two samples of the command's own CPU time and memory
SAMPLE_S = 0.1


def scaling_rows(paths: int = 2000, rounds: int = 3, workers: int | str = 2) -> dict:
    """The runs and the per-round ratios: ``{"runs": [...], "ratios": {...}}``.
    ``workers``: a count or comma-separated counts (the cluster gets the largest)."""
    counts = sorted({int(w) for w in str(workers).split(",")})
    top = counts[-1]
    exe = [sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml", "-", "-q",
           "--format", "jsonl", "--no-regions", "--backend", "flint"]
    runners = [(f"--jobs {n}", ["--jobs", str(n)]) for n in sorted({1, *counts})]
    try:
        import distributed  # noqa: F401

        runners.append((f"dask {top} workers", None))  # the cluster below
    except ImportError:  # the dask extra is missing: no cluster run
        pass
    runs: list[dict] = []
    cluster = None
    try:
        with tempfile.TemporaryDirectory() as tmp:
            env = {**os.environ, "SINGCHECK_CACHE_DIR": tmp}
            subprocess.run([*exe[:5], "trajectories/heart1.yaml", "-q", *exe[-2:]], cwd=ROOT,
                           env=env, capture_output=True)  # warm the projection cache
            stream = write_stream(Path(tmp) / f"paths-{paths}.yaml", paths)
            if runners[-1][1] is None:
                cluster = _Cluster(top, exe, stream, env)
            for r in range(rounds):
                order = runners[r % len(runners):] + runners[:r % len(runners)]
                for what, extra in order:
                    row = cluster.run(exe, stream, env) if extra is None else \
                        _run([*exe, *extra], stream, env)
                    runs.append({"round": r, "runner": what, "paths": paths,
                                 "paths_per_s": paths / row["wall_s"],
                                 "load_average": os.getloadavg()[0], **row})
    finally:
        if cluster is not None:
            cluster.close()

    def per_round(up: str, down: str) -> list[float]:
        rate = {(x["round"], x["runner"]): x["paths_per_s"] for x in runs}
        return [rate[r, up] / rate[r, down] for r in range(rounds)
                if (r, up) in rate and (r, down) in rate]

    ratios = {f"--jobs {n} / --jobs 1": per_round(f"--jobs {n}", "--jobs 1")
              for n in counts if n > 1}
    if any(extra is None for _, extra in runners):
        ratios[f"dask {top} workers / --jobs {top}"] = per_round(
            f"dask {top} workers", f"--jobs {top}")
    return {"paths": paths, "rounds": rounds, "workers": top if len(counts) == 1 else counts,
            "cores": os.cpu_count(), "runs": runs, "ratios": ratios,
            "targets": _targets(ratios)}


def _targets(ratios: dict) -> list[dict]:
    out = []
    for what, values in ratios.items():
        if not values:
            continue
        n = int(what.split()[1])
        goal = (DASK_TARGET if not what.endswith("--jobs 1")
                else JOBS_TARGET_2 if n == 2 else JOBS_TARGET * n)
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
              f"{statistics.median(r['cpu_s'] for r in mine):6.2f} s (parent "
              f"{_median_or_none([r.get('parent_cpu_s') for r in mine])}), peak RSS "
              f"{max(r['peak_rss_mb'] for r in mine):6.1f} MB, lines "
              f"{sorted({r['lines'] for r in mine})}")
    for t in result["targets"]:
        print(f"  {'MET    ' if t['met'] else 'NOT MET'}  {t['target']}: median "
              f"{t['value']:.2f} (rounds {t['min']:.2f}-{t['max']:.2f})")
    loads = [r["load_average"] for r in result["runs"]]
    print(f"  load average during the runs: {min(loads):.1f}-{max(loads):.1f} on "
          f"{os.cpu_count()} cores")


def _median_or_none(values: list) -> str:
    known = [v for v in values if v is not None]
    return f"{statistics.median(known):.2f} s" if known else "not sampled"


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("paths", type=int, nargs="?", default=2000)
    parser.add_argument("rounds", type=int, nargs="?", default=3)
    parser.add_argument("workers", nargs="?", default="2")
    parser.add_argument("--json", type=Path, help="also write the result here")
    args = parser.parse_args()
    result = scaling_rows(args.paths, args.rounds, args.workers)
    print_scaling(result)
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
