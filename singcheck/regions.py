"""Connected regions of a plane decomposition: joining open cells across columns.

The paper's third step ("connection of the cells belonging to the same connected
component").  For a 2-D open CAD, cells of one column are separated by sections of the
variety, so only cells of neighbouring columns can join.  Around each critical value α
between two columns, rationals a < α < b are taken inside the two columns (α's
isolating interval, narrowed round after round); for candidate heights y₀ (the sector
samples of the fibres at a and b), the horizontal segment [a, b] × {y₀} is checked
exactly to meet none of the variety's factors (no root of f(x, y₀) in [a, b]).  When it
is free, the cell holding (a, y₀) and the cell holding (b, y₀) are in one region.

What is proven: every region is connected (a chain of free segments and connected cells
links any two of its cells).  The regions are exactly the connected components when no
two of them share the same signs of the variety's factors (a component has one sign
vector, since no factor vanishes on it); ``components_proven`` says whether that holds.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from flint import fmpq, fmpq_poly

from singcheck.cad import Cell, OpenCAD, as_univariate, fiber, sector_samples
from singcheck.solution_counts import roots_within

_ROUNDS = 3


@dataclass(frozen=True)
class Region:
    number: int  # 1-based, in order of the first cell
    cells: tuple[Cell, ...]
    signs: tuple[int, ...]  # sign of each factor of the variety on the region


@dataclass(frozen=True)
class Regions:
    regions: tuple[Region, ...]
    components_proven: bool
    reason: str  # why not proven, when not

    def region_of(self, cell: Cell) -> Region:
        for region in self.regions:
            if cell in region.cells:
                return region
        raise KeyError(cell.index)


class _UnionFind:
    def __init__(self) -> None:
        self.parent: dict = {}

    def find(self, a):
        self.parent.setdefault(a, a)
        while self.parent[a] != a:
            self.parent[a] = self.parent[self.parent[a]]
            a = self.parent[a]
        return a

    def union(self, a, b) -> None:
        ra, rb = self.find(a), self.find(b)
        if ra != rb:
            self.parent[max(ra, rb)] = min(ra, rb)


def _q(x: Fraction) -> fmpq:
    return fmpq(x.numerator, x.denominator)


def factor_signs(cad: OpenCAD, point) -> tuple[int, ...]:
    """The exact sign of every factor of the variety at a rational point."""
    values = {v: _q(Fraction(x)) for v, x in zip(cad.variables, point, strict=True)}
    out = []
    for f in cad.factors:
        value = f.subs(values)
        c = value.leading_coefficient() if not value.is_zero() else fmpq(0)
        out.append((c > 0) - (c < 0))
    return tuple(out)


def no_root_between(q: fmpq_poly, a: Fraction, b: Fraction) -> bool:
    """True when q has no root in the closed [a, b] (exact).

    Quick proof first: q(a), q(b) ≠ 0 and no sign variation in the coefficients of
    (1+u)^d · q((a + b·u)/(1+u)), whose positive roots are the roots of q in (a, b)
    (Descartes).  Otherwise the roots are isolated and compared exactly.
    """
    qa, qb = _q(a), _q(b)
    if q(qa) == 0 or q(qb) == 0:
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


def segment_is_free(cad: OpenCAD, a: Fraction, b: Fraction, y0: Fraction) -> bool:
    """True when no factor of the variety vanishes on [a, b] × {y₀} (exact)."""
    for f in cad.factors:
        q = as_univariate(f.subs({cad.variables[1]: _q(y0)}), 0)  # f(x, y₀)
        if q.is_zero():
            return False
        if q.degree() >= 1 and not no_root_between(q, a, b):
            return False
    return True


def _locate(roots, y0: Fraction) -> int:
    """The sector index of y₀ among separated roots (y₀ must not be a root)."""
    q = _q(y0)
    return sum(1 for r in roots if r.compare(q) < 0)


def _brackets(base, i: int, round_: int) -> tuple[Fraction, Fraction]:
    """Rationals a < α_i < b, inside the two neighbouring columns, narrower each round."""
    r = base[i]
    if r.lo != r.hi:
        if round_:
            r.bisect_to((r.hi - r.lo) / 2 ** (8 * round_))
        return Fraction(int(r.lo.p), int(r.lo.q)), Fraction(int(r.hi.p), int(r.hi.q))
    alpha = Fraction(int(r.lo.p), int(r.lo.q))
    left = Fraction(int(base[i - 1].hi.p), int(base[i - 1].hi.q)) if i else alpha - 1
    right = Fraction(int(base[i + 1].lo.p), int(base[i + 1].lo.q)) \
        if i + 1 < len(base) else alpha + 1
    delta = min(alpha - left, right - alpha) / 2 ** (1 + 8 * round_)
    return alpha - delta, alpha + delta


def connect_regions(cad: OpenCAD) -> Regions:
    """Group the cells of a 2-D open CAD into proven-connected regions."""
    if len(cad.variables) != 2:
        raise ValueError("regions are computed for plane decompositions")
    uf = _UnionFind()
    for c in cad.cells:
        uf.find(c.index)
    base = fiber(cad.levels, cad.variables, ())
    for i in range(len(base)):
        _join_across(cad, base, i, uf)
    groups: dict = {}
    for c in cad.cells:
        groups.setdefault(uf.find(c.index), []).append(c)
    regions = []
    for n, members in enumerate(sorted(groups.values(), key=lambda m: m[0].index), 1):
        regions.append(Region(n, tuple(members), factor_signs(cad, members[0].sample)))
    seen: dict = {}
    clashes = 0
    for r in regions:
        clashes += r.signs in seen
        seen.setdefault(r.signs, r)
    reason = "" if not clashes else (
        f"{clashes} region(s) share the factor signs of another one: they may be parts of "
        "one connected component that no checked segment joined")
    return Regions(tuple(regions), clashes == 0, reason)


def _join_across(cad: OpenCAD, base, i: int, uf: _UnionFind) -> None:
    """Join the cells of columns i and i+1 through free segments across α_i."""
    for round_ in range(_ROUNDS):
        a, b = _brackets(base, i, round_)
        left, right = (fiber(cad.levels, cad.variables, (x,)) for x in (a, b))
        joined_left, joined_right = set(), set()
        for y0 in sorted(set(sector_samples(left)) | set(sector_samples(right))):
            if not segment_is_free(cad, a, b, y0):
                continue
            j, k = _locate(left, y0), _locate(right, y0)
            uf.union((i, j), (i + 1, k))
            joined_left.add(j)
            joined_right.add(k)
        if len(joined_left) == len(left) + 1 and len(joined_right) == len(right) + 1:
            return
