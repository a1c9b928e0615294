"""A trajectory against the workspace's regions: crossings, counts, exit time, region.

What is proven, and how:

* **Crossings.**  The path meets a surface of the workspace's discriminant variety
  (a leg's serial singularity D = 0, a joint limit projected, ξ = 0) exactly at the
  real roots of that surface's polynomial composed with φ(t); they are isolated in
  certified balls (:func:`singcheck.roots.isolate_real_roots`).
* **Counts between crossings.**  Between two consecutive crossings the path stays in
  one connected component of the complement, where the number of inverse-kinematic
  solutions inside the joint limits is constant; it is counted at one exact point of
  the stretch with ball arithmetic (each branch's reality from D's sign, its place
  against the limits), which is decided because no surface passes through the point.
* **Exit time.**  The first crossing after which the count is 0 is when the path
  leaves the workspace; its ball is the certified exit time.
* **Region.**  A path with no crossing lies in one region.  When it lies in a plane
  (a planar robot, or a pose coordinate that is a rational constant), the plane's
  decomposition (:mod:`singcheck.space_analysis`) is computed, a rational point of the
  path is located in a cell exactly, and the cell's region names it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

from flint import acb, arb, fmpq

from singcheck.intervals import fraction_ball, working_precision
from singcheck.path import PathModel
from singcheck.roots import IdenticallyZeroError, isolate_real_roots
from singcheck.trig import uses_t, uses_trig
from singcheck.working_modes import gap_points

_PRECISIONS = (53, 128, 384)


@dataclass(frozen=True)
class Crossing:
    t: arb
    surfaces: tuple[str, ...]


@dataclass(frozen=True)
class Stretch:
    point: arb  # the exact point where the count was taken
    count: int | None


@dataclass
class PathInWorkspace:
    crossings: list[Crossing]
    stretches: list[Stretch]  # one per gap between crossings, in time order
    undecided: list[str] = field(default_factory=list)
    exit_time: arb | None = None
    region: str | None = None  # e.g. "R21 of the workspace plane z = 1"

    @property
    def one_region(self) -> bool | None:
        """True/False when proven; None when some crossing could not be decided."""
        return None if self.undecided else not self.crossings


def path_surfaces(path: PathModel) -> list[tuple[str, object]]:
    """(label, trig polynomial along the path) for every surface of the variety."""
    out = []
    limits = path.projection.model.spec.joint_limits
    for leg in path.legs:
        joint = leg.leg.joint
        if leg.discriminant is not None:
            out.append((f"serial singularity of leg {joint}", leg.discriminant))
        for bound, value in zip(("min", "max"), limits.get(joint, ()), strict=False):
            out.append((f"{joint} = {value} ({bound})", leg.limit_polynomial(value)))
    out.append((XI, path.mu))
    return out


def _inside(v: arb, lo: arb, hi: arb) -> bool | None:
    if v >= lo and v <= hi:
        return True
    if v < lo or v > hi:
        return False
    return None


def _leg_count(leg, t: arb, bounds) -> int | None:
    """Real branches of one leg inside its limits at t (None if not decided)."""
    n = 0
    for value in leg.branches(t).values():
        if value is None:
            return None
        if isinstance(value, acb):
            continue  # a complex branch
        inside = True if bounds is None else _inside(
            value, fraction_ball(bounds[0]), fraction_ball(bounds[1]))
        if inside is None:
            return None
        n += inside
    return n


def ik_count_at(path: PathModel, t: arb) -> int | None:
    """IK solutions inside the limits at the exact time t (None if not decided)."""
    limits = path.projection.model.spec.joint_limits
    for prec in _PRECISIONS:
        with working_precision(prec):
            counts = [_leg_count(leg, t, limits.get(leg.leg.joint)) for leg in path.legs]
        if None not in counts:
            return math.prod(counts)
    return None


XI = "parallel singularity ξ"


def _crossings(path: PathModel, tolerance: float,
               mu_roots: list[arb] | None) -> tuple[list[Crossing], list[str]]:
    interval = path.trajectory.range
    events: list[tuple[arb, str]] = []
    undecided = []
    for label, poly in path_surfaces(path):
        if label == XI and mu_roots is not None:
            events += [(t, label) for t in mu_roots]
            continue
        try:
            iso = isolate_real_roots(poly, interval, tolerance)
        except IdenticallyZeroError:
            undecided.append(f"the path lies on the surface {label}")
            continue
        events += [(r.t, label) for r in iso.roots]
        undecided += [f"{label}: {u.reason}" for u in iso.undecided]
    events.sort(key=lambda e: float(e[0].mid()))
    merged: list[Crossing] = []
    for t, label in events:
        if merged and merged[-1].t.overlaps(t):
            last = merged[-1]
            merged[-1] = Crossing(last.t.union(t), (*last.surfaces, label))
        else:
            merged.append(Crossing(t, (label,)))
    return merged, undecided


def path_in_workspace(path: PathModel, tolerance: float = 1e-9, name_region: bool = True,
                      mu_roots: list[arb] | None = None) -> PathInWorkspace:
    """Where the path crosses the discriminant variety, and its IK count in between.

    ``mu_roots``: the certified roots of μ already isolated by the certification (every
    one of them, none undecided), so that they are not isolated twice.
    """
    crossings, undecided = _crossings(path, tolerance, mu_roots)
    points = gap_points(path.trajectory.range, [c.t for c in crossings])
    stretches = [Stretch(p, ik_count_at(path, p)) for p in points]
    result = PathInWorkspace(crossings, stretches, undecided)
    if not undecided and len(stretches) == len(crossings) + 1:
        for before, crossing, after in zip(stretches, crossings, stretches[1:], strict=False):
            if before.count and after.count == 0:
                result.exit_time = crossing.t
                break
    if name_region and result.one_region:
        result.region = locate_region(path)
    return result


# ---------------------------------------------------------------------------------
# naming the region of a path that stays in one


def _rational_time_points(path: PathModel):
    """Exact times with a rational pose: t = 2·atan(u) for rational u (sin/cos only),
    or rational t (polynomial paths); yields (t ball, {s, c, t} rationals)."""
    polys = path.phi
    trig = any(uses_trig(p) for p in polys)
    if trig and any(uses_t(p) for p in polys):
        return
    candidates = [Fraction(n, d) for d in (2, 3, 5, 7) for n in range(-3 * d, 3 * d + 1)
                  if n % d or d == 2]
    rng = path.trajectory.range
    lo, hi = rng.start.ball(), rng.end.ball()
    for u in candidates:
        if trig:
            s, c = 2 * u / (1 + u * u), (1 - u * u) / (1 + u * u)
            with working_precision(128):
                t = 2 * fraction_ball(u).atan()
            values = {"s": s, "c": c}
        else:
            t, values = fraction_ball(u), {"t": u}
        if t > lo and t < hi:
            yield values


def _plane(path: PathModel) -> tuple[dict[str, Fraction], tuple[int, ...]] | None:
    """The fixed pose coordinates (rational constants of φ) and the free axes' indices,
    when exactly two axes are free."""
    pose = path.projection.model.pose
    fixed, free = {}, []
    for i, (name, p) in enumerate(zip(pose, path.phi, strict=True)):
        if p.is_constant():
            c = p.leading_coefficient() if not p.is_zero() else fmpq(0)
            fixed[name] = Fraction(int(c.p), int(c.q))
        else:
            free.append(i)
    return (fixed, tuple(free)) if len(free) == 2 else None


def locate_region(path: PathModel) -> str | None:
    """The name of the plane region holding the path (None when it cannot be located)."""
    plane = _plane(path)
    if plane is None:
        return None
    fixed, free = plane
    analysis = _plane_analysis(path.projection, fixed)
    if analysis.regions is None:
        return None
    where = "" if not fixed else " " + ", ".join(f"{k} = {v}" for k, v in fixed.items())
    for values in _rational_time_points(path):
        point = [_exact(path.phi[i], values) for i in free]
        cell = _cell_of(analysis.cad, point)
        if cell is not None:
            region = analysis.regions.region_of(cell)
            return f"R{region.number} of the workspace plane{where}"
    return None


_PLANES: dict = {}


def _plane_analysis(projection, fixed: dict[str, Fraction]):
    """The plane's decomposition, computed once per robot and plane in a process (a
    batch of paths in one plane shares it)."""
    from singcheck.space_analysis import WORKSPACE, analyse, workspace_variety

    key = (id(projection), tuple(sorted(fixed.items())))
    if key not in _PLANES:
        _PLANES[key] = (projection, analyse(WORKSPACE, projection.model,
                                            workspace_variety(projection), fixed))
    return _PLANES[key][1]


def _exact(p, values: dict[str, Fraction]) -> Fraction:
    q = p.subs({k: fmpq(v.numerator, v.denominator) for k, v in values.items()})
    c = q.leading_coefficient() if not q.is_zero() else fmpq(0)
    return Fraction(int(c.p), int(c.q))


def _cell_of(cad, point: list[Fraction]):
    """The open cell holding a rational point, or None when it lies on a root."""
    from singcheck.cad import fiber

    index = []
    for k in range(len(point)):
        roots = fiber(cad.levels, cad.variables, tuple(point[:k]))
        q = fmpq(point[k].numerator, point[k].denominator)
        relations = [r.compare(q) for r in roots]
        if 0 in relations:
            return None
        index.append(sum(1 for r in relations if r < 0))
    for cell in cad.cells:
        if cell.index == tuple(index):
            return cell
    return None
