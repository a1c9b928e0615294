"""Candidate singular times, their classification per working mode, and the verdict.

What is proven, and how:

* **Candidates.**  Every time at which some working mode (real or complex) is
  singular is a real root of μ(t) = ξ(φ(t)), because ξ vanishes on the whole projection
  of ``{F = 0, det A = 0}``.  Those roots are isolated in certified balls, each holding
  exactly one root (:mod:`singcheck.roots`); between them μ ≠ 0, so no mode is
  singular there.
* **Regular.**  A mode is not singular at a candidate when the ball enclosure of
  det A(ρ_mode(T), φ(T)) over the candidate's ball T excludes 0.
* **Singular, by elimination.**  For a leg-decoupled robot the working modes list every
  complex solution of the inverse kinematics, so μ(τ) = 0 means some mode's det A
  vanishes at τ.  When every other mode is proven non-zero on T, it is this one.  With
  square roots among the parameters, "every mode" includes the conjugate robots' modes
  (√p ↦ -√p, evaluated but never feasible), since ξ is normed over them; with revolute
  legs it needs W = a² + b² ≠ 0 on T for each (the joint integral over the pose there).
* **Singular, det A free of the joints.**  When det A involves no joint, ξ is det A
  (normed over the square roots): at a root of μ where every conjugate det A is proven
  non-zero, det A vanishes, in every mode at once.
* **Singular, exactly.**  At a root known exactly (a point ball, e.g. t = 0) where every
  enclosure is exact, det A evaluating to an exact 0 is a proof.
* **Singular, by sign change.**  When det A along a real mode has proven opposite signs
  at the two ends of T, it vanishes inside T (intermediate values); that zero is a
  root of μ in T, hence τ itself (T isolates one root).
* **Singular or regular, exactly (algebraic).**  Where none of the above decides (a
  tangency, several modes vanishing at once), a root whose time is algebraic (every
  root of a polynomial or sin/cos path, and t = kπ of a mixed one) is decided exactly
  in Q(α)(√D₁, …) by :mod:`singcheck.certify.exact`.
* **On the surface.**  When μ ≡ 0, each feasible mode is decided on its own: det A ≡ 0
  along it, or the roots of a non-zero polynomial holding its zeros are its candidates
  (classified for that mode alone, without the elimination proof).
* Anything else, after refining T, is ``unknown`` for that mode, with the reason.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from flint import acb, arb

from singcheck.algebra.intervals import excludes_zero, sign, working_precision
from singcheck.algebra.radicals import evaluate_path
from singcheck.budget import checkpoint
from singcheck.certify.path import PathModel, joint_float
from singcheck.certify.working_modes import (
    FEASIBLE,
    INFEASIBLE,
    UNKNOWN,
    WorkingMode,
    gap_points,
    working_modes,
)
from singcheck.roots.enclosures import IdenticallyZeroError, RealRoot
from singcheck.roots.isolation import isolate_real_roots
from singcheck.roots.rational import arb_to_fmpq
from singcheck.spec.files import TrajectorySpec

SINGULAR, REGULAR = "singular", "regular"
BY_ELIMINATION = "elimination"
BY_SIGN_CHANGE = "sign change"
BY_EXCLUSION = "det A ≠ 0 (ball arithmetic)"
BY_EXACT_ZERO = "det A = 0 exactly"
BY_ALGEBRAIC_ZERO = "det A = 0 exactly (algebraic)"
BY_ALGEBRAIC_NONZERO = "det A ≠ 0 exactly (algebraic)"
BY_IDENTICALLY_ZERO = "det A ≡ 0 along the path (exact)"
BY_JOINT_FREE = "det A free of the joints (ξ = det A)"

VERDICT_FREE = "singularity-free"
VERDICT_SINGULAR = "singular"
VERDICT_INFEASIBLE = "infeasible"
VERDICT_UNKNOWN = "unknown"


@dataclass(frozen=True)
class ModeAtCandidate:
    mode: str
    status: str  # singular | regular | unknown
    proof: str  # how it was decided, or why not


@dataclass
class Candidate:
    root: RealRoot
    pose: list[arb]
    joints: dict[str, dict[str, float | None]]  # feasible mode -> joint -> value
    modes: list[ModeAtCandidate]
    status: str = UNKNOWN  # real | spurious | unknown
    segment: int = 1  # the piece of a multi-piece path it lies on (1 = the first)

    @property
    def t(self) -> arb:
        return self.root.t

    @property
    def singular_modes(self) -> list[str]:
        return [m.mode for m in self.modes if m.status == SINGULAR]


@dataclass
class TrajectoryReport:
    path: PathModel
    verdict: str
    reason: str
    candidates: list[Candidate]
    modes: list[WorkingMode]
    root_method: str
    undecided: list = field(default_factory=list)  # (t ball, reason) left unproven
    mu_roots_complete: bool = False  # every root of μ isolated (the candidates are all)
    spec: TrajectorySpec | None = None  # the whole path (None: path.trajectory)
    pieces: list[TrajectoryReport] = field(default_factory=list)  # per segment, if several

    @property
    def trajectory(self) -> TrajectorySpec:
        """The whole path's spec (all its segments)."""
        return self.spec or self.path.trajectory

    @property
    def name(self) -> str:
        return self.trajectory.name


