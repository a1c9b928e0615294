"""Exact numbers of real kinematic solutions at a rational point.

* :func:`inverse_kinematics_count`: at a pose X, the number of joint vectors ρ with
  F(ρ, X) = 0 inside the joint limits.  For a leg-decoupled robot this is the product
  over legs of the number of real roots of the leg's polynomial in its joint that lie
  in the joint's range; those roots are isolated exactly (Descartes/VCA) and compared
  with the limits on exact signs.
* :func:`direct_kinematics_count`: at a joint vector ρ, the number of real poses X with
  F(ρ, X) = 0.  A reduced lex Gröbner basis over Q (SymPy) in *shape position*,
  ``{x_1 - g_1(x_n), …, x_{n-1} - g_{n-1}(x_n), h(x_n)}`` with h squarefree, puts the
  solutions in bijection with the roots of h, real ones with real ones (the g_i have
  rational coefficients); the real roots of h are counted exactly.  When the basis is
  not in that shape, a rational linear change of coordinates is tried (it keeps the
  real solutions in bijection); if no shape is found the count is left undecided.
  A pose angle φ is the pair (cos φ, sin φ) with cos² + sin² = 1 (one real solution per
  φ in (-π, π]); a square root √p of the parameters is a variable r with r² = p, over Q
  (the norm, not Q(√p)), and only solutions with r > 0 (the robot, not its conjugate)
  are counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flint import acb, arb_poly, fmpq, fmpq_mpoly, fmpq_poly

from singcheck.algebra.intervals import fraction_ball, working_precision
from singcheck.algebra.polynomials import constant_value
from singcheck.budget import checkpoint
from singcheck.certify.path import branches_at_pose, inside_limits
from singcheck.elimination.projection import pose_circles
from singcheck.model.robot import REVOLUTE, RobotModel, leg_coefficients
from singcheck.roots.rational import rational_ball, to_fmpq
from singcheck.spaces.cad import separated_roots

_COORDINATE_CHANGES = ((), (1,), (1, -2), (3, 1, -1), (2, -3, 5, 1))


def roots_within(p: fmpq_poly, limits: tuple | None) -> int:
    """The number of distinct real roots of ``p`` in the closed range ``limits``
    (all real roots when ``limits`` is None)."""
    roots = separated_roots(p)
    if limits is None:
        return len(roots)
    lo, hi = (to_fmpq(v) for v in limits)
    return sum(1 for r in roots if r.compare(lo) >= 0 and r.compare(hi) <= 0)


def leg_polynomial_at(model: RobotModel, leg, pose_point) -> fmpq_poly:
    """The leg's polynomial in its joint at a rational pose (exact)."""
    values = {v: to_fmpq(q) for v, q in zip(model.pose, pose_point, strict=True)}
    coeffs = []
    for c in leg_coefficients(leg):
        value = c.subs(values) if values else c
        coeffs.append(constant_value(value))
    return fmpq_poly(coeffs[::-1])


def inverse_kinematics_count(model: RobotModel, pose_point, use_limits: bool = True) -> int:
    """Real IK solutions inside the joint limits (all of them when ``use_limits`` is
    False) at a rational pose (exact): the product over legs of their roots inside."""
    return ik_count(ik_root_placement(model, pose_point, use_limits))


def ik_count(placement: tuple[tuple[int, int, int], ...]) -> int:
    """The IK count from :func:`ik_root_placement`: the product of the legs' roots inside."""
    return math.prod(inside for _, inside, _ in placement)


def ik_root_placement(model: RobotModel, pose_point,
                      use_limits: bool = True) -> tuple[tuple[int, int, int], ...]:
    """Per leg, its distinct real joint roots below, inside and above the joint's range
    at a rational pose (exact; all 'inside' for a joint without limits, or when
    ``use_limits`` is False).

    Off the serial-singularity and joint-limit surfaces this is constant on every
    connected set: roots move continuously (the leading coefficient is constant), meet
    only where the discriminant vanishes and pass a limit only where the leg polynomial
    vanishes at it.  It refines the IK count (the product of the 'inside' entries).
    """
    if not model.polynomial:
        return _placement_by_balls(model, pose_point, use_limits)
    limits = model.spec.joint_limits if use_limits else {}
    out = []
    for leg in model.legs:
        roots = separated_roots(leg_polynomial_at(model, leg, pose_point))
        if leg.joint not in limits:
            out.append((0, len(roots), 0))
            continue
        lo, hi = (to_fmpq(v) for v in limits[leg.joint])
        below = sum(1 for r in roots if r.compare(lo) < 0)
        above = sum(1 for r in roots if r.compare(hi) > 0)
        out.append((below, len(roots) - below - above, above))
    return tuple(out)


