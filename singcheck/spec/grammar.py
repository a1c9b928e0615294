"""singcheck's own expression grammar for spec files (untrusted input: no eval, no sympify).

Grammar (``^`` and ``**`` are the same right-associative power, binding tighter than
unary minus, so ``-x^2`` is ``-(x^2)``)::

    expr    := term (("+" | "-") term)*
    term    := unary (("*" | "/") unary)*
    unary   := ("+" | "-") unary | power
    power   := atom (("^" | "**") unary)?
    atom    := NUMBER ["deg"] | NAME | NAME "(" expr ")" | "(" expr ")"

Numbers are exact: ``0.1`` is 1/10, ``1e-3`` is 1/1000; ``30 deg`` is 30·π/180 = π/6.
Implicit multiplication (``2x``) is refused.  The parser builds a small tree; the
compilers turn it into exact objects: a polynomial over Q (:func:`compile_polynomial`),
a trig polynomial in ``Q[t, s, c]`` (:func:`compile_trajectory_coordinate`), or a
constant ``a + b·π`` (:func:`compile_constant`).  Errors are :class:`ExprError` with a column.

>>> str(compile_constant(parse("-pi/2 + 0.5")))
'1/2-1/2*pi'
>>> str(compile_constant(parse("135 deg")))
'3/4*pi'
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.radicals import (
    Surd,
    angle_function,
    cos_pi,
    expand_trig,
    reduce_relations,
    sin_pi,
    surd_polynomial,
)
from singcheck.algebra.trig import TRIG, LinearInPi, cos_multiple, reduce_trig, sin_multiple

MAX_EXPONENT = 64
MAX_LENGTH = 10_000
MAX_DEGREE = 256  # of any intermediate polynomial
MAX_TERMS = 100_000
MAX_BITS = 4096  # of any intermediate rational's numerator or denominator (1233 digits)
MAX_LITERAL_BITS = 512  # of a number literal's numerator or denominator (1e154 is fine)
MAX_NESTING = 64  # parentheses, calls and exponents inside one another
FUNCTIONS = ("sin", "cos")  # sqrt is handled apart: it only takes constants


#: the unit after a number that makes it an angle in degrees: ``30 deg`` is π/6, exactly
DEGREE = "deg"


class ExprError(ValueError):
    """A problem in an expression; ``column`` is 1-based (None when not known)."""

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.column = column

    def __str__(self) -> str:
        return self.message + (f" (column {self.column})" if self.column else "")


class TooLarge(ExprError):
    """A number past the grammar's size bounds (MAX_BITS): refused, never taken as a ball
    (the bound is a budget, not a statement about the field)."""


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
        if k1 == "num" and k2 == "name" and v2 == DEGREE:
            continue  # 30 deg: a unit, not a missing operator
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
        self.depth = 0

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
        first = self.term()
        rest = []
        while self.peek()[1] in ("+", "-"):
            _, op, col = self.take()
            rest.append(("add" if op == "+" else "sub", col, self.term()))
        return _chain(first, rest)

    def term(self) -> Node:
        first = self.unary()
        rest = []
        while self.peek()[1] in ("*", "/"):
            _, op, col = self.take()
            rest.append(("mul" if op == "*" else "div", col, self.unary()))
        return _chain(first, rest)

    def unary(self) -> Node:
        # a run of signs is read in a loop (not one call per sign): "------t" is "t"
        negative, col = False, None
        while self.peek()[1] in ("+", "-"):
            _, v, c = self.take()
            if v == "-":
                negative, col = not negative, c if col is None else col
        operand = self.power()
        return Node("neg", col, None, (operand,)) if negative else operand

    def power(self) -> Node:
        base = self.atom()
        if self.peek()[1] in ("^", "**"):
            _, _, col = self.take()
            return Node("pow", col, None, (base, self.nested(self.unary, col)))
        return base

    def nested(self, parse, column: int) -> Node:
        """``parse()`` one level deeper: refused past MAX_NESTING levels, so a hostile
        expression ends with an error, not with Python's recursion limit."""
        if self.depth >= MAX_NESTING:
            raise ExprError(f"the expression is nested more than {MAX_NESTING} levels deep "
                            "(parentheses, calls and exponents)", column)
        self.depth += 1
        try:
            return parse()
        finally:
            self.depth -= 1

    def atom(self) -> Node:
        kind, v, col = self.take()
        if kind == "num":
            value = _exact_number(v, col)
            if self.peek()[0] == "name" and self.peek()[1] == DEGREE:
                self.take()  # d deg is d·π/180 exactly: (d/180)*pi
                return Node("mul", col, None, (Node("num", col, value / 180),
                                               Node("name", col, "pi")))
            return Node("num", col, value)
        if kind == "name":
            if self.peek()[1] == "(":
                self.take()
                arg = self.nested(self.expr, col)
                self.expect(")")
                return Node("call", col, v, (arg,))
            return Node("name", col, v)
        if v == "(":
            node = self.nested(self.expr, col)
            self.expect(")")
            return node
        found = "the end of the expression" if kind == "end" else repr(v)
        raise ExprError(f"expected a number, a name or '(' but found {found}", col)


