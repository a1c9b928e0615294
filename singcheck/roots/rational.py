"""Exact isolation of the real roots of a univariate polynomial over Q.

Squarefree factorisation, then Descartes' rule of signs with Vincent–Collins–Akritas
bisection in exact integer arithmetic: each root gets a rational interval holding
exactly one root, with a sign change at its ends (or a point, for a root met exactly),
refined by bisection on exact signs (a 128-bit ball decides most signs, exact rational
arithmetic the rest).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from flint import arb, arb_poly, ctx, fmpq, fmpq_poly, fmpz_poly

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.polynomials import memo_per_object
from singcheck.budget import checkpoint


def bits_for(tolerance: float) -> int:
    return max(53, int(-math.log2(tolerance)) + 30)


def exact_tolerance(x: float) -> fmpq:
    """An exact rational for a positive float tolerance (tiny ones clamped to 2^-1000)."""
    if x < 1e-300:
        return fmpq(1, 2**1000)
    num, den = x.as_integer_ratio()
    return fmpq(num, den)


def to_fraction(q: fmpq) -> Fraction:
    """An exact FLINT rational as a Python Fraction."""
    return Fraction(int(q.p), int(q.q))


def to_fmpq(x: Fraction | int) -> fmpq:
    """An exact Python rational (Fraction or int) as a FLINT rational."""
    x = Fraction(x)
    return fmpq(x.numerator, x.denominator)


def simplest_between(lo: Fraction | None, hi: Fraction | None) -> Fraction:
    """The rational with the smallest denominator (then numerator) in the open (lo, hi).

    ``None`` stands for -∞ / +∞.  Stern–Brocot descent, exact.  An empty interval
    (lo ≥ hi) is a caller's error: ValueError, never a division by zero deep inside.
    """
    if lo is not None and hi is not None and not lo < hi:
        raise ValueError(f"simplest_between: empty interval ({lo}, {hi})")
    if lo is None and hi is None:
        return Fraction(0)
    if lo is None:
        return Fraction(min(0, math.ceil(hi) - 1))
    if hi is None:
        return Fraction(max(0, math.floor(lo) + 1))
    if lo < 0 < hi:
        return Fraction(0)
    if hi <= 0:
        return -simplest_between(-hi, -lo)
    wholes = []  # while lo and hi share their integer part, go on with the reciprocals
    while not (hi is None or math.floor(lo) + 1 < hi):  # of their fractional parts (a
        whole = math.floor(lo)  # loop: balls of 2048 bits give thousands of steps)
        wholes.append(whole)
        lo, hi = 1 / (hi - whole), (1 / (lo - whole) if lo > whole else None)
    value = Fraction(math.floor(lo) + 1)
    for whole in reversed(wholes):
        value = whole + 1 / value
    return value


def rational_ball(lo: fmpq, hi: fmpq) -> arb:
    """A ball containing the rational interval [lo, hi], at a precision fine enough
    that rounding does not widen it noticeably."""
    width = hi - lo
    bits = 60 + (int(-math.log2(float(width))) if width > 0 and float(width) > 0 else 200)
    with working_precision(bits):
        return arb(lo).union(arb(hi))


def arb_to_fmpq(x: arb) -> fmpq:
    man, exp = x.man_exp()
    return fmpq(int(man) * 2**int(exp)) if exp >= 0 else fmpq(int(man), 2 ** (-int(exp)))


def ball_ends(x: arb) -> tuple[fmpq, fmpq]:
    """The exact ends mid − rad and mid + rad of a ball, as rationals.

    ``x.lower()`` and ``x.upper()`` round outward to the working precision: still an
    enclosure, but two disjoint balls closer than that precision would get crossing
    ends.  These are the ball's own ends, so disjoint balls keep disjoint intervals."""
    mid, rad = arb_to_fmpq(x.mid()), arb_to_fmpq(x.rad())
    return mid - rad, mid + rad


# ---------------------------------------------------------------------------------
# exact univariate isolation


