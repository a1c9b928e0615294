"""A computation in a forked child that a deadline can stop.

A FLINT call (a factorization, a resultant, a squarefree part) is one C call that no
cooperative :func:`~singcheck.budget.checkpoint` can interrupt, and an allocation that
fails inside GMP aborts the whole process.  :func:`run_forked` computes ``fn(argument)``
in a child made with ``fork`` (it inherits the argument and the loaded libraries;
nothing is re-imported), which sends its pickled result back through a pipe (FLINT
polynomials cross it through :mod:`singcheck.algebra.pickling`), under an address-space
bound and a timeout.  :func:`until_deadline` runs a costly call there with the time left
by the current :func:`~singcheck.budget.deadline`, a cheap one here.  Used by the
in-process backends (:mod:`.isolated`), the path-wise norm chain and the root
isolation's norm over sin t.
"""

from __future__ import annotations

import faulthandler
import os
import pickle
import resource
import select
import signal
import sys
import tempfile
import time

# loaded here, before any fork: a child that imported them itself (ctypes, for
# die_with_parent, above all) spent about 7 ms of a short call's 8 ms doing so
from singcheck.algebra.pickling import register
from singcheck.budget import TimeLimitExceeded, checkpoint, remaining
from singcheck.elimination.cas.guard import die_with_parent, ready_to_fork
from singcheck.elimination.cas.limits import (
    bound_text,
    inherited_limit,
    memory_limit,
    raise_hint,
    under_inherited,
)
from singcheck.errors import BackendError


def _address_space() -> int:
    """This process's current address-space size in bytes (0 when unknown)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _child(fn, argument, write: int, err: int, parent: int, limit: int) -> None:
    """In the forked child: bound, compute, send ``(status, value)`` pickled, exit."""
    try:
        die_with_parent(parent)
        signal.setitimer(signal.ITIMER_REAL, 0)  # the parent's alarm is the parent's
        os.dup2(err, 2)  # what GMP or FLINT print before aborting: for the parent
        # fresh streams: a thread of the parent (a progress display) may have held the
        # old ones' locks at the fork, and it does not exist here to release them
        sys.stdout = sys.stderr = open(2, "w", closefd=False)
        faulthandler.disable()  # an abort here is the parent's to report, in one line
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        if limit:
            bound = under_inherited(_address_space() + limit)
            resource.setrlimit(resource.RLIMIT_AS, (bound, bound))
        register()
        try:
            message = pickle.dumps(("ok", fn(argument)))
        except MemoryError:
            message = pickle.dumps(("memory", None))
        except Exception as e:  # noqa: BLE001 - re-raised in the parent
            try:
                message = pickle.dumps(("raise", e))
            except Exception:  # noqa: BLE001 - an exception that does not pickle
                message = pickle.dumps(("raise", BackendError(f"{type(e).__name__}: {e}")))
        view = memoryview(message)
        while view:
            view = view[os.write(write, view):]
        os._exit(0)
    except MemoryError:
        os._exit(3)
    except BaseException:  # noqa: BLE001 - never return into the parent's code
        os._exit(1)


def run_forked(fn, argument, timeout: float, what: str):
    """``fn(argument)`` computed in a forked child, within ``timeout`` seconds and the
    memory bound; its exceptions are re-raised here."""
    ready_to_fork()
    limit = memory_limit()
    read, write = os.pipe()
    parent = os.getpid()
    with tempfile.TemporaryFile() as err:
        pid = os.fork()
        if pid == 0:
            os.close(read)
            _child(fn, argument, write, err.fileno(), parent, limit)
        os.close(write)
        chunks = []
        try:
            end = time.monotonic() + timeout
            while True:
                left = end - time.monotonic()
                if left <= 0:
                    raise TimeLimitExceeded(
                        f"unknown: time limit ({timeout:g} s, --timeout): {what} did not "
                        "finish and was stopped")
                ready, _, _ = select.select([read], [], [], min(left, 1.0))
                if ready:
                    chunk = os.read(read, 1 << 20)
                    if not chunk:
                        break
                    chunks.append(chunk)
            _, status = os.waitpid(pid, 0)
            pid = 0
        finally:
            os.close(read)
            if pid:
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    pass
                os.waitpid(pid, 0)
        err.seek(0)
        said = err.read(4096).decode("utf-8", errors="replace").strip()
    return _outcome(b"".join(chunks), status, said, limit, what)


def _outcome(message: bytes, status: int, said: str, limit: int, what: str):
    bound = bound_text(limit) + ("" if limit == inherited_limit() else
                                 " (SINGCHECK_MEMORY_LIMIT)")
    try:
        kind, value = pickle.loads(message) if message else (None, None)
    except Exception:  # noqa: BLE001 - a truncated message: the child died writing it
        kind, value = None, None
    if kind == "ok":
        return value
    if kind == "raise":
        raise value
    if kind == "memory" or os.WIFEXITED(status) and os.WEXITSTATUS(status) == 3:
        if not limit:
            raise BackendError(f"{what} ran out of memory (no bound was set: "
                               "SINGCHECK_MEMORY_LIMIT=none)")
        raise BackendError(f"{what} ran out of memory under {bound}; {raise_hint(limit)}")
    how = (f"died of {signal.Signals(os.WTERMSIG(status)).name}" if os.WIFSIGNALED(status)
           else f"exited with status {os.WEXITSTATUS(status)}")
    first = said.splitlines()[0] if said else ""
    if limit and os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGABRT:
        how += f" under {bound}, most likely out of memory"
    elif limit and limit == inherited_limit():
        how += f" under {bound}: {raise_hint(limit)}"
    raise BackendError(f"{what} {how}" + (f": {first[:200]}" if first else ""))


def until_deadline(fn, argument, what: str, costly: bool):
    """``fn(argument)``, stopped at the current :func:`~singcheck.budget.deadline`.

    A ``costly`` call (its caller's size test says it may take longer than the 1 s a
    time limit may be overrun by) under a deadline runs in a forked child killed when
    the deadline passes (:func:`run_forked`): :class:`TimeLimitExceeded`, worded as a
    :func:`~singcheck.budget.checkpoint` words it.  Without a deadline, or when not
    ``costly`` (a fork costs a few milliseconds), it runs in this process."""
    left = remaining()
    if left is None or not costly:
        return fn(argument)
    checkpoint()
    try:
        return run_forked(fn, argument, left, what)
    except TimeLimitExceeded:
        checkpoint()  # past the deadline now: its own message
        raise