def _chain(first: Node, rest: list[tuple[str, int, Node]]) -> Node:
    """A left-associative chain ``a op b op c …`` as a tree of depth O(log n).

    ``a - b + c`` is ``a + (-b) + c`` and ``a * b / c * d`` is ``(a * b * d) / c``:
    exact rational arithmetic makes the regrouping change nothing, and a sum of
    thousands of terms cannot exhaust the recursion of the compilers that walk the tree.
    """
    if not rest:
        return first
    additive = rest[0][0] in ("add", "sub")
    if additive:
        terms = [first] + [Node("neg", col, None, (n,)) if op == "sub" else n
                           for op, col, n in rest]
        return _balanced("add", terms, [col for _, col, _ in rest])
    numerators = [first] + [n for op, _, n in rest if op == "mul"]
    denominators = [n for op, _, n in rest if op == "div"]
    cols = [col for _, col, _ in rest]
    top = _balanced("mul", numerators, cols)
    if not denominators:
        return top
    div_col = next(col for op, col, _ in rest if op == "div")
    return Node("div", div_col, None, (top, _balanced("mul", denominators, cols)))


def _balanced(kind: str, nodes: list[Node], cols: list[int]) -> Node:
    if len(nodes) == 1:
        return nodes[0]
    half = len(nodes) // 2
    return Node(kind, cols[min(half, len(cols)) - 1], None,
                (_balanced(kind, nodes[:half], cols), _balanced(kind, nodes[half:], cols)))


_LITERAL = re.compile(r"(\d*)\.?(\d*)(?:[eE]([+-]?\d+))?\Z")
_LOG2_10 = 3.3219280948873626


def _exact_number(text: str, column: int) -> Fraction:
    """The exact value of a literal, refused *before* it is built when its numerator or
    denominator would exceed MAX_LITERAL_BITS (``1e999999999`` costs nothing)."""
    m = _LITERAL.match(text)
    if not m:
        raise ExprError(f"bad number {text!r}", column)
    whole, frac, exp = m.groups()
    if exp is not None and len(exp.lstrip("+-").lstrip("0")) > 6:
        raise ExprError(f"the number {_short(text)} is too large (at most "
                        f"{MAX_LITERAL_BITS} bits)", column)
    e = int(exp) if exp is not None else 0
    digits = (whole + frac).lstrip("0")
    # value = int(digits) * 10^(e - len(frac)): bound the digits of both sides
    shift = e - len(frac)
    numerator = len(digits) + max(shift, 0)
    denominator = max(-shift, 0)
    if max(numerator, denominator) * _LOG2_10 > MAX_LITERAL_BITS + 4 and digits:
        raise ExprError(f"the number {_short(text)} is too large (at most "
                        f"{MAX_LITERAL_BITS} bits)", column)
    value = _LITERALS.get(text)
    if value is None:
        try:
            value = Fraction(text)  # exact decimal: Fraction("0.1") == 1/10
        except (ValueError, ZeroDivisionError):
            raise ExprError(f"bad number {text!r}", column) from None
        _kept(_LITERALS, text, value, 4096)
    if max(abs(value.numerator).bit_length(), value.denominator.bit_length()) > \
            MAX_LITERAL_BITS:
        raise ExprError(f"the number {_short(text)} is too large (at most "
                        f"{MAX_LITERAL_BITS} bits)", column)
    return value


def _kept(cache: dict, key, value, keep: int):
    """``value``, stored under ``key`` in one of the parse's caches, which is emptied when
    it holds ``keep`` entries (a batch's paths share a few; a hostile stream cannot grow
    it)."""
    if len(cache) >= keep:
        cache.clear()
    cache[key] = value
    return value


#: literals read (text -> Fraction, immutable): a batch's paths repeat their numbers
_LITERALS: dict[str, Fraction] = {}


def _short(text: str) -> str:
    """A number's text for a message: never thousands of digits."""
    return text if len(text) <= 24 else f"{text[:10]}…{text[-6:]} ({len(text)} characters)"


def _describe(q: Fraction) -> str:
    """A rational for a message, without converting a huge one to decimal."""
    bits = max(abs(q.numerator).bit_length(), q.denominator.bit_length())
    return _short(str(q)) if bits <= 256 else f"(a {bits}-bit number)"


def parse(text: str) -> Node:
    """The tree of an expression (raises :class:`ExprError`).  A short text read before
    gets the same tree (trees are frozen): a batch's paths repeat their ranges and
    constant coordinates (``-pi``, ``pi``, ``1``)."""
    if len(text) > MAX_LENGTH:
        raise ExprError(f"expression longer than {MAX_LENGTH} characters")
    if len(text) > _SHORT:
        return _Parser(text).parse()
    tree = _PARSED.get(text)
    if tree is None:
        tree = _kept(_PARSED, text, _Parser(text).parse(), 1024)
    return tree


#: texts up to this length are kept with their trees (:func:`parse`)
_SHORT = 32
_PARSED: dict[str, Node] = {}


# ---------------------------------------------------------------------------------
# compilers


@dataclass(frozen=True)
class Constant:
    """An exact constant ``surd + pi_coefficient·π`` (a parameter's value)."""

    surd: Surd
    pi_coefficient: Fraction = Fraction(0)

    def __str__(self) -> str:
        parts = [] if not self.surd and self.pi_coefficient else [str(self.surd)]
        if self.pi_coefficient:
            parts.append(f"{self.pi_coefficient}*pi")
        return " + ".join(parts)


class OutsideField:
    """A constant outside the exact field (a
    :class:`~singcheck.spec.real_constants.RealConstant`): the exact compilers refuse it,
    unless a hook gives them a variable standing for it."""

    text: str


