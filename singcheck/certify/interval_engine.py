"""The interval engine: det A along each working mode, enclosed by ball arithmetic.

It reads what the path model evaluates — the pose φ(T), each leg's closed-form branch
(quadratic for a prismatic leg, the (cos, sin) pair for a revolute one) and det A of
the robot — on balls T of the parameter, and never μ or anything the elimination made.
That makes it the second, independent computation behind every verdict
(:mod:`.engines` compares the two).

What it proves, per working mode given as *feasible* (its branches real, separated and
inside the limits on the whole closed range, so det A along it is continuous):

* **det A ≠ 0 on a piece T**: the ball enclosure of det A(φ(T), ρ_mode(T)) excludes 0
  (FLINT's comparisons are certain; every operation rounds outward).  Its sign there
  is proven too.
* **A crossing in a window W**: the pieces just left and right of W carry proven,
  opposite signs; det A is continuous, so it vanishes in W (intermediate values).

Pieces that are not proven are halved (the enclosures tighten as balls shrink) until
they are narrower than :data:`MIN_WIDTH` of the range or the evaluation budget is
spent; what is left are *windows*, each with the proven bound |det A| ≤ ε on it.  A
window whose two sides have the same sign (or touch a range end) may hold a tangency,
an even number of crossings, or nothing: the interval engine does not guess.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from flint import arb, ctx

from singcheck.algebra.ball_programs import ball_program
from singcheck.algebra.intervals import excludes_zero, sign
from singcheck.algebra.radicals import radical_balls
from singcheck.budget import checkpoint
from singcheck.certify.covers import halves, pieces
from singcheck.certify.mode_programs import mode_program
from singcheck.model.robot import REVOLUTE

#: the narrowest piece that is halved again, relative to the range's length
MIN_WIDTH = 2.0 ** -26
#: ... for a piece holding a time the caller expects det A to vanish at (a hint: the
#: window left there only has to be narrow enough to tell that zero from others)
HINT_WIDTH = 2.0 ** -14
#: pieces of the first cover per 2π of range (FIRST_COVER), or PER_HARMONIC per 2π and
#: per harmonic of the path (a coordinate's degree in sin t, cos t) when that is more;
#: at least MIN_FIRST_COVER, at most MAX_FIRST_COVER.  Wider pieces failed every test on
#: the bench's paths (their enclosures hold 0), so the halving starts there rather than
#: at six pieces (heart 1, 4 harmonics: 5.4 -> 4.3 ms; the [-10π, 10π] heart 1: 52 -> 31
#: ms).  16 and 8 won a scan of 9 settings (12, 16, 24 × 4, 6, 8) over 9 bench paths,
#: by balls of t weighted by their cost (the helix: 98 balls at 24, 77 at 16)
FIRST_COVER = 16
PER_HARMONIC = 8
MIN_FIRST_COVER = 6
MAX_FIRST_COVER = 256
#: ball evaluations (all the modes at once) per 2π of range, at least BUDGET
BUDGET = 20000


@dataclass(frozen=True)
class Window:
    """A stretch [lo, hi] on which det A along the mode was not proven ≠ 0."""

    lo: float
    hi: float
    bound: float  # proven: |det A| ≤ bound on the whole window (inf when not enclosed)
    left: int | None  # the proven sign just before the window (None: a range end)
    right: int | None  # ... and just after it

    @property
    def crossing(self) -> bool:
        """Proven: det A vanishes in the window (opposite signs around it)."""
        return self.left is not None and self.right is not None and self.left != self.right

    def overlaps(self, t: arb) -> bool:
        return not (t.upper() < self.lo or t.lower() > self.hi)


@dataclass
class ModeSearch:
    """What the interval engine proved about det A along one working mode."""

    label: str
    proven: list[tuple[float, float, int]] = field(default_factory=list)  # (lo, hi, sign)
    windows: list[Window] = field(default_factory=list)

    @property
    def free(self) -> bool:
        """Proven: det A ≠ 0 along the mode on the whole range."""
        return not self.windows

    @property
    def crossings(self) -> list[Window]:
        return [w for w in self.windows if w.crossing]

    def nonzero_on(self, t: arb) -> bool:
        """Proven: det A ≠ 0 on all of the ball t (it lies in one proven piece)."""
        lo, hi = t.lower(), t.upper()
        return any(a <= lo and hi <= b for a, b, _ in self.proven)


def _bound(value) -> float:
    """An upper bound of |value| over its ball (inf when there is none)."""
    if not isinstance(value, arb) or not value.is_finite():
        return math.inf
    return float(abs(value).upper())


def mode_values(path, modes: list, t: arb):
    """(pose, joints per mode, det A per mode) enclosed over the ball ``t``: the pose and
    the legs' branches once for all the modes, det A's pose part once (a mode whose
    branches are not all real there gets None)."""
    program = mode_program(path)
    if program is not None:  # the same enclosures, walked by a plan made once
        return program(path, t, modes)
    pose, variables = path.pose_and_variables_at(t)
    per_leg = path.leg_branches_at(t, variables)
    values: dict = {}
    joints: dict[str, list] = {}
    complete = {}
    for mode in modes:  # (plain loops: this runs for every mode at every candidate)
        js = []
        real = True
        for leg, b in zip(per_leg, mode.branches, strict=True):
            j = leg[b.label]
            real = real and j is not None
            js.append(j)
        joints[mode.label] = js
        values[mode.label] = None
        if real:
            complete[mode.label] = js
    values.update(path.det_A_modes(complete, variables))  # the pose part once for all
    return pose, joints, values


def search_det_a(path, modes: list, refine: set[str] | None = None,
                 budget: int | None = None, hints: dict | None = None,
                 mean_value_form: bool = True) -> dict[str, ModeSearch]:
    """Branch-and-bound of det A along each of ``modes`` (given as feasible) over the
    path's closed range.  Only the modes in ``refine`` (default: all) are refined past the
    first cover; the others are enclosed once on each of its pieces (a mode said to be
    singular all along: every piece stays a window, and refining it would cost
    everything).  All the modes open on a piece share one enclosure of the pose and the
    legs there.  ``hints`` (per mode, balls of t where det A is expected to vanish) only
    stop the halving early around them (:data:`HINT_WIDTH`): they change no proof."""
    interval = path.trajectory.range
    width = float(interval.end) - float(interval.start)
    smallest = max(width * MIN_WIDTH, 1e-300)
    near = max(width * HINT_WIDTH, smallest)
    hints = hints or {}
    periods = max(1.0, width / (2 * math.pi))
    left = budget if budget is not None else int(BUDGET * periods)
    refine = {m.label for m in modes} if refine is None else refine
    found: dict[str, dict[tuple[float, float], tuple[int | None, float]]] = {
        m.label: {} for m in modes}
    first = _first_cover(path, width)
    todo = deque((piece, list(modes)) for piece in pieces(interval, first))
    while todo:  # breadth first: a spent budget leaves the whole range equally refined
        checkpoint()
        piece, open_modes = todo.popleft()
        _, joints, values = mode_values(path, open_modes, piece)
        left -= 1
        lo, hi = float(piece.lower()), float(piece.upper())
        unproven = [m for m in open_modes if not (isinstance(values[m.label], arb)
                                                 and excludes_zero(values[m.label]))]
        monotone: dict[str, tuple[int, int]] = {}
        if unproven and mean_value_form:
            forms = mean_value(path, unproven, piece, joints)
            for label, (v, _) in forms.items():
                if excludes_zero(v) or not isinstance(values[label], arb):
                    values[label] = v
            steep = [m for m in unproven if m.label in forms
                     and not excludes_zero(values[m.label]) and excludes_zero(forms[m.label][1])]
            if steep:
                monotone = _end_signs(path, steep, piece)
        again = []
        for mode in open_modes:
            v = values[mode.label]
            ends = monotone.get(mode.label)
            if isinstance(v, arb) and excludes_zero(v):
                found[mode.label][lo, hi] = (sign(v), _bound(v))
            elif ends is not None and ends[0] == ends[1]:  # monotone, one sign at both ends
                found[mode.label][lo, hi] = (ends[0], _bound(v))
            elif ends is not None:  # monotone between opposite signs: one simple crossing
                found[mode.label][lo, hi] = (None, _bound(v), ends)
            elif mode.label in refine and left > 0 and hi - lo > smallest and not (
                    hi - lo <= near and any(h.overlaps(piece) for h in
                                            hints.get(mode.label, ()))):
                again.append(mode)
            else:
                found[mode.label][lo, hi] = (None, _bound(v))
        if again:
            a, b = halves(piece)
            todo += [(a, again), (b, again)]
    return {label: _summarise(label, pieces_found) for label, pieces_found in found.items()}


def _first_cover(path, width: float) -> int:
    """The number of pieces the search starts from (:data:`PER_HARMONIC`)."""
    harmonic = path.harmonic or 0
    per_period = max(FIRST_COVER, PER_HARMONIC * harmonic)
    return min(MAX_FIRST_COVER, max(MIN_FIRST_COVER, round(per_period * width / (2 * math.pi))))


def inside_range(path, piece: arb) -> tuple[arb, arb]:
    """The piece's two ends as points of the closed range: a cover's first and last
    balls may reach an ulp past the range (rounded radii), and a sign proven there would
    place a zero outside it; such an end is replaced by the range end's own ball (exact,
    or a tight ball about an irrational end such as π: a sign proven on it holds at the
    end itself).  (Fuzz campaign, issue 31: y = 10⁻⁹¹ + 3t/40 on [0, 10] of the biglide,
    det A = 4y(q - p) < 0 at t = -1.6·10⁻⁹, made a crossing the exact engine rightly did
    not find, an ``inconsistent`` error, exit 70.)"""
    rng = path.trajectory.range
    start, end = rng.start.ball(), rng.end.ball()
    lo, hi = arb(piece.lower()), arb(piece.upper())
    if not lo > start:
        lo = start
    if not hi < end:
        hi = end
    return lo, hi


def _end_signs(path, modes: list, piece: arb) -> dict[str, tuple[int, int]]:
    """The proven signs of det A at the two ends of the piece (exact points) for each
    mode where both are proven."""
    lo, hi = inside_range(path, piece)
    _, _, at_lo = mode_values(path, modes, lo)
    _, _, at_hi = mode_values(path, modes, hi)
    out = {}
    for mode in modes:
        a, b = at_lo[mode.label], at_hi[mode.label]
        if isinstance(a, arb) and isinstance(b, arb) and excludes_zero(a) and excludes_zero(b):
            out[mode.label] = (sign(a), sign(b))
    return out


def _summarise(label: str, found: dict) -> ModeSearch:
    """The proven pieces and the windows (maximal runs of unproven pieces, with the
    signs on either side) of one mode.  A piece on which det A is proven monotone
    between opposite signs is a window of its own with those signs: one simple crossing,
    whatever its neighbours."""
    out = ModeSearch(label)
    run: list = []
    before: int | None = None
    monotone: Window | None = None  # the last window, when a proven simple crossing

    def close(after: int | None) -> None:
        if run:
            out.windows.append(Window(run[0][0], run[-1][1], max(r[2] for r in run),
                                      before, after))
            run.clear()

    for (lo, hi), entry in sorted(found.items()):
        s, bound = entry[0], entry[1]
        if len(entry) == 3:  # a proven simple crossing
            close(None)
            left, right = entry[2]
            last = monotone
            if (last is not None and out.windows and out.windows[-1] is last
                    and lo <= last.hi and last.right != left):
                # two simple crossings on pieces that overlap (their balls' rounded
                # ends): this one's sign changes between its start and the last one's
                # end, both inside the last piece, where det A has one zero only: the
                # same zero, counted once (y = sin(2πt)/2 of the biglide, t = 1/2)
                end, after = (hi, right) if hi >= last.hi else (last.hi, last.right)
                out.windows[-1] = Window(last.lo, end, max(bound, last.bound), last.left,
                                         after)
            else:
                out.windows.append(Window(lo, hi, bound, left, right))
            monotone = out.windows[-1]
            before = right
            continue
        monotone = None
        if s is None:
            run.append((lo, hi, bound))
            continue
        out.proven.append((lo, hi, s))
        close(s)
        before = s
    close(None)
    return out


# -- the mean-value form: det A(T) ⊆ det A(m) + (d/dt det A)(T)·(T − m) ---------------------

_DERIVATIVES: dict = {}


def _derivative_parts(model):
    """Per model, once: ∂det A/∂v for every variable v it involves, and per leg what its
    joint's rate along the path is formed from (:func:`mean_value`):

    * a quadratic prismatic leg a·ρ² + b·ρ + c (a constant): ∇ₓb and ∇ₓD, D = b² − 4ac
      expanded, and D itself: ρ' = (−b' + σ·D'/(2√D))/(2a) on its branch σ;
    * a revolute leg P·cos θ + Q·sin θ + R: ∇ₓ of the constraint and Δ = P² + Q² − R²:
      θ' = −(∇ₓf·X')/(σ√Δ), since ∂f/∂θ = Q·cos θ − P·sin θ = σ√Δ on branch σ;
    * another leg: ∇ₓf and ∂f/∂ρ: ρ' = −(∇ₓf·X')/(∂f/∂ρ).

    The closed forms are the implicit derivative with ∂f/∂ρ replaced by the value it
    has on the branch, σ√D (and, for the prismatic leg, ρ itself eliminated from the
    numerator): the same function, enclosed without the dependency between a wide ball
    of ρ and the pose's balls (heart 1's slopes: about 35% narrower)."""
    from singcheck.algebra.polynomials import constant_value, memo_per_object
    from singcheck.model.robot import REVOLUTE, leg_coefficients, leg_discriminant

    def build(model):
        names = model.context.names()
        n_joint = len(model.joint_variables)
        n_pose = len(model.pose_variables)
        pose_range = range(n_joint, n_joint + n_pose)
        det = [(i, model.det_A.derivative(i)) for i, d in enumerate(model.det_A.degrees())
               if d > 0 and i < n_joint + n_pose]

        def grad(q):
            return [(i, q.derivative(i)) for i in pose_range if q.degrees()[i] > 0]

        legs = []
        for leg in model.legs:
            f = leg.constraint
            idx = [names.index(v) for v in leg.variables]
            coefficients = leg_coefficients(leg)
            if leg.kind == REVOLUTE:
                legs.append((REVOLUTE, idx, grad(f), (leg_discriminant(leg, coefficients),)))
            elif leg.degree == 2 and coefficients[0].is_constant():
                disc = leg_discriminant(leg, coefficients)
                legs.append((QUADRATIC, idx, grad(coefficients[1]),
                             (grad(disc), disc, 2 * constant_value(coefficients[0]))))
            else:
                legs.append(("prismatic", idx, grad(f), (f.derivative(idx[0]),)))
        return n_joint, det, legs

    return memo_per_object(_DERIVATIVES, model, build)


QUADRATIC = "quadratic"


def _derivative_polys(model) -> list:
    """:func:`_derivative_parts`' polynomials in the order :func:`mean_value` reads
    them: per leg its gradient, then (quadratic) ∇ₓD and D, (revolute) Δ, (other)
    ∂f/∂ρ; then det A's partial derivatives."""
    _, det_parts, legs = _derivative_parts(model)
    out = []
    for kind, _, dx, extra in legs:
        out += [q for _, q in dx]
        if kind == QUADRATIC:
            out += [q for _, q in extra[0]] + [extra[1]]
        else:
            out.append(extra[0])
    return out + [q for _, q in det_parts]