@dataclass
class RationalRoot:
    """A root of a squarefree integer polynomial in [lo, hi] with a sign change (or lo == hi)."""

    poly: fmpq_poly
    lo: fmpq
    hi: fmpq
    _balls: arb_poly | None = None
    _newton_polys: tuple | None = None  # (precision, f, f') as ball polynomials
    _sign_lo: int | None = None  # the sign of f at lo (the same at every later lo < root)

    def width(self) -> fmpq:
        return self.hi - self.lo

    def sign_at(self, q: fmpq) -> int:
        """The exact sign of the polynomial at q: a ball evaluation when it decides,
        exact rational arithmetic otherwise."""
        with working_precision(128):
            if self._balls is None:
                self._balls = _ball_polys_of(self.poly, 128)[0]
            value = self._balls(arb(q))
        if value > 0:
            return 1
        if value < 0:
            return -1
        return _qsign(self.poly(q))

    def bisect_to(self, width: fmpq) -> None:
        """Shrink [lo, hi] to ``width`` or less, keeping the root inside.

        First a guess is verified: Newton's iteration from the midpoint, in plain
        (unproven) ball midpoints, proposes the root; a short dyadic interval of the
        width asked for around it is accepted only when the exact signs of f at its ends
        differ and it lies inside [lo, hi] (which holds exactly one root): then the root
        is in it.  Otherwise, step by step:

        each step is an interval Newton step when it halves the interval at least:
        where the ball of f' over [lo, hi] excludes 0, f is monotone there and the root
        lies in m - f(m)/f'([lo, hi]) (mean value theorem; m the midpoint), intersected
        with [lo, hi] and rounded outward to rationals.  Otherwise (or when Newton gains
        too little) it is a bisection on exact signs.  Newton's quadratic convergence
        takes a root to 10⁻⁹ in a handful of steps instead of some thirty bisections.
        """
        if self.hi - self.lo <= width:
            return
        slo = self._sign_lo
        if slo is None:  # first refinement: are the ends roots themselves?
            slo = self.sign_at(self.lo)
            if slo == 0:
                self.hi = self.lo
                return
            if self.sign_at(self.hi) == 0:
                self.lo = self.hi
                return
            self._sign_lo = slo
        if self._guess_and_verify(width, slo):
            return
        retry_below = self.hi - self.lo  # after a failed Newton step, bisect 4 times first
        while self.hi - self.lo > width:
            checkpoint()
            if self.hi - self.lo <= retry_below:
                if self._newton_step(width):
                    # f is monotone on the old interval, which held the one root: the
                    # new ends keep their signs unless one is the root itself
                    if self.sign_at(self.lo) == 0:
                        self.hi = self.lo
                        return
                    if self.sign_at(self.hi) == 0:
                        self.lo = self.hi
                        return
                    continue
                retry_below = (self.hi - self.lo) / 16
            mid = (self.lo + self.hi) / 2
            sm = self.sign_at(mid)
            if sm == 0:
                self.lo = self.hi = mid
                return
            if sm == slo:
                self.lo = mid
            else:
                self.hi = mid

    def _guess_and_verify(self, target: fmpq, slo: int) -> bool:
        """Narrow [lo, hi] to about ``target`` around Newton's guess when exact signs
        confirm it (see :meth:`bisect_to`); False, with nothing changed, otherwise.  The
        guess is made in floats first (cheap; the polynomial scaled to coefficients of
        at most 1), then, if that guess is not confirmed, in ball midpoints."""
        w = float(target)
        if not w > 0 or not math.isfinite(w):
            return False
        for guess in (self._float_guess, self._ball_guess):
            centre = guess(w, slo)
            if centre is not None and self._confirm(centre, target, slo):
                return True
        return False

    def _float_guess(self, w: float, slo: int) -> fmpq | None:
        """Safeguarded Newton in floats (unproven); None when the coefficients or the
        ends do not fit a float, or it does not settle within 40 steps."""
        coeffs = _float_coefficients(self.poly)
        if coeffs is None:
            return None
        a, b = float(self.lo), float(self.hi)
        if not a < b:
            return None
        x = (a + b) / 2
        for _ in range(40):
            f = d = 0.0
            for c in coeffs:  # Horner for f and f' together, highest degree first
                d = d * x + f
                f = f * x + c
            if (f > 0) == (slo > 0):
                a = x
            else:
                b = x
            guess = x - f / d if d != 0 else (a + b) / 2
            if not a < guess < b:
                guess = (a + b) / 2
            step = abs(guess - x)
            x = guess
            if step < w / 16 or b - a < w / 16:
                return fmpq(*x.as_integer_ratio())
        return None

    def _ball_guess(self, w: float, slo: int) -> fmpq | None:
        """Safeguarded Newton in ball midpoints at a precision the width asks for."""
        bits = max(128, 2 * int(-math.log2(w)) + 64)
        old = ctx.prec
        ctx.prec = bits
        try:
            value, slope_poly = self._ball_polys(bits)
            a, b = arb(self.lo), arb(self.hi)  # a bracket: f has sign slo at a, -slo at b
            x = ((a + b) / 2).mid()
            for _ in range(200):  # safeguarded Newton (unproven guesses, checked below)
                fx = value(x).mid()
                if (fx > 0) == (slo > 0):
                    a = x
                else:
                    b = x
                slope = slope_poly(x).mid()
                guess = (x - fx / slope).mid() if slope != 0 else a
                if not (guess > a and guess < b):
                    guess = ((a + b) / 2).mid()
                step = abs(guess - x)
                x = guess
                if step < w / 16 or b - a < w / 16:
                    break
            else:
                return None
            return arb_to_fmpq(x)
        finally:
            ctx.prec = old

    def _confirm(self, centre: fmpq, target: fmpq, slo: int) -> bool:
        """Take the short dyadic interval of width about ``target`` around ``centre`` as
        the new [lo, hi] when it lies inside [lo, hi] and the exact signs of f at its ends
        are slo and -slo (or one end is the root itself): then it holds the root."""
        a, b = _short_dyadic_hull(centre - target / 4, centre + target / 4, target)
        if not (self.lo < a < b < self.hi):
            return False
        sa, sb = self.sign_at(a), self.sign_at(b)
        if sa == 0:
            self.lo = self.hi = a
            return True
        if sb == 0:
            self.lo = self.hi = b
            return True
        if sa != slo or sb != -slo:
            return False
        self.lo, self.hi = a, b
        return True

    def _ball_polys(self, bits: int) -> tuple[arb_poly, arb_poly]:
        """f and f' as ball polynomials at ``bits`` of precision (memoised)."""
        if self._newton_polys is None or self._newton_polys[0] != bits:
            self._newton_polys = (bits, *_ball_polys_of(self.poly, bits))
        return self._newton_polys[1], self._newton_polys[2]

    def _newton_step(self, target: fmpq) -> bool:
        """One interval Newton step on [lo, hi]; False (nothing changed) when f' may
        vanish there or the step would not halve the interval.  The new ends are
        dyadic with a few bits more than ``target`` (the width asked for) needs, as a
        bisection's would be: Newton's quadratic steps overshoot, and ends with
        hundreds of bits would slow every later exact computation with them."""
        width = self.hi - self.lo
        w = float(width)
        if not w > 0:
            return False
        bits = max(128, int(-math.log2(w)) * 2 + 64)
        with working_precision(bits):
            value, slope_poly = self._ball_polys(bits)
            box = arb(self.lo).union(arb(self.hi))
            slope = slope_poly(box)
            if slope.contains(0):
                return False
            mid = (self.lo + self.hi) / 2
            step = arb(mid) - value(arb(mid)) / slope
            new_lo = arb_to_fmpq(step.lower())
            new_hi = arb_to_fmpq(step.upper())
        new_lo, new_hi = _short_dyadic_hull(max(new_lo, self.lo), min(new_hi, self.hi), target)
        new_lo, new_hi = max(new_lo, self.lo), min(new_hi, self.hi)
        if new_lo > new_hi or 2 * (new_hi - new_lo) > width:
            return False
        self.lo, self.hi = new_lo, new_hi
        return True

    def ball(self) -> arb:
        return rational_ball(self.lo, self.hi)

    def compare(self, q: fmpq) -> int:
        """-1, 0, 1 as the root is below, at, above the rational q (exact: the interval
        is bisected until it lies on one side of q, or q is found to be the root)."""
        while True:  # (a root 2^-k from q takes about k/2 rounds)
            checkpoint()
            if self.hi < q:
                return -1
            if self.lo > q:
                return 1
            if self.lo == self.hi or self.poly(q) == 0:
                return 0
            self.bisect_to((self.hi - self.lo) / 4)

    def pin(self, q: fmpq) -> bool:
        """Collapse to ``q`` when it lies inside the isolating interval and is a root.

        The end points of an isolating interval are never its root (they may be
        another root), so only a point strictly inside, or the point itself, counts.
        """
        if (self.lo < q < self.hi or self.lo == q == self.hi) and self.poly(q) == 0:
            self.lo = self.hi = q
            return True
        return False


