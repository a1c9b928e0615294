"""The polynomial model of a robot: F(ρ, X) = 0, its Jacobians and their determinants.

Following the paper, ``A = ∂F/∂X`` (pose) and ``B = ∂F/∂ρ`` (joints); ``det A = 0`` is a
parallel singularity and ``det B = 0`` a serial one.  Everything is exact (``fmpq_mpoly``).

**Angles.**  A joint or pose variable v used inside sin/cos enters the algebra as the
pair ``(cos(v), sin(v))`` with cos² + sin² = 1 (every polynomial is kept reduced modulo
that relation, :func:`~singcheck.algebra.radicals.reduce_relations`).  The derivative in
an angle is the derivative along the circle, ``∂/∂v = -sin(v)·∂/∂cos(v) +
cos(v)·∂/∂sin(v)``: A and B keep one column per joint or pose variable, and det A, det B
are the determinants of the true Jacobians, as polynomials in the cos/sin variables.

**Square roots.**  A parameter like √3 is a variable ``sqrt(3)`` with the *pseudo-leg*
``sqrt(3)² - 3 = 0`` (:attr:`RobotModel.radical_legs`): it is eliminated with the joints,
so ξ(X) has rational coefficients and vanishes where some working mode of the robot *or
of a conjugate robot* (√3 ↦ -√3) is singular.  Conjugate modes are never feasible; the
certification evaluates them only to complete the elimination argument.

singcheck certifies robots whose inverse kinematics is *leg-decoupled*: each
constraint involves exactly one actuated joint (a leg), and that leg is

* **prismatic**: of degree 1 or 2 in its joint ρ with a non-zero constant leading
  coefficient (an irrational one, √3 from a parameter, is divided out: the model's
  constraint then has leading coefficient 1; one in parameters outside the exact field,
  c² + s² with c = cos 1, is kept when its ball excludes 0: only the interval engine
  takes such a robot); its branches are ``ρ = (-b ± √D)/(2a)``,
  D = b² - 4ac; or
* **revolute**: an angle joint θ entering as ``a(X)·cos θ + b(X)·sin θ + d(X)`` (degree
  ≤ 2 in the half-angle tangent); its branches are
  ``cos θ = (-a·d + σ·b·√Δ)/W``, ``sin θ = (-b·d - σ·a·√Δ)/W`` for σ = ±1, with
  ``W = a² + b²`` and ``Δ = W - d²`` (no half-angle tangent: θ = π is an ordinary point,
  and only W = 0, i.e. a = b = 0, the leg not depending on θ at all, is degenerate).
  ``∂F/∂θ = σ·√Δ`` on branch σ: the branches meet (serial singularity) where Δ = 0.

Two facts follow and the rest of the pipeline relies on them:

* the inverse kinematics has finitely many branches per leg, so the working modes are
  the sign choices, and
* every prismatic joint is integral over Q[X], and a revolute joint's (cos θ, sin θ) is
  integral where W ≠ 0, so the projection of ``{F = 0, det A = 0}`` is closed outside the
  degenerate set W = 0: there, ξ(X) vanishes exactly where some (possibly complex)
  working mode is singular.

When det A does not involve the joints at all (legs in which the joint appears only
squared, ρᵢ² = |…|²: 3-RPR, Gough–Stewart), every mode has the same det A(X) and
ξ(X) = det A(X) with no elimination (:attr:`RobotModel.joint_free_det_A`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import coefficient_in, memo_per_object
from singcheck.algebra.radicals import (
    angle_names,
    constant_surd,
    radical_name,
    reduce_relations,
    surd_polynomial,
)
from singcheck.errors import UnsupportedRobotError

if TYPE_CHECKING:
    from singcheck.spec.files import RobotSpec


PRISMATIC, REVOLUTE, RADICAL = "prismatic", "revolute", "radical"


@dataclass(frozen=True)
class Leg:
    """One constraint and the single actuated joint it involves (or a square root's
    pseudo-leg ``sqrt(p)² - p``, kind ``radical``)."""

    joint: str
    joint_index: int  # in the context: the joint, or cos(joint) for a revolute leg
    constraint: fmpq_mpoly
    constraint_index: int  # -1 for a radical pseudo-leg
    degree: int  # in the joint (prismatic); 2 for a revolute leg (in tan(θ/2))
    kind: str = PRISMATIC

    @property
    def variables(self) -> tuple[str, ...]:
        """The context variables of the joint: ``(ρ,)`` or ``(cos(θ), sin(θ))``."""
        return angle_names(self.joint) if self.kind == REVOLUTE else (self.joint,)


@dataclass(frozen=True)
class RobotModel:
    spec: RobotSpec
    context: fmpq_mpoly_ctx  # joint variables, pose variables, radicals (spec.context)
    joints: tuple[str, ...]
    pose: tuple[str, ...]
    constraints: tuple[fmpq_mpoly, ...]
    A: tuple[tuple[fmpq_mpoly, ...], ...]  # ∂F/∂X, one column per pose variable
    B: tuple[tuple[fmpq_mpoly, ...], ...]  # ∂F/∂ρ, one column per joint
    det_A: fmpq_mpoly
    det_B: fmpq_mpoly
    legs: tuple[Leg, ...]  # in joint order
    radical_legs: tuple[Leg, ...] = ()  # sqrt(p)² - p, one per square root

    @property
    def name(self) -> str:
        return self.spec.name

    def __repr__(self) -> str:  # short: F, A, B, det A and det B run to kilobytes
        return (f"<RobotModel {self.name}: {len(self.legs)} legs, det A of degree "
                f"{self.det_A.total_degree()}, det B of degree {self.det_B.total_degree()}>")

    @property
    def angles(self) -> frozenset[str]:
        return self.spec.angles

    @cached_property  # the model is immutable; asked at every candidate
    def joint_variables(self) -> tuple[str, ...]:
        return self.spec.joint_variables

    @cached_property  # the model is immutable; asked at every candidate
    def pose_variables(self) -> tuple[str, ...]:
        return self.spec.pose_variables

    @property
    def eliminated(self) -> tuple[str, ...]:
        """The variables a projection onto the pose eliminates: joints and radicals."""
        return (*self.joint_variables, *self.spec.radical_variables)

    @cached_property  # the model is immutable; asked at every candidate
    def joint_free_det_A(self) -> bool:
        """det A involves no joint variable: ξ(X) is det A itself (no elimination)."""
        names = self.context.names()
        return all(self.det_A.degrees()[names.index(v)] <= 0 for v in self.joint_variables)

    @cached_property  # the model is immutable; asked at every candidate
    def angle_joints(self) -> bool:
        """Some joint is revolute: its value is a (cos θ, sin θ) pair of variables."""
        return any(leg.kind == REVOLUTE for leg in self.legs)

    @cached_property  # the model is immutable; asked at every candidate
    def polynomial(self) -> bool:
        """No angle and no square root: the original, purely polynomial class."""
        return not self.spec.angles and not self.spec.radicals


def jacobian(polys: tuple[fmpq_mpoly, ...], variables: tuple[str, ...],
             angles: frozenset[str] = frozenset()):
    """The matrix ``∂polys/∂variables`` (rows: polys, columns: variables); for an angle
    v the column is the derivative along the circle, -sin(v)·∂/∂cos(v) + cos(v)·∂/∂sin(v)
    (reduced modulo cos² + sin² = 1)."""
    rows = []
    for p in polys:
        row = []
        for v in variables:
            if v in angles:
                c, s = angle_names(v)
                gens = dict(zip(p.context().names(), p.context().gens(), strict=True))
                row.append(reduce_relations(gens[c] * p.derivative(s)
                                            - gens[s] * p.derivative(c)))
            else:
                row.append(p.derivative(v))
        rows.append(tuple(row))
    return tuple(rows)


def determinant(matrix) -> fmpq_mpoly:
    """Exact determinant by Laplace expansion along rows, memoised on column sets.

    O(n · 2ⁿ) polynomial products: fine for the n ≤ 6 of parallel robots.

    >>> from flint import fmpq_mpoly_ctx
    >>> ctx = fmpq_mpoly_ctx.get(("a", "b"), "lex")
    >>> a, b = ctx.gens()
    >>> str(determinant(((a, b), (b, a))))
    'a^2 - b^2'
    """
    n = len(matrix)
    ctx = matrix[0][0].context()
    memo: dict[tuple[int, ...], fmpq_mpoly] = {(): ctx.from_dict({(0,) * ctx.nvars(): 1})}

    def minor(cols: tuple[int, ...]) -> fmpq_mpoly:
        # the determinant of rows n-len(cols).. of the columns ``cols``
        if cols not in memo:
            row = n - len(cols)
            total = ctx.from_dict({})
            for k, col in enumerate(cols):
                entry = matrix[row][col]
                if not entry.is_zero():
                    term = entry * minor(cols[:k] + cols[k + 1:])
                    total = total - term if k % 2 else total + term
            memo[cols] = total
        return memo[cols]

    return minor(tuple(range(n)))


_RESHAPE = ("; reformulate it so that each constraint drives one actuated joint, e.g. "
            "a leg's squared length ρ² = |B - A(X)|², or a revolute joint's distal link "
            "as |B(X) - A(θ)|² = l²")


def _legs(spec: RobotSpec) -> tuple[Leg, ...]:
    joints = spec.joints
    names = spec.context.names()
    found: dict[str, Leg] = {}
    for index, f in enumerate(spec.constraints):
        involved = [j for j in joints
                    if any(f.degrees()[names.index(v)] > 0 for v in spec.variables(j))]
        line = spec.constraint_lines[index]
        key = f"constraints[{index}]"
        if len(involved) != 1:
            what = "no actuated joint" if not involved else "joints " + ", ".join(involved)
            raise UnsupportedRobotError(
                f"involves {what}; singcheck certifies leg-decoupled robots, where each "
                "constraint involves exactly one actuated joint (passive joints must be "
                "eliminated first)" + _RESHAPE, path=spec.path, line=line, key=key)
        joint = involved[0]
        if joint in found:
            raise UnsupportedRobotError(
                f"joint {joint} already appears in constraints[{found[joint].constraint_index}];"
                " each actuated joint must drive exactly one leg constraint",
                path=spec.path, line=line, key=key)
        if joint in spec.angles:
            found[joint] = _revolute_leg(spec, joint, f, index, line, key)
            continue
        j = names.index(joint)
        degree = f.degrees()[j]
        if degree > 2:
            raise UnsupportedRobotError(
                f"is of degree {degree} in {joint}; singcheck supports legs of degree 1 or 2 "
                "in their joint (prismatic or distance legs)", path=spec.path, line=line, key=key)
        lead = coefficient_in(f, j, degree)
        if not lead.is_constant():
            value = constant_surd(lead)
            if value is None and _only_opaque_constants(lead):
                if not _proven_nonzero(lead):
                    raise UnsupportedRobotError(
                        f"the coefficient of {joint}^{degree} involves a parameter outside "
                        "the exact field and cannot be proven ≠ 0 by ball arithmetic; "
                        f"write the constraint with a rational or square-root coefficient "
                        f"of {joint}^{degree} (divide it out)", path=spec.path, line=line,
                        key=key)
                # a constant the balls prove ≠ 0 (c² + s² with c = cos 1, s = sin 1): the
                # leg keeps it; only the interval engine takes such a robot, and it reads
                # a leg's leading coefficient as a ball
                found[joint] = Leg(joint, j, f, index, degree)
                continue
            if value is None:
                raise UnsupportedRobotError(
                    f"the coefficient of {joint}^{degree} depends on the pose; singcheck needs "
                    "it constant so that the joint is integral over the pose (exact "
                    "projection)", path=spec.path, line=line, key=key)
            # a non-zero algebraic constant (√3 from a parameter): the constraint divided
            # by it has the same zeros and leading coefficient 1
            f = reduce_relations(f * surd_polynomial(value.inverse(), spec.context))
        found[joint] = Leg(joint, j, f, index, degree)
    return tuple(found[j] for j in joints)


def _proven_nonzero(p: fmpq_mpoly) -> bool:
    """Whether the ball of ``p``, a polynomial in opaque constants and square roots of
    rationals (:func:`~singcheck.algebra.radicals.radical_balls`), excludes 0."""
    from flint import arb

    from singcheck.algebra.radicals import radical_balls

    balls = radical_balls(p.context())
    total = arb(0)
    for exps, q in p.terms():
        term = arb(q)
        for i, e in enumerate(exps):
            if e:
                term *= balls[i] ** e
        total += term
    return not total.contains(0)


def _only_opaque_constants(p: fmpq_mpoly) -> bool:
    """Whether ``p`` involves opaque constants (parameters outside the exact field,
    :mod:`singcheck.spec.real_constants`) and no joint or pose variable."""
    from singcheck.algebra.opaque import is_opaque_constant

    names = p.context().names()
    used = [names[i] for i, d in enumerate(p.degrees()) if d > 0]
    return any(is_opaque_constant(n) for n in used) and \
        all(is_opaque_constant(n) or n.startswith("sqrt(") for n in used)


def _revolute_leg(spec: RobotSpec, joint: str, f: fmpq_mpoly, index: int, line: int,
                  key: str) -> Leg:
    names = spec.context.names()
    c, s = (names.index(v) for v in angle_names(joint))
    for exps, _ in f.terms():
        if exps[c] + exps[s] > 1:
            raise UnsupportedRobotError(
                f"is not of the form a·cos({joint}) + b·sin({joint}) + d (it has degree > 2 "
                f"in tan({joint}/2)); singcheck supports revolute legs with two inverse "
                "kinematics branches" + _RESHAPE, path=spec.path, line=line, key=key)
    return Leg(joint, c, f, index, 2, REVOLUTE)


def det_a_factors(model: RobotModel) -> list[tuple[fmpq_mpoly, int]]:
    """det A's irreducible factors over Q with their multiplicities (FLINT), once per
    det A object: the projection's size bound and the path-wise one both read them (0.9 s
    each on a 6-RUS hexapod's det A)."""
    return memo_per_object(_DET_A_FACTORS, model.det_A, lambda p: list(p.factor()[1]),
                           keep=16)