@dataclass(frozen=True)
class RealLimit:
    """A prismatic joint's limit that is not rational (``2*sqrt(2)``, ``pi``): an exact
    real ``surd + pi_coefficient·π``, or any other finite real (``3*cos(1/3) + 1``, also
    an angle joint's: a :class:`~singcheck.spec.real_constants.RealConstant`), compared
    by ball arithmetic only (its crossings are never isolated exactly;
    :mod:`singcheck.certify.working_modes`)."""

    value: Constant  # or a RealConstant (:mod:`singcheck.spec.real_constants`)
    text: str

    def ball(self):
        from flint import arb, fmpq

        if not isinstance(self.value, Constant):  # a RealConstant: its own enclosure
            return self.value.ball()
        out = self.value.surd.ball()
        q = self.value.pi_coefficient
        if q:
            out += arb.pi() * arb(fmpq(q.numerator, q.denominator))
        return out

    def __float__(self) -> float:
        if not isinstance(self.value, Constant):
            return float(self.value)
        return float(self.value.surd) + float(self.value.pi_coefficient) * 3.141592653589793

    def __str__(self) -> str:
        return self.text


def _exponent(node: Node, value) -> int:
    if not isinstance(value, Fraction) or value.denominator != 1 or value < 0:
        raise ExprError("exponents must be non-negative integers", node.column)
    if value > MAX_EXPONENT:
        raise ExprError(f"exponent {_describe(value)} is larger than {MAX_EXPONENT}",
                        node.column)
    return int(value)


def _constant_of(p) -> Fraction | None:
    if isinstance(p, Fraction):
        return p
    if isinstance(p, Surd):
        return p.rational_value() if p.is_rational() else None
    if p.is_constant():
        c = p.leading_coefficient() if not p.is_zero() else fmpq(0)
        return Fraction(int(fmpq(c).p), int(fmpq(c).q))
    return None


def _scalar(x) -> bool:
    return isinstance(x, (Fraction, Surd))


def _simplify(x):
    """A surd that is rational becomes a Fraction (the fast, backwards-compatible path)."""
    if isinstance(x, Surd) and x.is_rational():
        return x.rational_value()
    return x


class _Compiler:
    """Evaluate a tree over a ring, with hooks for names, calls, square roots and π."""

    def __init__(self, ring, names, call=None, what="expression", surd=None, pi=None,
                 forbidden=None, opaque=None) -> None:
        self.ring = ring
        self.names = names  # name -> ring element, Fraction, Surd or Constant
        self.call = call  # sin/cos hook
        self.what = what
        self.surd = surd  # Surd -> ring element (None: square roots not allowed)
        self.pi = pi  # the ring element standing for π (None: π not allowed)
        self.forbidden = forbidden or {}  # name -> why it cannot be used bare
        #: parameter name -> the ring's variable standing for its value, for a parameter
        #: outside the exact field (an opaque constant: :mod:`~singcheck.spec.real_constants`)
        self.opaque = opaque or {}

    def const(self, q: Fraction):
        return self.ring.from_dict({(0,) * self.ring.nvars(): fmpq(q.numerator, q.denominator)}) \
            if q else self.ring.from_dict({})

    def lift(self, v, node: Node | None = None):
        if isinstance(v, Fraction):
            return self.const(v)
        if isinstance(v, Surd):
            if self.surd is None:
                raise ExprError(f"square roots are not allowed in a {self.what}",
                                node.column if node else None)
            try:
                return self.surd(v)
            except ValueError as e:
                raise ExprError(str(e), node.column if node else None) from None
        return v

    def _name(self, node: Node):
        name = node.value
        if name in self.forbidden:
            raise ExprError(self.forbidden[name], node.column)
        if name == "pi" and name not in self.names:
            if self.pi is None:
                raise ExprError(f"pi is not allowed in a {self.what} outside sin/cos (it is "
                                "not algebraic; coefficients must be exact algebraic numbers)",
                                node.column)
            return self.pi
        if name not in self.names:
            declared = ", ".join(sorted(self.names)) or "none"
            raise ExprError(f"undeclared name {name!r} (declared: {declared})", node.column)
        value = self.names[name]
        if isinstance(value, Constant) and value.pi_coefficient and self.pi is None and \
                name in self.opaque:
            return self.opaque[name]  # π cannot stay apart here: the value's ball is read
        if isinstance(value, OutsideField):
            if name in self.opaque:
                return self.opaque[name]
            raise ExprError(f"parameter {name!r} is not an exact algebraic number (it is "
                            f"{value.text!r}): only the robot's constraints can use it "
                            "outside sin/cos", node.column)
        if isinstance(value, Constant):
            if value.pi_coefficient:
                if self.pi is None:
                    raise ExprError(f"parameter {name!r} contains pi, which is allowed only "
                                    "inside sin/cos or in an angle", node.column)
                return self.lift(_simplify(value.surd), node) + self.pi * fmpq(
                    value.pi_coefficient.numerator, value.pi_coefficient.denominator)
            return _simplify(value.surd)
        return value

    def _call(self, node: Node):
        if node.value == "sqrt" and node in self.opaque:  # of a real parameter: its own
            hit = self.opaque[node]  # opaque constant (real_constants.root_constants)
            if isinstance(hit, ExprError):
                raise hit
            return hit
        if node.value == "sqrt":
            arg = _simplify(self.run(node.args[0]))
            q = _constant_of(arg)
            if q is None:
                raise ExprError("sqrt takes a constant (e.g. sqrt(3), sqrt(3/4)" +
                                (", sqrt(l) of a parameter l" if self.opaque else "") +
                                "), not a joint or pose variable", node.column)
            if q < 0:
                raise ExprError("sqrt of a negative number is not real", node.column)
            try:
                return _simplify(Surd.sqrt(q))
            except ValueError as e:
                raise ExprError(str(e), node.column) from None
        if self.call is None or node.value not in FUNCTIONS:
            if node.value in FUNCTIONS:
                raise ExprError(f"{node.value} is not allowed in a {self.what}: it must be "
                                "polynomial", node.column)
            raise ExprError(f"unknown function {node.value!r} (only sin, cos and sqrt)",
                            node.column)
        return self.call(node)

    def run(self, node: Node):
        k = node.kind
        if k == "num":
            return node.value
        if k == "name":
            return self._name(node)
        if k == "call":
            return self._call(node)
        args = [self.run(a) for a in node.args]
        if k == "neg":
            return -args[0]
        if k == "pow":
            e = _exponent(node.args[1], _constant_of(args[1]))
            _check_power(args[0], e, node)
            return _simplify(_checked(args[0] ** e, node))
        a, b = args
        if k in ("add", "sub", "mul"):
            if _scalar(a) and _scalar(b):
                value = a + b if k == "add" else a - b if k == "sub" else a * b
                return _simplify(_checked(value, node))
            a, b = self.lift(a, node), self.lift(b, node)
            if k == "add":
                return a + b
            if k == "sub":
                return a - b
            if a.total_degree() + b.total_degree() > MAX_DEGREE:
                raise ExprError(f"the expression's degree exceeds {MAX_DEGREE}", node.column)
            return _checked(a * b, node)
        if k == "div":
            d = b if isinstance(b, Surd) else _constant_of(b)
            if d is None:
                raise ExprError(f"division by a non-constant expression is not polynomial in "
                                f"a {self.what}", node.column)
            if not d:
                raise ExprError("division by zero", node.column)
            if isinstance(d, Surd) or isinstance(a, Surd):
                inverse = Surd.rational(1) / d if isinstance(d, Surd) else \
                    Surd.rational(1 / d)
                if _scalar(a):
                    return _simplify(_checked(a * inverse, node))
                return a * self.lift(_simplify(inverse), node)
            if isinstance(a, Fraction):
                return a / d
            return a / fmpq(d.numerator, d.denominator)
        raise AssertionError(k)  # pragma: no cover


