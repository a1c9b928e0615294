"""Robots with angles: a planar 5-bar RR-RRR (revolute actuators) and a planar 3-RPR with
pose (x, y, φ), certified end to end and checked against the test's own 50-digit mpmath
evaluation: closed-form IK per working mode, det A along the path, its sign changes
refined with a bracketing root finder.  Never against singcheck's own numbers."""

from __future__ import annotations

import mpmath
import pytest

from singcheck.api import check, robot_from_spec
from singcheck.errors import BackendError, UnsupportedRobotError
from singcheck.spec.files import parse_robot, parse_trajectory

mpmath.mp.dps = 50
PI = mpmath.pi

FIVE_BAR = """\
name: fivebar
joints: [th1, th2]
pose: [x, y]
parameters: {l1: 1, l2: 2, e: 1}
constraints:
  - (x + e - l1*cos(th1))^2 + (y - l1*sin(th1))^2 - l2^2
  - (x - e - l1*cos(th2))^2 + (y - l1*sin(th2))^2 - l2^2
"""
CIRCLE = """\
name: circle
parameter: t
range: [0, 2*pi]
pose:
  x: 1/2*cos(t)
  y: 2 + 1/2*sin(t)
"""


def _robot(text, backend="flint"):
    return robot_from_spec(parse_robot(text, "robot.yaml"), backend, cache=False)


def _report(robot, text):
    return check(robot, parse_trajectory(text, "path.yaml", robot.spec))


# ---------------------------------------------------------------------------------
# the test's own model of the 5-bar (l1 = 1, l2 = 2, bases at (∓1, 0))

def _five_bar_pose(t):
    return mpmath.cos(t) / 2, 2 + mpmath.sin(t) / 2


def _five_bar_ik(t):
    """Both elbow angles of each leg: atan2 of the base-to-point vector ± the elbow
    angle from the law of cosines."""
    x, y = _five_bar_pose(t)
    out = []
    for base in (-1, 1):
        dx, dy = x - base, y
        d = mpmath.sqrt(dx * dx + dy * dy)
        beta = mpmath.atan2(dy, dx)
        gamma = mpmath.acos((d * d + 1 - 4) / (2 * d))
        out.append((beta + gamma, beta - gamma))
    return out


def _five_bar_det(t, th1, th2):
    """det ∂F/∂(x, y) = 4·(P - E1) × (P - E2), E the elbows: zero when the distal links
    are aligned."""
    x, y = _five_bar_pose(t)
    u = (x - (-1 + mpmath.cos(th1)), y - mpmath.sin(th1))
    v = (x - (1 + mpmath.cos(th2)), y - mpmath.sin(th2))
    return 4 * (u[0] * v[1] - u[1] * v[0])


def _same_angle(a, b) -> bool:
    return abs(mpmath.sin((a - b) / 2)) < mpmath.mpf(10) ** -30


def _sign_changes(f, lo, hi, n=1500, touching=False):
    """Roots of f on [lo, hi] where it changes sign on a grid, refined at 50 digits;
    with ``touching``, also the double roots: sign changes of f' where f vanishes (to
    40 digits) at the refined point."""
    roots = []
    grid = [lo + (hi - lo) * k / n for k in range(n + 1)]
    values = [f(t) for t in grid]
    for k in range(n):
        a, b, fa, fb = grid[k], grid[k + 1], values[k], values[k + 1]
        if fa == 0:
            roots.append(a)
        elif fa * fb < 0:
            roots.append(mpmath.findroot(f, (a, b), solver="anderson"))
    if touching:
        def df(t):
            return mpmath.diff(f, t)

        for a, b in zip(grid, grid[1:], strict=False):
            if df(a) * df(b) < 0:
                t = mpmath.findroot(df, (a, b), solver="anderson")
                if abs(f(t)) < mpmath.mpf(10) ** -40 and \
                        all(abs(t - r) > 1e-20 for r in roots):
                    roots.append(t)
    return sorted(roots)


