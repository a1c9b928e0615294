"""Two engines, one verdict (issue 26): the exact engine's answer is held against the
interval engine's enclosures of det A along each feasible mode, and a disagreement is
the verdict ``error`` (``error.kind`` ``inconsistent``), never a silent answer.

The disagreements are made by breaking one engine on purpose (monkeypatching its
result), since two correct engines never disagree; the interval engine's own findings
are checked against 50-digit mpmath values of det A along the Orthoglide's branches."""

from __future__ import annotations

import itertools

import mpmath as mp
import pytest

from singcheck import api
from singcheck.certify import classification, interval_engine
from singcheck.certify.interval_engine import search_det_a
from singcheck.roots.enclosures import RootIsolation
from tests import robot_oracles as oracles
from tests.conftest import ROBOTS, ROOT, TRAJECTORIES
from tests.test_robots import _agrees, robots  # noqa: F401 (the fixture)


@pytest.fixture(scope="module")
def orthoglide():
    return api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False)


def _check(robot, name):
    return api.check(robot, api.load_trajectory(TRAJECTORIES / f"{name}.yaml", robot),
                     regions=False)


def _det_a_plus(t) -> mp.mpf:
    """det A of the Orthoglide's +++ mode on heart 1 at t, at 50 digits, from the
    geometry: ρᵢ = Xᵢ + √(4 - |X|² + Xᵢ²), rows X - ρᵢ·eᵢ."""
    mp.mp.dps = 50
    x = 8 * mp.sin(t) ** 3 / 7
    y = 13 * mp.cos(t) / 14 - 5 * mp.cos(2 * t) / 14 - mp.cos(3 * t) / 10 - mp.cos(4 * t) / 14
    z = mp.mpf(1)
    X = [x, y, z]
    rows = []
    for i in range(3):
        rho = X[i] + mp.sqrt(4 - sum(v * v for j, v in enumerate(X) if j != i))
        rows.append([X[j] - (rho if j == i else 0) for j in range(3)])
    return mp.det(mp.matrix(rows))


_X8 = [(571, 700), (-3, 20), (-67, 140), (3, 100), (-1, 10), (-1, 100), (-1, 25), (9, 50)]
_Y8 = [(1397, 1400), (-323, 1400), (-9, 50), (17, 100), (-1, 10), (7, 100), (1, 5), (1, 20)]


def _heart_8h(t) -> tuple[list, mp.mpf]:
    """The pose of bench/paths/heart-8h.yaml at t and det A of the Orthoglide's +++ mode
    there, at 50 digits, from the geometry (as :func:`_det_a_plus`)."""
    mp.mp.dps = 50
    x = sum(mp.mpf(a) / b * mp.sin(k * t) for k, (a, b) in enumerate(_X8, 1))
    y = sum(mp.mpf(a) / b * mp.cos(k * t) for k, (a, b) in enumerate(_Y8, 1))
    X = [x, y, mp.mpf(1)]
    rows = []
    for i in range(3):
        rho = X[i] + mp.sqrt(4 - sum(v * v for j, v in enumerate(X) if j != i))
        rows.append([X[j] - (rho if j == i else 0) for j in range(3)])
    return X, mp.det(mp.matrix(rows))


def test_the_mode_program_encloses_pose_and_det_a_on_wide_and_narrow_balls(orthoglide):
    """The compiled walk of the interval engine (:mod:`singcheck.certify.mode_programs`:
    the pose in its Fourier form on a wide ball, Horner's in cos t on a narrow one) holds
    the 8-harmonic heart's pose and det A along +++ at 50 digits across each ball, and
    its balls are the general walk's or narrower."""
    from flint import arb

    from singcheck.algebra.trig import evaluate_trig
    from singcheck.certify import mode_programs
    from singcheck.certify.path import build_path

    spec = api.load_trajectory(ROOT / "bench" / "paths" / "heart-8h.yaml", orthoglide)
    path = build_path(orthoglide.projection, spec, "auto")
    program = mode_programs.mode_program(path)
    assert program is not None and program.harmonics == list(range(1, 9))
    report = api.check(orthoglide, spec, regions=False)
    modes = [m for m in report.working_modes if m.feasible]
    assert [m.label for m in modes] == ["+++"]
    fourier = 0
    for lo, hi in [(-3.0, -2.9), (-0.4, -0.1), (0.5, 0.52), (1.0, 1.0 + 1e-6), (2.5, 2.8)]:
        piece = arb(lo).union(arb(hi))
        pose, _, values = program(path, piece, modes)
        walk_pose, _ = path._pose_and_variables(piece)  # the general walk's pose
        if piece.rad() > mode_programs.FOURIER_WIDE:  # narrower than Horner's in cos t
            fourier += pose[0].rad() < evaluate_trig(path.trig_coordinates[0], piece).rad()
        for k in range(7):
            t = mp.mpf(lo) + (mp.mpf(hi) - mp.mpf(lo)) * k / 6
            X, d = _heart_8h(t)
            assert all(ball.contains(arb(str(v))) for ball, v in zip(pose, X, strict=True))
            assert values["+++"].contains(arb(str(8 * d)))
        for ours, theirs in zip(pose, walk_pose, strict=True):
            assert ours.rad() <= theirs.rad() * (1 + 1e-12)
    assert fourier >= 3


