"""Elimination backends: the adapters between the pure core and a computer-algebra engine.

A backend answers :class:`~singcheck.elimination.EliminationRequest`s.  Each adapter
lives in its own module; the core never imports one directly, it asks
:func:`get_backend` by name.  ``auto`` picks Singular when present, else Macaulay2,
else the in-process SymPy backend; a backend asked for by name and missing is an error
with an install hint, never a silent fallback.
"""

from __future__ import annotations

from dataclasses import dataclass

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
                return get_backend(candidate, timeout=timeout)
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
