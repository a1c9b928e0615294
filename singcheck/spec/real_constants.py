"""Parameters and joint limits that are real numbers outside singcheck's exact field.

The exact compilers (:func:`~singcheck.spec.grammar.compile_value`) take a constant when
it lies in the small field they compute in: rationals, square roots of rationals, ``pi``
(``a + b·π``) and sin/cos of multiples of π/12.  Any other finite real the grammar can
write — ``2*cos(1/10)``, ``3*cos(1/3) + 1``, ``sqrt(1 + sqrt(2))``, ``cos(1)^(-1)``,
``pi/2 + 1`` where π cannot stay apart (in a constraint) — is a :class:`RealConstant`: its
expression tree, enclosed by Arb ball arithmetic (outward rounding, never a float), so
its ball at any precision holds the true value.

Such a value is *proven* a finite real when it is read (:func:`real_constant`): every
division, negative power and square root of the tree is checked on balls (a divisor's
ball must exclude 0, a square root's argument must be proven positive) at rising
precision, and a constant that fails — ``sqrt(-2)``, ``1/(cos(1) - cos(1))``, one that
is 0 but not provably so — is refused with the reason.

In a robot's constraints a parameter whose value leaves the field is an *opaque
constant*: one variable of the robot's ring (``K[[l = 2*cos(1/10)]]``, registered with
:mod:`singcheck.algebra.opaque` like a path coordinate kept as a tree), whose ball is
the value's (:func:`~singcheck.algebra.radicals.radical_balls` appends it after the
square roots wherever the robot's polynomials are enclosed).  The robot's polynomials
stay exact polynomials over Q in that variable (F, A, det A, the legs' coefficients);
only the interval engine, which reads balls, can use them: the exact engine (μ over Q,
exact root isolation) and the elimination (ξ, the region statements) are not run for
such a robot, and the report says why (:func:`opaque_parameters`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from flint import arb, ctx, fmpq

from singcheck.spec.grammar import MAX_EXPONENT, Constant, ExprError, Node, OutsideField

#: the precisions (bits) at which a constant is tried before it is refused as not proven
PRECISIONS = (64, 256, 1024)


def constant_ball(value) -> arb:
    """The ball of a parameter's value: a Fraction, a :class:`Constant` or a
    :class:`RealConstant`, at the current precision."""
    if isinstance(value, RealConstant):
        return value.ball()
    if isinstance(value, Constant):
        out = value.surd.ball()
        if value.pi_coefficient:
            q = value.pi_coefficient
            out += arb.pi() * arb(fmpq(q.numerator, q.denominator))
        return out
    q = Fraction(value)
    return arb(fmpq(q.numerator, q.denominator))


@dataclass(frozen=True)
class RealConstant(OutsideField):
    """A finite real written in the grammar, outside the exact field: its tree,
    enclosed by balls.  ``constants`` are the earlier parameters it names (with their
    values); ``bits`` the precision at which it was proven finite."""

    text: str
    tree: Node
    constants: tuple[tuple[str, object], ...] = ()
    bits: int = 64

    def ball(self) -> arb:
        """An enclosure of the value at the working precision (at least ``bits``: the
        precision its proof needed, so the ball is always finite); computed once per
        precision (the interval engine reads it at every evaluation of det A)."""
        prec = ctx.prec
        key = (id(self), prec)
        hit = _BALLS.get(key)
        if hit is not None and hit[0] is self:  # (the entry holds self: id not reused)
            return hit[1]
        if prec >= self.bits:
            ball = _enclose(self.tree, dict(self.constants))
        else:
            ctx.prec = self.bits
            try:
                ball = _enclose(self.tree, dict(self.constants))
            finally:
                ctx.prec = prec
        if len(_BALLS) > 256:
            _BALLS.clear()
        _BALLS[key] = (self, ball)
        return ball

    def __float__(self) -> float:  # display only (tables, drawings): never a verdict
        return float(self.ball().mid())

    def __str__(self) -> str:
        if not self.constants:
            return self.text
        return f"{self.text} | " + ", ".join(f"{k}={v}" for k, v in self.constants)


#: (id of a RealConstant, precision) -> (the constant, its ball)
_BALLS: dict[tuple[int, int], tuple[RealConstant, arb]] = {}


def _enclose(node: Node, constants: dict) -> arb:
    """The ball of a checked tree (:func:`real_constant` proved it finite)."""
    return tree_ball(node, lambda name: arb.pi() if name == "pi" else
                     constant_ball(constants[name]), _integer)


def tree_ball(node: Node, name_ball, exponent) -> arb:
    """The ball of a checked tree of the grammar at the current precision: numbers
    exactly, each name by ``name_ball(name)``, each exponent's integer by
    ``exponent(node)`` (which refuses what it does not take), + - * / ^ and sin, cos,
    sqrt by Arb (the square root of a ball not proven > 0 is NaN: nothing proven).  A
    constant's tree here, a real path coordinate's in :mod:`singcheck.spec.real_paths`."""
    k = node.kind
    if k == "num":
        return arb(fmpq(node.value.numerator, node.value.denominator))
    if k == "name":
        return name_ball(node.value)
    if k == "pow":
        base = tree_ball(node.args[0], name_ball, exponent)
        return _power(base, exponent(node.args[1]))
    args = [tree_ball(a, name_ball, exponent) for a in node.args]
    if k == "neg":
        return -args[0]
    if cancels(node):
        return arb(0)
    if k == "add":
        return args[0] + args[1]
    if k == "sub":
        return args[0] - args[1]
    if k == "mul":
        return args[0] * args[1]
    if k == "div":
        return args[0] / args[1]
    if k != "call":
        raise AssertionError(k)  # pragma: no cover
    if node.value == "sin":
        return args[0].sin()
    if node.value == "cos":
        return args[0].cos()
    if args[0] == 0:  # exactly (a ball of radius 0 at 0: sqrt(cos(1) - cos(1)))
        return arb(0)
    return args[0].sqrt() if args[0] > 0 else arb("nan")


def cancels(node: Node) -> bool:
    """Whether ``node`` is a − a (``a - a`` or ``a + -a``, the two sides the same tree
    but for their columns): exactly 0 wherever a is defined, though its ball is not
    [0, 0] (``cos(1) - cos(1)``)."""
    from singcheck.spec.grammar import unparse

    if node.kind == "sub":
        a, b = node.args
    elif node.kind == "add" and node.args[1].kind == "neg":
        a, b = node.args[0], node.args[1].args[0]
    else:
        return False
    return unparse(a) == unparse(b)


def _power(base: arb, e: int) -> arb:
    from singcheck.algebra.intervals import power

    if e == 0:
        return arb(1)
    if e > 0:
        return power(base, e)
    return 1 / power(base, -e)


def _integer(node: Node) -> int:
    """An exponent: an integer from -MAX_EXPONENT to MAX_EXPONENT, written as a number
    (``x^2``, ``x^(-1)``)."""
    negative = False
    while node.kind == "neg":
        negative, node = not negative, node.args[0]
    if node.kind == "num" and node.value.denominator == 1 and \
            abs(node.value) <= MAX_EXPONENT:
        return -int(node.value) if negative else int(node.value)
    raise ExprError(f"exponents must be integers from -{MAX_EXPONENT} to {MAX_EXPONENT}",
                    node.column)


def _check(node: Node, constants: dict) -> arb:
    """The ball of ``node``, or :class:`ExprError` where a step is not proven defined
    (a square root of a value not proven positive, a division by a ball holding 0)."""
    k = node.kind
    if k == "num":
        return _enclose(node, constants)
    if k == "name":
        return _enclose(node, constants)
    if k == "call":
        if node.value not in ("sin", "cos", "sqrt"):
            raise ExprError(f"unknown function {node.value!r} (only sin, cos and sqrt)",
                            node.column)
        x = _check(node.args[0], constants)
        if node.value == "sqrt":
            if x == 0:  # exactly: sqrt(cos(1) - cos(1)), sqrt(1 - 1)
                return arb(0)
            if x < 0:
                raise ExprError("sqrt of a negative number is not real", node.column)
            if not x > 0:
                raise _unproven("the argument of sqrt is not proven positive", node)
            return x.sqrt()
        return x.sin() if node.value == "sin" else x.cos()
    if k == "pow":
        base, e = _check(node.args[0], constants), _integer(node.args[1])
        if e < 0 and not (base > 0 or base < 0):
            raise _zero("a negative power of", base, node)
        return _power(base, e)
    args = [_check(a, constants) for a in node.args]
    if cancels(node):
        return arb(0)
    if k == "div" and not (args[1] > 0 or args[1] < 0):
        raise _zero("division by", args[1], node)
    if k == "neg":
        return -args[0]
    a, b = args
    return {"add": a + b, "sub": a - b, "mul": a * b, "div": a / b}[k]


def _zero(what: str, ball: arb, node: Node) -> ExprError:
    if ball == 0:
        return ExprError(f"{what} zero", node.column)
    return _unproven(f"{what} a value not proven non-zero", node)


class _Unproven(ExprError):
    """A step not proven defined at this precision (tried again at a higher one)."""


def _unproven(message: str, node: Node) -> _Unproven:
    return _Unproven(message, node.column)


def real_constant(node: Node, text: str, parameters: dict) -> RealConstant:
    """The constant ``node`` (written ``text``) as a :class:`RealConstant`, proven a
    finite real, or :class:`ExprError` saying why not: a name that is neither ``pi`` nor
    an earlier parameter, a function other than sin, cos, sqrt, an exponent that is not
    an integer, or a value not proven finite and real at 1024 bits.

    >>> from singcheck.spec.grammar import parse
    >>> c = real_constant(parse("2*cos(1/10)"), "2*cos(1/10)", {})
    >>> c.ball().overlaps(2 * arb("0.1").cos()), c.ball().rad() < 1e-15
    (True, True)
    >>> real_constant(parse("sqrt(1 - 2*cos(0.1))"), "", {})
    Traceback (most recent call last):
    ...
    singcheck.spec.grammar.ExprError: sqrt of a negative number is not real (column 1)
    """
    used: dict[str, object] = {}

    def walk(n: Node) -> None:
        if n.kind == "name" and n.value != "pi":
            if n.value not in parameters:
                raise ExprError(f"{n.value!r} is not allowed here: use numbers, pi, sqrt, "
                                "sin, cos and parameters defined above", n.column)
            used[n.value] = parameters[n.value]
        if n.kind == "pow":
            walk(n.args[0])
            _integer(n.args[1])
            return
        for a in n.args:
            walk(a)

    walk(node)
    constants = dict(sorted(used.items()))
    prec = ctx.prec
    last: ExprError | None = None
    try:
        for bits in PRECISIONS:
            ctx.prec = max(prec, bits)
            try:
                ball = _check(node, constants)
            except _Unproven as e:
                last = e
                continue
            if ball.is_finite():
                return RealConstant(text, node, tuple(constants.items()), ctx.prec)
            last = ExprError("the value is not a finite real number")
    finally:
        ctx.prec = prec
    raise ExprError(f"{last.message} (at {PRECISIONS[-1]} bits): not proven a finite real "
                    "number", last.column)


@dataclass(frozen=True)
class ParameterValue:
    """The function behind a robot's opaque constant ``K[[…]]`` (registered with
    :mod:`singcheck.algebra.opaque`): the parameter's value at every t, derivative 0."""

    parameter: str
    value: object  # a RealConstant, or a Constant a + b·π with b ≠ 0

    @property
    def text(self) -> str:
        value = str(getattr(self.value, "text", self.value))
        return value if value == self.parameter else f"{self.parameter} = {value}"

    @property
    def constants(self) -> tuple:
        return getattr(self.value, "constants", ())

    def __call__(self, t: arb) -> arb:
        return constant_ball(self.value)

    def with_derivative(self, t: arb) -> tuple[arb, arb]:
        return constant_ball(self.value), arb(0)


