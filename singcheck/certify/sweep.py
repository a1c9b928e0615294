"""The legs' quick feasibility proofs, every leg in one walk over the pieces.

:mod:`.working_modes` first tries to prove, by ball arithmetic on balls covering the
range, that a leg's discriminant D is > 0 (both branches real and apart) and that a
branch stays strictly inside its joint limits.  Made leg after leg, each leg encloses
sin t and cos t over every piece again and goes through its own memo of enclosures.
Here the pieces are walked once for all the legs that allow it: per piece, sin t and
cos t are enclosed once and each leg's a, b and D are enclosed from them by the ball
polynomials :func:`~singcheck.algebra.trig.evaluate_trig` uses (Horner in cos t,
outward rounding), and the branches by the same formulas as
:meth:`~singcheck.certify.path.LegAlongPath.branches`.

What is proven is what the leg-by-leg walk proves: a fact holds on every ball of a
cover of the range (the same pieces, a piece where it fails halved until the same
budget of evaluations is spent), hence on the whole range.  A fact the sweep does not
prove is left to :mod:`.working_modes`, which then goes straight to root isolation
(the quick proof was tried).  Swept: prismatic quadratic legs whose polynomials are
plain trig polynomials (no square root, no angle function) of low degree (no tight
enclosures needed); the others keep the leg-by-leg proofs.
"""

from __future__ import annotations

from flint import arb, arb_poly

from singcheck.algebra.trig import TRIG, ball_split, evaluate_split
from singcheck.budget import checkpoint
from singcheck.certify.path import inside_limits, limit_balls
from singcheck.model.robot import REVOLUTE

#: a fact: (leg index, None) for "D > 0", (leg index, label) for "the branch is inside"
Fact = tuple[int, str | None]


def sweep_quick_proofs(path, covers, limits_of: dict,
                       pieces, halves, budget_of) -> tuple[set[Fact], set[Fact]]:
    """(proven, tried): the facts proven on a cover of the range, and every fact tried.

    ``covers`` are the legs' :class:`~singcheck.certify.working_modes._Cover`; ``pieces``,
    ``halves`` and ``budget_of`` the working-mode module's own cover functions (passed in
    so that both walks cut the range alike)."""
    groups: list[tuple[object, list[int]]] = []  # (range, legs covering it)
    for i, (leg, cover) in enumerate(zip(path.legs, covers, strict=True)):
        if not _sweepable(leg, cover):
            continue
        for rng, members in groups:
            if rng == cover.range:
                members.append(i)
                break
        else:
            groups.append((cover.range, [i]))
    proven: set[Fact] = set()
    tried: set[Fact] = set()
    for rng, members in groups:
        facts = _facts(path, covers, members, limits_of)
        tried |= set(facts)
        proven |= _walk(path, facts, pieces(rng), halves, budget_of(rng), limits_of)
    return proven, tried


def _sweepable(leg, cover) -> bool:
    polys = [p for p in (*leg.coefficients, leg.discriminant) if p is not None]
    return leg.leg.kind != REVOLUTE and leg.leg.degree == 2 and not cover.retry_tight \
        and all(p.context() is TRIG for p in polys)


def _facts(path, covers, members: list[int], limits_of: dict) -> list[Fact]:
    """D > 0 for each leg, and "inside" for each branch proven real and inside at the
    range start (one outside there, or complex, is decided without a sweep; an
    undecided one would fail)."""
    out: list[Fact] = []
    for i in members:
        leg, cover = path.legs[i], covers[i]
        out.append((i, None))
        limits = limits_of.get(leg.leg.joint)
        if limits is None:
            continue
        at_start = cover.branches(cover.start)
        out += [(i, label) for label in leg.labels if isinstance(at_start[label], arb)
                and inside_limits(leg.leg, at_start[label], limits) is True]
    return out


def _walk(path, facts: list[Fact], todo: list[arb], halves, budget: int,
          limits_of: dict) -> set[Fact]:
    """The facts that hold on every ball of the cover ``todo``, refined by halving.

    A quadratic leg's branches are (-b ± √D)/(2a) where D > 0, as
    :func:`~singcheck.certify.path.branch_values` makes them; a branch is inside when
    its ball lies strictly between the limits' balls, as
    :func:`~singcheck.certify.path.inside_limits` decides."""
    legs = {}
    for i, _ in facts:
        if i not in legs:
            leg = path.legs[i]
            limits = limits_of.get(leg.leg.joint)
            pa, pb, pd = (ball_split(p) for p in (leg.coefficients[0], leg.coefficients[1],
                                                  leg.discriminant))
            if isinstance(pa, arb_poly) and pa.degree() <= 0:  # a constant a: its ball
                pa = pa(arb(0))
            legs[i] = (pa, pb, pd, limit_balls(limits) if limits is not None else None)
    work = [(piece, facts) for piece in todo]
    queued = dict.fromkeys(facts, len(todo))
    spent = dict.fromkeys(facts, 0)
    failed: set[Fact] = set()
    while work:
        piece, pending = work.pop()
        checkpoint()
        s, c = piece.sin_cos()
        values: dict[int, list] = {}  # leg -> [D, D > 0, 2a, -b (when asked for)]
        still = []
        for f in pending:
            if f in failed:
                continue
            queued[f] -= 1
            spent[f] += 1
            i, label = f
            pa, pb, pd, limits = legs[i]
            hit = values.get(i)
            if hit is None:
                d = evaluate_split(pd, piece, s, c)
                hit = values[i] = [d, d > 0, None, None]
            if not hit[1]:
                still.append(f)
                continue
            if label is None:
                continue
            if hit[2] is None:
                a = pa if isinstance(pa, arb) else evaluate_split(pa, piece, s, c)
                hit[2], hit[3] = 2 * a, -evaluate_split(pb, piece, s, c)
            root = hit[0].sqrt()
            rho = (hit[3] + root if label == "+" else hit[3] - root) / hit[2]
            if not (rho > limits[0] and rho < limits[1]):
                still.append(f)
        for f in still:
            if spent[f] + queued[f] + 2 > budget:
                failed.add(f)
        still = [f for f in still if f not in failed]
        if still:
            for half in halves(piece):
                work.append((half, still))
            for f in still:
                queued[f] += 2
    return {f for f in facts if f not in failed}
