"""Interval branch-and-bound for the roots of functions mixing t with sin t and cos t.

A box is excluded when the ball enclosure of F over it (naive, or mean-value form with
F' from :func:`singcheck.trig.derivative`) excludes 0.  A box on which F' excludes 0 is
strictly monotone (the one-dimensional interval-Newton uniqueness condition), so a
proven sign change at its ends proves exactly one root there and equal signs prove
none; a root met exactly at a box end is kept.  Boxes that stay ambiguous down to the
minimum width become :class:`~singcheck.roots.Undecided`, with the reason.

**Roots at multiples of π, of any multiplicity.**  At t = kπ, sin t and cos t are
exact (0, ±1), so whether F and its derivatives vanish there is decided exactly: at
t = 0 by rational evaluation; at t = kπ, k ≠ 0, F(t, 0, ±1) is a polynomial in t with
rational coefficients and π is transcendental, so it vanishes at kπ only when it is the
zero polynomial.  When F, F', …, F⁽ᵐ⁻¹⁾ vanish at z = kπ and F⁽ᵐ⁾ is enclosed away from
0 on a box B around z, Taylor's theorem with the Lagrange remainder,
F(t) = F⁽ᵐ⁾(ξ)(t - z)ᵐ/m!, proves z the only root in B, of multiplicity m (a tangency
when m is even).  B is then taken out of the branch-and-bound, which could never prove
a multiple root.  (By the Lindemann–Weierstrass theorem these are the only algebraic
times where a function genuinely mixing t with sin t, cos t can vanish.)

F may also be a path polynomial with angle functions cos g(t), sin g(t) (a pose angle
that is not k·t + qπ): it is enclosed with the ball of g over the box, and F' comes from
:func:`~singcheck.algebra.radicals.path_derivative` (the chain rule through g); a zero at
kπ is then taken as exact only when F(kπ, 0, ±1, …) is the zero polynomial in what is
left (t and the angle functions), true whatever their values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from flint import arb, fmpq, fmpq_mpoly, fmpq_poly

from singcheck.algebra.intervals import excludes_zero, fraction_ball, sign, working_precision
from singcheck.algebra.radicals import evaluate_path as evaluate_trig
from singcheck.algebra.radicals import path_derivative as derivative
from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange, tightened
from singcheck.budget import checkpoint
from singcheck.roots.enclosures import (
    AT_ANGLE_ZERO,
    AT_POINT,
    BRANCH_AND_BOUND,
    IN_MIXED,
    IN_T,
    IN_U,
    ExactTime,
    RealRoot,
    RootIsolation,
    Undecided,
    inside_range,
    locate_root,
    point_time,
)
from singcheck.roots.rational import (
    RationalRoot,
    arb_to_fmpq,
    bits_for,
    exact_tolerance,
    rational_ball,
    real_roots_exact,
)
from singcheck.roots.transcendental import angle_circle

_MAX_BOXES = 200_000
_SPLIT = fmpq(1, 2) - fmpq(1, 97)  # off-centre, so a root rarely sits on a split point


def _eval(p: fmpq_mpoly, lo: fmpq, hi: fmpq) -> arb:
    return evaluate_trig(p, rational_ball(lo, hi))


def _point(p: fmpq_mpoly, t: fmpq) -> arb:
    return evaluate_trig(p, arb(t))


def _excluded(p, dp, lo: fmpq, hi: fmpq) -> tuple[bool, arb]:
    box = rational_ball(lo, hi)
    naive = evaluate_trig(p, box)
    if excludes_zero(naive) or excludes_zero(
            tightened(p, box, naive) if p.context() is TRIG else
            evaluate_trig(p, box, tight=True)):  # (a path ring's: Horner per part again)
        return True, None
    mid = (lo + hi) / 2
    slope = evaluate_trig(dp, box)
    centred = _point(p, mid) + slope * (box - arb(mid))
    return excludes_zero(centred), slope


def _bisect_root(p, lo: fmpq, hi: fmpq, s_lo: int, width: fmpq) -> tuple[fmpq, fmpq]:
    """Shrink a bracketing box (sign s_lo at lo, opposite at hi) to ``width``."""
    bits = 53
    while hi - lo > width:
        checkpoint()
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


_MAX_ORDER = 64


def vanishes_at_multiple_of_pi(p: fmpq_mpoly, k: int) -> bool:
    """Exactly: p(kπ, 0, (-1)^k) = 0 (see the module docstring).  At t = 0 a pose angle
    G = g(t) + qπ with g(0) = 0 and 2q an integer is exact too (cos G, sin G in
    {0, ±1}): it is substituted, so that a zero of μ at t = 0 on a path mixing sin t
    with such an angle is decided (otherwise the angle's cos, sin stay unknowns, and only
    "zero whatever their values" counts)."""
    q = p.subs({"s": 0, "c": 1 if k % 2 == 0 else -1})
    if k == 0:
        q = q.subs({"t": 0, **_exact_angles_at_zero(q.context())})
    return q.is_zero()


def _exact_angles_at_zero(ring) -> dict[str, int]:
    """{cos(g): cos qπ, sin(g): sin qπ} for the ring's angle functions with g(0) = 0 and
    2q an integer."""
    from singcheck.algebra.radicals import angle_function_of
    from singcheck.roots.angle_zeros import exact_sin_cos

    out: dict[str, int] = {}
    for name in ring.names()[3:]:
        if not name.startswith("cos("):
            continue
        found = angle_function_of(name)
        if found is None:
            continue
        g, q = found
        sc = exact_sin_cos(q)
        if sc is None or not g.subs({"t": 0, "s": 0, "c": 1}).is_zero():
            continue
        out[name], out["sin(" + name[4:]] = sc[1], sc[0]
    return out


def _exact_zeros(p: fmpq_mpoly, interval: TimeRange) -> list[tuple[int, int, fmpq, fmpq]]:
    """(k, m, a, b): t = kπ in the range is a root of multiplicity m, the only one in the
    rational box [a, b] (proven by the Taylor argument of the module docstring)."""
    start, end = float(interval.start), float(interval.end)
    out = []
    # at t = kπ ≠ 0 the test depends on k's parity alone (p(t, 0, ±1) ≡ 0 in Q[t], π
    # being transcendental): two substitutions, however many multiples the range holds,
    # and only the multiples of a parity where p vanishes (and 0) are visited
    parity = {r: vanishes_at_multiple_of_pi(p, 2 + r) for r in (0, 1)}
    first, last = math.floor(start / math.pi) - 1, math.ceil(end / math.pi) + 2
    ks = range(first, last) if any(parity.values()) else [0] if first <= 0 < last else []
    for k in ks:
        checkpoint()  # a long range has a multiple of π every 3.14: as many zeros
        if not (vanishes_at_multiple_of_pi(p, 0) if k == 0 else parity[k % 2]):
            continue
        with working_precision(128):
            z = k * arb.pi()
        if not inside_range(z, LinearInPi(Fraction(0), Fraction(k)), interval, 128):
            continue
        dk, order = p, 0
        while order < _MAX_ORDER and vanishes_at_multiple_of_pi(dk, k):
            checkpoint()
            dk, order = derivative(dk), order + 1
        if vanishes_at_multiple_of_pi(dk, k):
            continue
        for e in range(1, 64):
            checkpoint()
            with working_precision(128):
                a = arb_to_fmpq((z - arb(2) ** -e).lower())
                b = arb_to_fmpq((z + arb(2) ** -e).upper())
            if excludes_zero(_eval(dk, a, b)):
                out.append((k, order, a, b))
                break
    return out


def _angle_zeros(p: fmpq_mpoly, interval: TimeRange) -> list[tuple[RealRoot, fmpq, fmpq]]:
    """(root, a, b) for a path polynomial in t and one pose angle's C, S
    (G = g(t) + qπ): at a zero τ of g the point is algebraic, so whether p and its
    derivatives vanish there is decided exactly
    (:func:`~singcheck.roots.angle_zeros.angle_zeros`), and the Taylor argument of the
    module docstring proves τ the only root in [a, b], of its multiplicity (a touch when
    even: phi = t² at t = 0, phi = t² - 2 at t = ±√2).  A rational τ with 2q an integer
    keeps the exact time of a rational point (s, c in {0, ±1})."""
    from singcheck.roots.angle_zeros import angle_zeros, exact_sin_cos

    circle = angle_circle(p)
    if circle is None:
        return []
    out = []
    for rr, order, a, b in angle_zeros(p, circle, interval, derivative, _eval):
        sc = exact_sin_cos(circle.q)
        if rr.lo == rr.hi and sc is not None:
            t0 = Fraction(int(rr.lo.p), int(rr.lo.q))
            out.append((RealRoot(fraction_ball(t0), order, None,
                                 exact=point_time(t0, *sc)), a, b))
            continue
        out.append((_angle_zero_root(rr, order, circle.q), a, b))
    return out


def _angle_zero_root(rr: RationalRoot, order: int, q: Fraction) -> RealRoot:
    def make(tol: float) -> arb:
        rr.bisect_to(exact_tolerance(tol) / 2)
        return rational_ball(rr.lo, rr.hi)

    return RealRoot(make(1e-9), order, make,
                    exact=ExactTime(AT_ANGLE_ZERO, lambda: rr, angle_q=q))


#: a range end aπ is tested exactly only when cos aπ's minimal polynomial (a factor of
#: the Chebyshev polynomial T_q, q = a's denominator) stays small
_MAX_END_DENOMINATOR = 60


def _end_zeros(p: fmpq_mpoly, interval: TimeRange, lo0: fmpq, hi0: fmpq
               ) -> list[tuple[RealRoot, fmpq, fmpq]]:
    """(root, a, b) for a zero of p exactly at a range end e: a rational e ≠ 0, or
    e = aπ (a not an integer: t = kπ is :func:`_exact_zeros`'), where p(e) = 0 is
    decided exactly (:func:`~singcheck.algebra.trig_values.sum_is_zero`: π is
    transcendental over Q(sin aπ, cos aπ), and (sin e, cos e) is a generic point of the
    circle for a rational e ≠ 0).  The derivatives give its multiplicity m, and a
    one-sided box [lo0, b] (or [a, hi0]) on which p⁽ᵐ⁾ excludes 0 holds no other root
    (the Taylor argument of the module docstring): a zero the branch-and-bound could not
    bracket, since the range ends there."""
    if p.context() is not TRIG or interval.start == interval.end:
        return []
    from singcheck.algebra.trig_values import sum_is_zero

    out = []
    for end, side in ((interval.start, 1), (interval.end, -1)):
        checkpoint()
        a_pi = end.pi_coefficient
        if (end.rational == 0 and a_pi.denominator == 1) or \
                (end.rational != 0 and a_pi != 0) or a_pi.denominator > _MAX_END_DENOMINATOR \
                or excludes_zero(evaluate_trig(p, end.ball())):
            continue
        dk, order = p, 0
        while order < _MAX_ORDER and sum_is_zero([(dk, end)]) is True:
            checkpoint()
            dk, order = derivative(dk), order + 1
        if order == 0 or sum_is_zero([(dk, end)]) is not False:
            continue
        with working_precision(128):
            z = end.ball()
        for e in range(1, 64):
            checkpoint()
            with working_precision(128):
                a, b = (lo0, arb_to_fmpq((z + arb(2) ** -e).upper())) if side > 0 else \
                    (arb_to_fmpq((z - arb(2) ** -e).lower()), hi0)
            if excludes_zero(_eval(dk, a, b)):
                out.append((_end_root(end, order), a, b))
                break
    return out


def _end_root(end: LinearInPi, order: int) -> RealRoot:
    def make(tol: float) -> arb:
        with working_precision(bits_for(tol)):
            return end.ball()

    return RealRoot(make(1e-9), order, make, exact=_end_time(end))


def _end_time(end: LinearInPi) -> ExactTime | None:
    """A range end's exact time: t = a rational (≠ 0) in Q; t = aπ with sin, cos
    exact (a half-integer); else u = tan(aπ/2) on its minimal polynomial."""
    if end.pi_coefficient == 0:
        a = fmpq(end.rational.numerator, end.rational.denominator)
        root = RationalRoot(fmpq_poly([-a, 1]), a, a)
        return ExactTime(IN_T, lambda: root, end=end)
    a_pi = end.pi_coefficient
    if (2 * a_pi).denominator == 1:
        k = int(2 * a_pi) % 4
        return ExactTime(AT_POINT, None, Fraction((0, 1, 0, -1)[k]), Fraction((1, 0, -1, 0)[k]),
                         end=end)
    root = _tan_half_root(a_pi)
    return None if root is None else ExactTime(IN_U, lambda: root, end=end)


def _tan_half_root(a: Fraction) -> RationalRoot | None:
    """u = tan(aπ/2) as a root of a squarefree polynomial with an isolating interval:
    cos aπ = (1 - u²)/(1 + u²), so u is a root of m((1 - u²)/(1 + u²))·(1 + u²)^d for m
    the minimal polynomial of cos aπ; the interval that holds Arb's ball of tan(aπ/2)
    is singled out by refining the candidates until one is left (None if not)."""
    from singcheck.algebra.trig_values import _minimal_polynomial_of_cos

    g = a - 2 * (a // 2)
    m = _minimal_polynomial_of_cos(g)
    d = m.degree()
    one_minus, one_plus = fmpq_poly([1, 0, -1]), fmpq_poly([1, 0, 1])
    poly = sum((m[i] * one_minus ** i * one_plus ** (d - i) for i in range(d + 1)),
               fmpq_poly([]))
    with working_precision(256):
        u = (arb.pi() * arb(fmpq(g.numerator, g.denominator)) / 2).tan()
    hits = [r for r, _ in real_roots_exact(poly)
            if not (r.hi < arb_to_fmpq(u.lower()) or r.lo > arb_to_fmpq(u.upper()))]
    for _ in range(64):
        if len(hits) <= 1:
            break
        checkpoint()
        for r in hits:
            r.bisect_to(r.width() / 4)
        hits = [r for r in hits
                if not (r.hi < arb_to_fmpq(u.lower()) or r.lo > arb_to_fmpq(u.upper()))]
    return hits[0] if len(hits) == 1 else None


def _without(lo: fmpq, hi: fmpq, boxes: list[tuple[fmpq, fmpq]]) -> list[tuple[fmpq, fmpq]]:
    """[lo, hi] minus the open insides of the boxes (sorted, disjoint)."""
    pieces, at = [], lo
    for a, b in sorted(boxes):
        if a > at:
            pieces.append((at, min(a, hi)))
        at = max(at, b)
    if at < hi:
        pieces.append((at, hi))
    return [(x, y) for x, y in pieces if x < y]


def _exact_root(k: int, order: int) -> RealRoot:
    def make(tol: float) -> arb:
        with working_precision(bits_for(tol)):
            return k * arb.pi()

    time = point_time(Fraction(0) if k == 0 else None, 0, 1 if k % 2 == 0 else -1, k)
    return RealRoot(arb(0) if k == 0 else make(1e-9), order, None if k == 0 else make,
                    exact=time)


def branch_and_bound(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    dp = derivative(p)
    a, b = interval.start.ball(), interval.end.ball()
    lo0, hi0 = arb_to_fmpq(a.lower()), arb_to_fmpq(b.upper())
    min_width = exact_tolerance(max(tolerance, 1e-12) / 1000)
    exact_zeros = _exact_zeros(p, interval)
    angle_zeros = _angle_zeros(p, interval)
    end_zeros = _end_zeros(p, interval, lo0, hi0)
    stack = _without(lo0, hi0, [(za, zb) for _, _, za, zb in exact_zeros] +
                     [(za, zb) for _, za, zb in angle_zeros + end_zeros])[::-1]
    found: list[tuple[fmpq, fmpq]] = []
    exact_points: list[fmpq] = []
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
    return _finish_branch_and_bound(p, interval, tolerance, found, exact_points, ambiguous,
                                    [_exact_root(k, order) for k, order, _, _ in exact_zeros]
                                    + [r for r, _, _ in angle_zeros + end_zeros])


@dataclass
class Bracket:
    """The one zero τ of ``p(t, sin t, cos t)`` in [lo, hi], where p is strictly monotone
    with sign ``s_lo`` at lo and the opposite sign at hi (a root the branch-and-bound
    proved); :meth:`ball` narrows it by bisection on exact rational points."""

    p: fmpq_mpoly
    lo: fmpq
    hi: fmpq
    s_lo: int

    def ball(self, bits: int) -> arb:
        """A ball of width about 2^-bits around τ (wider only when p's sign cannot be
        told at 4000 bits next to τ)."""
        self.lo, self.hi = _bisect_root(self.p, self.lo, self.hi, self.s_lo,
                                        fmpq(1, 2 ** bits))
        return rational_ball(self.lo, self.hi)


def _mixed_time(p: fmpq_mpoly, lo: fmpq, hi: fmpq, s_lo: int) -> ExactTime | None:
    """The exact description of a bracketed root of p (a trig polynomial in t, s, c, or
    a path polynomial in t and one pose angle's cos, sin, :func:`angle_circle`; None for
    other angle functions or square roots)."""
    if p.context() is not TRIG:
        if angle_circle(p) is None:
            return None
    elif lo <= 0 <= hi and p.subs({"t": 0, "s": 0, "c": 1}) == 0:
        return None  # τ = 0 would be algebraic (the exact zeros at 0 are found apart)
    bracket = Bracket(p, lo, hi, s_lo)
    return ExactTime(IN_MIXED, lambda: bracket)


def _finish_branch_and_bound(p, interval, tolerance, found, exact_points, ambiguous,
                             exact_roots):
    roots, undecided = list(exact_roots), []
    for lo, hi, s_lo in found:
        checkpoint()
        bracket = {"lo": lo, "hi": hi}

        def make(tol: float, bracket=bracket, s_lo=s_lo) -> arb:
            w = exact_tolerance(tol) / 2
            bracket["lo"], bracket["hi"] = _bisect_root(p, bracket["lo"], bracket["hi"], s_lo, w)
            return rational_ball(bracket["lo"], bracket["hi"])

        where, t = locate_root(make, None, interval, tolerance)
        if where is None:
            undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
        elif where:
            exact = _mixed_time(p, bracket["lo"], bracket["hi"], s_lo)
            make(tolerance)
            roots.append(RealRoot(rational_ball(bracket["lo"], bracket["hi"]), None, make,
                                  exact=exact))
    for q in sorted(set(exact_points)):
        t = arb(q)
        where = inside_range(t, None, interval, 53)
        if where:
            roots.append(RealRoot(t, None, None, exact=point_time(Fraction(0), 0, 1)
                                  if q == 0 else None))
    for lo, hi, reason in _merge(ambiguous):
        box = rational_ball(lo, hi)
        undecided.append(Undecided(box, f"{reason} in t ∈ [{float(lo):.9g}, {float(hi):.9g}]"))
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

