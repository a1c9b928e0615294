"""Path coordinates that are real functions of t but not polynomials in (t, sin t, cos t).

``cos(t - 1)``, ``cos(t/2)``, ``cos(2*pi*t) + t/10``, ``sqrt(1 + t^2)``: the grammar
accepts them, but the exact engine cannot (μ would not be a polynomial over Q in t,
sin t, cos t).  Such a coordinate is kept as its expression tree and enclosed by ball
arithmetic: each operation of the tree is Arb's on balls (outward rounding), so the
value returned for a ball T encloses the coordinate at every t in T (a ball holding a
pole or a negative square root comes back infinite or NaN: nothing is proven there).

In the path ring the coordinate is an *opaque* variable whose ball at T is this
enclosure (:mod:`singcheck.algebra.opaque`).  Only the interval engine reads such
a path; the exact engine refuses it and says why.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from flint import arb

from singcheck.algebra.intervals import power
from singcheck.spec.grammar import MAX_EXPONENT, ExprError, Node
from singcheck.spec.real_constants import constant_ball, tree_ball

_ball = constant_ball  # the ball of a constant the tree names (a parameter's value)


@dataclass(frozen=True)
class RealFunction:
    """A coordinate t ↦ f(t) given by an expression tree (checked by :func:`real_function`)."""

    text: str
    tree: Node
    parameter: str
    constants: tuple[tuple[str, object], ...]  # the robot parameters it may name
    algebraic: bool = False  # whether the exact compilers take it alone (display only)

    def __call__(self, t: arb) -> arb:
        """An enclosure of f over the ball ``t`` (non-finite where f is not proven
        defined)."""
        constants = dict(self.constants)
        return _enclose(self.tree, t, self.parameter, constants)


    def with_derivative(self, t: arb) -> tuple[arb, arb]:
        """Enclosures of f and f' over the ball ``t`` (forward-mode differentiation of
        the tree, every operation on balls: f' is enclosed wherever it is defined)."""
        return _dual(self.tree, t, self.parameter, dict(self.constants))


def _dual(node: Node, t: arb, parameter: str, constants: dict) -> tuple[arb, arb]:
    """(value, derivative) of the tree over the ball t."""
    k = node.kind
    zero = arb(0)
    if k in ("num", "name"):
        if k == "name" and node.value == parameter:
            return t, arb(1)
        return _enclose(node, t, parameter, constants), zero
    if k == "pow":
        u, du = _dual(node.args[0], t, parameter, constants)
        e = _integer(node.args[1])
        if e == 0:
            return arb(1), zero
        return power(u, e), (e * power(u, e - 1) if e > 1 else arb(1)) * du
    args = [_dual(a, t, parameter, constants) for a in node.args]
    (u, du) = args[0]
    if k == "neg":
        return -u, -du
    if k in ("add", "sub", "mul", "div"):
        v, dv = args[1]
        if k == "add":
            return u + v, du + dv
        if k == "sub":
            return u - v, du - dv
        if k == "mul":
            return u * v, du * v + u * dv
        return u / v, (du * v - u * dv) / (v * v)
    if node.value == "sin":
        return u.sin(), u.cos() * du
    if node.value == "cos":
        return u.cos(), -u.sin() * du
    if u > 0:
        root = u.sqrt()
        return root, du / (2 * root)
    return arb("nan"), arb("nan")


def _enclose(node: Node, t: arb, parameter: str, constants: dict) -> arb:
    """The coordinate's ball over the ball ``t`` of the parameter
    (:func:`~singcheck.spec.real_constants.tree_ball`)."""
    def name_ball(name: str) -> arb:
        if name == parameter:
            return t
        return arb.pi() if name == "pi" else _ball(constants[name])

    return tree_ball(node, name_ball, _integer)


def _integer(node: Node) -> int:
    """An exponent: a non-negative integer literal (or a parenthesised one)."""
    if node.kind == "num" and isinstance(node.value, Fraction) and node.value.denominator == 1 \
            and 0 <= node.value <= MAX_EXPONENT:
        return int(node.value)
    raise ExprError(f"an exponent of a path's coordinate must be an integer from 0 to "
                    f"{MAX_EXPONENT}", node.column)


def real_function(node: Node, text: str, parameter: str, parameters: dict,
                  algebraic: bool = False) -> RealFunction:
    """The coordinate ``node`` (written ``text``) as a :class:`RealFunction` of the
    parameter, checked: names are the parameter, ``pi`` and the robot's parameters;
    functions sin, cos, sqrt; exponents integers (:class:`ExprError` otherwise)."""
    used: dict[str, object] = {}

    def walk(n: Node) -> None:
        if n.kind == "name":
            if n.value in (parameter, "pi"):
                return
            if n.value not in parameters:
                declared = ", ".join([parameter, "pi", *sorted(parameters)])
                raise ExprError(f"undeclared name {n.value!r} (declared: {declared})",
                                n.column)
            used[n.value] = parameters[n.value]
            return
        if n.kind == "call" and n.value not in ("sin", "cos", "sqrt"):
            raise ExprError(f"unknown function {n.value!r} (only sin, cos and sqrt)", n.column)
        if n.kind == "pow":
            walk(n.args[0])
            _integer(n.args[1])
            return
        for a in n.args:
            walk(a)

    walk(node)
    return RealFunction(text, node, parameter, tuple(sorted(used.items())), algebraic)
