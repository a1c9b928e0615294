"""The checker's own reader of spec files: a YAML subset (block mappings and sequences,
flow ``[...]`` and ``{...}``, comments, one document) and singcheck's expression
grammar (docs/spec.md), parsed into trees by recursive descent, never evaluated by
Python.  Anything else is refused with :class:`Refused` (one line).

>>> parse_yaml("a: [1, {b: 2}]  # c\\nd:\\n  - x^2\\n")
{'a': ['1', {'b': '2'}], 'd': ['x^2']}
>>> parse_expr("-x^2 + 1/3")
('+', ('neg', ('^', ('var', 'x'), 2)), ('num', Fraction(1, 3)))
"""

from __future__ import annotations

import re
from fractions import Fraction

MAX_TEXT, MAX_DEPTH, MAX_POWER, MAX_BITS, MAX_TERMS = 100_000, 64, 64, 512, 100_000


class Refused(ValueError):
    """Something odd in a spec: the checker reads no further."""


class NotRational(Refused):
    """A well-formed value that is not rational (π, a square root, sin): a robot the
    checker cannot re-check, not an odd spec."""


# --- YAML subset -------------------------------------------------------------------

def _strip_comment(line: str) -> str:
    for i, ch in enumerate(line):
        if ch == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i].rstrip()
    return line.rstrip()


def parse_yaml(text: str):
    """The value of one YAML document in the subset specs use (strings at the leaves)."""
    if len(text) > MAX_TEXT or "\t" in text or "\x00" in text:
        raise Refused("a spec text too long, or with a tab or NUL")
    lines = []
    for n, raw in enumerate(text.splitlines(), 1):
        line = _strip_comment(raw)
        if line.strip() in ("---", "...") and not raw.startswith(" "):
            if lines:
                raise Refused(f"line {n}: a second YAML document")
            continue
        if line.strip():
            lines.append((n, len(line) - len(line.lstrip(" ")), line.strip()))
    if not lines:
        raise Refused("an empty spec")
    value, i = _block(lines, 0, lines[0][1], 0)
    if i != len(lines):
        raise Refused(f"line {lines[i][0]}: unexpected indentation")
    return value


def _block(lines, i, indent, depth):
    if depth > MAX_DEPTH:
        raise Refused("nesting too deep")
    seq = lines[i][2] == "-" or lines[i][2].startswith("- ")
    out: list | dict = [] if seq else {}
    while i < len(lines) and lines[i][1] == indent:
        n, _, body = lines[i]
        if seq != (body == "-" or body.startswith("- ")):
            raise Refused(f"line {n}: a sequence item and a mapping key at one level")
        if seq:
            rest = body[1:].strip()
            key = None
            if re.match(r"[A-Za-z_][A-Za-z0-9_]*\s*:(\s|$)", rest):  # "- key: value ..."
                lines[i] = (n, indent + len(body) - len(rest), rest)
                value, i = _block(lines, i, lines[i][1], depth + 1)
                out.append(value)
                continue
        else:
            m = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*:(?:\s+(.*))?", body)
            if not m:
                raise Refused(f"line {n}: expected 'key: value'")
            key, rest = m.group(1), (m.group(2) or "").strip()
            if key in out:
                raise Refused(f"line {n}: key {key} given twice")
        i += 1
        if rest:
            while rest[0] in "[{" and _depth(rest) > 0 and i < len(lines) \
                    and lines[i][1] > indent:
                rest += " " + lines[i][2]
                i += 1
            value = _flow_value(rest, n, depth)
        elif i < len(lines) and lines[i][1] > indent:
            value, i = _block(lines, i, lines[i][1], depth + 1)
        else:
            raise Refused(f"line {n}: an empty value")
        if seq:
            out.append(value)
        else:
            out[key] = value
    return out, i


def _depth(text: str) -> int:
    return sum((ch in "[{") - (ch in "]}") for ch in text)


_FLOW = re.compile(r"[\[\]{},]|[^\[\]{},]+")


def _flow_value(text: str, line: int, depth: int):
    """A plain scalar, or a flow collection (``[a, [b]]``, ``{k: v}``) of them."""
    if text[0] not in "[{":
        return _flow([text], 0, line, depth)[0]  # (commas and all)
    toks = [t for t in _FLOW.findall(text) if t.strip()]
    value, j = _flow(toks, 0, line, depth)
    if j != len(toks):
        raise Refused(f"line {line}: text after a flow collection")
    return value