_PRECISIONS = (64, 256, 1024, 4096)


def _placement_by_balls(model: RobotModel, point, use_limits: bool):
    """:func:`ik_root_placement` for a robot with square roots or angles, at a rational
    point of its pose variables (cos φ, sin φ of an angle: rational in the chart).

    Each branch is enclosed by ball arithmetic (√p exact to the working precision),
    raising the precision until every decision is proven: a branch real or complex (the
    sign of the discriminant), below, inside or above a prismatic joint's range, inside
    or outside an angle joint's (:func:`~singcheck.certify.path.inside_limits`).  Off the
    discriminant variety (a cell's sample) none of those quantities is zero — the
    variety holds their norms over the square roots — so a precision decides them all.
    A revolute leg's entry is (0, inside, outside).  Raises ArithmeticError when even
    4096 bits decide nothing (a point on a surface).
    """
    limits = model.spec.joint_limits if use_limits else {}
    for prec in _PRECISIONS:
        with working_precision(prec):
            pose = [fraction_ball(q) for q in point]
            out = [_leg_placement(leg, branches_at_pose(model, leg, pose),
                                  limits.get(leg.joint)) for leg in model.legs]
        if None not in out:
            return tuple(out)
    raise ArithmeticError(f"the inverse kinematics at {list(point)} is not decided at "
                          f"{_PRECISIONS[-1]} bits (a point on a surface of the variety)")


def _leg_placement(leg, branches: dict, limits):
    """(below, inside, above) of one leg's real branches, or None if not decided."""
    below = inside = above = 0
    for value in branches.values():
        if value is None:
            return None
        if isinstance(value, acb) or (isinstance(value, tuple) and isinstance(value[0], acb)):
            continue  # a complex branch
        if limits is None:
            inside += 1
        elif leg.kind == REVOLUTE:
            where = inside_limits(leg, value, limits)
            if where is None:
                return None
            inside += where
            above += not where
        else:
            lo, hi = (fraction_ball(v) for v in limits)
            if value < lo:
                below += 1
            elif value > hi:
                above += 1
            elif value > lo and value < hi:
                inside += 1
            else:
                return None
    return below, inside, above


@dataclass(frozen=True)
class DirectCount:
    count: int | None
    reason: str = ""  # why it is None


#: The largest Bézout bound (product of the degrees of the direct-kinematics system in
#: its unknowns) whose count is attempted: the Deltas' and the 3-RPR's are 16; the
#: Gough–Stewart's (40 assembly modes, 9 unknowns: 32768) is far beyond a SymPy lex basis.
MAX_DIRECT_BEZOUT = 256


def direct_unknowns(model: RobotModel) -> tuple[str, ...]:
    """The unknowns of the direct kinematics: the square roots' variables, then the pose
    variables (cos, sin of an angle) — a pose variable last, the coordinate solved for."""
    return (*model.spec.radical_variables, *model.pose_variables)


def direct_system(model: RobotModel) -> tuple[fmpq_mpoly, ...]:
    """F with each pose angle's circle cos² + sin² - 1 and each square root's
    ``sqrt(p)² - p`` (in the robot's context; the joints still free)."""
    return (*model.constraints, *pose_circles(model),
            *(leg.constraint for leg in model.radical_legs))


def direct_bezout_bound(model: RobotModel) -> int:
    """Bézout's bound on the number of isolated solutions of :func:`direct_system` in
    its unknowns at any joint vector."""
    names = model.context.names()
    index = [names.index(v) for v in direct_unknowns(model)]
    return math.prod(max((sum(e[i] for i in index) for e, _ in f.terms()), default=0)
                     for f in direct_system(model))