def _mode_branch_map(report, ik, t0):
    """Our branch label per leg → the index of the mpmath branch with the same angle."""
    mapping = []
    for leg_index, joint in enumerate(("th1", "th2")):
        labels = {}
        for mode in report.working_modes:
            label = mode.label[leg_index]
            value = mpmath.mpf(mode.joints_at_start[joint])
            matches = [i for i, ref in enumerate(ik(t0)[leg_index])
                       if abs(mpmath.sin((value - ref) / 2)) < 1e-12]
            assert len(matches) == 1, (joint, label, value)
            labels[label] = matches[0]
        assert sorted(labels.values()) == [0, 1]
        mapping.append(labels)
    return mapping


def test_five_bar_ik_and_singular_times_match_an_independent_evaluation():
    robot = _robot(FIVE_BAR)
    report = _report(robot, CIRCLE)
    mapping = _mode_branch_map(report, _five_bar_ik, mpmath.mpf(0))
    # every mode is feasible: each leg's elbow triangle stays non-degenerate (checked here)
    for t in [2 * PI * k / 200 for k in range(201)]:
        for branches in _five_bar_ik(t):
            assert abs(mpmath.sin((branches[0] - branches[1]) / 2)) > 0.05
    assert all(m.feasible for m in report.working_modes)
    expected_any = False
    for mode in report.working_modes:
        i1, i2 = (mapping[k][mode.label[k]] for k in range(2))

        def det(t, i1=i1, i2=i2):
            ik = _five_bar_ik(t)
            return _five_bar_det(t, ik[0][i1], ik[1][i2])

        expected = _sign_changes(det, mpmath.mpf(0), 2 * PI, n=400, touching=True)
        expected_any |= bool(expected)
        got = [c.t for c in mode.singular_times]
        assert len(got) == len(expected), (mode.label, got, expected)
        for ball, root in zip(got, expected, strict=True):
            assert abs(mpmath.mpf(ball.mid().str(30, radius=False)) - root) < 1e-8
            assert float(ball.rad()) < 1e-8
    assert expected_any and report.verdict == "singular"
    # the pose is algebraic in cos/sin of the angles: ξ was eliminated, not sampled
    assert robot.projection.method.startswith("FLINT")


def test_five_bar_limits_in_radians_and_a_branch_through_pi():
    """Limits [-pi/2, pi] on th2: a branch that reaches θ = π leaves them exactly there
    (no half-angle tangent: θ = π is an ordinary point); the test finds that time from
    its own IK."""
    robot = _robot(FIVE_BAR + "joint_limits: {th2: [-pi/2, pi]}\n")
    report = _report(robot, CIRCLE)
    mapping = _mode_branch_map(report, _five_bar_ik, mpmath.mpf(0))
    for mode in report.working_modes:
        i2 = mapping[1][mode.label[1]]

        def angle(t, i2=i2):
            return _five_bar_ik(t)[1][i2]

        # inside [-π/2, π] modulo 2π: cos(θ - π/4) > cos(3π/4)
        def margin(t, angle=angle):
            return mpmath.cos(angle(t) - PI / 4) - mpmath.cos(3 * PI / 4)

        leaves = _sign_changes(margin, mpmath.mpf(0), 2 * PI)
        starts_inside = margin(mpmath.mpf(0)) > 0
        branch = mode.branches[1]
        if starts_inside and not leaves:
            assert mode.feasible, mode.label
        else:
            assert not mode.feasible, mode.label
            if starts_inside:
                assert branch.event_time is not None
                assert abs(mpmath.mpf(branch.event_time.mid().str(30, radius=False))
                           - leaves[0]) < 1e-8
    assert any(not m.feasible for m in report.working_modes)
    assert any(m.feasible for m in report.working_modes)


# ---------------------------------------------------------------------------------
# 3-RPR with an orientation angle and an exact √3 (cos(φ + 2π/3))

RPR = """\
name: rpr
joints: [r1, r2, r3]
pose: [x, y, phi]
constraints:
  - r1^2 - (x + cos(phi))^2 - (y + sin(phi))^2
  - r2^2 - (x + cos(phi + pi/2) - 4)^2 - (y + sin(phi + pi/2))^2
  - r3^2 - (x + cos(phi + 2*pi/3) - 1)^2 - (y + sin(phi + 2*pi/3) - 3)^2
joint_limits: {r1: [0, 10], r2: [0, 10], r3: [0, 10]}
"""
ROTATING = """\
name: rotating
parameter: t
range: [0, 2*pi]
pose:
  x: 2 + 1/5*cos(t)
  y: 1 + 1/5*sin(t)
  phi: t
"""
BASES = ((0, 0), (4, 0), (1, 3))
OFFSETS = (0, PI / 2, 2 * PI / 3)


