"""μ restricted to the interval engine's windows (``--engine auto``).

Where the interval engine leaves windows (stretches of t on which it could not prove
det A ≠ 0 along some feasible mode), the exact engine decides them.  It first takes μ
on the whole range (:data:`~singcheck.certify.classification.EXACT_WHOLE_RANGE_SECONDS`),
which also corroborates the stretches the intervals proved; past that, it isolates μ's
real roots on the windows alone, each one a closed range of t that holds its window.

What is proven: every real root of μ in each window is isolated and classified as on
the whole range (:func:`~singcheck.roots.isolation.isolate_real_roots` on a sub-range
is the same certified isolation); outside the windows det A ≠ 0 along every feasible
mode was proven by ball arithmetic.  The windows' ends are the search's box ends, read
as floats: each range is widened outward by a relative 2⁻⁴⁰ before it is made exact, so
that no rounding of an end can leave a root of the window outside its range.
"""

from __future__ import annotations

from fractions import Fraction

from singcheck.algebra.trig import LinearInPi, TimeRange
from singcheck.roots.enclosures import RootIsolation

#: outward widening of a window's float ends, relative to max(1, |end|)
WIDEN = 2.0 ** -40


def window_ranges(rng: TimeRange, searches: dict) -> list[TimeRange]:
    """The exact ranges of t that hold every window of every mode in ``searches``
    (the interval engine's :class:`~singcheck.certify.interval_engine.ModeSearch` per
    feasible mode), crossings included: each widened by :data:`WIDEN`, clipped to
    ``rng`` (an end past the range's is the range's own, exact), overlapping ones
    merged, in increasing order."""
    start, end = float(rng.start), float(rng.end)
    spans = []
    for search in searches.values():
        for w in search.windows:
            lo = w.lo - WIDEN * max(1.0, abs(w.lo))
            hi = w.hi + WIDEN * max(1.0, abs(w.hi))
            spans.append((max(lo, start), min(hi, end)))
    merged: list[list[float]] = []
    for lo, hi in sorted(spans):
        if merged and lo <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], hi)
        else:
            merged.append([lo, hi])
    return [TimeRange(rng.start if lo <= start else LinearInPi(Fraction(lo)),
                      rng.end if hi >= end else LinearInPi(Fraction(hi)))
            for lo, hi in merged if lo < hi]


def isolate_on_windows(isolate, ranges: list[TimeRange], note: str) -> RootIsolation:
    """One root isolation from ``isolate(range)`` on each of ``ranges`` (disjoint):
    their roots and undecided stretches together, the method named with ``note``."""
    parts = [isolate(r) for r in ranges]
    method = parts[0].method if parts else "none"
    return RootIsolation(roots=tuple(r for p in parts for r in p.roots),
                         undecided=tuple(u for p in parts for u in p.undecided),
                         method=f"{method}, {note}",
                         exact=tuple(e for p in parts for e in p.exact))
