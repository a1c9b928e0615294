"""singcheck's own expression grammar for spec files (untrusted input: no eval, no sympify).

Grammar (``^`` and ``**`` are the same right-associative power, binding tighter than
unary minus, so ``-x^2`` is ``-(x^2)``)::

    expr    := term (("+" | "-") term)*
    term    := unary (("*" | "/") unary)*
    unary   := ("+" | "-") unary | power
    power   := atom (("^" | "**") unary)?
    atom    := NUMBER | NAME | NAME "(" expr ")" | "(" expr ")"

Numbers are exact: ``0.1`` is 1/10, ``1e-3`` is 1/1000.  Implicit multiplication
(``2x``) is refused.  The parser builds a small tree; the compilers turn it into exact
objects: a polynomial over Q (:func:`compile_polynomial`), a trig polynomial in
``Q[t, s, c]`` (:func:`compile_trajectory_coordinate`), or a constant ``a + b·π``
(:func:`compile_constant`).  Errors are :class:`ExprError` with a column.

>>> str(compile_constant(parse("-pi/2 + 0.5")))
'1/2-1/2*pi'
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.trig import TRIG, LinearInPi, T, cos_multiple, reduce_trig, sin_multiple

MAX_EXPONENT = 64
MAX_LENGTH = 10_000
MAX_DEGREE = 256  # of any intermediate polynomial
MAX_TERMS = 100_000
MAX_BITS = 20_000  # of any intermediate rational's numerator or denominator
FUNCTIONS = ("sin", "cos")


class ExprError(ValueError):
    """A problem in an expression; ``column`` is 1-based (None when not known)."""

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.column = column

    def __str__(self) -> str:
        return self.message + (f" (column {self.column})" if self.column else "")


@dataclass(frozen=True)
class Node:
    kind: str  # num | name | neg | add | sub | mul | div | pow | call
    column: int
    value: object = None  # Fraction for num, str for name/call
    args: tuple[Node, ...] = ()


_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z_0-9]*)
  | (?P<op>\*\*|[-+*/^(),])
""", re.VERBOSE)


def _tokens(text: str) -> list[tuple[str, str, int]]:
    out = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m:
            raise ExprError(f"unexpected character {text[pos]!r}", pos + 1)
        kind = m.lastgroup
        if kind != "space":
            out.append((kind, m.group(), pos + 1))
        pos = m.end()
    for (k1, v1, _), (k2, v2, c2) in zip(out, out[1:], strict=False):
        if k1 == "num" and k2 in ("name", "num") or (k1 == "op" and v1 == ")" and
                                                     (k2 in ("name", "num") or v2 == "(")):
            raise ExprError(f"missing operator before {v2!r} (write 2*x, not 2x)", c2)
        if k1 == "num" and v2 == "(":
            raise ExprError("missing operator before '(' (write 2*(…), not 2(…))", c2)
    return out


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.toks = _tokens(text)
        self.i = 0

    def peek(self) -> tuple[str, str, int]:
        if self.i < len(self.toks):
            return self.toks[self.i]
        return ("end", "", len(self.text) + 1)

    def take(self) -> tuple[str, str, int]:
        tok = self.peek()
        self.i += 1
        return tok

    def expect(self, value: str) -> None:
        kind, v, col = self.take()
        if v != value:
            found = "the end of the expression" if kind == "end" else repr(v)
            raise ExprError(f"expected {value!r} but found {found}", col)

    def parse(self) -> Node:
        if not self.toks:
            raise ExprError("empty expression")
        node = self.expr()
        kind, v, col = self.peek()
        if kind != "end":
            raise ExprError(f"unexpected {v!r}" + (" (unbalanced parenthesis)" if v == ")"
                                                   else ""), col)
        return node

    def expr(self) -> Node:
        node = self.term()
        while self.peek()[1] in ("+", "-"):
            _, op, col = self.take()
            node = Node("add" if op == "+" else "sub", col, None, (node, self.term()))
        return node

    def term(self) -> Node:
        node = self.unary()
        while self.peek()[1] in ("*", "/"):
            _, op, col = self.take()
            node = Node("mul" if op == "*" else "div", col, None, (node, self.unary()))
        return node

    def unary(self) -> Node:
        kind, v, col = self.peek()
        if v in ("+", "-"):
            self.take()
            operand = self.unary()
            return operand if v == "+" else Node("neg", col, None, (operand,))
        return self.power()

    def power(self) -> Node:
        base = self.atom()
        if self.peek()[1] in ("^", "**"):
            _, _, col = self.take()
            return Node("pow", col, None, (base, self.unary()))
        return base

    def atom(self) -> Node:
        kind, v, col = self.take()
        if kind == "num":
            return Node("num", col, _exact_number(v, col))
        if kind == "name":
            if self.peek()[1] == "(":
                self.take()
                arg = self.expr()
                self.expect(")")
                return Node("call", col, v, (arg,))
            return Node("name", col, v)
        if v == "(":
            node = self.expr()
            self.expect(")")
            return node
        found = "the end of the expression" if kind == "end" else repr(v)
        raise ExprError(f"expected a number, a name or '(' but found {found}", col)


