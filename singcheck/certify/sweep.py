"""The legs' quick feasibility proofs, every leg in one walk over the pieces.

:mod:`.working_modes` first tries to prove, by ball arithmetic on balls covering the
range (:mod:`.covers`), that a leg's discriminant D is > 0 (both branches real and
apart) and that a branch stays strictly inside its joint limits.  Here the pieces are
walked once for all the legs: per piece, the pose coordinates φ(t) are enclosed over
the piece (Horner in cos t, or through the Fourier form on a wide piece for a
high-degree coordinate: :func:`~singcheck.algebra.trig.evaluate_trig`), and each leg's
a, b and D, polynomials in the robot's pose variables, are enclosed at those balls.
Each encloses its polynomial's values over every pose the piece reaches, hence over
every t of the piece; the branches are (-b ± √D)/(2a) where D > 0, as
:func:`~singcheck.certify.path.branch_values` makes them, and a branch is inside when
its ball lies strictly between the limits' balls, as
:func:`~singcheck.certify.path.inside_limits` decides.  Nothing is composed along the
path: a path whose quick proofs all pass never composes its legs.

A fact is proven when it holds on every ball of a cover of the range (a piece where it
fails is halved until the budget of evaluations is spent), hence on the whole range.
A fact the sweep does not prove is left to :mod:`.working_modes`, which then isolates
the roots that decide it.  Swept: prismatic quadratic legs and revolute legs (their
(cos θ, sin θ) branches from P·cos θ + Q·sin θ + R = 0 where Δ = P² + Q² − R² > 0,
:func:`~singcheck.certify.path.branch_values`, inside the limits as
:func:`~singcheck.certify.path.inside_limits` decides) of a robot free of square roots,
along a path whose coordinates are plain trig polynomials; the others keep the
leg-by-leg proofs.
"""

from __future__ import annotations

from flint import arb

from singcheck.algebra.intervals import evaluate
from singcheck.algebra.trig import ball_split, evaluate_split, evaluate_trig
from singcheck.budget import checkpoint
from singcheck.certify.covers import (
    TIGHT_ABOVE,
    TIGHT_DEGREE,
    budget,
    halves,
    one_period,
    pieces,
    within_one_period,
)
from singcheck.certify.path import (
    _branches_at_point,
    _branches_from,
    inside_limits,
    leg_polynomials,
    limit_balls,
)
from singcheck.model.robot import REVOLUTE

#: a fact: (leg index, None) for "D > 0", (leg index, label) for "the branch is inside"
Fact = tuple[int, str | None]

#: a coordinate of at least this degree in (sin t, cos t) is enclosed through its
#: Fourier form on wide pieces (a leg, quadratic in it, reaches the leg threshold)
TIGHT_COORDINATE = TIGHT_DEGREE // 2


def sweep_quick_proofs(path, limits_of: dict, starts: list[dict]
                       ) -> tuple[set[Fact], set[Fact]]:
    """(proven, tried): the facts proven on a cover of the range, and every fact tried.

    ``starts``: each leg's branches enclosed at the range start; a branch is tried only
    when it is real and proven inside its limits there (one outside is decided at the
    start; an undecided one would fail)."""
    if not path.legs_from_pose:
        return set(), set()
    facts: list[Fact] = []
    for i, leg in enumerate(path.legs):
        if leg.leg.kind != REVOLUTE and leg.leg.degree != 2:
            continue
        facts.append((i, None))
        limits = limits_of.get(leg.leg.joint)
        if limits is not None:
            facts += [(i, label) for label in leg.labels if _real(starts[i][label])
                      and inside_limits(leg.leg, starts[i][label], limits) is True]
    groups: list[tuple[object, list[Fact]]] = []  # (range, facts of the legs covering it)
    ranges: dict[int, object] = {}
    for f in facts:
        rng = ranges.get(f[0])
        if rng is None:
            rng = ranges[f[0]] = _leg_range(path, f[0])
        for known, members in groups:
            if known == rng:
                members.append(f)
                break
        else:
            groups.append((rng, [f]))
    proven: set[Fact] = set()
    for rng, members in groups:
        proven |= _walk(path, members, pieces(rng), budget(rng), limits_of)
    return proven, set(facts)


def _real(branch) -> bool:
    """A branch enclosed as real: a ball, or a revolute joint's (cos θ, sin θ) balls."""
    if isinstance(branch, tuple):
        return all(isinstance(v, arb) for v in branch)
    return isinstance(branch, arb)


