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
from math import comb

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import restrict, squarefree_part
from singcheck.elimination.cache import CachedBackend
from singcheck.elimination.requests import EliminationBackend, EliminationRequest, norm_chain
from singcheck.errors import BackendError
from singcheck.model.robot import RobotModel, leg_coefficients


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


#: ξ(X) is expanded when the bound on its number of terms (:func:`expansion_bound`) is at
#: most this; above it each trajectory eliminates the joints along its own path.
MAX_SURFACE_TERMS = 10_000_000


def singularity_surface_request(model: RobotModel) -> EliminationRequest:
    """Eliminate the joints from ``{F, det A}`` (the paper's ξ(X))."""
    return EliminationRequest("singularity_surface", model.context,
                              (*model.constraints, model.det_A), model.joints)


def joint_space_request(model: RobotModel) -> EliminationRequest:
    """Eliminate the pose from ``{F, det A}`` (the paper's ε(ρ))."""
    return EliminationRequest("joint_space_singularities", model.context,
                              (*model.constraints, model.det_A), model.pose)


def _pose_context(model: RobotModel) -> fmpq_mpoly_ctx:
    return fmpq_mpoly_ctx.get(model.pose, "lex")


def _single(result, label: str) -> fmpq_mpoly:
    polys = [p for p in result.polynomials if not p.is_zero()]
    if not polys:
        raise BackendError(f"{result.backend}: the {label} came back empty (zero ideal)")
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
    out = []
    for leg in model.legs:
        coeffs = [restrict(c, pose_ctx) for c in leg_coefficients(leg)]
        if leg.degree == 2:
            a, b, c = coeffs
            out.append(b * b - 4 * a * c)
        else:
            out.append(pose_ctx.from_dict({(0,) * pose_ctx.nvars(): 1}))
    return tuple(out)


def joint_limit_surfaces(model: RobotModel, pose_ctx) -> tuple[JointLimitSurface, ...]:
    out = []
    for leg in model.legs:
        limits = model.spec.joint_limits.get(leg.joint)
        if limits is None:
            continue
        coeffs = [restrict(c, pose_ctx) for c in leg_coefficients(leg)]
        for bound, value in zip(("min", "max"), limits, strict=True):
            poly = pose_ctx.from_dict({})
            q = fmpq(value.numerator, value.denominator)
            for c in coeffs:  # Horner in the joint value
                poly = poly * q + c
            out.append(JointLimitSurface(leg.joint, bound, value, poly))
    return tuple(out)


def norm_over_legs(model: RobotModel) -> fmpq_mpoly:
    """The norm of det A over the legs (squarefree, FLINT): exactly ξ's zero set."""
    legs = [(leg.joint, leg.constraint) for leg in model.legs]
    return restrict(norm_chain(model.det_A, legs), _pose_context(model))


def recheck_singularity_surface(model: RobotModel, xi: fmpq_mpoly, backend: str) -> None:
    """Refuse a ξ whose zero set differs from the independently computed norm's.

    Both are reduced to monic squarefree parts and compared exactly; a CAS result that
    parsed but is wrong (or belongs to another request) fails here, loudly.
    """
    if squarefree_part(xi) != squarefree_part(norm_over_legs(model)):
        raise BackendError(f"{backend}: the singularity surface it returned fails the "
                           "re-check against the in-process norm of det A over the legs")


def expansion_bound(model: RobotModel) -> tuple[int, int]:
    """(degree, terms): bounds on the largest factor of ξ(X) as the norm would build it.

    ξ is the product over the irreducible factors g of det A of the chain of resultants
    of g with the legs whose joints it involves.  ``deg Res_v(g, f) ≤ deg g · deg f``
    (total degrees), so that factor's norm has degree at most d = deg g · Π deg f_i, and
    at most C(n + d, n) terms in the n pose variables.  A bound, not a measurement: it
    decides beforehand, in microseconds, whether expanding ξ can be afforded.
    """
    names = model.context.names()
    n = len(model.pose)
    worst = (0, 1)
    for g, _ in model.det_A.factor()[1]:
        degree = g.total_degree()
        for leg in model.legs:
            if g.degrees()[names.index(leg.joint)] > 0:
                degree *= leg.constraint.total_degree()
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


def project_robot(model: RobotModel, backend: EliminationBackend,
                  max_surface_terms: int = MAX_SURFACE_TERMS) -> RobotProjection:
    """Every workspace surface of the robot, with ξ from ``backend`` (re-checked), or
    without ξ when it is too big to expand (:func:`not_expanded_reason`)."""
    pose_ctx = _pose_context(model)
    reason = not_expanded_reason(model, max_surface_terms)
    if reason:
        return RobotProjection(model, pose_ctx, None, None, workspace_boundary(model, pose_ctx),
                               joint_limit_surfaces(model, pose_ctx), backend.name,
                               "eliminated along each path", reason)

    def check(result) -> None:
        recheck_singularity_surface(model, _single(result, "singularity surface"),
                                    result.backend)

    request = singularity_surface_request(model)
    if isinstance(backend, CachedBackend):  # cache only what passes the re-check
        result = backend.eliminate(request, check=check)
    else:
        result = backend.eliminate(request)
        check(result)
    raw = _single(result, "singularity surface")
    xi = squarefree_part(raw)
    return RobotProjection(model, pose_ctx, xi, raw, workspace_boundary(model, pose_ctx),
                           joint_limit_surfaces(model, pose_ctx), result.backend, result.method)


def joint_space_singularities(model: RobotModel, backend: EliminationBackend) -> fmpq_mpoly:
    """ε(ρ), squarefree, in the joints' context."""
    result = backend.eliminate(joint_space_request(model))
    return squarefree_part(_single(result, "joint-space singularity surface"))