def _exact_number(text: str, column: int) -> Fraction:
    try:
        return Fraction(text)  # exact decimal: Fraction("0.1") == 1/10
    except (ValueError, ZeroDivisionError):
        raise ExprError(f"bad number {text!r}", column) from None


def parse(text: str) -> Node:
    """The tree of an expression (raises :class:`ExprError`)."""
    if len(text) > MAX_LENGTH:
        raise ExprError(f"expression longer than {MAX_LENGTH} characters")
    return _Parser(text).parse()


# ---------------------------------------------------------------------------------
# compilers


def _exponent(node: Node, value) -> int:
    if not isinstance(value, Fraction) or value.denominator != 1 or value < 0:
        raise ExprError("exponents must be non-negative integers", node.column)
    if value > MAX_EXPONENT:
        raise ExprError(f"exponent {value} is larger than {MAX_EXPONENT}", node.column)
    return int(value)


def _constant_of(p) -> Fraction | None:
    if isinstance(p, Fraction):
        return p
    if p.is_constant():
        c = p.leading_coefficient() if not p.is_zero() else fmpq(0)
        return Fraction(int(fmpq(c).p), int(fmpq(c).q))
    return None


class _Compiler:
    """Evaluate a tree over a ring, with hooks for names and calls."""

    def __init__(self, ring, names, call=None, what="expression") -> None:
        self.ring = ring
        self.names = names  # name -> ring element or Fraction
        self.call = call
        self.what = what

    def const(self, q: Fraction):
        return self.ring.from_dict({(0,) * self.ring.nvars(): fmpq(q.numerator, q.denominator)}) \
            if q else self.ring.from_dict({})

    def lift(self, v):
        return self.const(v) if isinstance(v, Fraction) else v

    def run(self, node: Node):
        k = node.kind
        if k == "num":
            return node.value
        if k == "name":
            if node.value == "pi" and "pi" not in self.names:
                raise ExprError(f"pi is not allowed in a {self.what} (coefficients must be "
                                "rational)", node.column)
            if node.value not in self.names:
                declared = ", ".join(sorted(self.names)) or "none"
                raise ExprError(f"undeclared name {node.value!r} (declared: {declared})",
                                node.column)
            return self.names[node.value]
        if k == "call":
            if self.call is None or node.value not in FUNCTIONS:
                if node.value in FUNCTIONS:
                    raise ExprError(f"{node.value} is not allowed in a {self.what}: it must be "
                                    "polynomial", node.column)
                raise ExprError(f"unknown function {node.value!r} (only sin and cos, in "
                                "trajectories)", node.column)
            return self.call(node)
        args = [self.run(a) for a in node.args]
        if k == "neg":
            return -args[0]
        if k == "pow":
            e = _exponent(node.args[1], _constant_of(args[1]) if not isinstance(
                args[1], Fraction) else args[1])
            _check_power(args[0], e, node)
            return _checked(args[0] ** e, node)
        a, b = args
        if k == "add":
            return a + b if isinstance(a, Fraction) and isinstance(b, Fraction) \
                else self.lift(a) + self.lift(b)
        if k == "sub":
            return a - b if isinstance(a, Fraction) and isinstance(b, Fraction) \
                else self.lift(a) - self.lift(b)
        if k == "mul":
            if not (isinstance(a, Fraction) or isinstance(b, Fraction)) and \
                    a.total_degree() + b.total_degree() > MAX_DEGREE:
                raise ExprError(f"the expression's degree exceeds {MAX_DEGREE}", node.column)
            return _checked(a * b if isinstance(a, Fraction) and isinstance(b, Fraction)
                            else self.lift(a) * self.lift(b), node)
        if k == "div":
            d = _constant_of(b)
            if d is None:
                raise ExprError(f"division by a non-constant expression is not polynomial in "
                                f"a {self.what}", node.column)
            if d == 0:
                raise ExprError("division by zero", node.column)
            if isinstance(a, Fraction):
                return a / d
            return a / fmpq(d.numerator, d.denominator)
        raise AssertionError(k)  # pragma: no cover