_DET_A_FACTORS: dict = {}


def leg_coefficients(leg: Leg) -> tuple[fmpq_mpoly, ...]:
    """``(a, b, c)`` with ``constraint = a·ρ² + b·ρ + c`` (``(b, c)`` for a linear leg);
    for a revolute leg ``(a, b, d)`` with ``constraint = a·cos θ + b·sin θ + d``.

    Each coefficient is a polynomial in the pose variables (still in the robot's context).
    """
    if leg.kind == REVOLUTE:
        f = leg.constraint
        c = leg.joint_index
        return (coefficient_in(f, c, 1), coefficient_in(f, c + 1, 1),
                coefficient_in(coefficient_in(f, c, 0), c + 1, 0))
    return tuple(coefficient_in(leg.constraint, leg.joint_index, d)
                 for d in range(leg.degree, -1, -1))


def revolute_discriminant(a: fmpq_mpoly, b: fmpq_mpoly, d: fmpq_mpoly) -> fmpq_mpoly:
    """Δ = a² + b² - d²: the branches of a·cos θ + b·sin θ + d = 0 are real and apart
    where Δ > 0, meet where Δ = 0 (serial singularity)."""
    return a * a + b * b - d * d


def leg_discriminant(leg: Leg, coefficients) -> fmpq_mpoly | None:
    """The polynomial whose sign says whether the leg's two branches are real and apart
    (b² - 4ac, or Δ for a revolute leg); None for a linear leg."""
    if leg.kind == REVOLUTE:
        return revolute_discriminant(*coefficients)
    if leg.degree == 2:
        a, b, c = coefficients
        return b * b - 4 * a * c
    return None


