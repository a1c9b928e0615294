"""Roots of sin/cos paths by the tangent half-angle u = tan(t/2).

s = 2u/(1+u²) and c = (1-u²)/(1+u²) turn μ into M(u) = (1+u²)^d μ ∈ Q[u]; its real roots
are isolated exactly (:mod:`singcheck.roots.rational`), after deflating M(u) = N(u^k) when
it can, and mapped to t = 2·atan(u) + 2kπ with Arb's rigorous ``atan`` for every period
that meets the range; t ≡ π (u = ∞) is decided exactly by evaluating μ at s = 0, c = -1.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

from flint import arb, fmpq, fmpq_mpoly, fmpq_poly, fmpz_poly

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.trig import LinearInPi, TimeRange, sin_cos_parts
from singcheck.budget import checkpoint
from singcheck.roots.enclosures import (
    HALF_ANGLE,
    IN_U,
    ExactTime,
    RealRoot,
    RootIsolation,
    Undecided,
    locate_root,
    point_time,
)
from singcheck.roots.rational import (
    RationalRoot,
    bits_for,
    exact_tolerance,
    real_roots_exact,
    root_of_power,
)

_TWO_U = fmpq_poly([0, 2])



def half_angle_polynomial(p: fmpq_mpoly) -> tuple[fmpq_poly, int]:
    """M(u) = (1+u²)^d · p(2u/(1+u²), (1-u²)/(1+u²)) and d (p reduced, free of t).

    With p = P₀(c) + s·P₁(c), M = H(P₀, d)(u²) + 2u·H(P₁, d-1)(u²) where
    H(Σ aₖcᵏ, n)(w) = Σ aₖ (1-w)ᵏ (1+w)ⁿ⁻ᵏ, a polynomial in w = u² (exact rational
    arithmetic throughout; :func:`_half_angle_parts`).
    """
    even, odd, d = _half_angle_parts(p)
    m = even(_U2)
    if odd is not None:
        m += _TWO_U * odd(_U2)
    return m, d


def _half_angle_parts(p: fmpq_mpoly, parts: tuple | None = None
                      ) -> tuple[fmpq_poly, fmpq_poly | None, int]:
    """(H(P₀, d), H(P₁, d-1) or None when p is free of s, d) of
    :func:`half_angle_polynomial`, as polynomials in w = u².

    Writing c = (1-w)/(1+w) = -1 + 2y with y = 1/(1+w),
    (1+w)^m P(c) = y^(-m) P(-1 + 2y) is the reversal of P(-1 + 2y) taken at 1 + w: two
    compositions with linear polynomials in FLINT and a reversal.  P₀ = p(s = 0) and
    s·P₁ = p - P₀ (p has degree ≤ 1 in s; ``parts``: (P₀, P₁) when the caller has
    them), d the total degree of p (free of t).
    """
    d = max(int(p.total_degree()), 0)
    p0, p1 = parts or sin_cos_parts(p)
    return _homogenised(p0, d), _homogenised(p1, d - 1) if p1 is not None else None, d


def _homogenised(poly: fmpq_poly, n: int) -> fmpq_poly:
    """(1+w)^n P((1-w)/(1+w)) for P of degree ≤ n, as a polynomial in w."""
    if poly.is_zero():
        return fmpq_poly([])
    top = poly.degree()
    shifted = poly(_MINUS_ONE_PLUS_2Y)
    cs = shifted.numer().coeffs()  # reversed as integers: the denominator is kept
    cs = [0] * (top + 1 - len(cs)) + cs[::-1]
    out = fmpq_poly(fmpz_poly(cs), shifted.denom())(_ONE_PLUS_W)
    return out if n == top else out * _ONE_PLUS_W ** (n - top)


def deflated_half_angle(p: fmpq_mpoly, parts: tuple | None = None) -> tuple[fmpq_poly, int]:
    """(N, k) with M(u) = N(u^k) for M = :func:`half_angle_polynomial` (p), k as large as
    FLINT's deflation finds.  For p free of s, M = H(u²) exactly, so N and k are those of
    H's own deflation with k doubled, without forming M (twice H's degree) and
    deflating it back: the same N and k.  ``parts``: p's (P₀, P₁) when the caller has
    them (:func:`~singcheck.algebra.trig.sin_cos_parts`)."""
    even, odd, _ = _half_angle_parts(p, parts)
    if odd is None and even.degree() >= 1:
        deflated, k = even.numer().deflation()
        return fmpq_poly(deflated), 2 * max(int(k), 1)
    m = even(_U2)
    if odd is not None:
        m += _TWO_U * odd(_U2)
    deflated, k = m.numer().deflation()
    return fmpq_poly(deflated), max(int(k), 1)


_MINUS_ONE_PLUS_2Y, _ONE_PLUS_W, _U2 = (fmpq_poly(c) for c in ([-1, 2], [1, 1], [0, 0, 1]))


@dataclass(frozen=True)
class _HalfAngleRoot:
    """One real root u₀ of M: ``ball(tol)`` encloses 2·atan(u₀); ``exact`` is u₀ ∈ {0, ±1}."""

    ball: Callable[[float], arb]
    exact: LinearInPi | None
    multiplicity: int
    time: ExactTime | None = None  # α = u₀ exactly, for exact decisions at the root


def _half_angle_roots(m: fmpq_poly) -> list[_HalfAngleRoot]:
    """The real roots of M, isolated exactly after deflation (:func:`_deflated_roots`)."""
    deflated, k = m.numer().deflation()
    return _deflated_roots(fmpq_poly(deflated), max(int(k), 1))


def _deflated_roots(deflated: fmpq_poly, k: int) -> list[_HalfAngleRoot]:
    """The real roots of M(u) = N(u^k) (N = ``deflated``), isolated exactly.

    When M(u) = N(u^k) (flint's deflation; even paths give k = 2), the roots of N are
    isolated instead (degree divided by k): each root v > 0 of N gives u = v^(1/k), and
    also -v^(1/k) when k is even; v < 0 gives -(-v)^(1/k) when k is odd and nothing
    real when k is even; v = 0 gives u = 0 with k times the multiplicity.  u is enclosed
    by Arb's rigorous k-th roots of the interval ends (u ↦ u^k is monotone on each side).
    """
    out = []
    # k even: u^k = v has no real root for v < 0, so only v ≥ 0 is isolated
    for rr, mult in real_roots_exact(deflated, nonnegative_only=k % 2 == 0):
        checkpoint()
        for q in (fmpq(0), fmpq(1), fmpq(-1)):  # u = 0, ±1 (t = 0, ±π/2) are exact
            rr.pin(q)
        if rr.lo == rr.hi == 0:  # u = 0 exactly: t = 0 (Arb's k-th root of 0 is NaN)
            out.append(_HalfAngleRoot(lambda tol: arb(0), LinearInPi(Fraction(0)), mult * k,
                                      ExactTime(IN_U, lambda rr=rr: rr)))
            continue
        positive = rr.lo >= 0
        if not positive and k % 2 == 0:
            continue
        signs = (1, -1) if k % 2 == 0 else (1 if positive else -1,)
        for sign in signs:
            exact = None
            if rr.lo == rr.hi and abs(rr.lo) == 1:
                exact = LinearInPi(Fraction(0), Fraction(sign, 2))
            out.append(_HalfAngleRoot(_atan_ball(rr, k, sign), exact, mult,
                                      ExactTime(IN_U, _u_root(rr, k, sign))))
    return out


def _u_root(rr: RationalRoot, k: int, sign: int) -> Callable[[], RationalRoot]:
    """The exact u = sign·v^(1/k) for the root v of N isolated by ``rr``: a rational
    interval isolating u among the real roots of h(u^k), h the minimal polynomial of v
    (:func:`~singcheck.roots.rational.root_of_power`)."""

    def locate():
        return rr if k == 1 else root_of_power(rr, k, sign)

    return locate


def _atan_ball(rr: RationalRoot, k: int, sign: int) -> Callable[[float], arb]:
    """t = 2·atan(sign·|v|^(1/k)) for the root v of N isolated by ``rr``."""

    def u_bounds(bits: int) -> arb:
        with working_precision(bits):
            ends = [arb(abs(q)).root(k) if k > 1 else arb(abs(q)) for q in (rr.lo, rr.hi)]
            return sign * ends[0].union(ends[1])

    done: dict[float, arb] = {}  # tol -> its ball: the root is mapped once per tolerance

    def ball(tol: float) -> arb:
        hit = done.get(tol)
        if hit is not None:
            return hit
        width = exact_tolerance(tol) / 4
        bits = bits_for(tol)
        rr.bisect_to(width)
        u = u_bounds(bits)  # (the ball of the final interval is the one mapped)
        while k > 1 and rr.lo != rr.hi and float(u.rad()) > tol / 8:
            checkpoint()
            width /= 16
            rr.bisect_to(width)
            u = u_bounds(bits)
        with working_precision(bits):
            hit = done[tol] = 2 * u.atan()
        return hit

    return ball


def _half_angle(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    parts = sin_cos_parts(p)
    deflated, k = deflated_half_angle(p, parts)
    at_pi = parts[0](-1)  # μ at s = 0, c = -1: P₀(-1)
    bases: list[tuple[Callable[[float], arb], LinearInPi | None, int | None,
                      ExactTime | None]] = [
        (r.ball, r.exact, r.multiplicity, r.time) for r in _deflated_roots(deflated, k)]
    if at_pi == 0:

        def base_pi(tol: float) -> arb:
            with working_precision(bits_for(tol)):
                return arb.pi()

        # multiplicity of t = π: the degree drop of M counts it
        bases.append((base_pi, LinearInPi(Fraction(0), Fraction(1)), None,
                      point_time(None, 0, -1)))
    roots, undecided = [], []
    for index, (base, exact, mult, time) in enumerate(bases):
        for k in _periods(base(tolerance), interval):
            checkpoint()  # a range of 10^6 holds 10^5 periods: each costs a ball map

            def make(tol: float, base=base, k=k) -> arb:
                with working_precision(bits_for(tol)):
                    return base(tol) + 2 * k * arb.pi()

            shifted = None
            if exact is not None:
                shifted = LinearInPi(exact.rational, exact.pi_coefficient + 2 * k)
            where, t = locate_root(make, shifted, interval, tolerance)
            if where is None and time is not None and _at_range_end(time, k, interval):
                where = True  # exactly at a (closed) end of the range
            if where is None:
                undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
            elif where:
                roots.append(RealRoot(make(tolerance), mult, make, period=(index, k),
                                      exact=time))
    roots.sort(key=lambda r: float(r.t.mid()))
    return RootIsolation(tuple(roots), tuple(undecided), HALF_ANGLE)


def tan_polynomial(b: int) -> fmpq_poly:
    """P(u) = ((1 + iu)^b - (1 - iu)^b)/(2i), whose real roots are exactly tan(mπ/b) for the
    integers m with |m/b| < 1/2: (1 + iu)/(1 - iu) = e^(2i·atan u) is a b-th root of
    unity exactly when atan u is a multiple of π/b."""
    coeffs = [0] * (b + 1)
    for j in range(1, b + 1, 2):
        coeffs[j] = math.comb(b, j) * (-1) ** ((j - 1) // 2)
    return fmpq_poly(coeffs)


def _at_range_end(time: ExactTime, k: int, interval: TimeRange) -> bool:
    """Exactly: is the root t = 2·atan(u₀) + 2kπ equal to an end of the range?

    Only an end that is a rational multiple qπ can be (t is then π-rational and u₀ is
    algebraic; a rational non-zero end is transcendental's opposite, and t = 0 is found
    before).  t = qπ means atan(u₀) = φ = (q/2 - k)π, possible only for |φ| < π/2, i.e.
    u₀ = tan(aπ/b) with φ = aπ/b: u₀ must be a root of :func:`tan_polynomial` (b) — a
    common factor with u₀'s polynomial vanishing on its isolating interval, decided
    exactly — and then it is *some* tan(mπ/b); it is the one for m = a when its interval,
    refined, excludes every other tan(mπ/b) ball and meets that one.
    """
    for end in (interval.start, interval.end):
        if end.rational != 0:
            continue
        phi = end.pi_coefficient / 2 - k
        if not -Fraction(1, 2) < phi < Fraction(1, 2):
            continue
        a, b = phi.numerator, phi.denominator
        rr = time.locate()
        h = rr.poly.gcd(tan_polynomial(b))
        if h.degree() < 1:
            continue
        on_h = h(rr.lo) == 0 if rr.lo == rr.hi else h(rr.lo) * h(rr.hi) < 0
        if not on_h:
            continue
        others = [m for m in range(-b, b + 1) if 2 * abs(m) < b and m != a]
        for _ in range(200):
            with working_precision(64 + 4 * max(0, -int(math.log2(float(rr.width()) or 1e-300)))):
                box = rr.ball()
                target = (arb.pi() * a / b).tan()
                if not box.overlaps(target):
                    break
                if not any(box.overlaps((arb.pi() * m / b).tan()) for m in others):
                    return True
            rr.bisect_to(rr.width() / 16)
    return False


def _periods(t0: arb, interval: TimeRange) -> range:
    """Every k for which t0 + 2kπ may meet the range (a superset: a k is dropped only
    when the float estimate misses the range by far more than rounding and the ball's
    radius could account for).  A lazy range: a range of 2³¹ holds 3·10⁸ periods, which
    the caller walks with a checkpoint each (a list of them took 70 s and gigabytes before
    any checkpoint: fuzz campaign, issue 31)."""
    two_pi = 2 * math.pi
    x, start, end = float(t0.mid()), float(interval.start), float(interval.end)
    margin = float(t0.rad()) + 1e-6 * (1 + abs(x) + abs(start) + abs(end))
    lo = math.ceil((start - margin - x) / two_pi)
    hi = math.floor((end + margin - x) / two_pi)
    while start - margin <= x + two_pi * (lo - 1):  # (the divisions round)
        lo -= 1
    while start - margin > x + two_pi * lo:
        lo += 1
    while x + two_pi * (hi + 1) <= end + margin:
        hi += 1
    while hi >= lo and x + two_pi * hi > end + margin:
        hi -= 1
    return range(lo, hi + 1)
