"""Exact polynomials as CAS text: writing them into scripts, reading them back.

Scripts name the ring variables ``v1 … vn`` (never the user's names, which could clash
with a CAS keyword); :func:`format_polynomial` writes exact rational coefficients and
:func:`parse_polynomial` reads what Singular (``short = 0``) or Macaulay2 (``toString``)
prints, in one left-to-right pass (linear time), refusing anything else.

>>> from flint import fmpq, fmpq_mpoly_ctx
>>> ctx = fmpq_mpoly_ctx.get(("x", "y"), "lex")
>>> x, y = ctx.gens()
>>> p = 3*x**2*y/4 + y - fmpq(1, 3)
>>> format_polynomial(p)
'3/4*v1^2*v2+v2-1/3'
>>> parse_polynomial(format_polynomial(p), ctx) == p
True
>>> parse_polynomial("-(1/7)*v1^3+2", ctx) == -x**3/7 + 2
True
"""

from __future__ import annotations

import re

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx, fmpz

from singcheck.budget import checkpoint

_TOKEN = re.compile(r"\s*(?:([0-9]+)|(v)([0-9]+)|([-+*/^()]))")
#: Bounds on what a CAS may print (its output is untrusted): the digits of one integer
#: in a coefficient, and an exponent.  Real results are far below both (the stacked
#: Orthoglide's ξ: 9 digits, degree 32).
MAX_DIGITS = 10_000
MAX_EXPONENT = 10_000


class PolynomialSyntaxError(ValueError):
    """The text is not a polynomial in v1 … vn with rational coefficients."""


def format_polynomial(p: fmpq_mpoly) -> str:
    """``p`` as ``c*v1^a*v2^b+…`` with exact rational ``c`` (``0`` for zero)."""
    if p.is_zero():
        return "0"
    out = []
    for exps, coeff in p.terms():
        c = fmpq(coeff)
        sign = "-" if c < 0 else "+"
        c = -c if c < 0 else c
        factors = [f"v{i + 1}" + (f"^{e}" if e > 1 else "") for i, e in enumerate(exps) if e]
        if c != 1 or not factors:
            factors.insert(0, str(c.p) if c.q == 1 else f"{c.p}/{c.q}")
        out.append(sign + "*".join(factors))
    text = "".join(out)
    return text[1:] if text.startswith("+") else text


def _tokens(text: str):
    pos = 0
    n = len(text)
    count = 0
    while pos < n:
        count += 1
        if count % (4 * CHECK_EVERY) == 0:
            checkpoint()
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            if text[pos:].strip() == "":
                return
            raise PolynomialSyntaxError(f"unexpected {text[pos:pos + 20]!r} at column {pos + 1}")
        pos = m.end()
        digits = m.group(1) if m.group(1) is not None else m.group(3)
        if digits is not None and len(digits) > MAX_DIGITS:
            raise PolynomialSyntaxError(f"a number of {len(digits)} digits (at most "
                                        f"{MAX_DIGITS}) at column {m.start(1) + 1}")
        if m.group(1) is not None:
            yield "num", fmpz(digits) if len(digits) > 1000 else int(digits)
        elif m.group(2):
            if len(digits) > 6:
                raise PolynomialSyntaxError(f"unknown variable v{digits[:6]}…")
            yield "var", int(digits)
        else:
            yield m.group(4), None


