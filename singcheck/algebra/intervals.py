"""Rigorous interval (ball) evaluation of exact polynomials.

Enclosures are FLINT ``arb`` balls (real) and ``acb`` balls (complex): every
operation rounds outward, so the true value of an expression at any point of the
input balls lies in the output ball.  FLINT's comparisons are certain: ``x > 0`` is
True only when every point of ``x`` is positive, so a False says "not proven",
never "proven false".  That is the three-valued logic a certificate needs.

>>> from flint import fmpq_mpoly_ctx
>>> ctx = fmpq_mpoly_ctx.get(("x", "y"), "lex")
>>> x, y = ctx.gens()
>>> b = evaluate(x**2 - 2*y, [arb(3), arb(1)])
>>> b.contains(7) and b.rad() == 0
True
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

from flint import acb, arb, ctx, fmpq, fmpq_mpoly

Ball = arb | acb


def fraction_ball(q: Fraction | int) -> arb:
    """The ball of an exact rational (exact when dyadic, else a tight enclosure)."""
    q = Fraction(q)
    return arb(fmpq(q.numerator, q.denominator))


def power(x: Ball, e: int) -> Ball:
    """An enclosure of ``x**e`` (e ≥ 1) for every point of the ball ``x``.

    A real ball's power is taken at its ends, where x ↦ x^e reaches its extremes over an
    interval (it is monotone on each side of 0): [L^e, U^e], or for an even e [U^e, L^e]
    below 0 and [0, max(|L|, |U|)^e] across it; each end power is a product of exact
    ends, rounded outward.  (python-flint's ``**`` takes Arb's real power, exp(e·log x):
    NaN for a ball around 0, and wide for a wide positive one.)  A complex ball is
    multiplied out."""
    if e == 1:
        return x
    if not isinstance(x, arb):
        out = x
        for _ in range(e - 1):
            out = out * x
        return out
    if x.is_exact():  # a point (a constant coordinate): its power, rounded outward
        return _point_power(x, e)
    if e == 2:  # [min |x|², max |x|²]: Arb's bounds of |x| (the commonest power, fast)
        a, b = x.abs_lower(), x.abs_upper()
        return (a * a).union(b * b)
    lo, hi = x.lower(), x.upper()  # (x·x would be m² ± (2|m|r + r²): 2r² wider)
    if e % 2 == 1 or lo >= 0:
        return _point_power(lo, e).union(_point_power(hi, e))
    if hi <= 0:
        return _point_power(hi, e).union(_point_power(lo, e))
    return arb(0).union(_point_power(max(-lo, hi), e))


def _point_power(p: arb, e: int) -> arb:
    """p^e for an exact ball p, by squaring and multiplying (each step rounded outward)."""
    if e == 2:
        return p * p
    if e == 3:  # (the loop's products, without its steps)
        return p * (p * p)
    if e == 4:
        q = p * p
        return q * q
    out, base = arb(1), p
    while e:
        if e & 1:
            out = out * base
        e >>= 1
        if e:
            base = base * base
    return out


def evaluate(poly: fmpq_mpoly, values: Sequence[Ball], powers: dict | None = None) -> Ball:
    """Enclose ``poly(values)``; ``values[i]`` is the ball of the i-th generator.

    Powers are computed once per generator and exponent (``powers``, when the caller
    shares them between polynomials enclosed at the same balls); each term is summed in
    ball arithmetic, so the result encloses the exact value for every point of the
    input balls.
    """
    if powers is None:
        powers = {}  # (generator, exponent ≥ 2) -> its power
    total: Ball = arb(0)
    for coeff, factors in _terms(poly):
        if not factors:
            total = total + coeff
            continue
        term: Ball = coeff
        for i, e in factors:
            if e == 1:
                term = term * values[i]
            else:
                p = powers.get((i, e))
                if p is None:
                    p = powers[i, e] = power(values[i], e)
                term = term * p
        total = total + term
    return total


_TERMS: dict[int, tuple[fmpq_mpoly, dict]] = {}


def _terms(poly: fmpq_mpoly) -> list[tuple[arb, tuple[tuple[int, int], ...]]]:
    """[(ball of the coefficient, ((generator, exponent), …))] of ``poly``'s terms at the
    current precision, once per polynomial and precision (the entry holds ``poly``, so
    its id is not reused): :func:`evaluate` runs on the same few polynomials thousands
    of times."""
    hit = _TERMS.get(id(poly))
    if hit is None or hit[0] is not poly:
        if len(_TERMS) > 1024:
            _TERMS.clear()
        hit = _TERMS[id(poly)] = (poly, {})
    terms = hit[1].get(ctx.prec)
    if terms is None:
        terms = hit[1][ctx.prec] = [
            (arb(coeff), tuple((i, int(e)) for i, e in enumerate(exps) if e))
            for exps, coeff in poly.terms()]
    return terms


def hull(lo: arb, hi: arb) -> arb:
    """The smallest ball holding both balls (used for ``[lo, hi]`` intervals)."""
    return lo.union(hi)


def sign(x: arb) -> int | None:
    """+1 or -1 when the sign of every point of ``x`` is proven, else None."""
    if x > 0:
        return 1
    if x < 0:
        return -1
    return None


def excludes_zero(x: Ball) -> bool:
    """True only when 0 is provably not in the ball (real or complex)."""
    if isinstance(x, acb):
        return not x.real.contains(0) or not x.imag.contains(0)
    return not x.contains(0)


def endpoints(x: arb) -> tuple[float, float]:
    """Floats ``lo ≤ x ≤ hi`` for every point of the ball (rounded outward)."""
    import math

    lo_ball, hi_ball = x.lower(), x.upper()
    lo, hi = float(lo_ball), float(hi_ball)
    # float() rounds to nearest: step outward one ulp unless the float is already outside
    if not arb(lo) <= lo_ball:
        lo = math.nextafter(lo, -math.inf)
    if not arb(hi) >= hi_ball:
        hi = math.nextafter(hi, math.inf)
    return lo, hi


class working_precision:  # noqa: N801 (used as a function: ``with working_precision(b):``)
    """Run a block with FLINT's ball precision raised to at least ``bits``; restore after
    (also on an exception).  A plain class rather than a generator context manager: it
    is entered dozens of times per certificate, and contextlib's machinery cost more
    than the block."""

    __slots__ = ("bits", "old")

    def __init__(self, bits: int) -> None:
        self.bits = int(bits)

    def __enter__(self) -> None:
        self.old = ctx.prec
        ctx.prec = max(self.old, self.bits)

    def __exit__(self, *exc) -> None:
        ctx.prec = self.old
