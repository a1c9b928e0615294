"""A robot's polynomials along one trajectory X = φ(t), as trig polynomials in t.

Composing with φ is exact (``fmpq_mpoly.compose`` into ``Q[t, s, c]`` then
:func:`~singcheck.trig.reduce_trig`).  The results are:

* ``mu`` = ξ(φ(t)), whose real roots are every candidate singular time (when ξ(X) was too
  big to expand, μ is computed directly: :func:`eliminate_along_path`),
* per leg, the coefficients of its constraint in its joint, its discriminant D(t) and
  its joint-limit polynomials, from which the IK branches ρ = (-b ± √D)/(2a) along the
  path and their limit crossings are certified.
"""

from __future__ import annotations

from dataclasses import dataclass

from flint import acb, arb, fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.intervals import evaluate, fraction_ball
from singcheck.algebra.polynomials import restrict
from singcheck.algebra.trig import TRIG, evaluate_trig, reduce_trig
from singcheck.elimination.projection import RobotProjection
from singcheck.elimination.requests import norm_chain
from singcheck.model.robot import Leg, RobotModel, leg_coefficients
from singcheck.spec.files import TrajectorySpec


def compose_pose(p: fmpq_mpoly, phi: tuple[fmpq_mpoly, ...], pose: tuple[str, ...]) -> fmpq_mpoly:
    """``p(…, X = φ(t))`` for a polynomial in any context whose non-pose variables are absent."""
    names = p.context().names()
    args = []
    for v in names:
        if v in pose:
            args.append(phi[pose.index(v)])
        elif p.degrees()[names.index(v)] > 0:
            raise ValueError(f"{v} is not a pose variable")
        else:
            args.append(TRIG.from_dict({}))
    return reduce_trig(p.compose(*args, ctx=TRIG))


#: The most terms μ(t) = ξ(φ(t)) may have by the a-priori bound of :func:`mu_size_bound`
#: (heart 1: 89, the helix: 225, the stacked heart: 201; the Orthoglide with
#: x = (sin t + cos t + t)^16: 35,217, composed in about a second, while the power 24
#: took 3 to 10 s and 64 ran out of memory).
MAX_MU_TERMS = 50_000


def mu_size_bound(xi: fmpq_mpoly, phi: tuple[fmpq_mpoly, ...],
                  pose: tuple[str, ...]) -> tuple[int, int, int]:
    """(degree in t, degree in sin/cos, terms) that ξ(φ(t)) cannot exceed, from the
    degrees alone: each monomial of ξ becomes a product of powers of the coordinates,
    and a reduced trig polynomial of degree a in t and b in (s, c) has at most
    (a + 1)(2b + 1) terms.  Cheap: nothing is composed."""
    names = xi.context().names()
    dt = [phi[pose.index(v)].degrees()[0] if v in pose else 0 for v in names]
    dsc = [sum(phi[pose.index(v)].degrees()[1:]) if v in pose else 0 for v in names]
    deg_t = deg_sc = 0
    for exps, _ in xi.terms():
        deg_t = max(deg_t, sum(e * d for e, d in zip(exps, dt, strict=True)))
        deg_sc = max(deg_sc, sum(e * d for e, d in zip(exps, dsc, strict=True)))
    return deg_t, deg_sc, (deg_t + 1) * (2 * deg_sc + 1)


def _refuse_costly(xi, phi, pose, trajectory) -> None:
    """Refuse up front (one line, exit 2) a path whose μ would be too large to compose
    and isolate within any reasonable budget (the composition is one FLINT call that a
    time limit cannot interrupt)."""
    deg_t, deg_sc, terms = mu_size_bound(xi, phi, pose)
    if terms > MAX_MU_TERMS:
        from singcheck.errors import SpecError

        raise SpecError(
            f"too costly: μ(t) = ξ(φ(t)) could have {terms} terms (degree {deg_t} in t and "
            f"{deg_sc} in sin t, cos t; at most {MAX_MU_TERMS}): lower the degree of the "
            "coordinates or the multiples of t in sin/cos", path=trajectory.path,
            line=trajectory.lines.get("pose"), key="pose")