_BALL_POLYS: dict = {}
_FLOAT_COEFFICIENTS: dict = {}


def _float_coefficients(poly: fmpq_poly) -> list[float] | None:
    """The coefficients, highest degree first, as floats scaled to at most 1 in absolute
    value (for unproven guesses only); None when one does not fit a float.  Once per
    polynomial object (the roots of one factor share it)."""
    def convert(p: fmpq_poly) -> list[float] | None:
        try:
            cs = [float(c) for c in p.coeffs()]
        except OverflowError:
            return None
        top = max((abs(c) for c in cs), default=0.0)
        if not (math.isfinite(top) and top > 0):
            return None
        return [c / top for c in reversed(cs)]

    return memo_per_object(_FLOAT_COEFFICIENTS, poly, convert)


def _ball_polys_of(poly: fmpq_poly, bits: int) -> tuple[arb_poly, arb_poly]:
    """f and f' as ball polynomials rounded at ``bits`` (the current precision must be
    ``bits``), shared by the roots of one factor (they hold the same ``poly`` object)."""
    key = (id(poly), bits)
    hit = _BALL_POLYS.get(key)
    if hit is None or hit[0] is not poly:  # the entry holds poly: its id is not reused
        if len(_BALL_POLYS) > 256:
            _BALL_POLYS.clear()
        value = arb_poly(poly)
        hit = _BALL_POLYS[key] = (poly, value, value.derivative())
    return hit[1], hit[2]


