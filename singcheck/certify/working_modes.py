"""Working modes along a path and which of them are feasible, with proofs.

A working mode picks one inverse-kinematics branch per leg (``+``/``-`` in front of √D,
``o`` for a linear leg), e.g. ``+++`` for the Orthoglide prototype.  A mode is
*feasible* when each of its branches is real, never meets the leg's other branch, and
stays inside the joint limits over the whole closed range.  How each part is proven:

1. **Real and separated.**  The roots of the leg's discriminant D(t) on the range are
   isolated with certified intervals.  No root and D > 0 at one point (ball
   arithmetic) proves D > 0 on the whole range by continuity: both branches are real
   and distinct (no serial singularity).  A root means the branches meet: the path
   reaches the workspace boundary (det B = 0) and the leg's modes are infeasible.
   A quick proof comes first: D > 0 in ball arithmetic on each of 6 pieces covering
   the range; only when it fails are the roots of D isolated.
2. **Inside the limits.**  A branch equals a limit L only at roots of the leg
   constraint with ρ = L.  Those roots cut the range into open gaps in which the branch
   is never equal to a limit, so it is inside or outside over each whole gap; one
   ball evaluation at a point of each gap decides which.  Touching a limit is inside
   (the limits are closed).  Quick proofs come first: a branch certainly outside the
   limits at the range start is infeasible, and one certainly inside them on each of
   6 pieces covering the range is feasible, without isolating any root.
Whatever cannot be proven makes the branch ``unknown``, with the reason.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from itertools import product

from flint import arb, ctx

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.radicals import evaluate_path, is_opaque
from singcheck.algebra.trig import TimeRange
from singcheck.budget import checkpoint
from singcheck.certify.covers import TIGHT_ABOVE, TIGHT_DEGREE, one_period
from singcheck.certify.covers import budget as _budget
from singcheck.certify.covers import halves as _halves
from singcheck.certify.covers import pieces as _pieces
from singcheck.certify.exact import vanishes_at_root
from singcheck.certify.path import LegAlongPath, PathModel, joint_float
from singcheck.certify.sweep import sweep_quick_proofs
from singcheck.roots.enclosures import IN_MIXED, IdenticallyZeroError, RootIsolation
from singcheck.roots.isolation import isolate_real_roots

FEASIBLE, INFEASIBLE, UNKNOWN = "feasible", "infeasible", "unknown"
_PRECISIONS = (53, 128, 384)


@dataclass(frozen=True)
class BranchFeasibility:
    joint: str
    label: str
    status: str  # feasible | infeasible | unknown
    reason: str = ""
    event_time: arb | None = None  # where it leaves (limit crossing or branch meeting)
    proof: str = ""  # the exact decisions it rests on, if any (ball arithmetic otherwise)


@dataclass
class WorkingMode:
    label: str  # one character per leg, in joint order
    branches: tuple[BranchFeasibility, ...]
    status: str
    reason: str
    joints_at_start: dict[str, float | None]
    singular_times: list = field(default_factory=list)  # filled by certification
    proof: str = ""  # the exact decisions its feasibility rests on ("": ball arithmetic)

    @property
    def feasible(self) -> bool:
        return self.status == FEASIBLE


def gap_points(interval: TimeRange, events: list[arb]) -> list[arb]:
    """One exact point strictly inside each gap between the events (sorted balls).

    Gaps run from the range start to the first event, between consecutive events,
    and from the last event to the range end; an empty gap yields no point.
    """
    bounds = [interval.start.ball(), *sorted(events, key=lambda b: b.mid()), interval.end.ball()]
    points = []
    for left, right in zip(bounds, bounds[1:], strict=False):
        lo, hi = left.upper(), right.lower()
        if lo < hi:
            mid = ((lo + hi) / 2).mid()
            if lo < mid < hi:
                points.append(mid)
    return points


def _aperiodic_variables(ctx) -> list[int]:
    """Indices of a path ring's variables that are functions of t with no known period
    (angle functions, opaque coordinates)."""
    from singcheck.algebra.radicals import angle_function_of, opaque_of

    return [i for i, n in enumerate(ctx.names()) if i >= 3 and (
        angle_function_of(n) is not None or opaque_of(n) is not None)]


#: what :func:`_isolate` returns for a polynomial of an opaque path (no exact isolation:
#: its feasibility is decided by :func:`_by_intervals` alone)
OPAQUE = "opaque"


def _isolate(poly, interval: TimeRange, tolerance: float) -> RootIsolation | None | str:
    if is_opaque(poly.context()):
        return OPAQUE
    try:
        return isolate_real_roots(poly, interval, tolerance, vanishes_at_root)
    except IdenticallyZeroError:
        return None


def _high_degree(degrees: list) -> bool:
    """Whether Horner in cos t is likely to overestimate badly on wide pieces (from the
    degrees in (t, s, c, …) of the leg's polynomials)."""
    return max(d[1] + d[2] for d in degrees) >= TIGHT_DEGREE


def _leg_polys(leg: LegAlongPath):
    return (*leg.coefficients, leg.discriminant)


class _Cover:
    """The balls that the quick proofs about one leg try, with the leg's enclosures on
    each computed once.

    The reality proof (D > 0 on every piece) and each branch's limit proof walk the same
    balls: the pieces covering (one period of) the range, halved the same way where a
    proof fails, and the range start.  Each ball's enclosures of a, b and D (and the
    branches made from them) are computed the first time a proof asks and then shared:
    the same enclosures of the same balls as evaluating them each time, so every proof
    is the one it was, at a fraction of the evaluations.  A leg whose polynomials are
    all constants along the path (the Orthoglide's z leg on a planar path) has the same
    enclosures on every ball: they are computed once."""

    def __init__(self, leg: LegAlongPath, interval: TimeRange) -> None:
        self.leg = leg
        self.interval = interval
        self.start = interval.start.ball()
        self._pieces: list[arb] | None = None
        self._halves: dict[int, tuple[arb, arb, arb]] = {}
        self._seen: dict[tuple[int, bool, int], list] = {}  # -> [ball, D, branches]

    @cached_property
    def _degrees(self) -> list:
        """The degrees of the leg's polynomials along the path (composing them)."""
        return [p.degrees() for p in _leg_polys(self.leg) if p is not None]

    @cached_property
    def range(self) -> TimeRange:
        return one_period(self.interval, (), periodic=self.periodic)

    @cached_property
    def periodic(self) -> bool:
        """Whether the leg's polynomials are 2π-periodic in t: free of the bare t and of
        every variable that is a function of t other than sin t and cos t (a pose
        angle's cos g(t), an opaque coordinate: neither need be periodic)."""
        polys = [p for p in _leg_polys(self.leg) if p is not None]
        return all(d[0] <= 0 for d in self._degrees) and not any(
            d[i] > 0 for p in polys for d in [p.degrees()]
            for i in _aperiodic_variables(p.context()))

    @cached_property
    def retry_tight(self) -> bool:
        return _high_degree(self._degrees)

    @cached_property
    def budget(self) -> int:
        return _budget(self.range)

    @cached_property
    def constant(self) -> bool:
        return all(max(d) <= 0 for d in self._degrees)

    def pieces(self) -> list[arb]:
        """:func:`_pieces` of the range (the same balls every time they are asked for)."""
        if self._pieces is None:
            self._pieces = _pieces(self.range)
        return list(self._pieces)

    def halves(self, piece: arb) -> tuple[arb, arb]:
        """:func:`_halves` of a piece (the same balls every time they are asked for)."""
        hit = self._halves.get(id(piece))
        if hit is None or hit[0] is not piece:
            hit = self._halves[id(piece)] = (piece, *_halves(piece))
        return hit[1], hit[2]

    def _entry(self, t: arb, tight: bool) -> list:
        if self.constant:  # one entry for every ball
            key = (0, False, ctx.prec)
            hit = self._seen.get(key)
            if hit is None:
                hit = self._seen[key] = [t, None, None]
            return hit
        key = (id(t), tight, ctx.prec)
        hit = self._seen.get(key)
        if hit is None or hit[0] is not t:  # the entry holds t: its id is not reused
            hit = self._seen[key] = [t, None, None]
        return hit

    def discriminant(self, t: arb, tight: bool = False) -> arb:
        """The enclosure of D over the ball ``t``."""
        entry = self._entry(t, tight)
        if entry[1] is None:
            entry[1] = self.leg.discriminant_at(t, tight)
        return entry[1]

    def branches(self, t: arb, tight: bool = False) -> dict:
        """:meth:`LegAlongPath.branches` over the ball ``t`` (D's enclosure shared)."""
        entry = self._entry(t, tight)
        if entry[2] is None:
            if self.leg.discriminant is not None and entry[1] is None:
                entry[1] = evaluate_path(self.leg.discriminant, t, tight=tight)
            entry[2] = self.leg.branches(t, tight, discriminant=entry[1])
        return entry[2]


def _everywhere(predicate, interval: TimeRange, retry_tight: bool = True,
                cover: _Cover | None = None) -> bool:
    """True when ``predicate(ball, tight)`` is proven on balls covering the whole range:
    a quick proof by ball arithmetic that spares a root isolation (False means "not
    proven").  With ``retry_tight`` a wide piece is tried with ``tight`` enclosures at
    once (they include the plain one, which the polynomials' degree makes fail there);
    a piece where it fails is halved (ball enclosures tighten as pieces shrink) until a
    budget of evaluations is spent.  With ``cover`` (whose range is ``interval``) the
    pieces and halves are the cover's, so that proofs about one leg share its
    enclosures."""
    todo = cover.pieces() if cover is not None else _pieces(interval)
    halves = cover.halves if cover is not None else _halves
    budget = cover.budget if cover is not None else _budget(interval)
    spent = 0
    while todo:
        piece = todo.pop()
        checkpoint()
        spent += 1
        if predicate(piece, retry_tight and piece.rad() > TIGHT_ABOVE):
            continue
        if spent + len(todo) + 2 > budget:
            return False
        todo += halves(piece)
    return True


def _leg_reality(leg: LegAlongPath, interval: TimeRange, tolerance: float, when,
                 cover: _Cover | None = None, quick: bool = True, exact=None):
    """Status of both branches of a quadratic leg with respect to step 1 (``when``
    writes a time ball in the user's parameter; ``quick=False`` when the quick proof
    was tried already, by :mod:`.sweep`; ``exact``: :func:`_exact_touch` of the leg, for
    a path only ball arithmetic reads)."""
    joint = leg.leg.joint
    cover = cover or _Cover(leg, interval)
    if quick and _everywhere(lambda t, tight: cover.discriminant(t, tight) > 0,
                             cover.range, cover.retry_tight, cover):
        return FEASIBLE, "", None
    iso = _isolate(leg.discriminant, interval, tolerance)
    if iso == OPAQUE:
        bad = _by_intervals(cover, lambda t: cover.discriminant(t) > 0,
                            lambda t: cover.discriminant(t) < 0, exact)
        if bad is True:
            return FEASIBLE, "", None
        if isinstance(bad, tuple):  # decided at an exact time
            return INFEASIBLE, bad[1], bad[0]
        if bad is not None:
            return INFEASIBLE, f"{joint} has no real solution at t ≈ {when(bad)} (the path " \
                "leaves the workspace)", bad
        return UNKNOWN, f"could not prove that the branches of {joint} stay real and apart " \
            f"({_OPAQUE_WHY})", None
    if iso is None:
        return INFEASIBLE, f"the two branches of {joint} coincide along the whole path " \
            "(serial singularity)", None
    if iso.roots:
        t = iso.roots[0].t
        return INFEASIBLE, f"the two branches of {joint} meet at t ≈ {when(t)} " \
            "(serial singularity: the path reaches the workspace boundary)", t
    for box in iso.undecided:
        checkpoint()
        if not evaluate_path(leg.discriminant, box.t) > 0:
            return UNKNOWN, f"could not prove that the branches of {joint} stay apart: " \
                f"{box.reason}", box.t
    for prec in _PRECISIONS:
        with working_precision(prec):
            d = evaluate_path(leg.discriminant, interval.start.ball())
        if d > 0:
            return FEASIBLE, "", None
        if d < 0:
            return INFEASIBLE, f"{joint} has no real solution along the path: both its " \
                "branches are complex from the start to the end (outside the workspace)", None
    return UNKNOWN, f"the sign of the discriminant of {joint} could not be decided", None


def _branch_limits(leg: LegAlongPath, label: str, interval: TimeRange, limits,
                   tolerance: float, crossings: dict, when,
                   cover: _Cover | None = None, quick: bool = True,
                   at_start: dict | None = None) -> BranchFeasibility:
    """Whether this branch stays strictly inside the joint limits along the whole path.

    ``crossings`` memoises, per limit value, the isolated times at which *some* branch of
    the leg equals it (one polynomial serves both branches); ``cover`` shares the quick
    proofs' enclosures with the leg's other proofs; ``quick=False`` when the quick proof
    was tried already (by :mod:`.sweep`); ``at_start``, the leg's branches enclosed at
    the range start when the caller has them."""
    joint = leg.leg.joint
    cover = cover or _Cover(leg, interval)
    opaque = _exact_limits_unavailable(leg, limits)
    start = at_start if at_start is not None else cover.branches(cover.start)
    if leg.inside(start[label], limits) is False:
        return BranchFeasibility(joint, label, INFEASIBLE,
                                 f"{joint} is outside {_bounds(limits)} from the start")
    if quick and _everywhere(lambda t, tight: leg.inside(cover.branches(t, tight)[label],
                                                          limits) is True,
                             cover.range, cover.retry_tight, cover):
        return BranchFeasibility(joint, label, FEASIBLE)
    if opaque:
        bad = _by_intervals(cover, lambda t: leg.inside(cover.branches(t)[label],
                                                         limits) is True,
                            lambda t: leg.inside(cover.branches(t)[label], limits) is False)
        if bad is True:
            return BranchFeasibility(joint, label, FEASIBLE)
        if bad is not None:
            return BranchFeasibility(joint, label, INFEASIBLE,
                                     f"{joint} is outside {_bounds(limits)} at t ≈ "
                                     f"{when(bad)}", bad)
        return BranchFeasibility(joint, label, UNKNOWN,
                                 f"could not prove that {joint} stays inside "
                                 f"{_bounds(limits)} ({_OPAQUE_WHY})")
    events: list[arb] = []
    undecided = []
    exact: list[str] = []  # limits met where p and a conjugate both vanish: decided exactly
    on_limit: dict = {}  # limit value -> w = 2aL + b, for a limit some branch sits on
    for value in limits:
        if value not in crossings:
            crossings[value] = _isolate(leg.limit_polynomial(value), interval, tolerance)
        iso = crossings[value]
        if iso is None:
            if leg.leg.degree == 1:  # the only branch is the limit all along: inside
                return BranchFeasibility(joint, label, FEASIBLE)
            w = _switch_polynomial(leg, value)
            on_limit[value] = w
            iso = _isolate(w, interval, tolerance)
            if iso is None:  # D = w² ≡ 0: the branches coincide (found by step 1)
                return BranchFeasibility(joint, label, UNKNOWN,
                                         f"both branches of {joint} sit on its limit {value}")
        events += [r.t for r in iso.roots]
        undecided += list(iso.undecided)
        exact += [f"{joint} {'=' if kept else '≠'} {value} at t ≈ {when(r.t)} exactly "
                  f"({_field(r)}: balls cannot tell the robot from a conjugate, √p ↦ -√p, "
                  "there)" for r, kept in iso.exact]
    for box in undecided:
        checkpoint()
        if leg.inside(leg.branches(box.t)[label], limits) is not True:
            return BranchFeasibility(joint, label, UNKNOWN,
                                     f"limit crossing of {joint} not decided: {box.reason}")
    events += [box.t for box in undecided]
    for point in gap_points(interval, events):
        checkpoint()
        verdict = None
        for prec in _PRECISIONS:
            with working_precision(prec):
                verdict = leg.inside(leg.branches(point)[label], limits)
                if verdict is None and _sits_on_limit(leg, label, on_limit, point):
                    verdict = True  # exactly on a (closed) limit over this whole gap
            if verdict is not None:
                break
        if verdict is None:
            return BranchFeasibility(joint, label, UNKNOWN,
                                     f"could not place {joint} against its limits at "
                                     f"t = {when(point)}")
        if verdict is False:
            crossing = max((e for e in events if e < point), key=lambda b: b.mid(),
                           default=None)
            reason = f"{joint} is outside {_bounds(limits)} from the start" \
                if crossing is None else \
                f"{joint} leaves {_bounds(limits)} at t ≈ {when(crossing)}"
            return BranchFeasibility(joint, label, INFEASIBLE, reason, crossing,
                                     "; ".join(exact))
    return BranchFeasibility(joint, label, FEASIBLE, proof="; ".join(exact))


#: how feasibility was tried where no exact isolation exists (a path kept as expression
#: trees, an angle limit that is not a multiple of π/12)
_OPAQUE_WHY = "by ball arithmetic alone"


def _exact_limits_unavailable(leg: LegAlongPath, limits) -> bool:
    """Whether the limits' crossings cannot be isolated exactly: the path is opaque, or
    an angle limit is not a multiple of π/12 (its cos and sin are not algebraic)."""
    from singcheck.elimination.projection import exact_angle_limit

    if leg._composer.balls_only:  # (read from the path: composing nothing)
        return True
    if not leg.revolute:
        return not all(isinstance(v, Fraction) for v in limits)  # 2*sqrt(2), pi
    return not all(exact_angle_limit(v) for v in limits)


#: evaluations per 2π an interval-only feasibility proof may spend (a leg's branch)
INTERVAL_ONLY_BUDGET = 4000


def _by_intervals(cover: _Cover, good, bad, exact=None) -> bool | arb | tuple | None:
    """An interval-only proof over the cover's range: True when ``good(piece)`` holds on
    balls covering it; else the first exact point found where ``bad(point)`` is proven
    (a ball of a time); None when the budget of evaluations ends first.  Each failing
    piece is tried at its midpoint (an exact point), then halved.  When the budget ends,
    ``exact(piece)`` (if given) is asked of the pieces left, narrowest first: its
    (time, reason) where it decides the bad case exactly (a touch the balls cannot see
    the sign of), returned as it is."""
    import math

    todo = cover.pieces()
    rng = cover.range
    periods = max(1.0, (float(rng.end) - float(rng.start)) / (2 * math.pi))
    spent, budget = 0, max(cover.budget, int(INTERVAL_ONLY_BUDGET * periods))
    while todo:
        piece = todo.pop()
        checkpoint()
        spent += 1
        if good(piece):
            continue
        point = arb(piece.mid())
        if bad(point):
            return point
        if spent + len(todo) + 2 > budget:
            if exact is not None:
                for left in sorted([piece, *todo], key=lambda b: b.rad())[:MAX_EXACT_TRIES]:
                    found = exact(left)
                    if found is not None:
                        return found
            return None
        todo += cover.halves(piece)
    return True


#: pieces left by an interval-only proof that are tried at an exact time
MAX_EXACT_TRIES = 16


def _field(root) -> str:
    """Where :func:`~singcheck.certify.exact.vanishes_at_root` decided at this root."""
    if root.exact.kind == IN_MIXED:
        return "at a transcendental time, in Q(τ, sin τ, cos τ)(√p)"
    return "algebraic, in Q(α)(√p)"


def _bounds(limits) -> str:
    return f"[{limits[0]}, {limits[1]}]"


def _switch_polynomial(leg: LegAlongPath, value) -> object:
    """w = 2aL + b(t) for a limit L that the leg constraint has as a root all along
    (a L² + b L + c ≡ 0).  Then D = b² - 4ac = w², so √D = |w| and the branch with sign
    σ is exactly L where σ·w ≥ 0 and L - w/a (≠ L) where σ·w < 0: the roots of w are
    where a branch gets on or off the limit, the events that replace the limit's
    crossings.

    For a revolute leg a·cos θ + b·sin θ + d with a·cos L + b·sin L + d ≡ 0,
    w = b·cos L - a·sin L: then Δ = a² + b² - d² = w², and the branch σ
    (W·cos θ = -a·d + σ·b·√Δ, W·sin θ = -b·d - σ·a·√Δ) is exactly L where σ·√Δ = w,
    i.e. where σ·w ≥ 0 — the same rule."""
    from flint import fmpq

    if leg.revolute:
        from singcheck.algebra.radicals import surd_polynomial
        from singcheck.elimination.projection import angle_limit_values

        a, b, _ = leg.coefficients
        cos_l, sin_l = angle_limit_values(leg.leg.joint, value)
        ring = a.context()
        return b * surd_polynomial(cos_l, ring) - a * surd_polynomial(sin_l, ring)
    a, b, _ = leg.coefficients
    return b + 2 * a * fmpq(value.numerator, value.denominator)


def _sits_on_limit(leg: LegAlongPath, label: str, on_limit: dict, point: arb) -> bool:
    """True when the branch equals one of the limits in ``on_limit`` exactly at ``point``
    (σ·w(point) > 0, proven; see :func:`_switch_polynomial`), hence over the whole gap
    between two roots of w that holds it."""
    sigma = 1 if label == "+" else -1
    return any(sigma * evaluate_path(w, point) > 0 for w in on_limit.values())


def _exact_touch(path: PathModel, leg: LegAlongPath):
    """``exact(piece)`` for :func:`_by_intervals`: the leg's discriminant at the simplest
    rational time of the piece (or an integer multiple of π in it), where the pose is
    known exactly: (the time's ball, why the mode is infeasible) when it is 0 (the
    branches meet: y = 3/2·cos(t − 1) against a leg of 3/2 at t = 1) or < 0; None
    otherwise."""
    from singcheck.certify.rational_pose import leg_discriminant_at, pose_values, simple_times

    model = path.projection.model
    rng = path.trajectory.range
    joint = leg.leg.joint

    def exact(piece: arb):
        for point in simple_times(float(piece.lower()), float(piece.upper()), rng):
            d = leg_discriminant_at(model, leg.leg, pose_values(path, point))
            at = f"{float(path.trajectory.to_global(point.ball()).mid()):.12g}"
            if d is not None and d == 0:
                return point.ball(), (f"the two branches of {joint} meet at t = {at}, "
                                      "decided exactly (serial singularity: the path "
                                      "reaches the workspace boundary)")
            if d is not None and d < 0:
                return point.ball(), (f"{joint} has no real solution at t = {at}, decided "
                                      "exactly (the path leaves the workspace)")
        return None

    return exact


def leg_branches(path: PathModel, tolerance: float, covers: list[_Cover] | None = None,
                 starts: list[dict] | None = None) -> list[list[BranchFeasibility]]:
    """Feasibility of every branch of every leg (outer list in joint order); ``covers``
    (one per leg, :class:`_Cover`) and ``starts`` (:func:`start_branches`) when the
    caller shares them."""
    interval = path.trajectory.range
    limits_of = path.projection.model.spec.joint_limits
    covers = covers or [_Cover(leg, interval) for leg in path.legs]
    starts = starts or start_branches(path)
    proven, tried = sweep_quick_proofs(path, limits_of, starts)

    def when(t: arb) -> str:
        return f"{float(path.trajectory.to_global(arb(t)).mid()):.6g}"

    out = []
    for i, (leg, cover) in enumerate(zip(path.legs, covers, strict=True)):
        joint = leg.leg.joint
        if (i, None) in proven:
            status, reason, event = FEASIBLE, "", None
        elif leg.discriminant is not None:
            status, reason, event = _leg_reality(leg, interval, tolerance, when, cover,
                                                 quick=(i, None) not in tried,
                                                 exact=_exact_touch(path, leg))
        else:
            status, reason, event = FEASIBLE, "", None
        branches = []
        crossings: dict = {}
        for label in leg.labels:
            if status != FEASIBLE:
                branches.append(BranchFeasibility(joint, label, status, reason, event))
            elif (i, label) in proven:
                branches.append(BranchFeasibility(joint, label, FEASIBLE))
            elif joint in limits_of:
                branches.append(_branch_limits(leg, label, interval, limits_of[joint],
                                               tolerance, crossings, when, cover,
                                               quick=(i, label) not in tried,
                                               at_start=starts[i]))
            else:
                branches.append(BranchFeasibility(joint, label, FEASIBLE))
        out.append(branches)
    return out


def start_branches(path: PathModel) -> list[dict]:
    """Each leg's branches enclosed at the range start
    (:meth:`~singcheck.certify.path.PathModel.leg_branches_at`)."""
    return path.leg_branches_at(path.trajectory.range.start.ball())


def _start_values(starts: list[dict]) -> list[dict[str, float | None]]:
    """Each leg's branches at the range start, for display."""
    return [{label: joint_float(v) for label, v in start.items()} for start in starts]


def working_modes(path: PathModel, tolerance: float = 1e-9) -> list[WorkingMode]:
    """Every working mode (sign choice per leg) with its proven feasibility."""
    covers = [_Cover(leg, path.trajectory.range) for leg in path.legs]
    start_balls = start_branches(path)
    per_leg = leg_branches(path, tolerance, covers, start_balls)
    starts = _start_values(start_balls)
    joints = [leg.leg.joint for leg in path.legs]
    modes = []
    for choice in product(*per_leg):  # 2^legs (plain loops: 64 modes for six legs)
        checkpoint()
        statuses = set()
        label = ""
        at_start = {}
        for i, b in enumerate(choice):
            label += b.label
            statuses.add(b.status)
            at_start[joints[i]] = starts[i][b.label]
        if INFEASIBLE in statuses:
            status = INFEASIBLE
        elif UNKNOWN in statuses:
            status = UNKNOWN
        else:
            status = FEASIBLE
        reasons, proofs = [], []
        for b in choice:
            if b.status == status and b.reason:
                reasons.append(b.reason)
            if b.proof and (status == FEASIBLE or b.status == status):
                proofs.append(b.proof)
        modes.append(WorkingMode(label, choice, status, "; ".join(reasons), at_start,
                                 proof="; ".join(proofs)))
    return modes
