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

from singcheck.elimination.cas.forked import run_forked
from singcheck.elimination.cas.limits import memory_limit
from singcheck.elimination.requests import EliminationRequest, EliminationResult

__all__ = ["IN_PROCESS_MIN_TIMEOUT", "Isolated", "run_bounded", "run_forked"]


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
