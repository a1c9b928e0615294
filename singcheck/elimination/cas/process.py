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
killed and reaped before ``run_program`` returns.  (Only SIGKILL of singcheck itself
leaves nothing to clean up with.)  Building the argv is the callers' job (pure
functions in each adapter).
"""

from __future__ import annotations

import os
import signal
import subprocess
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from singcheck.errors import BackendError

#: What a program may print on stdout and on stderr (each); beyond it, it is stopped.
MAX_OUTPUT_BYTES = 64 * 2**20
_PR_SET_CHILD_SUBREAPER = 36


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


_SUBREAPER: list[bool] = []


def _become_subreaper() -> bool:
    """Make this process the reaper of its orphaned descendants (once; Linux only)."""
    if not _SUBREAPER:
        ok = False
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            ok = libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
        except (OSError, AttributeError):
            ok = False
        _SUBREAPER.append(ok)
    return _SUBREAPER[0]


def _children() -> set[int]:
    """The pids whose parent is this process (from /proc; empty where there is none)."""
    me = os.getpid()
    out = set()
    try:
        entries = os.listdir("/proc")
    except OSError:
        return out
    for name in entries:
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat[stat.rfind(b")") + 2:].split()
        if len(fields) > 1 and int(fields[1]) == me:
            out.add(int(name))
    return out


def _reap_strays(known: set[int]) -> None:
    """Kill and reap the children that are not ``known`` and not in our own process
    group: descendants of the program that outlived it (re-parented to us because we
    are their subreaper), including those that called setsid."""
    own_group = os.getpgid(0)
    for _ in range(100):  # each round reaps one generation of re-parented descendants
        strays = []
        for pid in _children() - known:
            try:
                if os.getpgid(pid) != own_group:
                    strays.append(pid)
            except OSError:
                continue
        if not strays:
            return
        for pid in strays:
            for kill in (os.killpg, os.kill):
                try:
                    kill(pid, signal.SIGKILL)
                except OSError:
                    pass
        for pid in strays:
            try:
                os.waitpid(pid, 0)
            except OSError:
                pass


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
    f.seek(0)
    return f.read(limit).decode("utf-8", errors="replace")


def run_program(argv: list[str] | tuple[str, ...], timeout: float, *,
                cwd: str | None = None, env: dict[str, str] | None = None) -> ProgramRun:
    """Run ``argv`` to completion (or kill its group after ``timeout`` seconds, or once
    it has printed more than :data:`MAX_OUTPUT_BYTES` on stdout or stderr)."""
    start = time.monotonic()
    name = os.path.basename(argv[0])
    reaper = _become_subreaper()
    known = _children() if reaper else set()
    with _terminate_as_interrupt(), tempfile.TemporaryFile() as out, \
            tempfile.TemporaryFile() as err:
        try:
            proc = subprocess.Popen(list(argv), stdin=subprocess.DEVNULL, stdout=out,
                                    stderr=err, cwd=cwd, env=env, start_new_session=True)
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
            if reaper:
                _reap_strays(known)
        return ProgramRun(tuple(argv), proc.returncode, _read(out, MAX_OUTPUT_BYTES),
                          _read(err, MAX_OUTPUT_BYTES), time.monotonic() - start)


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
