"""Workspace and joint-space analysis: where the kinematics has how many real solutions.

The paper's second half, exactly:

1. **Discriminant variety** of the space studied, as a list of named surfaces:
   in the workspace, the serial singularities (each quadratic leg's discriminant: two
   IK branches meet), the parallel singularity surface ξ(X) and the joint limits
   projected (the leg polynomial with its joint at a limit); in the joint space, the
   serial singularities projected (the pose eliminated from {F, ∂f_i/∂ρ_i}), ε(ρ) and
   the limit planes ρ_i = bound.  The number of inverse-kinematic solutions inside the
   limits (workspace) changes only across the serial and limit surfaces; the number of
   direct-kinematic solutions (joint space) only across ε and the limits (the legs'
   leading coefficients are constant, so no solution escapes to infinity).
2. **Generic CAD** of its complement (:mod:`singcheck.cad`), in all the space's axes or
   in a slice where some axes are fixed to exact rationals: open cells with rational
   sample points.
3. **Counts**, exactly, at each sample point (:mod:`singcheck.solution_counts`): since a
   count is constant on a connected set avoiding the variety, it holds on the whole cell.
4. **Regions** (plane decompositions): cells joined by exact free segments
   (:mod:`singcheck.regions`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from fractions import Fraction

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import restrict, squarefree_part
from singcheck.budget import checkpoint
from singcheck.elimination.projection import (
    RobotProjection,
    joint_space_singularities,
    pose_elimination_request,
)
from singcheck.elimination.requests import EliminationRequest
from singcheck.errors import SingcheckError, UnsupportedRobotError
from singcheck.model.robot import REVOLUTE, RobotModel
from singcheck.spaces.cad import Cell, OpenCAD, open_cad
from singcheck.spaces.chart import Chart
from singcheck.spaces.regions import Region, Regions, connect_regions, factor_signs
from singcheck.spaces.solution_counts import (
    MAX_DIRECT_BEZOUT,
    direct_bezout_bound,
    direct_kinematics_count,
    direct_unknowns,
    ik_count,
    ik_root_placement,
)

WORKSPACE, JOINTSPACE = "workspace", "jointspace"
SERIAL, PARALLEL, LIMIT = "serial singularity", "parallel singularity", "joint limit"


class SliceError(SingcheckError):
    """A slice that cannot be studied (unknown axis, or lying inside a surface)."""


@dataclass(frozen=True)
class VarietyComponent:
    kind: str  # SERIAL | PARALLEL | LIMIT
    label: str  # what it is, e.g. "leg rho1: its two branches meet", "rho1 = 0"
    polynomial: fmpq_mpoly  # in the studied axes


@dataclass(frozen=True)
class CellCount:
    cell: Cell
    count: int | None  # real solutions (within the limits, for the workspace)
    reason: str  # why count is None
    within_limits: bool  # joint space: the sample is inside the joint-limit box
    region: int | None = None


@dataclass
class SpaceAnalysis:
    space: str  # WORKSPACE | JOINTSPACE
    robot: str
    axes: tuple[str, ...]  # the axes decomposed (free)
    fixed: dict[str, Fraction]  # the slice: axes set to exact values
    components: list[VarietyComponent]
    cad: OpenCAD
    cells: list[CellCount]
    regions: Regions | None
    timings: dict[str, float] = field(default_factory=dict)

    @property
    def counted(self) -> str:
        return ("inverse-kinematic solutions within the joint limits" if self.space == WORKSPACE
                else "direct-kinematic solutions")

    def region_count(self, number: int) -> int | None:
        counts = {c.count for c in self.cells if c.region == number}
        return counts.pop() if len(counts) == 1 else None


# ---------------------------------------------------------------------------------
# the discriminant varieties


#: The most axes a decomposition takes: a 6-D pose (Gough–Stewart) is refused.
MAX_AXES = 3


def space_chart(model: RobotModel, space: str) -> Chart:
    """The axes of the space: the pose or the joints, each angle v as tan(v/2)."""
    return Chart.of(model.pose if space == WORKSPACE else model.joints, model.angles)


def check_free_axes(model: RobotModel, space: str, fixed=()) -> None:
    """Refuse up front a decomposition of more than :data:`MAX_AXES` free axes (those
    left once the ``fixed`` axes are sliced): a 6-D pose needs three slices."""
    names = model.pose if space == WORKSPACE else model.joints
    free = [n for n in names if n not in fixed]
    if len(free) > MAX_AXES:
        raise UnsupportedRobotError(
            f"the {space} of {model.name} has {len(free)} free axes ({', '.join(free)}): "
            f"too many variables for a cylindrical decomposition (at most {MAX_AXES}); "
            "fix some with --slice; `singcheck run` still certifies its paths",
            path=model.spec.path)


def workspace_variety(projection: RobotProjection,
                      parallel: bool = True) -> list[VarietyComponent]:
    """Serial singularities, ξ (unless ``parallel`` is False) and joint limits in X (in
    the chart: an angle φ of the pose as tan(φ/2), :mod:`singcheck.spaces.chart`)."""
    model = projection.model
    refuse_transcendental_limits(model)
    chart = space_chart(model, WORKSPACE)
    out = []
    for leg, disc in zip(model.legs, projection.workspace_boundary, strict=True):
        if not disc.is_constant():
            out.append(VarietyComponent(SERIAL, f"leg {leg.joint}: its two branches meet",
                                        chart.polynomial(disc)))
    if parallel and projection.expanded:  # a ξ too big to expand is left out
        out.append(VarietyComponent(PARALLEL, "ξ(X): some working mode is singular",
                                    chart.polynomial(projection.singularity_surface)))
    for s in projection.joint_limit_surfaces:
        out.append(VarietyComponent(LIMIT, f"{s.joint} = {s.value} ({s.bound})",
                                    chart.polynomial(s.polynomial)))
    return out


def refuse_transcendental_limits(model: RobotModel) -> None:
    """Regions need the joint-limit surfaces as polynomials: an angle limit whose cos
    and sin are not algebraic (not a multiple of π/12) is refused with the reason (the
    trajectory check takes it, by ball arithmetic)."""
    from singcheck.elimination.projection import algebraic_limit, angle_limit_values

    for leg in model.legs:
        for value in model.spec.joint_limits.get(leg.joint, ()):
            if leg.kind != REVOLUTE and not algebraic_limit(leg, value):
                raise UnsupportedRobotError(
                    f"the limit {value} of joint {leg.joint} is not rational: regions need "
                    "algebraic limit surfaces (`singcheck run` takes it)",
                    path=model.spec.path, line=model.spec.lines.get("joint_limits"),
                    key=f"joint_limits.{leg.joint}")
            if leg.kind == REVOLUTE and not algebraic_limit(leg, value):
                try:
                    angle_limit_values(leg.joint, value)
                except UnsupportedRobotError as e:
                    raise UnsupportedRobotError(
                        f"{e.message} (needed for regions; `singcheck run` takes it)",
                        path=model.spec.path, line=model.spec.lines.get("joint_limits"),
                        key=f"joint_limits.{leg.joint}") from None


def serial_singularities_request(model: RobotModel, leg) -> EliminationRequest:
    """Eliminate the pose from ``{F, ∂f_leg/∂ρ_leg}``: where that leg is serially singular
    (for an angle joint the derivative along its circle, B's entry)."""
    derivative = model.B[leg.constraint_index][model.joints.index(leg.joint)]
    return pose_elimination_request(model, "joint_space_serial_singularities", derivative)


def refuse_jointspace(model: RobotModel) -> None:
    """Refuse in one line, before any elimination, a joint space whose direct-kinematics
    counts are out of reach: a system whose Bézout bound passes
    :data:`~singcheck.spaces.solution_counts.MAX_DIRECT_BEZOUT` (the Gough–Stewart)."""
    bound = direct_bezout_bound(model)
    if bound > MAX_DIRECT_BEZOUT:
        raise UnsupportedRobotError(
            f"the joint space of {model.name} is not decomposed: its direct kinematics in "
            f"{len(direct_unknowns(model))} unknowns has Bézout bound {bound} (over "
            f"{MAX_DIRECT_BEZOUT}), too large to count its solutions exactly; `singcheck "
            "workspace` and `singcheck run` are supported", path=model.spec.path)


def _limit_plane(model: RobotModel, chart: Chart, joint: str, value) -> fmpq_mpoly | None:
    """The limit ``joint = value`` in the chart: ρ - value, or for an angle joint
    w·(1 + cos L) - sin L (w = tan(θ/2)), normed over its square roots; None at L = ±π
    (the chart's cut: no bound in the chart)."""
    from singcheck.algebra.radicals import norm_radicals, radical_name, surd_polynomial
    from singcheck.elimination.projection import angle_limit_values

    axis = chart.axes[chart.names.index(joint)]
    if joint not in model.angles:
        gen = dict(zip(chart.axes, chart.context.gens(), strict=True))[axis]
        return gen - fmpq(value.numerator, value.denominator)
    try:
        cos_l, sin_l = angle_limit_values(joint, value)
    except UnsupportedRobotError as e:
        raise UnsupportedRobotError(e.message, path=model.spec.path,
                                    line=model.spec.lines.get("joint_limits"),
                                    key=f"joint_limits.{joint}") from None
    if (1 + cos_l).is_rational() and (1 + cos_l).rational_value() == 0:
        return None
    roots = tuple(radical_name(p) for p in sorted(cos_l.primes() | sin_l.primes()))
    ctx = fmpq_mpoly_ctx.get((axis, *roots), "lex")
    w = ctx.gens()[0]
    plane = norm_radicals(w * surd_polynomial(1 + cos_l, ctx) - surd_polynomial(sin_l, ctx))
    return chart.polynomial(plane)


def jointspace_variety(model: RobotModel, backend,
                       parallel: bool = True) -> list[VarietyComponent]:
    """Serial singularities projected, ε (unless ``parallel`` is False), limit planes (in
    the chart: an angle joint θ as tan(θ/2))."""
    from singcheck.algebra.radicals import reduce_relations

    refuse_jointspace(model)
    refuse_transcendental_limits(model)
    chart = space_chart(model, JOINTSPACE)
    out = []
    for leg in model.legs:
        if leg.degree < 2:
            continue
        result = backend.eliminate(serial_singularities_request(model, leg))
        polys = [p for p in result.polynomials if not p.is_zero()]
        g = polys[0] if polys else None
        for p in polys[1:]:
            g = g.gcd(p)
        if g is not None and not g.is_constant():
            g = chart.polynomial(reduce_relations(g))
            if not g.is_constant():
                out.append(VarietyComponent(SERIAL, f"leg {leg.joint}: two branches meet",
                                            squarefree_part(g)))
    if parallel:
        eps = chart.polynomial(reduce_relations(joint_space_singularities(model, backend)))
        out.append(VarietyComponent(PARALLEL, "ε(ρ): a parallel singularity",
                                    squarefree_part(eps)))
    for joint, (lo, hi) in model.spec.joint_limits.items():
        for bound, value in (("min", lo), ("max", hi)):
            plane = _limit_plane(model, chart, joint, value)
            if plane is not None:
                out.append(VarietyComponent(LIMIT, f"{joint} = {value} ({bound})", plane))
    return out


def fix_axes(components: list[VarietyComponent], axes: tuple[str, ...],
             fixed: dict[str, Fraction]) -> tuple[tuple[str, ...], list[VarietyComponent]]:
    """The components restricted to the slice where ``fixed`` axes take exact values.

    A surface the slice misses (a non-zero constant) is dropped; a slice lying inside a
    surface is refused, since no open cell of the slice would avoid it.
    """
    for name in fixed:
        if name not in axes:
            raise SliceError(f"--slice {name}=…: {name} is not one of the axes "
                             f"({', '.join(axes)})")
    free = tuple(a for a in axes if a not in fixed)
    if not free:
        raise SliceError("the slice fixes every axis; leave at least one free")
    ctx = fmpq_mpoly_ctx.get(free, "lex")
    values = {a: fmpq(v.numerator, v.denominator) for a, v in fixed.items()}
    out = []
    for c in components:
        p = c.polynomial.subs(values) if values else c.polynomial
        if p.is_zero():
            raise SliceError(f"the slice {_slice_text(fixed)} lies inside the surface "
                             f"{c.label}; choose another value")
        if p.is_constant():
            continue
        out.append(VarietyComponent(c.kind, c.label, restrict(p, ctx)))
    return free, out


COUNT_CHANGING = {WORKSPACE: (SERIAL, LIMIT), JOINTSPACE: (PARALLEL, LIMIT)}


def select_surfaces(components: list[VarietyComponent], space: str, surfaces: str,
                    free_axes: int) -> tuple[list[VarietyComponent], list[str]]:
    """The components to decompose by, and the labels of those left out.

    ``all`` keeps the whole discriminant variety; ``counts`` only the surfaces across
    which the count can change (workspace: serial singularities and limits; joint space:
    ε and limits); ``auto`` is ``all`` in a plane or a line and ``counts`` in 3-D and up,
    where the generic CAD with the parallel singularity surface has tens of thousands of
    cells (the Orthoglide: 30108, and minutes to join them into regions).
    """
    if surfaces == "auto":
        surfaces = "all" if free_axes <= 2 else "counts"
    if surfaces == "all":
        return list(components), []
    keep = [c for c in components if c.kind in COUNT_CHANGING[space]]
    return keep, [c.label for c in components if c.kind not in COUNT_CHANGING[space]]


def _slice_text(fixed: dict[str, Fraction]) -> str:
    return ", ".join(f"{a} = {v}" for a, v in fixed.items())


# ---------------------------------------------------------------------------------
# the analysis


def _point(axes: tuple[str, ...], free: tuple[str, ...], sample, fixed) -> list[Fraction]:
    values = dict(zip(free, sample, strict=True)) | dict(fixed)
    return [values[a] for a in axes]


def _within(model: RobotModel, joints) -> bool:
    """The joint vector (the model's joint variables: cos θ, sin θ of an angle joint,
    rational) is strictly inside the limits; an angle's side is decided by ball
    arithmetic (:func:`~singcheck.certify.path.inside_limits`), which ends off the limit
    planes (a cell's sample)."""
    from singcheck.algebra.intervals import fraction_ball, working_precision
    from singcheck.certify.path import inside_limits

    limits = model.spec.joint_limits
    values = iter(joints)
    for leg in model.legs:
        if leg.joint not in model.angles:
            q = next(values)
            if leg.joint in limits and not limits[leg.joint][0] < q < limits[leg.joint][1]:
                return False
            continue
        c, s = next(values), next(values)
        if leg.joint not in limits:
            continue
        for prec in (64, 256, 1024):
            with working_precision(prec):
                inside = inside_limits(leg, (fraction_ball(c), fraction_ball(s)),
                                       limits[leg.joint])
            if inside is not None:
                break
        if not inside:
            return False
    return True


#: For robots with angles or square roots (normed, charted surfaces of higher degree): the
#: most a decomposition's last projection degree may reach by the bound d^(2^(n-1))
#: (n free axes, d the surfaces' largest total degree).  The 3-RPR's 3-D workspace
#: (d = 4: 256) is decomposed, in tens of seconds.  The rotary Delta's (d = 8: 4096) is
#: refused: its projection proved cheap (1.2 s: 935 factors in x of degree ≤ 32), but
#: their 3331 real roots give about 40,000 cells in the plane (x, y) alone (measured on
#: 20 of the 3332 sectors), more than the Orthoglide's whole 3-D CAD with ξ (30108).
MAX_PROJECTION_DEGREE = 256


class CostlyDecomposition(UnsupportedRobotError):
    """A decomposition refused up front: its projection would be too large."""


def refuse_costly(components: list[VarietyComponent], axes: tuple[str, ...],
                  fixed: dict[str, Fraction], path=None) -> None:
    """Refuse, before any resultant, a decomposition whose projection degree could pass
    :data:`MAX_PROJECTION_DEGREE` (a bound from the degrees alone, in microseconds); the
    line names the slice to ask for instead (the last free axis: a plane of the others).
    """
    free, sliced = fix_axes(components, axes, fixed)
    d = max((c.polynomial.total_degree() for c in sliced), default=0)
    bound = d ** (2 ** (len(free) - 1)) if d else 0
    if bound > MAX_PROJECTION_DEGREE:
        raise CostlyDecomposition(
            f"decomposing {len(free)} axes ({', '.join(free)}) with surfaces of degree up to "
            f"{d} could reach projection degree {bound} (over {MAX_PROJECTION_DEGREE}): too "
            f"costly; fix an axis with --slice, e.g. --slice {free[-1]}=VALUE for the plane "
            f"of {', '.join(free[:-1])} at that {free[-1]}", path=path)


def decomposition(axes: tuple[str, ...], components: list[VarietyComponent],
                  fixed: dict[str, Fraction]) -> tuple[tuple[str, ...],
                                                       list[VarietyComponent], OpenCAD]:
    """The free axes, the components restricted to the slice, and the open CAD of their
    complement (cells with rational samples; no regions joined yet: the cheap part)."""
    free, sliced = fix_axes(components, axes, fixed)
    cad = open_cad([c.polynomial for c in sliced]) if sliced else _trivial_cad(free)
    return free, sliced, cad


def analyse(space: str, model: RobotModel, components: list[VarietyComponent],
            fixed: dict[str, Fraction] | None = None, use_limits: bool = True) -> SpaceAnalysis:
    """Decompose the complement of the variety and count solutions in every cell.

    With ``use_limits`` False the joint limits are ignored (and their surfaces must not
    be among ``components``): every real solution counts.
    """
    fixed = dict(fixed or {})
    check_free_axes(model, space, fixed)
    chart = space_chart(model, space)
    axes = chart.axes
    if not model.polynomial:
        refuse_costly(components, axes, fixed, model.spec.path)
    timings = {}
    start = time.perf_counter()
    free, sliced, cad = decomposition(axes, components, fixed)
    timings["decomposition_s"] = time.perf_counter() - start
    start = time.perf_counter()
    cells = []
    invariants = {}  # cell index -> what is constant on a component (for proofs)
    for cell in cad.cells:  # up to tens of thousands in 3-D
        checkpoint()
        point = chart.values(_point(axes, free, cell.sample, fixed))
        if space == WORKSPACE:
            placement = ik_root_placement(model, point, use_limits)
            cells.append(CellCount(cell, ik_count(placement), "", True))
            invariants[cell.index] = placement
        else:
            dk = direct_kinematics_count(model, point)
            cells.append(CellCount(cell, dk.count, dk.reason,
                                   not use_limits or _within(model, point)))
            if dk.count is not None:
                invariants[cell.index] = (dk.count, cells[-1].within_limits)
    timings["counting_s"] = time.perf_counter() - start
    start = time.perf_counter()
    regions = _regions(cad, invariants)
    timings["regions_s"] = time.perf_counter() - start
    if regions is not None:
        number = {c.index: r.number for r in regions.regions for c in r.cells}
        cells = [CellCount(c.cell, c.count, c.reason, c.within_limits,
                           number[c.cell.index]) for c in cells]
    return SpaceAnalysis(space, model.name, free, fixed, sliced, cad, cells, regions, timings)


def _regions(cad: OpenCAD, counts: dict) -> Regions:
    """Connected regions: every cell of a line, else cells joined by free segments
    (``counts``, constant on each component, help prove regions distinct)."""
    if len(cad.variables) == 1 or not cad.factors:
        return Regions(tuple(Region(i + 1, (c,), factor_signs(cad, c.sample))
                             for i, c in enumerate(cad.cells)), True, "")
    return connect_regions(cad, counts)


def _trivial_cad(free: tuple[str, ...]) -> OpenCAD:
    """No surface meets the slice: one cell, the whole slice."""
    return OpenCAD(free, (), tuple(() for _ in free),
                   (Cell(tuple(0 for _ in free), tuple(Fraction(0) for _ in free)),))