def parse_polynomial(text: str, ctx: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """Read a sum of terms ``±[coeff][*]v_i[^e]*…`` with coeff ``n``, ``n/m`` or ``(n/m)``."""
    plain = _parse_plain(text, ctx)
    if plain is not None:
        return plain
    nvars = ctx.nvars()
    terms: dict[tuple[int, ...], fmpq] = {}
    toks = list(_tokens(text))
    i = 0

    def peek(k: int = 0):
        return toks[i + k] if i + k < len(toks) else (None, None)

    if not toks:
        raise PolynomialSyntaxError("empty polynomial")
    read = 0
    while i < len(toks):
        read += 1
        if read % CHECK_EVERY == 0:
            checkpoint()  # a large polynomial (a cached ξ) is read within the time limit
        sign = 1
        kind, _ = peek()
        if kind in ("+", "-"):
            sign = -1 if kind == "-" else 1
            i += 1
        elif terms:
            raise PolynomialSyntaxError(f"expected + or - between terms, got {kind!r}")
        coeff, i = _coefficient(toks, i)
        exps = [0] * nvars
        expect_factor = coeff is None
        while True:
            kind, value = peek()
            if kind == "*" and coeff is not None or kind == "*" and not expect_factor:
                i += 1
                kind, value = peek()
                expect_factor = True
            if kind != "var":
                if expect_factor:
                    raise PolynomialSyntaxError(f"expected a variable, got {kind!r}")
                break
            if not 1 <= value <= nvars:
                raise PolynomialSyntaxError(f"unknown variable v{value}")
            i += 1
            power = 1
            if peek()[0] == "^":
                i += 1
                kind, power = peek()
                if kind != "num":
                    raise PolynomialSyntaxError("expected an exponent after ^")
                if power > MAX_EXPONENT:
                    raise PolynomialSyntaxError(f"an exponent larger than {MAX_EXPONENT}")
                power = int(power)
                i += 1
            exps[value - 1] += power
            expect_factor = False
            if peek()[0] != "*":
                break
        key = tuple(exps)
        c = (coeff if coeff is not None else fmpq(1)) * sign
        terms[key] = terms.get(key, fmpq(0)) + c
    return from_terms(ctx, {k: v for k, v in terms.items() if v != 0})


#: terms read between two checks of the time limit
CHECK_EVERY = 2048

#: one term of :func:`format_polynomial`'s own form: ``±n[/m]*v_i[^e]*…`` without spaces
#: or parentheses (possessive quantifiers: no backtracking)
_PLAIN_TERM = re.compile(r"([-+]?)(?:([0-9]++)(?:/([0-9]++))?(\*)?)?"
                         r"(v[0-9]++(?:\^[0-9]++)?(?:\*v[0-9]++(?:\^[0-9]++)?)*+)?")
_PLAIN_FACTOR = re.compile(r"v([0-9]++)(?:\^([0-9]++))?")


def _parse_plain(text: str, ctx: fmpq_mpoly_ctx) -> fmpq_mpoly | None:
    """:func:`parse_polynomial` for text in :func:`format_polynomial`'s form (what the
    caches hold), a term per regular-expression match; None for anything else, which
    the general parser then reads (or refuses, with the reason)."""
    if not text or any(ch in text for ch in " \t\r\n()"):
        return None
    nvars = ctx.nvars()
    terms: dict[tuple[int, ...], fmpq] = {}
    pos, n = 0, len(text)
    read = 0
    while pos < n:
        read += 1
        if read % CHECK_EVERY == 0:
            checkpoint()  # a large polynomial (a cached ξ) is read within the time limit
        m = _PLAIN_TERM.match(text, pos)
        sign, num, den, star, factors = m.groups()
        if m.end() == pos or (pos and not sign) or (num is None and factors is None) or \
                (star is not None) != (num is not None and factors is not None):
            return None
        if num is not None and (len(num) > MAX_DIGITS or den is not None and (
                len(den) > MAX_DIGITS or int(den) == 0)):
            return None
        exps = [0] * nvars
        for f in _PLAIN_FACTOR.finditer(factors or ""):
            index, power = f.groups()
            if len(index) > 6 or not 1 <= int(index) <= nvars or \
                    power is not None and (len(power) > 6 or int(power) > MAX_EXPONENT):
                return None
            exps[int(index) - 1] += 1 if power is None else int(power)
        c = fmpq(1) if num is None else fmpq(int(num), 1 if den is None else int(den))
        key = tuple(exps)
        terms[key] = terms.get(key, fmpq(0)) + (-c if sign == "-" else c)
        pos = m.end()
    return from_terms(ctx, {k: v for k, v in terms.items() if v != 0})


def from_terms(ctx: fmpq_mpoly_ctx, terms: dict) -> fmpq_mpoly:
    """``ctx.from_dict(terms)`` in O(n log n): FLINT's from_dict is quadratic in the
    number of terms, so build chunks and add them pairwise (additions merge linearly)."""
    items = list(terms.items())
    chunk = 128
    parts = [ctx.from_dict(dict(items[i:i + chunk])) for i in range(0, len(items), chunk)]
    if not parts:
        return ctx.from_dict({})
    while len(parts) > 1:
        parts = [parts[i] + parts[i + 1] if i + 1 < len(parts) else parts[i]
                 for i in range(0, len(parts), 2)]
    return parts[0]


def _coefficient(toks, i):
    """An optional ``n``, ``n/m`` or ``(n/m)`` at position i: (fmpq or None, next i)."""
    def at(k):
        return toks[k] if k < len(toks) else (None, None)

    paren = at(i)[0] == "("
    j = i + 1 if paren else i
    if at(j)[0] != "num":
        if paren:
            raise PolynomialSyntaxError("expected a number after (")
        return None, i
    num = at(j)[1]
    j += 1
    den = 1
    if at(j)[0] == "/":
        if at(j + 1)[0] != "num":
            raise PolynomialSyntaxError("expected a denominator after /")
        den = at(j + 1)[1]
        if den == 0:
            raise PolynomialSyntaxError("zero denominator")
        j += 2
    if paren:
        if at(j)[0] != ")":
            raise PolynomialSyntaxError("expected )")
        j += 1
    return fmpq(num, den), j
