"""Elimination requests: what the core asks a computer-algebra backend to compute.

A request is plain data: generators of an ideal in Q[variables] and the variables to
eliminate.  A backend returns polynomials in the kept variables whose common zero set
is the Zariski closure of the projection of the ideal's zero set (the generators of the
elimination ideal, or a multiple of it with the same zero set); the core only ever uses
that zero set, via squarefree parts.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import squarefree_part


@dataclass(frozen=True)
class EliminationRequest:
    label: str  # what is computed, in the paper's words (e.g. "singularity_surface")
    context: fmpq_mpoly_ctx  # the ring of the generators
    generators: tuple[fmpq_mpoly, ...]
    eliminate: tuple[str, ...]

    @property
    def keep(self) -> tuple[str, ...]:
        return tuple(v for v in self.context.names() if v not in self.eliminate)

    def kept_context(self) -> fmpq_mpoly_ctx:
        return fmpq_mpoly_ctx.get(self.keep, "lex")


@dataclass(frozen=True)
class EliminationResult:
    request: EliminationRequest
    polynomials: tuple[fmpq_mpoly, ...]  # in request.kept_context()
    method: str  # how it was computed, for the report (e.g. "resultant chain")
    backend: str


class EliminationBackend(Protocol):
    name: str

    def eliminate(self, request: EliminationRequest) -> EliminationResult: ...

    def version(self) -> str: ...


def leg_structure(request: EliminationRequest):
    """``(g, [(v, f_v), …])`` when every eliminated variable v has a generator f_v that
    involves v and no other eliminated variable, with a constant leading coefficient in
    v, and exactly one generator g is left; else None."""
    names = request.context.names()
    legs: dict[str, fmpq_mpoly] = {}
    rest = []
    for f in request.generators:
        involved = [v for v in request.eliminate if f.degrees()[names.index(v)] > 0]
        if len(involved) == 1 and involved[0] not in legs and _constant_lead(f, names,
                                                                            involved[0]):
            legs[involved[0]] = f
        else:
            rest.append(f)
    if len(rest) != 1 or set(legs) != set(request.eliminate):
        return None
    return rest[0], [(v, legs[v]) for v in request.eliminate]


def _constant_lead(f: fmpq_mpoly, names, v: str) -> bool:
    i = names.index(v)
    d = f.degrees()[i]
    return all(sum(e) == d for e, _ in f.terms() if e[i] == d)


def norm_chain(g: fmpq_mpoly, legs: list[tuple[str, fmpq_mpoly]]) -> fmpq_mpoly:
    """A polynomial with the zero set of ``Res_vn(… Res_v1(g, f_1) …, f_n)`` (FLINT).

    When each f_i is monic-like in its v_i (constant leading coefficient), that chain is
    the norm of g over the legs: g multiplied over every common complex root, so it
    vanishes exactly on the projection.  Computed one irreducible factor of g at a time,
    reduced to its squarefree part after each step (the next resultant vanishes exactly
    where the previous one has a root of the next leg, so the zero set is kept), which
    keeps factored inputs (stacked stages) small.
    """
    names = g.context().names()
    _, factors = g.factor()
    total = g.context().from_dict({(0,) * g.context().nvars(): 1})
    for factor, _mult in factors:
        acc = factor
        for v, f in legs:
            if acc.degrees()[names.index(v)] == 0:
                continue  # a leg that does not touch this factor only raises its power
            acc = squarefree_part(acc.resultant(f, v))
        total *= acc
    return squarefree_part(total)
