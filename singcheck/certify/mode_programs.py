"""det A along several working modes over a ball of t, in one pass with its plan made once.

:func:`~singcheck.certify.interval_engine.mode_values` encloses, on each ball T of the
parameter, the pose φ(T), each leg's branches and det A per mode.  Asked a hundred times
per path, its cost was mostly the walk between the pieces (the pose's memo, the robot's
point rebuilt with its square roots, the compiled programs looked up, a dict per leg and
per mode), not the ball arithmetic.  A :class:`ModeProgram` is that walk made once per
path: each coordinate's enclosure picked (a constant's ball, the Horner split in cos t,
or on a wide ball the Fourier form), the legs' and det A's compiled
:class:`~singcheck.algebra.ball_programs.BallProgram`, each quadratic leg's branches,
all written out as one compiled function (:func:`_compiled_walk`); per mode, the
indices of its branches.

Rigour: it performs the operations :func:`mode_values` performs — the same enclosures
of the pose (:mod:`singcheck.algebra.trig`), the same programs, the same branch
formulas (:func:`~singcheck.certify.path.branch_values`) and the same joint sums — so
each ball it returns encloses what that function's does.  The Fourier form on a wide
ball is one of the two rigorous forms :func:`~singcheck.algebra.trig.evaluate_trig`
offers (each sin kT, cos kT enclosed by Arb), the tighter one at a high degree."""

from __future__ import annotations

from flint import arb, arb_poly, ctx

from singcheck.algebra.ball_programs import ball_program, generated_function, joint_sum
from singcheck.algebra.radicals import radical_balls
from singcheck.algebra.trig import (
    FOURIER_DEGREE,
    FOURIER_WIDE,
    _fourier,
    evaluate_split,
    fourier_sum,
)


class ModeProgram:
    """``program(path, t, modes)`` = (pose, joints per mode, det A per mode) over the ball
    t, as :func:`~singcheck.certify.interval_engine.mode_values` returns them; built by
    :func:`mode_program` for a path whose legs are enclosed from the pose."""

    __slots__ = ("path", "plan", "pose_at", "variables_at", "offsets", "harmonics",
                 "legs", "legs_program", "det_program", "det_sum", "modes", "prefix",
                 "radicals", "rate_plan", "last", "walk")

    def __init__(self, path, legs_program, det_program, det_sum) -> None:
        model = path.projection.model
        plan, self.pose_at, self.variables_at, self.offsets = path._pose_plan
        self.path = path
        self.plan = [_coordinate_step(x, split) for x, split, _ in plan]
        self.rate_plan = _rate_plan(path)  # (made on the first call of rates())
        self.harmonics = sorted({k for step in self.plan if step[0] == "fourier"
                                 for k in step[3]})
        self.last: tuple = (None, None)  # (t, sin kt and cos kt of its pose)
        self.legs_program, self.det_program, self.det_sum = legs_program, det_program, det_sum
        self.legs = path._legs_program[1]  # [(leg, start, end) of its balls]
        self.modes: dict[str, list] = {}  # label -> [(leg, branch label)]
        self.prefix = [arb(0)] * len(model.joint_variables)
        self.radicals = [b for _, b in sorted(radical_balls(model.context).items())]
        self.walk = _compiled_walk(self)

    def _multiples(self, t: arb) -> tuple[bool, dict]:
        """(whether t is wide, {k: (sin kt, cos kt)}): k = 1 always, the harmonics of the
        Fourier forms on a wide ball; the last ball's are kept (its rates follow)."""
        last = self.last
        if last[0] is t:
            return last[1]
        wide = t.rad() > FOURIER_WIDE
        multiples = {1: t.sin_cos()}
        if wide:
            for k in self.harmonics:
                if k != 1:
                    multiples[k] = (k * t).sin_cos()
        self.last = (t, (wide, multiples))
        return wide, multiples

    def _enclose(self, plan: list, t: arb) -> list[arb]:
        wide, multiples = self._multiples(t)
        s, c = multiples[1]
        balls = []
        for step in plan:
            kind = step[0]
            if kind == "constant":
                balls.append(step[1])
            elif kind == "fourier" and wide:
                balls.append(_fourier_sum(step[2], t, multiples))
            elif kind == "split" or kind == "fourier":
                balls.append(evaluate_split(step[1](), t, s, c))
            else:
                from singcheck.algebra.radicals import evaluate_path

                balls.append(evaluate_path(step[1], t))
        return balls

    def rates(self, t: arb) -> list[arb] | None:
        """d/dt of each pose variable over the ball t (as
        :meth:`~singcheck.certify.path.PathModel.pose_rates_at` without angle functions),
        or None where the path ring has them."""
        plan = self.rate_plan
        if plan is _NOT_YET:
            plan = self.rate_plan = _rate_steps(self.path)
            self.harmonics = sorted({*self.harmonics, *(k for step in plan or ()
                                                        if step[0] == "fourier"
                                                        for k in step[3])})
            self.last = (None, None)
        if plan is None:
            return None
        return self._enclose(plan, t)

    def __call__(self, path, t: arb, modes: list):
        pose, variables, per_leg, q, multiples = self.walk(t)
        self.last = (t, multiples)
        object.__setattr__(path, "_last_pose", (t, ctx.prec, pose, variables))
        joints, values = {}, {}
        total = self.det_sum
        revolute = path.projection.model.angle_joints
        for mode in modes:
            label = mode.label
            picks = self.modes.get(label)
            if picks is None:
                picks = self.modes[label] = [(k, b.label) for k, b in enumerate(mode.branches)]
            js = [per_leg[k][b] for k, b in picks]
            joints[label] = js
            if any(j is None for j in js):
                values[label] = None
                continue
            if revolute:
                flat: list = []
                for j in js:
                    flat += list(j) if isinstance(j, tuple) else [j]
                values[label] = total(q, flat)
            else:
                values[label] = total(q, js)
        return list(pose), joints, values


