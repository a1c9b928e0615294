"""Exact zero tests of sums of trig polynomials at given times (the joins of a path).

A join of two segments is a time at which two pieces, each a polynomial in its own
local time τ and in sin τ, cos τ, must give the same pose.  :func:`sum_is_zero` decides
exactly whether ``Σ pᵢ(τᵢ, sin τᵢ, cos τᵢ) = 0`` for local times ``τᵢ = aᵢ + bᵢπ``:

* at ``τ = bπ`` (b rational) each value is ``Σₖ πᵏ Qₖ(sin bπ, cos bπ)`` with Qₖ over Q;
  sin bπ and cos bπ are algebraic and π is transcendental over the algebraic numbers, so
  the sum is zero exactly when each power's coefficient is.  Angles are brought to a
  common one gπ (cos(mθ), sin(mθ) by Chebyshev polynomials), and
  ``P₀(c) + s·P₁(c) = 0`` at ``c = cos gπ``, ``s = sin gπ`` is decided with the minimal
  polynomial m of c (the irreducible factor of ``T_q(x) − (−1)ᵖ``, g = p/q, that
  vanishes at c, picked by ball arithmetic): P₁(c) = 0 ⇔ m | P₁; then the sum is zero
  ⇔ m | P₀; otherwise s = −P₀(c)/P₁(c) is needed, i.e. m | P₀² − (1 − c²)P₁² and the
  sign of s equal to that of −P₀(c)P₁(c) (both non-zero, so balls decide it);
* at a rational ``τ = a ≠ 0`` (Lindemann–Weierstrass: e^{ia} is transcendental) a
  polynomial in sin a, cos a, reduced modulo s² + c² − 1, is algebraic only when it is
  a constant: a non-constant part makes the sum non-zero;
* ``τ = a + bπ`` with a and b both non-zero, where sin/cos or τ is used, is not decided
  (None).
"""

from __future__ import annotations

from fractions import Fraction
from math import gcd

from flint import arb, arb_poly, fmpq, fmpq_mpoly, fmpq_poly, fmpz_poly

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.trig import (
    TRIG,
    LinearInPi,
    cos_multiple,
    reduce_trig,
    sin_multiple,
)

_PRECISIONS = (64, 256, 1024, 4096)


def _q(x: Fraction) -> fmpq:
    return fmpq(x.numerator, x.denominator)


def _by_t_power(p: fmpq_mpoly, scale: Fraction) -> dict[int, fmpq_mpoly]:
    """{k: Qₖ(s, c)} with p(bπ, s, c) = Σₖ πᵏ Qₖ(s, c) (``scale`` = b)."""
    out: dict[int, dict] = {}
    for (i, j, k), coeff in p.terms():
        out.setdefault(i, {})[(0, j, k)] = coeff * _q(scale) ** i
    return {i: TRIG.from_dict(d) for i, d in out.items()}


def _at_rational(p: fmpq_mpoly, a: Fraction) -> fmpq_mpoly:
    """p(a, s, c): t substituted, s and c kept."""
    return reduce_trig(p.compose(TRIG.from_dict({(0, 0, 0): _q(a)}) if a else TRIG.from_dict({}),
                                 *TRIG.gens()[1:], ctx=TRIG))


def _rescaled(p: fmpq_mpoly, m: int) -> fmpq_mpoly:
    """p(sin mθ, cos mθ) as a polynomial in sin θ, cos θ (p free of t)."""
    return reduce_trig(p.compose(TRIG.gens()[0], sin_multiple(m), cos_multiple(m), ctx=TRIG))


def _rational_gcd(values: list[Fraction]) -> Fraction:
    num = den = 0
    for v in values:
        num = gcd(num, abs(v.numerator))
        den = den * v.denominator // gcd(den, v.denominator) if den else v.denominator
    return Fraction(num, den or 1)


def _in_c(p: fmpq_mpoly, odd: int) -> fmpq_poly:
    coeffs: dict[int, fmpq] = {}
    for (_, j, k), c in p.terms():
        if j == odd:
            coeffs[k] = c
    return fmpq_poly([coeffs.get(i, fmpq(0)) for i in range(max(coeffs, default=-1) + 1)])