def _mode_values(path: PathModel, modes: list[WorkingMode], t: arb):
    pose = path.pose_at(t)
    variables = path.pose_variables_at(t)
    per_leg = [leg.branches(t) for leg in path.legs]
    values: dict[str, arb | acb | None] = {}
    joints: dict[str, list] = {}
    complete = {}
    for mode in modes:
        js = [per_leg[i][b.label] for i, b in enumerate(mode.branches)]
        joints[mode.label] = js
        values[mode.label] = None
        if not any(j is None for j in js):
            complete[mode.label] = js
    values.update(path.det_A_modes(complete, variables))  # the pose part once for all
    return pose, joints, values


def _conjugate_values(path: PathModel, modes: list[WorkingMode], t: arb) -> list:
    """det A of every mode of every conjugate robot (square roots' signs flipped)."""
    from itertools import product

    from singcheck.algebra.radicals import radical_variables

    primes = [q for _, q in radical_variables(path.projection.model.context)]
    if not primes:
        return []
    variables = path.pose_variables_at(t)
    out = []
    for signs in product((1, -1), repeat=len(primes)):
        if -1 not in signs:
            continue
        sigma = dict(zip(primes, signs, strict=True))
        per_leg = path.conjugate_branches(t, variables, sigma)
        for mode in modes:
            js = [per_leg[i][b.label] for i, b in enumerate(mode.branches)]
            out.append(None if any(j is None for j in js) else
                       path.det_A(js, variables, sigma))
    return out


def _integral(path: PathModel, t: arb) -> bool:
    """W ≠ 0 on the ball for every revolute leg (its joint integral over the pose)."""
    return all(excludes_zero(evaluate_path(w, t)) for w in path.degenerate)


def _sign_at(path: PathModel, mode: WorkingMode, point: arb) -> int | None:
    _, _, values = _mode_values(path, [mode], point)
    value = values[mode.label]
    return sign(value) if isinstance(value, arb) else None


def _branches_continuous(path: PathModel, t: arb) -> bool:
    """True when every quadratic leg's discriminant is proven > 0 on the whole ball:
    then each branch is real and continuous there, as the intermediate value
    theorem needs."""
    return all(leg.discriminant is None or evaluate_path(leg.discriminant, t) > 0
               for leg in path.legs)