def _coordinate_step(x, split):
    """How one distinct coordinate polynomial is enclosed: ("constant", ball),
    ("fourier", split, Fourier terms, harmonics) for a trig polynomial of degree
    :data:`~singcheck.algebra.trig.FOURIER_DEGREE` or more in (s, c), ("split", split)
    for another trig polynomial, ("path", x) else."""
    if split is None:
        return ("path", x)
    if x.is_constant():
        return ("constant", evaluate_split(split(), arb(0), arb(0), arb(1)))
    from singcheck.certify.path import _in_trig

    trig = _in_trig(x)
    degrees = trig.degrees()
    if degrees[1] + degrees[2] < FOURIER_DEGREE:  # (an upper bound of the reduced one's)
        return ("split", split)
    form = _fourier(trig)
    if form is not None and form[3] >= FOURIER_DEGREE:
        terms, harmonics, _, _ = form
        return ("fourier", split, (terms, form[2]), harmonics)
    return ("split", split)


_NOT_YET = object()


def _rate_plan(path):
    """:func:`_rate_steps`, put off until the mean-value form first needs it (most
    paths' first cover is proven without)."""
    return _NOT_YET


def _rate_steps(path) -> list | None:
    """The steps of d/dt of each pose variable (:func:`_coordinate_step`), None where
    the path ring has angle functions of its own (the mean-value form does without)."""
    from singcheck.algebra.trig import TRIG, split_of
    from singcheck.certify.path import _coordinate_derivatives

    opaque, functions = path._rates_plan
    if opaque is not None or functions:
        return None
    steps = []
    for d in _coordinate_derivatives(path):
        split = split_of(d) if d.context() is TRIG else None
        steps.append(_coordinate_step(d, split))
    return steps


def _fourier_sum(form, t: arb, multiples: dict) -> arb:
    """Σ tⁱ (a cos kT + b sin kT) with Arb's sin kT, cos kT (``multiples``)."""
    terms, dt = form
    return fourier_sum(terms, dt, t, multiples)