def _evaluator(polys: list, point: list, powers: dict):
    """Each call: the ball of the next polynomial of ``polys`` at ``point``."""
    from singcheck.algebra.intervals import evaluate

    return (evaluate(q, point, powers) for q in polys).__next__


def mean_value(path, modes: list, t: arb, joints: dict) -> dict:
    """(det A, its derivative along the mode) per mode over the ball ``t``, det A in
    mean-value form (a mode where it could not be formed is left out): det A at the
    midpoint, plus the enclosure of its derivative along the mode over ``t`` times
    (t − m).  The derivative: ∂det A/∂v · v' summed over
    the pose variables (v' from d/dt of the path) and the joints (implicit
    differentiation of each leg f(ρ, X) = 0: ρ' = −(∇ₓf·X')/(∂f/∂ρ); a revolute joint's
    θ' = −(∇ₓf·X')/(b·cos θ − a·sin θ), then (cos θ)' = −sin θ·θ', (sin θ)' = cos θ·θ').
    Every quantity is a ball enclosing its values over ``t``, so the result encloses
    det A over ``t`` (the mean value theorem, on a continuous branch of a feasible mode).
    ``joints``: each mode's joint balls over ``t`` (:func:`mode_values`)."""
    model = path.projection.model
    if len(model.det_A) > 5000:
        return {}
    fast = mode_program(path)
    rates = fast.rates(t) if fast is not None else path.pose_rates_at(t, angle_functions=False)
    if rates is None:
        return {}
    parts = _compiled_parts(model)
    if parts is not None:  # every partial derivative at once, then the rates
        return _compiled_mean_value(parts, path, modes, t, joints, rates)
    n_joint, det_parts, legs = _derivative_parts(model)
    radicals = [b for _, b in sorted(radical_balls(model.context).items())]
    m, variables, points = _mode_points(path, modes, t, joints)
    out = {}
    for mode, mid, flat in points:
        point = flat + variables + radicals
        speed = [_ZERO] * n_joint + rates
        sigmas = _branch_signs(mode)
        ball = _evaluator(_derivative_polys(model), point, {})  # too many terms: one by one
        for (kind, idx, dx, extra), sigma in zip(legs, sigmas, strict=True):
            push = arb(0)
            for i, _ in dx:
                push += ball() * speed[i]
            if kind == QUADRATIC:  # ρ' = (−b' + σ·D'/(2√D))/(2a)
                d_rate = arb(0)
                for i, _ in extra[0]:
                    d_rate += ball() * speed[i]
                disc = ball()
                if not disc > 0 or sigma is None:
                    break
                speed[idx[0]] = (-push + sigma * d_rate / (2 * disc.sqrt())) / extra[2]
            elif kind == REVOLUTE:  # θ' = −(∇ₓf·X')/(σ√Δ)
                disc = ball()
                if not disc > 0 or sigma is None:
                    break
                c, s = point[idx[0]], point[idx[1]]
                rate = -push / (sigma * disc.sqrt())
                speed[idx[0]], speed[idx[1]] = -s * rate, c * rate
            else:
                speed[idx[0]] = -push / ball()
        else:
            slope = arb(0)
            for i, _ in det_parts:
                slope += ball() * speed[i]
            value = mid + slope * (t - m)
            if value.is_finite():
                out[mode.label] = (value, slope)
    return out