def _decide(path, modes, root: RealRoot, by_elimination: bool = True):
    """One attempt at the given enclosure; returns ``{mode: ModeAtCandidate}``."""
    pose, joints, values = _mode_values(path, modes, root.t)
    decided: dict[str, ModeAtCandidate] = {}
    open_modes = []
    conjugate = _conjugate_values(path, modes, root.t) if not path.projection.model.polynomial \
        else []
    conjugates_regular = all(v is not None and excludes_zero(v) for v in conjugate)
    if path.projection.model.joint_free_det_A and conjugates_regular:
        return pose, joints, {m.label: ModeAtCandidate(m.label, SINGULAR, BY_JOINT_FREE)
                              for m in modes}
    for mode in modes:
        v = values[mode.label]
        if v is not None and excludes_zero(v):
            decided[mode.label] = ModeAtCandidate(mode.label, REGULAR, BY_EXCLUSION)
        elif v is not None and v.is_exact() and v == 0:
            # an exactly known root, evaluated without rounding: det A is 0 there
            decided[mode.label] = ModeAtCandidate(mode.label, SINGULAR, BY_EXACT_ZERO)
        else:
            open_modes.append(mode)
    if by_elimination and len(open_modes) == 1 and conjugates_regular and \
            _integral(path, root.t):
        m = open_modes[0]
        decided[m.label] = ModeAtCandidate(m.label, SINGULAR, BY_ELIMINATION)
        open_modes = []
    if open_modes and not _branches_continuous(path, root.t):
        return pose, joints, decided
    for mode in open_modes:
        lo, hi = _sign_at(path, mode, root.t.lower()), _sign_at(path, mode, root.t.upper())
        if lo is not None and hi is not None and lo != hi:
            decided[mode.label] = ModeAtCandidate(mode.label, SINGULAR, BY_SIGN_CHANGE)
    return pose, joints, decided


def _decide_exactly(path, modes, time) -> dict[str, ModeAtCandidate]:
    """The modes that ball arithmetic left open, decided in Q(α) (:mod:`.exact`, loaded
    only when balls did not decide)."""
    from singcheck.certify.exact import AlgebraicPoint, NotExact, det_a_vanishes_at

    out = {}
    try:
        point = AlgebraicPoint(time)
        for mode in modes:
            if det_a_vanishes_at(path, point, mode.label):
                out[mode.label] = ModeAtCandidate(mode.label, SINGULAR, BY_ALGEBRAIC_ZERO)
            else:
                out[mode.label] = ModeAtCandidate(mode.label, REGULAR, BY_ALGEBRAIC_NONZERO)
    except NotExact:
        pass
    return out


def classify_candidate(path: PathModel, modes: list[WorkingMode], root: RealRoot,
                       tolerance: float, by_elimination: bool = True) -> Candidate:
    """Decide, for every working mode, whether it is singular at this root of μ.

    ``by_elimination=False`` when ``modes`` are not every mode that may vanish at the
    root (candidates of one mode on a path lying on ξ = 0)."""
    decided: dict[str, ModeAtCandidate] = {}
    shown_at = None
    r = root
    for step, prec in enumerate((53, 128, 256)):
        if step:
            r = r.refined(tolerance * 10.0 ** (-8 * step))
        with working_precision(prec):
            pose, joints, newly = _decide(path, modes, r, by_elimination)
        shown_at = shown_at or (pose, joints)
        for label, verdict in newly.items():
            decided.setdefault(label, verdict)
        if len(decided) == len(modes):
            break
    if len(decided) < len(modes) and root.exact is not None:
        decided.update(_decide_exactly(path, [m for m in modes if m.label not in decided],
                                       root.exact))
    pose, joints = shown_at
    per_mode = [decided.get(m.label) or ModeAtCandidate(
        m.label, UNKNOWN, "neither det A ≠ 0 nor a zero could be proven at this root")
        for m in modes]
    feasible = {m.label for m in modes if m.status == FEASIBLE}
    states = {pm.status for pm in per_mode if pm.mode in feasible}
    status = "real" if SINGULAR in states else "unknown" if UNKNOWN in states else "spurious"
    shown = {m.label: {leg.leg.joint: joint_float(v)
                       for leg, v in zip(path.legs, joints[m.label], strict=True)}
             for m in modes if m.status == FEASIBLE}
    return Candidate(root, pose, shown, per_mode, status)


