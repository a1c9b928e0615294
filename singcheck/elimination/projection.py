"""The robot's surfaces projected into the workspace (and joint space).

* ``singularity_surface`` ξ(X): the projection of ``{F = 0, det A = 0}`` onto the pose
  space, computed by a backend (joints eliminated), then reduced to its squarefree part.
* ``workspace_boundary``: per leg, the discriminant of the leg constraint in its joint.
  B = ∂F/∂ρ is a permuted diagonal for a leg-decoupled robot, so det B = 0 projects to
  the union of these discriminants (serial singularities: two IK branches of a leg meet).
* ``joint_limit_surfaces``: the leg constraint with its joint set to a limit (the paper's
  μ(X) list), exact because the leg involves no other joint.
* ``joint_space_singularities`` ε(ρ): the projection of ``{F = 0, det A = 0}`` onto the
  joint space (pose eliminated), computed on demand.

When ξ(X) would be too big to expand (:func:`expansion_bound` over
``max_surface_terms``: six pose variables and six legs reach that), it is not computed:
``singularity_surface`` is None, ``not_expanded`` says why, and each trajectory eliminates
the joints along its own path instead (:func:`singcheck.certify.path.eliminate_along_path`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from math import comb

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import restrict, squarefree_part
from singcheck.algebra.radicals import (
    angle_names,
    cos_pi,
    modulo_circles,
    norm_radicals,
    radical_name,
    sin_pi,
    surd_polynomial,
)
from singcheck.elimination.cache import CachedBackend
from singcheck.elimination.requests import (
    EliminationBackend,
    EliminationRequest,
    chain_is_small,
    norm_chain,
)
from singcheck.errors import BackendError, UnsupportedRobotError
from singcheck.model.robot import (
    REVOLUTE,
    RobotModel,
    det_a_factors,
    leg_coefficients,
    leg_discriminant,
    revolute_discriminant,
)
from singcheck.spec.grammar import RealLimit
from singcheck.spec.real_constants import exact_engine_refusal


@dataclass(frozen=True)
class JointLimitSurface:
    joint: str
    bound: str  # "min" or "max"
    value: object  # Fraction
    polynomial: fmpq_mpoly  # in the pose context


@dataclass(frozen=True)
class RobotProjection:
    model: RobotModel
    pose_context: fmpq_mpoly_ctx
    singularity_surface: fmpq_mpoly | None  # ξ, squarefree, monic; None: not expanded
    singularity_surface_as_computed: fmpq_mpoly | None  # what the backend returned
    workspace_boundary: tuple[fmpq_mpoly, ...]  # one discriminant per leg
    joint_limit_surfaces: tuple[JointLimitSurface, ...]
    backend: str
    method: str
    not_expanded: str = ""  # why ξ(X) was not expanded (then μ is eliminated per path)

    @property
    def expanded(self) -> bool:
        return self.singularity_surface is not None

    @cached_property
    def surface_on_circles(self) -> fmpq_mpoly | None:
        """ξ modulo cos² + sin² = 1 of each pose angle (:func:`modulo_circles`): the same
        function of every real pose, what a path composes (the 3-PRR's ξ: 24,389 terms,
        2,609 on the circle), or ξ itself when that is not smaller.  Computed once per
        projection."""
        xi = self.singularity_surface
        if xi is None:
            return None
        reduced = modulo_circles(xi)
        return reduced if len(reduced) < len(xi) else xi


#: ξ(X) is expanded when the bound on its number of terms (:func:`expansion_bound`) is at
#: most this; above it each trajectory eliminates the joints along its own path.
MAX_SURFACE_TERMS = 10_000_000


def _circles(model: RobotModel, names) -> tuple[fmpq_mpoly, ...]:
    """cos(v)² + sin(v)² - 1 for each angle among ``names`` (user variables)."""
    gens = dict(zip(model.context.names(), model.context.gens(), strict=True))
    return tuple(gens[c] ** 2 + gens[s] ** 2 - 1
                 for c, s in (angle_names(v) for v in names if v in model.angles))


def pose_circles(model: RobotModel) -> tuple[fmpq_mpoly, ...]:
    """cos(φ)² + sin(φ)² - 1 for each angle φ of the pose."""
    return _circles(model, model.pose)


def singularity_surface_request(model: RobotModel) -> EliminationRequest:
    """Eliminate the joints from ``{F, det A}`` (the paper's ξ(X)); an angle joint brings
    its circle cos² + sin² = 1, a square root its pseudo-leg sqrt(p)² = p (eliminated
    too, so ξ has rational coefficients)."""
    return EliminationRequest(
        "singularity_surface", model.context,
        (*model.constraints, model.det_A, *_circles(model, model.joints),
         *(leg.constraint for leg in model.radical_legs)), model.eliminated)


def joint_space_request(model: RobotModel) -> EliminationRequest:
    """Eliminate the pose from ``{F, det A}`` (the paper's ε(ρ))."""
    return pose_elimination_request(model, "joint_space_singularities", model.det_A)


def pose_elimination_request(model: RobotModel, kind: str,
                             extra: fmpq_mpoly) -> EliminationRequest:
    """Eliminate the pose from ``{F, extra}``: a pose angle brings its circle
    cos² + sin² = 1 (its cos and sin are eliminated), a square root its pseudo-leg."""
    return EliminationRequest(
        kind, model.context,
        (*model.constraints, extra, *pose_circles(model),
         *(leg.constraint for leg in model.radical_legs)),
        (*model.pose_variables, *model.spec.radical_variables))


def _pose_context(model: RobotModel) -> fmpq_mpoly_ctx:
    return fmpq_mpoly_ctx.get(model.pose_variables, "lex")


def to_pose(model: RobotModel, p: fmpq_mpoly, pose_ctx: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """A polynomial in the pose (and square roots) as one over Q in the pose context:
    its norm over the square roots (every conjugate's zero set together)."""
    return restrict(norm_radicals(p), pose_ctx)


class ZeroIdeal(BackendError):
    """The elimination ideal is zero: its surface is the whole space (every pose is
    singular in some working mode: two legs on one rail, say), not "no surface"."""


#: the projection's ``method`` reason when the singularity surface is the whole workspace
WHOLE_WORKSPACE = ("the singularity surface is the whole workspace (the elimination ideal "
                   "is zero): some working mode is singular at every pose, so μ is "
                   "formed along each path and each mode is decided on its own")


def _single(result, label: str) -> fmpq_mpoly:
    polys = [p for p in result.polynomials if not p.is_zero()]
    if not polys:
        raise ZeroIdeal(f"{result.backend}: the {label} came back empty (zero ideal)")
    if len(polys) == 1:
        return polys[0]
    # not a hypersurface: keep the gcd, whose zero set contains the projection
    g = polys[0]
    for p in polys[1:]:
        g = g.gcd(p)
    if g.is_constant():
        raise BackendError(f"{result.backend}: the {label} is not a hypersurface")
    return g


def workspace_boundary(model: RobotModel, pose_ctx: fmpq_mpoly_ctx) -> tuple[fmpq_mpoly, ...]:
    """Per leg, where its two branches meet: b² - 4ac, or Δ = a² + b² - d² for a
    revolute leg (1 for a linear leg); normed over the square roots."""
    out = []
    for leg in model.legs:
        disc = leg_discriminant(leg, leg_coefficients(leg))
        out.append(pose_ctx.from_dict({(0,) * pose_ctx.nvars(): 1}) if disc is None
                   else to_pose(model, disc, pose_ctx))
    return tuple(out)


def transcendental_limits(model: RobotModel) -> str:
    """Which angle limits have no algebraic cos and sin ("" when none): with them the
    joint-limit surfaces are not algebraic, so no region statement is made."""
    found = [f"{leg.joint} {value}" for leg in model.legs
             for value in model.spec.joint_limits.get(leg.joint, ())
             if not algebraic_limit(leg, value)]
    return ", ".join(found)


def algebraic_limit(leg, value) -> bool:
    """Whether the limit's surface is algebraic over Q: a rational prismatic limit, an
    angle limit qπ with 12q an integer."""
    if leg.kind == REVOLUTE:
        return exact_angle_limit(value)
    return isinstance(value, Fraction)


def exact_angle_limit(value) -> bool:
    """Whether an angle joint's limit has exact (algebraic) cos and sin here: qπ with 12q
    an integer.  Other limits (0.5 rad, ``cos(1/3)``: a RealLimit) are compared by ball
    arithmetic alone."""
    if isinstance(value, RealLimit):
        return False
    return not value.rational and cos_pi(value.pi_coefficient) is not None


def angle_limit_values(joint: str, value) -> tuple:
    """``(cos L, sin L)`` as exact surds for an angle joint's limit L = qπ, 12q an
    integer (the limits whose crossings are algebraic)."""
    if isinstance(value, RealLimit) or value.rational or cos_pi(value.pi_coefficient) is None:
        raise UnsupportedRobotError(
            f"the limit {value} of angle joint {joint} must be a multiple of pi/12 (e.g. "
            "-pi/2, 2*pi/3) so that its sine and cosine are exact")
    return cos_pi(value.pi_coefficient), sin_pi(value.pi_coefficient)


def limit_constraint(model: RobotModel, leg, value) -> fmpq_mpoly:
    """The leg's constraint with its joint at the limit ``value``, in a context with
    every square root it needs (the robot's context, plus sqrt(2), sqrt(3) for an angle
    limit)."""
    coeffs = leg_coefficients(leg)
    if leg.kind != REVOLUTE:
        poly = coeffs[0].context().from_dict({})
        q = fmpq(value.numerator, value.denominator)
        for c in coeffs:  # Horner in the joint value
            poly = poly * q + c
        return poly
    cos_l, sin_l = angle_limit_values(leg.joint, value)
    names = model.context.names()
    extra = tuple(radical_name(p) for p in sorted(cos_l.primes() | sin_l.primes())
                  if radical_name(p) not in names)
    ctx = fmpq_mpoly_ctx.get((*names, *extra), "lex")
    a, b, d = (ctx.from_dict({(*e, *(0,) * len(extra)): k for e, k in c.terms()})
               for c in coeffs)
    return a * surd_polynomial(cos_l, ctx) + b * surd_polynomial(sin_l, ctx) + d


def joint_limit_surfaces(model: RobotModel, pose_ctx) -> tuple[JointLimitSurface, ...]:
    out = []
    for leg in model.legs:
        limits = model.spec.joint_limits.get(leg.joint)
        if limits is None:
            continue
        for bound, value in zip(("min", "max"), limits, strict=True):
            if not algebraic_limit(leg, value):
                continue  # not algebraic: the region statement is refused for this robot
            try:
                poly = norm_radicals(limit_constraint(model, leg, value))
            except UnsupportedRobotError as e:
                raise UnsupportedRobotError(
                    e.message, path=model.spec.path, line=model.spec.lines.get("joint_limits"),
                    key=f"joint_limits.{leg.joint}") from None
            out.append(JointLimitSurface(leg.joint, bound, value, restrict(poly, pose_ctx)))
    return tuple(out)


def norm_legs(model: RobotModel) -> list:
    """The legs as :func:`~singcheck.elimination.requests.norm_chain` takes them: a
    revolute leg's (cos, sin) pair, then each square root's pseudo-leg."""
    legs = [(leg.variables if leg.kind == REVOLUTE else leg.joint, leg.constraint)
            for leg in model.legs]
    return legs + [(leg.joint, leg.constraint) for leg in model.radical_legs]


def norm_over_legs(model: RobotModel) -> fmpq_mpoly:
    """The norm of det A over the legs (squarefree, FLINT): exactly ξ's zero set (outside
    the degenerate set of revolute legs, :func:`degenerate_set`)."""
    return restrict(norm_chain(model.det_A, norm_legs(model)), _pose_context(model))


def degenerate_set(model: RobotModel) -> tuple[fmpq_mpoly, ...]:
    """W = a² + b² of each revolute leg, normed over the square roots (pose context):
    where W ≠ 0 the leg's joint is integral over the pose and ξ vanishes exactly on the
    singular modes; a real pose has W = 0 only if the leg does not depend on its angle."""
    pose_ctx = _pose_context(model)
    over_q = not exact_engine_refusal(model.spec)
    out = []
    for leg in model.legs:
        if leg.kind == REVOLUTE:
            a, b, d = leg_coefficients(leg)
            w = revolute_discriminant(a, b, d) + d * d
            # (a robot with opaque constants: W in its own ring, only enclosed by balls)
            out.append(to_pose(model, w, pose_ctx) if over_q else w)
    return tuple(out)


def _without_degenerate_factors(p: fmpq_mpoly, degenerate) -> fmpq_mpoly:
    """``p``'s squarefree part without the factors that divide a degenerate W; the zero
    polynomial stays zero (it has no factors to drop, and dropping "all of them" would
    leave 1)."""
    if p.is_zero():
        return p
    if not degenerate:
        return squarefree_part(p)
    _, factors = squarefree_part(p).factor()
    out = p.context().from_dict({(0,) * p.context().nvars(): 1})
    for f, _ in factors:
        if not any(divmod(w, f)[1].is_zero() for w in degenerate):
            out *= f
    return squarefree_part(out)


def bounded_norm_over_legs(model: RobotModel, timeout: float) -> fmpq_mpoly:
    """:func:`norm_over_legs` under the bounds of every elimination: in this process when
    :func:`~singcheck.elimination.requests.chain_is_small` proves it small, else in a
    forked child with ``timeout`` seconds and the memory bound
    (:func:`~singcheck.elimination.cas.isolated.run_bounded`)."""
    from singcheck.elimination.cas.isolated import run_bounded
    from singcheck.elimination.cas.limits import memory_limit

    small = chain_is_small(model.det_A, norm_legs(model), memory_limit())
    return run_bounded(norm_over_legs, model, small, timeout,
                       "the re-check (the norm of det A over the legs)")


def recheck_singularity_surface(model: RobotModel, xi: fmpq_mpoly, backend: str,
                                norm: fmpq_mpoly | None = None,
                                timeout: float | None = None) -> fmpq_mpoly:
    """Refuse a ξ whose zero set differs from the independently computed norm's; return
    ξ without the degenerate factors (what :func:`project_robot` keeps).

    Both are reduced to monic squarefree parts and compared exactly (for revolute legs,
    without the factors of the degenerate set W = 0, where a CAS's closure of the
    projection and the norm may differ); a CAS result that parsed but is wrong (or
    belongs to another request) fails here, loudly.  A ξ equal to the norm as it stands
    passes at once: the norm is squarefree and monic by construction.  ``norm``: that
    norm when the caller has it (the flint backend's result, computed now, is that
    norm: recomputing it would re-check nothing); else it is computed under ``timeout``
    (:func:`bounded_norm_over_legs`).
    """
    from singcheck.elimination.cas.external import DEFAULT_TIMEOUT

    degenerate = degenerate_set(model)
    if norm is None:
        norm = bounded_norm_over_legs(model, timeout or DEFAULT_TIMEOUT)
    if xi == norm and not degenerate:
        return norm
    clean = _without_degenerate_factors(xi, degenerate)
    if clean != _without_degenerate_factors(norm, degenerate):
        raise BackendError(f"{backend}: the singularity surface it returned fails the "
                           "re-check against the in-process norm of det A over the legs")
    return clean


def expansion_bound(model: RobotModel) -> tuple[int, int]:
    """(degree, terms): bounds on the largest factor of ξ(X) as the norm would build it.

    ξ is the product over the irreducible factors g of det A of the chain of resultants
    of g with the legs whose joints it involves.  ``deg Res_v(g, f) ≤ deg g · deg f``
    (total degrees), so that factor's norm has degree at most d = deg g · Π deg f_i, and
    at most C(n + d, n) terms in the n pose variables (a revolute leg's norm, a square
    root's pseudo-leg: the same bound with their constraint's degree, doubled for the
    revolute norm's square).  A bound, not a measurement: it decides beforehand, in
    microseconds, whether expanding ξ can be afforded.
    """
    names = model.context.names()
    n = len(model.pose_variables)
    worst = (0, 1)
    for g, _ in det_a_factors(model):
        degree = g.total_degree()
        for leg in (*model.legs, *model.radical_legs):
            if any(g.degrees()[names.index(v)] > 0 for v in leg.variables):
                degree *= leg.constraint.total_degree() * (2 if leg.kind == REVOLUTE else 1)
        worst = max(worst, (degree, comb(n + degree, n)), key=lambda b: b[1])
    return worst


def not_expanded_reason(model: RobotModel, max_terms: int = MAX_SURFACE_TERMS) -> str:
    """Why ξ(X) should not be expanded ("" when it should)."""
    degree, terms = expansion_bound(model)
    if terms <= max_terms:
        return ""
    return (f"ξ(X) in {len(model.pose)} pose variables could reach degree {degree} "
            f"({terms:.1e} terms, over the limit of {max_terms:.0e}); each path eliminates "
            "the joints along itself instead (μ(t) computed directly)")


JOINT_FREE = "det A is free of the joints: ξ = det A (no elimination)"


def project_robot(model: RobotModel, backend: EliminationBackend,
                  max_surface_terms: int = MAX_SURFACE_TERMS) -> RobotProjection:
    """Every workspace surface of the robot, with ξ from ``backend`` (re-checked), or
    without ξ when it is too big to expand (:func:`not_expanded_reason`).

    When det A involves no joint (squared-distance legs), ξ is det A itself, normed over
    the square roots: no backend runs.  Factors of the degenerate set W = 0 of revolute
    legs are dropped from ξ (each backend's closure may keep them or not): a real pose
    there has no real, separated branches of that leg (Δ = W - d² ≤ 0), so no feasible
    mode passes through it."""
    refused = exact_engine_refusal(model.spec)
    if refused:  # parameters outside the exact field: nothing over Q to eliminate
        return not_projected(model, refused)
    pose_ctx = _pose_context(model)
    xi = None
    if model.joint_free_det_A:
        raw = to_pose(model, model.det_A, pose_ctx)
        name, method = "none", JOINT_FREE
    else:
        reason = not_expanded_reason(model, max_surface_terms)
        if reason:
            return RobotProjection(model, pose_ctx, None, None,
                                   workspace_boundary(model, pose_ctx),
                                   joint_limit_surfaces(model, pose_ctx), backend.name,
                                   "eliminated along each path", reason)

        checked: list = []  # (ξ as returned, ξ re-checked) of the last result checked

        timeout = getattr(backend, "timeout", None) or getattr(
            getattr(backend, "backend", None), "timeout", None)

        def check(result) -> None:
            raw = _single(result, "singularity surface")
            checked[:] = [raw, recheck_singularity_surface(
                model, raw, result.backend, raw if result.is_norm else None, timeout)]

        request = singularity_surface_request(model)
        try:
            if isinstance(backend, CachedBackend):  # cache only what passes the re-check
                result = backend.eliminate(request, check=check)
            else:
                result = backend.eliminate(request)
                check(result)
        except ZeroIdeal:  # ξ ≡ 0: no surface to restrict to a path, μ along each path
            return RobotProjection(model, pose_ctx, None, None,
                                   workspace_boundary(model, pose_ctx),
                                   joint_limit_surfaces(model, pose_ctx), backend.name,
                                   "eliminated along each path", WHOLE_WORKSPACE)
        raw = _single(result, "singularity surface")
        name, method = result.backend, result.method
        if checked and checked[0] is raw:
            xi = checked[1]
    if xi is None:
        xi = _without_degenerate_factors(raw, degenerate_set(model))
    return RobotProjection(model, pose_ctx, xi, raw, workspace_boundary(model, pose_ctx),
                           joint_limit_surfaces(model, pose_ctx), name, method)


#: the projection's ``method`` for a robot whose parameters leave the exact field
NOT_PROJECTED = "not computed"


def not_projected(model: RobotModel, reason: str) -> RobotProjection:
    """The projection of a robot with opaque constants (parameters outside the exact
    field, :mod:`singcheck.spec.real_constants`): ξ, the workspace boundary and the
    joint-limit surfaces are not computed (they would not be polynomials over Q), and
    ``not_expanded`` says why; the interval engine alone certifies its paths."""
    pose_ctx = fmpq_mpoly_ctx.get(model.pose_variables, "lex")
    return RobotProjection(model, pose_ctx, None, None, (), (), "none",
                           f"{NOT_PROJECTED}: {reason}", reason)


def refuse_elimination(model: RobotModel, what: str) -> None:
    """An :class:`UnsupportedRobotError` (the spec's ``parameters`` line) when the robot
    has parameters outside the exact field: ``what`` (an elimination, a region map, the
    exact engine) cannot be computed for it, and the message says why."""
    refused = exact_engine_refusal(model.spec)
    if refused:
        raise UnsupportedRobotError(f"{what}: {refused}",
                                    path=model.spec.path,
                                    line=model.spec.lines.get("parameters"),
                                    key="parameters")


def joint_space_singularities(model: RobotModel, backend: EliminationBackend) -> fmpq_mpoly:
    """ε(ρ), squarefree, in the joints' context."""
    result = backend.eliminate(joint_space_request(model))
    return squarefree_part(_single(result, "joint-space singularity surface"))