def _rpr_det(t):
    """det ∂F/∂(x, y, φ), F_i = ρ_i² - |P_i - B_i|², at 50 digits."""
    x, y, phi = 2 + mpmath.cos(t) / 5, 1 + mpmath.sin(t) / 5, t
    rows = []
    for (bx, by), a in zip(BASES, OFFSETS, strict=True):
        c, s = mpmath.cos(phi + a), mpmath.sin(phi + a)
        dx, dy = x + c - bx, y + s - by
        rows.append([-2 * dx, -2 * dy, -2 * (dx * -s + dy * c)])
    return mpmath.det(mpmath.matrix(rows))


def test_three_rpr_det_a_is_xi_and_its_roots_are_the_singular_times():
    robot = _robot(RPR)
    assert robot.model.joint_free_det_A and robot.projection.backend == "none"
    report = _report(robot, ROTATING)
    feasible = [m for m in report.working_modes if m.feasible]
    assert [m.label for m in feasible] == ["+++"]  # ρ = +|P - B| inside [0, 10]
    for joint, (bx, by), a in zip(("r1", "r2", "r3"), BASES, OFFSETS, strict=True):
        expected = mpmath.sqrt((2 + mpmath.cos(0 + a) + mpmath.mpf(1) / 5 - bx) ** 2 +
                               (1 + mpmath.sin(a) - by) ** 2)
        assert abs(feasible[0].joints_at_start[joint] - expected) < 1e-12
    expected = _sign_changes(_rpr_det, mpmath.mpf(0), 2 * PI)
    assert expected
    got = [c.t for c in report.candidates if c.status == "real"]
    assert len(got) == len(expected)
    for ball, root in zip(got, expected, strict=True):
        assert abs(mpmath.mpf(ball.mid().str(30, radius=False)) - root) < 1e-8
    # the other candidates are roots of the conjugate robot's det A (√3 ↦ -√3) only
    assert all(c.status == "spurious" for c in report.candidates if c.status != "real")
    assert report.verdict == "singular"


def test_three_rpr_at_a_fixed_regular_orientation_is_free():
    robot = _robot(RPR)
    fixed = ROTATING.replace("phi: t", "phi: pi/3").replace("1/5", "1/10")
    report = _report(robot, fixed)
    x = [2 + mpmath.cos(2 * PI * k / 400) / 10 for k in range(401)]
    assert x  # the test's check: det A keeps one sign along the fixed-orientation circle
    values = []
    for k in range(401):
        t = 2 * PI * k / 400
        xx, yy, phi = 2 + mpmath.cos(t) / 10, 1 + mpmath.sin(t) / 10, PI / 3
        rows = []
        for (bx, by), a in zip(BASES, OFFSETS, strict=True):
            c, s = mpmath.cos(phi + a), mpmath.sin(phi + a)
            dx, dy = xx + c - bx, yy + s - by
            rows.append([dx, dy, dx * -s + dy * c])
        values.append(mpmath.det(mpmath.matrix(rows)))
    assert all(v > 0 for v in values) or all(v < 0 for v in values)
    assert report.verdict == "singularity-free", report.reason


# ---------------------------------------------------------------------------------
# outside the class, and backends


@pytest.mark.parametrize("constraint, phrase", [
    ("(x - cos(th1) - cos(th2))^2 + y^2 - 4", "joints th1, th2"),
    ("(x + e - l1*cos(2*th1))^2 + (y - l1*sin(th1))^2 - l2^2", "degree > 2 in tan(th1/2)"),
])
def test_robots_outside_the_class_get_one_line_with_a_reformulation(constraint, phrase):
    text = FIVE_BAR.replace("(x + e - l1*cos(th1))^2 + (y - l1*sin(th1))^2 - l2^2", constraint)
    with pytest.raises(UnsupportedRobotError) as err:
        _robot(text)
    message = str(err.value)
    assert "\n" not in message and phrase in message and "reformulate" in message


