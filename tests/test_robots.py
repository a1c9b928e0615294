"""Acceptance tests for the bundled robots of issue 12, each path against an independent
oracle (tests/robot_oracles.py: the robot's geometry written again, closed-form IK per
working mode, det A at 50 digits with mpmath, sign changes refined by bisection), never
against singcheck's own numbers; and each singularity surface against the literature's
closed form where there is one (5-bar: the distal links aligned; 3-RPR: the leg lines
concurrent; Gough–Stewart: the legs' Plücker lines dependent)."""

from __future__ import annotations

import random
from fractions import Fraction

import mpmath as mp
import pytest

from singcheck import api
from tests import robot_oracles as oracles
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_cli import singcheck

PATHS = {p.name: p for p in oracles.PATHS}


@pytest.fixture(scope="module")
def robots():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = api.load_robot(ROBOTS / f"{name}.yaml", backend="flint", cache=False)
        return cache[name]

    return get


def _same_joints(oracle, ours: list, theirs: dict) -> bool:
    for leg, value in zip(oracle.legs, ours, strict=True):
        other = theirs.get(leg.joint)
        if other is None:
            return False
        diff = float(value) - float(other)
        if leg.revolute:
            diff = (diff + float(mp.pi)) % (2 * float(mp.pi)) - float(mp.pi)
        if abs(diff) > 1e-6:
            return False
    return True


def _contains(ball, t, slack=1e-12) -> bool:
    lo, hi = float(ball.mid() - ball.rad()), float(ball.mid() + ball.rad())
    return lo - slack <= float(t) <= hi + slack


@pytest.mark.parametrize("name", sorted(PATHS))
def test_bundled_path_agrees_with_the_independent_oracle(name, robots):
    path = PATHS[name]
    truth = oracles.solve(path)
    assert truth.verdict == ("singular" if path.singular else "singularity-free"), \
        "the path no longer does what it was designed to do"
    oracle = path.oracle()
    robot = robots(oracle.robot)
    traj = api.load_trajectory(TRAJECTORIES / f"{name}.yaml", robot)
    _agrees(api.check(robot, traj, regions=False), oracle, truth)


def _agrees(report, oracle, truth) -> None:
    """The report's verdict, feasible modes and singular times are the oracle's."""
    assert report.verdict == truth.verdict, report.reason
    feasible = [m for m in report.working_modes if m.feasible]
    assert len(feasible) == len(truth.feasible)
    for mode in truth.feasible:  # the same working modes, matched by their joints at t0
        (ours,) = [m for m in feasible if _same_joints(oracle, mode.joints_at_start,
                                                       m.joints_at_start)]
        assert len(ours.singular_times) == len(mode.singular_times)
        for c, t in zip(sorted(ours.singular_times, key=lambda c: float(c.t.mid())),
                        mode.singular_times, strict=True):
            assert _contains(c.t, t), (c.t, t)
    distinct = []  # a time where several modes are singular is one candidate
    for t in truth.singular_times:
        if not distinct or t - distinct[-1] > mp.mpf(10) ** -30:
            distinct.append(t)
    real = [c for c in report.candidates if c.status == "real"]
    assert len(real) == len(distinct)
    for c, t in zip(sorted(real, key=lambda c: float(c.t.mid())), distinct, strict=True):
        assert _contains(c.t, t), (c.t, t)
    assert not [c for c in report.candidates if c.status == "unknown"]


SQRT3_LEAD = """\
name: sqrt3-lead
joints: [p, q]
pose: [x, y]
parameters: {s3: sqrt(3)}
constraints:
  - s3*p^2 - 2*p*x + x^2 + y^2 - 4
  - (x - q)^2 + y^2 - 9/4
joint_limits: {p: [-4, 4], q: [-4, 4]}
"""


def test_a_constant_irrational_leading_coefficient_is_a_leg(tmp_path):
    """√3·p² + …: the coefficient of p² is a constant (from a √3 parameter), not a
    function of the pose, so the leg is accepted (divided by √3) and the path's answer
    is the oracle's, whose IK p = (x ± √(x² - √3(x² + y² - 4)))/√3 and det A = 4y(q - p)
    are written here from the constraints as given."""
    (tmp_path / "robot.yaml").write_text(SQRT3_LEAD)
    (tmp_path / "path.yaml").write_text(
        "name: line\nparameter: t\nrange: [0, 1]\npose: {x: t, y: 1 - 2*t}\n")

    def oracle():
        def p(X):
            return oracles.SQRT3, -2 * X[0], X[0] ** 2 + X[1] ** 2 - 4

        def q(X):
            return 1, -2 * X[0], X[0] ** 2 + X[1] ** 2 - mp.mpf(9) / 4

        legs = (oracles.quadratic_leg("p", p, -4, 4), oracles.quadratic_leg("q", q, -4, 4))
        return oracles.Oracle("sqrt3-lead", ("x", "y"), legs,
                              lambda j, X: 4 * X[1] * (j[1] - j[0]))

    path = oracles.Path("line", oracle, 0, 1, lambda t: [t, 1 - 2 * t], True)
    truth = oracles.solve(path)
    assert len(truth.feasible) == 4 and len(truth.singular_times) == 5  # y = 0, and p = q
    robot = api.load_robot(tmp_path / "robot.yaml", backend="flint", cache=False)
    report = api.check(robot, api.load_trajectory(tmp_path / "path.yaml", robot),
                       regions=False)
    _agrees(report, path.oracle(), truth)