def _periodic(path: PathModel) -> bool:
    """Whether everything along the path is 2π-periodic in t: no polynomial of it
    (pose, pose coordinates, legs, μ) involves the bare t."""
    from singcheck.algebra.trig import uses_t

    polys = [*path.phi, *path.coordinates, path.mu, *path.degenerate]
    for leg in path.legs:
        polys += [*leg.coefficients, leg.discriminant]
    return not any(uses_t(p) for p in polys if p is not None)


def _classify_all(path: PathModel, modes: list[WorkingMode], roots, tolerance: float
                  ) -> list[Candidate]:
    """Every root classified.  On a path free of the bare t everything the
    classification looks at (the pose, each mode's joints, det A) is 2π-periodic, so
    the root τ + 2kπ has exactly the classification of τ: a root known to be a 2kπ
    shift of one already classified (``RealRoot.period``) takes its verdicts per mode,
    with their proofs, and its pose and joints."""
    periodic = _periodic(path)
    done: dict[int, Candidate] = {}
    out = []
    for r in roots:  # hundreds for a high-degree μ
        checkpoint()
        base = done.get(r.period[0]) if periodic and r.period is not None else None
        if base is None:
            candidate = classify_candidate(path, modes, r, tolerance)
            if periodic and r.period is not None:
                done[r.period[0]] = candidate
        else:
            candidate = replace(base, root=r)
        out.append(candidate)
    return out


def _clear_undecided(path, modes, box) -> bool:
    """True when there is a feasible mode and every feasible mode's det A provably stays
    away from 0 on the box (with no feasible mode nothing clears it: the box is kept in
    the report, not dropped)."""
    feasible = [m for m in modes if m.status == FEASIBLE]
    if not feasible:
        return False
    _, _, values = _mode_values(path, feasible, box.t)
    return all(v is not None and excludes_zero(v) for v in values.values())


def certify_path(path: PathModel, tolerance: float = 1e-9) -> TrajectoryReport:
    """The verdict for one trajectory, with everything that supports it."""
    modes = working_modes(path, tolerance)
    try:
        isolation = isolate_real_roots(path.mu, path.trajectory.range, tolerance)
    except IdenticallyZeroError:
        return _certify_on_surface(path, modes, tolerance)
    candidates = _classify_all(path, modes, isolation.roots, tolerance)
    for mode in modes:
        mode.singular_times = [c for c in candidates if mode.label in c.singular_modes]
    undecided = [(b.t, b.reason) for b in isolation.undecided
                 if not _clear_undecided(path, modes, b)]
    verdict, reason = verdict_of(modes, candidates, undecided)
    return TrajectoryReport(path, verdict, reason, candidates, modes, isolation.method,
                            undecided, not isolation.undecided)


def _certify_on_surface(path: PathModel, modes: list[WorkingMode],
                        tolerance: float) -> TrajectoryReport:
    """μ ≡ 0: the path lies on ξ(X) = 0, so μ gives no candidates.  Each feasible mode is
    decided on its own (:func:`.exact.mode_zero_polynomial`): det A ≡ 0 along it (singular
    all along), or a non-zero trig polynomial whose roots hold its zeros, which are then
    isolated and classified for that mode alone (no elimination proof: the other modes
    are not looked at).  Infeasible modes are not examined."""
    from singcheck.certify.exact import NotExact

    interval = path.trajectory.range
    feasible = [m for m in modes if m.status == FEASIBLE]
    middle = gap_points(interval, [])
    samples = [arb_to_fmpq(t) for t in middle + gap_points(interval, middle)]
    candidates, undecided, method, complete = [], [], "none", True
    for mode in feasible:
        try:
            zeros = _mode_zeros(path, mode, samples)
        except NotExact as why:
            candidates.append(_on_surface_candidate(path, mode, UNKNOWN, str(why)))
            continue
        if zeros is None:
            candidates.append(_on_surface_candidate(path, mode, SINGULAR, BY_IDENTICALLY_ZERO))
            continue
        isolation = isolate_real_roots(zeros, interval, tolerance)
        method = isolation.method
        complete = complete and not isolation.undecided
        for r in isolation.roots:
            c = classify_candidate(path, [mode], r, tolerance, by_elimination=False)
            candidates.append(c)
        undecided += [(b.t, b.reason) for b in isolation.undecided
                      if not _clear_undecided(path, [mode], b)]
    candidates.sort(key=lambda c: float(c.t.mid()))
    for mode in modes:
        mode.singular_times = [c for c in candidates if mode.label in c.singular_modes]
    verdict, reason = verdict_of(modes, candidates, undecided)
    if verdict == VERDICT_FREE:
        reason += " (the path lies on ξ(X) = 0: each mode was decided on its own)"
    return TrajectoryReport(path, verdict, reason, candidates, modes, method, undecided,
                            complete)