_ZERO = arb(0)
_COMPILED_PARTS: dict = {}


def _compiled_parts(model):
    """(joints' count, the compiled program of :func:`_derivative_polys`, the compiled
    :func:`_assembler`, the robot's square roots' balls) once per model and precision,
    None when the program is too large to compile (then the loop of
    :func:`mean_value`)."""
    key = (id(model), ctx.prec)
    hit = _COMPILED_PARTS.get(key)
    if hit is not None and hit[0] is model:
        return hit[1]
    if len(_COMPILED_PARTS) > 64:
        _COMPILED_PARTS.clear()
    program = ball_program(model, "mean value", _derivative_polys)
    parts = None if program is None else (
        _derivative_parts(model)[0], program, _assembler(model),
        [b for _, b in sorted(radical_balls(model.context).items())])
    _COMPILED_PARTS[key] = (model, parts)
    return parts


def _mode_points(path, modes: list, t: arb, joints: dict):
    """(m, the pose variables' balls over ``t``, [(mode, det A at m, its joint balls over
    ``t`` flattened)]) for the mean-value form: m the midpoint of ``t``, each mode whose
    det A at m and joints over ``t`` are all real balls."""
    variables = path.pose_variables_at(t)  # (before the midpoint's: the caller's, kept)
    m = arb(t.mid())
    _, _, at_mid = mode_values(path, modes, m)
    points = []
    for mode in modes:
        js, mid = joints[mode.label], at_mid[mode.label]
        if not isinstance(mid, arb) or any(j is None for j in js):
            continue
        flat = []
        for j in js:
            flat += list(j) if isinstance(j, tuple) else [j]
        if all(isinstance(v, arb) for v in flat):
            points.append((mode, mid, flat))
    return m, variables, points


