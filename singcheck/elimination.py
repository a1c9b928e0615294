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


def restrict(p: fmpq_mpoly, ctx: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """``p`` (free of the dropped variables) re-expressed in the smaller context ``ctx``."""
    names = p.context().names()
    keep = [names.index(v) for v in ctx.names()]
    out = {}
    for exps, coeff in p.terms():
        if any(e for i, e in enumerate(exps) if i not in keep):
            raise ValueError(f"{p} still involves an eliminated variable")
        out[tuple(exps[i] for i in keep)] = coeff
    return ctx.from_dict(out)


def squarefree_part(p: fmpq_mpoly) -> fmpq_mpoly:
    """The product of the distinct irreducible factors of ``p``, made monic (exact).

    It has the same zero set as ``p`` and simple factors, so its roots along a path are
    the candidates without multiplicity blow-up.
    """
    _, factors = p.factor_squarefree()
    out = p.context().from_dict({(0,) * p.context().nvars(): 1})
    for f, _mult in factors:
        out *= f
    lc = out.leading_coefficient()
    return out / lc if lc != 0 else out
