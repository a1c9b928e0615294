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


def test_blocks_time_a_contenders_runs_in_a_row_and_its_first_run_apart():
    """bench.in_blocks: each sample is a block of BLOCK runs of one contender in a row;
    the block's first run is reported as cold, the mean of the others as warm (here a
    contender whose first run of every block burns ten times the CPU of the others)."""
    import time

    import bench

    calls: list[int] = []

    def burn(seconds: float) -> None:
        end = time.process_time() + seconds
        while time.process_time() < end:
            pass

    def contender(k: int) -> None:
        first = calls.count(k) % 4 == 0  # (the first of each of its blocks of 4)
        calls.append(k)
        burn(0.02 if first else 0.002)

    warm, cold = bench.in_blocks([lambda: contender(0), lambda: contender(1)], 3, 4)
    blocks = [tuple(calls[i:i + 4]) for i in range(0, len(calls), 4)]
    assert len(blocks) == 6 and all(len(set(b)) == 1 for b in blocks)
    for k in (0, 1):
        assert len(warm[k]) == len(cold[k]) == 3
        assert all(c > 5 * w for (_, c), (_, w) in zip(cold[k], warm[k], strict=True))
        assert all(0.0015 < w < 0.01 for _, w in warm[k])


def _contains(ball, root) -> bool:
    lo = mpmath.mpf(ball.lower().str(40, radius=False))
    hi = mpmath.mpf(ball.upper().str(40, radius=False))
    return lo - mpmath.mpf(10) ** -30 <= root <= hi + mpmath.mpf(10) ** -30 and hi - lo <= 1e-9


def _elbow(ax, px, py, left: bool):
    """The 5-bar's elbow B on a leg from A = (ax, 0) (links of length 2 and 2) to the end
    effector P: one of the two intersections of the circles of radius 2 about A and P,
    the one further left (or right), and its joint angle atan2(By, Bx - ax)."""
    dx, dy = px - ax, py
    dist = mpmath.sqrt(dx**2 + dy**2)
    h = mpmath.sqrt(4 - (dist / 2) ** 2)
    mx, my = (ax + px) / 2, py / 2
    nx, ny = -dy / dist, dx / dist
    b = sorted([(mx + h * nx, my + h * ny), (mx - h * nx, my - h * ny)])
    bx, by = b[0] if left else b[1]
    return bx, by, mpmath.atan2(by, bx - ax)


def _five_bar_det_a(px, py):
    """det A / 4 of the 5-bar (d = 1, l1 = l2 = 2; robots/five-bar.yaml) at P in the mode
    of its limits, elbow 1 out to the left, elbow 2 to the right: det(P - B1, P - B2),
    each row ∂/∂(x, y) of |P - Bᵢ|² / 2."""
    b1x, b1y, th1 = _elbow(-1, px, py, left=True)
    b2x, b2y, th2 = _elbow(1, px, py, left=False)
    assert mpmath.pi / 3 < th1 < mpmath.pi and 0 < th2 < 2 * mpmath.pi / 3
    return (px - b1x) * (py - b2y) - (py - b1y) * (px - b2x)


def _three_rpr_det_a(x, y, phi):
    """det A of the 3-RPR (robots/3-rpr.yaml): rows ∂/∂(x, y, phi) of each leg's squared
    length; no joint in it (every mode has the same det A)."""
    c, s = mpmath.cos(phi), mpmath.sin(phi)
    u, v = x + c - 5, y + s
    p, q = x - s - 1, y + c - 4
    return mpmath.det(mpmath.matrix([[2 * x, 2 * y, 0],
                                     [2 * u, 2 * v, 2 * (-u * s + v * c)],
                                     [2 * p, 2 * q, 2 * (-p * c - q * s)]]))