def outside_field(value) -> bool:
    """Whether a parameter's value cannot enter a constraint exactly: a
    :class:`RealConstant`, or ``a + b·π`` with b ≠ 0 (π is not algebraic)."""
    return isinstance(value, OutsideField) or \
        isinstance(value, Constant) and bool(value.pi_coefficient)


def opaque_parameter(parameter: str, value) -> str:
    """The robot ring's variable standing for the parameter's value (registered)."""
    from singcheck.algebra.opaque import opaque_name

    return opaque_name("K", ParameterValue(parameter, value))


def angle_offsets(trees: list[Node], angles, parameters: dict) -> dict:
    """{sin/cos call: ({angle: k}, name of cos c, name of sin c)} for each call of the
    constraint trees whose argument is Σ k·angle + c with a constant c outside the exact
    field (``cos(th1 + a)`` with ``a: 2*cos(1/10)`` or ``a: 0.1``): cos c and sin c are
    opaque constants of the robot's ring, proven finite reals like a parameter
    (:func:`real_constant`).  A call the exact compiler takes is not listed."""
    from singcheck.spec.grammar import _linear_argument, angle_offset, parse

    out: dict = {}

    def walk(node: Node) -> None:
        if node.kind == "call" and node.value in ("sin", "cos") and node not in out:
            try:
                _linear_argument(node.args[0], angles, parameters)
            except ExprError:
                found = angle_offset(node.args[0], angles, parameters)
                if found is not None:
                    coefficients, text = found
                    names = []
                    for f in ("cos", "sin"):
                        label = f"{f}({text})"
                        try:
                            value = real_constant(parse(label), label, parameters)
                        except ExprError:
                            return  # (the compiler then says what is wrong)
                        names.append(opaque_parameter(label, value))
                    out[node] = (coefficients, *names)
        for a in node.args:
            walk(a)

    for tree in trees:
        walk(tree)
    return out


