"""A content-addressed on-disk cache of elimination results.

Key: SHA-256 of the request's script (what the backend would run) + backend name +
backend version + :data:`ALGORITHM_VERSION`.  One JSON file per entry, written to a
temporary file in the same directory and renamed into place (atomic, so concurrent runs
never see half an entry).  Each entry carries an HMAC-SHA-256 of its payload under a
secret key kept *outside* the cache (``~/.config/singcheck/cache.key``, mode 0600,
created on first use): a corrupted entry, or one written by anyone who cannot read that
key (a shared or restored cache directory), is detected, ignored and recomputed, never
trusted.  Without a readable or creatable key nothing is read from or written to disk.

Where: ``$SINGCHECK_CACHE_DIR``, else ``$XDG_CACHE_HOME/singcheck``, else
``~/.cache/singcheck``.
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
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
from singcheck.errors import BackendError

#: Bump when what is computed for a request changes meaning.
ALGORITHM_VERSION = "1"
FORMAT = "singcheck-elimination-cache/2"


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


def key_file() -> Path:
    """Where the cache's secret key lives: beside the user's configuration, not the cache."""
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"),
                                                             ".config")
    return Path(base) / "singcheck" / "cache.key"


_KEYS: dict[str, bytes | None] = {}


def _secret() -> bytes | None:
    """The cache's secret key (32 random bytes), created 0600 on first use; None when it
    can be neither read nor created (then the cache is not used)."""
    path = key_file()
    if str(path) in _KEYS:
        return _KEYS[str(path)]
    key = None
    for _ in range(2):
        try:
            data = read_bounded(path, 4096).strip()
            if len(data) >= 32:
                key = data
            break
        except FileNotFoundError:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
                with os.fdopen(fd, "wb") as f:
                    f.write(os.urandom(32).hex().encode())
            except FileExistsError:
                continue
            except OSError:
                break
        except (OSError, ValueError):
            break
    _KEYS[str(path)] = key
    return key


def _seal(payload: dict) -> str:
    """The HMAC of a payload under the cache key (raises ValueError without a key)."""
    import hmac

    secret = _secret()
    if secret is None:
        raise ValueError("no cache key")
    return hmac.new(secret, json.dumps(payload, sort_keys=True).encode("utf-8"),
                    hashlib.sha256).hexdigest()


def _digest(*parts: str) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part.encode("utf-8"))
        h.update(b"\0")
    return h.hexdigest()


#: The largest cache entry read (the stacked Orthoglide's ξ is about 2 MB).
MAX_ENTRY_BYTES = 64 * 2**20


def read_bounded(path: Path, limit: int = MAX_ENTRY_BYTES) -> bytes:
    """The bytes of a *regular* file of at most ``limit`` bytes.

    Cache files are untrusted: the last path component is not followed if it is a
    symlink (a link to ``/dev/zero`` is not read forever), the file is opened without
    blocking (a FIFO planted as an entry does not hang the run) and refused unless it is
    a regular file, and no more than ``limit`` bytes are read.  Raises ``OSError``
    (``FileNotFoundError`` for a miss) or ``ValueError``.
    """
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0) | \
        getattr(os, "O_CLOEXEC", 0)
    fd = os.open(path, flags)
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError("not a regular file")
        if st.st_size > limit:
            raise ValueError(f"larger than {limit} bytes")
        data = f.read(limit + 1)
    if len(data) > limit:
        raise ValueError(f"larger than {limit} bytes")
    return data


def read_entry(path: Path, fmt: str, key: str) -> dict:
    """The payload of a cache entry written by :func:`write_entry`.

    Raises ``ValueError`` when the file is not a bounded regular file, is not JSON (or is
    nested too deeply to read), or its format, key or checksum disagree (a damaged or
    foreign file); ``OSError`` (``FileNotFoundError`` for a miss) passes through.
    """
    try:
        entry = json.loads(read_bounded(path).decode("utf-8"))
        if not isinstance(entry, dict) or not isinstance(entry.get("payload"), dict):
            raise ValueError("not a cache entry")
        payload = entry["payload"]
        seal = _seal(payload)
    except RecursionError:
        raise ValueError("nested too deeply") from None
    import hmac

    if entry.get("format") != fmt or entry.get("key") != key or \
            not hmac.compare_digest(str(entry.get("hmac")), seal):
        raise ValueError("checksum or key mismatch")
    return payload


def write_entry(path: Path, fmt: str, key: str, payload: dict) -> None:
    """Write a cache entry carrying its payload's HMAC, atomically; a cache that cannot be
    written is only slower, never wrong, so write errors (and a missing key) are ignored."""
    try:
        entry = {"format": fmt, "key": key, "payload": payload, "hmac": _seal(payload)}
    except ValueError:
        return
    try:
        write_atomically(path, json.dumps(entry), make_parents=True)
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

    def eliminate(self, request: EliminationRequest, check=None) -> EliminationResult:
        """The result for ``request``: from the cache, else from the backend.

        ``check(result)`` (raising :class:`~singcheck.errors.BackendError` on a wrong
        answer) runs on both: a cached entry that fails it is a miss (recomputed and
        replaced), and a computed result is stored only once it has passed, so one wrong
        answer is never cached for the next runs.
        """
        key = self.cache.key(self._identity(request), self.backend.name, self.backend.version())
        hit = self.cache.load(key, request)
        if hit is not None:
            if check is None:
                return hit
            try:
                check(hit)
                return hit
            except BackendError:
                self.cache.stats.hits -= 1
                self.cache.stats.corrupted += 1
                self.cache.stats.misses += 1
        result = self.backend.eliminate(request)
        if check is not None:
            check(result)
        self.cache.store(key, result)
        return result
