"""Zero is not "no factor": every step from F to μ keeps a polynomial that vanishes
everywhere as zero (issue 26).

A 6-RUS hexapod at its home pose lay on its singularity in 44 of its 64 working modes,
yet was proven free: the path-wise elimination's intermediate norm was identically zero
(the constant path is on ξ = 0) and FLINT's squarefree factorization of 0 is the empty
product, so μ became 1.  These tests hold each normalising step to the zero polynomial,
and whole paths lying on the singularity to an exact oracle written here (rational
inverse kinematics and det A in ``fractions.Fraction``)."""

from __future__ import annotations

import itertools
from fractions import Fraction as Q

import mpmath as mp
import pytest
from flint import fmpq, fmpq_mpoly_ctx

from singcheck import api
from singcheck.algebra.polynomials import squarefree_part
from singcheck.elimination.projection import _without_degenerate_factors
from singcheck.elimination.requests import _split_free, norm_chain, revolute_norm
from tests.conftest import ROBOTS

RING = fmpq_mpoly_ctx.get(("r", "cr", "sr", "t", "s", "c"), "lex")
r, cr, sr, t, s, c = RING.gens()
ZERO = RING.from_dict({})


def test_the_squarefree_part_of_zero_is_zero():
    assert squarefree_part(ZERO).is_zero()
    assert squarefree_part(4 * (t - 1) ** 2 * (s + 1)) == (t - 1) * (s + 1)


def test_splitting_zero_keeps_it_whole():
    keep, free = _split_free(ZERO, {0})
    assert keep.is_zero() and free == 1


def test_dropping_degenerate_factors_of_zero_leaves_zero():
    assert _without_degenerate_factors(ZERO, (t ** 2 + 1,)).is_zero()
    assert _without_degenerate_factors(ZERO, ()).is_zero()


def test_the_norm_of_zero_is_zero():
    assert norm_chain(ZERO, [("r", r ** 2 - t)]).is_zero()


def test_a_chain_step_that_vanishes_identically_makes_the_norm_zero():
    """det A = r - 1/2 on a leg r² - 1/4 = 0 (a constant pose): Res_r = 1/4 - 1/4 = 0.  The
    mode r = 1/2 is singular all along; the other (r = -1/2) is not."""
    assert norm_chain(r - fmpq(1, 2), [("r", r ** 2 - fmpq(1, 4))]).is_zero()
    # and the same with a later leg still to come, whose step must not turn 0 into 1
    g = (r - fmpq(1, 2)) * (cr + 2)
    assert norm_chain(g, [("r", r ** 2 - fmpq(1, 4)), (("cr", "sr"), cr + sr - 1)]).is_zero()


def test_a_revolute_norm_that_vanishes_identically_stays_zero():
    """g = cos θ on the leg cos θ = 0 (θ = ±π/2): g is zero on both branches."""
    assert revolute_norm(cr, "cr", "sr", cr).is_zero()
    assert norm_chain(cr * (t + 3), [(("cr", "sr"), cr)]).is_zero()


def test_a_non_zero_norm_is_unchanged():
    """The explicit zero cases leave ordinary norms alone: Res_r(r - t, r² - 1) = t² - 1."""
    assert norm_chain(r - t, [("r", r ** 2 - 1)]) == t ** 2 - 1


# -- whole paths on the singularity, against an exact oracle -----------------------------

#: A pose of the Orthoglide (legs of length 2) whose inverse kinematics is rational:
#: 4 - y² - z², 4 - x² - z², 4 - x² - y² are squares of rationals (1444 = 38²).
POSE = (Q(2, 19), Q(12, 19), Q(36, 19))


def _isqrt(q: Q) -> Q:
    from math import isqrt

    a, b = isqrt(q.numerator), isqrt(q.denominator)
    assert a * a == q.numerator and b * b == q.denominator
    return Q(a, b)


def _det3(m) -> Q:
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def orthoglide_singular_modes(pose) -> tuple[set[str], set[str]]:
    """(modes inside [0, 4]ᶟ, those singular there), exactly: ρᵢ = Xᵢ ± √(4 - |X|² + Xᵢ²),
    A's rows the leg vectors X - ρᵢ·eᵢ (up to the factor 2 of the gradient)."""
    x = list(pose)
    w = [_isqrt(4 - sum(v * v for j, v in enumerate(x) if j != i)) for i in range(3)]
    inside, singular = set(), set()
    for signs in itertools.product("+-", repeat=3):
        rho = [x[i] + (w[i] if signs[i] == "+" else -w[i]) for i in range(3)]
        if not all(0 <= v <= 4 for v in rho):
            continue
        label = "".join(signs)
        inside.add(label)
        rows = [[x[j] - (rho[i] if j == i else 0) for j in range(3)] for i in range(3)]
        if _det3(rows) == 0:
            singular.add(label)
    return inside, singular


def _constant_path(tmp_path, pose, name="on-surface"):
    x, y, z = pose
    f = tmp_path / f"{name}.yaml"
    f.write_text(f"name: {name}\nparameter: t\nrange: [0, 1]\n"
                 f"pose: {{x: {x}, y: {y}, z: {z}}}\n")
    return f