def test_a_real_leading_coefficient_not_proven_nonzero_is_refused_in_one_line(tmp_path):
    """c·p² − k·p² + … with c = k = cos 1: the coefficient of p² is 0, which balls cannot
    prove ≠ 0 (nor = 0): refused, exit 2, naming the file, line and joint, no traceback
    (c² + s² with s = sin 1 is accepted: tests/test_field_inputs.py)."""
    (tmp_path / "robot.yaml").write_text(SQRT3_LEAD.replace(
        "{s3: sqrt(3)}", "{c: cos(1), k: cos(1)}").replace("s3*p^2", "c*p^2 - k*p^2"))
    (tmp_path / "path.yaml").write_text(
        "name: line\nparameter: t\nrange: [0, 1]\npose: {x: t, y: 1 - 2*t}\n")
    out = singcheck("run", str(tmp_path / "robot.yaml"), str(tmp_path / "path.yaml"))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    last = out.stderr.splitlines()[-1]
    assert last.startswith(f"singcheck: error: {tmp_path / 'robot.yaml'}:6:")
    assert "coefficient of p^2" in last and "cannot be proven ≠ 0" in last


def test_designed_crossings_are_where_the_geometry_says():
    """The oracles themselves, against closed forms: the 5-bar path meets y = √3 (the
    distal links aligned: P the midpoint of B1 B2) at t = (3 - √3)/2; the
    Gough–Stewart path is singular at t = π/2 (observed to 40 digits, quoted in the
    README)."""
    (t,) = oracles.solve(PATHS["five-bar-cross"]).singular_times
    assert abs(t - (3 - mp.sqrt(3)) / 2) < mp.mpf(10) ** -40
    (t,) = oracles.solve(PATHS["gough-stewart-rotate"]).singular_times
    assert abs(t - mp.pi / 2) < mp.mpf(10) ** -40


# --- closed forms from the literature ----------------------------------------------------

def _circle_point(m: Fraction) -> tuple[Fraction, Fraction]:
    """(cos, sin) of a rational point on the unit circle: ((1 - m²), 2m) / (1 + m²)."""
    return (1 - m * m) / (1 + m * m), 2 * m / (1 + m * m)


def _value(poly, point: dict) -> Fraction:
    """An fmpq_mpoly at a rational point given by variable name, exactly."""
    from flint import fmpq

    args = [fmpq(point[n].numerator, point[n].denominator) for n in poly.context().names()]
    v = poly(*args)
    return Fraction(int(v.p), int(v.q))


def _angle_point(name: str, m: Fraction) -> dict:
    c, s = _circle_point(m)
    return {f"cos({name})": c, f"sin({name})": s}


def _proportional(pairs) -> bool:
    """Is there one non-zero constant k with a = k·b for every (a, b)?"""
    ratios = {a / b for a, b in pairs if b}
    return len(ratios) == 1 and 0 not in ratios and all(a == 0 for a, b in pairs if not b)


def test_3rpr_singularity_surface_is_the_concurrency_of_the_leg_lines(robots):
    """ξ(x, y, φ) = k · det[u_i, A_i × u_i] on the circle c² + s² = 1, exactly, at random
    rational poses (u_i: leg i's vector, A_i its base point)."""
    xi = robots("3-rpr").singularity_surface
    rng = random.Random(12)
    pairs = []
    for _ in range(12):
        x, y = (Fraction(rng.randint(-40, 40), rng.randint(1, 9)) for _ in range(2))
        m = Fraction(rng.randint(-30, 30), rng.randint(1, 9))
        c, s = _circle_point(m)
        rows = []
        for (ax, ay), (bx, by) in zip(oracles.RPR_BASE, oracles.RPR_PLATFORM, strict=True):
            ux, uy = x + c * bx - s * by - ax, y + s * bx + c * by - ay
            rows.append([ux, uy, ax * uy - ay * ux])
        closed = _det(rows)
        pairs.append((_value(xi, {"x": x, "y": y, **_angle_point("phi", m)}), closed))
    assert _proportional(pairs)