def _check_power(base, e: int, node: Node) -> None:
    """Refuse a power before computing it when its size would explode."""
    if isinstance(base, Fraction):
        bits = max(abs(base.numerator).bit_length(), base.denominator.bit_length())
        if bits * e > MAX_BITS:
            raise ExprError(f"the number {base}^{e} is too large", node.column)
    elif base.total_degree() * e > MAX_DEGREE:
        raise ExprError(f"the expression's degree exceeds {MAX_DEGREE}", node.column)
    elif len(base) > 1 and e > 1:
        from math import comb

        nvars = sum(1 for d in base.degrees() if d)
        if comb(nvars + base.total_degree() * e, nvars) > MAX_TERMS and \
                min(len(base), e + 1) ** min(e, 12) > MAX_TERMS:
            raise ExprError(f"the expanded expression would have more than {MAX_TERMS} terms",
                            node.column)


def _checked(value, node: Node):
    if isinstance(value, Fraction):
        if max(abs(value.numerator).bit_length(), value.denominator.bit_length()) > MAX_BITS:
            raise ExprError("a number in the expression is too large", node.column)
    elif len(value) > MAX_TERMS:
        raise ExprError(f"the expanded expression has more than {MAX_TERMS} terms",
                        node.column)
    return value


def compile_polynomial(node: Node, ctx: fmpq_mpoly_ctx, variables: dict[str, fmpq_mpoly],
                       parameters: dict[str, Fraction]) -> fmpq_mpoly:
    """The exact polynomial of ``node`` in ``ctx`` (parameters substituted)."""
    compiler = _Compiler(ctx, {**parameters, **variables}, what="constraint")
    return compiler.lift(compiler.run(node))


_ARGUMENT = fmpq_mpoly_ctx.get(("t", "p"), "lex")  # a sin/cos argument: t and π


def _argument(node: Node, parameter: str) -> tuple[Fraction, bool] | None:
    """(k, False) when ``node`` is k·parameter, (k, True) when it is k·π·parameter, for a
    rational k ≠ 0; None otherwise."""
    t, p = _ARGUMENT.gens()
    try:
        value = _Compiler(_ARGUMENT, {parameter: t, "pi": p},
                          what="sin/cos argument").run(node)
    except ExprError:
        return None
    terms = dict(value.terms()) if not isinstance(value, Fraction) else {}
    if len(terms) != 1:
        return None
    (exps, coeff), = terms.items()
    if exps not in ((1, 0), (1, 1)):
        return None
    k = fmpq(coeff)
    return Fraction(int(k.p), int(k.q)), exps == (1, 1)


def pi_multiples(node: Node, parameter: str) -> list[Fraction]:
    """Every k of an argument k·π·parameter of sin/cos in the tree (to pick the rescaling
    τ = g·π·t under which they all become integer multiples of τ)."""
    out = []
    if node.kind == "call" and node.args:
        arg = _argument(node.args[0], parameter)
        if arg is not None and arg[1]:
            out.append(arg[0])
    for a in node.args:
        out += pi_multiples(a, parameter)
    return out


