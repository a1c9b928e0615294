"""A content-addressed on-disk cache of elimination results.

Key: SHA-256 of the request's script (what the backend would run) + backend name +
backend version + :data:`ALGORITHM_VERSION`.  One JSON file per entry, written to a
temporary file in the same directory and renamed into place (atomic, so concurrent runs
never see half an entry).  Each entry carries the SHA-256 of its own payload: a
corrupted or foreign file is detected, ignored and recomputed, never trusted.

Where: ``$SINGCHECK_CACHE_DIR``, else ``$XDG_CACHE_HOME/singcheck``, else
``~/.cache/singcheck``.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path

from singcheck.algebra.polynomials import restrict
from singcheck.atomic import write_atomically
from singcheck.elimination.cas.polytext import (
    PolynomialSyntaxError,
    format_polynomial,
    parse_polynomial,
)
from singcheck.elimination.requests import EliminationRequest, EliminationResult

#: Bump when what is computed for a request changes meaning.
ALGORITHM_VERSION = "1"
FORMAT = "singcheck-elimination-cache/1"


def cache_dir() -> Path:
    if os.environ.get("SINGCHECK_CACHE_DIR"):
        return Path(os.environ["SINGCHECK_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "singcheck"


def request_text(request: EliminationRequest) -> str:
    """A canonical text of the request (variables, generators, eliminated variables)."""
    return "\n".join([
        request.label,
        ",".join(request.context.names()),
        ",".join(request.eliminate),
        *[format_polynomial(g) for g in request.generators],
    ])


def _digest(*parts: str) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part.encode("utf-8"))
        h.update(b"\0")
    return h.hexdigest()


def read_entry(path: Path, fmt: str, key: str) -> dict:
    """The payload of a cache entry written by :func:`write_entry`.

    Raises ``ValueError`` when its format, key or checksum disagree (a damaged or foreign
    file); ``OSError`` (``FileNotFoundError`` for a miss) and JSON errors pass through.
    """
    entry = json.loads(path.read_text(encoding="utf-8"))
    payload = entry["payload"]
    if entry.get("format") != fmt or entry.get("key") != key or \
            entry.get("sha256") != _digest(json.dumps(payload, sort_keys=True)):
        raise ValueError("checksum or key mismatch")
    return payload


def write_entry(path: Path, fmt: str, key: str, payload: dict) -> None:
    """Write a cache entry carrying its payload's checksum, atomically; a cache that
    cannot be written is only slower, never wrong, so write errors are ignored."""
    entry = {"format": fmt, "key": key, "payload": payload,
             "sha256": _digest(json.dumps(payload, sort_keys=True))}
    try:
        write_atomically(path, json.dumps(entry))
    except OSError:
        return


@dataclass
class CacheStats:
    hits: int = 0
    misses: int = 0
    corrupted: int = 0


class EliminationCache:
    def __init__(self, directory: Path | None = None) -> None:
        self.directory = directory or cache_dir()
        self.stats = CacheStats()

    def key(self, script: str, backend: str, version: str) -> str:
        return _digest(script, backend, version, ALGORITHM_VERSION)

    def _path(self, key: str) -> Path:
        return self.directory / key[:2] / f"{key}.json"

    def load(self, key: str, request: EliminationRequest) -> EliminationResult | None:
        try:
            payload = read_entry(self._path(key), FORMAT, key)
            polys = tuple(restrict(parse_polynomial(text, request.context),
                                   request.kept_context())
                          for text in payload["polynomials"])
            result = EliminationResult(request, polys, payload["method"], payload["backend"])
        except FileNotFoundError:
            self.stats.misses += 1
            return None
        except (OSError, ValueError, KeyError, TypeError, PolynomialSyntaxError):
            self.stats.corrupted += 1
            self.stats.misses += 1
            return None
        self.stats.hits += 1
        return result

    def store(self, key: str, result: EliminationResult) -> None:
        ctx = result.request.context
        payload = {
            "label": result.request.label,
            "backend": result.backend,
            "method": result.method,
            # in the request's full ring, so they parse back without ambiguity
            "polynomials": [format_polynomial(_widen(p, ctx)) for p in result.polynomials],
        }
        write_entry(self._path(key), FORMAT, key, payload)

    def entries(self) -> list[Path]:
        if not self.directory.exists():
            return []
        return sorted(self.directory.glob("*/*.json"))

    def clear(self) -> int:
        removed = 0
        for path in self.entries():
            try:
                path.unlink()
                removed += 1
            except OSError:
                pass
        return removed


def _widen(p, ctx):
    """A polynomial of the kept context, re-expressed in the request's full context."""
    names = ctx.names()
    small = p.context().names()
    index = [names.index(v) for v in small]
    out = {}
    for exps, coeff in p.terms():
        full = [0] * len(names)
        for i, e in zip(index, exps, strict=True):
            full[i] = e
        out[tuple(full)] = coeff
    return ctx.from_dict(out)


class CachedBackend:
    """Wraps a backend: answers from the cache when it can, stores what it computes."""

    def __init__(self, backend, cache: EliminationCache) -> None:
        self.backend = backend
        self.cache = cache
        self.name = backend.name

    def version(self) -> str:
        return self.backend.version()

    def _identity(self, request: EliminationRequest) -> str:
        identity = getattr(self.backend, "cache_identity", None)
        return identity(request) if identity else request_text(request)

    def eliminate(self, request: EliminationRequest) -> EliminationResult:
        key = self.cache.key(self._identity(request), self.backend.name, self.backend.version())
        hit = self.cache.load(key, request)
        if hit is not None:
            return hit
        result = self.backend.eliminate(request)
        self.cache.store(key, result)
        return result
