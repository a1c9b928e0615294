"""Certified isolation of the real roots of a trig polynomial on a time range.

``isolate_real_roots(poly, interval)`` returns balls in t, each proven to hold exactly
one root of ``poly(t, sin t, cos t)``, proves every gap between them root-free, and
reports whatever it cannot prove as :class:`~singcheck.roots.enclosures.Undecided` with
a reason.  It picks one of three methods:

* **exact univariate** (no sin/cos, here): the squarefree factors of the polynomial in t
  over Z; Descartes' rule of signs with Vincent–Collins–Akritas bisection (exact
  integer arithmetic) gives rational intervals each holding exactly one root, with a
  sign change at their ends, refined by bisection on exact signs;
* **tangent half-angle** (sin/cos only): :mod:`singcheck.roots.half_angle`;
* **interval branch-and-bound** (t mixed with sin/cos): :mod:`singcheck.roots.branch_bound`.
"""

from __future__ import annotations

from flint import arb, fmpq, fmpq_mpoly, fmpq_poly

from singcheck.algebra.trig import LinearInPi, TimeRange, reduce_trig, uses_t, uses_trig
from singcheck.roots.branch_bound import branch_and_bound
from singcheck.roots.enclosures import (
    EXACT,
    IdenticallyZeroError,
    RealRoot,
    RootIsolation,
    Undecided,
    locate_root,
)
from singcheck.roots.half_angle import _half_angle
from singcheck.roots.rational import (
    exact_tolerance,
    no_root_between,
    nonzero_on,
    real_roots_exact,
    to_fraction,
)


def _as_univariate_t(p: fmpq_mpoly) -> fmpq_poly:
    coeffs = [fmpq(0)] * (p.degrees()[0] + 1)
    for (i, _j, _k), c in p.terms():  # free of s and c here: one term per power of t
        coeffs[i] += c
    return fmpq_poly(coeffs)


def _exact_univariate(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    roots, undecided = [], []
    ends = [fmpq(e.rational.numerator, e.rational.denominator)
            for e in (interval.start, interval.end) if not e.pi_coefficient]
    poly = _as_univariate_t(p)
    if len(ends) == 2 and (nonzero_on(poly, *ends) or no_root_between(poly, *ends)):
        return RootIsolation((), (), EXACT)  # quick proofs: ball arithmetic, Descartes on [a, b]
    for rr, mult in real_roots_exact(poly):
        for q in ends:
            rr.pin(q)

        def make(tol: float, rr=rr) -> arb:
            rr.bisect_to(exact_tolerance(tol))
            return rr.ball()

        exact = LinearInPi(to_fraction(rr.lo)) if rr.lo == rr.hi else None
        where, t = locate_root(make, exact, interval, tolerance)
        if where is None:
            undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
        elif where:
            roots.append(RealRoot(make(tolerance), mult, make))
    return RootIsolation(tuple(roots), tuple(undecided), EXACT)




def isolate_real_roots(poly: fmpq_mpoly, interval: TimeRange,
                       tolerance: float = 1e-9) -> RootIsolation:
    """Every real root of ``poly(t, sin t, cos t)`` on the closed range, certified."""
    p = reduce_trig(poly)
    if p.is_zero():
        raise IdenticallyZeroError("the function is identically zero along the path")
    if uses_t(p) and uses_trig(p):
        return branch_and_bound(p, interval, tolerance)
    if uses_trig(p):
        return _half_angle(p, interval, tolerance)
    return _exact_univariate(p, interval, tolerance)