def test_contender_on_the_five_bar_matches_mpmath():
    # five-bar-cross: x = 0, y = 3 - 2t on [0, 1]; five-bar-free: x = -1 + 2t, y = 5/2
    model, spec = _load("five-bar", "five-bar-cross")
    answer = contender(model, spec)
    assert answer.verdict == "singular" and answer.feasible == ["+-"]
    expected = _sign_changes(lambda t: _five_bar_det_a(mpmath.mpf(0), 3 - 2 * t), 0, 1)
    (found,) = answer.singular_times["+-"]
    assert len(expected) == 1 and _contains(found, expected[0])
    assert abs(expected[0] - (3 - mpmath.sqrt(3)) / 2) < mpmath.mpf(10) ** -40
    model, spec = _load("five-bar", "five-bar-free")
    answer = contender(model, spec)
    assert answer.verdict == "singularity-free" and answer.feasible == ["+-"]
    assert not _sign_changes(lambda t: _five_bar_det_a(-1 + 2 * t, mpmath.mpf(5) / 2), 0, 1)


def test_contender_on_the_three_rpr_matches_mpmath():
    # 3-rpr-cross: (2 + cos t, 2 + sin t, t); 3-rpr-free: (3 - cos t, 1/2 + sin t, t);
    # each leg -r² + |…|²: its branch '-' is r = +√|…|², the one within [1/2, 5]
    model, spec = _load("3-rpr", "3-rpr-cross")
    answer = contender(model, spec)
    assert answer.verdict == "singular" and answer.feasible == ["---"]
    expected = _sign_changes(
        lambda t: _three_rpr_det_a(2 + mpmath.cos(t), 2 + mpmath.sin(t), t), 0, 1)
    (found,) = answer.singular_times["---"]
    assert len(expected) == 1 and _contains(found, expected[0])
    model, spec = _load("3-rpr", "3-rpr-free")
    answer = contender(model, spec)
    assert answer.verdict == "singularity-free" and answer.feasible == ["---"]
    assert not _sign_changes(
        lambda t: _three_rpr_det_a(3 - mpmath.cos(t), mpmath.mpf(1) / 2 + mpmath.sin(t), t),
        0, 1)


def test_contender_slopes_match_mpmath_derivatives():
    # F'(t) from the chain rule through the revolute branches' θ' (5-bar) and the pose
    # angle's cos φ, sin φ (3-RPR) against mpmath's numerical derivative of det A along
    # the path; the model's det A is the test's up to a constant factor k
    from contender import BranchAndBound
    from flint import arb

    cases = (("five-bar", "five-bar-cross", "+-",
              lambda t: _five_bar_det_a(mpmath.mpf(0), 3 - 2 * t)),
             ("3-rpr", "3-rpr-cross", "---",
              lambda t: _three_rpr_det_a(2 + mpmath.cos(t), 2 + mpmath.sin(t), t)))
    for robot, trajectory, mode, f in cases:
        model, spec = _load(robot, trajectory)
        bb = BranchAndBound(model, spec)
        for t in (mpmath.mpf(3) / 10, mpmath.mpf(7) / 10):
            value, slope = bb.det_a(arb(str(t)), mode, True)
            k = float(value.mid()) / float(f(t))
            assert abs(float(slope.mid()) - k * float(mpmath.diff(f, t))) < 1e-9 * (
                1 + abs(float(slope.mid())))


def test_contender_proves_leaving_the_workspace_infeasible():
    # x = 3 sin t, y = 0, z = 1 on [0, π/2]: leg 2's ρ₂ = y ± √(4 - x² - z²) has its
    # branches meet at x = √3 (t = asin(1/√3)) and is complex after it; the box where
    # they meet stays undecided, the later ones prove the leg infeasible
    t = mpmath.mpf(3) / 2
    assert 4 - (3 * mpmath.sin(t)) ** 2 - 1 < 0
    model, spec = _load("orthoglide", "leaves-workspace")
    answer = contender(model, spec)
    assert answer.verdict == "infeasible" and answer.feasible == []
