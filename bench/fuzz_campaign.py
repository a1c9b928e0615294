"""An offline fuzz campaign: tests/test_fuzz.py's properties, run long.

Not part of CI (which runs the same properties at 30 examples each, in seconds).  Each
worker is a pytest process running one fuzz property (round robin) with a large number
of examples, in-process through the API (the robot's projection memoised per text, so
thousands of specs share it), with ``SINGCHECK_FUZZ_KEEP_GOING=1`` (a failing case is
recorded, not shrunk), ``SINGCHECK_FUZZ_SLACK=1`` (a case more than 1 s past its time
limit is a failure) and ``SINGCHECK_FUZZ_BUDGET`` (``--budget``: each case's time
limit; shorter than the CI's 2 s, so more cases run in the time), in a sandbox of its
own: its working directory, ``HOME``, ``TMPDIR`` and cache are in it, so that
afterwards every file in the sandbox that is neither the cache nor a case file is
something written outside the named outputs.  One run in ``--regions-every`` states
the workspace region too (the rest leave it out: it triples a case's cost).  At the
end (``--minutes``, or ``--cases`` reached) the workers are interrupted and their
counts merged::

    nice -n 19 python bench/fuzz_campaign.py --minutes 60 --jobs 1 --out /tmp/campaign

writes ``/tmp/campaign/summary.json`` (cases, exit statuses, cases per property,
failures, the largest overrun of the time limit, stray files) and keeps each run's
failures (``worker-N-R.json.failures``: JSON lines, the specs and the error) for
tests/data/crashes/.  On a shared 2-core machine, under ``nice -n 19`` with other
work running, one worker ran about 10-20 cases a second.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROPERTIES = ["test_structured_and_grammar_trajectories_end_with_exit_0_to_3",
              "test_byte_mutated_specs_end_with_exit_0_to_3",
              "test_paths_of_pieces_end_with_exit_0_to_3"]


def start_worker(n: int, run: int, out: Path, examples: int, budget: float = 1.0,
                 regions_every: int = 4, shared: bool = False) -> subprocess.Popen:
    """Worker slot ``n``'s ``run``-th pytest process: one property (round robin), the
    region statement in one run of ``regions_every`` (0: never)."""
    regions = regions_every > 0 and run % regions_every == 0
    sandbox = out / f"sandbox-{n}"
    for sub in ("home", "tmp", "cases", "cwd"):
        (sandbox / sub).mkdir(parents=True, exist_ok=True)
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)
    env = {**os.environ, "PYTHONPATH": path, "HOME": str(sandbox / "home"),
           "TMPDIR": str(sandbox / "tmp"), "SINGCHECK_FUZZ_DIR": str(sandbox / "cases"),
           "SINGCHECK_FUZZ_EXAMPLES": str(examples), "SINGCHECK_FUZZ_KEEP_GOING": "1",
           "SINGCHECK_FUZZ_SLACK": "1", "SINGCHECK_FUZZ_BUDGET": str(budget),
           "SINGCHECK_FUZZ_SHARED": "1" if shared else "0",
           "SINGCHECK_FUZZ_REGIONS": "1" if regions else "0",
           "SINGCHECK_FUZZ_REPORT": str(out / f"worker-{n}-{run}-{PROPERTIES[run % 3][5:9]}"
                                        f"{'-regions' if regions else ''}.json"),
           "XDG_CONFIG_HOME": str(sandbox / "home" / ".config")}
    env.pop("SINGCHECK_CACHE_DIR", None)
    argv = [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
            "--rootdir", str(ROOT), "-c", str(ROOT / "pyproject.toml"),
            str(ROOT / "tests" / "test_fuzz.py"), "-k", PROPERTIES[run % len(PROPERTIES)]]
    log = open(out / f"worker-{n}.log", "a")  # noqa: SIM115 - closed with the process
    return subprocess.Popen(argv, cwd=sandbox / "cwd", env=env, stdout=log,
                            stderr=subprocess.STDOUT, start_new_session=True)


def strays(sandbox: Path) -> list[str]:
    """Files in a worker's sandbox that are not the cache, a case file, pytest's or
    hypothesis' own: written outside the named outputs."""
    allowed = [sandbox / "cases", sandbox / "home" / ".cache" / "singcheck",
               sandbox / "cwd" / ".hypothesis",  # hypothesis' own constants
               sandbox / "tmp"]  # tmp: pytest's tmp_path_factory (the fuzz cache) only
    out = []
    for path in sandbox.rglob("*"):
        if path.is_file() and not any(a == path or a in path.parents for a in allowed):
            out.append(str(path.relative_to(sandbox)))
    for path in (sandbox / "tmp").iterdir():  # only pytest's own directory there
        if not path.name.startswith("pytest-of-"):
            out.append(str(path.relative_to(sandbox)))
    return out


