"""The content-addressed elimination cache."""

from __future__ import annotations

import json
import threading

import pytest

from singcheck.elimination.cache import CachedBackend, EliminationCache
from singcheck.elimination.cas import get_backend
from tests.test_cas import XI


class CountingBackend:
    """The SymPy backend, counting the eliminations it really performs."""

    def __init__(self) -> None:
        self.inner = get_backend("sympy")
        self.name = self.inner.name
        self.calls = 0

    def version(self) -> str:
        return self.inner.version()

    def eliminate(self, request):
        self.calls += 1
        return self.inner.eliminate(request)


@pytest.fixture
def cache(tmp_path):
    return EliminationCache(tmp_path / "cache")


def test_a_warm_cache_does_no_backend_call_and_returns_the_same_result(cache):
    backend = CountingBackend()
    first = CachedBackend(backend, cache).eliminate(XI)
    second = CachedBackend(backend, EliminationCache(cache.directory)).eliminate(XI)
    assert backend.calls == 1
    assert second.polynomials == first.polynomials
    assert second.method == first.method and second.backend == "sympy"
    assert len(cache.entries()) == 1


def test_the_key_depends_on_script_backend_and_version(cache):
    k = cache.key("script", "singular", "4.3.1")
    assert k != cache.key("script ", "singular", "4.3.1")
    assert k != cache.key("script", "macaulay2", "4.3.1")
    assert k != cache.key("script", "singular", "4.3.2")


@pytest.mark.parametrize("damage", ["truncate", "tamper", "garbage", "wrong key"])
def test_a_corrupted_entry_is_detected_and_recomputed(cache, damage):
    backend = CountingBackend()
    good = CachedBackend(backend, cache).eliminate(XI)
    (path,) = cache.entries()
    text = path.read_text()
    if damage == "truncate":
        path.write_text(text[: len(text) // 2])
    elif damage == "tamper":
        entry = json.loads(text)
        entry["payload"]["polynomials"][0] = "v4-1"
        path.write_text(json.dumps(entry))
    elif damage == "garbage":
        path.write_bytes(b"\x00\xff not json")
    else:
        entry = json.loads(text)
        entry["key"] = "0" * 64
        path.write_text(json.dumps(entry))
    fresh = EliminationCache(cache.directory)
    again = CachedBackend(backend, fresh).eliminate(XI)
    assert backend.calls == 2
    assert fresh.stats.corrupted == 1
    assert again.polynomials == good.polynomials
    # and the entry was rewritten whole
    assert CachedBackend(backend, EliminationCache(cache.directory)).eliminate(XI)
    assert backend.calls == 2


def test_concurrent_writers_leave_one_whole_entry(cache):
    backend = CountingBackend()
    errors = []

    def work():
        try:
            CachedBackend(backend, EliminationCache(cache.directory)).eliminate(XI)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    (path,) = cache.entries()
    assert json.loads(path.read_text())["payload"]["backend"] == "sympy"
    assert not list(cache.directory.glob("*/.*.tmp"))  # no temporary file left behind


def test_clear_removes_every_entry(cache):
    CachedBackend(CountingBackend(), cache).eliminate(XI)
    assert cache.clear() == 1
    assert cache.entries() == []
