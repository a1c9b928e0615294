"""The bench's certified contender (interval branch-and-bound on det A along each feasible
mode, bench/contender.py), checked against det A computed independently with 50-digit
mpmath along the paths."""

from __future__ import annotations

import sys
from pathlib import Path

import mpmath

from singcheck.model.robot import build_model
from singcheck.spec.files import load_robot, load_trajectory

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from contender import contender  # noqa: E402

mpmath.mp.dps = 50


def _heart_det_a(t, sx, cy):
    """det A of the Orthoglide (legs of length 2, mode +++) along the heart
    x = sx·sin³t, y = Σ cy[k]·cos((k+1)t), z = 1, in mpmath: ρᵢ = Xᵢ + √(4 - the other
    two coordinates squared); A = ∂F/∂X."""
    x = sx * mpmath.sin(t) ** 3
    y = sum(c * mpmath.cos((k + 1) * t) for k, c in enumerate(cy))
    z = mpmath.mpf(1)
    r1 = x + mpmath.sqrt(4 - y**2 - z**2)
    r2 = y + mpmath.sqrt(4 - x**2 - z**2)
    r3 = z + mpmath.sqrt(4 - x**2 - y**2)
    return mpmath.det(mpmath.matrix([[2 * (x - r1), 2 * y, 2 * z],
                                     [2 * x, 2 * (y - r2), 2 * z],
                                     [2 * x, 2 * y, 2 * (z - r3)]]))


def _q(a, b):
    return mpmath.mpf(a) / b


HEART1 = (_q(8, 7), [_q(13, 14), _q(-5, 14), _q(-1, 10), _q(-1, 14)])
HEART2 = (_q(4, 5), [_q(13, 20), _q(-1, 4), _q(-1, 20), _q(-1, 20)])


def _orthoglide_det_a(t):
    return _heart_det_a(t, *HEART1)


def _sign_changes(f, a, b, n=400):
    ts = [a + (b - a) * mpmath.mpf(i) / n for i in range(n + 1)]
    roots = []
    for lo, hi in zip(ts, ts[1:], strict=False):
        if f(lo) * f(hi) < 0:
            roots.append(mpmath.findroot(f, (lo, hi), solver="anderson"))
    return roots


def _load(robot: str, trajectory: str):
    model = build_model(load_robot(ROOT / "robots" / f"{robot}.yaml"))
    return model, load_trajectory(ROOT / "trajectories" / f"{trajectory}.yaml", model.spec)


def test_contender_finds_heart1_singularities_where_mpmath_does():
    model, spec = _load("orthoglide", "heart1")
    answer = contender(model, spec)
    assert answer.verdict == "singular"
    assert answer.feasible == ["+++"]
    expected = _sign_changes(_orthoglide_det_a, -mpmath.pi, mpmath.pi)
    found = sorted(answer.singular_times["+++"], key=lambda b: b.mid())
    assert len(found) == len(expected) == 2
    for ball, root in zip(found, expected, strict=True):
        lo = mpmath.mpf(ball.lower().str(40, radius=False))
        hi = mpmath.mpf(ball.upper().str(40, radius=False))
        assert lo - mpmath.mpf(10) ** -30 <= root <= hi + mpmath.mpf(10) ** -30
        assert hi - lo <= 1e-9


def test_contender_says_unknown_at_a_graze_and_free_on_heart2():
    # the biglide's path touches y = 0 (det A = 4y(q - p)) without crossing it: no sign
    # change to prove, so branch-and-bound cannot decide; heart 2 never meets det A = 0
    model, spec = _load("biglide", "biglide-graze")
    assert contender(model, spec).verdict == "unknown"
    model, spec = _load("orthoglide", "heart2")
    answer = contender(model, spec)
    assert answer.verdict == "singularity-free" and answer.feasible == ["+++"]
    assert all(_orthoglide_sign(t) for t in (mpmath.mpf(i) / 10 for i in range(-31, 32)))


def _orthoglide_sign(t) -> bool:
    """det A along heart 2 (mode +++) is far from 0 at t: a smoke check of the free path."""
    return abs(_heart_det_a(t, *HEART2)) > mpmath.mpf(10) ** -3


def test_the_round_robin_varies_each_rounds_order_reproducibly(monkeypatch):
    """bench.interleaved: every contender runs once per round and its times stay its
    own; the rounds' orders vary (no contender always follows the same one) and are the
    same from run to run; BENCH_FIXED_ORDER keeps the listed order."""
    import bench

    def rounds(repeat=40):
        calls = []
        fns = [lambda k=k: calls.append(k) for k in range(5)]
        times = bench.interleaved(fns, repeat)
        assert [len(ts) for ts in times] == [repeat] * 5
        return [tuple(calls[i:i + 5]) for i in range(0, len(calls), 5)]

    orders = rounds()
    assert all(sorted(o) == [0, 1, 2, 3, 4] for o in orders)
    assert orders == rounds() and len(set(orders)) > 10
    after = {(o[i], o[i + 1]) for o in orders for i in range(4)}
    assert all((a, 3) in after for a in (0, 1, 4))  # 3 follows others than 2
    monkeypatch.setattr(bench, "FIXED_ORDER", True)
    assert set(rounds(3)) == {(0, 1, 2, 3, 4)}
