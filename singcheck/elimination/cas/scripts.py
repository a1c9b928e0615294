"""Compile elimination requests into CAS scripts and read the results back (pure code).

Compile: a ring over QQ in variables ``v1 … vn`` (the request's variables, in order),
the ideal, and one call of the library procedure that prints the result between
``@@singcheck-begin <label> <n>`` and ``@@singcheck-end <label>``.

Parse: each marker must appear exactly once and in order, the count must match, no
line may look like an error, and every line in between must be a polynomial in
``v1 … vn`` over QQ.  The exit status of the CAS is never taken as success by itself
(Singular exits 0 after ``? error occurred``).
"""

from __future__ import annotations

import re

from flint import fmpq_mpoly

from singcheck.algebra.polynomials import restrict
from singcheck.elimination.cas.polytext import (
    PolynomialSyntaxError,
    format_polynomial,
    parse_polynomial,
)
from singcheck.elimination.requests import EliminationRequest, prismatic_chain
from singcheck.errors import BackendError

BEGIN, END = "@@singcheck-begin", "@@singcheck-end"
_QUOTE = 160


def _label(request: EliminationRequest) -> str:
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", request.label):
        raise ValueError(f"request label {request.label!r} is not a plain word")
    return request.label


def _var(request: EliminationRequest, name: str) -> str:
    return f"v{request.context.names().index(name) + 1}"


def _parts(request: EliminationRequest) -> tuple[list[str], str, list[str]]:
    """Ring variables, the generators (one per line) and the variables to eliminate."""
    names = [f"v{i}" for i in range(1, request.context.nvars() + 1)]
    generators = ",\n  ".join(format_polynomial(g) for g in request.generators)
    return names, generators, [_var(request, v) for v in request.eliminate]


def singular_script(request: EliminationRequest, library: str) -> str:
    """The Singular script for ``request`` (``library``: path of singcheck.lib): Gröbner
    elimination, or the resultant chain over prismatic legs (:func:`prismatic_chain`)."""
    names, generators, eliminated = _parts(request)
    chain = prismatic_chain(request)
    if chain is None:
        call = f'sc_eliminate(I, {"*".join(eliminated)}, "{_label(request)}");\n'
    else:
        g, legs = chain
        generators = ",\n  ".join(format_polynomial(p) for p in (g, *(f for _, f in legs)))
        variables = ", ".join(_var(request, v) for v, _ in legs)
        call = f'sc_resultant_chain(I, ideal({variables}), "{_label(request)}");\n'
    return (
        f'LIB "{library}";\n'
        f"ring R = 0, ({','.join(names)}), dp;\n"
        "short = 0;\n"
        f"ideal I =\n  {generators};\n"
        f"{call}"
        "quit;\n"
    )


def macaulay2_script(request: EliminationRequest, library: str) -> str:
    """The Macaulay2 script for ``request`` (``library``: path of singcheck.m2)."""
    names, generators, eliminated = _parts(request)
    return (
        f'load "{library}";\n'
        f"R = QQ[{', '.join(names)}];\n"
        f"I = ideal(\n  {generators});\n"
        f'scEliminate(I, {{{", ".join(eliminated)}}}, "{_label(request)}");\n'
        "exit 0;\n"
    )


def _short(text: str) -> str:
    text = text.strip().replace("\n", " ⏎ ")
    return text if len(text) <= _QUOTE else text[:_QUOTE] + "…"


def parse_result(cas: str, stdout: str, stderr: str,
                 request: EliminationRequest) -> tuple[fmpq_mpoly, ...]:
    """The polynomials printed for ``request``, in the request's kept variables."""
    label = _label(request)
    lines = stdout.splitlines()
    for line in lines + stderr.splitlines():
        s = line.strip()
        if s.startswith("?") or " error" in s.lower() or s.startswith("error"):
            raise BackendError(f"{cas} reported an error: {_short(line)}")
    begins = [i for i, s in enumerate(lines) if s.startswith(BEGIN + " ")]
    ends = [i for i, s in enumerate(lines) if s.strip() == f"{END} {label}"]
    if len(begins) != 1 or len(ends) != 1:
        what = "begin" if len(begins) != 1 else "end"
        count = len(begins) if what == "begin" else len(ends)
        tail = _short("\n".join(lines[-3:]) or stderr) or "no output"
        raise BackendError(f"{cas} output has {count} '{what}' markers (expected 1); "
                           f"the output ends with: {tail}")
    b, e = begins[0], ends[0]
    head = lines[b].split()
    if len(head) != 3 or head[1] != label or not re.fullmatch(r"[0-9]{1,6}", head[2]) \
            or e < b:
        raise BackendError(f"{cas} output has a malformed marker: {_short(lines[b])}")
    stray = [s for s in lines[:b] + lines[e + 1:] if s.strip()]
    if stray:
        raise BackendError(f"{cas} printed something unexpected: {_short(stray[0])}")
    body = lines[b + 1:e]
    if len(body) != int(head[2]):
        raise BackendError(f"{cas} announced {head[2]} polynomials but printed {len(body)}: "
                           "truncated output?")
    ctx = request.context
    kept = request.kept_context()
    out = []
    for line in body:
        try:
            p = parse_polynomial(line, ctx)
        except PolynomialSyntaxError as err:
            raise BackendError(f"{cas} printed an unreadable polynomial ({err}): "
                               f"{_short(line)}") from None
        try:
            out.append(restrict(p, kept))
        except ValueError:
            raise BackendError(f"{cas} returned a polynomial that still involves an "
                               f"eliminated variable: {_short(line)}") from None
    return tuple(out)