def direct_kinematics_count(model: RobotModel, joint_point) -> DirectCount:
    """Real DK solutions (poses) at a rational joint vector, from a shape-position basis.

    The unknowns are :func:`direct_unknowns`: a pose angle φ as (cos φ, sin φ) on its
    circle (a real solution is a real point of the circle: one φ in (-π, π]), and each
    square root √p of the parameters as a variable r with r² = p.  The system is over Q;
    its solutions are those of the robot (r = +√p) and of its conjugates (r = -√p), and
    only those with every r > 0 are counted: in the basis r = g_r(t) with g_r rational,
    and the sign of g_r at each real root t of h is decided on the root's isolating
    interval by ball arithmetic (|g_r(t)| = √p, so refining ends).
    """
    import sympy

    unknowns = direct_unknowns(model)
    names = model.context.names()
    index = [names.index(v) for v in unknowns]
    syms = sympy.symbols(f"v0:{len(unknowns)}")
    values = {j: to_fmpq(q) for j, q in zip(model.joint_variables, joint_point, strict=True)}
    system = [_to_sympy(f.subs(values) if values else f, syms, index)
              for f in direct_system(model)]
    radicals = len(model.spec.radical_variables)
    last = syms[-1]
    # with a square root, the last pose coordinate alone rarely separates the robot's
    # poses from its conjugate's (the linear Delta's are mirror images with the same z):
    # the shift by r, (1,), is tried first
    changes = _COORDINATE_CHANGES[1:2] + _COORDINATE_CHANGES[:1] + _COORDINATE_CHANGES[2:] \
        if radicals else _COORDINATE_CHANGES
    for change in changes:
        checkpoint()
        shift = sum((c * v for c, v in zip(change, syms[:-1], strict=False)), sympy.Integer(0))
        changed = [sympy.expand(e.subs(last, last - shift)) for e in system]
        basis = sympy.groebner(changed, *syms, order="lex", domain="QQ")
        exprs = list(basis.exprs)
        if exprs == [1]:
            return DirectCount(0)
        shape = _shape_position(exprs, syms, radicals)
        if shape is not None:
            return _count_on_positive_roots(*shape)
    return DirectCount(None, "no coordinate change put the Gröbner basis in shape position "
                             "(solutions at infinity, multiple or infinitely many)")


def _count_on_positive_roots(h: fmpq_poly, radicals: list[fmpq_poly]) -> DirectCount:
    """The real roots t of h at which every ``g`` of ``radicals`` is positive."""
    count = 0
    for root in separated_roots(h):
        checkpoint()
        signs = [_sign_at_root(g, root) for g in radicals]
        if None in signs:
            return DirectCount(None, "the sign of a square root at a solution was not "
                                     f"decided at {_MAX_ROOT_BITS} bits")
        count += all(s > 0 for s in signs)
    return DirectCount(count)


_MAX_ROOT_BITS = 4096


def _sign_at_root(g: fmpq_poly, root) -> int | None:
    """The sign of ``g`` at the root isolated by ``root`` (g non-zero there), by ball
    arithmetic on the isolating interval, refined until it decides; None past
    :data:`_MAX_ROOT_BITS` bits of width."""
    if root.lo == root.hi:
        value = g(root.lo)
        return (value > 0) - (value < 0)
    while True:
        checkpoint()
        width = root.width()
        bits = 64 + max(0, int(width.q).bit_length() - int(width.p).bit_length())
        if bits > _MAX_ROOT_BITS:
            return None
        with working_precision(bits):
            value = arb_poly(g)(rational_ball(root.lo, root.hi))
        if value > 0:
            return 1
        if value < 0:
            return -1
        root.bisect_to(width / 256)


def _to_sympy(poly, syms, index):
    """``poly`` (its other variables at degree 0) in the SymPy symbols ``syms``, the
    variable of ``syms[k]`` at position ``index[k]`` of the context."""
    import sympy

    expr = sympy.Integer(0)
    for exps, c in poly.terms():
        term = sympy.Rational(int(c.p), int(c.q))
        for var, i in zip(syms, index, strict=True):
            term *= var ** exps[i]
        expr += term
    return expr


def _shape_position(exprs, pose, wanted: int = 0) -> tuple[fmpq_poly, list[fmpq_poly]] | None:
    """(h, [g_1, …, g_wanted]) when ``exprs`` is ``{x_i - g_i(x_n)}`` plus a squarefree
    h(x_n), else None."""
    import sympy

    if len(exprs) != len(pose):
        return None
    last = pose[-1]
    *linear, h = exprs
    coordinates = []
    for var, g in zip(pose[:-1], linear, strict=True):
        p = sympy.Poly(g, *pose)
        lead = p.coeff_monomial(var)
        if p.degree(var) != 1 or lead == 0:
            return None
        rest = g - lead * var
        if rest.free_symbols - {last}:
            return None
        if len(coordinates) < wanted:
            coordinates.append(_univariate(-rest / lead, last))
    hp = sympy.Poly(h, *pose)
    if hp.free_symbols - {last} or hp.degree(last) < 1:
        return None
    h = _univariate(h, last)
    if h.gcd(h.derivative()).degree() > 0:
        return None
    return h, coordinates


def _univariate(expr, var) -> fmpq_poly:
    import sympy

    coeffs = sympy.Poly(sympy.expand(expr), var).all_coeffs()[::-1]
    return fmpq_poly([fmpq(int(c.p), int(c.q)) for c in coeffs])
