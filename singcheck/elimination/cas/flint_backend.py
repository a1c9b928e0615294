"""The fast in-process backend: FLINT resultant chains (``--backend flint``).

For leg-shaped requests (ξ: joints eliminated from {F, det A}) it computes the norm of
det A over the legs with :func:`~singcheck.elimination.norm_chain`, factor by factor,
in C: about a millisecond for the Orthoglide.  Other requests (ε, the pose eliminated)
fall back to the SymPy Gröbner basis.
"""

from __future__ import annotations

from singcheck.algebra.polynomials import restrict
from singcheck.elimination.requests import (
    EliminationRequest,
    EliminationResult,
    leg_structure,
    norm_chain,
    proven_small,
)


class FlintBackend:
    name = "flint"

    def version(self) -> str:
        from importlib.metadata import version

        return version("python-flint")

    def preload(self, request: EliminationRequest) -> None:
        """Import what :meth:`eliminate` needs (before a fork: :mod:`.isolated`)."""
        if leg_structure(request) is None:
            from singcheck.elimination.cas.sympy_backend import SympyBackend

            SympyBackend().preload(request)

    def proven_small(self, request: EliminationRequest, memory_limit: int) -> bool:
        """Whether :class:`~singcheck.elimination.cas.isolated.Isolated` may run
        ``request`` in this process (:func:`~singcheck.elimination.requests.proven_small`)."""
        return proven_small(request, memory_limit)

    def eliminate(self, request: EliminationRequest) -> EliminationResult:
        structure = leg_structure(request)
        if structure is None:
            from singcheck.elimination.cas.sympy_backend import SympyBackend

            result = SympyBackend().eliminate(request)
            return EliminationResult(request, result.polynomials, result.method, self.name)
        g, legs = structure
        poly = restrict(norm_chain(g, legs), request.kept_context())
        return EliminationResult(request, (poly,), "FLINT resultant chain (norm over the legs)",
                                 self.name, is_norm=True)