def _short_dyadic_hull(lo: fmpq, hi: fmpq, target: fmpq) -> tuple[fmpq, fmpq]:
    """[lo, hi] widened outward to dyadic ends with 4 bits more than the width
    ``target`` needs (so by at most an eighth of it)."""
    width = max(hi - lo, target)
    if width <= 0:
        return lo, hi
    k = max(0, math.ceil(-math.log2(float(width))) + 4) if float(width) > 0 else 1100
    scale = 2**k
    return (fmpq((lo * scale).floor(), scale), fmpq((hi * scale).ceil(), scale))


def _qsign(q: fmpq) -> int:
    return (q > 0) - (q < 0)


def _variations(coeffs, up_to: int | None = None) -> int:
    """The number of sign variations of ``coeffs`` (zeros skipped), or ``up_to`` once it
    reaches that many: by Descartes' rule of signs, a bound on the number of positive
    roots (with multiplicity).  Descartes' test on an interval only needs to tell 0, 1
    and more apart, so it stops at the second variation (``up_to=2``)."""
    count = last = 0
    for c in coeffs:
        if c:
            s = 1 if c > 0 else -1
            if last and s != last:
                count += 1
                if count == up_to:
                    return count
            last = s
    return count


_X_PLUS_1 = fmpz_poly([1, 1])


