"""Exact decisions for one working mode: is det A zero at an algebraic root of μ, or
identically zero along the path?

Ball arithmetic proves det A ≠ 0, and a sign change proves a crossing, but neither can
prove that det A *touches* 0 (a tangency: a root of even multiplicity) nor say which of
several modes vanishing at one time are singular.  This module decides those exactly.

**det A along a mode.**  Each quadratic leg's joint is ρᵢ = (-bᵢ + rᵢ)/(2aᵢ) with
rᵢ² = Dᵢ (its discriminant along the path) and aᵢ constant; a linear leg's joint is
-cᵢ/bᵢ.  (Square roots √p among the robot's or the path's numbers come first, as levels
with D = p and the positive sign.)  Substituting into det A and reducing rᵢ² → Dᵢ gives
one polynomial E(r),
multilinear in the r's, whose coefficients are trig polynomials in t, sin t, cos t.  A
working mode picks rᵢ = σᵢ·√Dᵢ (σᵢ = ±1 from its label; i·√-Dᵢ where Dᵢ < 0, the
convention of :meth:`~singcheck.certify.path.LegAlongPath.branches`).

**The zero test (a tower of quadratic extensions).**  Write E = x + y·r_k with x, y free
of r_k, and Ē = x - y·r_k (the mode with σ_k flipped).  Then E·Ē = x² - y²·D_k.

* if D_k = 0 exactly, r_k = 0 and E = x;
* if y = 0 (decided recursively), E = x;
* if N = x² - y²·D_k ≠ 0 (recursively), E ≠ 0 (every zero of E is a zero of N);
* otherwise E·Ē = 0 while E - Ē = 2·y·r_k ≠ 0: *exactly one* of E and Ē is zero, and
  ball arithmetic at rising precision decides which (the non-zero one is eventually
  enclosed away from 0; the other one then is proven zero).

The bottom of the recursion is an exact test in the base field:

* at a root of μ: Q(α), α the root's exact algebraic value (t itself, or u = tan(t/2))
  with its minimal polynomial f (the irreducible factor of its squarefree polynomial
  that changes sign on its isolating interval) — an element is 0 exactly when its
  polynomial is 0 modulo f;
* along the path (μ ≡ 0): the field of trig functions on the range (reduced trig
  polynomials are 0 exactly when they are 0 as polynomials); "exactly one of E, Ē
  vanishes" then holds on every interval where the branches are analytic (the identity
  theorem: a product of analytic functions that vanishes identically has a factor that
  does), and is decided at a rational sample time.

For the μ ≡ 0 case the recursion also returns, for a mode whose det A is not ≡ 0, a
non-zero trig polynomial P (a product of conjugates with the identically vanishing ones
dropped) whose roots hold every zero of det A along that mode: its candidates.
"""

from __future__ import annotations

from fractions import Fraction

from flint import acb, arb, arb_poly, fmpq, fmpq_mpoly, fmpq_mpoly_ctx, fmpq_poly

from singcheck.algebra.intervals import evaluate, excludes_zero, working_precision
from singcheck.algebra.polynomials import constant_value, memo_per_object
from singcheck.algebra.radicals import radical_prime
from singcheck.algebra.trig import TRIG, evaluate_trig, reduce_trig, uses_t, uses_trig
from singcheck.budget import checkpoint
from singcheck.certify.path import PathModel
from singcheck.roots.angle_zeros import AngleZero, univariate
from singcheck.roots.enclosures import (
    AT_ANGLE_ZERO,
    AT_POINT,
    IN_MIXED,
    IN_T,
    IN_U,
    ExactTime,
    point_time,
)
from singcheck.roots.half_angle import half_angle_polynomial
from singcheck.roots.isolation import as_univariate_t
from singcheck.roots.rational import RationalRoot, minimal_polynomial, rational_ball
from singcheck.roots.transcendental import (
    NotExact,
    TranscendentalPoint,
    TrigElements,
    ring_circle,
)

_MAX_BITS = 1 << 16


# ---------------------------------------------------------------------------------
# det A along the path as a multilinear polynomial in the square roots r_i