def test_sympy_says_it_cannot_eliminate_a_revolute_joint_and_who_can():
    with pytest.raises(BackendError) as err:
        _robot(FIVE_BAR, backend="sympy")
    assert "\n" not in str(err.value) and "flint" in str(err.value)


@pytest.mark.parametrize("backend", ["singular", "macaulay2"])
def test_external_backends_agree_with_flint_on_the_five_bar(backend):
    assert _robot(FIVE_BAR, backend).singularity_surface == \
        _robot(FIVE_BAR).singularity_surface


def test_project_writes_the_revolute_branches_the_test_computes():
    """`project`'s cos θ = (-a·d ± b·√Δ)/W, sin θ = (-b·d ∓ a·√Δ)/W along the circle give
    the test's own elbow angles."""
    from flint import arb

    from singcheck.algebra.intervals import working_precision
    from singcheck.algebra.radicals import evaluate_path
    from singcheck.certify.path import build_path
    from singcheck.report.formulas import joint_formula

    robot = _robot(FIVE_BAR)
    path = build_path(robot.projection, parse_trajectory(CIRCLE, "path.yaml", robot.spec))
    for t in (mpmath.mpf(1) / 3, mpmath.mpf(2)):
        for i in range(2):
            f = joint_formula(path, i)
            with working_precision(200):
                a, b, d, delta = (mpmath.mpf(evaluate_path(p, arb(str(t))).mid().str(
                    50, radius=False)) for p in (f.a, f.b, f.d, f.delta))
            w = a * a + b * b
            angles = {mpmath.atan2((-b * d - sigma * a * mpmath.sqrt(delta)) / w,
                                   (-a * d + sigma * b * mpmath.sqrt(delta)) / w)
                      for sigma in (1, -1)}
            for ref in _five_bar_ik(t)[i]:
                assert any(abs(mpmath.sin((ref - x) / 2)) < 1e-30 for x in angles)


def test_an_angle_path_that_is_not_k_t_is_certified_by_branch_and_bound():
    """phi: t^2 makes the path non-algebraic in sin t, cos t: μ mixes t with cos(t²),
    sin(t²) and its roots come from interval branch-and-bound (never sampling); the test
    finds det A's sign changes itself."""
    robot = _robot(RPR)
    text = ROTATING.replace("phi: t", "phi: t^2").replace("[0, 2*pi]", "[0, 2]")
    report = _report(robot, text)
    assert report.certificate.root_method == "interval branch-and-bound"

    def det(t):
        x, y, phi = 2 + mpmath.cos(t) / 5, 1 + mpmath.sin(t) / 5, t * t
        rows = []
        for (bx, by), a in zip(BASES, OFFSETS, strict=True):
            c, s = mpmath.cos(phi + a), mpmath.sin(phi + a)
            dx, dy = x + c - bx, y + s - by
            rows.append([dx, dy, dx * -s + dy * c])
        return mpmath.det(mpmath.matrix(rows))

    expected = _sign_changes(det, mpmath.mpf(0), mpmath.mpf(2))
    got = [c.t for c in report.candidates if c.status == "real"]
    assert expected and len(got) == len(expected)
    for ball, root in zip(got, expected, strict=True):
        assert abs(mpmath.mpf(ball.mid().str(30, radius=False)) - root) < 1e-8
    assert not report.certificate.undecided


ORIENTED = """\
name: oriented
joints: [r1, r2]
pose: [y, phi]
constraints:
  - (cos(phi) - r1)^2 + (y + sin(phi))^2 - 4
  - (cos(phi + pi) - r2)^2 + (y + sin(phi + pi) - 1)^2 - 4
"""


@pytest.mark.parametrize("backend", ["singular", "macaulay2", "sympy"])
def test_backends_agree_on_a_robot_with_orientation(backend):
    """A pose angle (cos φ, sin φ kept, not eliminated) with prismatic legs whose det A
    involves the joints: every backend eliminates the same ξ."""
    assert _robot(ORIENTED, backend).singularity_surface == \
        _robot(ORIENTED).singularity_surface
