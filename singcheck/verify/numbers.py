"""Rigorous interval arithmetic on exact integers: every interval is a pair of integers
(lo, hi) standing for [lo/2^P, hi/2^P]; every operation rounds outward (floor for lo,
ceiling for hi), so the true value always lies inside.  Square roots are bounded by
integer square roots (exact: ``math.isqrt``), sin and cos by Taylor series with their
remainder, π by fifty published digits.  No floats take part in a bound.

>>> x = Iv.q(Fraction(1, 3))
>>> (x * 3).contains(1)
True
>>> s = sin(Iv.q(Fraction(1, 2)))
>>> s.lo <= Iv.q(Fraction(479425538604203, 10**15)).lo <= s.hi
True
"""

from __future__ import annotations

import math
from fractions import Fraction

P = 96  # fraction bits of every bound
ONE = 1 << P
GUARD = 20  # extra bits inside the sin/cos series


def _floor(num: int, den: int) -> int:
    return (num * ONE) // den


def _ceil(num: int, den: int) -> int:
    return -((-num * ONE) // den)


class NotDecided(ArithmeticError):
    """An operation whose answer the enclosures cannot give (division by an interval
    holding 0, the square root of one reaching below 0)."""


class Iv:
    __slots__ = ("lo", "hi")

    def __init__(self, lo: int, hi: int) -> None:
        self.lo, self.hi = lo, hi

    @staticmethod
    def q(x) -> Iv:
        """The tightest enclosure of the rational ``x``."""
        x = Fraction(x)
        return Iv(_floor(x.numerator, x.denominator), _ceil(x.numerator, x.denominator))

    def __repr__(self) -> str:
        return f"[{self.lo / ONE!r}, {self.hi / ONE!r}]"

    def __add__(self, o) -> Iv:
        o = _iv(o)
        return Iv(self.lo + o.lo, self.hi + o.hi)

    __radd__ = __add__

    def __neg__(self) -> Iv:
        return Iv(-self.hi, -self.lo)

    def __sub__(self, o) -> Iv:
        o = _iv(o)
        return Iv(self.lo - o.hi, self.hi - o.lo)

    def __rsub__(self, o) -> Iv:
        return _iv(o) - self

    def __mul__(self, o) -> Iv:
        o = _iv(o)
        p = (self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi)
        return Iv(min(p) >> P, -((-max(p)) >> P))

    __rmul__ = __mul__

    def recip(self) -> Iv:
        if self.lo <= 0 <= self.hi:
            raise NotDecided("division by an interval holding 0")
        return Iv((ONE * ONE) // self.hi, -((-ONE * ONE) // self.lo))

    def __truediv__(self, o) -> Iv:
        return self * _iv(o).recip()

    def __pow__(self, n: int) -> Iv:
        if n == 0:
            return Iv(ONE, ONE)
        lo, hi = self.lo, self.hi
        if max(abs(lo), abs(hi)).bit_length() * n > 200_000:
            raise NotDecided("a power too large")
        if n % 2 == 0:
            if lo >= 0:
                a, b = lo, hi
            elif hi <= 0:
                a, b = -hi, -lo
            else:
                a, b = 0, max(-lo, hi)
        else:
            a, b = lo, hi
        scale = ONE ** (n - 1)
        return Iv(a ** n // scale, -((-(b ** n)) // scale))

    def sqrt(self) -> Iv:
        if self.lo < 0:
            raise NotDecided("square root of an interval reaching below 0")
        top = self.hi * ONE
        r = math.isqrt(top)
        return Iv(math.isqrt(self.lo * ONE), r if r * r == top else r + 1)

    def positive(self) -> bool:
        return self.lo > 0

    def negative(self) -> bool:
        return self.hi < 0

    def sign(self) -> int:
        """+1 or -1 when the whole interval has that sign, else 0."""
        return 1 if self.lo > 0 else -1 if self.hi < 0 else 0

    def contains(self, x) -> bool:
        x = Iv.q(x)
        return self.lo <= x.lo and x.hi <= self.hi

    def hull(self, o: Iv) -> Iv:
        return Iv(min(self.lo, o.lo), max(self.hi, o.hi))


def _iv(x) -> Iv:
    return x if isinstance(x, Iv) else Iv.q(x)


#: π to fifty decimals (any table of π; e.g. OEIS A000796): π ∈ [PI_50, PI_50 + 10^-50]
PI_50 = 314159265358979323846264338327950288419716939937510
PI = Iv(_floor(PI_50, 10 ** 50), _ceil(PI_50 + 1, 10 ** 50))


def _series(v: int) -> tuple[Iv, Iv]:
    """sin and cos of the point v/2^P, |v/2^P| ≤ 1, by their Taylor series, computed with
    GUARD more bits: each term is off by ≤ 4 units (2 per step, halved by the next one),
    and the tail (alternating, decreasing: at most the first term left out, < 1 unit)
    is added to the bound."""
    q = P + GUARD
    one = 1 << q
    x = v << GUARD
    x2 = (x * x) >> q
    sums, steps = [], 0
    for term, k in ((x, 1), (one, 0)):  # sin starts at x, cos at 1
        total = 0
        while term != 0:
            total += term
            term = -((term * x2) >> q) // ((k + 1) * (k + 2))
            k += 2
            steps += 1
        sums.append(total)
    err = 5 * steps + 10  # each term is off by ≤ 4 units (the errors shrink as they go)
    return tuple(Iv((s - err) >> GUARD, -((-(s + err)) >> GUARD)) for s in sums)


def sincos_point(x: int) -> tuple[Iv, Iv]:
    """sin and cos of the point x/2^P: x = k·π/2 + u with |u| ≲ π/4, the series at one
    end of u's (tiny) enclosure, widened by its width (sin and cos are 1-Lipschitz)."""
    if abs(x) > (1 << 40) * ONE:
        raise NotDecided("an angle too large for the sin/cos argument reduction")
    k = round(x / ONE / (math.pi / 2))  # any k does; a near one keeps the series short
    u = Iv(x, x) - PI * Iv.q(Fraction(k, 2))
    if abs(u.lo) > ONE or abs(u.hi) > ONE:
        raise NotDecided("the sin/cos argument reduction failed")
    s, c = _series(u.lo)
    w = u.hi - u.lo
    s, c = Iv(s.lo - w, s.hi + w), Iv(c.lo - w, c.hi + w)
    return [(s, c), (c, -s), (-s, -c), (-c, s)][k % 4]


def _clip(x: Iv) -> Iv:
    return Iv(max(x.lo, -ONE), min(x.hi, ONE))


def _around(t: Iv) -> tuple[Iv, Iv, Iv, Iv] | None:
    if t.hi - t.lo > ONE:
        return None
    m = (t.lo + t.hi) >> 1
    r = max(t.hi - m, m - t.lo)
    s, c = sincos_point(m)
    half_r2 = -((-(r * r)) >> (P + 1))
    return s, c, Iv(-r, r), Iv(-half_r2, half_r2)


def sin(t: Iv) -> Iv:
    """sin over t: sin m + cos m·h − sin ξ·h²/2 with t = m + h (Taylor with remainder)."""
    a = _around(t)
    return Iv(-ONE, ONE) if a is None else _clip(a[0] + a[1] * a[2] + a[3])


def cos(t: Iv) -> Iv:
    a = _around(t)
    return Iv(-ONE, ONE) if a is None else _clip(a[1] - a[0] * a[2] + a[3])
