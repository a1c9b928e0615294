"""In-process backends (FLINT, SymPy) run in a forked child, with a time limit and a
memory bound, like a CAS process.

A resultant chain or a Gröbner basis in this process is one long call that no
cooperative :func:`~singcheck.budget.checkpoint` can interrupt, and an allocation that
fails inside GMP aborts the whole process.  :class:`Isolated` runs the backend's
``eliminate`` in a child made with ``fork`` (it inherits the request and the loaded
libraries; nothing is re-imported), which sends its pickled result back through a pipe
(FLINT polynomials cross it through :mod:`singcheck.algebra.pickling`).  The child

* runs under an address-space bound of what the parent had at the fork plus
  :func:`~singcheck.elimination.cas.limits.memory_limit` (``RLIMIT_AS``): past it,
  Python raises ``MemoryError`` or GMP/FLINT abort the child, and singcheck reports a
  backend error (exit 4) in one line;
* is killed after ``timeout`` seconds (``--timeout``, as for a CAS): ``unknown: time
  limit`` (exit 3);
* dies with the thread that forked it, which waits for it (``PR_SET_PDEATHSIG``), so a
  SIGKILLed singcheck leaves no child computing; on Ctrl-C, SIGTERM or SIGHUP it is
  killed and reaped.

A fork costs a few milliseconds, and bringing a large result back through the pipe
tens (the 3-PRR's 24,389-term ξ: about 35 ms, README "Speed"), so a request that
:func:`~singcheck.elimination.requests.proven_small` bounds up front (a norm chain of at
most 10⁶ terms of 1024 bits, its memory count at most half the bound) runs in this
process.  :func:`singcheck.elimination.cas.get_backend` wraps the in-process backends in
:class:`Isolated`; their classes used directly run in this process.
"""

from __future__ import annotations

import os
import signal
import sys
import time

from singcheck.budget import TimeLimitExceeded
from singcheck.elimination.cas.guard import die_with_parent
from singcheck.elimination.cas.limits import (
    bound_text,
    inherited_limit,
    memory_limit,
    raise_hint,
    under_inherited,
)
from singcheck.elimination.requests import EliminationRequest, EliminationResult
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
    import pickle

    try:
        die_with_parent(parent)
        signal.setitimer(signal.ITIMER_REAL, 0)  # the parent's alarm is the parent's
        os.dup2(err, 2)  # what GMP or FLINT print before aborting: for the parent
        # fresh streams: a thread of the parent (a progress display) may have held the
        # old ones' locks at the fork, and it does not exist here to release them
        sys.stdout = sys.stderr = open(2, "w", closefd=False)
        import faulthandler

        faulthandler.disable()  # an abort here is the parent's to report, in one line
        import resource

        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        if limit:
            bound = under_inherited(_address_space() + limit)
            resource.setrlimit(resource.RLIMIT_AS, (bound, bound))
        from singcheck.algebra.pickling import register

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
    import pickle  # noqa: F401 - loaded once here, not in the child
    import select
    import tempfile

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
    import pickle

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


def run_bounded(fn, argument, proven_small: bool, timeout: float, what: str):
    """``fn(argument)`` in this process when ``proven_small`` (an a-priori bound showed
    that its time and memory are far below ``timeout`` and the memory bound: README,
    "Budgets") and ``timeout`` is at least :data:`IN_PROCESS_MIN_TIMEOUT`, else
    :func:`run_forked` — a fork would cost more than such a computation."""
    if proven_small and timeout >= IN_PROCESS_MIN_TIMEOUT:
        return fn(argument)
    return run_forked(fn, argument, timeout, what)


#: Below this ``--timeout`` every request goes to the fork (a proven-small chain took at
#: most about 7 s here even when dense, filling its bound: README, "Budgets").
IN_PROCESS_MIN_TIMEOUT = 60.0


class Isolated:
    """An in-process backend whose eliminations run in a forked child
    (:func:`run_forked`) with ``timeout`` seconds and the memory bound, unless the
    backend proves one small up front (:func:`run_bounded`)."""

    def __init__(self, backend, timeout: float) -> None:
        self.backend = backend
        self.name = backend.name
        self.timeout = timeout

    def version(self) -> str:
        return self.backend.version()

    def eliminate(self, request: EliminationRequest) -> EliminationResult:
        proven = getattr(self.backend, "proven_small", None)
        small = proven is not None and proven(request, memory_limit())
        if not small:
            self.backend.preload(request)  # imported once here, not in every child
        return run_bounded(self.backend.eliminate, request, small, self.timeout,
                           f"the {self.name} backend")
