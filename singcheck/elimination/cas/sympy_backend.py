"""The in-process backend: SymPy resultants and Gröbner bases, no external program.

Two methods, chosen from the shape of the request:

* **resultant chain** when every eliminated variable v has a *leg* generator that
  involves v and no other eliminated variable, with a constant leading coefficient in
  v, and exactly one generator g is left.  Then ``Res_v(…Res_v1(g, f_v1)…, f_vk)`` is
  the norm of g: the product of g over all (complex) roots of the legs, up to a
  non-zero constant.  It vanishes exactly on the projection (which is closed, the legs
  being integral), so its zero set is the one asked for.  Seconds become milliseconds
  compared with a lex Gröbner basis on the Orthoglide.
* **Gröbner basis** (lex, eliminated variables first) otherwise: its elements free of
  the eliminated variables generate the elimination ideal (the Elimination Theorem).
"""

from __future__ import annotations

from flint import fmpq, fmpq_mpoly

from singcheck.algebra.polynomials import restrict
from singcheck.elimination.requests import (
    EliminationRequest,
    EliminationResult,
    leg_structure,
    slow_backend_refusal,
)
from singcheck.errors import BackendError


def _to_sympy(p: fmpq_mpoly, gens):
    from sympy import QQ, Poly, Rational

    return Poly.from_dict(
        {exps: Rational(int(c.p), int(c.q)) for exps, c in p.terms()}, *gens, domain=QQ)


def _from_sympy(poly, ctx, gens) -> fmpq_mpoly:
    names = [str(g) for g in gens]
    order = [names.index(v) for v in ctx.names()]
    out = {}
    for monom, coeff in poly.terms():
        out[tuple(monom[i] for i in order)] = fmpq(int(coeff.p), int(coeff.q))
    return ctx.from_dict(out)


class SympyBackend:
    name = "sympy"

    def version(self) -> str:
        from importlib.metadata import version

        return version("sympy")  # without importing SymPy (a third of a second)

    def preload(self, request: EliminationRequest) -> None:
        """Import what :meth:`eliminate` needs (before a fork: :mod:`.isolated`)."""
        import sympy  # noqa: F401

    def eliminate(self, request: EliminationRequest) -> EliminationResult:
        from sympy import groebner, symbols

        gens = symbols(request.context.names())
        by_name = dict(zip(request.context.names(), gens, strict=True))
        kept = request.kept_context()
        structure = leg_structure(request)
        pairs = [v for v in request.eliminate if v.startswith("cos(")]
        if pairs:
            raise BackendError(
                f"sympy cannot eliminate the angle {pairs[0][4:-1]} (a revolute joint's cos, "
                "sin pair: its Gröbner basis does not finish); use --backend flint, singular "
                "or macaulay2")
        refusal = slow_backend_refusal(request, "sympy")
        if refusal:
            raise BackendError(refusal)
        if structure is not None:
            g, legs = structure
            acc = _to_sympy(g, gens)
            for v, f in legs:
                first = (by_name[v], *[x for x in gens if x != by_name[v]])
                res = acc.reorder(*first).resultant(_to_sympy(f, gens).reorder(*first))
                acc = _to_sympy_poly(res.as_expr(), gens)
            polys = (restrict(_from_sympy(acc, request.context, gens), kept),)
            method = "resultant chain (norm over the legs)"
        else:
            order = [by_name[v] for v in request.eliminate] + [by_name[v] for v in request.keep]
            basis = groebner([_to_sympy(f, gens).as_expr() for f in request.generators],
                             *order, order="lex")
            eliminated = set(by_name[v] for v in request.eliminate)
            polys = tuple(
                restrict(_from_sympy(_to_sympy_poly(b, gens), request.context, gens), kept)
                for b in basis.exprs if not (b.free_symbols & eliminated))
            method = "lex Gröbner basis"
        return EliminationResult(request, polys, method, self.name)


def _to_sympy_poly(expr, gens):
    from sympy import QQ, Poly

    return Poly(expr, *gens, domain=QQ)