def test_the_interval_engine_proves_heart_1_crossings_where_det_a_changes_sign(orthoglide):
    report = _check(orthoglide, "heart1")
    search = search_det_a(report.path, [m for m in report.working_modes if m.feasible])
    crossings = search["+++"].crossings
    assert len(crossings) == 2
    for w in crossings:  # the oracle: det A at 50 digits has opposite signs at the ends
        assert mp.sign(_det_a_plus(mp.mpf(w.lo))) * mp.sign(_det_a_plus(mp.mpf(w.hi))) < 0
    for lo, hi, s in search["+++"].proven[::7]:  # a proven sign is the true sign
        assert mp.sign(_det_a_plus((mp.mpf(lo) + mp.mpf(hi)) / 2)) == s


def test_agreeing_engines_are_reported_confirmed(orthoglide):
    free, singular = _check(orthoglide, "heart2"), _check(orthoglide, "heart1")
    assert free.verdict == "singularity-free" and singular.verdict == "singular"
    for report in (free, singular):
        doc = report.to_dict()
        assert doc["corroboration"]["engine"] == "interval"
        assert doc["corroboration"]["status"] == "confirmed"
        assert "error" not in doc


def test_an_exact_engine_that_misses_the_roots_is_caught(orthoglide, monkeypatch):
    """μ's isolation made to find nothing (what μ = 1 did on the 6-RUS): the exact engine
    alone would say free; the intervals prove det A changes sign along +++."""
    monkeypatch.setattr(classification, "isolate_real_roots",
                        lambda *a, **k: RootIsolation((), (), "broken on purpose"))
    report = _check(orthoglide, "heart1")
    doc = report.to_dict()
    assert report.verdict == "error"
    assert doc["error"]["kind"] == "inconsistent"
    assert "exact engine: singularity-free" in doc["reason"]
    assert "changes sign along mode +++" in doc["reason"]
    assert doc["corroboration"]["status"] == "inconsistent"


def test_a_singular_time_where_det_a_is_proven_nonzero_is_caught(orthoglide, monkeypatch):
    """The classification made to call every mode singular at every root: at heart 1's
    negative roots +++ is proven regular by the intervals."""
    real = classification.classify_candidate

    def everything_singular(path, modes, root, tolerance, by_elimination=True):
        c = real(path, modes, root, tolerance, by_elimination)
        c.modes = [classification.ModeAtCandidate(m.mode, classification.SINGULAR, "broken")
                   for m in c.modes]
        return c

    monkeypatch.setattr(classification, "classify_candidate", everything_singular)
    doc = _check(orthoglide, "heart1").to_dict()
    assert doc["verdict"] == "error" and doc["error"]["kind"] == "inconsistent"
    assert "ball arithmetic proves det A ≠ 0 there" in doc["reason"]


def test_a_free_verdict_the_intervals_cannot_confirm_is_unknown(orthoglide, monkeypatch):
    """No refinement at all (a budget of nothing): the first cover of heart 2 does not
    prove det A ≠ 0 everywhere, so the exact engine's `free` stands alone: unknown,
    with the window and its bound."""
    monkeypatch.setattr(interval_engine, "BUDGET", 0)
    monkeypatch.setattr(classification, "first_pass_budget", lambda path, modes: 0)
    monkeypatch.setattr(interval_engine, "pieces", lambda interval, count=6: [
        interval.start.ball().union(interval.end.ball())])
    report = _check(orthoglide, "heart2")
    assert report.verdict == "unknown"
    assert "could not confirm det A ≠ 0 in mode +++" in report.reason
    assert "|det A| ≤" in report.reason