@dataclass(frozen=True)
class LegAlongPath:
    """One leg's constraint along the path: ``a ρ² + b(t) ρ + c(t)`` (or ``b ρ + c``)."""

    leg: Leg
    coefficients: tuple[fmpq_mpoly, ...]  # TRIG polys, highest degree first
    discriminant: fmpq_mpoly | None  # b² - 4ac for a quadratic leg

    @property
    def labels(self) -> tuple[str, ...]:
        """Branch labels: the sign in front of √D, or 'o' for a linear leg."""
        return ("+", "-") if self.leg.degree == 2 else ("o",)

    def limit_polynomial(self, value) -> fmpq_mpoly:
        """The constraint with the joint set to ``value``: it vanishes when a branch is there."""
        out = TRIG.from_dict({})
        q = fmpq(value.numerator, value.denominator)
        for c in self.coefficients:
            out = out * q + c
        return out

    def branches(self, t: arb) -> dict[str, arb | acb | None]:
        """Enclosures of each branch's joint value for every t in the ball ``t``.

        A quadratic leg's branches are real where D > 0 (proven) and complex
        conjugate where D < 0; where the sign of D is not proven both are None.
        """
        values = [evaluate_trig(c, t) for c in self.coefficients]
        if self.leg.degree == 1:
            b, c = values
            return {"o": -c / b}
        a, b, _ = values
        d = evaluate_trig(self.discriminant, t)
        if d > 0:
            root = d.sqrt()
            return {"+": (-b + root) / (2 * a), "-": (-b - root) / (2 * a)}
        if d < 0:
            root = acb(0, (-d).sqrt())
            return {"+": (-acb(b) + root) / (2 * a), "-": (-acb(b) - root) / (2 * a)}
        return {"+": None, "-": None}


@dataclass(frozen=True)
class PathModel:
    projection: RobotProjection
    trajectory: TrajectorySpec
    phi: tuple[fmpq_mpoly, ...]  # pose coordinates in the robot's pose order
    mu: fmpq_mpoly  # ξ(φ(t))
    legs: tuple[LegAlongPath, ...]

    def pose_at(self, t: arb) -> list[arb]:
        return [evaluate_trig(x, t) for x in self.phi]

    def det_A(self, joints: list[arb | acb], pose: list[arb]) -> arb | acb:
        """Enclosure of det A at the given joint and pose enclosures."""
        return evaluate(self.projection.model.det_A, [*joints, *pose])


def eliminate_along_path(model: RobotModel, phi: tuple[fmpq_mpoly, ...]) -> fmpq_mpoly:
    """μ(t) without ξ(X): substitute X = φ(t) first, then eliminate the joints.

    det A and every leg constraint are composed with φ into Q[ρ, t, s, c], and the joints
    are eliminated by the same norm as ξ (:func:`~singcheck.elimination.requests.norm_chain`,
    a chain of resultants, one factor of det A at a time).  Each leg's leading
    coefficient in its joint is a non-zero constant, so the resultants commute with the
    substitution: the result is ξ(φ(t)) up to a constant factor and multiplicities, and
    has exactly its zeros.  Only polynomials in one parameter (and s, c) are formed, never
    ξ(X) in every pose variable.
    """
    ring = fmpq_mpoly_ctx.get((*model.joints, "t", "s", "c"), "lex")
    gens = ring.gens()
    to_ring = gens[len(model.joints):]
    args = [*gens[:len(model.joints)], *(p.compose(*to_ring, ctx=ring) for p in phi)]
    det_a = model.det_A.compose(*args, ctx=ring)
    legs = [(leg.joint, leg.constraint.compose(*args, ctx=ring)) for leg in model.legs]
    return reduce_trig(restrict(norm_chain(det_a, legs), TRIG))


def build_path(projection: RobotProjection, trajectory: TrajectorySpec) -> PathModel:
    """The model along one piece (a multi-piece path: one per ``trajectory.pieces``)."""
    if trajectory.segments:
        raise ValueError("build_path takes one piece: use trajectory.pieces")
    model = projection.model
    phi = tuple(trajectory.pose[v] for v in model.pose)
    if any(p.context() is not TRIG for p in phi):
        from singcheck.errors import UnsupportedRobotError

        raise UnsupportedRobotError(
            "the trajectory uses square roots (sqrt, or sin/cos of t plus a multiple of pi): "
            "this version certifies trajectories with rational coefficients only",
            path=trajectory.path, line=trajectory.lines.get("pose"), key="pose")
    if projection.expanded:
        _refuse_costly(projection.singularity_surface, phi, model.pose, trajectory)
        mu = compose_pose(projection.singularity_surface, phi, model.pose)
    else:
        mu = eliminate_along_path(model, phi)
    legs = []
    for leg in model.legs:
        coeffs = tuple(compose_pose(c, phi, model.pose) for c in leg_coefficients(leg))
        disc = None
        if leg.degree == 2:
            a, b, c = coeffs
            disc = reduce_trig(b * b - 4 * a * c)
        legs.append(LegAlongPath(leg, coeffs, disc))
    return PathModel(projection, trajectory, phi, mu, tuple(legs))


def exact_point(q) -> arb:
    """The ball of an exact rational time (exact when dyadic)."""
    return fraction_ball(q)