def _check_power(base, e: int, node: Node) -> None:
    """Refuse a power before computing it when its size would explode."""
    if isinstance(base, Surd):
        return  # e ≤ MAX_EXPONENT and the terms stay few (one per squarefree product)
    if isinstance(base, Fraction):
        bits = max(abs(base.numerator).bit_length(), base.denominator.bit_length())
        if bits * e > MAX_BITS:
            raise TooLarge(f"the number {_describe(base)}^{e} is too large", node.column)
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
            raise TooLarge("a number in the expression is too large", node.column)
    elif isinstance(value, Surd):
        for q in value.terms.values():
            _checked(q, node)
    elif len(value) > MAX_TERMS:
        raise ExprError(f"the expanded expression has more than {MAX_TERMS} terms",
                        node.column)
    return value


def angles_in(node: Node, names) -> set[str]:
    """The names among ``names`` used inside a sin/cos argument: the angles."""
    out: set[str] = set()

    def walk(n: Node, inside: bool) -> None:
        if n.kind == "name" and inside and n.value in names:
            out.add(n.value)
        for a in n.args:
            walk(a, inside or (n.kind == "call" and n.value in ("sin", "cos")))

    walk(node, False)
    return out


_ARGUMENT_FORM = ("the argument of sin/cos must be an integer combination of angles plus a "
                  "constant (e.g. cos(2*theta + pi/3), sin(theta + a))")


def _linear_argument(node: Node, angles, parameters) -> tuple[dict[str, int], Fraction]:
    """``({angle: k}, q)`` with the argument = Σ k·angle + q·π (k integers, 12q integer)."""
    ring = fmpq_mpoly_ctx.get((*sorted(angles), "pi"), "lex")
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    pi = gens.pop("pi")
    value = _Compiler(ring, {**parameters, **gens}, what="sin/cos argument", pi=pi).run(node)
    value = _Compiler(ring, {}).lift(value, node)
    coefficients: dict[str, int] = {}
    q = Fraction(0)
    for exps, coeff in value.terms():
        c = Fraction(int(coeff.p), int(coeff.q))
        if sum(exps) != 1:
            raise ExprError(_ARGUMENT_FORM, node.column)
        name = ring.names()[exps.index(1)]
        if name == "pi":
            q = c
        elif c.denominator != 1:
            raise ExprError(_ARGUMENT_FORM, node.column)
        else:
            coefficients[name] = int(c)
    if (12 * q).denominator != 1:
        raise ExprError("only multiples of pi/12 have exact sines and cosines here (e.g. "
                        "theta + pi/4)", node.column)
    if sum(abs(k) for k in coefficients.values()) > MAX_EXPONENT:
        raise ExprError(f"the multiples in a sin/cos argument add up to more than "
                        f"{MAX_EXPONENT}", node.column)
    return coefficients, q


