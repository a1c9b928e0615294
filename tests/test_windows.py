"""μ restricted to the interval engine's windows (issue 27, ``--engine auto``).

Where the intervals leave windows (a touch of the singularity: no sign change to prove),
the exact engine takes μ on the whole range within its budget, and past it only on the
windows.  These tests force the second route (a budget of 0 s) on paths of the biglide,
whose det A = 4·y·(q − p) vanishes exactly where y = 0: the oracle is y itself, at 50
digits, written here.  The two routes must give the same singular times."""

from __future__ import annotations

from fractions import Fraction

import mpmath as mp
import pytest

from singcheck import api
from singcheck.algebra.trig import LinearInPi, TimeRange
from singcheck.certify import classification
from singcheck.certify.interval_engine import ModeSearch, Window
from singcheck.certify.windows import window_ranges
from tests.conftest import ROBOTS

#: paths of y ≥ 0 touching y = 0 (x = sin(3t)/5): (y as text, y for mpmath, touches)
TOUCHES = [
    ("1 - cos(t)", lambda t: 1 - mp.cos(t), [0]),
    ("t^2/2", lambda t: t ** 2 / 2, [0]),
    ("sin(t)^2", lambda t: mp.sin(t) ** 2, [0]),
    ("t^2*(2 + sin(5*t))/4", lambda t: t ** 2 * (2 + mp.sin(5 * t)) / 4, [0]),
    ("(1 - cos(2*t))*(1 + t)/4", lambda t: (1 - mp.cos(2 * t)) * (1 + t) / 4, [-1, 0]),
]


@pytest.fixture(scope="module")
def biglide():
    return api.load_robot(ROBOTS / "biglide.yaml", backend="flint")


def _zeros_of(y, touches) -> list:
    """The oracle: y vanishes at each touch (50 digits) and is > 0 at 2,001 points of
    [-1, 1] away from them (y is a sum of squares there: no other zero in between)."""
    mp.mp.dps = 50
    assert all(abs(y(mp.mpf(t))) < mp.mpf(10) ** -45 for t in touches)
    grid = [mp.mpf(-1) + mp.mpf(i) / 1000 for i in range(2001)]
    assert all(y(t) > 0 for t in grid if min(abs(t - z) for z in touches) > mp.mpf(1) / 100)
    return touches


