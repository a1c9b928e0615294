"""Interval branch-and-bound for the roots of functions mixing t with sin t and cos t.

A box is excluded when the ball enclosure of F over it (naive, or mean-value form with
F' from :func:`singcheck.trig.derivative`) excludes 0.  A box on which F' excludes 0 is
strictly monotone (the one-dimensional interval-Newton uniqueness condition), so a
proven sign change at its ends proves exactly one root there and equal signs prove
none; a root met exactly at a box end is kept.  Boxes that stay ambiguous down to the
minimum width become :class:`~singcheck.roots.Undecided`, with the reason.
"""

from __future__ import annotations

from flint import arb, fmpq, fmpq_mpoly

from singcheck.algebra.intervals import excludes_zero, sign, working_precision
from singcheck.algebra.trig import TimeRange, derivative, evaluate_trig
from singcheck.budget import checkpoint
from singcheck.roots.enclosures import (
    BRANCH_AND_BOUND,
    RealRoot,
    RootIsolation,
    Undecided,
    inside_range,
    locate_root,
)
from singcheck.roots.rational import arb_to_fmpq, exact_tolerance, rational_ball

_MAX_BOXES = 200_000
_SPLIT = fmpq(1, 2) - fmpq(1, 97)  # off-centre, so a root rarely sits on a split point


def _eval(p: fmpq_mpoly, lo: fmpq, hi: fmpq) -> arb:
    return evaluate_trig(p, rational_ball(lo, hi))


def _point(p: fmpq_mpoly, t: fmpq) -> arb:
    return evaluate_trig(p, arb(t))


def _excluded(p, dp, lo: fmpq, hi: fmpq) -> tuple[bool, arb]:
    box = rational_ball(lo, hi)
    naive = evaluate_trig(p, box)
    if excludes_zero(naive) or excludes_zero(evaluate_trig(p, box, tight=True)):
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


def branch_and_bound(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    dp = derivative(p)
    a, b = interval.start.ball(), interval.end.ball()
    lo0, hi0 = arb_to_fmpq(a.lower()), arb_to_fmpq(b.upper())
    min_width = exact_tolerance(max(tolerance, 1e-12) / 1000)
    stack = [(lo0, hi0)]
    found: list[tuple[fmpq, fmpq]] = []
    exact_points: list[fmpq] = []
    zero = fmpq(0)
    if lo0 < zero < hi0:
        # t = 0 is the one rational time where sin and cos are exact: a root there (even a
        # double one, with no sign change) is proven by an exact 0 and always reported
        at_zero = _point(p, zero)
        if at_zero.is_exact() and at_zero == 0:
            exact_points.append(zero)
        stack = [(zero, hi0), (lo0, zero)]
    ambiguous: list[tuple[fmpq, fmpq, str]] = []
    boxes = 0
    while stack:
        lo, hi = stack.pop()
        checkpoint()
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
            w = exact_tolerance(tol) / 2
            bracket["lo"], bracket["hi"] = _bisect_root(p, bracket["lo"], bracket["hi"], s_lo, w)
            return rational_ball(bracket["lo"], bracket["hi"])

        where, t = locate_root(make, None, interval, tolerance)
        if where is None:
            undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
        elif where:
            make(tolerance)
            roots.append(RealRoot(rational_ball(bracket["lo"], bracket["hi"]), None, make))
    for q in sorted(set(exact_points)):
        t = arb(q)
        where = inside_range(t, None, interval, 53)
        if where:
            roots.append(RealRoot(t, None, None))
    for lo, hi, reason in _merge(ambiguous):
        box = rational_ball(lo, hi)
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

