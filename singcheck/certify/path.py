"""A robot's polynomials along one trajectory X = φ(t), as trig polynomials in t.

Composing with φ is exact (``fmpq_mpoly.compose`` into ``Q[t, s, c]`` then
:func:`~singcheck.trig.reduce_trig`).  The results are:

* ``mu`` = ξ(φ(t)), whose real roots are every candidate singular time (when ξ(X) was too
  big to expand, μ is computed directly: :func:`eliminate_along_path`),
* per leg, the coefficients of its constraint in its joint, its discriminant D(t) and
  its joint-limit polynomials, from which the IK branches ρ = (-b ± √D)/(2a) along the
  path (for a revolute leg, cos θ and sin θ of its two branches) and their limit
  crossings are certified.

**Angles along the path.**  A pose angle φ(t) = k·t + qπ (k an integer, 12q an integer)
has ``cos φ(t) = cos(kt)·cos(qπ) - sin(kt)·sin(qπ)`` (and likewise sin), exact
polynomials in s, c with surd coefficients.  Square roots (of the robot's parameters, of
such offsets, of an angle joint's limits) stay variables ``sqrt(p)`` of the path ring
(:func:`~singcheck.algebra.radicals.path_ring`), evaluated as balls and isolated through
their norm (:mod:`singcheck.roots.isolation`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

from flint import acb, acb_mat, arb, arb_mat, ctx, fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.ball_programs import ball_program, joint_sum
from singcheck.algebra.composition import (
    MAX_COMPOSE_WORK,
    PIECE_WORK,
    TooCostly,
    compose_in_pieces,
    composition_work,
    crude_work,
)
from singcheck.algebra.intervals import evaluate, fraction_ball, power
from singcheck.algebra.opaque import has_opaque_coordinates, is_opaque_constant
from singcheck.algebra.polynomials import (
    coefficient_in,
    constant_value,
    memo_per_object,
    restrict,
    with_unit_coefficients,
)
from singcheck.algebra.radicals import (
    angle_function,
    angle_function_of,
    cos_pi,
    evaluate_path,
    into_ring,
    is_opaque,
    opaque_constants,
    opaque_of,
    path_ring,
    radical_balls,
    radical_prime,
    radical_variables,
    reduce_relations,
    sin_pi,
    surd_polynomial,
)
from singcheck.algebra.trig import (
    FOURIER_WIDE,
    TRIG,
    cos_multiple,
    evaluate_split,
    fourier_enclosure,
    reduce_trig,
    sin_multiple,
)
from singcheck.budget import checkpoint
from singcheck.elimination.projection import (
    RobotProjection,
    angle_limit_values,
    degenerate_set,
    exact_angle_limit,
    limit_constraint,
    norm_legs,
)
from singcheck.elimination.requests import norm_chain
from singcheck.errors import SpecError, UnsupportedRobotError
from singcheck.model.robot import (
    REVOLUTE,
    Leg,
    RobotModel,
    det_a_factors,
    leg_coefficients,
    leg_discriminant,
)
from singcheck.spec.files import TrajectorySpec
from singcheck.spec.grammar import MAX_DEGREE
from singcheck.spec.real_constants import exact_engine_refusal


def _reduce(p: fmpq_mpoly) -> fmpq_mpoly:
    return reduce_trig(p) if p.context() is TRIG else reduce_relations(p)


def _pose_args(p: fmpq_mpoly, phi: tuple[fmpq_mpoly, ...],
               pose: tuple[str, ...]) -> tuple[fmpq_mpoly_ctx, list[fmpq_mpoly]]:
    """The ring of ``phi`` and the images of ``p``'s variables in it."""
    ring = phi[0].context() if phi else TRIG
    plan = _composition_plan(p.context(), ring, pose)
    degrees = p.degrees()
    args = []
    for i, (kind, what) in enumerate(plan):
        if kind == "pose":
            args.append(phi[what])
        elif kind == "gen":
            args.append(what)
        elif degrees[i] > 0:
            raise ValueError(f"{what} is not a pose variable")
        else:
            args.append(ring.from_dict({}))
    return ring, args


def compose_pose(p: fmpq_mpoly, phi: tuple[fmpq_mpoly, ...], pose: tuple[str, ...],
                 work: int | None = None) -> fmpq_mpoly:
    """``p(…, X = φ(t))`` for a polynomial in any context whose non-pose variables are absent
    (square roots ``sqrt(q)`` become the path ring's, which ``phi`` lives in).  A costly
    composition is refused or cut into pieces a time limit can stop
    (:func:`~singcheck.algebra.composition.compose_in_pieces`)."""
    ring, args = _pose_args(p, phi, pose)
    if p.is_constant():  # (a leg's leading coefficient): nothing to compose
        return ring.from_dict({(0,) * ring.nvars(): constant_value(p)})
    return compose_in_pieces(p, args, ring, _reduce, work)


def _constants_first(p: fmpq_mpoly, args: list[fmpq_mpoly]) -> fmpq_mpoly:
    """``p`` with the variables whose image is a constant (a coordinate such as z = 1)
    replaced by that rational (exact): the same composition, and FLINT's compose then
    expands fewer and smaller powers (ξ of the Orthoglide along heart 1: half the time;
    on a leg's small coefficients the substitution costs more than it saves).  ``p`` no
    longer depends on them, so their images are left unused."""
    constants = {}
    for name, a, d in zip(p.context().names(), args, p.degrees(), strict=True):
        if d > 0 and a.is_constant():
            constants[name] = constant_value(a)
    return p.subs(constants) if constants else p


_SQUARED: dict = {}


def _squares_first(p: fmpq_mpoly, args: list[fmpq_mpoly]
                   ) -> tuple[fmpq_mpoly, list[fmpq_mpoly]]:
    """(p̃, ``args`` with some images squared) where p = p̃(…, v², …) for every
    variable v whose exponents in ``p`` are all even, so that p(args) = p̃(args'), an
    identity of polynomials; each square is reduced (``_reduce``) before it is raised
    to the halved powers.  ξ of the Orthoglide is even in x, y and z: composing p̃
    expands powers of half the degree (along heart 1, μ in half the time).  p̃ is made
    once per ``p``."""
    halved, even = memo_per_object(_SQUARED, p, _halved)
    if not even:
        return p, args
    return halved, [_reduce(a * a) if i in even else a for i, a in enumerate(args)]