def _check(robot, y: str, tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text(f"name: p\nparameter: t\nrange: [-1, 1]\npose:\n  x: sin(3*t)/5\n"
                    f"  y: {y}\n")
    return api.check(robot, api.load_trajectory(str(path), robot), regions=False).to_dict()


@pytest.mark.parametrize("y, y_mp, touches", TOUCHES, ids=[t[0] for t in TOUCHES])
def test_mu_on_the_windows_alone_finds_the_touches_of_the_oracle(biglide, tmp_path,
                                                                 monkeypatch, y, y_mp,
                                                                 touches):
    zeros = _zeros_of(y_mp, touches)
    whole = _check(biglide, y, tmp_path)
    monkeypatch.setattr(classification, "EXACT_WHOLE_RANGE_SECONDS", 0.0)
    windows = _check(biglide, y, tmp_path)
    assert "window(s) only" not in whole["root_isolation"]
    assert "window(s) only (μ restricted to them" in windows["root_isolation"]
    for doc in (whole, windows):
        assert doc["verdict"] == "singular", doc["reason"]
        assert doc["corroboration"]["status"] in ("consistent", "confirmed")
        found = [c for c in doc["candidates"] if c["singular_modes"]]
        assert len(found) == len(zeros)
        for c, z in zip(found, zeros, strict=True):
            lo, hi = c["t_interval"]
            assert lo <= z <= hi and hi - lo < 1e-6
    assert [c["singular_modes"] for c in whole["candidates"]] == \
        [c["singular_modes"] for c in windows["candidates"]]


def _search(label: str, *windows: tuple[float, float]) -> ModeSearch:
    return ModeSearch(label, [], [Window(lo, hi, 1.0, 1, 1) for lo, hi in windows])


def test_window_ranges_hold_every_window_merged_widened_and_clipped_exactly():
    """Each window is held by an exact range a little wider than its float ends;
    overlapping windows of two modes make one range; a window at a range end keeps the
    range's own end (π here, not a float near it)."""
    pi = LinearInPi(Fraction(0), Fraction(1))
    rng = TimeRange(LinearInPi(Fraction(0)), pi)
    ranges = window_ranges(rng, {"a": _search("a", (0.1, 0.2), (3.0, float(pi))),
                                 "b": _search("b", (0.15, 0.3))})
    assert len(ranges) == 2
    first, last = ranges
    assert first.start.rational < Fraction(0.1) and first.end.rational > Fraction(0.3)
    assert first.end.rational - Fraction(0.3) < Fraction(1, 10 ** 11)
    assert last.start.rational < 3 and last.end is pi
    assert window_ranges(rng, {"a": _search("a")}) == []


def _touch_case(rng):
    """A random biglide path y = a(t − t0)²(1 + b·sin kt) + ε, x = c·sin mt, on a range
    about t0 (a touch at t0 for ε = 0, two crossings for ε < 0, none for ε > 0), and the
    oracle's answer: the verdict and the singular times at 50 digits (None: the path
    comes within 1/100 of the workspace's edge y = 3/2, not this test's question)."""
    t0 = Fraction(rng.randint(-8, 8), rng.choice([2, 3, 4, 5, 7])) / 4
    a = Fraction(rng.randint(1, 3), rng.choice([8, 10, 12]))
    b, c = Fraction(rng.randint(-3, 3), 4), Fraction(rng.randint(-4, 4), 5)
    k, m = rng.randint(1, 6), rng.randint(1, 5)
    eps = rng.choice([Fraction(0), Fraction(0), Fraction(1, 10**8), Fraction(-1, 10**8)])
    lo, hi = Fraction(rng.randint(-6, 0), 4), Fraction(rng.randint(1, 6), 4)
    text = (f"name: p\nparameter: t\nrange: [{lo}, {hi}]\npose:\n  x: ({c})*sin({m}*t)\n"
            f"  y: ({a})*(t - ({t0}))^2*(1 + ({b})*sin({k}*t)) + ({eps})\n")
    mp.mp.dps = 50

    def q(r):
        return mp.mpf(r.numerator) / r.denominator

    def y(t):
        return q(a) * (t - q(t0)) ** 2 * (1 + q(b) * mp.sin(k * t)) + q(eps)

    top = max(abs(y(q(lo) + (q(hi) - q(lo)) * j / 4000)) for j in range(4001))
    if abs(top - mp.mpf(3) / 2) < mp.mpf(1) / 100:
        return text, None
    if top > mp.mpf(3) / 2:  # the shorter leg (3/2) cannot reach: no mode follows the path
        return text, ("infeasible", [])
    if eps > 0:
        return text, ("singularity-free", [])
    if eps == 0:
        return text, (("singular", [t0]) if lo <= t0 <= hi else ("singularity-free", []))
    width = 3 * mp.sqrt(q(-eps / a) / (1 - abs(q(b))))
    zeros = [mp.findroot(y, tuple(sorted((q(t0), q(t0) + side * width))), solver="anderson")
             for side in (-1, 1)]
    zeros = [z for z in zeros if q(lo) <= z <= q(hi)]
    return text, (("singular", zeros) if zeros else ("singularity-free", []))


@pytest.mark.slow
def test_both_routes_agree_with_the_oracle_on_random_touches(biglide, tmp_path, monkeypatch):
    """40 random touches, near misses and double crossings of the biglide's y = 0 (seed
    fixed): the default route and μ on the windows alone give the oracle's verdict and
    singular times (within 1e-6), and the windows route is taken on the touches."""
    import random

    rng = random.Random(20261128)
    taken = 0
    for _ in range(40):
        text, expected = _touch_case(rng)
        if expected is None:
            continue
        path = tmp_path / "p.yaml"
        path.write_text(text)
        for seconds in (classification.EXACT_CORROBORATION_BUDGET, 0.0):
            monkeypatch.setattr(classification, "EXACT_WHOLE_RANGE_SECONDS", seconds)
            doc = api.check(biglide, api.load_trajectory(str(path), biglide),
                            regions=False).to_dict()
            times = sorted(c["t"] for c in doc["candidates"] if c["singular_modes"])
            assert doc["verdict"] == expected[0], (text, doc["reason"])
            assert len(times) == len(expected[1]), (text, times)
            assert all(abs(s - float(z)) < 1e-6 for s, z in zip(times, expected[1],
                                                                   strict=True)), text
            taken += "window(s) only" in doc["root_isolation"]
    assert taken >= 5  # the windows route did run
