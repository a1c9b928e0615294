"""Peak resident memory of a command, measured from a small launcher.

A child's ``ru_maxrss`` (wait4, RUSAGE_CHILDREN) keeps the high-water mark of the
process it was forked from: Linux carries it across ``execve``.  A command started
straight from a big process (a bench that has loaded NumPy, a pytest run hundreds of
tests in) therefore reports at least that process's size, and growth below it is
invisible.  So the command is started from this script, a fresh interpreter of a few
MB: what it reads back from RUSAGE_CHILDREN is the peak of the command and of the
workers it forked (the largest of them) and their CPU seconds.

    python bench/peak_rss.py REPORT CMD ARGS...   (REPORT gets 'maxrss_kb utime stime')
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path


def run_measured(cmd: list[str], **popen) -> tuple[int, float, float]:
    """Run ``cmd`` (Popen keyword arguments pass through: stdin, stdout, env, cwd) from
    the launcher: its exit status, peak RSS in MB and CPU seconds (user + system)."""
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "rusage"
        code = subprocess.run([sys.executable, __file__, str(report), *cmd],
                              check=False, **popen).returncode
        maxrss_kb, utime, stime = report.read_text().split()
    return code, int(maxrss_kb) / 1024, float(utime) + float(stime)


def main() -> None:
    import resource

    report, cmd = sys.argv[1], sys.argv[2:]
    code = subprocess.run(cmd, check=False).returncode
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    Path(report).write_text(f"{usage.ru_maxrss} {usage.ru_utime} {usage.ru_stime}\n")
    os._exit(code if code >= 0 else 128 - code)


if __name__ == "__main__":
    main()