def multilinear_product(a: dict, b: dict, D: list[dict], mul, is_zero) -> dict:
    """The product of two multilinear elements (dicts mask → coefficient) reduced with
    r_q² = D[q], where D[q] is itself an element of the levels below q."""
    out: dict = {}
    for ma, va in a.items():
        for mb, vb in b.items():
            checkpoint()
            part = {ma ^ mb: mul(va, vb)}
            common, q = ma & mb, 0
            while common:
                if common & 1:
                    part = multilinear_product(part, D[q], D, mul, is_zero)
                common >>= 1
                q += 1
            for m, v in part.items():
                out[m] = out[m] + v if m in out else v
    return {m: v for m, v in out.items() if not is_zero(v)}


def _trig_mul(a: fmpq_mpoly, b: fmpq_mpoly) -> fmpq_mpoly:
    return reduce_trig(a * b)


def _is_zero(a) -> bool:
    return a.is_zero()


class ModeExpression:
    """E(r) = det A along the path, multilinear in its square roots: first one level per
    prime p of the robot's or the path's numbers (√p, always the positive root), then one
    rᵢ per quadratic leg (√Dᵢ, Dᵢ in the levels below: it may involve the √p).

    ``terms`` maps a bit mask of levels to its trig-polynomial coefficient; ``D[q]`` is
    the element (a dict of the same kind, levels below q) whose square root level q is;
    ``fixed`` is the number of √p levels; ``legs[j]`` the leg index of r_j.
    """

    def __init__(self, path: PathModel) -> None:
        model = path.projection.model
        ring_in = path.coordinates[0].context() if path.coordinates else TRIG
        #: a pose angle g(t) + qπ, g ∈ Q[t]: its (C, S) renamed (c, s) (transcendental)
        self.circle = ring_circle(ring_in)
        if self.circle is not None:
            ring_in = TRIG
        path_names = ring_in.names()
        primes = [radical_prime(v) for v in path_names[3:]]
        if tuple(path_names[:3]) != ("t", "s", "c") or None in primes:
            raise NotExact("the path ring has variables other than t, sin t, cos t and "
                           "square roots (two pose angles, an angle with sin t or cos t, "
                           "or one with square roots)")
        quadratic = [i for i, leg in enumerate(path.legs) if leg.leg.degree == 2]
        names = (*path_names, *(f"r{q}" for q in range(len(quadratic))))
        ring = fmpq_mpoly_ctx.get(names, "lex")
        pad = (0,) * len(quadratic)

        def lift(p: fmpq_mpoly) -> fmpq_mpoly:
            if self.circle is not None:
                p = self.circle.to_trig(p)
            if p.context() is not ring_in:
                p = ring_in.from_dict({(*e, *(0,) * len(primes)): c for e, c in p.terms()}) \
                    if p.context() is TRIG else None
                if p is None:
                    raise NotExact("a polynomial of the path outside its ring")
            return ring.from_dict({(*e, *pad): c for e, c in p.terms()})

        gens = dict(zip(names, ring.gens(), strict=True))
        r = ring.gens()[len(path_names):]
        images: dict[str, fmpq_mpoly] = {}
        revolute: list[tuple[str, str, fmpq_mpoly]] = []  # (cos θ, sin θ, W) per leg
        for i, leg in enumerate(path.legs):
            if leg.revolute:
                # W·(cos θ, sin θ) = (-a·d + σ·b·√Δ, -b·d - σ·a·√Δ) (W = a² + b²)
                a, b, d = (lift(x) for x in leg.coefficients)
                root = r[quadratic.index(i)]
                cos_v, sin_v = leg.leg.variables
                images[cos_v], images[sin_v] = -a * d + root * b, -b * d - root * a
                revolute.append((cos_v, sin_v, a * a + b * b))
            elif leg.leg.degree == 2:
                a, b, _ = leg.coefficients
                images[leg.leg.joint] = (r[quadratic.index(i)] - lift(b)) / \
                    (2 * constant_value(a))
            else:
                b, c = leg.coefficients
                images[leg.leg.joint] = -lift(c) / constant_value(b)
        images.update(zip(model.pose_variables, (lift(x) for x in path.coordinates),
                          strict=True))
        images.update({v: gens[v] for v in path_names[3:]})
        det_names = model.det_A.context().names()
        if any(v not in images for v in det_names):
            raise NotExact("det A involves variables other than the joints, the pose and "
                           "square roots of the path's ring")
        self.fixed = len(primes)
        self.legs = quadratic
        self.D: list[dict] = [{0: TRIG.from_dict({(0, 0, 0): p})} for p in primes]
        for i in quadratic:
            self.D.append(self._split(lift(path.legs[i].discriminant)))
        args = [images[v] for v in det_names]
        full = ring.from_dict({})
        for deficit, part in _by_angle_degree(model.det_A, revolute).items():
            checkpoint()
            term = part.compose(*args, ctx=ring)
            for (_, _, w), k in zip(revolute, deficit, strict=True):
                term = term * w ** k
            full += term
        self.terms = self._split(full)
        #: W of each revolute leg: det A along a mode is E / ∏ W^e, valid where W ≠ 0
        self.W = [self._split(w) for _, _, w in revolute]

    def _split(self, p: fmpq_mpoly) -> dict:
        return split_levels(p, self.D)

    def signs(self, label: str) -> list[int]:
        """σ per level for a working mode label: + for every √p, then the mode's signs."""
        return [1] * self.fixed + [1 if label[i] == "+" else -1 for i in self.legs]


