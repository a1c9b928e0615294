"""Exact adjacency of a plane open CAD's cells across a critical value α.

Free segments (:mod:`singcheck.regions`) prove that two cells are connected; they cannot
prove that two cells are *not*.  Here the line x = α itself is studied, exactly, so that
joining cells across every critical value gives exactly the connected components.

* **The fibre.**  α is a real root of an irreducible m ∈ Q[x] (its isolating interval
  picks the factor).  The product P of the variety's factors is taken in Q(α)[y]
  (coefficients reduced mod m; an element is 0 exactly when its remainder is).  If P(α, y)
  is 0 the line x = α lies in the variety: nothing is adjacent across it.  Otherwise the
  squarefree part h = P / gcd(P, ∂P/∂y) (Euclid in Q(α)[y]) has the distinct roots of
  P(α, ·) as simple roots; Arb isolates them from ball coefficients (α enclosed as
  tightly as needed), and a root ball whose conjugate meets no other root ball holds a
  real root (h has real coefficients).
* **Bands.**  Rationals s₀ < y₁ < s₁ < … < y_k < s_k separate the fibre's real points; a
  bracket a < α < b is narrowed until every line y = s_j is free on [a, b] (exact).
  Then no section crosses a line on [a, b]: the sections over (a, α) in a bounded band
  converge to its one fibre point, and those in the unbounded bands go to ±∞.
* **Adjacency.**  In a bounded band the lowest sector on the left touches the open
  segment {α} × (s_{j-1}, y_j), which avoids the variety, and so does the lowest on the
  right: they are joined; likewise the highest sectors through (y_j, s_j).  Sectors
  between two sections that meet at y_j are pinched there and touch nothing.  Below s₀
  only the highest sectors touch {α} × (-∞, s₀); above s_k only the lowest.  So the
  sectors adjacent across α are exactly, for each j, the left and the right sector
  holding the line y = s_j.
"""

from __future__ import annotations

from fractions import Fraction

from flint import acb, acb_poly, arb, arb_poly, fmpq, fmpq_poly

from singcheck.algebra.intervals import working_precision
from singcheck.budget import checkpoint
from singcheck.roots.rational import RationalRoot, ball_ends, to_fraction
from singcheck.spaces.cad import fiber, sector_of, simplest_between
from singcheck.spaces.segments import segment_is_free

WALL = "wall"  # the line x = α lies in the variety

#: Critical values α of higher degree are not studied exactly: Euclid in Q(α)[y] grows
#: too fast (a 3-RPR plane in the chart tan(φ/2) has α of degree 10 and did not finish
#: in minutes; the Orthoglide's planes and the 5-bar's workspace reach 8 and 6).  Their
#: cells are joined by free segments instead, and the regions are then not proven to be
#: the components.
MAX_EXACT_DEGREE = 8


class NotDecided(ArithmeticError):
    """The fibre could not be certified at the precisions tried."""


# ---------------------------------------------------------------------------------
# Q(α)[y]: lists of fmpq_poly (coefficient of y^i), reduced mod m, no zero leading term


def minimal_polynomial(root: RationalRoot) -> fmpq_poly:
    """The irreducible factor of ``root.poly`` vanishing at the isolated root."""
    if root.lo == root.hi:
        return fmpq_poly([-root.lo, 1])
    for f, _ in root.poly.factor()[1]:
        if f.degree() >= 1 and (f(root.lo) > 0) != (f(root.hi) > 0):
            return f
    raise NotDecided("no factor changes sign on the isolating interval")


class _Field:
    """Q[x]/(m) for an irreducible m, and polynomials in y over it (Euclid's algorithm
    with exact remainders; an element is zero exactly when its remainder mod m is)."""

    def __init__(self, m: fmpq_poly) -> None:
        self.m = m

    def reduce(self, p: fmpq_poly) -> fmpq_poly:
        return p % self.m if p.degree() >= self.m.degree() else p

    def inverse(self, p: fmpq_poly) -> fmpq_poly:
        g, s, _ = p.xgcd(self.m)
        if g.degree() != 0:
            raise NotDecided("a zero divisor: m is not irreducible")
        return self.reduce(s / g.leading_coefficient())

    def trim(self, a: list) -> list:
        while a and a[-1].is_zero():
            a.pop()
        return a

    def monic(self, a: list) -> list:
        inv = self.inverse(a[-1])
        return [self.reduce(c * inv) for c in a]

    def divmod(self, a: list, b: list) -> tuple[list, list]:
        b = self.monic(b)
        a = list(a)
        q = [fmpq_poly([])] * max(len(a) - len(b) + 1, 0)
        while len(a) >= len(b):
            c, shift = a[-1], len(a) - len(b)
            q[shift] = c
            for i in range(len(b) - 1):
                a[shift + i] = self.reduce(a[shift + i] - c * b[i])
            a.pop()
            self.trim(a)
        return q, a

    def gcd(self, a: list, b: list) -> list:
        while b:
            checkpoint()
            a, b = b, self.divmod(a, b)[1]
        return self.monic(a)