@pytest.mark.parametrize("name", sorted(p.name for p in oracles.PATHS))
def test_the_interval_engine_alone_agrees_with_the_independent_oracle(name, robots):  # noqa: F811
    """Each bundled robot path that has a 50-digit oracle (tests/robot_oracles.py),
    certified with ``engine="interval"`` (no μ at all): the same verdict, feasible modes
    and singular times as the oracle's."""
    path = {p.name: p for p in oracles.PATHS}[name]
    truth = oracles.solve(path)
    oracle = path.oracle()
    robot = robots(oracle.robot)
    traj = api.load_trajectory(TRAJECTORIES / f"{name}.yaml", robot)
    report = api.check(robot, traj, regions=False, engine="interval")
    assert report.path.mu is None
    assert report.to_dict()["corroboration"]["status"] == "exact engine not run"
    _agrees(report, oracle, truth)


def test_auto_answers_a_path_the_exact_engine_refuses(robots, tmp_path):  # noqa: F811
    """3-PRR with φ = 30t: the exact engine refuses (μ's half-angle degree over its
    bound); ``auto`` still answers, without μ: infeasible, and the oracle agrees (at
    t = 1/10, 50 digits, no working mode has every leg real and inside its limits)."""
    from singcheck.errors import SpecError

    robot = robots("3-prr")
    f = tmp_path / "spin.yaml"
    f.write_text("name: spin\nparameter: t\nrange: [0, 1]\n"
                 "pose: {x: 3/2 + sin(t)/2, y: 2 - cos(t)/2, phi: 30*t}\n")
    traj = api.load_trajectory(f, robot)
    with pytest.raises(SpecError):
        api.check(robot, traj, regions=False, engine="exact")
    report = api.check(robot, traj, regions=False)
    assert report.path.mu is None  # not needed: no mode is feasible
    assert report.verdict == "infeasible"
    oracle = oracles.three_prr()
    t = mp.mpf(1) / 10
    X = [mp.mpf(3) / 2 + mp.sin(t) / 2, 2 - mp.cos(t) / 2, 30 * t]
    for mode in itertools.product((0, 1), repeat=3):
        q = oracle.joints(mode, X)
        assert q is None or any(not (leg.lo <= v <= leg.hi)
                                for leg, v in zip(oracle.legs, q, strict=True))


def _oracle_det(oracle, start: list, pose, t, steps: int = 2000):
    """det A at t along the mode whose joints at t = 0 are ``start``: each leg's branch
    followed from 0 to t in small steps (the nearest of the two closed-form roots)."""
    q = [mp.mpf(v) for v in start]
    for k in range(1, steps + 1):
        X = pose(t * k / steps)
        q = [min(leg.branches(X), key=lambda v, old=old: abs(v - old))
             for leg, old in zip(oracle.legs, q, strict=True)]
    return oracle.det_A(q, pose(t))


def test_the_mean_value_form_encloses_det_a_on_every_piece(orthoglide):
    """On pieces of heart 1 (wide and narrow), the mean-value enclosure of det A along
    +++ holds det A = 8·det(X - ρᵢ·eᵢ) at 50 digits at points across the piece, and is
    narrower than the plain enclosure on narrow pieces."""
    from flint import arb

    from singcheck.certify.interval_engine import mean_value, mode_values

    report = _check(orthoglide, "heart1")
    modes = [m for m in report.working_modes if m.feasible]
    narrower = 0
    for lo, hi in [(-3.0, -2.0), (0.5, 0.6), (0.97, 0.98), (1.5, 1.5001), (2.0, 2.00001)]:
        piece = arb(lo).union(arb(hi))
        _, joints, plain = mode_values(report.path, modes, piece)
        enclosure = (mean_value(report.path, modes, piece, joints).get("+++") or (None,))[0]
        if enclosure is None:  # not formed (a branch not enclosed as real on the piece)
            assert hi - lo > 0.5
            continue
        for k in range(5):
            t = mp.mpf(lo) + (mp.mpf(hi) - mp.mpf(lo)) * k / 4
            assert enclosure.contains(arb(str(8 * _det_a_plus(t))))
        narrower += enclosure.rad() < plain["+++"].rad()
    assert narrower >= 3