def _flow(toks: list[str], j: int, line: int, depth: int):
    if depth > MAX_DEPTH:
        raise Refused("nesting too deep")
    tok = toks[j].strip() if j < len(toks) else ""
    if tok not in ("[", "{"):
        if not tok or tok[0] in "&*!|>\"'%@`:,]}":
            raise Refused(f"line {line}: an empty or unaccepted item {tok[:20]!r}")
        return tok, j + 1
    close, out = ("]", []) if tok == "[" else ("}", {})
    j += 1
    while j >= len(toks) or toks[j].strip() != close:
        if j >= len(toks) or (len(out) and toks[j].strip() != ","):
            raise Refused(f"line {line}: an unclosed flow collection")
        j += len(out) > 0
        if close == "]":
            item, j = _flow(toks, j, line, depth + 1)
            out.append(item)
            continue
        key, sep, rest = toks[j].partition(":") if j < len(toks) else ("", "", "")
        key = key.strip()
        if not sep or not key.isidentifier() or key in out or rest[:1] not in " ":
            raise Refused(f"line {line}: expected 'key: value' (once each) in a flow mapping")
        toks[j] = rest
        j += not rest.strip()
        out[key], j = _flow(toks, j, line, depth + 1)
    return out, j + 1


# --- expressions -------------------------------------------------------------------

_TOKEN = re.compile(r"\s*(?:(\d+(?:\.\d*)?(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)"
                    r"|([A-Za-z_][A-Za-z0-9_]*)|(\*\*|[-+*/^()]))")
FUNCTIONS = ("sin", "cos", "sqrt")


def _number(text: str) -> Fraction:
    mant, _, exp = text.lower().partition("e")
    whole, _, frac = mant.partition(".")
    value = Fraction(int(whole or "0") * 10 ** len(frac) + int(frac or "0"), 10 ** len(frac))
    e = int(exp or "0")
    if abs(e) > 160:
        raise Refused(f"number {text!r} out of range")
    value *= Fraction(10) ** e
    if max(value.numerator.bit_length(), value.denominator.bit_length()) > MAX_BITS:
        raise Refused(f"number {text!r} too long")
    return value


def _tokens(text: str) -> list[tuple[str, str]]:
    out, j = [], 0
    text = text.rstrip()
    while j < len(text):
        m = _TOKEN.match(text, j)
        if not m or m.end() == j:
            raise Refused(f"unexpected character {text[j:].lstrip()[:1]!r} in {text[:60]!r}")
        kind = "num" if m.group(1) else "name" if m.group(2) else "op"
        out.append((kind, m.group(m.lastindex)))
        j = m.end()
    return out


def parse_expr(text) -> tuple:
    """The tree of one expression: ('num', q), ('var', name), ('pi',), ('neg', e),
    (op, e, e) for + - * /, ('^', e, n), (f, e) for sin, cos, sqrt."""
    if not isinstance(text, str) or len(text) > 10_000:
        raise Refused(f"not an expression: {str(text)[:60]!r}")
    toks = _tokens(text)
    tree, j = _sum(toks, 0, 0)
    if j != len(toks):
        raise Refused(f"unexpected {toks[j][1]!r} in {text[:60]!r}")
    return tree


def _peek(toks, j):
    return toks[j][1] if j < len(toks) and toks[j][0] == "op" else None


def _sum(toks, j, d):
    left, j = _product(toks, j, d)
    while _peek(toks, j) in ("+", "-"):
        op = toks[j][1]
        right, j = _product(toks, j + 1, d)
        left = (op, left, right)
    return left, j


def _product(toks, j, d):
    left, j = _unary(toks, j, d)
    while _peek(toks, j) in ("*", "/"):
        op = toks[j][1]
        right, j = _unary(toks, j + 1, d)
        left = (op, left, right)
    return left, j


def _unary(toks, j, d):
    if d > MAX_DEPTH:
        raise Refused("expression nested too deep")
    if _peek(toks, j) in ("+", "-"):
        inner, k = _unary(toks, j + 1, d + 1)
        return (inner if toks[j][1] == "+" else ("neg", inner)), k
    base, j = _atom(toks, j, d)
    if _peek(toks, j) in ("^", "**"):
        exponent, j = _unary(toks, j + 1, d + 1)
        n = constant(exponent)
        if n.denominator != 1 or not 0 <= n <= MAX_POWER:
            raise Refused("an exponent must be a whole number from 0 to 64")
        base = ("^", base, int(n))
    if j < len(toks) and (toks[j][0] != "op" or toks[j][1] == "("):
        raise Refused(f"missing operator before {toks[j][1]!r}")
    return base, j