def root_constants(trees: list[Node], parameters: dict) -> dict:
    """{sqrt call: opaque constant's name} for each ``sqrt`` of the constraint trees whose
    argument is a constant outside the exact field (``sqrt(l)`` with ``l: 2*cos(1/10)``):
    its value is an opaque constant of the robot's ring, proven a finite real like a
    parameter (:func:`real_constant`: the argument proven > 0 on balls), or the
    :class:`ExprError` saying why it is not (the compiler raises it).  A call the exact
    compiler takes is not listed."""
    from singcheck.spec.grammar import constant_text, parse

    out: dict = {}

    def walk(node: Node) -> None:
        if node.kind == "call" and node.value == "sqrt" and node not in out:
            text = constant_text(node.args[0], parameters)
            if text is not None:
                label = f"sqrt({text})"
                try:
                    out[node] = opaque_parameter(label, real_constant(parse(label), label,
                                                                      parameters))
                except ExprError as e:  # (the compiler raises it, with the line)
                    out[node] = ExprError(f"{label}: {e.message}", node.column)
                return
        for a in node.args:
            walk(a)

    for tree in trees:
        walk(tree)
    return out


def opaque_parameters(spec) -> dict[str, str]:
    """{parameter: its value's text} for each opaque constant of a robot spec's ring (""
    for none): what the report names when it says why the exact engine does not run."""
    from singcheck.algebra.opaque import opaque_of
    from singcheck.algebra.radicals import opaque_constants

    out = {}
    for _, name in opaque_constants(spec.context):
        f = opaque_of(name)[0]
        out[f.parameter] = str(getattr(f.value, "text", f.value))
    return out


def exact_engine_refusal(spec) -> str:
    """Why the exact engine and the elimination cannot run for this robot ("" when they
    can): the parameters whose values are outside the exact field."""
    found = opaque_parameters(spec)
    if not found:
        return ""
    names = ", ".join(k if k == v else f"{k} = {v}" for k, v in found.items())
    what = "parameter" if all(k != v for k, v in found.items()) else "constant"
    return (f"the {what}{'s' if len(found) > 1 else ''} {names} "
            f"{'are' if len(found) > 1 else 'is'} outside the exact field (rationals, square "
            "roots, pi, sin/cos of multiples of pi/12), so the robot's polynomials are not "
            "over Q: neither the elimination (singularity surface, regions) nor the exact "
            "engine runs")