def _model_det_at(model, joints: list, X: list) -> mp.mpf:
    """det A of the robot model (its exact polynomial) at 50 digits: the joints' values
    (a revolute joint's angle, substituted as its cos and sin) and the pose's (an
    angle's likewise), each variable by its name."""
    values = {}
    for leg, q in zip(model.legs, joints, strict=True):
        if leg.kind == "revolute":
            values[f"cos({leg.joint})"], values[f"sin({leg.joint})"] = mp.cos(q), mp.sin(q)
        else:
            values[leg.joint] = q
    for v, x in zip(model.pose, X, strict=True):
        values[v], values[f"cos({v})"], values[f"sin({v})"] = x, mp.cos(x), mp.sin(x)
    names = model.context.names()
    total = mp.mpf(0)
    for exps, c in model.det_A.terms():
        term = mp.mpf(int(c.p)) / int(c.q)
        for name, e in zip(names, exps, strict=True):
            if e:
                term *= values[name] ** int(e)
        total += term
    return total


@pytest.mark.parametrize("name", ["five-bar-cross", "3-rpr-cross", "3-prr-cross"])
def test_the_mean_value_form_and_its_slope_enclose_det_a_and_its_rate(name, robots):  # noqa: F811
    """On pieces of a revolute robot's path and of two pose-angle robots' paths, the
    mean-value enclosure of det A along the feasible mode holds det A, and its slope holds
    d/dt det A, both at 50 digits at points across the piece: det A is the model's own
    polynomial evaluated in mpmath at the oracle's inverse kinematics (each leg's branch:
    the closed-form root nearest the engine's ball at the piece's middle), its rate a
    central difference with h = 10⁻²⁰.  (The slopes use the closed-form branch rates,
    ρ' = (−b' + σD'/(2√D))/(2a) and θ' = −(∇ₓf·X')/(σ√Δ).)"""
    from flint import arb

    from singcheck.certify.interval_engine import mean_value, mode_values

    path = {p.name: p for p in oracles.PATHS}[name]
    oracle = path.oracle()
    robot = robots(oracle.robot)
    report = api.check(robot, api.load_trajectory(TRAJECTORIES / f"{name}.yaml", robot),
                       regions=False)
    modes = [m for m in report.working_modes if m.feasible]
    model = robot.projection.model
    assert modes
    checked = 0
    for lo, hi in [(0.1, 0.2), (0.4, 0.45), (0.7, 0.7001)]:
        piece = arb(lo).union(arb(hi))
        _, joints, _ = mode_values(report.path, modes, piece)
        forms = mean_value(report.path, modes, piece, joints)
        mid = (mp.mpf(lo) + mp.mpf(hi)) / 2
        _, at_mid, _ = mode_values(report.path, modes, arb(str(mid)))
        for mode in modes:
            if mode.label not in forms:
                continue
            value, slope = forms[mode.label]
            picks = []  # which closed-form root each leg's branch is
            for leg, ours in zip(oracle.legs, at_mid[mode.label], strict=True):
                both = leg.branches(path.pose(mid))
                ball = ours[0] if isinstance(ours, tuple) else ours
                target = float(ball.mid())
                picks.append(min((0, 1), key=lambda k, both=both, target=target: abs(
                    (mp.cos(both[k]) if leg.revolute else both[k]) - target)))

            def det_at(t, picks=picks):
                X = path.pose(t)
                q = [leg.branches(X)[k] for leg, k in zip(oracle.legs, picks, strict=True)]
                return _model_det_at(model, q, X)

            h = mp.mpf(10) ** -20
            for k in range(5):
                t = mp.mpf(lo) + (mp.mpf(hi) - mp.mpf(lo)) * k / 4
                assert value.contains(arb(mp.nstr(det_at(t), 40)))
                rate = (det_at(t + h) - det_at(t - h)) / (2 * h)
                assert slope.contains(arb(mp.nstr(rate, 30))), (mode.label, lo, t)
            checked += 1
    assert checked >= 3
