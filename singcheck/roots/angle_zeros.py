"""Roots at a zero of a pose angle's polynomial: the algebraic points (τ, cos qπ, sin qπ).

On a path whose pose angle is G(t) = g(t) + qπ (g ∈ Q[t] not constant, q rational:
``phi: t^2 - 2``, ``phi: t^2 + pi/3``), the point (τ, C, S) = (τ, cos G(τ), sin G(τ)) is
algebraic exactly at the zeros τ of g (anywhere else it is not:
:mod:`singcheck.roots.transcendental`).  There τ is a root of an irreducible factor f of
g, isolated by a rational interval, and (C, S) = (cos qπ, sin qπ).  :class:`AngleZero` is
that point; :func:`angle_zeros` finds the roots of a path polynomial at such points, with
their multiplicity, for the branch-and-bound (which cannot bracket a root of even
multiplicity: ``phi: t^2 - 2`` at the constant position on the 3-RPR's singular surface
at φ = 0 touches it at t = ±√2).

**The zero test** of an element a(t, s, c) (a path polynomial, C and S renamed c and s)
at the point, exact:

* when 2q is an integer, C and S are 0 or ±1: a(t, S, C) is a polynomial in t, and it
  vanishes at τ exactly when f divides it (f is irreducible);
* otherwise the value v = a(τ, S, C) is an algebraic number, a root of
  P(z) = Res_t(f, Res_c(m, Res_s(s² + c² - 1, z - a))) with m the minimal polynomial of
  cos qπ: each resultant vanishes at z = v (the others' common root is there), and P is
  not the zero polynomial (its leading coefficient in z is a product of powers of the
  non-zero leading coefficients of s² + c² - 1, m and f).  If P(0) ≠ 0, then v ≠ 0.
  Otherwise P = zᵏ·Q with Q(0) ≠ 0, and every non-zero root z of P has
  |z| ≥ r = |Q₀| / (|Q₀| + maxᵢ≥₁ |Qᵢ|) (from Q₀ = -Σᵢ≥₁ Qᵢzⁱ, for |z| < 1); so a ball of
  v inside (-r, r) proves v = 0, and one that excludes 0 proves v ≠ 0.  Balls narrow
  with the precision and τ's interval until one of the two holds (a cap then ends in
  :class:`~singcheck.roots.transcendental.NotExact`).

**Multiplicity.**  When p and its derivatives along the path (the chain rule through g)
up to order m - 1 vanish at τ and the m-th encloses away from 0 on a rational box B
around τ, Taylor's theorem with the Lagrange remainder makes τ the only root in B, of
multiplicity m (the argument of :mod:`singcheck.roots.branch_bound`).
"""

from __future__ import annotations

from fractions import Fraction

from flint import arb, fmpq, fmpq_mpoly, fmpq_mpoly_ctx, fmpq_poly

from singcheck.algebra.intervals import evaluate, excludes_zero, working_precision
from singcheck.algebra.trig import TRIG, TimeRange
from singcheck.budget import checkpoint
from singcheck.roots.enclosures import inside_range
from singcheck.roots.rational import RationalRoot, rational_ball, real_roots_exact
from singcheck.roots.transcendental import NotExact

#: precision cap of the ball side of the zero test (far past any separation seen)
_MAX_BITS = 4096
#: what the exact test takes on: g of degree at most 64 (factored, its roots isolated),
#: q with a denominator at most 60 (cos qπ's minimal polynomial is a factor of the
#: Chebyshev polynomial of that degree), and deg f · deg m at most 64 (the degree of the
#: annihilating polynomial, over two); beyond, the zero is left to the branch-and-bound
_MAX_G_DEGREE, _MAX_Q_DENOMINATOR, _MAX_FIELD_DEGREE = 64, 60, 64
_Z = fmpq_mpoly_ctx.get(("z", "t", "s", "c"), "lex")
_CIRCLE = TRIG.from_dict({(0, 2, 0): 1, (0, 0, 2): 1, (0, 0, 0): -1})


def exact_sin_cos(q: Fraction) -> tuple[int, int] | None:
    """(sin qπ, cos qπ) when both are 0 or ±1 (2q an integer), else None."""
    if (2 * q).denominator != 1:
        return None
    k = int(2 * q) % 4
    return (0, 1, 0, -1)[k], (1, 0, -1, 0)[k]


def univariate(p: fmpq_mpoly) -> fmpq_poly:
    """A polynomial in t alone (of ``TRIG``, or of a one-variable ring) as an fmpq_poly."""
    out = fmpq_poly([])
    for exps, coeff in p.terms():
        out += fmpq_poly([0] * int(exps[0]) + [coeff])
    return out


