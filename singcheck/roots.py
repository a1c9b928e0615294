"""Certified isolation of the real roots of a trig polynomial on a time range.

``isolate_real_roots(poly, interval)`` returns balls in t, each proven to hold exactly
one root of ``poly(t, sin t, cos t)``, proves every gap between them root-free, and
reports whatever it cannot prove as :class:`Undecided` with a reason.  Three methods:

* **exact univariate** (no sin/cos): the squarefree factors of the polynomial in t
  over Z; Descartes' rule of signs with Vincent–Collins–Akritas bisection (exact
  integer arithmetic) gives rational intervals each holding exactly one root, with a
  sign change at their ends, refined by bisection on exact signs.
* **tangent half-angle** (sin/cos only): u = tan(t/2), s = 2u/(1+u²),
  c = (1-u²)/(1+u²) turn μ into M(u) = (1+u²)^d μ ∈ Q[u]; its real roots are isolated
  as above and mapped to t = 2·atan(u) + 2kπ with Arb's rigorous ``atan``; t ≡ π
  (u = ∞) is decided exactly by evaluating μ at s = 0, c = -1.
* **interval branch-and-bound** (t mixed with sin/cos): a box is excluded when the ball
  enclosure of μ over it (naive, or mean-value form) excludes 0; a box on which μ' excludes
  0 is strictly monotone, so a proven sign change at its ends proves exactly one root
  (and equal signs prove none).  Boxes that stay ambiguous down to the minimum width
  become :class:`Undecided`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from flint import arb, arb_poly, fmpq, fmpq_mpoly, fmpq_poly, fmpz_poly

from singcheck.errors import SingcheckError
from singcheck.intervals import excludes_zero, sign, working_precision
from singcheck.trig import (
    LinearInPi,
    TimeRange,
    derivative,
    evaluate_trig,
    reduce_trig,
    uses_t,
    uses_trig,
)

EXACT = "exact univariate"
HALF_ANGLE = "tangent half-angle"
BRANCH_AND_BOUND = "interval branch-and-bound"


class IdenticallyZeroError(SingcheckError):
    """The function is identically zero along the path: it has no isolated roots."""


@dataclass(frozen=True)
class RealRoot:
    t: arb  # holds exactly one root in the range
    multiplicity: int | None  # exact where the method knows it
    _refine: Callable[[float], arb] | None = field(default=None, compare=False, repr=False)

    def refined(self, tolerance: float) -> RealRoot:
        """The same root in a ball of width at most ``tolerance`` (when refinable)."""
        if self._refine is None or 2 * float(self.t.rad()) <= tolerance:
            return self
        return RealRoot(self._refine(tolerance), self.multiplicity, self._refine)


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


def _bits(tolerance: float) -> int:
    return max(53, int(-math.log2(tolerance)) + 30)


def _q(x: float) -> fmpq:
    """An exact rational for a positive float tolerance (tiny ones clamped to 2^-1000)."""
    if x < 1e-300:
        return fmpq(1, 2**1000)
    num, den = x.as_integer_ratio()
    return fmpq(num, den)


def _ball(lo: fmpq, hi: fmpq) -> arb:
    """A ball containing the rational interval [lo, hi], at a precision fine enough
    that rounding does not widen it noticeably."""
    width = hi - lo
    bits = 60 + (int(-math.log2(float(width))) if width > 0 and float(width) > 0 else 200)
    with working_precision(bits):
        return arb(lo).union(arb(hi))


def _to_fmpq(x: arb) -> fmpq:
    man, exp = x.man_exp()
    return fmpq(int(man) * 2**int(exp)) if exp >= 0 else fmpq(int(man), 2 ** (-int(exp)))


# ---------------------------------------------------------------------------------
# exact univariate isolation


@dataclass
class _RationalRoot:
    """A root of a squarefree integer polynomial in [lo, hi] with a sign change (or lo == hi)."""

    poly: fmpq_poly
    lo: fmpq
    hi: fmpq
    _balls: arb_poly | None = None

    def width(self) -> fmpq:
        return self.hi - self.lo

    def sign_at(self, q: fmpq) -> int:
        """The exact sign of the polynomial at q: a ball evaluation when it decides,
        exact rational arithmetic otherwise."""
        if self._balls is None:
            with working_precision(128):
                self._balls = arb_poly([arb(c) for c in self.poly.coeffs()])
        with working_precision(128):
            value = self._balls(arb(q))
        if value > 0:
            return 1
        if value < 0:
            return -1
        return _qsign(self.poly(q))

    def bisect_to(self, width: fmpq) -> None:
        f = self.poly
        slo = _qsign(f(self.lo))
        if slo == 0:
            self.hi = self.lo
            return
        if _qsign(f(self.hi)) == 0:
            self.lo = self.hi
            return
        while self.hi - self.lo > width:
            mid = (self.lo + self.hi) / 2
            sm = self.sign_at(mid)
            if sm == 0:
                self.lo = self.hi = mid
                return
            if sm == slo:
                self.lo = mid
            else:
                self.hi = mid

    def ball(self) -> arb:
        return _ball(self.lo, self.hi)

    def pin(self, q: fmpq) -> bool:
        """Collapse to ``q`` when it lies inside the isolating interval and is a root.

        The end points of an isolating interval are never its root (they may be
        another root), so only a point strictly inside, or the point itself, counts.
        """
        if (self.lo < q < self.hi or self.lo == q == self.hi) and self.poly(q) == 0:
            self.lo = self.hi = q
            return True
        return False


def _qsign(q: fmpq) -> int:
    return (q > 0) - (q < 0)


def _sign_variations(coeffs) -> int:
    signs = [c > 0 for c in coeffs if c != 0]
    return sum(1 for x, y in zip(signs, signs[1:], strict=False) if x != y)


_X_PLUS_1 = fmpz_poly([1, 1])
_TWO_X = fmpz_poly([0, 2])


def _positive_root_intervals(f: fmpz_poly) -> list[tuple[fmpq, fmpq]]:
    """Isolating intervals of the positive real roots of a squarefree ``f`` with f(0) ≠ 0.

    Vincent–Collins–Akritas bisection: roots are first scaled into (0, 1) by a power
    of two above the Cauchy bound; on a dyadic interval, the number of sign variations
    of the coefficients of (x+1)^n g(1/(x+1)) bounds the number of roots and has the
    same parity (Descartes); 0 proves none, 1 proves exactly one (Vincent's theorem
    makes the bisection terminate for squarefree input).  A root found exactly at a
    bisection point is returned as a point interval; an interval whose end is such a
    root is bisected further, so every other interval has a sign change at its ends.
    """
    cs = [int(c) for c in f.coeffs()]
    n = len(cs) - 1
    # Fujiwara: every root has |z| <= 2 max |a_i / a_n|^(1/(n-i)); bounded with bit
    # lengths (|a| < 2^bitlen), plus one more bit so that every root is < 2^b strictly.
    top = abs(cs[-1]).bit_length() - 1  # 2^top <= |a_n|
    b = 2 + max((-(-(abs(c).bit_length() - top) // (n - i)) for i, c in enumerate(cs[:-1])
                 if c), default=0)
    b = max(b, 1)
    g = fmpz_poly([c << (b * i) for i, c in enumerate(cs)])  # g(x) = f(2^b x)
    out: list[tuple[int, int, int, bool]] = []  # (a, k, exact) on (a/2^k, (a+1)/2^k)
    stack = [(g, 0, 0)]
    while stack:
        g, a, k = stack.pop()
        coeffs = g.coeffs()
        m = len(coeffs) - 1
        reversed_g = fmpz_poly(coeffs[::-1])
        v = _sign_variations(reversed_g(_X_PLUS_1).coeffs())
        ends_are_roots = coeffs[0] == 0 or g(1) == 0
        if v == 0:
            continue
        if v == 1 and not ends_are_roots:
            out.append((a, k, False))
            continue
        # 2^m g(x/2): reverse, substitute 2x, reverse back (all in FLINT)
        scaled = reversed_g(_TWO_X).coeffs()
        scaled += [0] * (m + 1 - len(scaled))
        half = fmpz_poly(scaled[::-1])
        if half(1) == 0:
            out.append((2 * a + 1, k + 1, True))
        stack.append((half(_X_PLUS_1), 2 * a + 1, k + 1))
        stack.append((half, 2 * a, k + 1))
    scale = fmpq(2**b)
    intervals = []
    for a, k, exact in out:
        lo = scale * fmpq(a, 2**k)
        intervals.append((lo, lo) if exact else (lo, scale * fmpq(a + 1, 2**k)))
    return intervals


def _real_roots_exact(p: fmpq_poly) -> list[tuple[_RationalRoot, int]]:
    """Isolating rational intervals of the real roots of ``p``, with multiplicities."""
    if p.degree() < 1:
        return []
    num = fmpz_poly([int(c * p.denom()) for c in p.coeffs()])
    _, factors = num.factor_squarefree()
    out = []
    for factor, mult in factors:
        f = fmpq_poly(factor)
        cs = [int(c) for c in factor.coeffs()]
        shift = next(i for i, c in enumerate(cs) if c != 0)
        if shift:  # a root at 0 (squarefree: simple)
            out.append((_RationalRoot(f, fmpq(0), fmpq(0)), mult))
            factor = fmpz_poly(cs[shift:])
            f = fmpq_poly(factor)  # the other roots: f no longer vanishes at 0
        if factor.degree() < 1:
            continue
        for lo, hi in _positive_root_intervals(factor):
            out.append((_RationalRoot(f, lo, hi), mult))
        mirrored = fmpz_poly([c if i % 2 == 0 else -c
                              for i, c in enumerate(int(c) for c in factor.coeffs())])
        for lo, hi in _positive_root_intervals(mirrored):
            out.append((_RationalRoot(f, -hi, -lo), mult))
    out.sort(key=lambda item: item[0].lo)
    return out


# ---------------------------------------------------------------------------------
# comparing times with the range ends


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


def _inside(t: arb, exact: LinearInPi | None, interval: TimeRange, bits: int) -> bool | None:
    a = _relation(t, exact, interval.start, bits)
    b = _relation(t, exact, interval.end, bits)
    if a is None or b is None:
        return None
    return a >= 0 and b <= 0


def _locate(make_ball: Callable[[float], arb], exact: LinearInPi | None,
            interval: TimeRange, tolerance: float) -> tuple[bool | None, arb]:
    """Refine a root until it is proven inside or outside the range (or give up)."""
    tol = tolerance
    for _ in range(8):
        t = make_ball(tol)
        where = _inside(t, exact, interval, _bits(tol))
        if where is not None:
            return where, t
        tol /= 1e6
    return None, make_ball(tol)


# ---------------------------------------------------------------------------------
# the three methods


def _as_univariate_t(p: fmpq_mpoly) -> fmpq_poly:
    coeffs: dict[int, fmpq] = {}
    for (i, _j, _k), c in p.terms():
        coeffs[i] = coeffs.get(i, fmpq(0)) + c
    return fmpq_poly([coeffs.get(i, fmpq(0)) for i in range(max(coeffs) + 1)])


def _exact_univariate(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    roots, undecided = [], []
    ends = [fmpq(e.rational.numerator, e.rational.denominator)
            for e in (interval.start, interval.end) if not e.pi_coefficient]
    for rr, mult in _real_roots_exact(_as_univariate_t(p)):
        for q in ends:
            rr.pin(q)

        def make(tol: float, rr=rr) -> arb:
            rr.bisect_to(_q(tol))
            return rr.ball()

        exact = LinearInPi(_fraction(rr.lo)) if rr.lo == rr.hi else None
        where, t = _locate(make, exact, interval, tolerance)
        if where is None:
            undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
        elif where:
            roots.append(RealRoot(make(tolerance), mult, make))
    return RootIsolation(tuple(roots), tuple(undecided), EXACT)


def _fraction(q: fmpq):
    from fractions import Fraction

    return Fraction(int(q.p), int(q.q))


def _half_angle_polynomial(p: fmpq_mpoly) -> tuple[fmpq_poly, int]:
    """M(u) = (1+u²)^d · p(2u/(1+u²), (1-u²)/(1+u²)) and d (p free of t)."""
    d = max((j + k for (_i, j, k), _ in p.terms()), default=0)
    def powers(base: fmpq_poly) -> list[fmpq_poly]:
        out = [fmpq_poly([1])]
        for _ in range(d):
            out.append(out[-1] * base)
        return out

    two_u, one_minus, one_plus = (powers(fmpq_poly(c)) for c in ([0, 2], [1, 0, -1],
                                                                  [1, 0, 1]))
    total = fmpq_poly([])
    for (_i, j, k), c in p.terms():
        total += c * two_u[j] * one_minus[k] * one_plus[d - j - k]
    return total, d


def _half_angle(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    m, _ = _half_angle_polynomial(p)
    at_pi = p.subs({"s": 0, "c": -1})
    bases: list[tuple[Callable[[float], arb], LinearInPi | None, int]] = []
    for rr, mult in _real_roots_exact(m):
        for q in (fmpq(0), fmpq(1), fmpq(-1)):  # t = 0, ±π/2: exact, may be range ends
            rr.pin(q)

        def base(tol: float, rr=rr) -> arb:
            rr.bisect_to(_q(tol) / 4)
            with working_precision(_bits(tol)):
                return 2 * rr.ball().atan()

        exact = None
        if rr.lo == rr.hi and rr.lo in (fmpq(0), fmpq(1), fmpq(-1)):
            from fractions import Fraction

            exact = LinearInPi(Fraction(0), Fraction(int(rr.lo.p), 2))
        bases.append((base, exact, mult))
    if at_pi.is_zero():
        from fractions import Fraction

        def base_pi(tol: float) -> arb:
            with working_precision(_bits(tol)):
                return arb.pi()

        # multiplicity of t = π: the degree drop of M counts it
        bases.append((base_pi, LinearInPi(Fraction(0), Fraction(1)), None))
    roots, undecided = [], []
    for base, exact, mult in bases:
        for k in _periods(base(tolerance), interval):
            def make(tol: float, base=base, k=k) -> arb:
                with working_precision(_bits(tol)):
                    return base(tol) + 2 * k * arb.pi()

            shifted = None
            if exact is not None:
                shifted = LinearInPi(exact.rational, exact.pi_coefficient + 2 * k)
            where, t = _locate(make, shifted, interval, tolerance)
            if where is None:
                undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
            elif where:
                roots.append(RealRoot(make(tolerance), mult, make))
    roots.sort(key=lambda r: float(r.t.mid()))
    return RootIsolation(tuple(roots), tuple(undecided), HALF_ANGLE)


def _periods(t0: arb, interval: TimeRange) -> range:
    """Every k for which t0 + 2kπ may meet the range (a superset)."""
    two_pi = 2 * math.pi
    lo = math.floor((float(interval.start) - float(t0.mid())) / two_pi) - 1
    hi = math.ceil((float(interval.end) - float(t0.mid())) / two_pi) + 1
    return range(lo, hi + 1)


# --- branch and bound ------------------------------------------------------------

_MAX_BOXES = 200_000
_SPLIT = fmpq(1, 2) - fmpq(1, 97)  # off-centre, so a root rarely sits on a split point


def _eval(p: fmpq_mpoly, lo: fmpq, hi: fmpq) -> arb:
    return evaluate_trig(p, _ball(lo, hi))


def _point(p: fmpq_mpoly, t: fmpq) -> arb:
    return evaluate_trig(p, arb(t))


def _excluded(p, dp, lo: fmpq, hi: fmpq) -> tuple[bool, arb]:
    box = _ball(lo, hi)
    naive = evaluate_trig(p, box)
    if excludes_zero(naive):
        return True, None
    mid = (lo + hi) / 2
    slope = evaluate_trig(dp, box)
    centred = _point(p, mid) + slope * (box - arb(mid))
    return excludes_zero(centred), slope


def _bisect_root(p, lo: fmpq, hi: fmpq, s_lo: int, width: fmpq) -> tuple[fmpq, fmpq]:
    """Shrink a bracketing box (sign s_lo at lo, opposite at hi) to ``width``."""
    bits = 53
    while hi - lo > width:
        mid = (lo + hi) / 2
        with working_precision(bits):
            s = sign(_point(p, mid))
        if s is None:
            if bits > 4000:
                break  # cannot separate further: return the current bracket
            bits *= 2
            continue
        if s == s_lo:
            lo = mid
        else:
            hi = mid
    return lo, hi


def _branch_and_bound(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    dp = derivative(p)
    a, b = interval.start.ball(), interval.end.ball()
    lo0, hi0 = _to_fmpq(a.lower()), _to_fmpq(b.upper())
    min_width = _q(max(tolerance, 1e-12) / 1000)
    stack = [(lo0, hi0)]
    found: list[tuple[fmpq, fmpq]] = []
    exact_points: list[fmpq] = []
    ambiguous: list[tuple[fmpq, fmpq, str]] = []
    boxes = 0
    while stack:
        lo, hi = stack.pop()
        boxes += 1
        if boxes > _MAX_BOXES:
            ambiguous.append((lo, hi, "the branch-and-bound budget ran out"))
            ambiguous += [(l_, h_, "the branch-and-bound budget ran out") for l_, h_ in stack]
            break
        out, slope = _excluded(p, dp, lo, hi)
        if out:
            continue
        if slope is not None and excludes_zero(slope):
            f_lo, f_hi = _point(p, lo), _point(p, hi)
            s_lo, s_hi = sign(f_lo), sign(f_hi)
            if s_lo is not None and s_hi is not None:
                if s_lo != s_hi:
                    found.append((lo, hi, s_lo))
                continue  # strictly monotone: one root, or none
            for end, value in ((lo, f_lo), (hi, f_hi)):
                if value.is_exact() and value == 0:
                    exact_points.append(end)
            if any(value.is_exact() and value == 0 for value in (f_lo, f_hi)) and \
                    (s_lo is not None or s_hi is not None or lo == hi):
                continue  # the root is the exact end point; monotone: no other
        if hi - lo < min_width:
            ambiguous.append((lo, hi, "possible multiple root or tangency: neither exclusion "
                              "nor a monotone sign change could be proven"))
            continue
        cut = lo + (hi - lo) * _SPLIT
        stack += [(cut, hi), (lo, cut)]
    return _finish_branch_and_bound(p, interval, tolerance, found, exact_points, ambiguous)


def _finish_branch_and_bound(p, interval, tolerance, found, exact_points, ambiguous):
    roots, undecided = [], []
    for lo, hi, s_lo in found:
        bracket = {"lo": lo, "hi": hi}

        def make(tol: float, bracket=bracket, s_lo=s_lo) -> arb:
            w = _q(tol) / 2
            bracket["lo"], bracket["hi"] = _bisect_root(p, bracket["lo"], bracket["hi"], s_lo, w)
            return _ball(bracket["lo"], bracket["hi"])

        where, t = _locate(make, None, interval, tolerance)
        if where is None:
            undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
        elif where:
            make(tolerance)
            roots.append(RealRoot(_ball(bracket["lo"], bracket["hi"]), None, make))
    for q in sorted(set(exact_points)):
        t = arb(q)
        where = _inside(t, None, interval, 53)
        if where:
            roots.append(RealRoot(t, None, None))
    for lo, hi, reason in _merge(ambiguous):
        box = _ball(lo, hi)
        undecided.append(Undecided(box, f"{reason} near t ≈ {float(box.mid()):.6g}"))
    roots = _dedupe(sorted(roots, key=lambda r: float(r.t.mid())))
    return RootIsolation(tuple(roots), tuple(undecided), BRANCH_AND_BOUND)


def _dedupe(roots: list[RealRoot]) -> list[RealRoot]:
    """A root found as an exact box end and as a bracket is one root."""
    out: list[RealRoot] = []
    for r in roots:
        if out and out[-1].t.overlaps(r.t) and (out[-1]._refine is None or r._refine is None):
            keep = out[-1] if out[-1]._refine is None else r
            out[-1] = keep
            continue
        out.append(r)
    return out


def _merge(boxes):
    out = []
    for lo, hi, reason in sorted(boxes):
        if out and lo <= out[-1][1]:
            out[-1] = (out[-1][0], max(hi, out[-1][1]), out[-1][2])
        else:
            out.append((lo, hi, reason))
    return out


def isolate_real_roots(poly: fmpq_mpoly, interval: TimeRange,
                       tolerance: float = 1e-9) -> RootIsolation:
    """Every real root of ``poly(t, sin t, cos t)`` on the closed range, certified."""
    p = reduce_trig(poly)
    if p.is_zero():
        raise IdenticallyZeroError("the function is identically zero along the path")
    if uses_t(p) and uses_trig(p):
        return _branch_and_bound(p, interval, tolerance)
    if uses_trig(p):
        return _half_angle(p, interval, tolerance)
    return _exact_univariate(p, interval, tolerance)