def _leg_range(path, i: int):
    """The part of the range the quick proofs about leg ``i`` cover: one period when the
    coordinates its polynomials involve are free of the bare t (:func:`one_period`);
    the whole range when it is one period long at most (the leg's degrees unread)."""
    if within_one_period(path.trajectory.range):
        return path.trajectory.range
    offset = len(path.projection.model.joint_variables)
    degrees = [p.degrees() for p in leg_polynomials(path.legs[i].leg)]
    used = [x for k, x in enumerate(path.coordinates) if any(d[offset + k] > 0 for d in degrees)]
    return one_period(path.trajectory.range, used)


def _walk(path, facts: list[Fact], todo: list[arb], allowed: int,
          limits_of: dict) -> set[Fact]:
    """The facts that hold on every ball of the cover ``todo``, refined by halving."""
    model = path.projection.model
    legs = {}
    for i, _ in facts:
        if i not in legs:
            leg = path.legs[i].leg
            limits = limits_of.get(leg.joint)
            if leg.kind == REVOLUTE:  # its (cos θ, sin θ) branches from the pose's balls
                legs[i] = (REVOLUTE, leg, None, limits)
                continue
            a, b, d = leg_polynomials(leg)
            # a constant leading coefficient (the Orthoglide's 1): 2a once for all pieces
            legs[i] = (2 * evaluate(a, ()) if a.is_constant() else a, b, d,
                       limit_balls(limits) if limits else None)
    # revolute legs: every leg's polynomials (P, Q, R, Δ; a, b, D) by the path's compiled
    # program, once a piece; with prismatic legs alone each leg's D, then a and b, only
    # when asked (the lazier walk: 8% faster on an Orthoglide path whose pieces mostly
    # test one leg's limits)
    program, slices = path._legs_program
    if program is not None and (all(entry[0] is not REVOLUTE for entry in legs.values())
                                or any(slices[i][0] is not path.legs[i].leg for i in legs)):
        program = None
    coordinates = [(x, ball_split(x), x.degrees()[1] + x.degrees()[2] >= TIGHT_COORDINATE)
                   for x in path.trig_coordinates]  # (legs_from_pose: all in TRIG)
    head = [arb(0)] * len(model.joint_variables)
    work = [(piece, facts) for piece in todo]
    queued = dict.fromkeys(facts, len(todo))
    spent = dict.fromkeys(facts, 0)
    failed: set[Fact] = set()
    while work:
        piece, pending = work.pop()
        checkpoint()
        s, c = piece.sin_cos()
        wide = piece.rad() > TIGHT_ABOVE
        point = head + [evaluate_trig(x, piece, tight=True) if wide and high else
                        evaluate_split(split, piece, s, c) for x, split, high in coordinates]
        powers: dict = {}
        balls = program(point) if program is not None else None
        values: dict[int, list] = {}  # leg -> [D, D > 0, 2a, -b (when asked for)]
        still = []
        for f in pending:
            if f in failed:
                continue
            queued[f] -= 1
            spent[f] += 1
            i, label = f
            a, b, d, limits = legs[i]
            if a is REVOLUTE:
                hit = values.get(i)
                if hit is None:
                    both = _branches_from(b, balls[slices[i][1]:slices[i][2]]) \
                        if balls is not None else _branches_at_point(model, b, point, powers)
                    hit = values[i] = [both, all(_real(v) for v in both.values())]
                if not hit[1] or (label is not None and
                                  inside_limits(b, hit[0][label], limits) is not True):
                    still.append(f)
                continue
            hit = values.get(i)
            if hit is None:
                dv = evaluate(d, point, powers) if balls is None else balls[slices[i][1] + 2]
                hit = values[i] = [dv, dv > 0, None, None]
            if not hit[1]:
                still.append(f)
                continue
            if label is None:
                continue
            if hit[2] is None:
                if balls is None:
                    hit[2] = a if isinstance(a, arb) else 2 * evaluate(a, point, powers)
                    hit[3] = -evaluate(b, point, powers)
                else:  # (the program's a, b, D: the same sums as evaluate's)
                    at = slices[i][1]
                    hit[2] = a if isinstance(a, arb) else 2 * balls[at]
                    hit[3] = -balls[at + 1]
            root = hit[0].sqrt()
            rho = (hit[3] + root if label == "+" else hit[3] - root) / hit[2]
            if not (rho > limits[0] and rho < limits[1]):
                still.append(f)
        for f in still:
            if spent[f] + queued[f] + 2 > allowed:
                failed.add(f)
        still = [f for f in still if f not in failed]
        if still:
            for half in halves(piece):
                work.append((half, still))
            for f in still:
                queued[f] += 2
    return {f for f in facts if f not in failed}