def _atom(toks, j, d):
    if j >= len(toks):
        raise Refused("an expression ends too early")
    kind, text = toks[j]
    if kind == "num":
        value = ("num", _number(text))
        if j + 1 < len(toks) and toks[j + 1] == ("name", "deg"):
            return ("*", value, ("/", ("pi",), ("num", Fraction(180)))), j + 2
        return value, j + 1
    if kind == "name":
        if text in FUNCTIONS:
            if _peek(toks, j + 1) != "(":
                raise Refused(f"{text} needs an argument in parentheses")
            inner, k = _sum(toks, j + 2, d + 1)
            if _peek(toks, k) != ")":
                raise Refused("expected ')'")
            return (text, inner), k + 1
        return (("pi",) if text == "pi" else ("var", text)), j + 1
    if text == "(":
        inner, k = _sum(toks, j + 1, d + 1)
        if _peek(toks, k) != ")":
            raise Refused("expected ')'")
        return inner, k + 1
    raise Refused(f"unexpected {text!r}")


def constant(tree, names: dict | None = None) -> Fraction:
    """The exact rational value of a tree of numbers and rational ``names``; anything else
    (π, sqrt, sin: :class:`NotRational`; an unknown name, a value of more than 4096 bits
    on the way: :class:`Refused`)."""
    names = names or {}
    op = tree[0]
    if op == "num":
        return tree[1]
    if op == "var":
        if tree[1] not in names:
            raise Refused(f"unknown name {tree[1]!r}")
        return names[tree[1]]
    if op in ("neg", "^"):
        a = constant(tree[1], names)
        value = -a if op == "neg" else a ** tree[2] if _bits(a) * tree[2] <= 8 * MAX_BITS \
            else None
    elif op in "+-*/" and len(op) == 1:
        a, b = constant(tree[1], names), constant(tree[2], names)
        if op == "/" and b == 0:
            raise Refused("division by zero")
        value = a + b if op == "+" else a - b if op == "-" else a * b if op == "*" else a / b
    else:
        raise NotRational(f"not a rational constant: {op}")
    if value is None or _bits(value) > 8 * MAX_BITS:
        raise Refused("a constant too large")
    return value


def _bits(q: Fraction) -> int:
    return max(q.numerator.bit_length(), q.denominator.bit_length())


# --- polynomials: {exponents: Fraction} over a fixed tuple of variables -------------

def poly(tree, variables: tuple, names: dict) -> dict:
    """The polynomial of a tree in ``variables`` with rational ``names`` substituted."""
    op = tree[0]
    n = len(variables)
    name = tree[1] if op == "var" else f"{op}({tree[1][1]})" if op in ("sin", "cos") and \
        tree[1][0] == "var" else None  # (sin, cos of a joint angle are variables too)
    if name in variables:
        e = [0] * n
        e[variables.index(name)] = 1
        return {tuple(e): Fraction(1)}
    if op in ("num", "var") or op == "/":
        c = constant(tree if op != "/" else tree[2], names)
        if op != "/":
            return {(0,) * n: c} if c else {}
        if c == 0:
            raise Refused("division by zero")
        return {e: v / c for e, v in poly(tree[1], variables, names).items()}
    if op == "neg":
        return {e: -v for e, v in poly(tree[1], variables, names).items()}
    if op in ("+", "-"):
        out = dict(poly(tree[1], variables, names))
        for e, v in poly(tree[2], variables, names).items():
            out[e] = out.get(e, 0) + (v if op == "+" else -v)
        return {e: v for e, v in out.items() if v}
    if op == "*":
        return mul(poly(tree[1], variables, names), poly(tree[2], variables, names))
    if op == "^":
        out = {(0,) * n: Fraction(1)}
        base = poly(tree[1], variables, names)
        for _ in range(tree[2]):
            out = mul(out, base)
        return out
    raise NotRational(f"{op} in a constraint, of something other than a joint or pose "
                      "variable")


def mul(p: dict, q: dict) -> dict:
    out: dict = {}
    for e, a in p.items():
        for f, b in q.items():
            g = tuple(x + y for x, y in zip(e, f, strict=False))
            out[g] = out.get(g, 0) + a * b
    if len(out) > MAX_TERMS:
        raise Refused("a polynomial with too many terms")
    return {e: v for e, v in out.items() if v}


def derivative(p: dict, k: int) -> dict:
    return {e[:k] + (e[k] - 1,) + e[k + 1:]: v * e[k] for e, v in p.items() if e[k]}


def coefficient(p: dict, k: int, d: int) -> dict:
    """The coefficient of variable k to the power d (its exponent set to 0)."""
    return {e[:k] + (0,) + e[k + 1:]: v for e, v in p.items() if e[k] == d}