def _positive_root_intervals(f: fmpz_poly) -> list[tuple[fmpq, fmpq]]:
    """Isolating intervals of the positive real roots of a squarefree ``f`` with f(0) ≠ 0.

    The roots in (0, 1) are those of f there; the roots x > 1 are the 1/y for the roots
    y in (0, 1) of the reversal y^n f(1/y) (same degree, non-zero at 0, and of the sign
    of f(1/y) for y > 0); x = 1 is tested exactly.  Each part is isolated in (0, 1) by
    :func:`_unit_root_intervals`; an interval [a, b] of the reversal becomes [1/b, 1/a]
    ([0, b] is first narrowed off 0, :func:`_off_zero`).  Splitting at 1 instead of
    bisecting down from a bound on the roots spares the levels between the bound and
    the roots: a root near u = 0 or u = ∞ (t near 0 or ±π) no longer costs a dozen
    halvings for every other root.
    """
    cs = f.coeffs()  # FLINT integers: compared and summed as they are, no conversion
    if cs[-1] < 0:
        cs = [-c for c in cs]
    variations = _variations(cs)  # Descartes: at most that many positive roots
    if variations == 0:
        return []
    one = fmpq(1)
    intervals = [(one, one)] if sum(cs) == 0 else []
    intervals += _unit_root_intervals(fmpz_poly(cs))
    if len(intervals) == variations:
        return intervals  # all found: none above 1
    reversal = fmpz_poly(cs[::-1])
    for lo, hi in _unit_root_intervals(reversal):
        if lo == 0:
            lo, hi = _off_zero(fmpq_poly(reversal), hi)
        intervals.append((1 / hi, 1 / lo))
    return intervals


def _off_zero(g: fmpq_poly, hi: fmpq) -> tuple[fmpq, fmpq]:
    """An isolating interval [lo, hi'] with lo > 0 for the one root y of g in (0, hi),
    where g(0) > 0 > g(hi) (the reversal's largest-x root): hi is halved while g stays
    negative there (exact signs); the first point where g > 0 is lo (a point where g = 0
    is the root itself).  It ends once hi/2 falls below y > 0."""
    while True:
        checkpoint()
        mid = hi / 2
        value = g(mid)
        if value == 0:
            return mid, mid
        if value > 0:
            return mid, hi
        hi = mid


def _unit_root_intervals(g: fmpz_poly) -> list[tuple[fmpq, fmpq]]:
    """Isolating intervals of the roots in (0, 1) of a squarefree ``g`` with g(0) ≠ 0.

    Vincent–Collins–Akritas bisection: on a dyadic interval, the number of sign
    variations of the coefficients of (x+1)^n g(1/(x+1)) bounds the number of roots and
    has the same parity (Descartes); 0 proves none, 1 proves exactly one (Vincent's
    theorem makes the bisection terminate for squarefree input).  A root found exactly
    at a bisection point is returned as a point interval; an interval whose end is such
    a root (or 1) is bisected further, so every other interval has a sign change at its
    ends.

    Each node costs one Taylor shift by 1 in FLINT (the test polynomial, whose constant
    term is g(1)) and, when it is split, one more for the right half; halving,
    2^m g(x/2), is a shift of each coefficient.
    """
    out: list[tuple[int, int, bool]] = []  # (a, k, exact) on (a/2^k, (a+1)/2^k)
    stack = [(g, 0, 0)]
    while stack:
        g, a, k = stack.pop()
        checkpoint()
        coeffs = g.coeffs()
        m = len(coeffs) - 1
        test = fmpz_poly(coeffs[::-1])(_X_PLUS_1).coeffs()  # (x+1)^m g(1/(x+1))
        v = _variations(test, up_to=2)
        if v == 0:
            continue
        ends_are_roots = coeffs[0] == 0 or test[0] == 0  # g(0), g(1)
        if v == 1 and not ends_are_roots:
            out.append((a, k, False))
            continue
        half = fmpz_poly([c << (m - i) for i, c in enumerate(coeffs)])  # 2^m g(x/2)
        if half(1) == 0:
            out.append((2 * a + 1, k + 1, True))
        stack.append((half(_X_PLUS_1), 2 * a + 1, k + 1))
        stack.append((half, 2 * a, k + 1))
    intervals = []
    for a, k, exact in out:
        lo = fmpq(a, 2**k)
        intervals.append((lo, lo) if exact else (lo, fmpq(a + 1, 2**k)))
    return intervals


def nonzero_on(p: fmpq_poly, a: fmpq, b: fmpq, pieces: int = 8) -> bool:
    """True when ball evaluations of ``p`` on ``pieces`` balls covering [a, b] all exclude
    0 (then p has no root there: a proof by ball arithmetic).  False: not proven."""
    with working_precision(64):
        balls = arb_poly(p)  # each coefficient's ball, converted in FLINT
        lo, width = arb(a), arb(b - a)
        for k in range(pieces):
            piece = (lo + width * k / pieces).union(lo + width * (k + 1) / pieces)
            if balls(piece).contains(0):
                return False
    return True