# ---------------------------------------------------------------------------------
# the fibre over α


def _product_in_y(factors, field: _Field) -> list:
    """The product of the factors (in x, y) as an element of Q(α)[y]."""
    out = [fmpq_poly([1])]
    for f in factors:
        coeffs: dict[int, dict[int, fmpq]] = {}
        for (i, j), c in f.terms():
            coeffs.setdefault(j, {})[i] = c
        g = [field.reduce(fmpq_poly([coeffs.get(j, {}).get(i, 0)
                                     for i in range(max(coeffs.get(j, {0: 0})) + 1)]))
             for j in range(max(coeffs) + 1)]
        prod = [fmpq_poly([])] * (len(out) + len(g) - 1)
        for i, a in enumerate(out):
            for j, b in enumerate(g):
                prod[i + j] = prod[i + j] + a * b
        out = field.trim([field.reduce(c) for c in prod])
    return out


def squarefree_fibre(factors, m: fmpq_poly) -> list | str:
    """The squarefree part of ∏ factors in Q[x]/(m)[y] (or :data:`WALL` when it is 0).

    The same for every root of m: Q[x]/(m) is isomorphic to Q(α) for each of them."""
    field = _Field(m)
    p = _product_in_y(factors, field)
    if not p:
        return WALL
    if len(p) == 1:
        return p
    dp = field.trim([field.reduce(c * i) for i, c in enumerate(p)][1:])
    g = field.gcd(p, dp)
    return field.divmod(p, g)[0] if len(g) > 1 else p


def fibre_points(factors, alpha: RationalRoot, memo: dict | None = None) -> list[arb] | str:
    """The distinct real points of the variety on the line x = α (sorted, disjoint
    balls), or :data:`WALL` when the whole line lies in it.  ``memo`` keeps the
    squarefree fibre per minimal polynomial (conjugate critical values share it)."""
    m = minimal_polynomial(alpha)
    memo = {} if memo is None else memo
    if str(m) not in memo:
        memo[str(m)] = squarefree_fibre(factors, m)
    h = memo[str(m)]
    if h == WALL:
        return WALL
    if len(h) == 1:
        return []
    for bits in (128, 512, 2048):
        points = _real_roots(h, alpha, bits)
        if points is not None:
            return points
    raise NotDecided("the real points of the fibre could not be isolated")


def _real_roots(h: list, alpha: RationalRoot, bits: int) -> list[arb] | None:
    alpha.bisect_to(fmpq(1, 2 ** (bits + 16)))
    with working_precision(bits + 64):
        a = alpha.ball()
        coeffs = [arb_poly([arb(c) for c in q.coeffs()])(a) if not q.is_zero() else arb(0)
                  for q in h]
        try:
            roots = acb_poly([acb(c) for c in coeffs]).roots(maxprec=4 * bits)
        except ValueError:
            return None
        real = []
        for i, z in enumerate(roots):
            if not z.imag.contains(0):
                continue
            mirror = z.conjugate()
            if any(j != i and mirror.overlaps(w) for j, w in enumerate(roots)):
                return None
            real.append(z.real)
    real.sort(key=lambda r: r.mid())
    if any(x.overlaps(y) for x, y in zip(real, real[1:], strict=False)):
        return None
    return real


def separators(points: list[arb]) -> list[Fraction]:
    """Rationals s₀ < y₁ < s₁ < … < y_k < s_k (k + 1 of them)."""
    if not points:
        return [Fraction(0)]
    ends = [tuple(map(to_fraction, ball_ends(p))) for p in points]
    out = [simplest_between(None, ends[0][0])]
    out += [simplest_between(lo_hi[1], nxt[0]) for lo_hi, nxt in zip(ends, ends[1:],
                                                                     strict=False)]
    out.append(simplest_between(ends[-1][1], None))
    return out


# ---------------------------------------------------------------------------------
# adjacency across α


def exact_joins(cad, base, i: int, brackets, memo: dict | None = None
                ) -> list[tuple[int, int]] | None:
    """The (left sector, right sector) pairs adjacent across the i-th critical value of
    a plane CAD, or None when they could not be decided (the caller falls back to free
    segments, which prove joins but not separations).

    The pairs are those holding the same separator s_j on both sides: the line y = s_j
    is free on [a, b], so the sector holding (a, s_j) reaches (b, s_j).  By the band
    argument above no other sectors touch across α.
    """

    try:
        if minimal_polynomial(base[i]).degree() > MAX_EXACT_DEGREE:
            return None
        points = fibre_points(cad.factors, base[i], memo)
    except NotDecided:
        return None
    if points == WALL:
        return []
    seps = separators(points)
    for round_ in range(6):
        checkpoint()
        a, b = brackets(base, i, round_)
        if all(segment_is_free(cad, (a, s), 0, a, b) for s in seps):
            left, right = (fiber(cad.levels, cad.variables, (x,)) for x in (a, b))
            return [(sector_of(left, s), sector_of(right, s)) for s in seps]
    return None