def split_levels(p: fmpq_mpoly, D: list[dict]) -> dict:
    """A polynomial in t, s, c and the levels (its variables after the third) as a
    multilinear element, reduced with level_q² = D[q]."""
    by_levels: dict[tuple[int, ...], dict] = {}
    for exps, coeff in p.terms():
        by_levels.setdefault(tuple(exps[3:]), {})[tuple(exps[:3])] = coeff
    out: dict = {}
    for level_exps, trig_terms in by_levels.items():
        checkpoint()
        value = {0: reduce_trig(TRIG.from_dict(trig_terms))}
        for q, e in enumerate(level_exps):
            factor = {(e % 2) << q: TRIG.from_dict({(0, 0, 0): 1})}
            for _ in range(e // 2):
                factor = multilinear_product(factor, D[q], D, _trig_mul, _is_zero)
            if e:
                value = multilinear_product(value, factor, D, _trig_mul, _is_zero)
        for m, v in value.items():
            out[m] = out[m] + v if m in out else v
    return {m: v for m, v in out.items() if not v.is_zero()}


def _by_angle_degree(det_a: fmpq_mpoly, revolute: list) -> dict:
    """det A's terms grouped by how far each is below its revolute joint's top degree
    e in (cos θ, sin θ): a group with deficits k, composed with W·(cos θ, sin θ) and
    multiplied by ∏ W^k, adds up to ∏ W^e · det A (a polynomial: no division by W)."""
    names = det_a.context().names()
    pairs = [(names.index(c), names.index(s)) for c, s, _ in revolute]
    top = [max((e[i] + e[j] for e, _ in det_a.terms()), default=0) for i, j in pairs]
    groups: dict[tuple[int, ...], dict] = {}
    for exps, coeff in det_a.terms():
        deficit = tuple(m - exps[i] - exps[j] for m, (i, j) in zip(top, pairs, strict=True))
        groups.setdefault(deficit, {})[exps] = coeff
    return {k: det_a.context().from_dict(v) for k, v in groups.items()}


_EXPRESSIONS: dict[int, tuple[PathModel, ModeExpression]] = {}


def mode_expression(path: PathModel) -> ModeExpression:
    """The (memoised) E(r) of a path: built once, only when an exact decision is needed."""
    return memo_per_object(_EXPRESSIONS, path, ModeExpression, keep=64)


# ---------------------------------------------------------------------------------
# base fields: Q(α) at a root, trig functions along the path


class AlgebraicPoint:
    """Q(α) for the exact time of a root: elements are polynomials in α modulo its
    minimal polynomial ``f``; ``ball`` encloses an element's value at the root."""

    def __init__(self, time: ExactTime) -> None:
        self.time = time
        if time.kind == AT_POINT:
            self.f = fmpq_poly([0, 1])
            self.root = RationalRoot(self.f, fmpq(0), fmpq(0))
            return
        self.root = minimal_polynomial(time.locate())
        self.f = self.root.poly
        if time.kind == IN_U:
            one_plus = fmpq_poly([1, 0, 1]) % self.f
            g, inverse, _ = one_plus.xgcd(self.f)  # 1 + α² ≠ 0 for a real α: g = 1
            self._inverse = (inverse / g.leading_coefficient()) % self.f
            self._inverse_powers = [fmpq_poly([1])]  # (1 + α²)^-d for d = 0, 1, …

    def of(self, p: fmpq_mpoly) -> fmpq_poly:
        """A trig polynomial's value at the root, as an element of Q(α)."""
        time = self.time
        if time.kind == AT_POINT:
            if uses_t(p) and time.t_value is None:
                raise NotExact("t is a non-zero multiple of π, not algebraic")
            values = {"s": _q(time.s), "c": _q(time.c)}
            if uses_t(p):
                values["t"] = _q(time.t_value)
            return fmpq_poly([constant_value(p.subs(values))]) if values else fmpq_poly([])
        if time.kind == IN_T:
            if uses_trig(p):
                raise NotExact("a path mixing t with sin t, cos t at a time other than 0")
            return as_univariate_t(p) % self.f if not p.is_zero() else fmpq_poly([])
        if uses_t(p):
            raise NotExact("a path mixing t with sin t, cos t at a time other than 0")
        if p.is_zero():
            return fmpq_poly([])
        m, d = half_angle_polynomial(p)
        powers = self._inverse_powers
        while len(powers) <= d:
            powers.append((powers[-1] * self._inverse) % self.f)
        return ((m % self.f) * powers[d]) % self.f

    def mul(self, a: fmpq_poly, b: fmpq_poly) -> fmpq_poly:
        return (a * b) % self.f

    def is_zero(self, a: fmpq_poly) -> bool:
        return a.is_zero()

    def ball(self, a: fmpq_poly, bits: int) -> arb:
        """An enclosure of the element at the root, at about ``bits`` of precision."""
        if self.root.lo != self.root.hi:
            self.root.bisect_to(fmpq(1, 2**bits))
        alpha = rational_ball(self.root.lo, self.root.hi)
        return arb_poly(a)(alpha)  # coefficients rounded outward, Horner's rule in Arb


_T_ALPHA = fmpq_mpoly_ctx.get(("t", "a"), "lex")


class TimeTranscendentalPoint:
    """A root t = τ ≠ 0 of a path using the bare t where sin τ and cos τ are algebraic
    (in Q(α): t = 2·atan(α) + 2kπ, or t = kπ): τ itself is then transcendental
    (Lindemann–Weierstrass: e^{iτ} is algebraic), so an element Σ tⁱ·gᵢ(α) vanishes at
    the root exactly when every gᵢ is 0 in Q(α).  Elements are polynomials in t and α,
    reduced modulo α's minimal polynomial; balls take τ from the root's own enclosure
    (refined in floating-point tolerances: hence the lower precision cap)."""

    max_bits = 1024

    def __init__(self, time: ExactTime, root) -> None:
        self.inner = AlgebraicPoint(time)  # s, c (and α) without t
        self.root = root
        self.f = _T_ALPHA.from_dict({(0, i): c for i, c in enumerate(self.inner.f.coeffs())})

    def of(self, p: fmpq_mpoly) -> fmpq_mpoly:
        by_power: dict[int, dict] = {}
        for (i, j, k), coeff in p.terms():
            by_power.setdefault(i, {})[(0, j, k)] = coeff
        out = {}
        for i, terms in by_power.items():
            value = self.inner.of(TRIG.from_dict(terms))
            for e, c in enumerate(value.coeffs()):
                if c != 0:
                    out[(i, e)] = c
        return _T_ALPHA.from_dict(out)

    def mul(self, a: fmpq_mpoly, b: fmpq_mpoly) -> fmpq_mpoly:
        return (a * b) % self.f

    def is_zero(self, a: fmpq_mpoly) -> bool:
        return a.is_zero()

    def ball(self, a: fmpq_mpoly, bits: int) -> arb:
        t = self.root.refined(max(2.0 ** -bits, 1e-300)).t
        alpha = self.inner.ball(fmpq_poly([0, 1]), bits)
        return evaluate(a, [t, alpha])


_A_S_C = fmpq_mpoly_ctx.get(("a", "s", "c"), "lex")
_S2 = _A_S_C.from_dict({(0, 2, 0): 1, (0, 0, 2): 1, (0, 0, 0): -1})


class CircleAtAlgebraicTime:
    """t = τ algebraic and non-zero (a root of a factor of μ in t alone, on a path that
    mixes t with sin t, cos t, or with the cos, sin of a pose angle G(t) = g(t) + qπ
    where g(τ) ≠ 0): the elements are polynomials in α = τ, s and c, reduced with
    s² = 1 - c² and modulo α's minimal polynomial f.

    **Why the zero test is exact.**  The angle θ at τ (τ itself, or G(τ)) is θ = β + qπ
    with β a non-zero algebraic number (τ, or g(τ)), so e^{iθ} = e^{iβ}·e^{iqπ} is
    transcendental (Hermite–Lindemann: e^{iβ} is, and e^{iqπ} is a root of unity), and so
    is cos θ (e^{iθ} is a root of z² - 2·cos θ·z + 1).  An element a₀(c) + s·a₁(c), with
    coefficients in Q(τ), vanishes at (sin θ, cos θ) exactly when a₀ = a₁ = 0: otherwise
    a₀² - (1 - c²)·a₁², a polynomial over Q(τ) that is not zero (1 - c² is not a square),
    would vanish at the transcendental cos θ.  So an element is 0 exactly when it is the
    zero polynomial: no ball is needed, as in :class:`TimeTranscendentalPoint` with the
    roles of t and the angle swapped.  ``circle`` (the pose angle's, renamed c, s) gives
    the balls of G; g(τ) ≠ 0 is proven exactly (f does not divide g)."""

    def __init__(self, time: ExactTime, circle=None) -> None:
        self.inner = AlgebraicPoint(time)
        f = self.inner.f
        if circle is None and f.degree() == 1 and f[0] == 0:
            raise NotExact("t = 0: sin t and cos t are algebraic there")
        if circle is not None:
            if (univariate(circle.g) % f).is_zero():
                raise NotExact("the pose angle's polynomial g vanishes at the root, where the "
                               "point is algebraic")
        self.circle = circle
        self.f = _A_S_C.from_dict({(i, 0, 0): c for i, c in enumerate(f.coeffs())})

    def of(self, p: fmpq_mpoly) -> fmpq_mpoly:
        return self._reduce(_A_S_C.from_dict(dict(p.terms())))

    def _reduce(self, a: fmpq_mpoly) -> fmpq_mpoly:
        return (a % _S2) % self.f

    def mul(self, a: fmpq_mpoly, b: fmpq_mpoly) -> fmpq_mpoly:
        return self._reduce(a * b)

    def is_zero(self, a: fmpq_mpoly) -> bool:
        return a.is_zero()

    def ball(self, a: fmpq_mpoly, bits: int) -> arb:
        t = self.inner.ball(fmpq_poly([0, 1]), bits)  # α is t itself
        p = TRIG.from_dict(dict(a.terms()))
        if self.circle is not None:
            return self.circle.evaluate(p, t)
        return evaluate_trig(p, t)


def _at_algebraic_time(time: ExactTime, circle):
    """The base field at an algebraic root τ of a mixed or pose-angle path: at t = 0
    (sin, cos exact) Q itself; at a zero of the pose angle's g the algebraic point
    (τ, cos qπ, sin qπ); elsewhere the generic point of the circle over Q(τ)."""
    root = minimal_polynomial(time.locate())
    f = root.poly
    if circle is None and f.degree() == 1 and f[0] == 0:
        return AlgebraicPoint(point_time(Fraction(0), 0, 1))
    if circle is not None and (univariate(circle.g) % f).is_zero():
        return AngleZero(root, circle.q)
    return CircleAtAlgebraicTime(time, circle)


def exact_point(time: ExactTime, root=None, circle=None, mixed: bool = False):
    """The base field of the exact decisions at a root with this exact time; ``root``
    (its :class:`~singcheck.roots.enclosures.RealRoot`) only for a path that uses the
    bare t, where sin t, cos t algebraic leave t itself transcendental; ``mixed`` for a
    path that mixes t with sin t, cos t or with a pose angle's (``circle``), where an
    algebraic t leaves them transcendental."""
    if time.kind == IN_MIXED:
        return TranscendentalPoint(time)
    if time.kind == AT_ANGLE_ZERO:
        return AngleZero(time.locate(), time.angle_q)
    if time.kind == IN_T and (mixed or circle is not None):
        return _at_algebraic_time(time, circle)
    if time.kind in (IN_U, AT_POINT) and time.t_value is None and root is not None and \
            excludes_zero(root.t):
        return TimeTranscendentalPoint(time, root)
    return AlgebraicPoint(time)


class PathFunctions(TrigElements):
    """The trig functions along the path (μ ≡ 0): elements are reduced trig polynomials,
    exact zero tests are polynomial ones, and balls are taken at a rational time."""

    def __init__(self, t0: fmpq, circle=None) -> None:
        self.t0 = t0
        self.circle = circle  # a pose angle's (C, S), renamed (c, s)

    def is_zero(self, a: fmpq_mpoly) -> bool:
        return a.is_zero()

    def ball(self, a: fmpq_mpoly, bits: int) -> arb:
        if self.circle is not None:
            return self.circle.evaluate(a, arb(self.t0))
        return evaluate_trig(a, arb(self.t0))


def _q(x: Fraction) -> fmpq:
    return fmpq(x.numerator, x.denominator)


# ---------------------------------------------------------------------------------
# the tower


class _Tower:
    """The zero test of the module docstring for one working mode over one base field."""

    def __init__(self, expr: ModeExpression, base, signs: list[int]) -> None:
        self.base = base
        self.signs = signs
        self.D = [self._of(d) for d in expr.D]
        self.E = self._of(expr.terms)
        self.D_zero: list[bool] = []
        for q, d in enumerate(self.D):  # level by level: each test uses the levels below
            self.D_zero.append(self.reduce(d, q) is None)
        if any(self.reduce(self._of(w)) is None for w in expr.W):
            raise NotExact("a revolute leg does not depend on its joint there (W = a² + b² "
                           "= 0): its branches are not defined")

    def _of(self, element: dict) -> dict:
        out = {m: self.base.of(v) for m, v in element.items()}
        return {m: v for m, v in out.items() if not self.base.is_zero(v)}

    def _mul(self, a: dict, b: dict) -> dict:
        return multilinear_product(a, b, self.D, self.base.mul, self.base.is_zero)

    def _sub(self, a: dict, b: dict) -> dict:
        out = dict(a)
        for m, v in b.items():
            out[m] = out[m] - v if m in out else -v
        return {m: v for m, v in out.items() if not self.base.is_zero(v)}

    def reduce(self, e: dict | None = None, k: int | None = None):
        """None when the element (at this mode's signs) is exactly 0; otherwise a non-zero
        base element whose zeros hold the element's (for the path field)."""
        e = self.E if e is None else e
        k = len(self.D) if k is None else k
        checkpoint()
        if k == 0:
            value = e.get(0)
            return None if value is None or self.base.is_zero(value) else value
        bit = 1 << (k - 1)
        x = {m: v for m, v in e.items() if not m & bit}
        y = {m ^ bit: v for m, v in e.items() if m & bit}
        if not y or self.D_zero[k - 1] or self.reduce(y, k - 1) is None:
            return self.reduce(x, k - 1)
        norm = self._sub(self._mul(x, x), self._mul(self._mul(y, y), self.D[k - 1]))
        found = self.reduce(norm, k - 1)
        if found is not None:
            return found
        # E·Ē = 0 and E - Ē = 2·y·r_k ≠ 0: exactly one of them is 0
        if self._which_vanishes(e, k):
            return None
        return self.reduce(x, k - 1)  # Ē = 0, so E = 2x ≠ 0

    def _which_vanishes(self, e: dict, k: int) -> bool:
        """True when E is the zero one of {E, Ē} (flipping level k), decided by balls."""
        bits = 64
        while bits <= getattr(self.base, "max_bits", _MAX_BITS):
            checkpoint()
            with working_precision(bits):
                value = self._ball(e, k, flip=None)
                flipped = self._ball(e, k, flip=k - 1)
            if flipped is not None and excludes_zero(flipped):
                return True
            if value is not None and excludes_zero(value):
                return False
            bits *= 2
        raise NotExact("ball arithmetic did not separate a mode from its conjugate")

    def _value(self, e: dict, roots: list, bits: int):
        total = arb(0)
        for m, v in e.items():
            term = self.base.ball(v, bits)
            q = 0
            while m:
                if m & 1:
                    term = term * roots[q]
                m >>= 1
                q += 1
            total = total + term
        return total

    def _ball(self, e: dict, k: int, flip: int | None):
        bits = int(working_bits())
        roots: list = []
        for q in range(k):
            if self.D_zero[q]:
                roots.append(arb(0))
                continue
            d = self._value(self.D[q], roots, bits)
            if not isinstance(d, arb):
                return None
            sigma = -self.signs[q] if q == flip else self.signs[q]
            if d > 0:
                roots.append(sigma * d.sqrt())
            elif d < 0:
                roots.append(acb(0, sigma * (-d).sqrt()))
            else:
                return None
        return self._value(e, roots, bits)


def working_bits() -> int:
    from flint import ctx

    return ctx.prec


def det_a_vanishes_at(path: PathModel, point: AlgebraicPoint, label: str) -> bool:
    """det A of working mode ``label`` at the root, exactly: True when it is 0.

    Raises :class:`NotExact` when the root is not an algebraic number we can compute with.
    """
    expr = mode_expression(path)
    return _Tower(expr, point, expr.signs(label)).reduce() is None


def mode_zero_polynomial(path: PathModel, label: str, t0: fmpq) -> fmpq_mpoly | None:
    """Along the whole path (for a mode whose branches are real and analytic on the
    range, with every discriminant ≠ 0 at the rational sample ``t0``): None when det A ≡ 0
    along the mode, else a non-zero trig polynomial whose roots hold its zeros (in the
    path ring, with a pose angle's cos, sin, for an angle path)."""
    expr = mode_expression(path)
    zeros = _Tower(expr, PathFunctions(t0, expr.circle), expr.signs(label)).reduce()
    if zeros is None or expr.circle is None:
        return zeros
    return expr.circle.from_trig(zeros)  # C, S back to the pose angle's cos, sin


class _RadicalElement:
    """A trig polynomial over Q(√p₁, …, √pₖ) (a path-ring polynomial) in the form the
    tower takes: one level per √p (D = p, the positive root), no legs, no W."""

    def __init__(self, p: fmpq_mpoly) -> None:
        names = p.context().names()
        primes = [radical_prime(v) for v in names[3:]]
        if tuple(names[:3]) != ("t", "s", "c") or None in primes:
            raise NotExact("a polynomial with variables other than t, sin t, cos t and "
                           "square roots")
        self.D: list[dict] = [{0: TRIG.from_dict({(0, 0, 0): q})} for q in primes]
        self.terms = split_levels(p, self.D)
        self.W: list[dict] = []


def vanishes_at_root(p: fmpq_mpoly, root) -> bool | None:
    """Whether a path-ring polynomial p (square roots among its numbers) is exactly 0 at
    a root of its norm (a :class:`~singcheck.roots.enclosures.RealRoot` with an exact
    time), decided in the tower Q(α)(√p₁)…(√pₖ): e.g. a joint's limit polynomial at a time
    where both it and its conjugate (√3 ↦ -√3) vanish, which no ball can tell apart.
    None when the root's time has no exact description we compute with."""
    if root.exact is None:
        return None
    try:
        element = _RadicalElement(p)
        point = exact_point(root.exact, root, mixed=uses_trig(p) and uses_t(p))
        tower = _Tower(element, point, [1] * len(element.D))
        return tower.reduce() is None
    except NotExact:
        return None