def angle_offset(node: Node, angles, parameters) -> tuple[dict[str, int], str] | None:
    """``({angle: k}, c)`` when a sin/cos argument that :func:`_linear_argument` refuses
    is Σ k·angle + c with integer k and a constant c (``th1 + a``, ``2*phi + 1/3``, with
    ``a: 2*cos(1/10)`` or ``a: 0.1``): ``c`` written in the grammar (numbers, ``pi``,
    parameters); None for any other argument.  cos c and sin c are then opaque constants
    (:mod:`singcheck.spec.real_constants`)."""
    names = sorted(angles)
    symbolic = sorted(p for p, v in parameters.items() if not isinstance(v, Fraction))
    ring = fmpq_mpoly_ctx.get((*names, "pi", *symbolic), "lex")
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    pi = gens.pop("pi")
    rational = {p: v for p, v in parameters.items() if isinstance(v, Fraction)}
    try:
        compiler = _Compiler(ring, {**rational, **gens}, what="sin/cos argument", pi=pi)
        value = compiler.lift(compiler.run(node), node)
    except ExprError:
        return None
    count = len(names)
    coefficients: dict[str, int] = {}
    rest = {}
    for exps, coeff in value.terms():
        if any(exps[:count]):
            if sum(exps[:count]) != 1 or any(exps[count:]) or coeff.q != 1:
                return None  # not linear in the angles with integer multiples
            coefficients[names[list(exps[:count]).index(1)]] = int(coeff.p)
        else:
            rest[exps[count:]] = coeff
    if not rest or sum(abs(k) for k in coefficients.values()) > MAX_EXPONENT:
        return None
    constant = fmpq_mpoly_ctx.get(("pi", *symbolic), "lex").from_dict(rest)
    return coefficients, str(constant)


def constant_text(node: Node, parameters) -> str | None:
    """The constant ``node`` written anew in the grammar, when it names nothing but
    parameters and ``pi`` and is not a rational (the argument of ``sqrt(l)`` in a
    constraint, ``l: 2*cos(1/10)``, or of ``sqrt(1 + sqrt(2))``); None otherwise (the
    exact compiler takes ``sqrt(3)``; ``sqrt(x)`` of a pose variable is refused)."""
    if not _names_in(node) <= {*parameters, "pi"}:
        return None
    try:
        value = compile_value(node, parameters)
        if not value.pi_coefficient and value.surd.is_rational():
            return None
    except ExprError:
        pass
    return unparse(node)


def _names_in(node: Node) -> set[str]:
    own = {node.value} if node.kind == "name" else set()
    return own.union(*(_names_in(a) for a in node.args))


_SYMBOLS = {"add": "+", "sub": "-", "mul": "*", "div": "/", "pow": "^"}
_PRECEDENCE = {"add": 1, "sub": 1, "mul": 2, "div": 2, "neg": 3, "pow": 4}


def unparse(node: Node) -> str:
    """The text of a tree in the grammar, with the parentheses its precedence needs.

    >>> unparse(parse("-2*l^2/3 + sqrt(l - 1/2)"))
    '-2*l^2/3 + sqrt(l - 1/2)'
    >>> unparse(parse("(a - b)^2 / (c*d) - -e / -3"))
    '(a - b)^2/(c*d) - -e/-3'
    """
    return _unparse(node)[0]


def _unparse(node: Node) -> tuple[str, int]:
    """(text, precedence): 5 for an atom."""
    k = node.kind
    if k == "num":
        q = Fraction(node.value)
        return (str(q.numerator), 5) if q.denominator == 1 else (str(q), 2)
    if k in ("name", "call"):
        return (str(node.value), 5) if k == "name" else \
            (f"{node.value}({_unparse(node.args[0])[0]})", 5)
    if k == "neg":
        if node.args[0].kind == "neg":
            return _unparse(node.args[0].args[0])
        inner, p = _unparse(node.args[0])
        return (f"-{inner}", min(p, 3)) if p >= 2 else (f"-({inner})", 3)
    (a, pa), (b, pb) = (_unparse(x) for x in node.args)
    own = _PRECEDENCE[k]
    if k in ("add", "sub"):
        right = node.args[1]
        while right.kind == "neg":  # a + -b: a - b (and a - -b: a + b)
            right = right.args[0]
            k = "sub" if k == "add" else "add"
        b, pb = _unparse(right)
        b = f"({b})" if pb <= 1 and k == "sub" else b
        return f"{a} {_SYMBOLS[k]} {b}", own
    if k == "pow":
        return f"{a if pa == 5 else f'({a})'}^{b if pb == 5 else f'({b})'}", own
    a = a if pa >= own else f"({a})"
    b = b if pb > own or (k == "mul" and pb == own) else f"({b})"
    return f"{a}{_SYMBOLS[k]}{b}", own