def no_root_between(p: fmpq_poly, a: fmpq, b: fmpq) -> bool:
    """True when ``p`` provably has no root in the closed interval [a, b] (a < b): p(a)
    and p(b) are non-zero exactly, and the Möbius transform (1 + v)ⁿ·p(a + (b − a)/(1 + v)),
    whose positive roots are p's roots in (a, b), has no sign variation in its
    coefficients (Descartes' rule of signs).  False means "not proven" (maybe roots)."""
    if p(a) == 0 or p(b) == 0:
        return False
    n = p.degree()
    q = p(fmpq_poly([a, b - a]))  # roots in (0, 1)
    coeffs = q.coeffs() + [fmpq(0)] * (n + 1 - len(q.coeffs()))
    moved = fmpq_poly(coeffs[::-1])(fmpq_poly([1, 1]))  # x^n q(1/x) at x = 1 + v
    signs = [c > 0 for c in moved.coeffs() if c != 0]
    return all(x == signs[0] for x in signs)


def real_roots_exact(p: fmpq_poly, nonnegative_only: bool = False
                     ) -> list[tuple[RationalRoot, int]]:
    """Isolating rational intervals of the real roots of ``p``, with multiplicities
    (only the roots ≥ 0 when ``nonnegative_only``)."""
    if p.degree() < 1:
        return []
    num = p.numer()  # p = num / denominator: the same roots
    _, factors = num.factor_squarefree()
    out = []
    for factor, mult in factors:
        f = fmpq_poly(factor)
        cs = factor.coeffs()
        if cs[0] == 0:  # a root at 0 (squarefree: simple)
            shift = next(i for i, c in enumerate(cs) if c != 0)
            out.append((RationalRoot(f, fmpq(0), fmpq(0)), mult))
            factor = fmpz_poly(cs[shift:])
            f = fmpq_poly(factor)  # the other roots: f no longer vanishes at 0
        if factor.degree() < 1:
            continue
        for lo, hi in _positive_root_intervals(factor):
            out.append((RationalRoot(f, lo, hi), mult))
        if nonnegative_only:
            continue
        mirrored = fmpz_poly([c if i % 2 == 0 else -c for i, c in enumerate(factor.coeffs())])
        for lo, hi in _positive_root_intervals(mirrored):
            out.append((RationalRoot(f, -hi, -lo), mult))
    out.sort(key=lambda item: item[0].lo)
    return out


# ---------------------------------------------------------------------------------
# minimal polynomials of isolated roots, and roots of their k-th powers

_FACTORS: dict = {}
_POWERS: dict = {}


def irreducible_factors(poly: fmpq_poly) -> list[fmpq_poly]:
    """The monic irreducible factors of ``poly`` over Q, once per polynomial object: the
    roots of one squarefree factor hold the same object, so the exact decisions at
    several of its roots factor it once."""
    def factor(p: fmpq_poly) -> list[fmpq_poly]:
        return [fmpq_poly(h) / fmpq_poly(h).leading_coefficient()
                for h, _ in p.numer().factor()[1]]
    return memo_per_object(_FACTORS, poly, factor)


def minimal_polynomial(rr: RationalRoot) -> RationalRoot:
    """The same root on the irreducible factor of ``rr.poly`` that vanishes there (its
    minimal polynomial, monic; the same interval).

    The interval isolates one root of the squarefree polynomial, so exactly one
    irreducible factor has a root there: the one that vanishes at a point interval, or
    changes sign between the ends (roots of a squarefree polynomial are simple, and the
    ends of an isolating interval are not roots).
    """
    for f in irreducible_factors(rr.poly):
        if rr.lo == rr.hi:
            if f(rr.lo) == 0:
                return RationalRoot(f, rr.lo, rr.hi)
        elif f(rr.lo) * f(rr.hi) < 0:
            return RationalRoot(f, rr.lo, rr.hi)
    raise AssertionError("no factor of an isolated root's polynomial vanishes there")


