"""Elimination backends: the adapters between the pure core and a computer-algebra engine.

A backend answers :class:`~singcheck.elimination.EliminationRequest`s.  Each adapter
lives in its own module; the core never imports one directly, it asks
:func:`get_backend` by name.  ``auto`` picks Singular when present, else Macaulay2,
else the in-process SymPy backend; a request the picked CAS does not finish within
:data:`AUTO_CAS_SECONDS` goes to the in-process flint backend (:class:`AutoBackend`).
A backend asked for by name and missing is an error with an install hint, never a
silent fallback, and one asked for by name has the whole ``--timeout``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from singcheck.elimination.requests import EliminationBackend
from singcheck.errors import BackendError

BACKEND_NAMES = ("singular", "macaulay2", "sympy", "flint")


@dataclass(frozen=True)
class BackendInfo:
    name: str
    found: bool
    path: str | None
    version: str | None
    tested: str
    note: str


def _external(name: str):
    from singcheck.elimination.cas.external import MACAULAY2, SINGULAR

    return {"singular": SINGULAR, "macaulay2": MACAULAY2}[name]


def get_backend(name: str = "auto", *, timeout: float | None = None) -> EliminationBackend:
    """The backend called ``name`` (``auto``: Singular, else Macaulay2, else SymPy), each
    elimination bounded by ``timeout`` seconds (600) and the memory bound (the CAS
    processes as the forked children of the in-process backends: :mod:`.isolated`)."""
    if name == "auto":
        for candidate in ("singular", "macaulay2"):
            if _external(candidate).find() is not None:
                return AutoBackend(candidate, timeout)
        return get_backend("sympy", timeout=timeout)
    from singcheck.elimination.cas.external import DEFAULT_TIMEOUT

    if name in ("sympy", "flint"):  # in a forked child, with a time and a memory bound
        from singcheck.elimination.cas.isolated import Isolated

        if name == "sympy":
            from singcheck.elimination.cas.sympy_backend import SympyBackend as InProcess
        else:
            from singcheck.elimination.cas.flint_backend import FlintBackend as InProcess
        return Isolated(InProcess(), timeout or DEFAULT_TIMEOUT)
    if name in ("singular", "macaulay2"):
        from singcheck.elimination.cas.external import ExternalBackend

        return ExternalBackend(_external(name), timeout=timeout or DEFAULT_TIMEOUT)
    raise BackendError(f"unknown backend {name!r}; choose one of: auto, "
                       f"{', '.join(BACKEND_NAMES)}")


#: seconds an external CAS picked by ``auto`` has for one request before the in-process
#: flint backend takes it (the bundled 6-joint stacked Orthoglide: Singular ran past
#: 600 s and the command failed, exit 4; flint projects it in 0.4 s)
AUTO_CAS_SECONDS = 60.0


class AutoBackend:
    """``auto``: the external CAS ``name``, within :data:`AUTO_CAS_SECONDS` (or the
    ``timeout`` if less) per request; a request it does not finish by then goes to the
    in-process flint backend, in a forked child with the whole ``timeout`` (its result
    is re-checked like any other, and says which backend made it).  Named, cached and
    versioned as the CAS."""

    def __init__(self, name: str, timeout: float | None) -> None:
        from singcheck.elimination.cas.external import DEFAULT_TIMEOUT

        self.timeout = timeout or DEFAULT_TIMEOUT
        self.external = get_backend(name, timeout=min(self.timeout, AUTO_CAS_SECONDS))
        self.name = self.external.name
        self._fallback: EliminationBackend | None = None

    def version(self) -> str:
        return self.external.version()

    def cache_identity(self, request) -> str:
        return self.external.cache_identity(request)

    def script(self, request) -> str:
        return self.external.script(request)

    def eliminate(self, request):
        from singcheck.elimination.cas.process import BackendTimeout

        try:
            return self.external.eliminate(request)
        except BackendTimeout:
            if self.external.timeout >= self.timeout:
                raise
        if self._fallback is None:
            self._fallback = get_backend("flint", timeout=self.timeout)
        result = self._fallback.eliminate(request)
        return replace(result, method=f"{result.method}; {self.name} did not finish within "
                       f"{self.external.timeout:g} s (auto)")


def describe_backends() -> list[BackendInfo]:
    """Each backend, found or not, with its path and version (for ``singcheck backends``)."""
    import sympy

    from singcheck.elimination.cas.external import cas_version

    out = []
    for name in ("singular", "macaulay2"):
        cas = _external(name)
        path = cas.find()
        version, note = None, cas.install_hint if path is None else ""
        if path is not None:
            try:
                version = cas_version(cas, path)
            except BackendError as e:
                note = f"found but not working: {e}"
        out.append(BackendInfo(name, path is not None and not note, path, version,
                               cas.tested_versions, note))
    out.append(BackendInfo("sympy", True, sympy.__file__, sympy.__version__, "1.12 – 1.14",
                           "in-process (resultant chains and Gröbner bases)"))
    import flint

    out.append(BackendInfo("flint", True, flint.__file__, flint.__version__, "0.7 – 0.9",
                           "in-process FLINT resultant chains (fastest; Gröbner via SymPy)"))
    return out