def _det(rows) -> Fraction:
    """Exact determinant (Fractions) by Gaussian elimination."""
    a = [list(r) for r in rows]
    n, out = len(a), Fraction(1)
    for i in range(n):
        pivot = next((r for r in range(i, n) if a[r][i] != 0), None)
        if pivot is None:
            return Fraction(0)
        if pivot != i:
            a[i], a[pivot] = a[pivot], a[i]
            out = -out
        out *= a[i][i]
        for r in range(i + 1, n):
            f = a[r][i] / a[i][i]
            for k in range(i, n):
                a[r][k] -= f * a[i][k]
    return out


def test_gough_stewart_det_A_is_the_plucker_determinant(robots):
    """det A = -64·cos θ·det[u_i, a_i × u_i] exactly at random rational poses (angles at
    rational points of their circles): the legs' Plücker coordinates, and cos θ, where
    the Z-Y-X Euler angles themselves are singular."""
    model = robots("gough-stewart").model
    rng = random.Random(6)
    for _ in range(6):
        p = [Fraction(rng.randint(-20, 20), rng.randint(1, 7)) for _ in range(3)]
        ms = [Fraction(rng.randint(-9, 9), rng.randint(1, 5)) for _ in range(3)]
        (cz, sz), (cy, sy), (cx, sx) = (_circle_point(m) for m in ms)
        R = oracles.rotation_zyx(cz, sz, cy, sy, cx, sx)
        closed = -64 * cy * _det(oracles.plucker_matrix(p, R))
        point = {"x": p[0], "y": p[1], "z": p[2]}
        for name, m in zip(("psi", "theta", "phi"), ms, strict=True):
            point.update(_angle_point(name, m))
        assert _det_A_at(model, point) == closed


def _det_A_at(model, point: dict) -> Fraction:
    """singcheck's A = ∂F/∂X at a rational pose (its entries do not involve the squared
    joints of a Gough–Stewart platform), then its determinant here, exactly."""
    rows = [[_value(entry, {n: point.get(n, Fraction(0)) for n in entry.context().names()})
             for entry in row] for row in model.A]
    return _det(rows)


def test_five_bar_singularity_surface_is_the_distal_links_aligned(robots):
    """The distal links B1P and B2P aligned, with |B_i P| = l2 = 2: either P is the
    midpoint of B1 B2 (eliminated here with SymPy from B1 = (u, v) on the circle about
    A1, B2 = 2P - B1 on the circle about A2, |P - B1| = 2), or B1 = B2 = (0, ±√3), the
    intersection of the proximal circles, and P on the circle of radius 2 about it:
    (x² + y² - 1)² - 12y².  ξ is their product up to a constant."""
    import sympy

    x, y, u, v = sympy.symbols("x y u v")
    eqs = [(u + 1) ** 2 + v ** 2 - 4, (2 * x - u - 1) ** 2 + (2 * y - v) ** 2 - 4,
           (x - u) ** 2 + (y - v) ** 2 - 4]
    basis = sympy.groebner(eqs, u, v, x, y, order="lex")
    (midpoint,) = [g for g in basis.exprs if not g.has(u) and not g.has(v)]
    coincident = (x ** 2 + y ** 2 - 1) ** 2 - 12 * y ** 2
    closed = sympy.Poly(sympy.sqf_part(sympy.expand(midpoint * coincident)), x, y)
    xi = robots("five-bar").singularity_surface
    ours = sympy.Poly(sympy.sympify(str(xi).replace("^", "**")), x, y)
    ratio = sympy.cancel(ours.as_expr() / closed.as_expr())
    assert ratio.is_number and ratio != 0, ratio


def test_the_gough_stewart_yaml_is_what_its_generator_writes():
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "generate_gough_stewart", ROBOTS / "generate_gough_stewart.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert (ROBOTS / "gough-stewart.yaml").read_text(encoding="utf-8") == module.document()
    assert module.BASE == oracles.GS_BASE and module.PLATFORM == oracles.GS_PLATFORM


def test_paths_compose_xi_reduced_on_the_circles_and_it_is_the_same_function(robots):
    """The 3-PRR's ξ (24,389 terms, unreduced in cos φ, sin φ) is composed along a path
    modulo cos² φ + sin² φ = 1: far fewer terms, and exactly the same values at rational
    poses on the circle (Pythagorean points), so μ is the same."""

    robot = robots("3-prr")
    xi, reduced = robot.projection.singularity_surface, robot.projection.surface_on_circles
    assert 9 * len(reduced) < len(xi)
    assert min(reduced.degrees()[2:]) <= 1  # degree ≤ 1 in cos φ or in sin φ
    rng = random.Random(3)
    for _ in range(8):
        x, y = (Fraction(rng.randint(-30, 30), rng.randint(1, 7)) for _ in range(2))
        point = {"x": x, "y": y, **_angle_point("phi", Fraction(rng.randint(-9, 9),
                                                                rng.randint(1, 5)))}
        assert _value(reduced, point) == _value(xi, point)