def _power_substituted(h: fmpq_poly, k: int) -> fmpq_poly:
    """h(u^k), one object per (h, k): its own factorisation is then shared by the roots
    that need it."""
    per_h = memo_per_object(_POWERS, h, lambda _: {})
    if k not in per_h:
        coeffs = [fmpq(0)] * (k * h.degree() + 1)
        for i, c in enumerate(h.coeffs()):
            coeffs[k * i] = c
        per_h[k] = fmpq_poly(coeffs)
    return per_h[k]


def root_of_power(rr: RationalRoot, k: int, sign: int) -> RationalRoot:
    """u = sign·|v|^(1/k) for the root v ≠ 0 isolated by ``rr`` (sign = the sign of v when
    k is odd), as a root of g(u) = h(u^k), h the minimal polynomial of v, with an
    isolating rational interval: found from v's own interval, without isolating g.

    The roots of g of u's sign are the u' = sign·|v'|^(1/k) for the roots v' of h of v's
    sign, and u' ↦ v' = u'^k is monotone there.  With [lo, hi] v's isolating interval
    (refined off 0), rationals x₋ ≥ |e₁|^(1/k) and x₊ ≤ |e₂|^(1/k) are taken from Arb's
    k-th roots of the end nearer 0 (e₁) and the farther one (e₂); w₋ = σ·x₋^k and
    w₊ = σ·x₊^k (σ the sign of v) are then checked exactly to lie in [lo, hi] with h
    non-zero of the sign h has at e₁, resp. e₂: on an isolating interval with a sign
    change, that places w₋ strictly between e₁ and v and w₊ strictly between v and e₂.
    So [x₋, x₊] (mirrored for sign < 0) holds exactly one root of g, u, and g, which is
    h(σ·x^k) there, changes sign at its ends.  Otherwise ``rr`` is refined and the test
    repeated.  A rational v with |v| a k-th power gives u exactly.
    """
    v = minimal_polynomial(rr)
    g = _power_substituted(v.poly, k)
    if v.compare(fmpq(0)) == 0:
        raise ValueError("the k-th root of 0 is not isolated here")
    sigma = 1 if v.lo > 0 else -1

    def between(w: fmpq, end: fmpq) -> bool:  # strictly between the end and v, proven
        return v.lo <= w <= v.hi and v.sign_at(w) == v.sign_at(end) != 0

    while True:
        checkpoint()
        if v.lo == v.hi:  # v rational (given so, or met exactly by a bisection)
            x_lo, x_hi = _kth_root_bracket(abs(v.lo), k)
            break
        near, far = (v.lo, v.hi) if sigma > 0 else (v.hi, v.lo)
        with working_precision(64 + max(0, int(-math.log2(float(v.width()))))):
            x_lo = arb_to_fmpq(arb(abs(near)).root(k).upper())
            x_hi = arb_to_fmpq(arb(abs(far)).root(k).lower())
        if 0 < x_lo < x_hi and between(sigma * x_lo**k, near) and \
                between(sigma * x_hi**k, far):
            break
        v.bisect_to(v.width() / 4)
    return RationalRoot(g, *((x_lo, x_hi) if sign > 0 else (-x_hi, -x_lo)))


def _kth_root_bracket(w: fmpq, k: int) -> tuple[fmpq, fmpq]:
    """w^(1/k) for a rational w > 0: a point when it is rational, else rationals
    x₋ < x₊ with x₋^k < w < x₊^k (checked exactly)."""
    a, b = _integer_root(int(w.p), k), _integer_root(int(w.q), k)
    if a**k == w.p and b**k == w.q:
        return fmpq(a, b), fmpq(a, b)
    bits = 64
    while True:
        checkpoint()
        with working_precision(bits):
            ball = arb(w).root(k)
            x_lo, x_hi = arb_to_fmpq(ball.lower()), arb_to_fmpq(ball.upper())
        if 0 < x_lo and x_lo**k < w < x_hi**k:
            return x_lo, x_hi
        bits *= 2


def _integer_root(n: int, k: int) -> int:
    """⌊n^(1/k)⌋ for an integer n ≥ 1 (Newton's iteration in integers)."""
    x = 1 << -(-n.bit_length() // k)  # above the root
    while True:
        y = ((k - 1) * x + n // x ** (k - 1)) // k
        if y >= x:
            return x
        x = y