def _multiple_of(node: Node, parameter: str, pi_scale: Fraction | None = None) -> int:
    """The integer m of a sin/cos argument m·τ: k·parameter (integer k) on an unscaled
    path, k·π·parameter = (k/g)·τ on a path rescaled by τ = g·π·parameter."""
    arg = _argument(node, parameter)
    if arg is not None:
        k, with_pi = arg
        if with_pi and pi_scale is not None and (k / pi_scale).denominator == 1:
            return int(k / pi_scale)
        if with_pi and pi_scale is None:
            raise ExprError(f"pi*{parameter} arguments need their own segment: sin/cos of "
                            f"k*pi*{parameter} cannot be mixed here", node.column)
        if not with_pi and pi_scale is not None:
            raise ExprError(f"sin/cos of k*{parameter} and of k*pi*{parameter} cannot be "
                            "mixed in one segment", node.column)
        if not with_pi and k.denominator == 1:
            return int(k)
    raise ExprError(f"the argument of sin/cos must be an integer multiple of {parameter} "
                    f"or a rational multiple of pi*{parameter} (e.g. 3*{parameter}, "
                    f"2*pi*{parameter})", node.column)


def compile_trajectory_coordinate(node: Node, parameter: str,
                                  parameters: dict[str, Fraction],
                                  pi_scale: Fraction | None = None) -> fmpq_mpoly:
    """The trig polynomial (in ``TRIG``, reduced) of a trajectory coordinate.

    With ``pi_scale`` g the coordinate is written in τ = g·π·parameter: sin(k·π·t)
    becomes sin((k/g)·τ) (k/g must be an integer), and a bare parameter is refused (it
    would be τ/(gπ), not rational)."""

    def call(n: Node):
        k = _multiple_of(n.args[0], parameter, pi_scale)
        if abs(k) > MAX_DEGREE:
            raise ExprError(f"the multiple {k} of {parameter} is larger than {MAX_DEGREE}",
                            n.column)
        return sin_multiple(k) if n.value == "sin" else cos_multiple(k)

    names: dict = {**parameters}
    if pi_scale is None:
        names[parameter] = T
    compiler = _Compiler(TRIG, names, call, what="trajectory")
    try:
        return reduce_trig(compiler.lift(compiler.run(node)))
    except ExprError as e:
        if pi_scale is not None and e.message.startswith(f"undeclared name {parameter!r}"):
            raise ExprError(f"{parameter} outside sin/cos cannot be mixed with sin/cos of "
                            f"k*pi*{parameter} (it would need an irrational coefficient)",
                            e.column) from None
        raise


def compile_constant(node: Node) -> LinearInPi:
    """An exact ``a + b·π`` (range ends)."""
    k = node.kind
    if k == "num":
        return LinearInPi(node.value)
    if k == "name":
        if node.value == "pi":
            return LinearInPi(Fraction(0), Fraction(1))
        raise ExprError(f"{node.value!r} is not allowed here: use numbers and pi", node.column)
    if k == "neg":
        v = compile_constant(node.args[0])
        return LinearInPi(-v.rational, -v.pi_coefficient)
    if k in ("add", "sub"):
        a, b = (compile_constant(x) for x in node.args)
        sign = 1 if k == "add" else -1
        return LinearInPi(a.rational + sign * b.rational,
                          a.pi_coefficient + sign * b.pi_coefficient)
    if k in ("mul", "div"):
        a, b = (compile_constant(x) for x in node.args)
        if k == "div":
            if b.pi_coefficient or b.rational == 0:
                raise ExprError("can only divide by a non-zero number", node.column)
            return LinearInPi(a.rational / b.rational, a.pi_coefficient / b.rational)
        if a.pi_coefficient and b.pi_coefficient:
            raise ExprError("pi^2 is not allowed: use a + b*pi", node.column)
        if a.pi_coefficient:
            a, b = b, a
        return LinearInPi(a.rational * b.rational, a.rational * b.pi_coefficient)
    if k == "pow":
        base, e = (compile_constant(x) for x in node.args)
        if base.pi_coefficient or e.pi_coefficient:
            raise ExprError("powers of pi are not allowed: use a + b*pi", node.column)
        n = _exponent(node.args[1], e.rational)
        _check_power(base.rational, n, node)
        return LinearInPi(base.rational ** n)
    raise ExprError("only numbers, pi, + - * / and ^ are allowed here", node.column)