def test_the_path_wise_norm_reduces_sin_t_squared_exactly():
    """_on_circle (FLINT's remainder by s² + c² - 1 in a ring ordering s before c) gives
    degree ≤ 1 in s and the same values on the circle as the input."""
    from flint import fmpq_mpoly_ctx

    from singcheck.certify.path import _on_circle

    ctx = fmpq_mpoly_ctx.get(("r", "t", "s", "c"), "lex")
    r, t, s, c = ctx.gens()
    p = (3 * r * s**3 - t * s**2 * c + s * c**4 - 5) ** 3 + r**2 * s**5
    q = _on_circle(p)
    assert q.degrees()[2] <= 1
    for m in (Fraction(1, 3), Fraction(-7, 2), Fraction(5)):
        cm, sm = _circle_point(m)
        point = {"r": Fraction(2, 7), "t": Fraction(-3, 4), "s": sm, "c": cm}
        assert _value(q, point) == _value(p, point)


def test_a_pose_angle_that_is_a_multiple_of_t_agrees_with_the_oracle(tmp_path, robots):
    """The 3-PRR's crossing path run five times as fast (phi = 5t on [0, 1/5]: μ in sin t,
    cos t of five times the degree): the oracle's singular time, divided by five."""
    path = oracles.Path("3-prr-5t", oracles.three_prr, 0, mp.mpf(1) / 5,
                        lambda t: [mp.mpf(3) / 2 + mp.sin(5 * t) / 2,
                                   2 - mp.cos(5 * t) / 2, 5 * t], True)
    truth = oracles.solve(path)
    assert truth.verdict == "singular"
    file = tmp_path / "3-prr-5t.yaml"
    file.write_text("name: 3-prr-5t\nparameter: t\nrange: [0, 1/5]\npose:\n"
                    "  x: 3/2 + sin(5*t)/2\n  y: 2 - cos(5*t)/2\n  phi: 5*t\n")
    robot = robots("3-prr")
    _agrees(api.check(robot, api.load_trajectory(file, robot), regions=False),
            path.oracle(), truth)


def test_a_pose_angle_too_high_a_multiple_of_t_is_refused_up_front(tmp_path, robots,
                                                                    monkeypatch, capsys):
    """phi = 30t: μ's roots would be isolated in a polynomial of degree above the bound
    (the run went past a 120 s time limit before the bound): refused at once, in one
    line naming the bound (a spec error: run exits 2)."""
    import time

    from singcheck.errors import SpecError
    from tests.test_hardening import run_cli, trajectory

    path = trajectory(tmp_path, {"x": "3/2 + sin(t)/2", "y": "2 - cos(t)/2", "phi": "30*t"})
    robot = robots("3-prr")
    start = time.monotonic()
    with pytest.raises(SpecError) as refused:  # the exact engine's refusal (auto: intervals)
        api.check(robot, api.load_trajectory(path, robot), regions=False, engine="exact")
    assert time.monotonic() - start < 5
    message = str(refused.value)
    assert "\n" not in message
    assert "too costly: isolating the real roots of μ(t) would take a polynomial of degree" \
        in message
    assert "in tan(t/2) (at most 800: the cost grows as its fourth power)" in message
    monkeypatch.setenv("SINGCHECK_CACHE_DIR", str(tmp_path / "cache"))
    code, out, _ = run_cli(monkeypatch, capsys, "run", str(ROBOTS / "3-prr.yaml"), path,
                           "--backend", "flint", "-q", "--format", "json", "--engine", "exact")
    assert code == 2


def test_a_mixed_t_and_sin_t_path_of_the_rotary_delta_agrees_with_the_oracle(tmp_path,
                                                                             robots):
    """ξ of the rotary Delta is not expanded: μ is eliminated along this path (t and
    sin t, cos t mixed), then its roots are found by branch-and-bound."""
    path = oracles.Path("rotary-delta-mixed", oracles.rotary_delta, 0, 1,
                        lambda t: [t / 3, mp.sin(t) / 4, -2 + mp.cos(t) / 10], False)
    truth = oracles.solve(path)
    file = tmp_path / "rotary-delta-mixed.yaml"
    file.write_text("name: rotary-delta-mixed\nparameter: t\nrange: [0, 1]\npose:\n"
                    "  x: t/3\n  y: sin(t)/4\n  z: -2 + cos(t)/10\n")
    robot = robots("rotary-delta")
    report = api.check(robot, api.load_trajectory(file, robot), regions=False)
    assert report.verdict == "singularity-free"
    _agrees(report, path.oracle(), truth)