def _halved(p: fmpq_mpoly) -> tuple[fmpq_mpoly, frozenset[int]]:
    """(p̃, the indices of the variables halved) of :func:`_squares_first`."""
    monoms = p.monoms()
    even = frozenset(i for i, d in enumerate(p.degrees())
                     if d > 0 and all(m[i] % 2 == 0 for m in monoms))
    if not even:
        return p, even
    return p.context().from_dict({
        tuple(e // 2 if i in even else e for i, e in enumerate(m)): c
        for m, c in zip(monoms, p.coeffs(), strict=True)}), even


_PLANS: dict = {}


def _composition_plan(source, ring, pose: tuple[str, ...]) -> tuple:
    """Per variable of ``source``: ("pose", index in ``pose``), ("gen", the ring's
    square-root generator) or ("absent", name); once per (context, ring, pose)."""
    key = (id(source), id(ring), pose)
    hit = _PLANS.get(key)
    if hit is None or hit[0] is not source or hit[1] is not ring:
        gens = dict(zip(ring.names(), ring.gens(), strict=True))
        plan = tuple(("pose", pose.index(v)) if v in pose else
                     ("gen", gens[v]) if (radical_prime(v) is not None or
                                          is_opaque_constant(v)) and v in gens else
                     ("absent", v) for v in source.names())
        if len(_PLANS) > 256:
            _PLANS.clear()
        hit = _PLANS[key] = (source, ring, plan)  # holds both contexts: ids not reused
    return hit[2]


def joint_float(value) -> float | None:
    """A joint value for display: a real ball's midpoint, or the angle atan2(s, c) of a
    revolute branch (radians, in (-π, π]); None when not real."""
    if isinstance(value, arb):
        return float(value.mid())
    if isinstance(value, tuple) and all(isinstance(v, arb) for v in value):
        # from the midpoints: atan2 of balls whose sine straddles 0 on the negative cosine
        # side (θ = π) is the whole (-π, π], whose midpoint 0 is the wrong display
        import math

        angle = math.atan2(float(value[1].mid()), float(value[0].mid()))
        return math.pi if angle <= -math.pi else angle
    return None


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
    _, deg_t, deg_sc = composition_work(xi, _pose_args(xi, phi, pose)[1])
    return deg_t, deg_sc, (deg_t + 1) * (2 * deg_sc + 1)


#: The highest degree in tan(t/2) whose real roots a path's μ may ask for (μ free of t:
#: exact isolation in the half-angle tangent, :mod:`singcheck.roots.half_angle`).  The
#: isolation's cost grows about as the fourth power of the degree: the 3-PRR with
#: phi = k*t (μ of degree 20k in sin t, cos t, 40k in the tangent) isolated μ's roots
#: in 0.1 s for k = 5, 1.1 s for 10, 6.2 s for 15 and 19 s for 20 (CPU, quiet machine);
#: k = 30 did not finish its certification in 120 s.
MAX_HALF_ANGLE_DEGREE = 800


def isolation_degree(mu: fmpq_mpoly) -> int:
    """The degree in u = tan(t/2) of the polynomial whose real roots certify ``mu`` (0
    when ``mu`` involves t or an angle function: then interval branch-and-bound, with
    its own budget of boxes, isolates them): twice its degree in (sin t, cos t), doubled
    again for each square root among its coefficients (their norm is isolated)."""
    degrees = mu.degrees()
    if mu.context() is TRIG:  # (t, s, c)
        return 0 if degrees[0] > 0 else 2 * max(int(mu.total_degree()), 0)
    names = mu.context().names()
    radicals = [i for i, _ in radical_variables(mu.context())]
    if any(d > 0 for i, (v, d) in enumerate(zip(names, degrees, strict=True))
           if v not in ("s", "c") and i not in radicals):
        return 0
    used = sum(1 for i in radicals if degrees[i] > 0)
    if not used:  # only s and c occur: the degree in them is the total degree
        return 2 * max(int(mu.total_degree()), 0)
    si, ci = names.index("s"), names.index("c")
    trig = max((e[si] + e[ci] for e in mu.monoms()), default=0)
    return 2 * trig * 2 ** used


def _too_costly(what: str, trajectory: TrajectorySpec) -> SpecError:
    """The refusal of a path whose certification would cost too much, saying what to
    change: the path's degrees, or, for a path already of degree 1 in t without sin/cos
    (a straight line), nothing in the path: the cost is the robot's."""
    straight = all(p.degrees()[0] <= 1 and max(p.degrees()[1:], default=0) <= 0
                   for piece in trajectory.pieces for p in piece.pose.values()
                   if not p.is_zero())  # degrees in t, then in sin t, cos t (and others)
    if straight:
        advice = ("the path is already a straight line (degree 1 in t, no sin/cos): the "
                  "cost is the robot's (its singularity surface ξ(X) and its legs), not "
                  "the path's; a robot with fewer pose variables or simpler legs is needed")
    else:
        advice = ("lower the degrees or the coefficients of the coordinates, or the "
                  "multiples of t in sin/cos (or cut the path into shorter, simpler pieces)")
    return SpecError(f"too costly: {what}: {advice}", path=trajectory.path,
                     line=trajectory.lines.get("pose"), key="pose")


def _compose_mu(xi: fmpq_mpoly, phi: tuple[fmpq_mpoly, ...], pose: tuple[str, ...],
                trajectory: TrajectorySpec) -> fmpq_mpoly:
    """μ = ξ(φ(t)), refused up front (one line, exit 2) when it could have more than
    :data:`MAX_MU_TERMS` terms or cost more than
    :data:`~singcheck.algebra.composition.MAX_COMPOSE_WORK`; otherwise composed in
    pieces a time limit can stop."""
    ring, args = _pose_args(xi, phi, pose)
    xi, args = _squares_first(xi, args)
    work = _small_composition(xi, args)
    if work is not None:
        return compose_in_pieces(_constants_first(xi, args), args, ring, _reduce, work)
    work, deg_t, deg_sc = composition_work(xi, args)
    terms = (deg_t + 1) * (2 * deg_sc + 1)
    if terms > MAX_MU_TERMS:
        raise _too_costly(f"μ(t) = ξ(φ(t)) could have {terms} terms (degree {deg_t} in t "
                          f"and {deg_sc} in sin t, cos t; at most {MAX_MU_TERMS})", trajectory)
    if work > MAX_COMPOSE_WORK:
        raise _too_costly(f"composing μ(t) = ξ(φ(t)) would cost {work:.3g} by its a-priori "
                          f"estimate (ξ has {len(xi)} terms; at most {MAX_COMPOSE_WORK:.3g})",
                          trajectory)
    return compose_in_pieces(_constants_first(xi, args), args, ring, _reduce, work)


def _small_composition(p: fmpq_mpoly, args: list[fmpq_mpoly]) -> int | None:
    """A bound on :func:`composition_work` proven by a crude estimate, when that estimate
    already keeps ``p(args)`` within one FLINT call and within :data:`MAX_MU_TERMS`
    (the common case); None otherwise (then the exact estimate is needed).

    Crude: every term is charged the largest exponents of all variables together, so
    its degrees in t and in (s, c) bound the true ones from above, and its work bounds
    :func:`composition_work`'s (:func:`~singcheck.algebra.composition.crude_work`).
    The decisions taken on the bound (compose in one call, do not refuse) are those the
    exact estimate would take, which is skipped: on heart 1 it cost a third of composing
    μ."""
    work, deg_t, deg_sc = crude_work(p, args)
    if work <= PIECE_WORK and (deg_t + 1) * (2 * deg_sc + 1) <= MAX_MU_TERMS:
        return work
    return None


class LegAlongPath:
    """One leg's constraint along the path: ``a ρ² + b(t) ρ + c(t)`` (or ``b ρ + c``), or
    ``a(t) cos θ + b(t) sin θ + d(t)`` for a revolute leg.

    Its polynomials along the path (``coefficients``, highest degree first or (a, b, d);
    ``discriminant``, b² - 4ac or Δ; ``limits``, a revolute joint's limit constraints)
    are composed on first use: the quick feasibility proofs and the classification
    enclose a leg from the balls of the pose (:func:`branches_at_pose`), so a path whose
    quick proofs all pass never composes them.  Whether composing them could cost too
    much was checked when the path was built (:func:`build_path`)."""

    __slots__ = ("leg", "_composer", "_along")

    def __init__(self, leg: Leg, composer: _LegComposer) -> None:
        self.leg = leg
        self._composer = composer
        self._along: tuple | None = None

    def _composed(self) -> tuple:
        if self._along is None:
            self._along = self._composer.leg(self.leg)
        return self._along

    @property
    def coefficients(self) -> tuple[fmpq_mpoly, ...]:
        return self._composed()[0]

    @property
    def discriminant(self) -> fmpq_mpoly | None:
        return self._composed()[1]

    @property
    def limits(self) -> dict:
        """Limit value -> its constraint along the path (revolute joints only)."""
        return self._composed()[2]

    @property
    def revolute(self) -> bool:
        return self.leg.kind == REVOLUTE

    @property
    def labels(self) -> tuple[str, ...]:
        """Branch labels: the sign in front of √D, or 'o' for a linear leg."""
        return ("+", "-") if self.leg.degree == 2 else ("o",)

    def limit_polynomial(self, value) -> fmpq_mpoly:
        """The constraint with the joint set to ``value``: it vanishes when a branch is there."""
        if value in self.limits:
            return self.limits[value]
        out = self.coefficients[0].context().from_dict({})
        q = fmpq(value.numerator, value.denominator)
        for c in self.coefficients:
            out = out * q + c
        return out

    def branches(self, t: arb, tight: bool = False,
                 discriminant: arb | None = None) -> dict[str, arb | acb | tuple | None]:
        """Enclosures of each branch's joint value for every t in the ball ``t``.

        A quadratic leg's branches are real where D > 0 (proven) and complex
        conjugate where D < 0; where the sign of D is not proven both are None.  A
        revolute branch is the pair (cos θ, sin θ).  ``tight`` spends more on a wide
        ball (:func:`~singcheck.algebra.trig.evaluate_trig`); ``discriminant``, D's
        enclosure over the same ball (and ``tight``) when the caller has it already."""
        if self._composer.balls_only:  # enclosed from the pose's balls (no composition)
            point = self._composer.point(t)
            return _branches_at_point(self._composer.model, self.leg, point)
        if self.leg.kind != REVOLUTE and self.leg.degree == 2:
            # ρ = (-b ± √D)/(2a) needs a, b and D only: c is in D already
            coefficients = self.coefficients
            values = [evaluate_path(coefficients[0], t, None, tight),
                      evaluate_path(coefficients[1], t, None, tight), None]
        else:
            values = [evaluate_path(c, t, None, tight) for c in self.coefficients]
        d = discriminant
        if d is None and self.discriminant is not None:
            d = evaluate_path(self.discriminant, t, None, tight)
        return branch_values(self.leg, values, d)

    def discriminant_at(self, t: arb, tight: bool = False) -> arb:
        """D's enclosure over the ball ``t`` (from the pose's balls on an opaque path)."""
        if self._composer.balls_only:
            return evaluate(_model_discriminant(self.leg), self._composer.point(t))
        return evaluate_path(self.discriminant, t, tight=tight)

    def inside(self, value, limits) -> bool | None:
        """Whether a branch value is strictly inside the limits (True), outside them
        (False), or not decided (None, also on the limits themselves)."""
        return inside_limits(self.leg, value, limits)


def branch_values(leg: Leg, values: list, d) -> dict:
    """Each branch from the leg's coefficient balls (and its discriminant's)."""
    if leg.kind == REVOLUTE:
        a, b, dd = values
        w = a * a + b * b
        if d > 0:
            root = d.sqrt()
        elif d < 0:
            root = acb(0, (-d).sqrt())
            a, b, dd, w = acb(a), acb(b), acb(dd), acb(w)
        else:
            return {"+": None, "-": None}
        return {label: ((-a * dd + sigma * b * root) / w, (-b * dd - sigma * a * root) / w)
                for label, sigma in (("+", 1), ("-", -1))}
    if leg.degree == 1:
        b, c = values
        return {"o": -c / b}
    a, b, _ = values
    if d > 0:
        root = d.sqrt()
        return {"+": (-b + root) / (2 * a), "-": (-b - root) / (2 * a)}
    if d < 0:
        root = acb(0, (-d).sqrt())
        return {"+": (-acb(b) + root) / (2 * a), "-": (-acb(b) - root) / (2 * a)}
    return {"+": None, "-": None}


_DET_A_SPLITS: dict[int, tuple] = {}


def _det_a_by_joints(model: RobotModel) -> list[tuple[tuple[tuple[int, int], ...], fmpq_mpoly]]:
    """det A as [(α, q_α)]: α the exponents of the joint variables (sparse pairs), q_α
    the polynomial in the other variables; once per model."""
    def split(model: RobotModel) -> list:
        n_joint = len(model.joint_variables)
        groups: dict[tuple[int, ...], dict] = {}
        for exps, coeff in model.det_A.terms():
            rest = (0,) * n_joint + tuple(exps[n_joint:])
            groups.setdefault(tuple(exps[:n_joint]), {})[rest] = coeff
        return [(tuple((v, e) for v, e in enumerate(alpha) if e),
                 model.context.from_dict(terms)) for alpha, terms in groups.items()]

    return memo_per_object(_DET_A_SPLITS, model, split)


_LIMIT_BALLS: dict = {}


def limit_balls(limits) -> tuple[arb, arb]:
    """The balls of a prismatic joint's rational limits (exact when dyadic), once per
    limits object and working precision: feasibility proofs compare against them
    thousands of times (keyed by the object, not by hashing its Fractions each time)."""
    key = (id(limits), ctx.prec)
    hit = _LIMIT_BALLS.get(key)
    if hit is None or hit[0] is not limits:  # the entry holds limits: its id is not reused
        if len(_LIMIT_BALLS) > 256:
            _LIMIT_BALLS.clear()
        hit = _LIMIT_BALLS[key] = (limits, tuple(
            v.ball() if hasattr(v, "ball") else fraction_ball(v) for v in limits))
    return hit[1]


_ARCS: dict = {}


def _angle_arc(limits) -> tuple[arb, arb, arb] | None:
    """(cos m, sin m, cos(w/2)) of an angle's limits [lo, hi] (middle m, width w), None
    when w ≥ 2π (every angle is inside); once per limits object and precision, as
    :func:`limit_balls`."""
    key = (id(limits), ctx.prec)
    hit = _ARCS.get(key)
    if hit is None or hit[0] is not limits:
        if len(_ARCS) > 256:
            _ARCS.clear()
        lo, hi = (v.ball() for v in limits)
        width = hi - lo
        if width >= 2 * arb.pi():
            arc = None
        else:
            mid = (lo + hi) / 2
            arc = (mid.cos(), mid.sin(), (width / 2).cos())
        hit = _ARCS[key] = (limits, arc)
    return hit[1]


def inside_limits(leg: Leg, value, limits) -> bool | None:
    """Strictly inside (True), outside (False) or undecided (None).  For an angle θ and
    limits [lo, hi] of width w < 2π with middle m: θ is inside (mod 2π) exactly when
    cos(θ - m) = cos θ·cos m + sin θ·sin m ≥ cos(w/2) (no branch cut to straddle)."""
    if value is None:
        return None
    if leg.kind == REVOLUTE:
        if not isinstance(value, tuple) or not all(isinstance(v, arb) for v in value):
            return None
        arc = _angle_arc(limits)
        if arc is None:
            return True
        cos_m, sin_m, cos_half = arc
        margin = value[0] * cos_m + value[1] * sin_m - cos_half
        return True if margin > 0 else False if margin < 0 else None
    lo, hi = limit_balls(limits)
    if value > lo and value < hi:
        return True
    if value < lo or value > hi:
        return False
    return None


@dataclass(frozen=True)
class PathModel:
    projection: RobotProjection
    trajectory: TrajectorySpec
    phi: tuple[fmpq_mpoly, ...]  # pose coordinates in the robot's pose order (display)
    mu: fmpq_mpoly | None  # ξ(φ(t)); None: the exact engine did not run (exact_refused)
    legs: tuple[LegAlongPath, ...]
    coordinates: tuple[fmpq_mpoly, ...] = ()  # the pose variables' (cos φ, sin φ for angles)
    degenerate: tuple[fmpq_mpoly, ...] = ()  # W of each revolute leg along the path
    exact_refused: str = ""  # why μ was not computed ("" when it was)

    #: (t, precision, pose, variables) of the last :meth:`pose_and_variables_at` (set
    #: per instance; this class attribute is only the empty start)
    _last_pose = (None, 0, (), ())

    def pose_at(self, t: arb) -> list[arb]:
        """The pose coordinates (an angle in radians, its π offset included)."""
        return self.pose_and_variables_at(t)[0]

    def pose_variables_at(self, t: arb) -> list[arb]:
        """Balls of the model's pose variables (cos φ, sin φ for an angle)."""
        return self.pose_and_variables_at(t)[1]

    def pose_and_variables_at(self, t: arb) -> tuple[list[arb], list[arb]]:
        """:meth:`pose_at` and :meth:`pose_variables_at` together, each polynomial
        evaluated once: a coordinate that is not an angle is its own pose variable (the
        same polynomial object, hence the same ball).  The last ball's answer is kept
        (the interval engine asks for the same ball's pose for the enclosure, then for
        its mean-value form); it is replaced whole, never edited, and the lists handed
        out are copies."""
        last = self._last_pose
        if last[0] is t and last[1] == ctx.prec:
            return list(last[2]), list(last[3])
        pose, variables = self._pose_and_variables(t)
        object.__setattr__(self, "_last_pose", (t, ctx.prec, pose, variables))
        return list(pose), list(variables)

    def _pose_and_variables(self, t: arb) -> tuple[list[arb], list[arb]]:
        plan, pose_at, variables_at, offsets = self._pose_plan
        s = c = None
        balls = []
        wide = t.rad() > FOURIER_WIDE
        for x, split, trig in plan:  # each distinct coordinate polynomial once
            if split is None:
                balls.append(evaluate_path(x, t))
                continue
            if wide:
                f = fourier_enclosure(trig, t)
                if f is not None:
                    balls.append(f)
                    continue
            if s is None:
                s, c = t.sin_cos()
            balls.append(evaluate_split(split(), t, s, c))
        pose = [balls[i] for i in pose_at]
        for i, offset in offsets:
            pose[i] = pose[i] + arb.pi() * offset
        return pose, [balls[i] for i in variables_at]

    @cached_property
    def harmonic(self) -> int | None:
        """The highest harmonic of the path: the largest degree in (sin t, cos t) of its
        coordinates (0 for a path polynomial in t); None when a coordinate is not a trig
        polynomial (angle functions, square roots, expression trees)."""
        degrees = []
        for trig in self.trig_coordinates:
            if trig is None:
                return None
            d = trig.degrees()
            degrees.append(int(max(d[1], 0) + max(d[2], 0)))
        return max(degrees, default=0)

    @cached_property
    def trig_coordinates(self) -> tuple[fmpq_mpoly | None, ...]:
        """Each pose variable's polynomial in the ring TRIG of t, sin t, cos t, or None
        where it involves anything else (:func:`_in_trig`), once per path."""
        return tuple(_in_trig(x) for x in self.coordinates)

    @cached_property
    def _pose_plan(self):
        """How :meth:`pose_and_variables_at` encloses the pose, once per path: each
        distinct coordinate polynomial with, for a trig polynomial of low degree, its
        ball split (:func:`~singcheck.algebra.trig.evaluate_split`, at the current
        precision: the enclosure :func:`evaluate_path` makes, without its look-ups)
        and its restriction to TRIG (None for another); the pose's and the pose
        variables' positions among them; the angle offsets."""
        from singcheck.algebra.trig import split_of

        plan, where = [], {}

        def at(x: fmpq_mpoly) -> int:
            if id(x) not in where:
                where[id(x)] = len(plan)
                trig = _in_trig(x)
                plan.append((x, split_of(trig) if trig is not None else None, trig))
            return where[id(x)]

        pose_at = [at(x) for x in self.phi]
        variables_at = [at(x) for x in self.coordinates]
        offsets = self.trajectory.angle_offsets
        shifts = [(i, fraction_ball(offsets[v]))
                  for i, v in enumerate(self.projection.model.pose) if v in offsets]
        return plan, pose_at, variables_at, shifts

    def pose_rates_at(self, t: arb, angle_functions: bool = True) -> list[arb] | None:
        """d/dt of each pose variable over the ball ``t`` (None, without
        ``angle_functions``, where the path ring has angle functions of its own: the
        mean-value form does without them).  A path kept as
        expression trees is differentiated on its trees
        (:meth:`~singcheck.spec.real_paths.RealFunction.with_derivative`)."""
        from singcheck.algebra.opaque import opaque_rate

        opaque, functions = self._rates_plan
        if opaque is not None:
            return [opaque_rate(name, t) for name in opaque]
        if functions and not angle_functions:
            return None
        if t.rad() > FOURIER_WIDE:
            return [_wide_enclosure(d, t) for d in _coordinate_derivatives(self)]
        return [evaluate_path(d, t) for d in _coordinate_derivatives(self)]

    @cached_property
    def _rates_plan(self) -> tuple[list[str] | None, bool]:
        """(the opaque variables' names of a path kept as expression trees, else None;
        whether the path ring has angle functions), once per path."""
        from singcheck.algebra.radicals import has_angle_functions

        if self.legs and self.legs[0]._composer.opaque:
            names = []
            for x in self.coordinates:
                (exps, _), = x.terms()
                names.append(x.context().names()[list(exps).index(1)])
            return names, True
        return None, any(has_angle_functions(x.context()) for x in self.coordinates)

    def det_A(self, joints: list, pose: list[arb], signs: dict[int, int] | None = None):
        """Enclosure of det A at the given joint values (a revolute joint's as a (cos,
        sin) pair) and pose-variable balls; ``signs`` picks conjugate square roots."""
        model = self.projection.model
        point = _flat_joints(joints) + list(pose)
        point += [b for _, b in sorted(radical_balls(model.context, signs).items())]
        return evaluate(model.det_A, point)

    def det_A_modes(self, joints_by_mode: dict, pose: list[arb],
                    signs: dict[int, int] | None = None) -> dict:
        """:meth:`det_A` for several modes at the same pose in one pass: det A is written
        once as Σ_α q_α(pose) ρ^α (ρ the joint variables), each q_α is enclosed once at
        the pose, and each mode only sums its few joint monomials.  The same polynomial,
        grouped differently: every enclosure is as rigorous as :meth:`det_A`'s."""
        model = self.projection.model
        if len(model.det_A) > MATRIX_FORM_ABOVE:
            return _det_a_by_matrix(model, joints_by_mode, pose, signs)
        split = _det_a_by_joints(model)
        n_joint = len(model.joint_variables)
        point = [arb(0)] * n_joint + list(pose)
        point += [b for _, b in sorted(radical_balls(model.context, signs).items())]
        program = ball_program(model, "det A by joints",
                               lambda m: [q for _, q in _det_a_by_joints(m)])
        revolute = model.angle_joints  # a revolute joint's ball is a (cos θ, sin θ) pair
        if program is not None:
            q = program(point)
            total = joint_sum(model, lambda m: [alpha for alpha, _ in _det_a_by_joints(m)])
            return {label: total(q, _flat_joints(joints) if revolute else joints)
                    for label, joints in joints_by_mode.items()}
        powers: dict = {}
        terms = [(alpha, evaluate(q, point, powers)) for alpha, q in split]
        out = {}
        for label, joints in joints_by_mode.items():
            flat = _flat_joints(joints) if revolute else joints
            total = None
            for alpha, term in terms:
                for v, e in alpha:
                    term = term * (flat[v] if e == 1 else power(flat[v], e))
                total = term if total is None else total + term
            out[label] = arb(0) if total is None else total
        return out

    @cached_property  # asked at every candidate; the fields it reads do not change
    def legs_from_pose(self) -> bool:
        """Whether the legs are enclosed from the pose's balls (the quick feasibility
        proofs of :mod:`.sweep`, the classification): a robot free of square roots and
        angles, whose few-term leg polynomials cost little to evaluate, along plain trig
        coordinates.  Otherwise the legs are composed along the path and enclosed there
        (a polynomial in the robot's pose variables can have many terms — the
        Gough–Stewart platform's — where the path fixes most of them)."""
        return _legs_from_pose(self.projection.model, self.coordinates)

    def leg_branches_at(self, t: arb, variables: list[arb] | None = None) -> list[dict]:
        """Per leg, its branches enclosed over the ball ``t`` (``variables``: the pose
        variables' balls there, when the caller has them)."""
        if self.legs_from_pose or (self.legs and self.legs[0]._composer.balls_only):
            return self.branches_at_pose(variables if variables is not None
                                         else self.pose_variables_at(t))
        return [leg.branches(t) for leg in self.legs]

    def branches_at_pose(self, pose: list[arb]) -> list[dict]:
        """Per leg, its branches at the pose given by balls of the pose variables (ball
        evaluation of the leg's coefficients in the robot's variables:
        :func:`branches_at_pose`)."""
        model = self.projection.model
        point = _pose_point(model, pose)
        program, slices = self._legs_program
        if program is None:
            powers: dict = {}  # the pose's powers, shared by the legs
            return [_branches_at_point(model, leg.leg, point, powers) for leg in self.legs]
        balls = program(point)  # every leg's coefficients and discriminant at once
        return [_branches_from(leg, balls[a:b]) for leg, a, b in slices]

    @cached_property
    def _legs_program(self):
        """(the compiled program of every leg's :func:`_branch_polys`, [(leg, start, end)]
        of its balls), or (None, None) when too large; once per path."""
        model = self.projection.model  # (self.legs are model.legs along the path)
        program = ball_program(model, "legs", lambda m: [q for leg in m.legs
                                                         for q in _branch_polys(leg)])
        slices, at = [], 0
        for leg in model.legs:
            n = len(_branch_polys(leg))
            slices.append((leg, at, at + n))
            at += n
        return program, slices

    def conjugate_branches(self, t: arb, pose: list[arb], signs: dict[int, int]):
        """Per leg, the branches of the conjugate robot (its square roots' signs flipped
        as ``signs`` says), by ball evaluation of the leg's coefficients at the pose."""
        model = self.projection.model
        return [branches_at_pose(model, leg.leg, pose, signs) for leg in self.legs]


def _wide_enclosure(p: fmpq_mpoly, t: arb) -> arb:
    """A path polynomial enclosed over a wide ball t: a trig polynomial in its Fourier
    form (:data:`FOURIER_WIDE`), anything else by :func:`evaluate_path`."""
    if p.context() is TRIG:
        f = fourier_enclosure(p, t)
        if f is not None:
            return f
    return evaluate_path(p, t)


_COORDINATE_DERIVATIVES: dict = {}


def _coordinate_derivatives(path: PathModel) -> list | None:
    """d/dt of each pose variable along the path, once per path."""
    from singcheck.algebra.radicals import path_derivative

    def build(path):
        return [path_derivative(x) for x in path.coordinates]

    return memo_per_object(_COORDINATE_DERIVATIVES, path, build)


#: det A with more terms than this (a hexapod's: 10⁵) is enclosed per mode as the
#: determinant of the ball matrix A(φ(T), ρ_mode(T)) instead of term by term
MATRIX_FORM_ABOVE = 5000


def _det_a_by_matrix(model: RobotModel, joints_by_mode: dict, pose: list[arb],
                     signs: dict[int, int] | None = None) -> dict:
    """det A per mode as the determinant of the ball matrix A = ∂F/∂X enclosed at the
    mode's joints and the pose (FLINT's ``arb_mat.det``, rigorous): the same value as
    the expanded det A wherever the (cos, sin) pairs lie on their circles and the
    square roots square to their radicands — true of every point the balls stand for —
    at a few hundred terms instead of det A's many thousands."""
    radicals = [b for _, b in sorted(radical_balls(model.context, signs).items())]
    row_legs = _row_legs(model)
    programs = [ball_program(model, ("row of A", i), lambda m, i=i: m.A[i])
                for i in range(len(model.A))]
    out = {}
    shared: dict = {}  # (row, id of its leg's joint ball) -> the row's balls
    kept = []  # the joint balls keyed by id, alive for the whole call
    for label, joints in joints_by_mode.items():
        point = None
        rows = []
        for i, row in enumerate(model.A):
            k = row_legs[i]
            key = None if k is None else (i, id(joints[k]))
            hit = shared.get(key) if key is not None else None
            if hit is None:
                if point is None:
                    point = _flat_joints(joints) + list(pose) + radicals
                    powers: dict = {}
                program = programs[i]  # (the same sums, compiled: 3x faster)
                hit = program(point) if program is not None else \
                    [evaluate(e, point, powers) for e in row]
                if key is not None:
                    shared[key] = hit
                    kept.append(joints[k])
            rows.append(hit)
        real = all(isinstance(e, arb) for row in rows for e in row)
        out[label] = (arb_mat(rows) if real else acb_mat(rows)).det()
    return out


_ROW_LEGS: dict = {}


def _row_legs(model: RobotModel) -> list[int | None]:
    """Per row of A, the one leg (index in ``model.legs``) whose joint variables it
    involves (None: several, or none: such a row is enclosed per mode), once per model.
    Rows of modes that share that leg's branch are then enclosed once."""
    def build(model: RobotModel) -> list:
        names = model.context.names()
        owner = {names.index(v): k for k, leg in enumerate(model.legs)
                 for v in leg.variables}
        out = []
        for row in model.A:
            used = {owner[i] for e in row for i, d in enumerate(e.degrees())
                    if d > 0 and i in owner}
            out.append(used.pop() if len(used) == 1 else None)
        return out

    return memo_per_object(_ROW_LEGS, model, build)


def _flat_joints(joints: list) -> list:
    """The joints' balls as the robot's variables: a revolute joint's (cos θ, sin θ)
    pair as two."""
    flat: list = []
    for j in joints:
        flat += list(j) if isinstance(j, tuple) else [j]
    return flat


def branches_at_pose(model: RobotModel, leg: Leg, pose: list, signs=None) -> dict:
    """The leg's branches at a pose given by balls of the model's pose variables (cos φ,
    sin φ for an angle), the square roots' signs as ``signs`` says (default: the robot's
    own, all positive): ball evaluation of the leg's coefficients and discriminant, as
    polynomials in the robot's variables, at those balls (each encloses its polynomial
    over every pose in the balls, hence the branches)."""
    return _branches_at_point(model, leg, _pose_point(model, pose, signs))


def _pose_point(model: RobotModel, pose: list, signs=None) -> list:
    """The balls of the robot's variables: joints (unused: 0), pose, square roots."""
    radicals = [b for _, b in sorted(radical_balls(model.context, signs).items())]
    return [_ZERO] * len(model.joint_variables) + list(pose) + radicals


_ZERO = arb(0)

def _branches_at_point(model: RobotModel, leg: Leg, point: list,
                       powers: dict | None = None) -> dict:
    return _branches_from(leg, [evaluate(q, point, powers) for q in _branch_polys(leg)])


_BRANCH_POLYS: dict = {}


def _branch_polys(leg: Leg) -> tuple[fmpq_mpoly, ...]:
    """The polynomials whose balls give the leg's branches (:func:`branch_values`): a
    quadratic prismatic leg's a, b and D (c is in D already), another leg's coefficients
    and its discriminant when it has one; once per leg."""
    def build(leg):
        coefficients = _leg_coefficients(leg)
        disc = _model_discriminant(leg)
        if leg.kind != REVOLUTE and leg.degree == 2:  # (-b ± √D)/(2a)
            return (coefficients[0], coefficients[1], disc)
        return tuple(coefficients) + ((disc,) if disc is not None else ())

    return memo_per_object(_BRANCH_POLYS, leg, build)


def _branches_from(leg: Leg, balls: list) -> dict:
    """:func:`branch_values` from the balls of :func:`_branch_polys` (in its order)."""
    if leg.kind != REVOLUTE and leg.degree == 2:
        return branch_values(leg, [balls[0], balls[1], None], balls[2])
    n = len(_leg_coefficients(leg))
    return branch_values(leg, list(balls[:n]), balls[n] if len(balls) > n else None)


def leg_polynomials(leg: Leg) -> tuple[fmpq_mpoly, fmpq_mpoly, fmpq_mpoly]:
    """(a, b, D = b² - 4ac) of a quadratic prismatic leg a ρ² + b ρ + c, polynomials in
    the robot's variables (the pose's), once per leg."""
    a, b, _ = _leg_coefficients(leg)
    return a, b, _model_discriminant(leg)


_MODEL_DISCRIMINANTS: dict = {}


def _model_discriminant(leg: Leg) -> fmpq_mpoly | None:
    """:func:`~singcheck.model.robot.leg_discriminant` of the leg's own coefficients (in
    the robot's variables), once per leg."""
    return memo_per_object(_MODEL_DISCRIMINANTS, leg,
                           lambda leg: leg_discriminant(leg, _leg_coefficients(leg)))


def _angle_k(p: fmpq_mpoly, q) -> int | None:
    """k when the angle p + qπ is k·t + qπ with k an integer and 12q an integer."""
    if cos_pi(q) is None:
        return None
    terms = dict(p.terms())
    if not terms:
        return 0
    if len(terms) == 1:
        (exps, coeff), = terms.items()
        if exps[0] == 1 and not any(exps[1:]) and coeff.q == 1:
            return int(coeff.p)
    return None


def _angle_coordinates(p: fmpq_mpoly, q, ring) -> tuple[fmpq_mpoly, fmpq_mpoly]:
    """(cos, sin) of the angle p + qπ along the path: exact polynomials in s, c when it is
    k·t + qπ, else the ring's angle-function variables (certified by branch-and-bound)."""
    k = _angle_k(p, q)
    if k is None:
        gens = dict(zip(ring.names(), ring.gens(), strict=True))
        c, s = angle_function(p, q)
        return gens[c], gens[s]
    ck, sk = into_ring(cos_multiple(k), ring), into_ring(sin_multiple(k), ring)
    cq, sq = surd_polynomial(cos_pi(q), ring), surd_polynomial(sin_pi(q), ring)
    return _reduce(ck * cq - sk * sq), _reduce(sk * cq + ck * sq)


def _opaque_names(phi: tuple[fmpq_mpoly, ...]) -> list[str]:
    """The opaque variables of a pose kept as expression trees (an angle's A with its C
    and S), in order; [] for an exact pose."""
    names: list[str] = []
    for x in phi:
        for n in x.context().names()[3:]:
            if opaque_of(n) is not None and n not in names:
                names.append(n)
    return names


def _opaque_angle(x: fmpq_mpoly, ring) -> tuple[fmpq_mpoly, fmpq_mpoly]:
    """(cos, sin) of an angle kept as an expression tree: its C and S variables."""
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    (exps, _), = x.terms()
    name = ring.names()[list(exps).index(1)]
    return gens["C" + name[1:]], gens["S" + name[1:]]


def _primes_of(*polys) -> set[int]:
    out = set()
    for p in polys:
        radicals = radical_variables(p.context())
        if radicals:
            degrees = p.degrees()
            out.update(prime for i, prime in radicals if degrees[i] > 0)
    return out


def _free_of_radicals(p: fmpq_mpoly) -> bool:
    """``p`` (in a path ring) involves no ``sqrt(q)`` variable: it lives in Q[t, s, c]."""
    names = p.context().names()
    return all(p.degrees()[i] <= 0 for i, v in enumerate(names) if v not in ("t", "s", "c"))


def eliminate_along_path(model: RobotModel, coordinates: tuple[fmpq_mpoly, ...],
                         where: dict | None = None) -> fmpq_mpoly:
    """μ(t) without ξ(X): substitute X = φ(t) first, then eliminate the joints.

    det A and every leg constraint are composed with φ (the pose variables' coordinates:
    cos φ, sin φ for an angle) into Q[ρ, √…, t, s, c], and the joints (and the robot's
    square roots) are eliminated by the same norm as ξ
    (:func:`~singcheck.elimination.requests.norm_chain`, a chain of resultants and
    revolute norms, one factor of det A at a time).  Each leg's leading coefficient in
    its joint is a non-zero constant (a revolute leg's norm is a polynomial identity), so
    the elimination commutes with the substitution: the result is ξ(φ(t)) up to a
    constant factor and multiplicities, and has exactly its zeros.  Only polynomials in
    one parameter (and s, c) are formed, never ξ(X) in every pose variable.  A path with
    square roots of its own is refused (they would be conjugated with the robot's).
    """
    if all(_free_of_radicals(x) for x in coordinates):
        coordinates = tuple(restrict(x, TRIG) for x in coordinates)
    else:
        raise UnsupportedRobotError(
            "ξ(X) was not expanded and this path has square roots or an angle that is not "
            "k*t + q*pi of its own: eliminating along it is not supported yet",
            **(where or {}))
    deg_t, deg_sc, largest = pathwise_size_bound(model, coordinates)
    if largest > MAX_PATHWISE_TERMS:
        raise TooCostly(
            f"eliminating the joints along the path could take intermediates of "
            f"{largest:.3g} terms by an a-priori bound (at most {MAX_PATHWISE_TERMS:.3g}; "
            f"μ of degree up to {deg_t} in t and {deg_sc} in sin t, cos t)")
    eliminated = model.eliminated
    ring = fmpq_mpoly_ctx.get((*eliminated, "t", "s", "c"), "lex")
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    tsc = [gens["t"], gens["s"], gens["c"]]
    pose = model.pose_variables
    args = [gens[v] if v in gens else coordinates[pose.index(v)].compose(*tsc, ctx=ring)
            for v in model.context.names()]
    det_a = _on_circle(model.det_A.compose(*args, ctx=ring))
    checkpoint()
    legs = [(v, _on_circle(f.compose(*args, ctx=ring))) for v, f in norm_legs(model)]
    return reduce_trig(restrict(norm_chain(det_a, legs, reduce=_on_circle), TRIG))


#: The most terms an intermediate of the path-wise elimination may have by the bound of
#: :func:`pathwise_size_bound`, which is loose (degree 160 for 18 on the rotary Delta's
#: circle): its circle 18,850; x = t/2, y = sin t/2: 484,866 (0.65 s of CPU); a helix,
#: 546,650 (about 1 s); cos 12t, sin 11t: 219,050 (1.3 s); cos 6t, sin 5t and t/10:
#: 3.2·10⁶ (16 s), refused.  Between checkpoints one FLINT product or resultant runs.
MAX_PATHWISE_TERMS = 2_000_000


def pathwise_size_bound(model: RobotModel, coordinates: tuple[fmpq_mpoly, ...]
                        ) -> tuple[int, int, int]:
    """(degree in t, degree in sin/cos, terms) that the path-wise μ cannot exceed, and a
    bound on the terms of the largest intermediate of its norm chain — predicted from
    degrees alone, before any work.

    Along the chain each polynomial carries bounds on its degree in every eliminated
    variable, in each revolute leg's (cos, sin) together, in t and in (s, c) together.
    For a weight w (one of those), ``deg_w Res_v(g, f) ≤ deg_v(g)·deg_w(f) +
    deg_v(f)·deg_w(g)`` (the resultant is homogeneous of degree deg_v f in g's
    coefficients and deg_v g in f's).  A revolute norm ``G₀² - Δ·G₁²`` over
    f = a·cos + b·sin + d has ``deg_w ≤ 2·deg_w(g) + 2k·(α + max(α, δ))`` with k g's
    degree in that cos and sin, α = deg_w of a and b, δ = deg_w d: each of cos, sin
    becomes a numerator of that degree over W = a² + b² (:func:`revolute_norm`).
    Replacing s² by 1 - c² keeps the degree in (s, c); squarefree parts only lower it.
    The start, det A and the legs along the path, is bounded by the weighted degrees of
    :func:`~singcheck.algebra.composition.composition_work`."""
    names = model.context.names()
    pose = model.pose_variables
    zero = TRIG.from_dict({})
    args = [coordinates[pose.index(v)] if v in pose else zero for v in names]
    pairs = [v for v, _ in norm_legs(model) if isinstance(v, tuple)]

    def bounds(p: fmpq_mpoly) -> dict:
        _, deg_t, deg_sc = composition_work(p, args)
        degrees = [max(0, int(d)) for d in p.degrees()]
        out = {v: d for v, d in zip(names, degrees, strict=True) if v not in pose}
        out.update(zip(pairs, _pair_degrees(p, names, pairs), strict=True))
        out.update(t=deg_t, sc=deg_sc)
        return out

    def size(b: dict) -> int:
        n = (b["t"] + 1) * 2 * (b["sc"] + 1)
        for v, d in b.items():
            if isinstance(v, str) and v not in ("t", "sc"):
                n *= d + 1
        return n

    legs = []
    for v, f in norm_legs(model):
        if isinstance(v, tuple):
            ci, si = names.index(v[0]), names.index(v[1])
            a, b = bounds(coefficient_in(f, ci, 1)), bounds(coefficient_in(f, si, 1))
            d = bounds(coefficient_in(coefficient_in(f, ci, 0), si, 0))
            legs.append((v, {w: max(a[w], b[w]) for w in a}, d))
        else:
            legs.append((v, bounds(f), None))
    # (the legs along the path are composed too: their size counts)
    largest = max((size(bounds(f)) for _, f in norm_legs(model)), default=0)
    total_t = total_sc = 0
    for factor, _ in det_a_factors(model):
        acc = bounds(factor)
        largest = max(largest, size(acc))
        for v, f, d in legs:
            variables = v if isinstance(v, tuple) else (v,)
            if all(acc[x] == 0 for x in variables):
                continue
            if d is not None:
                k = acc[v]
                acc = {w: 2 * acc[w] + 2 * k * (f[w] + max(f[w], d[w])) for w in acc}
                acc[v] = 0
            else:
                m, n = acc[v], f[v]
                acc = {w: m * f[w] + n * acc[w] for w in acc}
            for x in variables:
                acc[x] = 0
            largest = max(largest, size(acc))
        total_t += acc["t"]
        total_sc += acc["sc"]
    return total_t, total_sc, largest


_PAIR_DEGREES: dict = {}


def _pair_degrees(p: fmpq_mpoly, names, pairs: list) -> list[int]:
    """Per revolute pair (cos, sin), p's largest total degree in the two: p with every
    coefficient 1 (no cancellation) composed with cos, sin ↦ zₖ and every other
    variable ↦ 1, read off the degrees of the image (FLINT; no Python loop over p's
    terms after the first), once per polynomial."""
    def compute(p: fmpq_mpoly) -> list[int]:
        if not pairs or p.is_zero():
            return [0] * len(pairs)
        ring = fmpq_mpoly_ctx.get(tuple(f"z{k}" for k in range(len(pairs))), "lex")
        one = ring.from_dict({(0,) * len(pairs): 1})
        image = {names.index(v): ring.gens()[k] for k, pair in enumerate(pairs) for v in pair}
        ones = with_unit_coefficients(p)
        composed = ones.compose(*[image.get(i, one) for i in range(len(names))], ctx=ring)
        return [max(0, int(d)) for d in composed.degrees()]

    return memo_per_object(_PAIR_DEGREES, p, compute)


def _on_circle(p: fmpq_mpoly) -> fmpq_mpoly:
    """``p`` (in a ring with the path's s = sin t, c = cos t, s before c) with s² replaced
    by 1 - c²: degree ≤ 1 in s, the same function of t.  Keeps path-wise norms small.
    FLINT's remainder modulo s² + c² - 1 (s² is its leading monomial), in C."""
    ctx = p.context()
    names = ctx.names()
    si, ci = names.index("s"), names.index("c")
    if p.degrees()[si] < 2:
        return p
    if ci < si:
        raise ValueError("the ring must order s before c")
    s, c = ctx.gens()[si], ctx.gens()[ci]
    return divmod(p, s * s + c * c - 1)[1]


_LEG_COEFFICIENTS: dict[int, tuple[Leg, tuple[fmpq_mpoly, ...]]] = {}


def _leg_coefficients(leg: Leg) -> tuple[fmpq_mpoly, ...]:
    """:func:`~singcheck.model.robot.leg_coefficients`, once per leg of a model (the same
    legs serve every path of a batch)."""
    return memo_per_object(_LEG_COEFFICIENTS, leg, leg_coefficients)


#: which engines certify a path: both (the interval engine first, the exact one where
#: it can run), the exact one (μ required: refused when too costly), the interval one
AUTO, EXACT, INTERVAL = "auto", "exact", "interval"
ENGINES = (AUTO, EXACT, INTERVAL)


def build_path(projection: RobotProjection, trajectory: TrajectorySpec,
               engine: str = EXACT) -> PathModel:
    """The model along one piece (a multi-piece path: one per ``trajectory.pieces``).

    μ is computed here only for ``engine="exact"``, the default (refused with a
    :class:`SpecError` when too costly).  With ``auto`` it is left for later (None:
    :func:`with_mu`, once the interval engine has run); with ``interval`` it is never
    computed (``exact_refused`` says so)."""
    if trajectory.segments:
        raise ValueError("build_path takes one piece: use trajectory.pieces")
    model = projection.model
    spec = model.spec
    where = dict(path=trajectory.path, line=trajectory.lines.get("pose"), key="pose")
    phi = tuple(trajectory.pose[v] for v in model.pose)
    primes = set(spec.radicals) | _primes_of(*phi)
    offsets = trajectory.angle_offsets
    for v in model.pose:
        if v in offsets and cos_pi(offsets[v]) is not None:
            primes |= cos_pi(offsets[v]).primes() | sin_pi(offsets[v]).primes()
    for leg in model.legs:
        if leg.kind == REVOLUTE and leg.joint in spec.joint_limits:
            for value in spec.joint_limits[leg.joint]:
                if not exact_angle_limit(value):
                    continue  # compared by ball arithmetic alone (working_modes)
                try:
                    cos_l, sin_l = angle_limit_values(leg.joint, value)
                except UnsupportedRobotError as e:
                    raise UnsupportedRobotError(
                        e.message, path=spec.path, line=spec.lines.get("joint_limits"),
                        key=f"joint_limits.{leg.joint}") from None
                primes |= cos_l.primes() | sin_l.primes()
    functions = []
    opaque = _opaque_names(phi)
    for v, x in zip(model.pose, phi, strict=True):
        if opaque:  # a pose kept as expression trees: no exact angle form to check
            continue
        k = _angle_k(x, offsets.get(v, 0)) if v in model.angles else None
        if k is not None and abs(k) > MAX_DEGREE:
            raise SpecError(f"the angle {v} is {k:.3g}*t: cos and sin of a multiple of t "
                            f"above {MAX_DEGREE} are not supported (the bound of sin(k*t) "
                            "in a coordinate)", path=trajectory.path,
                            line=trajectory.lines.get(f"pose.{v}", where["line"]),
                            key=f"pose.{v}")
        if v in model.angles and k is None:
            if x.context() is not TRIG:
                raise UnsupportedRobotError(
                    f"the angle {v} is neither k*t plus a multiple of pi/12 nor free of square "
                    "roots: not supported", **where)
            functions.append(angle_function(x, offsets.get(v, 0)))
    for x in phi:  # cos(g(t)), sin(g(t)) written in a coordinate (x: cos(t^2))
        names = x.context().names()
        functions += [(n, "sin(" + n[4:]) for n in names if n.startswith("cos(")
                      and angle_function_of(n) is not None
                      and (n, "sin(" + n[4:]) not in functions]
    # a robot's opaque constants (parameters outside the exact field) are variables of
    # the path ring too: its legs composed along the path are enclosed, never isolated
    constants = [name for _, name in opaque_constants(model.context)]
    ring = path_ring(primes, functions, (*opaque, *constants))
    phi = tuple(into_ring(x, ring) for x in phi)
    coordinates = []
    for v, x in zip(model.pose, phi, strict=True):
        if v in model.angles and opaque:
            coordinates += _opaque_angle(x, ring)
        elif v in model.angles:
            coordinates += _angle_coordinates(trajectory.pose[v], offsets.get(v, 0), ring)
        else:
            coordinates.append(x)
    coordinates = tuple(coordinates)
    pose_vars = model.pose_variables
    mu, refused = None, ""
    if engine == EXACT:
        mu = _mu(projection, trajectory, coordinates, where)
    elif engine == INTERVAL:
        refused = "the interval engine alone was asked for (--engine interval)"
    elif exact_engine_refusal(spec):  # the robot's polynomials are not over Q
        refused = exact_engine_refusal(spec)
    try:
        legs = _legs_along(model, coordinates)
        degenerate = tuple(compose_pose(w, coordinates, pose_vars)
                           for w in memo_per_object(_DEGENERATE, model, degenerate_set))
    except TooCostly as e:
        raise _too_costly(f"a leg's constraint along the path: {e}", trajectory) from None
    return PathModel(projection, trajectory, phi, mu, legs, coordinates, degenerate, refused)


def with_mu(path: PathModel) -> PathModel:
    """The path with μ computed (the exact engine's input), or with ``exact_refused``
    saying why the exact engine refuses it (μ or its isolation too costly, a path-wise
    elimination not supported)."""
    if path.mu is not None or path.exact_refused:
        return path
    trajectory = path.trajectory
    where = dict(path=trajectory.path, line=trajectory.lines.get("pose"), key="pose")
    try:
        mu = _mu(path.projection, trajectory, path.coordinates, where)
    except SpecError as e:  # UnsupportedRobotError included
        return replace(path, exact_refused=f"the exact engine refused this path: {e.message}")
    return replace(path, mu=mu)


def _mu(projection: RobotProjection, trajectory: TrajectorySpec,
        coordinates: tuple[fmpq_mpoly, ...], where: dict) -> fmpq_mpoly:
    """μ(t): ξ(φ(t)) when ξ was expanded, else eliminated along the path; refused (a
    :class:`SpecError` naming the pose) when it, or isolating its roots, is too costly."""
    model = projection.model
    refused = exact_engine_refusal(model.spec)
    if refused:  # the robot's polynomials are not over Q: nothing exact to isolate
        raise UnsupportedRobotError(f"the exact engine cannot certify this robot: {refused} "
                                    "(use --engine auto or interval)", path=model.spec.path,
                                    line=model.spec.lines.get("parameters"), key="parameters")
    if trajectory.not_algebraic:
        raise SpecError(f"{trajectory.not_algebraic}: only the interval engine takes it "
                        "(--engine auto or interval)", **where)
    if projection.expanded:
        # ξ modulo the pose angles' circles: μ is the same (φ's cos, sin lie on them)
        mu = _compose_mu(projection.surface_on_circles, coordinates, model.pose_variables,
                         trajectory)
    else:
        try:
            mu = eliminate_along_path(model, coordinates, where)
        except TooCostly as e:
            raise _too_costly(str(e), trajectory) from None
    degree = isolation_degree(mu)
    if degree > MAX_HALF_ANGLE_DEGREE:
        raise _too_costly(f"isolating the real roots of μ(t) would take a polynomial of degree "
                          f"{degree} in tan(t/2) (at most {MAX_HALF_ANGLE_DEGREE}: the cost "
                          "grows as its fourth power)", trajectory)
    return mu


#: W of each revolute leg (:func:`~singcheck.elimination.projection.degenerate_set`),
#: once per robot model
_DEGENERATE: dict = {}


def _legs_from_pose(model: RobotModel, coordinates: tuple[fmpq_mpoly, ...]) -> bool:
    """:attr:`PathModel.legs_from_pose`: a robot free of square roots, along coordinates
    that are plain trig polynomials (in t, sin t, cos t alone, even in a path ring with
    more variables: a 5-bar's limit at π/3 brings √3 into it)."""
    return not model.spec.radicals and not is_opaque(model.context) and \
        all(_in_trig(x) is not None for x in coordinates)


def _in_trig(x: fmpq_mpoly) -> fmpq_mpoly | None:
    """``x`` in the ring TRIG of t, sin t, cos t, when it involves nothing else."""
    if x.context() is TRIG:
        return x
    names, degrees = x.context().names(), x.degrees()
    if names[:3] != ("t", "s", "c") or any(d > 0 for d in degrees[3:]):
        return None
    return restrict(x, TRIG)


def _legs_along(model: RobotModel, coordinates: tuple[fmpq_mpoly, ...]
                ) -> tuple[LegAlongPath, ...]:
    """The legs along the path.  Where they are enclosed from the pose
    (:func:`_legs_from_pose`) their polynomials are composed on first use, after a check
    that none would cost too much (:class:`TooCostly`, up front); elsewhere the proofs
    use them at once, and they are composed now (the same refusal)."""
    composer = _LegComposer(model, coordinates)
    legs = tuple(LegAlongPath(leg, composer) for leg in model.legs)
    if _legs_from_pose(model, coordinates) or composer.balls_only:
        composer.check()
    else:
        for leg in legs:
            leg.coefficients  # noqa: B018 - composed now
    return legs


_LIMIT_CONSTRAINTS: dict = {}
_DISTINCT_SOURCES: dict = {}


class _LegComposer:
    """Composes the legs' polynomials along one path, each distinct coefficient once
    (legs often share one: the Orthoglide's constant a = 1 and c = x² + y² + z² - l²)."""

    def __init__(self, model: RobotModel, coordinates: tuple[fmpq_mpoly, ...]) -> None:
        self.model = model
        self.coordinates = coordinates
        self._composed: list[tuple[fmpq_mpoly, fmpq_mpoly]] = []  # (coefficient, image)
        #: a path given by expression trees: its legs are enclosed from the pose's balls
        self.opaque = any(has_opaque_coordinates(x.context()) for x in coordinates)
        #: the legs are enclosed from the pose's balls, never composed: on an opaque path,
        #: and for a robot with opaque constants (parameters outside the exact field,
        #: :mod:`singcheck.spec.real_constants`: their legs are not over Q)
        self.balls_only = self.opaque or is_opaque(model.context)
        self._last: tuple = (None, 0, None)  # (t, precision, point)

    def point(self, t: arb) -> list:
        """The balls of the robot's variables over ``t`` (joints 0, the pose's, square
        roots), remembered for the last ball."""
        last = self._last
        if last[0] is t and last[1] == ctx.prec:
            return last[2]
        point = _pose_point(self.model, [evaluate_path(x, t) for x in self.coordinates])
        self._last = (t, ctx.prec, point)
        return point

    def _limit_constraints(self, leg: Leg) -> dict:
        """A revolute joint's constraint at each of its limits (in the robot's ring),
        once per leg of the model (exact cos and sin of the limits: costly)."""
        model = self.model
        if leg.kind != REVOLUTE or leg.joint not in model.spec.joint_limits:
            return {}
        return memo_per_object(_LIMIT_CONSTRAINTS, leg, lambda leg: {
            value: limit_constraint(model, leg, value)
            for value in model.spec.joint_limits[leg.joint] if exact_angle_limit(value)})

    def _sources(self) -> list[fmpq_mpoly]:
        polys = []
        for leg in self.model.legs:
            polys += [*_leg_coefficients(leg), *self._limit_constraints(leg).values()]
        return polys

    def check(self) -> None:
        """:class:`TooCostly` when composing some leg polynomial would cost more than
        :data:`~singcheck.algebra.composition.MAX_COMPOSE_WORK` (the estimate
        :func:`compose_pose` refuses on), before anything is composed."""
        pose_vars = self.model.pose_variables
        args_in: dict = {}  # the images of a context's variables
        for p in memo_per_object(_DISTINCT_SOURCES, self.model, lambda _: self._distinct()):
            ring = p.context()
            args = args_in.get(ring)
            if args is None:
                args = args_in[ring] = _pose_args(p, self.coordinates, pose_vars)[1]
            if crude_work(p, args)[0] <= PIECE_WORK:
                continue
            work = composition_work(p, args)[0]
            if work > MAX_COMPOSE_WORK:
                raise TooCostly(f"composing would cost {work:.3g} by its a-priori estimate "
                                f"(at most {MAX_COMPOSE_WORK:.3g})")

    def _distinct(self) -> list[fmpq_mpoly]:
        """The model's distinct leg polynomials that are not constants."""
        seen: list[fmpq_mpoly] = []
        for p in self._sources():
            if not p.is_constant() and not any(p == q for q in seen):
                seen.append(p)
        return seen

    def along(self, c: fmpq_mpoly) -> fmpq_mpoly:
        for known, image in self._composed:
            if known == c:
                return image
        image = compose_pose(c, self.coordinates, self.model.pose_variables)
        self._composed.append((c, image))
        return image

    def leg(self, leg: Leg) -> tuple:
        """(coefficients, discriminant, limits) of one leg along the path."""
        coeffs = tuple(self.along(c) for c in _leg_coefficients(leg))
        disc = leg_discriminant(leg, coeffs)
        limits = {value: compose_pose(p, self.coordinates, self.model.pose_variables)
                  for value, p in self._limit_constraints(leg).items()}
        return coeffs, _reduce(disc) if disc is not None else None, limits


def exact_point(q) -> arb:
    """The ball of an exact rational time (exact when dyadic)."""
    return fraction_ball(q)
