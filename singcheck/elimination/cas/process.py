"""The one funnel through which every external program is started.

``run_program`` starts the program in its own session (so in its own process group),
feeds it nothing on stdin, captures stdout and stderr, and enforces a wall-clock
timeout and a bound on what it may print.  On timeout, on Ctrl-C, on SIGTERM or SIGHUP,
or on any other interruption the *whole group* is killed and reaped, so no zombie or
stray child (a CAS forks helpers) outlives the call.

A descendant that leaves the group (``setsid``) would escape a group kill: singcheck
makes itself a *child subreaper* (Linux ``PR_SET_CHILD_SUBREAPER``), so such a process
is re-parented to singcheck when its parent dies instead of to init, and every child of
singcheck outside singcheck's own process group that appeared during the call is
killed and reaped before ``run_program`` returns.

SIGKILL of singcheck itself leaves it nothing to clean up with: so the program is
started through :mod:`~singcheck.elimination.cas.guard`, a small process that the kernel
signals when the thread of singcheck that started it exits (``PR_SET_PDEATHSIG``; that
thread is the one waiting here, in the main thread as in a worker thread), and that
then kills the program, its group and its setsid'd descendants (it is their subreaper
too).  The guard also bounds the program's address space (``RLIMIT_AS``,
:func:`~singcheck.elimination.cas.limits.memory_limit`), so that a Gröbner basis that
blows up ends with an allocation failure, reported as a backend error, instead of
waking the kernel's OOM killer.
Building the argv is the callers' job (pure functions in each adapter).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from singcheck.elimination.cas.guard import (
    EXEC_FAILED,
    EXEC_FAILED_MARK,
    PR_SET_CHILD_SUBREAPER,
    SCRIPT,
    children,
    prctl,
    reap_children,
)
from singcheck.elimination.cas.limits import memory_limit
from singcheck.errors import BackendError

#: What a program may print on stdout and on stderr (each); beyond it, it is stopped.
MAX_OUTPUT_BYTES = 64 * 2**20


class BackendTimeout(BackendError):
    """The program ran past its wall-clock budget and was killed with its process group."""


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP arrived while a program ran: handled like Ctrl-C (the program's
    group is killed, temporary files removed, exit status 130)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


@dataclass(frozen=True)
class ProgramRun:
    argv: tuple[str, ...]
    returncode: int
    stdout: str
    stderr: str
    seconds: float
    memory_limit: int = 0  # the bound on its address space, in bytes (0: none)


_SUBREAPER: list[bool] = []
#: the programs (their guards) running now, from any thread: not another call's strays
_RUNNING: set[int] = set()
_STARTING = threading.Lock()  # held while a program starts and while strays are reaped


def _become_subreaper() -> bool:
    """Make this process the reaper of its orphaned descendants (once; Linux only)."""
    if not _SUBREAPER:
        _SUBREAPER.append(prctl(PR_SET_CHILD_SUBREAPER, 1))
    return _SUBREAPER[0]


def _reap_strays(known: set[int]) -> None:
    """Kill and reap the children that are not ``known`` and not in our own process
    group: descendants of the program that outlived it (re-parented to us because we
    are their subreaper), including those that called setsid."""
    own_group = os.getpgid(0)

    def keep(pid: int) -> bool:
        try:
            return pid in known or pid in _RUNNING or os.getpgid(pid) == own_group
        except OSError:
            return True  # gone already

    with _STARTING:
        reap_children(keep)


def _guarded(argv: list[str] | tuple[str, ...], limit: int, scratch: str = "") -> list[str]:
    """``argv`` started through :mod:`~singcheck.elimination.cas.guard` (a fresh
    interpreter that dies with this thread and takes the program's descendants with it,
    and ``scratch``, a directory, too); ``argv`` itself where there is no interpreter or
    script file to run (a frozen or zipped install)."""
    if not sys.executable or not os.path.isfile(SCRIPT):
        return list(argv)
    return [sys.executable, "-I", "-S", SCRIPT, str(os.getpid()), str(limit), scratch,
            "--", *argv]


def _kill_group(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.wait(timeout=5)
    except (subprocess.TimeoutExpired, OSError):
        pass


@contextmanager
def _terminate_as_interrupt() -> Iterator[None]:
    """While a program runs, SIGTERM and SIGHUP raise :class:`Terminated` (like Ctrl-C)
    instead of ending the process on the spot, so the group kill and the removal of
    temporary files still happen.  A handler someone else installed is left alone."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, _frame):
        raise Terminated(signum)

    previous = {}
    for sig in (signal.SIGTERM, signal.SIGHUP):
        if signal.getsignal(sig) == signal.SIG_DFL:
            previous[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _read(f, limit: int) -> str:
    """Up to ``limit`` bytes of the file, as text; a buffer of its size, not of ``limit``
    (256 MiB at once was a MemoryError under a small ``ulimit -v``)."""
    f.seek(0)
    size = os.fstat(f.fileno()).st_size
    return f.read(min(limit, size)).decode("utf-8", errors="replace")


def run_program(argv: list[str] | tuple[str, ...], timeout: float, *,
                cwd: str | None = None, env: dict[str, str] | None = None,
                scratch: str = "") -> ProgramRun:
    """Run ``argv`` to completion (or kill its group after ``timeout`` seconds, or once
    it has printed more than :data:`MAX_OUTPUT_BYTES` on stdout or stderr).
    ``scratch``: the program's temporary directory (``singcheck-*``), which its guard
    removes should this process be killed (SIGKILL) before it can."""
    start = time.monotonic()
    name = os.path.basename(argv[0])
    reaper = _become_subreaper()
    known = children() if reaper else set()
    limit = memory_limit()
    with _terminate_as_interrupt(), tempfile.TemporaryFile() as out, \
            tempfile.TemporaryFile() as err:
        try:
            with _STARTING:
                proc = subprocess.Popen(_guarded(argv, limit, scratch), stdin=subprocess.DEVNULL,
                                        stdout=out, stderr=err, cwd=cwd, env=env,
                                        start_new_session=True)
                _RUNNING.add(proc.pid)
        except OSError as e:
            raise BackendError(f"could not start {argv[0]}: {e.strerror or e}") from None
        try:
            _wait(proc, out, err, start + timeout, name, timeout)
        except BaseException:
            _kill_group(proc)
            raise
        finally:
            # the leader is done (or killed); its helpers in the group go too, and so does
            # any descendant that left the group
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            _RUNNING.discard(proc.pid)
            if reaper:
                _reap_strays(known)
        stderr = _read(err, MAX_OUTPUT_BYTES)
        if proc.returncode == EXEC_FAILED and stderr.startswith(EXEC_FAILED_MARK):
            reason = stderr[len(EXEC_FAILED_MARK):].strip().splitlines()[0]
            raise BackendError(f"could not start {reason}")
        return ProgramRun(tuple(argv), proc.returncode, _read(out, MAX_OUTPUT_BYTES),
                          stderr, time.monotonic() - start, limit)


def _wait(proc: subprocess.Popen, out, err, end: float, name: str, timeout: float) -> None:
    """Wait for ``proc``, polling (1 ms, doubling to 50 ms) its output size and the clock."""
    interval = 0.001
    while True:
        try:
            proc.wait(timeout=max(0.0, min(interval, end - time.monotonic())))
            return
        except subprocess.TimeoutExpired:
            pass
        if time.monotonic() >= end:
            raise BackendTimeout(f"{name} did not finish within {timeout:g} s and was "
                                 "stopped (raise --timeout if the robot is large)")
        if max(os.fstat(out.fileno()).st_size, os.fstat(err.fileno()).st_size) > \
                MAX_OUTPUT_BYTES:
            raise BackendError(f"{name} printed more than {MAX_OUTPUT_BYTES // 2**20} MiB "
                               "and was stopped")
        interval = min(interval * 2, 0.05)
