"""Open cylindrical algebraic decomposition over Q (the paper's "generic CAD").

``open_cad(polys)`` splits the complement of the hypersurface ``∏ polys = 0`` in Rⁿ
into open cells, each with an exact rational sample point.  What is proven, and how:

* **Projection.**  Variables are eliminated last first.  For every irreducible factor
  p involving x_k the projection keeps its leading coefficient and discriminant in x_k,
  and the resultant in x_k of every pair (Brown/Collins without the parts only lower-
  dimensional cells need).  On an open connected set C where none of those vanish, each
  p keeps its degree (leading coefficient ≠ 0), its real roots stay simple
  (discriminant ≠ 0) and never meet another factor's roots (resultants ≠ 0), so by the
  implicit function theorem they are continuous non-crossing functions on C: the
  sectors between them are open connected cells on which every p has a constant sign.
* **Lifting.**  Over a rational sample point of a lower cell the factors become
  univariate polynomials over Q; their real roots are isolated exactly
  (:func:`singcheck.rational_roots.real_roots_exact`, Descartes/VCA) and the simplest
  rational strictly between consecutive roots is the next sample coordinate.  All
  arithmetic is exact, so every sample point lies in the open cell it names and off
  the hypersurface.

Only full-dimensional cells are built: they are what a solution count is constant on.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from itertools import combinations

from flint import fmpq, fmpq_mpoly, fmpq_poly

from singcheck.algebra.polynomials import coefficient_in
from singcheck.budget import checkpoint
from singcheck.roots.rational import RationalRoot, real_roots_exact, simplest_between, to_fraction


@dataclass(frozen=True)
class Cell:
    """An open cell: its sector number at each level, and a rational point inside it."""

    index: tuple[int, ...]
    sample: tuple[Fraction, ...]


@dataclass(frozen=True)
class OpenCAD:
    variables: tuple[str, ...]
    factors: tuple[fmpq_mpoly, ...]  # the irreducible factors of the input: the variety
    levels: tuple[tuple[fmpq_mpoly, ...], ...]  # levels[k]: factors in x_1..x_{k+1}
    cells: tuple[Cell, ...]


# ---------------------------------------------------------------------------------
# exact polynomial helpers


def irreducible_factors(polys) -> list[fmpq_mpoly]:
    """The distinct non-constant irreducible factors of ``polys``, each made monic."""
    seen: dict[str, fmpq_mpoly] = {}
    for p in polys:
        if p.is_zero() or p.is_constant():
            continue
        checkpoint()
        for f, _ in p.factor()[1]:
            if f.is_constant():
                continue
            f = f / f.leading_coefficient()
            seen.setdefault(str(f), f)
    return sorted(seen.values(), key=str)


def as_univariate(q: fmpq_mpoly, var_index: int) -> fmpq_poly:
    """``q``, which involves no variable but ``var_index``, as a univariate polynomial."""
    coeffs: dict[int, fmpq] = {}
    for exps, c in q.terms():
        coeffs[exps[var_index]] = coeffs.get(exps[var_index], fmpq(0)) + c
    if not coeffs:
        return fmpq_poly([])
    return fmpq_poly([coeffs.get(i, fmpq(0)) for i in range(max(coeffs) + 1)])


def specialize(p: fmpq_mpoly, variables, point) -> fmpq_poly:
    """``p`` with its first ``len(point)`` variables set to rationals, as a univariate
    polynomial in the next variable (``p`` must not involve later ones)."""
    values = {variables[i]: fmpq(q.numerator, q.denominator) for i, q in enumerate(point)}
    return as_univariate(p.subs(values) if values else p, len(point))


def project(polys: list[fmpq_mpoly], var_index: int) -> list[fmpq_mpoly]:
    """Factors whose non-vanishing on an open cell makes ``polys`` delineable over it."""
    lower: list[fmpq_mpoly] = []
    upper = []
    for p in polys:
        d = p.degrees()[var_index]
        if d == 0:
            lower.append(p)
            continue
        upper.append(p)
        lower.append(coefficient_in(p, var_index, d))
        if d >= 2:
            checkpoint()
            lower.append(p.discriminant(p.context().names()[var_index]))
    name = polys[0].context().names()[var_index] if polys else None
    for p, q in combinations(upper, 2):  # a resultant each
        checkpoint()
        lower.append(p.resultant(q, name))
    return irreducible_factors(lower)


# ---------------------------------------------------------------------------------
# sample points


def separated_roots(p: fmpq_poly) -> list[RationalRoot]:
    """The real roots of ``p`` (squarefree part), sorted, with pairwise disjoint closed
    isolating intervals (point intervals for roots met exactly)."""
    if p.degree() < 1:
        return []
    sqf = p / p.gcd(p.derivative()) if p.degree() > 1 else p
    roots = [r for r, _ in real_roots_exact(sqf)]
    while True:  # distinct roots: halving the clashing intervals separates them
        checkpoint()  # (roots closer than 2^-k apart take about k rounds)
        clash = [i for i in range(len(roots) - 1) if roots[i].hi >= roots[i + 1].lo]
        if not clash:
            return roots
        for i in clash:
            for r in (roots[i], roots[i + 1]):
                if r.lo != r.hi:
                    r.bisect_to((r.hi - r.lo) / 2)


def sector_samples(roots: list[RationalRoot]) -> list[Fraction]:
    """One rational in each open interval cut out by the (separated) roots.

    Between two roots the gap ``(hi_i, lo_{i+1})`` lies strictly between them (a root
    is inside its interval, or is the interval when met exactly), so any rational in
    it is a sample; the simplest one is taken, for readable reports.
    """
    if not roots:
        return [Fraction(0)]
    gaps = [(None, to_fraction(roots[0].lo))]
    gaps += [(to_fraction(a.hi), to_fraction(b.lo)) for a, b in zip(roots, roots[1:], strict=False)]
    gaps.append((to_fraction(roots[-1].hi), None))
    return [simplest_between(lo, hi) for lo, hi in gaps]


# ---------------------------------------------------------------------------------
# the decomposition


def projection_levels(polys: list[fmpq_mpoly]) -> tuple[tuple[fmpq_mpoly, ...], ...]:
    """``levels[k]``: the projection factors in x_1..x_{k+1} (with x_{k+1} or lower)."""
    n = polys[0].context().nvars()
    current = irreducible_factors(polys)
    levels: list[list[fmpq_mpoly]] = [[] for _ in range(n)]
    for k in range(n - 1, -1, -1):
        levels[k] = [p for p in current if p.degrees()[k] > 0]
        if k:
            current = project(current, k)
    return tuple(tuple(level) for level in levels)


def fiber(levels, variables, point: tuple[Fraction, ...]) -> list[RationalRoot]:
    """The separated real roots, over ``point``, of the next level's factors.

    Each factor's roots are isolated on its own (smaller degrees) and the intervals of
    different factors are bisected apart.  Where two factors share a root (a point off
    the open cells, e.g. on a lower section) they never come apart: the squarefree
    product is isolated instead.
    """
    polys = [specialize(p, variables, point) for p in levels[len(point)]]
    polys = [q for q in polys if q.degree() >= 1]
    roots = [r for q in polys for r, _ in real_roots_exact(q)]
    apart = _bisect_apart(roots)
    if apart is not None:
        return apart
    product = fmpq_poly([1])
    for q in polys:
        product *= q
    return separated_roots(product)


def _bisect_apart(roots: list[RationalRoot], rounds: int = 60) -> list[RationalRoot] | None:
    """The roots sorted with pairwise disjoint closed intervals, or None when two of
    them could not be separated (they may be one root of two factors)."""
    for _ in range(rounds):
        checkpoint()
        roots.sort(key=lambda r: r.lo)
        clash = set()
        for i, r in enumerate(roots):
            for s in roots[i + 1:]:
                if s.lo > r.hi:
                    break
                clash.update((id(r), id(s)))
                if r.lo == r.hi and s.lo == s.hi:
                    return None  # the same rational root of two factors
        if not clash:
            return roots
        for r in roots:
            if id(r) in clash and r.lo != r.hi:
                r.bisect_to((r.hi - r.lo) / 2)
    return None


def sector_of(roots: list[RationalRoot], y0: Fraction) -> int | None:
    """The index of the sector holding the rational y₀ among separated roots (exact
    comparisons); None when y₀ is one of the roots."""
    q = fmpq(y0.numerator, y0.denominator)
    relations = [r.compare(q) for r in roots]
    if 0 in relations:
        return None
    return sum(1 for r in relations if r < 0)


def cell_index_of(fibre, point: tuple[Fraction, ...], head: tuple[int, ...] = (),
                  known: int = 0) -> tuple[int, ...] | None:
    """The index of the open cell holding a rational point, level by level (``fibre``
    gives the separated roots over a point); the first ``known`` coordinates are known to
    lie in the sectors ``head``.  None when the point lies on a root (on no open cell)."""
    index = list(head)
    for k in range(known, len(point)):
        sector = sector_of(fibre(tuple(point[:k])), point[k])
        if sector is None:
            return None
        index.append(sector)
    return tuple(index)


def lift(levels, variables, point: tuple[Fraction, ...]) -> list[Fraction]:
    """Sample coordinates of the sectors over ``point`` at the next level."""
    checkpoint()
    return sector_samples(fiber(levels, variables, point))


def open_cad(polys: list[fmpq_mpoly]) -> OpenCAD:
    """The open cells of the complement of ``∏ polys = 0`` in Rⁿ, with rational samples."""
    ctx = polys[0].context()
    variables = tuple(ctx.names())
    levels = projection_levels(polys)
    cells = [Cell((), ())]
    for _ in variables:
        cells = [Cell(c.index + (i,), c.sample + (x,))
                 for c in cells
                 for i, x in enumerate(lift(levels, variables, c.sample))]
    return OpenCAD(variables, tuple(irreducible_factors(polys)), levels, tuple(cells))
