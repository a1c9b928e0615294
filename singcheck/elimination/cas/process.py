"""The one funnel through which every external program is started.

``run_program`` starts the program in its own session (so in its own process group),
feeds it nothing on stdin, captures stdout and stderr, and enforces a wall-clock
timeout.  On timeout, on Ctrl-C, or on any other interruption the *whole group* is
killed and reaped, so no zombie or stray child (a CAS forks helpers) outlives the call.
Building the argv is the callers' job (pure functions in each adapter).
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from dataclasses import dataclass

from singcheck.errors import BackendError


class BackendTimeout(BackendError):
    """The program ran past its wall-clock budget and was killed with its process group."""


@dataclass(frozen=True)
class ProgramRun:
    argv: tuple[str, ...]
    returncode: int
    stdout: str
    stderr: str
    seconds: float


def _kill_group(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.communicate(timeout=5)
    except (subprocess.TimeoutExpired, ValueError, OSError):
        pass


def run_program(argv: list[str] | tuple[str, ...], timeout: float, *,
                cwd: str | None = None, env: dict[str, str] | None = None) -> ProgramRun:
    """Run ``argv`` to completion (or kill its group after ``timeout`` seconds)."""
    start = time.monotonic()
    try:
        proc = subprocess.Popen(list(argv), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, cwd=cwd, env=env, text=True,
                                encoding="utf-8", errors="replace", start_new_session=True)
    except OSError as e:
        raise BackendError(f"could not start {argv[0]}: {e.strerror or e}") from None
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill_group(proc)
        raise BackendTimeout(
            f"{os.path.basename(argv[0])} did not finish within {timeout:g} s and was "
            "stopped (raise --timeout if the robot is large)") from None
    except BaseException:
        _kill_group(proc)
        raise
    # the leader is done; make sure helpers it left in its group go too
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    return ProgramRun(tuple(argv), proc.returncode, stdout, stderr, time.monotonic() - start)
