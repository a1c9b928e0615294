"""Exactly checked segments: does a segment parallel to an axis meet the variety?

A segment from a rational point along one axis is free when every factor of the
decomposed variety, restricted to it, has no root on it: Descartes' rule of signs on the
interval, else exact real-root isolation.  Both the region joins
(:mod:`singcheck.spaces.regions`) and the exact plane adjacency
(:mod:`singcheck.spaces.plane_adjacency`) rest on it.
"""

from __future__ import annotations

from fractions import Fraction

from flint import fmpq_poly

from singcheck.roots.rational import to_fmpq
from singcheck.spaces.cad import (
    OpenCAD,
    as_univariate,
)
from singcheck.spaces.solution_counts import roots_within


def no_root_between(q: fmpq_poly, a: Fraction, b: Fraction) -> bool:
    """True when q has no root in the closed [a, b] (exact).

    Quick proof first: q(a), q(b) ≠ 0 and no sign variation in the coefficients of
    (1+u)^d · q((a + b·u)/(1+u)), whose positive roots are the roots of q in (a, b)
    (Descartes).  Otherwise the roots are isolated and compared exactly.
    """
    qa, qb = to_fmpq(a), to_fmpq(b)
    va, vb = q(qa), q(qb)
    if va == 0 or vb == 0 or (va > 0) != (vb > 0):  # a root at an end, or a sign change
        return False
    d = q.degree()
    num, one_plus = fmpq_poly([qa, qb]), fmpq_poly([1, 1])
    total, power = fmpq_poly([]), fmpq_poly([1])
    pows = [fmpq_poly([1])]
    for _ in range(d):
        pows.append(pows[-1] * one_plus)
    for k, c in enumerate(q.coeffs()):
        if c != 0:
            total += c * power * pows[d - k]
        power *= num
    signs = [c > 0 for c in total.coeffs() if c != 0]
    if all(x == signs[0] for x in signs):
        return True
    return roots_within(q, (a, b)) == 0


def segment_is_free(cad: OpenCAD, point: tuple[Fraction, ...], axis: int,
                    a: Fraction, b: Fraction) -> bool:
    """True when no factor of the variety vanishes on the segment that runs along
    ``axis`` from a to b through ``point`` (whose ``axis`` coordinate is ignored): exact."""
    values = {v: to_fmpq(x) for i, (v, x) in enumerate(zip(cad.variables, point, strict=True))
              if i != axis}
    for f in cad.factors:
        q = as_univariate(f.subs(values), axis)
        if q.is_zero():
            return False
        if q.degree() >= 1 and not no_root_between(q, a, b):
            return False
    return True