def _compiled_mean_value(parts, path, modes: list, t: arb, joints: dict,
                         rates: list) -> dict:
    """:func:`mean_value` by the model's compiled programs (:func:`_compiled_parts`):
    the same balls and operations as its loop, the lookups made once."""
    n_joint, program, assemble, radicals = parts
    m, variables, points = _mode_points(path, modes, t, joints)
    head = [_ZERO] * n_joint
    out = {}
    for mode, mid, flat in points:
        point = flat + variables + radicals
        slope = assemble(program(point), head + rates, _branch_signs(mode), point)
        if slope is not None:
            value = mid + slope * (t - m)
            if value.is_finite():
                out[mode.label] = (value, slope)
    return out


_ASSEMBLERS: dict = {}


def _assembler(model):
    """``assemble(B, speed, sigmas, point)``: the loop of :func:`mean_value` over the legs
    and det A's partial derivatives, written out once per model as one Python function
    (B: the balls of :func:`_derivative_polys` in order; ``speed``: the pose variables'
    rates, the joints' filled in here; None where a branch's discriminant is not proven
    > 0).  The same ball operations as the loop, so the same enclosure; the source is
    made from the variables' indices and the legs' kinds alone (each 2a is passed in)."""
    from singcheck.algebra.ball_programs import generated_function
    from singcheck.algebra.polynomials import memo_per_object
    from singcheck.model.robot import REVOLUTE

    def build(model):
        _, det_parts, legs = _derivative_parts(model)
        at = 0
        lines = ["def assemble(B, speed, sg, point):"]
        twice_a = []

        def dot(indices) -> str:
            nonlocal at
            terms = []
            for i in indices:
                terms.append(f"B[{at}] * speed[{i}]")
                at += 1
            return " + ".join(terms) if terms else "ZERO"

        for k, (kind, idx, dx, extra) in enumerate(legs):
            lines.append(f"    push = {dot([i for i, _ in dx])}")
            if kind == QUADRATIC:  # ρ' = (−b' + σ·D'/(2√D))/(2a)
                lines.append(f"    d_rate = {dot([i for i, _ in extra[0]])}")
                twice_a.append(extra[2])
                lines += [f"    disc = B[{at}]",
                          f"    if not disc > 0 or sg[{k}] is None:", "        return None",
                          f"    speed[{idx[0]}] = (-push + sg[{k}] * d_rate / "
                          f"(2 * disc.sqrt())) / A[{len(twice_a) - 1}]"]
                at += 1
            elif kind == REVOLUTE:  # θ' = −(∇ₓf·X')/(σ√Δ)
                lines += [f"    disc = B[{at}]",
                          f"    if not disc > 0 or sg[{k}] is None:", "        return None",
                          f"    rate = -push / (sg[{k}] * disc.sqrt())",
                          f"    speed[{idx[0]}] = -point[{idx[1]}] * rate",
                          f"    speed[{idx[1]}] = point[{idx[0]}] * rate"]
                at += 1
            else:
                lines.append(f"    speed[{idx[0]}] = -push / B[{at}]")
                at += 1
        lines.append(f"    return {dot([i for i, _ in det_parts])}")
        return generated_function("\n".join(lines) + "\n", "assemble",
                                  {"A": twice_a, "ZERO": _ZERO})

    return memo_per_object(_ASSEMBLERS, model, build)


def _branch_signs(mode) -> list[int | None]:
    """σ = ±1 of each leg's branch in the mode (None for a linear leg's only one)."""
    return [1 if b.label == "+" else -1 if b.label == "-" else None for b in mode.branches]