def _mode_zeros(path: PathModel, mode: WorkingMode, samples: list):
    """:func:`.exact.mode_zero_polynomial` at the first sample time where ball arithmetic
    tells a mode from its conjugate (a sample may happen to be a zero of the non-vanishing
    one)."""
    from singcheck.certify.exact import NotExact, mode_zero_polynomial

    why = None
    for t0 in samples:
        try:
            return mode_zero_polynomial(path, mode.label, t0)
        except NotExact as e:
            why = e
            if "conjugate" not in str(e):
                break
    raise why


def _on_surface_candidate(path, mode, status, proof) -> Candidate:
    """The whole path for one mode, shown at the range start."""
    t = path.trajectory.range.start.ball()
    pose, joints, _ = _mode_values(path, [mode], t)
    shown = {mode.label: {leg.leg.joint: joint_float(v)
                          for leg, v in zip(path.legs, joints[mode.label], strict=True)}}
    state = "real" if status == SINGULAR else UNKNOWN
    return Candidate(RealRoot(t, None), pose, shown, [ModeAtCandidate(mode.label, status, proof)],
                     state)


def verdict_of(modes, candidates, undecided) -> tuple[str, str]:
    """The verdict and its one-sentence reason from the modes' feasibility, the
    classified candidates and what root isolation left undecided."""
    feasible = [m for m in modes if m.status == FEASIBLE]
    unsure = [m for m in modes if m.status == UNKNOWN]
    singular = [(m.label, c) for c in candidates for m in feasible
                if m.label in c.singular_modes]
    if singular:
        label, c = singular[0]
        if any(m.proof == BY_IDENTICALLY_ZERO for m in c.modes):
            return VERDICT_SINGULAR, (f"working mode {label} is singular along the whole "
                                      "path (det A ≡ 0: the path lies on its singularity "
                                      "surface)")
        return VERDICT_SINGULAR, (f"working mode {label} is singular at t ≈ "
                                  f"{float(c.t.mid()):.6g}")
    if not feasible and not unsure:
        reasons = sorted({m.reason for m in modes if m.status == INFEASIBLE})
        return VERDICT_INFEASIBLE, "no working mode stays in the workspace and joint limits: " \
            + "; ".join(reasons)
    if unsure:
        return VERDICT_UNKNOWN, "feasibility of working mode(s) " + ", ".join(
            f"{m.label} ({m.reason})" for m in unsure) + " could not be proven"
    open_candidates = [c for c in candidates if c.status == UNKNOWN]
    if open_candidates:
        return VERDICT_UNKNOWN, "could not classify the candidate(s) at t ≈ " + ", ".join(
            f"{float(c.t.mid()):.6g}" for c in open_candidates)
    if undecided:
        return VERDICT_UNKNOWN, "root isolation left sub-ranges undecided: " + "; ".join(
            reason for _, reason in undecided)
    return VERDICT_FREE, "every feasible working mode (" + ", ".join(
        m.label for m in feasible) + ") is proven free of parallel singularities"
