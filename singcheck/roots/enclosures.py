"""What a root isolation returns, and where a root lies against the range ends.

:class:`RealRoot` is a ball in t proven to hold exactly one root (refinable on demand),
:class:`Undecided` a ball where nothing could be proven (with the reason), and
:class:`RootIsolation` the whole answer with the method used.  ``inside_range`` and
``locate_root`` place a root against range ends linear in π, exactly where they can.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction

from flint import arb

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.trig import LinearInPi, TimeRange
from singcheck.errors import SingcheckError
from singcheck.roots.rational import (
    bits_for,
)

EXACT = "exact univariate"


HALF_ANGLE = "tangent half-angle"


BRANCH_AND_BOUND = "interval branch-and-bound"


class IdenticallyZeroError(SingcheckError):
    """The function is identically zero along the path: it has no isolated roots."""


#: kinds of :class:`ExactTime`
IN_T, IN_U, AT_POINT = "t", "u", "point"


@dataclass(frozen=True)
class ExactTime:
    """A root's time as an exact algebraic number, for exact decisions at that root.

    * ``IN_T``: t = α, the root of a squarefree polynomial in t isolated by a rational
      interval (polynomial paths);
    * ``IN_U``: t = 2·atan(α) + 2kπ, α the root of a squarefree polynomial in
      u = tan(t/2) isolated by a rational interval (paths in sin t, cos t only), so
      s = 2α/(1+α²) and c = (1-α²)/(1+α²);
    * ``AT_POINT``: s and c are exact rationals (t = kπ), and so is t when it is 0
      (``t_value``); ``None`` means t is a non-zero multiple of π (not rational).

    ``locate()`` returns the :class:`~singcheck.roots.rational.RationalRoot` of α (its
    squarefree polynomial and isolating interval): built lazily, since only the roots
    that ball arithmetic could not decide need it.
    """

    kind: str
    locate: Callable[[], tuple] | None = field(default=None, compare=False, repr=False)
    s: Fraction | None = None
    c: Fraction | None = None
    t_value: Fraction | None = None


def point_time(t: Fraction | None, s: int, c: int) -> ExactTime:
    """The exact time of a root at t = kπ (s, c in {0, ±1}; t rational only when 0)."""
    return ExactTime(AT_POINT, None, Fraction(s), Fraction(c), t)


@dataclass(frozen=True)
class RealRoot:
    t: arb  # holds exactly one root in the range
    multiplicity: int | None  # exact where the method knows it
    _refine: Callable[[float], arb] | None = field(default=None, compare=False, repr=False)
    # (i, k): this root is exactly the method's i-th root of a 2π-periodic function
    # shifted by 2kπ (tangent half-angle roots); None when not known to be one
    period: tuple[int, int] | None = field(default=None, compare=False)
    exact: ExactTime | None = field(default=None, compare=False, repr=False)

    def refined(self, tolerance: float) -> RealRoot:
        """The same root in a ball of width at most ``tolerance`` (when refinable)."""
        if self._refine is None or 2 * float(self.t.rad()) <= tolerance:
            return self
        return RealRoot(self._refine(tolerance), self.multiplicity, self._refine,
                        period=self.period, exact=self.exact)


@dataclass(frozen=True)
class Undecided:
    t: arb
    reason: str


@dataclass(frozen=True)
class RootIsolation:
    roots: tuple[RealRoot, ...]
    undecided: tuple[Undecided, ...]
    method: str

    @property
    def certified(self) -> bool:
        return not self.undecided


def _relation(t: arb, exact: LinearInPi | None, end: LinearInPi, bits: int) -> int | None:
    """-1 if t < end, 0 if t == end, +1 if t > end (proven), None if not decided."""
    if exact is not None and exact == end:
        return 0
    with working_precision(bits):
        e = end.ball()
        if t.is_exact() and e.is_exact() and t == e:
            return 0
        if t < e:
            return -1
        if t > e:
            return 1
    return None


def inside_range(t: arb, exact: LinearInPi | None, interval: TimeRange, bits: int) -> bool | None:
    a = _relation(t, exact, interval.start, bits)
    b = _relation(t, exact, interval.end, bits)
    if a is None or b is None:
        return None
    return a >= 0 and b <= 0


def locate_root(make_ball: Callable[[float], arb], exact: LinearInPi | None,
            interval: TimeRange, tolerance: float) -> tuple[bool | None, arb]:
    """Refine a root until it is proven inside or outside the range (or give up)."""
    tol = tolerance
    for _ in range(8):
        t = make_ball(tol)
        where = inside_range(t, exact, interval, bits_for(tol))
        if where is not None:
            return where, t
        tol /= 1e6
    return None, make_ball(tol)