def cases_so_far(out: Path) -> int:
    """The cases the runs' reports count (each written every 25 cases and at exit)."""
    total = 0
    for report in out.glob("worker-*.json"):
        try:
            total += json.loads(report.read_text()).get("cases", 0)
        except (OSError, ValueError):  # being rewritten
            pass
    return total


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=60)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--examples", type=int, default=1000,
                        help="examples per pytest run (each worker runs the properties "
                             "in turn, a run each, until the time is up)")
    parser.add_argument("--cases", type=int, default=0,
                        help="stop once this many cases have run (0: run --minutes)")
    parser.add_argument("--budget", type=float, default=1.0,
                        help="each case's time limit in seconds (CI: 2)")
    parser.add_argument("--regions-every", type=int, default=4,
                        help="state the workspace region in one run of this many (0: never)")
    parser.add_argument("--shared", action="store_true",
                        help="a machine shared with other work: a case past its time limit "
                             "by more than 1 s of wall clock but not of CPU is counted and "
                             "kept in worker-N-R.json.overruns, not a failure")
    parser.add_argument("--out", type=Path, default=Path("fuzz-campaign"))
    parser.add_argument("--summarize", action="store_true",
                        help="run nothing: merge the reports already in --out (a campaign "
                             "stopped before its end) into its summary.json")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()
    if not args.summarize:
        run_workers(args)
    return summarize(args.out, (time.monotonic() - started) / 60 if not args.summarize
                     else None, args)


def run_workers(args) -> None:
    """The workers, each running the properties in turn, until the time or the cases are
    reached; then interrupted (their counts are written as they exit)."""
    started = time.monotonic()
    runs = [0] * args.jobs

    def start(n: int) -> subprocess.Popen:
        return start_worker(n, runs[n], args.out, args.examples, args.budget,
                            args.regions_every, args.shared)

    workers = [start(n) for n in range(args.jobs)]
    end = started + args.minutes * 60
    while time.monotonic() < end and not (args.cases and cases_so_far(args.out) >= args.cases):
        time.sleep(2)
        for n, w in enumerate(workers):
            if w.poll() is not None:
                runs[n] += 1
                workers[n] = start(n)
    for w in workers:
        if w.poll() is None:
            os.killpg(w.pid, signal.SIGINT)  # pytest stops; the counts are written at exit
    for w in workers:
        try:
            w.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(w.pid, signal.SIGKILL)
            w.wait()



def _stopped(failure: str) -> bool:
    """The case a worker was in when the campaign stopped it (SIGINT: exit 130), as the
    test's assertion words it (with the interruption's own message since issue 32)."""
    return failure.startswith(("AssertionError: 130\n", "AssertionError: 130: "))

def summarize(out: Path, minutes: float | None, args) -> int:
    """Merge the runs' reports in ``out`` into ``out/summary.json`` (printed too); 1 when
    there is a failure or a stray file."""
    total: Counter = Counter()
    per_property: Counter = Counter()
    past, cpu_past = 0, -10**9
    failures = []
    for report in sorted(out.glob("worker-*.json")):
        if report.exists():
            counts = json.loads(report.read_text())
            past = max(past, counts.pop("max ms past the limit", 0))
            cpu_past = max(cpu_past, counts.pop("max ms of CPU past the limit", -10**9))
            total.update(counts)
            per_property[report.stem.split("-", 3)[3]] += counts.get("cases", 0)
        failed = report.with_name(report.name + ".failures")
        if failed.exists():
            failures += [json.loads(line)["error"] for line in failed.read_text().splitlines()]
    # the case each worker was in when the campaign stopped it (SIGINT: exit 130)
    stopped = sum(1 for f in failures if _stopped(f))
    failures = [f for f in failures if not _stopped(f)]
    total["exit 130"] -= stopped
    total["cases"] -= stopped
    summary = {"minutes": None if minutes is None else round(minutes, 1), "jobs": args.jobs,
               "budget s": args.budget, "examples per run": args.examples,
               **{k: v for k, v in sorted(total.items()) if v}, "stopped at the end": stopped,
               "cases per property": dict(sorted(per_property.items())),
               "max ms past the limit": past, "max ms of CPU past the limit": cpu_past,
               "failures": Counter(failures).most_common(),
               "stray files": {p.name: strays(p) for p in sorted(out.glob("sandbox-*"))}}
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    return 1 if failures or any(summary["stray files"].values()) else 0


if __name__ == "__main__":
    sys.exit(main())