def test_the_oracle_pose_is_singular_in_some_modes_only():
    inside, singular = orthoglide_singular_modes(POSE)
    assert singular and inside - singular


@pytest.mark.parametrize("max_surface_terms", [None, 0], ids=["xi-expanded", "path-wise"])
def test_a_constant_path_on_the_singularity_is_singular_in_exactly_those_modes(
        tmp_path, max_surface_terms):
    """Both ways of computing μ (ξ(φ(t)) and the path-wise chain) give μ ≡ 0 here; the
    verdict is `singular`, and the modes reported singular all along are the oracle's."""
    kwargs = {} if max_surface_terms is None else {"max_surface_terms": max_surface_terms}
    robot = api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False, **kwargs)
    report = api.check(robot, api.load_trajectory(_constant_path(tmp_path, POSE), robot),
                       regions=False)
    inside, singular = orthoglide_singular_modes(POSE)
    assert report.verdict == "singular"
    feasible = {m.label for m in report.working_modes if m.feasible}
    assert feasible == inside
    found = {label for c in report.candidates for label in c.singular_modes}
    assert found == singular
    regular = {m.label for m in report.working_modes if m.feasible and not m.singular_times}
    assert regular == inside - singular


def test_a_constant_path_off_the_singularity_is_free(tmp_path):
    """A nearby rational pose where no mode is singular (oracle): free, both ways."""
    pose = (Q(1, 2), Q(1, 2), Q(1, 2))
    for kwargs in ({}, {"max_surface_terms": 0}):
        robot = api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False,
                               **kwargs)
        report = api.check(robot, api.load_trajectory(_constant_path(tmp_path, pose), robot),
                           regions=False)
        assert report.verdict == "singularity-free"


def test_a_whole_range_singularity_is_reported_on_surface_in_json_and_table(tmp_path):
    """The modes singular all along carry on_surface: [t0, t1] (JSON, working modes and
    candidates) and the table says "all of [t0, t1]"; the others carry null."""
    import io

    from rich.console import Console

    from singcheck.report.trajectory import render_tables, robot_json

    robot = api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False)
    report = api.check(robot, api.load_trajectory(_constant_path(tmp_path, POSE), robot),
                       regions=False)
    doc = report.to_dict()
    _, singular = orthoglide_singular_modes(POSE)
    on = {m["label"]: m["on_surface"] for m in doc["working_modes"]}
    assert {label for label, v in on.items() if v} == singular
    assert all(on[label] == [0.0, 1.0] for label in singular)
    assert all(c["on_surface"] == [0.0, 1.0] for c in doc["candidates"])
    out = io.StringIO()
    render_tables(Console(file=out, width=200), robot_json(robot.projection), [doc])
    assert "all of [0, 1] (det A ≡ 0)" in out.getvalue()
    assert "singular along the whole path" in out.getvalue()


# -- degenerate inverse kinematics: a leg that does not fix its joint, a joint at π ---------


def test_a_leg_whose_ik_degenerates_is_never_proven_free(tmp_path):
    """The five-bar's end effector on its base joint A1 = (-1, 0) with l1 = l2 = 2: leg 1
    reads 4cos²θ + 4sin²θ - 4 = 0, true for every θ (a = b = d = 0, W = 0), so its
    branches are not separated anywhere (exactly: the oracle's discriminant is 0).  The
    answer must not be `singularity-free` in any engine; it is infeasible (serial
    singularity), and so is a line leaving that pose."""
    for k in range(7):  # leg 1 at P = A1 holds for every θ: no branch is singled out
        theta = mp.mpf(k)
        with mp.workdps(50):
            assert abs((-1 + 1 - 2 * mp.cos(theta)) ** 2 + (2 * mp.sin(theta)) ** 2 - 4) \
                < mp.mpf(10) ** -45
    robot = api.load_robot(ROBOTS / "five-bar.yaml", backend="flint", cache=False)
    still = tmp_path / "still.yaml"
    still.write_text("name: still\nparameter: t\nrange: [0, 1]\npose: {x: -1, y: 0}\n")
    leaving = tmp_path / "leaving.yaml"
    leaving.write_text("name: leaving\nparameter: t\nrange: [0, 1]\n"
                       "pose: {x: -1 + t/10, y: t/10}\n")
    for f in (still, leaving):
        for engine in ("auto", "exact", "interval"):
            report = api.check(robot, api.load_trajectory(f, robot), regions=False,
                               engine=engine)
            assert report.verdict == "infeasible", (f.name, engine, report.reason)
            assert "th1" in report.reason


