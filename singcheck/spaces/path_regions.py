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
* **On a surface.**  A surface whose polynomial is identically 0 along the path (μ ≡ 0:
  the path lies on ξ = 0) is not crossed: the path lies on it for its whole range (on
  a multi-piece path, for that piece's range), and is then in no open region.
* **Region.**  A path with no crossing lies in one region.  The decomposition of the
  smallest subspace holding it (pose coordinates that are rational constants fixed: a
  line, a plane, or the whole workspace) is computed (:mod:`singcheck.space_analysis`),
  a rational point of the path is located in a cell exactly, and the cell's region
  names it.  In 3-D, ξ is left out of the decomposition (``--surfaces auto``), and the
  name says so: the region is then one of the count-changing surfaces' complement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

from flint import acb, arb

from singcheck.algebra.intervals import fraction_ball, sign, working_precision
from singcheck.algebra.polynomials import constant_value
from singcheck.algebra.radicals import cos_pi, evaluate_path, sin_pi
from singcheck.algebra.trig import uses_t, uses_trig
from singcheck.budget import checkpoint
from singcheck.certify.exact import vanishes_at_root
from singcheck.certify.path import PathModel, compose_pose
from singcheck.certify.working_modes import gap_points
from singcheck.roots.enclosures import IdenticallyZeroError
from singcheck.roots.isolation import isolate_real_roots
from singcheck.roots.rational import to_fmpq, to_fraction
from singcheck.spaces.chart import Chart, chart_axis

_PRECISIONS = (53, 128, 384)


@dataclass(frozen=True)
class Crossing:
    """Where the path meets the variety: ``kind`` is "crosses" when some surface's sign
    is proven to differ on the two sides, "touches" when every surface met there is
    proven to keep its sign (a tangency), None when not decided (or at a range end)."""
    t: arb
    surfaces: tuple[str, ...]
    kind: str | None = None


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
    region_reason: str = ""  # why a path in one region gets no name (when known)
    #: (surface, time range) where the path lies on a surface (its polynomial ≡ 0)
    on_surfaces: list[tuple[str, str]] = field(default_factory=list)

    @property
    def one_region(self) -> bool | None:
        """True/False when proven; None when some crossing could not be decided."""
        return None if self.undecided else not self.crossings and not self.on_surfaces


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
        if isinstance(value, acb) or (isinstance(value, tuple) and isinstance(value[0], acb)):
            continue  # a complex branch
        if bounds is None:
            inside = True
        elif leg.revolute:
            inside = leg.inside(value, bounds)
        else:
            inside = _inside(value, fraction_ball(bounds[0]), fraction_ball(bounds[1]))
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


def _crossings(path: PathModel, surfaces: list[tuple[str, object]], tolerance: float,
               mu_roots: list[arb] | None
               ) -> tuple[list[Crossing], list[str], list[tuple[str, str]]]:
    interval = path.trajectory.range
    events: list[tuple[arb, str]] = []
    undecided, on = [], []
    for label, poly in surfaces:
        checkpoint()
        if label == XI and mu_roots is not None:
            events += [(t, label) for t in mu_roots]
            continue
        try:
            iso = isolate_real_roots(poly, interval, tolerance, vanishes_at_root)
        except IdenticallyZeroError:
            on.append((label, str(interval)))
            continue
        events += [(r.t, label) for r in iso.roots]
        undecided += [f"{label}: {u.reason}" for u in iso.undecided]
    events.sort(key=lambda e: float(e[0].mid()))
    merged: list[Crossing] = []
    for t, label in events:
        checkpoint()
        if merged and merged[-1].t.overlaps(t):
            last = merged[-1]
            merged[-1] = Crossing(last.t.union(t), (*last.surfaces, label))
        else:
            merged.append(Crossing(t, (label,)))
    return merged, undecided, on


def path_in_workspace(path: PathModel, tolerance: float = 1e-9, name_region: bool = True,
                      mu_roots: list[arb] | None = None, region_cache=None,
                      notify=None) -> PathInWorkspace:
    """Where the path crosses the discriminant variety, and its IK count in between.

    ``mu_roots``: the certified roots of μ already isolated by the certification (every
    one of them, none undecided), so that they are not isolated twice.  ``region_cache``:
    where region maps are kept between runs (None: computed in this process only);
    ``notify(message)`` is told before a decomposition is computed (it takes seconds).
    """
    surfaces = path_surfaces(path)
    crossings, undecided, on = _crossings(path, surfaces, tolerance, mu_roots)
    points = gap_points(path.trajectory.range, [c.t for c in crossings])
    stretches = [Stretch(p, ik_count_at(path, p)) for p in points]
    crossings = _crossing_kinds(dict(surfaces), crossings, stretches)
    result = PathInWorkspace(crossings, stretches, undecided, on_surfaces=on)
    result.exit_time = _exit_time(result)
    if name_region and result.one_region:
        _name_region(result, path, region_cache, notify)
    return result


def _crossing_kinds(polys: dict[str, object], crossings: list[Crossing],
                    stretches: list[Stretch]) -> list[Crossing]:
    """Each crossing with its kind, from the signs of its surfaces (``polys``: label ->
    polynomial along the path) at the exact points of the stretches on either side (ball
    signs; a sign not proven leaves it None).  Only a crossing with a stretch on both
    sides and each surface met once is judged."""
    timeline = sorted([*crossings, *stretches], key=lambda x: float(
        (x.t if isinstance(x, Crossing) else x.point).mid()))
    out = []
    for j, item in enumerate(timeline):
        if not isinstance(item, Crossing):
            continue
        kind = None
        if 0 < j < len(timeline) - 1 and isinstance(timeline[j - 1], Stretch) and \
                isinstance(timeline[j + 1], Stretch) and \
                len(set(item.surfaces)) == len(item.surfaces):
            kind = _kind(polys, item.surfaces, timeline[j - 1].point, timeline[j + 1].point)
        out.append(Crossing(item.t, item.surfaces, kind))
    return out


def _kind(polys: dict, surfaces: tuple[str, ...], left: arb, right: arb) -> str | None:
    kept = []  # per surface: its sign proven the same on both sides
    for label in surfaces:
        checkpoint()
        before = sign(evaluate_path(polys[label], left))
        after = sign(evaluate_path(polys[label], right))
        if before is not None and after is not None and before != after:
            return "crosses"
        kept.append(before is not None and before == after)
    return "touches" if all(kept) else None


def _name_region(result: PathInWorkspace, path: PathModel, cache, notify) -> None:
    """Set the region of a path crossing none of its surfaces, or the reason it has none."""
    reason = region_refusal(path)
    if reason:
        result.region_reason = reason
        return
    from singcheck.spaces.analysis import CostlyDecomposition

    try:
        result.region = locate_region(path, cache, notify)
    except CostlyDecomposition as e:
        result.region_reason = f"no region named: {e.message}"


def region_refusal(path: PathModel) -> str:
    """Why a path crossing none of its own surfaces gets no region name ("" if none):
    a pose of more axes than a decomposition takes, an angle reaching π (the chart's
    cut), or a conjugate surface crossed."""
    from singcheck.spaces.analysis import MAX_AXES

    pose = path.projection.model.pose
    if len(pose) > MAX_AXES:
        return (f"the workspace has {len(pose)} axes ({', '.join(pose)}): too many variables "
                f"for a cylindrical decomposition (at most {MAX_AXES}); no region named")
    return outside_chart(path, path.trajectory.range) or conjugate_crossing(path)


def _exit_time(w: PathInWorkspace) -> arb | None:
    """The crossing after which no IK solution is left, when every count is known."""
    if not w.undecided and len(w.stretches) == len(w.crossings) + 1:
        for before, crossing, after in zip(w.stretches, w.crossings, w.stretches[1:],
                                           strict=False):
            if before.count and after.count == 0:
                return crossing.t
    return None


def pieces_in_workspace(report, tolerance: float = 1e-9, region_cache=None,
                        notify=None) -> PathInWorkspace:
    """:func:`path_in_workspace` for a path of several pieces (or a rescaled one), in the
    user's parameter.  Each piece is placed on its own closed range; then, at each join,
    a stretch ending one piece and a stretch starting the next are one stretch (the path
    between their points crosses nothing), and a crossing ending one piece and one
    starting the next are one crossing when every surface of both vanishes exactly at the
    join (:func:`_vanishes_at_join`).  The region is named, for a
    path crossing nothing, in the smallest subspace holding the first piece when every
    piece lies in that same subspace."""
    spec = report.trajectory
    items: list = []  # crossings and stretches in time order, in the user's parameter
    undecided: list[str] = []
    on: list[tuple[str, str]] = []
    for i, (piece, r) in enumerate(zip(spec.pieces, report.pieces, strict=True)):
        mu_roots = [c.t for c in r.candidates] if r.mu_roots_complete else None
        w = path_in_workspace(r.path, tolerance, False, mu_roots)
        undecided += [f"segment {i + 1}: {u}" for u in w.undecided]
        on += [(surface, f"{piece.global_range} (segment {i + 1})")
               for surface, _ in w.on_surfaces]
        own = sorted([*w.crossings, *w.stretches],
                     key=lambda x: float((x.t if isinstance(x, Crossing) else x.point).mid()))
        own = [Crossing(piece.to_global(x.t), x.surfaces, x.kind) if isinstance(x, Crossing)
               else Stretch(piece.to_global(x.point), x.count) for x in own]
        if items and own:
            at = piece.global_range.start
            last, first = items[-1], own[0]
            if isinstance(last, Stretch) and isinstance(first, Stretch):
                own = own[1:]  # one stretch across the join
            elif isinstance(last, Crossing) and isinstance(first, Crossing):
                surfaces = dict(path_surfaces(r.path))
                if set(last.surfaces) == set(first.surfaces) and all(
                        _vanishes_at_join(surfaces[s], piece.local_time(at))
                        for s in first.surfaces):
                    own = own[1:]  # the same crossing, exactly at the join
        items += own
    crossings = [x for x in items if isinstance(x, Crossing)]
    stretches = [x for x in items if isinstance(x, Stretch)]
    result = PathInWorkspace(crossings, stretches, undecided, on_surfaces=on)
    result.exit_time = _exit_time(result)
    if result.one_region:
        model = report.path.projection.model
        subspaces = {tuple(_subspace(model, p)[0].items()) for p in spec.pieces}
        if len(subspaces) == 1:
            reasons = [region_refusal(r.path) for r in report.pieces]
            if any(reasons):
                result.region_reason = next(r for r in reasons if r)
            else:
                _name_region(result, report.pieces[0].path, region_cache, notify)
    return result


def _vanishes_at_join(p, at) -> bool:
    """Proven: the surface ``p`` (in the piece's path ring) vanishes at its local time
    ``at``.  A polynomial in t, sin t, cos t alone is decided by
    :func:`~singcheck.algebra.trig_values.sum_is_zero`; one with a pose angle's cos and
    sin (a 3-RPR path whose phi is a polynomial in t) only at ``at`` = 0, where an angle
    g(0) + qπ with 2q an integer is exact (else it must vanish whatever the angle's value).
    False when not proven: the two crossings then stay two."""
    from singcheck.algebra.trig import TRIG
    from singcheck.algebra.trig_values import sum_is_zero
    from singcheck.roots.branch_bound import vanishes_at_multiple_of_pi

    terms = p.to_dict()
    if p.context() is not TRIG and not any(any(e[3:]) for e in terms):
        p = TRIG.from_dict({e[:3]: c for e, c in terms.items()})  # free of the others
    if p.context() is TRIG:
        return sum_is_zero([(p, at)]) is True
    return at.rational == 0 and at.pi_coefficient == 0 and vanishes_at_multiple_of_pi(p, 0)


# ---------------------------------------------------------------------------------
# naming the region of a path that stays in one


def outside_chart(path: PathModel, interval) -> str:
    """Why the path leaves the half-angle chart of a pose angle φ (it reaches φ = π, where
    the decomposition is cut, or may: 1 + cos φ(t) has a root or an undecided box on the
    range), or "" when 1 + cos φ(t) is proven non-zero all along (and the chart's regions
    can name the path's)."""
    model = path.projection.model
    index = _coordinate_index(model)
    for v in model.pose:
        if v not in model.angles:
            continue
        one_plus_cos = path.coordinates[index[v][0]] + 1
        why = (f"the angle {v} reaches π (mod 2π) on the path, where the decomposition in "
               f"tan({v}/2) is cut: no region named")
        try:
            iso = isolate_real_roots(one_plus_cos, interval, 1e-9, vanishes_at_root)
        except IdenticallyZeroError:
            return why
        if iso.roots:
            return why.replace("on the path", f"at t ≈ {float(iso.roots[0].t.mid()):.6g}")
        if iso.undecided:
            return why.replace("reaches", "may reach")
    return ""


def conjugate_crossing(path: PathModel) -> str:
    """For a robot with square roots (parameters, or an angle joint's limits such as
    cos(3π/4) = -√2/2): the decomposition's surfaces are norms, the robot's and its
    conjugates' (√p ↦ -√p) together.  A path crossing none of the robot's own surfaces may
    still cross a conjugate one: then it is not in one region of the decomposition.
    Returns why ("" when no normed serial or limit surface meets the path; ξ is normed
    already, and its crossings are μ's)."""
    projection = path.projection
    model = projection.model
    if model.polynomial:
        return ""
    surfaces = [(f"the serial singularity of leg {leg.joint}", p)
                for leg, p in zip(model.legs, projection.workspace_boundary, strict=True)]
    surfaces += [(f"the limit {s.joint} = {s.value}", s.polynomial)
                 for s in projection.joint_limit_surfaces]
    for label, p in surfaces:
        if p.is_constant():
            continue
        checkpoint()
        along = compose_pose(p, path.coordinates, model.pose_variables)
        try:
            iso = isolate_real_roots(along, path.trajectory.range, 1e-9)
        except IdenticallyZeroError:
            return f"the path lies on a conjugate of {label} (a square root's other sign)"
        if iso.roots or iso.undecided:
            return (f"the path meets a conjugate of {label} (a square root's other sign), "
                    "which cuts the decomposition (it is normed over the square roots): "
                    "no region named")
    return ""


def _coordinate_index(model) -> dict[str, tuple[int, ...]]:
    """Each pose variable's place among the model's pose variables (cos, sin of an angle)."""
    out, i = {}, 0
    for v in model.pose:
        n = 2 if v in model.angles else 1
        out[v] = tuple(range(i, i + n))
        i += n
    return out


def _rational_time_points(path: PathModel, polys):
    """Exact times at which ``polys`` (the path's coordinates) are rational: t = 2·atan(u)
    for rational u (sin/cos only), or rational t (polynomial paths); yields the
    {s, c} or {t} rationals."""
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


def _fixed_value(p, offset) -> Fraction | None:
    """The chart coordinate of a pose coordinate that is constant along the path, when
    rational: the constant itself, or tan(φ/2) = sin φ/(1 + cos φ) for an angle
    (``offset`` its multiple of π; φ = 0, ±π/2 give 0, ±1); None otherwise."""
    if not p.is_constant():
        return None
    value = to_fraction(constant_value(p))
    if offset is None:
        return value
    if value != 0:
        return None  # tan of a non-zero rational half-angle is transcendental
    c, s = cos_pi(offset), sin_pi(offset)
    if c is None or not c.is_rational() or not s.is_rational() or c.rational_value() == -1:
        return None
    return s.rational_value() / (1 + c.rational_value())


def _subspace(model, spec) -> tuple[dict[str, Fraction], tuple[int, ...]]:
    """The fixed axes of the chart (pose coordinates constant along the trajectory
    ``spec``, with a rational chart value) and the free axes' indices."""
    chart = Chart.of(model.pose, model.angles)
    fixed, free = {}, []
    offsets = spec.angle_offsets
    for i, (name, axis) in enumerate(zip(model.pose, chart.axes, strict=True)):
        offset = offsets.get(name, Fraction(0)) if name in chart.angles else None
        value = _fixed_value(spec.pose[name], offset)
        if value is None:
            free.append(i)
        else:
            fixed[axis] = value
    return fixed, tuple(free)


def prepare_region_maps(projection, specs, cache=None, notify=None) -> None:
    """Compute, in this process, the region map of every subspace that several of the
    trajectories lie in (forked workers then inherit it instead of each computing it)."""
    from collections import Counter

    from singcheck.spaces.analysis import MAX_AXES, CostlyDecomposition

    model = projection.model
    if len(model.pose) > MAX_AXES:
        return
    shared = Counter()
    for spec in specs:
        fixed, free = _subspace(model, spec)
        shared[tuple(fixed.items()), len(free)] += 1
    for (fixed, free), n in shared.items():
        if n > 1 and free:
            try:
                _region_map(projection, dict(fixed), free, cache, notify)
            except CostlyDecomposition:
                continue  # each path then says why it has no region name


def locate_region(path: PathModel, cache=None, notify=None) -> str | None:
    """The name of the region holding the path, in the smallest space that holds it
    (a line, a plane or the whole workspace: φ's constant coordinates are fixed); None
    when no rational point of the path could be located in an open cell.  ``cache``: a
    :class:`~singcheck.region_map.RegionMapCache`, or None to compute without storing.

    With angles in the pose the space is the chart tan(φ/2) (:mod:`singcheck.spaces.chart`):
    the caller has proven that the path stays off φ = π (:func:`outside_chart`)."""
    model = path.projection.model
    fixed, free = _subspace(model, path.trajectory)
    if not free:
        return None
    regions, left_out = _region_map(path.projection, fixed, len(free), cache, notify)
    where = "" if not fixed else " " + ", ".join(f"{k} = {v}" for k, v in fixed.items())
    kind = {1: "line", 2: "plane"}.get(len(free), "")
    space = f"the workspace {kind}{where}".replace("  ", " ").rstrip()
    if left_out:
        space += " cut by its serial-singularity and joint-limit surfaces only"
    angles = [v for v in model.pose if v in model.angles]
    if angles:
        space += (" (in the chart " + ", ".join(chart_axis(v) for v in angles) + ": cut along "
                  + ", ".join(f"{v} = π" for v in angles) + ")")
    index = _coordinate_index(model)
    needed = [path.coordinates[k] for i in free for k in index[model.pose[i]]]
    points = (point for values in _rational_time_points(path, needed)
              for point in [_chart_point(path, free, index, values)] if point is not None)
    for point in (*points, *_rational_points_near(path, free, index, regions.factors)):
        number = regions.region_at(point)
        if number is not None:
            return f"R{number} of {space}"
    return None


def _chart_point(path: PathModel, free, index, values) -> list[Fraction] | None:
    """The free chart coordinates of the path at exact time values, when rational."""
    model = path.projection.model
    out = []
    for i in free:
        coords = [_exact(path.coordinates[k], values) for k in index[model.pose[i]]]
        if None in coords:
            return None
        if len(coords) == 2:  # an angle: tan(φ/2) = sin φ / (1 + cos φ)
            c, s = coords
            if c == -1:
                return None
            coords = [s / (1 + c)]
        out += coords
    return out


def _rational_points_near(path: PathModel, free: tuple[int, ...], index, factors):
    """Rational points in the same component as a point of the path, for paths whose
    rational times give irrational poses (t mixed with sin t, cos t).

    At a rational time t₀ the pose is enclosed in a box of balls (an angle's chart
    coordinate as sin φ/(1 + cos φ)); when every factor of the decomposition excludes 0 on
    the whole box (ball arithmetic), the box is a connected set avoiding the variety, so
    its rational centre lies in the path's component.
    """
    from singcheck.algebra.intervals import evaluate
    from singcheck.roots.rational import arb_to_fmpq

    model = path.projection.model
    rng = path.trajectory.range
    lo, hi = rng.start.ball(), rng.end.ball()
    for k in range(1, 8):
        t = lo + (hi - lo) * k / 8
        with working_precision(128):
            t0 = t.mid()
            coordinates = path.pose_variables_at(t0)
            box = []
            for i in free:
                balls = [coordinates[j] for j in index[model.pose[i]]]
                if len(balls) == 2:
                    if not balls[0] > -1:
                        break
                    balls = [balls[1] / (1 + balls[0])]
                box += balls
            else:
                if all(evaluate(f, box).contains(0) is False for f in factors):
                    yield [to_fraction(arb_to_fmpq(b.mid())) for b in box]


_SUBSPACES: dict = {}


def _region_map(projection, fixed: dict[str, Fraction], free_axes: int, cache,
                notify=None):
    """The region map of the subspace where ``fixed`` holds and the surfaces left out
    (``--surfaces auto``): from this process's memo, else the disk cache, else computed
    (then stored).  A batch of paths in one plane shares it."""
    from singcheck.spaces.analysis import (
        WORKSPACE,
        analyse,
        decomposition,
        select_surfaces,
        space_chart,
        workspace_variety,
    )
    from singcheck.spaces.region_map import RegionMap

    memo_key = (id(projection), tuple(sorted(fixed.items())))
    if memo_key not in _SUBSPACES:
        components, left_out = select_surfaces(workspace_variety(projection), WORKSPACE,
                                               "auto", free_axes)
        if not projection.expanded:
            left_out = [*left_out, "ξ(X) (not expanded)"]
        key = cache.key([c.polynomial for c in components], fixed) if cache else None
        regions = cache.load(key) if cache else None
        if regions is not None:  # checked against the inputs, not only by its HMAC
            axes = space_chart(projection.model, WORKSPACE).axes
            _, _, cad = decomposition(axes, components, fixed)
            problem = regions.verify(cad)
            if problem:
                if notify:
                    notify(f"the cached region map failed its check ({problem}): "
                           "recomputed")
                regions = None
        if regions is None:
            if notify:
                where = ", ".join(f"{k} = {v}" for k, v in fixed.items())
                where = f"{where}; {free_axes}-D" if where else f"in {free_axes}-D"
                notify(f"decomposing the workspace ({where}) into regions, once"
                       + (" (then kept in the cache)" if cache else ""))
            regions = RegionMap.of(analyse(WORKSPACE, projection.model, components, fixed))
            if cache:
                cache.store(key, regions)
        _SUBSPACES[memo_key] = (projection, regions, left_out)
    return _SUBSPACES[memo_key][1:]


def _exact(p, values: dict[str, Fraction]) -> Fraction | None:
    """``p`` at exact values of t or s, c; None when it is not rational there (square
    roots or angle functions left)."""
    q = p.subs({k: to_fmpq(v) for k, v in values.items()})
    return to_fraction(constant_value(q)) if q.is_constant() else None