def _minimal_polynomial_of_cos(g: Fraction) -> fmpq_poly:
    """The minimal polynomial over Q of cos(gπ): the factor of T_q − (−1)ᵖ vanishing there."""
    p, q = g.numerator, g.denominator
    target = fmpz_poly.chebyshev_t(q) - (-1) ** p
    factors = [f for f, _ in target.factor()[1]]
    for bits in _PRECISIONS:
        with working_precision(bits):
            c = (arb.pi() * arb(fmpq(p, q))).cos()
            hits = [f for f in factors
                    if arb_poly([arb(a) for a in f.coeffs()])(c).contains(0)]
        if len(hits) == 1:
            return fmpq_poly(hits[0])
    raise ArithmeticError(f"could not single out the minimal polynomial of cos({g}π)")


def _sign_of(poly: fmpq_poly, g: Fraction) -> int:
    """The sign of poly(cos gπ), known to be non-zero."""
    for bits in _PRECISIONS:
        with working_precision(bits):
            v = arb_poly([arb(a) for a in poly.coeffs()])((arb.pi() * arb(_q(g))).cos())
            if v > 0:
                return 1
            if v < 0:
                return -1
    raise ArithmeticError("a non-zero algebraic number could not be signed")  # pragma: no cover


def _zero_at_angle(p: fmpq_mpoly, g: Fraction) -> bool:
    """Exactly whether p(sin gπ, cos gπ) = 0 (p reduced, free of t)."""
    p = reduce_trig(p)
    if p.is_zero():
        return True
    g = g - 2 * (g // 2)  # the angle modulo 2π
    if g == 0:
        return sum((c for (_, j, _), c in p.terms() if j == 0), fmpq(0)) == 0
    p0, p1 = _in_c(p, 0), _in_c(p, 1)
    m = _minimal_polynomial_of_cos(g)
    if p1 % m == 0:
        return p0 % m == 0
    one_minus_c2 = fmpq_poly([1, 0, -1])
    if (p0 * p0 - one_minus_c2 * p1 * p1) % m != 0:
        return False
    if g.denominator == 1:  # sin gπ = 0, P₁(c) ≠ 0, so P₀(c) would have to vanish
        return p0 % m == 0
    s_sign = 1 if 0 < g < 1 else -1
    return s_sign == -_sign_of(p0, g) * _sign_of(p1, g)


def sum_is_zero(terms: list[tuple[fmpq_mpoly, LinearInPi]]) -> bool | None:
    """Exactly whether Σ pᵢ at τᵢ vanishes (see the module docstring); None if undecided
    (also for a polynomial outside ``TRIG``, with a pose angle's or a radical's variable)."""
    transcendental: dict[Fraction, fmpq_mpoly] = {}
    algebraic: list[tuple[Fraction, dict[int, fmpq_mpoly]]] = []
    for p, at in terms:
        if p.context() is not TRIG:
            return None  # a path ring's angle or radical variables: not handled here
        p = reduce_trig(p)
        if p.is_zero():
            continue
        a, b = at.rational, at.pi_coefficient
        if p.is_constant() or b == 0 and a == 0:
            algebraic.append((Fraction(0), _by_t_power(p, Fraction(0))))
        elif a == 0:
            algebraic.append((b, _by_t_power(p, b)))
        elif b == 0:
            q = _at_rational(p, a)
            transcendental[a] = transcendental.get(a, TRIG.from_dict({})) + q
        else:
            return None
    for q in transcendental.values():
        if not reduce_trig(q).is_constant():
            if len(transcendental) > 1:
                return None  # values of sin/cos at two rational angles: not handled
            return False
        algebraic.append((Fraction(0), {0: q}))
    angles = [b for b, _ in algebraic if b != 0]
    g = _rational_gcd(angles) if angles else Fraction(0)
    total: dict[int, fmpq_mpoly] = {}
    for b, powers in algebraic:
        m = int(b / g) if g else 0
        for k, q in powers.items():
            if m != 1 and m != 0:
                q = _rescaled(q, m)
            elif m == 0:
                q = _zero_angle(q)
            total[k] = total.get(k, TRIG.from_dict({})) + q
    return all(_zero_at_angle(q, g) for q in total.values())


def _zero_angle(q: fmpq_mpoly) -> fmpq_mpoly:
    """q at angle 0 (s = 0, c = 1) as a constant."""
    value = q.compose(TRIG.from_dict({}), TRIG.from_dict({}), TRIG.from_dict({(0, 0, 0): 1}),
                      ctx=TRIG)
    return value