class AngleZero:
    """The point (τ, sin qπ, cos qπ) for a root τ of the irreducible ``f`` isolated by
    ``root`` (module docstring): elements are ``TRIG`` polynomials (s, c standing for
    the pose angle's S, C), reduced with s² = 1 - c² and modulo f(t); ``is_zero`` is the
    exact test, ``ball`` an enclosure of an element's value."""

    max_bits = _MAX_BITS

    def __init__(self, root: RationalRoot, q: Fraction) -> None:
        self.root, self.q = root, q
        self.f = root.poly / root.poly.leading_coefficient()
        self.F = TRIG.from_dict({(i, 0, 0): c for i, c in enumerate(self.f.coeffs())})
        self.exact = exact_sin_cos(q)
        self._m: fmpq_poly | None = None

    def of(self, p: fmpq_mpoly) -> fmpq_mpoly:
        return self._reduce(p)

    def _reduce(self, a: fmpq_mpoly) -> fmpq_mpoly:
        return (a % _CIRCLE) % self.F

    def mul(self, a: fmpq_mpoly, b: fmpq_mpoly) -> fmpq_mpoly:
        return self._reduce(a * b)

    def is_zero(self, a: fmpq_mpoly) -> bool:
        a = self._reduce(a)
        if a.is_zero():
            return True
        if self.exact is not None:
            s0, c0 = self.exact
            return (univariate(a.subs({"s": s0, "c": c0})) % self.f).is_zero()
        return self._by_root_bound(a)

    def _minimal_polynomial_of_cos(self) -> fmpq_poly:
        if self._m is None:
            from singcheck.algebra.trig_values import _minimal_polynomial_of_cos

            if self.q.denominator > _MAX_Q_DENOMINATOR:
                raise NotExact(f"cos({self.q}π) has a minimal polynomial of too high a degree "
                               "for the exact test")
            self._m = _minimal_polynomial_of_cos(self.q - 2 * (self.q // 2))
            if self._m.degree() * self.f.degree() > _MAX_FIELD_DEGREE:
                raise NotExact("the point at a zero of the pose angle's polynomial has too "
                               "high a degree for the exact test")
        return self._m

    def _annihilator(self, a: fmpq_mpoly) -> fmpq_poly:
        """P(z) of the module docstring: a non-zero polynomial with P(a at the point) = 0."""
        gens = dict(zip(_Z.names(), _Z.gens(), strict=True))
        z, t, s, c = gens["z"], gens["t"], gens["s"], gens["c"]
        lifted = _Z.from_dict({(0, *e): coeff for e, coeff in a.terms()})
        m = sum((coeff * c ** i for i, coeff in enumerate(self._minimal_polynomial_of_cos()
                                                           .coeffs())), _Z.from_dict({}))
        f = sum((coeff * t ** i for i, coeff in enumerate(self.f.coeffs())), _Z.from_dict({}))
        checkpoint()
        p1 = (z - lifted).resultant(s * s + c * c - 1, "s")
        checkpoint()
        p2 = p1.resultant(m, "c")
        checkpoint()
        p3 = p2.resultant(f, "t")
        out = fmpq_poly([])
        for exps, coeff in p3.terms():
            out += fmpq_poly([0] * int(exps[0]) + [coeff])
        if out.is_zero():  # cannot happen (see the module docstring): refuse, never guess
            raise NotExact("the annihilating polynomial of a value at a zero of the pose "
                           "angle's polynomial vanished")
        return out

    def _by_root_bound(self, a: fmpq_mpoly) -> bool:
        p = self._annihilator(a)
        coeffs = p.coeffs()
        if coeffs[0] != 0:
            return False
        k = next(i for i, x in enumerate(coeffs) if x != 0)
        q = coeffs[k:]
        q0 = abs(q[0])
        top = max((abs(x) for x in q[1:]), default=fmpq(0))
        radius = q0 / (q0 + top)
        bits = 64
        while bits <= self.max_bits:
            checkpoint()
            with working_precision(bits):
                v = self.ball(a, bits)
                if excludes_zero(v):
                    return False
                if v.upper() < arb(radius) and v.lower() > -arb(radius):
                    return True
            bits *= 2
        raise NotExact("ball arithmetic did not decide a value at a zero of the pose angle's "
                       f"polynomial near t ≈ {float(self.root.lo):.6g}")

    def point_balls(self, bits: int) -> list[arb]:
        """Balls of τ, sin qπ and cos qπ (τ's interval narrowed to about 2^-bits)."""
        if self.root.lo != self.root.hi:
            self.root.bisect_to(fmpq(1, 2 ** bits))
        angle = arb.pi() * arb(fmpq(self.q.numerator, self.q.denominator))
        return [rational_ball(self.root.lo, self.root.hi), angle.sin(), angle.cos()]

    def ball(self, a: fmpq_mpoly, bits: int) -> arb:
        with working_precision(bits):
            return evaluate(a, self.point_balls(bits))


def angle_zeros(p: fmpq_mpoly, circle, interval: TimeRange, derivative, eval_box
                ) -> list[tuple[RationalRoot, int, fmpq, fmpq]]:
    """(τ's root, m, a, b) for each zero τ of g in the range (every irreducible factor of
    g, any q) where the path polynomial p vanishes with multiplicity m, τ the only root
    of p in the rational box [a, b] (module docstring).  ``derivative`` differentiates p
    along the path, ``eval_box(p, a, b)`` encloses it over [a, b]."""
    g = univariate(circle.g)
    if g.degree() > _MAX_G_DEGREE or (exact_sin_cos(circle.q) is None
                                      and circle.q.denominator > _MAX_Q_DENOMINATOR):
        return []
    out = []
    for factor, _ in g.numer().factor()[1]:
        f = fmpq_poly(factor)
        if f.degree() < 1:
            continue
        for rr, _ in real_roots_exact(f):
            checkpoint()
            where = None
            for _ in range(64):
                where = inside_range(rr.ball(), None, interval, 128)
                if where is not None or rr.lo == rr.hi:
                    break
                rr.bisect_to(rr.width() / 1024)
            if not where:
                continue
            point = AngleZero(rr, circle.q)
            try:
                dk, order = p, 0
                while order < 64 and point.is_zero(circle.to_trig(dk)):
                    checkpoint()
                    dk, order = derivative(dk), order + 1
                if order == 0 or point.is_zero(circle.to_trig(dk)):
                    continue
            except NotExact:
                continue  # left to the branch-and-bound (an undecided window, if a root)
            for e in range(1, 64):
                checkpoint()
                rr.bisect_to(fmpq(1, 2 ** (e + 1)))
                a, b = rr.lo - fmpq(1, 2 ** e), rr.hi + fmpq(1, 2 ** e)
                if excludes_zero(eval_box(dk, a, b)):
                    out.append((rr, order, a, b))
                    break
    return out
