"""Connected regions of an open CAD: joining open cells across critical values.

The paper's third step ("connection of the cells belonging to the same connected
component"), in any dimension.  At each level k below the top, over the sample of
every cell of the first k axes, the next axis is cut by the real roots α of the
level's projection factors.  Around each α, rationals a < α < b are taken inside the
two neighbouring sectors (α's isolating interval, narrowed round after round); for
candidate points above (the sector samples of the fibres over both ends, level after
level), the segment from a to b along axis k is checked exactly to meet none of the
variety's factors (no root of f restricted to it in [a, b]).  When it is free, the
cells holding its two ends are in one region.  Cells of one stack at the top level are
separated by the variety's own sections, so only lower levels are crossed.

What is proven: every region is connected (a chain of free segments and connected cells
links any two of its cells).  The regions are exactly the connected components when
every two of them differ in something constant on a component: the sign of a factor of
the variety (none vanishes on a component), the side of a *wall* (a factor in one
variable x_k gives hyperplanes x_k = α that no component crosses), or an invariant the
caller proves constant (the solution counts); ``components_proven`` says whether that
holds.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from singcheck.algebra.polynomials import constant_value
from singcheck.budget import checkpoint
from singcheck.roots.rational import to_fmpq, to_fraction
from singcheck.spaces.cad import (
    Cell,
    OpenCAD,
    as_univariate,
    cell_index_of,
    fiber,
    sector_of,
    sector_samples,
    separated_roots,
)
from singcheck.spaces.segments import segment_is_free

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


def factor_signs(cad: OpenCAD, point) -> tuple[int, ...]:
    """The exact sign of every factor of the variety at a rational point."""
    values = {v: to_fmpq(Fraction(x)) for v, x in zip(cad.variables, point, strict=True)}
    out = []
    for f in cad.factors:
        value = f.subs(values)
        c = constant_value(value)
        out.append((c > 0) - (c < 0))
    return tuple(out)


def _brackets(base, i: int, round_: int) -> tuple[Fraction, Fraction]:
    """Rationals a < α_i < b, inside the two neighbouring sectors, narrower each round."""
    r = base[i]
    if r.lo != r.hi and round_:
        r.bisect_to((r.hi - r.lo) / 2 ** (8 * round_))
    if r.lo != r.hi:  # (bisection may have met the root exactly: then it is a point)
        return to_fraction(r.lo), to_fraction(r.hi)
    alpha = to_fraction(r.lo)
    left = to_fraction(base[i - 1].hi) if i else alpha - 1
    right = to_fraction(base[i + 1].lo) if i + 1 < len(base) else alpha + 1
    delta = min(alpha - left, right - alpha) / 2 ** (1 + 8 * round_)
    return alpha - delta, alpha + delta


def connect_regions(cad: OpenCAD, invariants: dict | None = None) -> Regions:
    """Group the cells of an open CAD (2-D or more) into proven-connected regions.

    ``invariants`` (cell index → value), when given, holds a quantity proven constant on
    every connected component of the complement (a solution count): regions whose values
    differ are then known to be different components.
    """
    if len(cad.variables) < 2:
        raise ValueError("regions are joined in decompositions of two or more axes")
    uf = _UnionFind()
    indices = {c.index for c in cad.cells}
    for index in indices:
        uf.find(index)
    memo: dict = {}

    def fibre(point: tuple) -> list:
        if point not in memo:
            memo[point] = fiber(cad.levels, cad.variables, point)
        return memo[point]

    exact = len(cad.variables) == 2  # complete adjacency is known in the plane only
    fibres_over_alpha: dict = {}
    # the top level's roots are the variety's own factors: no segment crosses them freely
    for level in range(len(cad.variables) - 1):
        prefixes = {(c.index[:level], c.sample[:level]) for c in cad.cells}
        over: dict = {}  # the cells over each sector of this level
        for c in cad.cells:
            over.setdefault(c.index[:level + 1], set()).add(c.index)
        for prefix_index, prefix_sample in sorted(prefixes):
            checkpoint()
            base = fibre(prefix_sample)
            for i in range(len(base)):
                if exact and _join_exactly(cad, base, i, indices, uf, fibres_over_alpha):
                    continue
                exact = False
                _join_across(cad, fibre, indices, over, prefix_index, prefix_sample, base, i,
                             uf)
    regions = _regions_of(cad, uf, invariants or {})
    if exact:  # every adjacency decided: the regions are the components
        return Regions(regions.regions, True, "")
    return regions


def _join_exactly(cad: OpenCAD, base, i: int, indices: set, uf: _UnionFind,
                  memo: dict) -> bool:
    """Join the columns on either side of the plane's i-th critical value by their exact
    adjacency (:mod:`singcheck.plane_adjacency`); False when it could not be decided."""
    from singcheck.spaces.plane_adjacency import exact_joins

    pairs = exact_joins(cad, base, i, _brackets, memo)
    if pairs is None:
        return False
    for left, right in pairs:
        if (i, left) not in indices or (i + 1, right) not in indices:
            return False
        uf.union((i, left), (i + 1, right))
    return True


def _regions_of(cad: OpenCAD, uf: _UnionFind, invariants: dict) -> Regions:
    groups: dict = {}
    for c in cad.cells:
        groups.setdefault(uf.find(c.index), []).append(c)
    regions = []
    for n, members in enumerate(sorted(groups.values(), key=lambda m: m[0].index), 1):
        regions.append(Region(n, tuple(members), factor_signs(cad, members[0].sample)))
    walls = _walls(cad)
    by_signs: dict = {}
    for r in regions:
        key = (r.signs, _slabs(walls, r.cells[0].sample))
        by_signs.setdefault(key, []).append(invariants.get(r.cells[0].index))
    clashes = 0
    for values in by_signs.values():
        known = {v for v in values if v is not None}
        clashes += len(values) - 1 if None in values else len(values) - len(known)
    reason = "" if not clashes else (
        f"{clashes} region(s) share the factor signs, the side of every wall and the "
        "solution count of another one: they may be parts of one connected component "
        "that no checked segment joined")
    return Regions(tuple(regions), clashes == 0, reason)


def _walls(cad: OpenCAD) -> list[tuple[int, list]]:
    """Factors in a single variable x_k: their real roots α are hyperplanes x_k = α of the
    variety, which no connected set off the variety crosses.  (axis, separated roots)."""
    out = []
    for f in cad.factors:
        axes = [k for k, d in enumerate(f.degrees()) if d > 0]
        if len(axes) == 1:
            out.append((axes[0], separated_roots(as_univariate(f, axes[0]))))
    return out


def _slabs(walls, sample) -> tuple[int | None, ...]:
    """For each wall, how many of its hyperplanes lie below the sample (exact)."""
    return tuple(sector_of(roots, sample[axis]) for axis, roots in walls)


def _join_across(cad: OpenCAD, fibre, indices: set, over: dict, prefix_index: tuple,
                 prefix_sample: tuple, base, i: int, uf: _UnionFind) -> None:
    """Join the cells over sector i and sector i+1 of ``base`` (the fibre over the prefix
    cell's sample at the next level) through free segments across its root α_i."""
    level = len(prefix_sample)
    # the cells on either side that still have to be joined across α_i
    waiting = [set(over.get(prefix_index + (j,), ())) for j in (i, i + 1)]
    for round_ in range(_ROUNDS):
        a, b = _brackets(base, i, round_)
        for rest in _candidate_rests(cad, fibre, prefix_sample, a, b):
            checkpoint()  # (the candidates multiply with the levels above)
            point = (*prefix_sample, a, *rest)
            if not segment_is_free(cad, point, level, a, b):
                continue
            known = level + 1  # the ends' sectors up to the crossing level are known
            lo = cell_index_of(fibre, point, prefix_index + (i,), known)
            hi = cell_index_of(fibre, (*prefix_sample, b, *rest), prefix_index + (i + 1,),
                               known)
            if lo in indices and hi in indices:
                uf.union(lo, hi)
                waiting[0].discard(lo)
                waiting[1].discard(hi)
                if not waiting[0] and not waiting[1]:
                    return


def _candidate_rests(cad: OpenCAD, fibre, prefix: tuple, a: Fraction, b: Fraction):
    """Coordinates for the levels above the crossing: at each level, the sector samples
    of the fibres over the two ends (a point on a root of either is skipped, since
    it lies on no open cell there)."""
    def extend(rest: tuple):
        if len(prefix) + 1 + len(rest) == len(cad.variables):
            yield rest
            return
        fibres = [fibre((*prefix, end, *rest)) for end in (a, b)]
        for y0 in sorted(set(sector_samples(fibres[0])) | set(sector_samples(fibres[1]))):
            if all(sector_of(f, y0) is not None for f in fibres):
                yield from extend((*rest, y0))

    yield from extend(())
