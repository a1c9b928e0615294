"""The balls that the quick feasibility proofs try: pieces covering the range.

A quick proof shows a property of a path's polynomials (a leg's D > 0, a branch inside
its limits) by ball arithmetic on each ball of a cover of the range: :func:`pieces`
cuts the closed range into 6 balls, :func:`halves` splits a ball where the property
is not proven (enclosures tighten as balls shrink), until :func:`budget` evaluations
are spent; then the proof falls back to a root isolation.  On a wide ball a
high-degree polynomial is enclosed through its Fourier form (``tight``).
"""

from __future__ import annotations

import math

from flint import arb

from singcheck.algebra.trig import LinearInPi, TimeRange, uses_t

PIECES = 6
BUDGET = 64  # ball evaluations per 2π of range spent before falling back to a root isolation
TIGHT_ABOVE = 0.05  # radius above which a piece gets tight enclosures (high-degree legs)
TIGHT_DEGREE = 10  # ... when the leg's polynomials have at least this degree in (s, c)


def budget(interval: TimeRange) -> int:
    """The evaluation budget grows with the range: a longer path needs more pieces."""
    periods = (float(interval.end) - float(interval.start)) / (2 * math.pi)
    return max(BUDGET, math.ceil(BUDGET * periods))


def pieces(interval: TimeRange, count: int = PIECES) -> list[arb]:
    """``count`` balls covering the closed range (slightly more at irrational ends)."""
    lo, hi = interval.start.ball().lower(), interval.end.ball().upper()
    step = (hi - lo) / count
    edges = [(lo + step * i).mid() for i in range(count)] + [hi]
    edges[0] = lo
    return [a.union(b) for a, b in zip(edges, edges[1:], strict=False)]


def halves(piece: arb) -> tuple[arb, arb]:
    """The two halves of a ball (their union is the ball)."""
    lo, hi = piece.lower(), piece.upper()
    mid = piece.mid()
    return lo.union(mid), mid.union(hi)


def within_one_period(interval: TimeRange) -> bool:
    """Whether the range is at most 2π long (then it is its own :func:`one_period`)."""
    return float(interval.end) - float(interval.start) <= 2 * math.pi + 1e-9


def one_period(interval: TimeRange, polys, periodic: bool | None = None) -> TimeRange:
    """The part of the range a quick proof about ``polys`` needs to cover (``periodic``:
    whether they are all free of t, when the caller knows).

    Trig polynomials free of the bare t are 2π-periodic, so over a range longer than 2π
    they take no value that they do not take on its first 2π: proving a property of
    their values on [start, start + 2π] proves it on the whole range.
    """
    start = interval.start
    if within_one_period(interval):
        return interval
    if periodic is None:
        periodic = not any(uses_t(p) for p in polys if p is not None)
    if not periodic:
        return interval
    return TimeRange(start, LinearInPi(start.rational, start.pi_coefficient + 2))