def test_a_constant_pose_with_a_joint_at_pi_agrees_with_the_oracle(tmp_path):
    """P = (-7/5, 6/5): |P - A1 - 2·(cos π, sin π)| = |(8/5, 6/5)| = 2, so one branch of
    θ1 is π exactly, on its closed upper limit.  The verdict and the feasible modes'
    joints at the start agree with the 50-digit oracle (θ1 shown as π, not 0 or -π)."""
    from tests import robot_oracles as oracles

    oracle = oracles.five_bar()
    X = [mp.mpf(-7) / 5, mp.mpf(6) / 5]
    truth = {}
    for mode in itertools.product((0, 1), repeat=2):
        q = oracle.joints(mode, X)
        if q is None or not all(leg.lo - mp.mpf(10) ** -30 <= v <= leg.hi + mp.mpf(10) ** -30
                                for leg, v in zip(oracle.legs, q, strict=True)):
            continue
        truth[tuple(float(v) for v in q)] = oracle.det_A(q, X)
    assert any(abs(q[0] - float(mp.pi)) < 1e-12 for q in truth)  # the θ1 = π branch
    robot = api.load_robot(ROBOTS / "five-bar.yaml", backend="flint", cache=False)
    f = tmp_path / "pi.yaml"
    f.write_text("name: pi\nparameter: t\nrange: [0, 1]\npose: {x: -7/5, y: 6/5}\n")
    report = api.check(robot, api.load_trajectory(f, robot), regions=False)
    feasible = [m for m in report.working_modes if m.feasible]
    shown = sorted(tuple(m.joints_at_start[j] for j in ("th1", "th2")) for m in feasible)
    assert len(shown) == len(truth)
    for ours, expected in zip(shown, sorted(truth), strict=True):
        assert ours == pytest.approx(expected, abs=1e-9)
    singular = any(abs(v) < mp.mpf(10) ** -30 for v in truth.values())
    assert report.verdict == ("singular" if singular else "singularity-free")


def _branch_points(a, b, d):
    """The two points of a·cos + b·sin + d = 0 on the unit circle (50-digit mpmath)."""
    w = a * a + b * b
    root = mp.sqrt(w - d * d)
    return [((-a * d + sigma * b * root) / w, (-b * d - sigma * a * root) / w)
            for sigma in (1, -1)]


@pytest.mark.parametrize("seed", range(12))
def test_a_path_norm_taken_on_the_legs_circle_is_the_norm(seed):
    """Along a path (``reduce`` given) a revolute norm first takes g modulo its leg's
    circle cos² + sin² - 1: the same values at the leg's two points, so the same norm up
    to a power of W = a² + b² (the degree it is homogenised to may drop).  Checked against
    the norm without that step, exactly, and against the product of g at the two points
    (mpmath, 50 digits) at rational times."""
    import random

    rng = random.Random(seed)
    mp.mp.dps = 50

    def rand(scale=3):
        return fmpq(rng.randint(-scale, scale), rng.randint(1, 3))

    g = sum((rand() * t ** rng.randint(0, 2) * cr ** i * sr ** j
             for i in range(4) for j in range(4 - i) if rng.random() < 0.6), ZERO)
    g += cr ** 2 * sr ** 2 * (t + 1)  # degree 4 in (cos, sin), always
    a, b, d = ZERO + rand() + t / 2, ZERO + rand() + 1, ZERO + rand(1) * t
    f = a * cr + b * sr + d
    reduced = revolute_norm(g, "cr", "sr", f, reduce=lambda p: p)
    plain = revolute_norm(g, "cr", "sr", f)
    w = a * a + b * b
    power = 0
    while reduced * w ** power != plain and power < 10:
        power += 1
    assert reduced * w ** power == plain, "not the same norm up to a power of W"
    k = max(int(e[1] + e[2]) for e in divmod(g, cr ** 2 + sr ** 2 - 1)[1].monoms())
    for t0 in (fmpq(1, 3), fmpq(-2, 7), fmpq(5, 4)):
        av, bv, dv = (_at(x, t0) for x in (a, b, d))
        if av * av + bv * bv <= dv * dv:
            continue  # the leg has no real point there: the norm's value is not a product
        value = mp.mpf(1)
        for cv, sv in _branch_points(av, bv, dv):
            value *= _at(g, t0, cv, sv)
        scale = (av * av + bv * bv) ** (2 * k)
        assert abs(_at(reduced, t0) - scale * value) <= mp.mpf(10) ** -30 * (1 + abs(scale * value))


def _at(p, t0, cv=0, sv=0):
    """p(cr = cv, sr = sv, t = t0) at 50 digits (r, s, c absent)."""
    return sum(mp.mpf(int(q.p)) / int(q.q) * mp.mpf(cv) ** int(e[1]) * mp.mpf(sv) ** int(e[2])
               * (mp.mpf(int(t0.p)) / int(t0.q)) ** int(e[3])
               for e, q in zip(p.monoms(), p.coeffs(), strict=True))


def test_a_function_zero_on_the_legs_circle_has_norm_zero():
    """g = (cos² + sin² - 1)·(t + 1) vanishes at both points of any leg: its norm along a
    path is 0 (the whole range singular), with or without the reduction."""
    g = (cr ** 2 + sr ** 2 - 1) * (t + 1)
    assert revolute_norm(g, "cr", "sr", cr + 2 * sr - t, reduce=lambda p: p).is_zero()
    assert revolute_norm(g, "cr", "sr", cr + 2 * sr - t).is_zero()