def _compiled_walk(program: ModeProgram):
    """``walk(t)`` = (pose, pose variables, per leg its branches, det A's pose
    coefficients, (wide, sin kt and cos kt)) over the ball t: each coordinate's step
    (as :meth:`ModeProgram._enclose` takes them), the legs' program and
    :func:`~singcheck.certify.path._branches_from` written out as one Python function
    for this path (each quadratic leg's two branches (-b ± √D)/(2a) and each revolute
    leg's (cos θ, sin θ) = ((-P·R ± Q·√Δ)/W, (-Q·R ∓ P·√Δ)/W) inline where the
    discriminant is proven > 0, the rest by ``_branches_from``), compiled once per
    shape.

    The same operations on the same balls, so the same enclosures (module docstring).
    Safety, as for :class:`~singcheck.algebra.ball_programs.BallProgram`: the source is
    made from the plan's kinds and positions alone; every polynomial, ball and function
    it uses is passed in the list K, and nothing a user wrote reaches ``compile``."""
    from singcheck.algebra.radicals import evaluate_path
    from singcheck.certify.path import _branches_from
    from singcheck.model.robot import REVOLUTE

    K: list = []

    def const(value) -> str:
        K.append(value)
        return f"K[{len(K) - 1}]"

    def split_expr(split) -> str:
        if type(split) is tuple:
            p0, p1 = split
            return f"{const(p0)}(c)" if p1 is None else f"{const(p0)}(c) + s * {const(p1)}(c)"
        if isinstance(split, arb_poly):
            return f"{const(split)}(t)"
        return f"{const(evaluate_split)}({const(split)}, t, s, c)"

    lines = ["def walk(t):", "    wide = t.rad() > FW", "    s, c = t.sin_cos()",
             "    M = {1: (s, c)}"]
    if program.harmonics:
        lines.append("    if wide:")
        lines += [f"        M[{k}] = ({k} * t).sin_cos()" for k in program.harmonics if k != 1]
        if all(k == 1 for k in program.harmonics):
            lines.append("        pass")
    for i, step in enumerate(program.plan):
        kind = step[0]
        if kind == "constant":
            lines.append(f"    v{i} = {const(step[1])}")
        elif kind == "path":
            lines.append(f"    v{i} = {const(evaluate_path)}({const(step[1])}, t)")
        elif kind == "fourier":
            lines.append(f"    v{i} = {const(_fourier_sum)}({const(step[2])}, t, M) if wide "
                         f"else {split_expr(step[1]())}")
        else:
            lines.append(f"    v{i} = {split_expr(step[1]())}")
    pose = [f"v{i}" for i in program.pose_at]
    for i, offset in program.offsets:
        pose[i] = f"{pose[i]} + {const(arb.pi() * offset)}"
    variables = [f"v{i}" for i in program.variables_at]
    point = ["Z"] * len(program.prefix) + variables + [const(b) for b in program.radicals]
    lines.append(f"    point = [{', '.join(point)}]")
    lines.append(f"    L = {const(program.legs_program)}(point)")
    legs = []
    for k, (leg, a, b) in enumerate(program.legs):
        if leg.kind != REVOLUTE and leg.degree == 2:  # (-b ± √D)/(2a), as branch_values
            lines += [f"    a{k}, b{k}, d{k} = L[{a}], L[{a + 1}], L[{a + 2}]",
                      f"    if d{k} > 0:",
                      f"        r{k} = d{k}.sqrt()",
                      f"        g{k} = {{'+': (-b{k} + r{k}) / (2 * a{k}), "
                      f"'-': (-b{k} - r{k}) / (2 * a{k})}}",
                      "    else:",
                      f"        g{k} = BR({const(leg)}, L[{a}:{b}])"]
        elif leg.kind == REVOLUTE and b - a == 4:  # (cos θ, sin θ), as branch_values
            lines += [f"    a{k}, b{k}, c{k}, d{k} = L[{a}], L[{a + 1}], L[{a + 2}], L[{a + 3}]",
                      f"    w{k} = a{k} * a{k} + b{k} * b{k}",
                      f"    if d{k} > 0:",
                      f"        r{k} = d{k}.sqrt()",
                      f"        g{k} = {{" + ", ".join(
                          f"'{label}': ((-a{k} * c{k} + {sigma} * b{k} * r{k}) / w{k}, "
                          f"(-b{k} * c{k} - {sigma} * a{k} * r{k}) / w{k})"
                          for label, sigma in (("+", 1), ("-", -1))) + "}",
                      "    else:",
                      f"        g{k} = BR({const(leg)}, L[{a}:{b}])"]
        else:
            lines.append(f"    g{k} = BR({const(leg)}, L[{a}:{b}])")
        legs.append(f"g{k}")
    lines.append(f"    q = {const(program.det_program)}(point)")
    lines.append(f"    return [{', '.join(pose)}], [{', '.join(variables)}], "
                 f"[{', '.join(legs)}], q, (wide, M)")
    return generated_function("\n".join(lines) + "\n", "walk",
                              {"K": K, "FW": FOURIER_WIDE, "Z": _ZERO, "BR": _branches_from})


_ZERO = arb(0)


_PROGRAMS: dict = {}


def mode_program(path) -> ModeProgram | None:
    """The :class:`ModeProgram` of the path (once per path — its legs along it, which a
    copy of the path made for the exact engine shares — at the current precision), or
    None where :func:`mode_values`' general walk is needed: legs not enclosed from the
    pose, an opaque path, a det A too large to compile."""
    if not path.legs:  # (the empty tuple is one object: not a key)
        return None
    key = (id(path.legs), ctx.prec)
    hit = _PROGRAMS.get(key)
    if hit is not None and hit[0] is path.legs:
        return hit[1]
    if len(_PROGRAMS) > 64:
        _PROGRAMS.clear()
    program = _build(path)
    _PROGRAMS[key] = (path.legs, program)
    return program


def _build(path) -> ModeProgram | None:
    from singcheck.certify.path import MATRIX_FORM_ABOVE, _det_a_by_joints

    model = path.projection.model
    if not path.legs_from_pose or len(model.det_A) > MATRIX_FORM_ABOVE:
        return None
    legs_program, _ = path._legs_program
    det_program = ball_program(model, "det A by joints",
                               lambda m: [q for _, q in _det_a_by_joints(m)])
    if legs_program is None or det_program is None:
        return None
    det_sum = joint_sum(model, lambda m: [alpha for alpha, _ in _det_a_by_joints(m)])
    return ModeProgram(path, legs_program, det_program, det_sum)