def compile_polynomial(node: Node, ctx: fmpq_mpoly_ctx, variables: dict[str, fmpq_mpoly],
                       parameters: dict[str, object],
                       angles: dict[str, tuple[fmpq_mpoly, fmpq_mpoly]] | None = None,
                       opaque: dict[str, fmpq_mpoly] | None = None,
                       offsets: dict | None = None) -> fmpq_mpoly:
    """The exact polynomial of ``node`` in ``ctx`` (parameters substituted).

    ``angles[v] = (cos(v), sin(v))`` are the ring's variables of each angle v: ``sin`` and
    ``cos`` of integer combinations of angles plus multiples of π/12 are expanded exactly
    and reduced modulo cos² + sin² = 1; a bare angle is refused.  Square roots become
    the ring's ``sqrt(p)`` variables (reduced modulo sqrt(p)² = p).  ``opaque[name]``
    is the ring's variable standing for a parameter outside the exact field (its value
    a :class:`~singcheck.spec.real_constants.RealConstant`, or ``a + b·π`` with b ≠ 0,
    which cannot stay apart outside sin/cos); without it such a parameter is refused.
    ``offsets[call]`` is ``({angle: k}, cos c, sin c)`` for a sin/cos call whose argument
    is Σ k·angle + c with c outside the exact field (:func:`angle_offset`): cos c and
    sin c are the ring's variables of those opaque constants, and
    cos(Σ + c) = cos Σ·cos c − sin Σ·sin c exactly (sin likewise).
    """
    angles = angles or {}
    offsets = offsets or {}

    def constant(value: Surd):
        return compiler.lift(_simplify(value))

    def call(n: Node):
        if n in offsets:
            coefficients, cos_c, sin_c = offsets[n]
            c, s = expand_trig(coefficients, Fraction(0), angles, constant)
            out = c * cos_c - s * sin_c if n.value == "cos" else s * cos_c + c * sin_c
            return reduce_relations(out)
        coefficients, q = _linear_argument(n.args[0], angles, parameters)
        c, s = expand_trig(coefficients, q, angles, constant)
        return c if n.value == "cos" else s

    forbidden = {v: f"{v!r} is an angle (it appears inside sin/cos): use it only through "
                    f"sin({v}) and cos({v})" for v in angles}
    compiler = _Compiler(ctx, {**parameters, **variables}, call, what="constraint",
                         surd=lambda v: surd_polynomial(v, ctx), forbidden=forbidden,
                         opaque=opaque)
    return reduce_relations(compiler.lift(compiler.run(node), node))


def compile_value(node: Node, parameters: dict[str, object]) -> Constant:
    """The exact value ``surd + q·π`` of a constant expression (a parameter's value):
    numbers, earlier parameters, ``pi``, ``sqrt`` of rationals, sin/cos of multiples of
    π/12, ``+ - * / ^``."""
    k = node.kind
    if k == "num":
        return Constant(Surd.rational(node.value))
    if k == "name":
        if node.value == "pi":
            return Constant(Surd(), Fraction(1))
        if node.value not in parameters:
            raise ExprError(f"{node.value!r} is not allowed here: use numbers, pi, sqrt and "
                            "parameters defined above", node.column)
        v = parameters[node.value]
        if isinstance(v, OutsideField):
            raise ExprError(f"parameter {node.value!r} is not an exact algebraic number",
                            node.column)
        return v if isinstance(v, Constant) else Constant(Surd.rational(v))
    if k == "call":
        arg = compile_value(node.args[0], parameters)
        if node.value == "sqrt":
            if arg.pi_coefficient or not arg.surd.is_rational():
                raise ExprError("sqrt takes a rational constant (e.g. sqrt(3))", node.column)
            if arg.surd.rational_value() < 0:
                raise ExprError("sqrt of a negative number is not real", node.column)
            return Constant(Surd.sqrt(arg.surd.rational_value()))
        if node.value in FUNCTIONS:
            if arg.surd:
                raise ExprError("sin/cos of a constant must be of a multiple of pi/12 (e.g. "
                                "sin(pi/3))", node.column)
            value = (cos_pi if node.value == "cos" else sin_pi)(arg.pi_coefficient)
            if value is None:
                raise ExprError("only multiples of pi/12 have exact sines and cosines here",
                                node.column)
            return Constant(value)
        raise ExprError(f"unknown function {node.value!r} (only sin, cos and sqrt)", node.column)
    args = [compile_value(a, parameters) for a in node.args]
    if k == "neg":
        return Constant(-args[0].surd, -args[0].pi_coefficient)
    if k in ("add", "sub"):
        a, b = args
        sign = 1 if k == "add" else -1
        return Constant(a.surd + b.surd * sign, a.pi_coefficient + sign * b.pi_coefficient)
    if k == "mul":
        a, b = args
        if a.pi_coefficient and b.pi_coefficient:
            raise ExprError("pi^2 is not allowed: use a + b*pi", node.column)
        if a.pi_coefficient:
            a, b = b, a
        if b.pi_coefficient and not a.surd.is_rational():
            raise ExprError("pi times a square root is not supported", node.column)
        factor = a.surd.rational_value() if b.pi_coefficient else Fraction(0)
        return Constant(_checked(a.surd * b.surd, node), factor * b.pi_coefficient)
    if k == "div":
        a, b = args
        if b.pi_coefficient or not b.surd:
            raise ExprError("can only divide by a non-zero number without pi", node.column)
        if a.pi_coefficient and not b.surd.is_rational():
            raise ExprError("pi divided by a square root is not supported", node.column)
        pi = a.pi_coefficient / b.surd.rational_value() if a.pi_coefficient else Fraction(0)
        return Constant(_checked(a.surd / b.surd, node), pi)
    if k == "pow":
        base, e = args
        if e.pi_coefficient or not e.surd.is_rational():
            raise ExprError("exponents must be non-negative integers", node.column)
        exponent = e.surd.rational_value()
        inverse = exponent < 0 and exponent.denominator == 1  # x^(-n) = 1/x^n
        n = _exponent(node.args[1], -exponent if inverse else exponent)
        if base.pi_coefficient:
            raise ExprError("powers of pi are not allowed: use a + b*pi", node.column)
        if base.surd.is_rational():
            _check_power(base.surd.rational_value(), n, node)
        if inverse and not base.surd:
            raise ExprError("a negative power of zero", node.column)
        value = _checked(base.surd ** n, node)
        return Constant(_checked(value.inverse(), node) if inverse else value)
    raise AssertionError(k)  # pragma: no cover


