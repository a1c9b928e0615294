"""The polynomial model of a robot: F(ρ, X) = 0, its Jacobians and their determinants.

Following the paper, ``A = ∂F/∂X`` (pose) and ``B = ∂F/∂ρ`` (joints); ``det A = 0`` is a
parallel singularity and ``det B = 0`` a serial one.  Everything is exact (``fmpq_mpoly``).

singcheck certifies robots whose inverse kinematics is *leg-decoupled*: each
constraint involves exactly one actuated joint (a leg), is of degree 1 or 2 in it, and
its leading coefficient in that joint is a non-zero constant.  That covers robots with
prismatic actuators and distance legs (Orthoglide, biglides, linear Deltas, Gough-Stewart
legs).  Two facts follow and the rest of the pipeline relies on them:

* the inverse kinematics has finitely many branches, ``ρ_i = (-b ± √D)/(2a)`` per leg,
  so the working modes are the sign choices, and
* the map ``V(F) → pose space`` is finite (every ρ_i is integral over Q[X]), so the
  projection of ``{F = 0, det A = 0}`` is closed: ξ(X) vanishes exactly where some
  (possibly complex) working mode is singular.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import coefficient_in
from singcheck.errors import UnsupportedRobotError

if TYPE_CHECKING:
    from singcheck.spec.files import RobotSpec


@dataclass(frozen=True)
class Leg:
    """One constraint and the single actuated joint it involves."""

    joint: str
    joint_index: int
    constraint: fmpq_mpoly
    constraint_index: int
    degree: int  # 1 or 2 in the joint


@dataclass(frozen=True)
class RobotModel:
    spec: RobotSpec
    context: fmpq_mpoly_ctx  # joints then pose
    joints: tuple[str, ...]
    pose: tuple[str, ...]
    constraints: tuple[fmpq_mpoly, ...]
    A: tuple[tuple[fmpq_mpoly, ...], ...]  # ∂F/∂X
    B: tuple[tuple[fmpq_mpoly, ...], ...]  # ∂F/∂ρ
    det_A: fmpq_mpoly
    det_B: fmpq_mpoly
    legs: tuple[Leg, ...]  # in joint order

    @property
    def name(self) -> str:
        return self.spec.name


def jacobian(polys: tuple[fmpq_mpoly, ...], variables: tuple[str, ...]):
    """The matrix ``∂polys/∂variables`` (rows: polys, columns: variables)."""
    return tuple(tuple(p.derivative(v) for v in variables) for p in polys)


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


def _legs(spec: RobotSpec) -> tuple[Leg, ...]:
    joints = spec.joints
    found: dict[str, Leg] = {}
    for index, f in enumerate(spec.constraints):
        involved = [j for j in joints if f.degrees()[joints.index(j)] > 0]
        line = spec.constraint_lines[index]
        key = f"constraints[{index}]"
        if len(involved) != 1:
            what = "no actuated joint" if not involved else "joints " + ", ".join(involved)
            raise UnsupportedRobotError(
                f"involves {what}; singcheck certifies leg-decoupled robots, where each "
                "constraint involves exactly one actuated joint",
                path=spec.path, line=line, key=key)
        joint = involved[0]
        if joint in found:
            raise UnsupportedRobotError(
                f"joint {joint} already appears in constraints[{found[joint].constraint_index}];"
                " each actuated joint must drive exactly one leg constraint",
                path=spec.path, line=line, key=key)
        j = joints.index(joint)
        degree = f.degrees()[j]
        if degree > 2:
            raise UnsupportedRobotError(
                f"is of degree {degree} in {joint}; singcheck supports legs of degree 1 or 2 "
                "in their joint (prismatic or distance legs)", path=spec.path, line=line, key=key)
        if not coefficient_in(f, j, degree).is_constant():
            raise UnsupportedRobotError(
                f"the coefficient of {joint}^{degree} depends on the pose; singcheck needs it "
                "constant so that the joint is integral over the pose (exact projection)",
                path=spec.path, line=line, key=key)
        found[joint] = Leg(joint, j, f, index, degree)
    return tuple(found[j] for j in joints)


def leg_coefficients(leg: Leg) -> tuple[fmpq_mpoly, ...]:
    """``(a, b, c)`` with ``constraint = a·ρ² + b·ρ + c`` (``(b, c)`` for a linear leg).

    Each coefficient is a polynomial in the pose variables (still in the robot's context).
    """
    return tuple(coefficient_in(leg.constraint, leg.joint_index, d)
                 for d in range(leg.degree, -1, -1))


def build_model(spec: RobotSpec) -> RobotModel:
    """F, A = ∂F/∂X, B = ∂F/∂ρ, det A, det B and the legs, from a parsed spec.

    Raises :class:`UnsupportedRobotError` (with the constraint's file and line) for a
    robot outside the leg-decoupled class, and when det A is identically zero.
    """
    if spec.angles or spec.radicals:
        what = "angles (sin/cos)" if spec.angles else "square roots"
        raise UnsupportedRobotError(
            f"the constraints use {what}: the spec language accepts them, but this version "
            "certifies only polynomial constraints with rational coefficients",
            path=spec.path, line=spec.lines.get("constraints"), key="constraints")
    constraints = tuple(spec.constraints)
    A = jacobian(constraints, spec.pose)
    B = jacobian(constraints, spec.joints)
    det_A = determinant(A)
    det_B = determinant(B)
    legs = _legs(spec)
    if det_A.is_zero():
        raise UnsupportedRobotError(
            "det A = det(∂F/∂pose) is identically zero: the robot is singular everywhere",
            path=spec.path, line=spec.lines.get("constraints"), key="constraints")
    return RobotModel(spec, spec.context, spec.joints, spec.pose, constraints, A, B, det_A,
                      det_B, legs)
