"""Time budgets: a deadline that long computations check cooperatively.

``with deadline(seconds, "what"):`` sets a wall-clock limit for the work inside it;
the loops whose length depends on the input (root isolation, branch-and-bound,
working-mode proofs, cell decompositions) call :func:`checkpoint`, which raises
:class:`TimeLimitExceeded` once the limit has passed.  The caller turns that into an
``unknown: time limit`` answer, so a hostile or unlucky input ends with a reason
instead of hanging.  Without a deadline, :func:`checkpoint` costs one lookup.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from singcheck.errors import SingcheckError

_DEADLINE: ContextVar[tuple[float, float] | None] = ContextVar("singcheck_deadline",
                                                               default=None)


class TimeLimitExceeded(SingcheckError):
    """The work ran past its time limit; the answer is unknown, not wrong."""


@contextmanager
def deadline(seconds: float | None, spent: float = 0.0) -> Iterator[None]:
    """Limit the work inside to ``seconds`` of wall-clock time, ``spent`` of which have
    already gone to an earlier stage of the same work (None: no limit; an outer, earlier
    deadline still applies)."""
    if seconds is None:
        yield
        return
    end = time.monotonic() + seconds - spent
    outer = _DEADLINE.get()
    if outer is not None and outer[0] < end:
        end, seconds = outer
    token = _DEADLINE.set((end, seconds))
    try:
        yield
    finally:
        _DEADLINE.reset(token)


def remaining() -> float | None:
    """Seconds left before the current deadline (0 when past it; None: no deadline)."""
    limit = _DEADLINE.get()
    return None if limit is None else max(0.0, limit[0] - time.monotonic())


def checkpoint() -> None:
    """Raise :class:`TimeLimitExceeded` when the current deadline has passed."""
    limit = _DEADLINE.get()
    if limit is not None and time.monotonic() > limit[0]:
        raise TimeLimitExceeded(f"time limit ({limit[1]:g} s) reached")