def _argument_terms(node: Node, parameter: str, parameters) -> dict | None:
    """The argument of sin/cos as {(t-degree, π-degree): coefficient}, or None (a new
    dict each call: callers pop from it).

    A trajectory's compilation asks this of each sin/cos node three times (the π
    rescaling, the pose angles, the polynomial), and a batch's paths share their
    arguments (``2*t``): about a fifth of a heart's parse.  The answer is kept per
    argument's shape (the tree without its columns), parameter name and parameters (the
    same dict object holding the same items; the dict held with it so that its id is not
    reused while the entry lives)."""
    key = (_shape(node), parameter, id(parameters))
    items = tuple(parameters.items())
    hit = _ARGUMENT_TERMS.get(key)
    if hit is not None and hit[0] is parameters and hit[1] == items:
        return None if hit[2] is None else dict(hit[2])
    terms = _argument_terms_of(node, parameter, parameters)
    _kept(_ARGUMENT_TERMS, key, (parameters, items, terms), 512)
    return None if terms is None else dict(terms)


def _shape(node: Node) -> tuple:
    """The tree as nested tuples of kinds and values, without the columns."""
    return (node.kind, node.value, *(_shape(a) for a in node.args))


_ARGUMENT_TERMS: dict = {}


def _argument_terms_of(node: Node, parameter: str, parameters) -> dict | None:
    ring = fmpq_mpoly_ctx.get((parameter, "pi"), "lex")
    t, pi = ring.gens()
    try:
        p = _Compiler(ring, {**parameters, parameter: t}, what="sin/cos argument",
                      pi=pi).run(node)
        p = _Compiler(ring, {}).lift(p, node)
    except ExprError:
        return None
    return {e: Fraction(int(c.p), int(c.q)) for e, c in p.terms()}


def pi_multiples(node: Node, parameter: str, parameters=None) -> list[Fraction]:
    """Every k of a sin/cos argument k·π·parameter (+ a multiple of π) in the tree, to pick
    the rescaling τ = g·π·parameter under which each is an integer multiple of τ."""
    out = []
    if node.kind == "call" and node.value in FUNCTIONS and node.args:
        terms = _argument_terms(node.args[0], parameter, parameters or {})
        if terms and terms.get((1, 1)):
            out.append(terms[(1, 1)])
    for a in node.args:
        out += pi_multiples(a, parameter, parameters)
    return out


def _multiple_of(node: Node, parameter: str, parameters,
                 pi_scale: Fraction | None = None) -> tuple[int, Fraction]:
    """(k, q) when ``node`` is k·parameter + q·π for an integer k and 12q an integer; on a
    piece rescaled by τ = g·π·parameter (``pi_scale`` g), when it is (k·g)·π·parameter
    + q·π = k·τ + q·π."""
    terms = _argument_terms(node, parameter, parameters) or {}
    k, q = terms.pop((1, 0), Fraction(0)), terms.pop((0, 1), Fraction(0))
    k_pi = terms.pop((1, 1), Fraction(0))
    if k_pi and pi_scale is None or k and pi_scale is not None:
        raise ExprError(f"sin/cos of k*{parameter} and of k*pi*{parameter} cannot be mixed "
                        "in one piece (give each its own segment)", node.column)
    if pi_scale is not None:
        k = k_pi / pi_scale
    if not terms and k.denominator == 1 and (12 * q).denominator == 1 and (k or q):
        return int(k), q
    raise ExprError(f"the argument of sin/cos must be an integer multiple of {parameter} "
                    f"or a rational multiple of pi*{parameter} (e.g. 3*{parameter}, "
                    f"2*pi*{parameter}), plus a multiple of pi/12", node.column)


def polynomial_angle(node: Node, parameter: str, parameters,
                     pi_scale: Fraction | None = None) -> tuple[str, str] | None:
    """The path-ring variables ``(cos(g), sin(g))`` of a sin/cos argument g(t) + qπ that
    is not k·t + qπ, with g a non-constant polynomial in t (``cos(t^2)``): they are the
    pose angle functions of :func:`~singcheck.algebra.radicals.angle_function`.  None for
    any other argument (sin/cos inside it, a constant, a piece rescaled by π)."""
    if pi_scale is not None:
        return None
    try:
        p, q = compile_angle_coordinate(node, parameter, parameters, TRIG)
    except ExprError:
        return None
    degrees = p.degrees()
    if degrees[1] > 0 or degrees[2] > 0 or degrees[0] < 1:
        return None
    return angle_function(p, q)


def polynomial_angles(node: Node, parameter: str, parameters,
                      pi_scale: Fraction | None = None) -> list[tuple[str, str]]:
    """Every :func:`polynomial_angle` of the sin/cos calls in the tree, in order."""
    out = []
    if node.kind == "call" and node.value in FUNCTIONS and node.args:
        try:
            _multiple_of(node.args[0], parameter, parameters, pi_scale)
        except ExprError:
            names = polynomial_angle(node.args[0], parameter, parameters, pi_scale)
            if names is not None and names not in out:
                out.append(names)
    for a in node.args:
        out += [n for n in polynomial_angles(a, parameter, parameters, pi_scale)
                if n not in out]
    return out


