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

from flint import arb, fmpq, fmpq_mpoly, fmpq_poly

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.trig import LinearInPi, TimeRange
from singcheck.roots.enclosures import HALF_ANGLE, RealRoot, RootIsolation, Undecided, locate_root
from singcheck.roots.rational import (
    RationalRoot,
    bits_for,
    exact_tolerance,
    real_roots_exact,
)

_ONE_PLUS_U2, _ONE_MINUS_U2, _TWO_U = (fmpq_poly(c) for c in ([1, 0, 1], [1, 0, -1], [0, 2]))



def _half_angle_polynomial(p: fmpq_mpoly) -> tuple[fmpq_poly, int]:
    """M(u) = (1+u²)^d · p(2u/(1+u²), (1-u²)/(1+u²)) and d (p reduced, free of t).

    With p = P₀(c) + s·P₁(c), M = H(P₀, d) + 2u·H(P₁, d-1) where
    H(Σ aₖcᵏ, n) = Σ aₖ (1-u²)ᵏ (1+u²)ⁿ⁻ᵏ, summed by Horner's rule in 1-u²
    (exact rational arithmetic throughout).
    """
    d = max((j + k for (_i, j, k), _ in p.terms()), default=0)
    by_s: list[dict[int, fmpq]] = [{}, {}]
    for (_i, j, k), c in p.terms():
        by_s[j][k] = c
    one_plus = [fmpq_poly([1])]
    for _ in range(d):
        one_plus.append(one_plus[-1] * _ONE_PLUS_U2)

    def homogenised(coeffs: dict[int, fmpq], n: int) -> fmpq_poly:
        if not coeffs:
            return fmpq_poly([])
        top = max(coeffs)
        r = fmpq_poly([coeffs[top]])
        for k in range(top - 1, -1, -1):
            r = r * _ONE_MINUS_U2 + coeffs.get(k, 0) * one_plus[top - k]
        return r * one_plus[n - top]

    return homogenised(by_s[0], d) + _TWO_U * homogenised(by_s[1], d - 1), d


@dataclass(frozen=True)
class _HalfAngleRoot:
    """One real root u₀ of M: ``ball(tol)`` encloses 2·atan(u₀); ``exact`` is u₀ ∈ {0, ±1}."""

    ball: Callable[[float], arb]
    exact: LinearInPi | None
    multiplicity: int


def _half_angle_roots(m: fmpq_poly) -> list[_HalfAngleRoot]:
    """The real roots of M, isolated exactly after deflation.

    When M(u) = N(u^k) (flint's deflation; even paths give k = 2), the roots of N are
    isolated instead (degree divided by k): each root v > 0 of N gives u = v^(1/k), and
    also -v^(1/k) when k is even; v < 0 gives -(-v)^(1/k) when k is odd and nothing
    real when k is even; v = 0 gives u = 0 with k times the multiplicity.  u is enclosed
    by Arb's rigorous k-th roots of the interval ends (u ↦ u^k is monotone on each side).
    """
    deflated, k = m.numer().deflation()
    k = max(int(k), 1)
    out = []
    # k even: u^k = v has no real root for v < 0, so only v ≥ 0 is isolated
    for rr, mult in real_roots_exact(fmpq_poly(deflated), nonnegative_only=k % 2 == 0):
        for q in (fmpq(0), fmpq(1), fmpq(-1)):  # u = 0, ±1 (t = 0, ±π/2) are exact
            rr.pin(q)
        if rr.lo == rr.hi == 0:  # u = 0 exactly: t = 0 (Arb's k-th root of 0 is NaN)
            out.append(_HalfAngleRoot(lambda tol: arb(0), LinearInPi(Fraction(0)), mult * k))
            continue
        positive = rr.lo >= 0
        if not positive and k % 2 == 0:
            continue
        signs = (1, -1) if k % 2 == 0 else (1 if positive else -1,)
        for sign in signs:
            exact = None
            if rr.lo == rr.hi and abs(rr.lo) == 1:
                exact = LinearInPi(Fraction(0), Fraction(sign, 2))
            out.append(_HalfAngleRoot(_atan_ball(rr, k, sign), exact, mult))
    return out


def _atan_ball(rr: RationalRoot, k: int, sign: int) -> Callable[[float], arb]:
    """t = 2·atan(sign·|v|^(1/k)) for the root v of N isolated by ``rr``."""

    def u_bounds(bits: int) -> arb:
        with working_precision(bits):
            ends = [arb(abs(q)).root(k) if k > 1 else arb(abs(q)) for q in (rr.lo, rr.hi)]
            return sign * ends[0].union(ends[1])

    def ball(tol: float) -> arb:
        width = exact_tolerance(tol) / 4
        bits = bits_for(tol)
        rr.bisect_to(width)
        while k > 1 and rr.lo != rr.hi and float(u_bounds(bits).rad()) > tol / 8:
            width /= 16
            rr.bisect_to(width)
        with working_precision(bits):
            return 2 * u_bounds(bits).atan()

    return ball


def _half_angle(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    m, _ = _half_angle_polynomial(p)
    at_pi = p.subs({"s": 0, "c": -1})
    bases: list[tuple[Callable[[float], arb], LinearInPi | None, int | None]] = [
        (r.ball, r.exact, r.multiplicity) for r in _half_angle_roots(m)]
    if at_pi.is_zero():

        def base_pi(tol: float) -> arb:
            with working_precision(bits_for(tol)):
                return arb.pi()

        # multiplicity of t = π: the degree drop of M counts it
        bases.append((base_pi, LinearInPi(Fraction(0), Fraction(1)), None))
    roots, undecided = [], []
    for index, (base, exact, mult) in enumerate(bases):
        for k in _periods(base(tolerance), interval):
            def make(tol: float, base=base, k=k) -> arb:
                with working_precision(bits_for(tol)):
                    return base(tol) + 2 * k * arb.pi()

            shifted = None
            if exact is not None:
                shifted = LinearInPi(exact.rational, exact.pi_coefficient + 2 * k)
            where, t = locate_root(make, shifted, interval, tolerance)
            if where is None:
                undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
            elif where:
                roots.append(RealRoot(make(tolerance), mult, make, (index, k)))
    roots.sort(key=lambda r: float(r.t.mid()))
    return RootIsolation(tuple(roots), tuple(undecided), HALF_ANGLE)


def _periods(t0: arb, interval: TimeRange) -> list[int]:
    """Every k for which t0 + 2kπ may meet the range (a superset: a k is dropped only
    when the float estimate misses the range by far more than rounding and the ball's
    radius could account for)."""
    two_pi = 2 * math.pi
    x, start, end = float(t0.mid()), float(interval.start), float(interval.end)
    margin = float(t0.rad()) + 1e-6 * (1 + abs(x) + abs(start) + abs(end))
    lo = math.floor((start - x) / two_pi) - 1
    hi = math.ceil((end - x) / two_pi) + 1
    return [k for k in range(lo, hi + 1)
            if start - margin <= x + two_pi * k <= end + margin]