def _radical_legs(spec: RobotSpec) -> tuple[Leg, ...]:
    names = spec.context.names()
    gens = spec.context.gens()
    out = []
    for p in spec.radicals:
        i = names.index(radical_name(p))
        out.append(Leg(radical_name(p), i, gens[i] ** 2 - p, -1, 2, RADICAL))
    return tuple(out)


def build_model(spec: RobotSpec) -> RobotModel:
    """F, A = ∂F/∂X, B = ∂F/∂ρ, det A, det B and the legs, from a parsed spec.

    Raises :class:`UnsupportedRobotError` (with the constraint's file and line) for a
    robot outside the leg-decoupled class, and when det A is identically zero.
    """
    legs = _legs(spec)
    # each leg's constraint, divided by its leading coefficient when that is an irrational
    # constant (:func:`_legs`): F keeps its zeros, det A and det B change by a non-zero
    # constant factor
    normalised = {leg.constraint_index: leg.constraint for leg in legs}
    constraints = tuple(normalised.get(i, f) for i, f in enumerate(spec.constraints))
    A = jacobian(constraints, spec.pose, spec.angles)
    B = jacobian(constraints, spec.joints, spec.angles)
    det_A = reduce_relations(determinant(A))
    det_B = reduce_relations(determinant(B))
    if det_A.is_zero():
        raise UnsupportedRobotError(
            "det A = det(∂F/∂pose) is identically zero: the robot is singular everywhere",
            path=spec.path, line=spec.lines.get("constraints"), key="constraints")
    return RobotModel(spec, spec.context, spec.joints, spec.pose, constraints, A, B, det_A,
                      det_B, legs, _radical_legs(spec))