def compile_trajectory_coordinate(node: Node, parameter: str, parameters,
                                  ring: fmpq_mpoly_ctx = TRIG,
                                  pi_scale: Fraction | None = None) -> fmpq_mpoly:
    """The trig polynomial (in ``ring``: ``TRIG``, or ``TRIG`` with ``sqrt(p)``
    variables, reduced) of a trajectory coordinate.

    With ``pi_scale`` g the coordinate is written in τ = g·π·parameter: sin(k·π·t)
    becomes sin((k/g)·τ) (k/g must be an integer), and a bare parameter is refused (it
    would be τ/(gπ), not rational)."""
    t, s, c = ring.gens()[:3]

    def constant(value: Surd):
        return compiler.lift(_simplify(value))

    def call(n: Node):
        try:
            k, q = _multiple_of(n.args[0], parameter, parameters, pi_scale)
        except ExprError:
            names = polynomial_angle(n.args[0], parameter, parameters, pi_scale)
            if names is None or names[0] not in ring.names():
                raise
            return ring.gens()[ring.names().index(names[0 if n.value == "cos" else 1])]
        if abs(k) > MAX_DEGREE:
            raise ExprError(f"the multiple {k} of {parameter} is larger than {MAX_DEGREE}",
                            n.column)
        key = (ring, n.value, k, q)
        hit = _SIN_COS.get(key)
        if hit is None:
            ck, sk = (_into(cos_multiple(k), ring), _into(sin_multiple(k), ring))
            cq, sq = constant(cos_pi(q)), constant(sin_pi(q))
            hit = _kept(_SIN_COS, key, ck * cq - sk * sq if n.value == "cos" else
                        sk * cq + ck * sq, 1024)
        return hit

    forbidden = {} if pi_scale is None else {parameter: (
        f"{parameter} outside sin/cos cannot be mixed with sin/cos of k*pi*{parameter} (it "
        "would need an irrational coefficient)")}
    compiler = _Compiler(ring, {**parameters, parameter: t}, call, what="trajectory",
                         surd=lambda v: surd_polynomial(v, ring), forbidden=forbidden)
    return _reduce_path(compiler.lift(compiler.run(node), node))


#: cos(k·t + qπ) and sin(k·t + qπ) per (ring, function, k, q), as compiled by
#: :func:`compile_trajectory_coordinate`: a batch's hearts ask for the same few multiples
#: again and again (Chebyshev polynomials, moved into the ring, times the exact cos qπ,
#: sin qπ: about a tenth of a heart's parse).  FLINT polynomials are values here: nothing
#: in singcheck changes one in place, so one object serves every coordinate.
_SIN_COS: dict = {}


def compile_angle_coordinate(node: Node, parameter: str, parameters,
                             ring: fmpq_mpoly_ctx = TRIG,
                             pi_scale: Fraction | None = None) -> tuple[fmpq_mpoly, Fraction]:
    """``(P, q)`` with an angle's trajectory coordinate = P(t, sin t, cos t) + q·π."""
    names = ring.names()
    ring_pi = fmpq_mpoly_ctx.get((*names, "pi"), "lex")
    p = compile_trajectory_coordinate_with_pi(node, parameter, parameters, ring_pi, pi_scale)
    q = Fraction(0)
    rest = {}
    for exps, coeff in p.terms():
        if exps[-1] == 0:
            rest[exps[:-1]] = coeff
        elif exps[-1] == 1 and not any(exps[:-1]):
            q = Fraction(int(coeff.p), int(coeff.q))
        else:
            raise ExprError("pi may only be added to an angle (e.g. t + pi/6)", node.column)
    return ring.from_dict(rest), q


def compile_trajectory_coordinate_with_pi(node, parameter, parameters, ring_pi, pi_scale=None):
    """A trajectory coordinate in a ring whose last variable stands for π."""
    t = ring_pi.gens()[0]
    base = fmpq_mpoly_ctx.get(ring_pi.names()[:-1], "lex")

    def call(n: Node):
        inner = compile_trajectory_coordinate(n, parameter, parameters, base, pi_scale)
        return ring_pi.from_dict({(*e, 0): c for e, c in inner.terms()})

    forbidden = {} if pi_scale is None else {parameter: (
        f"{parameter} outside sin/cos cannot be mixed with sin/cos of k*pi*{parameter}")}
    compiler = _Compiler(ring_pi, {**parameters, parameter: t}, call, what="trajectory",
                         surd=lambda v: surd_polynomial(v, ring_pi), pi=ring_pi.gens()[-1],
                         forbidden=forbidden)
    return _reduce_path(compiler.lift(compiler.run(node), node))


def _into(p: fmpq_mpoly, ring: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """A ``TRIG`` polynomial in a ring whose first variables are t, s, c."""
    if ring is TRIG:
        return p
    extra = (0,) * (ring.nvars() - 3)
    return ring.from_dict({(*e, *extra): c for e, c in p.terms()})


def _reduce_path(p: fmpq_mpoly) -> fmpq_mpoly:
    return reduce_trig(p) if p.context() is TRIG else reduce_relations(p)


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
