"""Exact decisions where ball arithmetic cannot decide (issue 13): tangencies, several
modes singular at one time, roots at t = 0 and at the range ends, paths lying on the
singularity surface, and paths mixing t with cos t through such a point.

Every expected answer is computed here, independently of singcheck: exact rational
arithmetic (``Fraction``) at poses and joints that are rational, SymPy for a symbolic
determinant, and 50-digit mpmath along the path.
"""

from __future__ import annotations

import time
from fractions import Fraction
from itertools import product

import mpmath
import pytest
import sympy

from singcheck.certify.classification import certify_path, classify_candidate
from singcheck.certify.path import build_path
from singcheck.elimination.cas import get_backend
from singcheck.elimination.projection import project_robot
from singcheck.model.robot import build_model
from singcheck.roots.isolation import isolate_real_roots
from singcheck.spec.files import parse_robot, parse_trajectory
from tests.test_certify import BIGLIDE

ORTHOGLIDE = """\
name: orthoglide
joints: [rho1, rho2, rho3]
pose: [x, y, z]
parameters: {l: 2}
constraints:
  - (x - rho1)^2 + y^2 + z^2 - l^2
  - x^2 + (y - rho2)^2 + z^2 - l^2
  - x^2 + y^2 + (z - rho3)^2 - l^2
joint_limits: {rho1: [LO, 4], rho2: [LO, 4], rho3: [LO, 4]}
"""

# the biglide: rods of length 2, sliders on the x and on the y axis
XY_BIGLIDE = """\
name: xy-biglide
joints: [p, q]
pose: [x, y]
constraints:
  - (x - p)^2 + y^2 - 4
  - x^2 + (y - q)^2 - 4
"""

_PROJECTIONS: dict[str, object] = {}


def certify(robot_text: str, trajectory_text: str):
    if robot_text not in _PROJECTIONS:
        model = build_model(parse_robot(robot_text, "r.yaml"))
        _PROJECTIONS[robot_text] = project_robot(model, get_backend("flint"))
    projection = _PROJECTIONS[robot_text]
    spec = parse_trajectory(trajectory_text, "t.yaml", projection.model.spec)
    return certify_path(build_path(projection, spec))


def orthoglide(lower: str = "0") -> str:
    return ORTHOGLIDE.replace("LO", lower)


def trajectory(start: str, end: str, **pose: str) -> str:
    lines = "".join(f"  {k}: {v}\n" for k, v in pose.items())
    return f"name: p\nparameter: t\nrange: [{start}, {end}]\npose:\n{lines}"


def along(direction: tuple[str, str, str], scale: str) -> dict[str, str]:
    """The pose scale·X0 for X0 = ``direction`` (exact rationals as text)."""
    return {axis: f"{d}*({scale})" for axis, d in zip("xyz", direction, strict=True)}


# X0 = (2/3, 4/3, 4/3) lies on the sphere x² + y² + z² = 4 (|(1, 2, 2)| = 3)
X0 = (Fraction(2, 3), Fraction(4, 3), Fraction(4, 3))
X0_TEXT = ("2/3", "4/3", "4/3")


def det3(m) -> Fraction:
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def orthoglide_det_a(pose, joints) -> Fraction:
    """det ∂F/∂X of the Orthoglide: row i is 2(X - ρᵢ eᵢ)."""
    rows = [[2 * (pose[j] - (joints[i] if i == j else 0)) for j in range(3)] for i in range(3)]
    return det3(rows)


def modes_singular_on_sphere(pose) -> set[str]:
    """At a pose on the sphere |X| = 2 with positive coordinates, the joints are exactly
    ρᵢ = xᵢ ± xᵢ (D = xᵢ²): the modes whose exact det A is 0."""
    out = set()
    for label in ("".join(s) for s in product("+-", repeat=3)):
        joints = [x + x if s == "+" else x - x for x, s in zip(pose, label, strict=True)]
        if orthoglide_det_a(pose, joints) == 0:
            out.add(label)
    return out


def singular_at(report, index: int = 0) -> set[str]:
    return set(report.candidates[index].singular_modes)


# -- the biglide path ------------------------------------------------------------


def test_biglide_path_through_a_rational_singular_pose_is_singular_in_two_modes():
    report = certify(XY_BIGLIDE, trajectory("0", "1", x="8/5 - 3/5*(t - 1/2)",
                                            y="6/5 + 4/5*(t - 1/2)"))
    # independent: at t = 1/2 the pose is (8/5, 6/5); p = x ± √(4 - y²) = 8/5 ± 8/5 and
    # q = y ± √(4 - x²) = 6/5 ± 6/5; det A = det [[2(x - p), 2y], [2x, 2(y - q)]]
    x, y = Fraction(8, 5), Fraction(6, 5)
    expected = set()
    for sp, sq in product((1, -1), repeat=2):
        p, q = x + sp * Fraction(8, 5), y + sq * Fraction(6, 5)
        if 4 * (x - p) * (y - q) - 4 * x * y == 0:
            expected.add(("+" if sp > 0 else "-") + ("+" if sq > 0 else "-"))
    assert expected == {"++", "--"}
    # and a tangency in both (50 digits): det A has one sign on either side of t = 1/2
    mpmath.mp.dps = 50

    def det_a(t, sp, sq):
        x = mpmath.mpf(8) / 5 - mpmath.mpf(3) / 5 * (t - mpmath.mpf(1) / 2)
        y = mpmath.mpf(6) / 5 + mpmath.mpf(4) / 5 * (t - mpmath.mpf(1) / 2)
        p, q = x + sp * mpmath.sqrt(4 - y * y), y + sq * mpmath.sqrt(4 - x * x)
        return 4 * (x - p) * (y - q) - 4 * x * y

    for sp in (1, -1):
        before, after = (det_a(mpmath.mpf(1) / 2 + e, sp, sp) for e in (-mpmath.mpf("1e-3"),
                                                                         mpmath.mpf("1e-3")))
        assert before * after > 0
    assert report.verdict == "singular"
    [candidate] = report.candidates
    assert candidate.t.contains(Fraction(1, 2).__float__()) and candidate.t.rad() < 1e-9
    assert singular_at(report) == expected
    proofs = {m.mode: m.proof for m in candidate.modes}
    assert {proofs[m] for m in expected} == {"det A = 0 exactly (algebraic)"}


# -- tangency at an irrational time, four modes at once -------------------------------


def test_orthoglide_tangent_to_the_sphere_at_t_asin_3_5_is_singular_in_four_modes():
    # X(t) = (1 + (1 - cos(t - t0))/4)·X0 with t0 = asin(3/5): |X| ≥ 2, = 2 only at t0
    w = "(4*cos(t) + 3*sin(t))/5"
    report = certify(orthoglide(), trajectory("0", "1", **along(X0_TEXT, f"1 + (1 - {w})/4")))
    mpmath.mp.dps = 50
    t0 = mpmath.asin(mpmath.mpf(3) / 5)

    def radius2_minus_4(t):
        scale = 1 + (1 - mpmath.cos(t - t0)) / 4
        return scale**2 * 4 - 4

    # a tangency: no sign change around t0 (sampling and sign changes cannot see it)
    assert radius2_minus_4(t0 - mpmath.mpf("1e-3")) > 0 < radius2_minus_4(t0 + mpmath.mpf("1e-3"))
    expected = modes_singular_on_sphere(X0)
    assert expected == {"+--", "-+-", "--+", "---"}
    assert report.verdict == "singular"
    at_t0 = [c for c in report.candidates if c.t.contains(float(t0))]
    assert len(at_t0) == 1 and at_t0[0].t.rad() < 1e-9
    assert abs(float(at_t0[0].t.mid()) - float(t0)) < 1e-9
    assert set(at_t0[0].singular_modes) == expected
    assert all(m.status == "regular" for m in at_t0[0].modes if m.mode not in expected)


def test_the_same_tangency_is_spurious_when_limits_exclude_the_singular_modes():
    # with ρ ≥ 1/10 the branches near ρ = 0 are infeasible; +++ (ρ = 2X at t0) is not singular
    w = "(4*cos(t) + 3*sin(t))/5"
    report = certify(orthoglide("1/10"),
                     trajectory("0", "1", **along(X0_TEXT, f"1 + (1 - {w})/4")))
    assert orthoglide_det_a(X0, [2 * x for x in X0]) != 0
    assert [m.label for m in report.modes if m.feasible] == ["+++"]
    assert report.verdict == "singularity-free"
    assert [c.status for c in report.candidates] == ["spurious"]


# -- roots at t = 0 and at the range ends -------------------------------------------------


@pytest.mark.parametrize("start, end, scale", [
    ("0", "1/5", "1 + t/4"),                  # radial, crossing outward at the range start
    ("-1/5", "0", "1 - t/4"),                 # the same, ending on the sphere
    ("0", "1", "1 + (1 - cos(t))/16"),        # tangency at t = 0, the range start (u = 0)
    ("-1", "1", "1 + (1 - cos(t))/16"),       # tangency at t = 0 inside the range
    ("2", "pi", "1 + (1 + cos(t))/16"),       # tangency at t = π, the range end (u = ∞)
])
def test_roots_at_zero_and_at_the_range_ends_are_decided_exactly(start, end, scale):
    report = certify(orthoglide(), trajectory(start, end, **along(X0_TEXT, scale)))
    # independent: the pose at the root is X0 exactly, on the sphere
    expected = modes_singular_on_sphere(X0)
    assert report.verdict == "singular"
    root = 0.0 if "pi" not in end else float(mpmath.pi)
    at = [c for c in report.candidates if c.t.contains(root)
          or abs(float(c.t.mid()) - root) < 1e-12]
    assert len(at) == 1
    assert set(at[0].singular_modes) == expected
    assert all(m.status != "unknown" for c in report.candidates for m in c.modes)


# -- paths lying on the singularity surface (μ ≡ 0) ----------------------------------------


def test_a_constant_pose_on_the_sphere_is_singular_all_along_in_four_modes():
    report = certify(orthoglide(), trajectory("0", "1", x="2/3", y="4/3", z="4/3"))
    assert report.verdict == "singular"
    assert "whole path" in report.reason
    expected = modes_singular_on_sphere(X0)
    assert {m for c in report.candidates for m in c.singular_modes} == expected
    # every mode is feasible (the branches at ρ = 0 sit on the closed limit)
    assert all(m.feasible for m in report.modes)


def test_a_circle_on_the_sphere_is_singular_in_four_modes_and_free_without_them():
    # x² + y² = 64/25, z = 6/5: on the sphere x² + y² + z² = 4 for every t
    circle = trajectory("1/4", "1", x="8/5*cos(t)", y="8/5*sin(t)", z="6/5")
    report = certify(orthoglide(), circle)
    mpmath.mp.dps = 50
    expected = None
    for k in range(1, 8):  # independent: 50-digit det A per mode at sample times
        t = mpmath.mpf(1) / 4 + mpmath.mpf(k) * (mpmath.mpf(3) / 4) / 8
        pose = [8 * mpmath.cos(t) / 5, 8 * mpmath.sin(t) / 5, mpmath.mpf(6) / 5]
        zero = set()
        for label in ("".join(s) for s in product("+-", repeat=3)):
            joints = [x + x if s == "+" else x - x for x, s in zip(pose, label, strict=True)]
            if abs(orthoglide_det_a(pose, joints)) < mpmath.mpf("1e-40"):
                zero.add(label)
        expected = zero if expected is None else expected & zero
    assert expected == {"+--", "-+-", "--+", "---"}
    assert report.verdict == "singular"
    assert {m for c in report.candidates for m in c.singular_modes} == expected
    # with ρ ≥ 1/10 only +++ (ρ = 2X) is feasible; its det A is 16·x·y·z·(stuff) ≠ 0
    x, y, z = sympy.symbols("x y z")
    rows = [[2 * (v - (2 * v if i == j else 0)) for j, v in enumerate((x, y, z))]
            for i in range(3)]
    assert sympy.factor(sympy.Matrix(rows).det()) == 32 * x * y * z
    free = certify(orthoglide("1/10"), circle)
    assert [m.label for m in free.modes if m.feasible] == ["+++"]
    assert free.verdict == "singularity-free"


# -- paths mixing t with cos t ---------------------------------------------------------


def test_mixed_path_through_a_tangency_at_zero_takes_seconds():
    # x = t/3, y = 0, z = 1 + cos t: at t = 0 the pose (0, 0, 2) is on the sphere, both
    # branches of ρ1 (and of ρ2) meet (D = 4 - y² - z² = 0) and ρ3 = 4 is the limit
    start = time.perf_counter()
    report = certify(orthoglide(), trajectory("-1/2", "1/2", x="t/3", y="0", z="1 + cos(t)"))
    assert time.perf_counter() - start < 20
    # independent: D1(t) = 4 - (1 + cos t)² is 0 at t = 0 and > 0 elsewhere in the range
    assert 4 - (1 + 1) ** 2 == 0
    assert report.verdict == "infeasible"
    assert "rho1 meet at t ≈ 0" in report.reason
    assert report.candidates == []  # no mode can follow the path: μ is not looked at
    # the candidate at t = 0 is still decided exactly, and fast, when it is asked for
    path = report.path
    roots = isolate_real_roots(path.mu, path.trajectory.range, 1e-9).roots
    [candidate] = [classify_candidate(path, report.modes, r, 1e-9) for r in roots]
    assert time.perf_counter() - start < 20
    assert candidate.t.contains(0) and candidate.t.rad() == 0
    # at (0, 0, 2) with ρ1 = ρ2 = 0 rows 1 and 2 of A are equal: every mode is singular
    for rho3 in (Fraction(4), Fraction(0)):
        assert orthoglide_det_a((0, 0, Fraction(2)), (0, 0, rho3)) == 0
    assert all(m.status == "singular" for m in candidate.modes)


_HALF = mpmath.mpf(1) / 2


@pytest.mark.parametrize("interval, scale, oracle, root", [
    (("0", "1"), "1 + (t^2 - 1/2)^2*(2 + cos(t))/64",
     lambda t: 1 + (t * t - _HALF) ** 2 * (2 + mpmath.cos(t)) / 64, "sqrt"),
    (("0", "1"), "1 + (t - 1/2)^2*(2 + cos(t))/64",
     lambda t: 1 + (t - _HALF) ** 2 * (2 + mpmath.cos(t)) / 64, _HALF),
    (("1/2", "1"), "1 + (t - 1/2)^2*(2 + cos(t))/64",  # at the range's start
     lambda t: 1 + (t - _HALF) ** 2 * (2 + mpmath.cos(t)) / 64, _HALF),
    (("0", "1/2"), "1 - (t - 1/2)*(2 + cos(t))/64",  # a crossing at the range's end
     lambda t: 1 - (t - _HALF) * (2 + mpmath.cos(t)) / 64, _HALF),
])
def test_mixed_path_meeting_the_sphere_at_an_algebraic_time_is_decided(interval, scale,
                                                                       oracle, root):
    """The scale is 1 exactly at an algebraic time τ ≠ 0 (a factor of μ in t alone),
    where sin τ, cos τ are transcendental: four modes are singular at once there (so no
    elimination proof), decided exactly over Q(τ)[sin, cos] (issue 13: a tangency, or
    several modes, at an algebraic time of a mixed path, also at a range end)."""
    mpmath.mp.dps = 50
    root = mpmath.sqrt(_HALF) if root == "sqrt" else root
    assert abs(oracle(root) - 1) < mpmath.mpf(10) ** -45  # the pose is X0 (on the sphere)
    assert oracle(root + mpmath.mpf(10) ** -6) != 1
    report = certify(ORTHOGLIDE.replace("LO", "0"), trajectory(*interval,
                                                               **along(X0_TEXT, scale)))
    at_root = [c for c in report.candidates
               if float(c.t.lower()) <= root <= float(c.t.upper())]
    assert len(at_root) == 1
    expected = modes_singular_on_sphere(X0)
    assert len(expected) == 4
    assert set(at_root[0].singular_modes) == expected
    proofs = {m.mode: m.proof for m in at_root[0].modes}
    assert "det A = 0 exactly (algebraic time, transcendental sin and cos)" in \
        {proofs[m] for m in expected}
    assert all(m.status != "unknown" for m in at_root[0].modes)
    assert report.verdict != "unknown"


def test_mixed_path_meeting_the_sphere_at_t_zero_through_a_factor_t_is_decided():
    """scale = 1 + t(1 + cos t)/64: μ's factor t gives an algebraic root t = 0 (found by
    a campaign: the exact step refused t = 0, where sin t and cos t are exact); four
    modes are singular there at once, decided exactly in Q."""
    report = certify(ORTHOGLIDE.replace("LO", "0"),
                     trajectory("0", "pi/4", **along(X0_TEXT, "1 + t*(1 + cos(t))/64")))
    [at_zero] = [c for c in report.candidates if c.t.contains(0)]
    assert set(at_zero.singular_modes) == modes_singular_on_sphere(X0)
    assert all(m.status != "unknown" for m in at_zero.modes)
    assert report.verdict == "singular"


@pytest.mark.parametrize("interval, scale, oracle, end", [
    (("0", "pi/4"), "1 + (cos(t) - sin(t))^2*(1 + t)/64",
     lambda t: 1 + (mpmath.cos(t) - mpmath.sin(t)) ** 2 * (1 + t) / 64, "end"),
    (("pi/4", "1"), "1 + (cos(t) - sin(t))^2*(1 + t)/64",
     lambda t: 1 + (mpmath.cos(t) - mpmath.sin(t)) ** 2 * (1 + t) / 64, "start"),
    (("0", "pi/4"), "1 + (cos(t) - sin(t))*(1 + t)/64",
     lambda t: 1 + (mpmath.cos(t) - mpmath.sin(t)) * (1 + t) / 64, "end"),
    (("0", "pi/6"), "1 + (sin(3*t) - 1)^2*(1 + t)/64",
     lambda t: 1 + (mpmath.sin(3 * t) - 1) ** 2 * (1 + t) / 64, "end"),
])
def test_mixed_path_meeting_the_sphere_at_a_range_end_a_pi_is_decided(interval, scale,
                                                                        oracle, end):
    """The range ends at π/4 or π/6, exactly where the path (mixing t with sin t, cos t)
    meets the sphere: the joints sit on their limit 0 there in four modes, so the limit
    polynomials vanish at the range end, where no sign change can bracket them (the
    branch-and-bound left `limit crossing … not decided`).  The zero at the end is
    decided exactly (π transcendental over Q(sin aπ, cos aπ)); issue 13, class 3."""
    mpmath.mp.dps = 50
    e = {"pi/4": mpmath.pi / 4, "pi/6": mpmath.pi / 6}[interval[0 if end == "start" else 1]]
    assert abs(oracle(e) - 1) < mpmath.mpf(10) ** -45  # the pose is X0, on the sphere
    inside = e + (mpmath.mpf(10) ** -3 if end == "start" else -mpmath.mpf(10) ** -3)
    assert oracle(inside) > 1 or "*(1 + t)/64" in scale and "^2" not in scale
    report = certify(ORTHOGLIDE.replace("LO", "0"), trajectory(*interval,
                                                               **along(X0_TEXT, scale)))
    assert report.verdict == "singular", report.reason
    at_end = [c for c in report.candidates if float(c.t.lower()) <= e <= float(c.t.upper())]
    assert len(at_end) == 1
    assert set(at_end[0].singular_modes) == modes_singular_on_sphere(X0)
    assert all(m.status != "unknown" for m in at_end[0].modes)
    assert all(m.status != "unknown" for m in report.modes)


def test_mixed_path_touching_the_sphere_at_zero_from_outside_is_singular():
    # scale 1 + t²/16 + (1 - cos t)/8 ≥ 1, = 1 only at t = 0: a tangency of order 2
    report = certify(orthoglide(), trajectory(
        "-1/2", "1/2", **along(X0_TEXT, "1 + t^2/16 + (1 - cos(t))/8")))
    assert report.root_method == "interval branch-and-bound"
    assert report.verdict == "singular"
    at_zero = [c for c in report.candidates if c.t.contains(0)]
    assert len(at_zero) == 1
    assert set(at_zero[0].singular_modes) == modes_singular_on_sphere(X0)
    assert at_zero[0].root.multiplicity % 2 == 0  # even: a tangency
    assert not report.undecided



def test_a_root_exactly_at_an_irrational_range_end_is_kept():
    # y = cos(2t)/2 + 1/4 is 0 exactly at t = π/3, the range end (u = tan(π/6) = 1/√3);
    # det A = 4·y·(q - p) vanishes there in every mode
    report = certify(BIGLIDE, trajectory("0", "pi/3", x="cos(t)/2", y="cos(2*t)/2 + 1/4"))
    mpmath.mp.dps = 50
    assert abs(mpmath.cos(2 * mpmath.pi / 3) / 2 + mpmath.mpf(1) / 4) < mpmath.mpf("1e-45")
    assert report.verdict == "singular"
    [candidate] = report.candidates
    assert abs(float(candidate.t.mid()) - float(mpmath.pi / 3)) < 1e-9
    assert all(m.status == "singular" for m in candidate.modes)
    assert not report.undecided


def test_a_singular_pose_at_the_join_of_two_segments_is_decided_exactly(tmp_path):
    from singcheck.certify.pieces import certify_trajectory
    from singcheck.spec.files import load_trajectory

    model = build_model(parse_robot(XY_BIGLIDE, "r.yaml"))
    projection = project_robot(model, get_backend("flint"))
    path = tmp_path / "seg.yaml"
    pose = "{x: 8/5 - 3/5*(t - 1/2), y: 6/5 + 4/5*(t - 1/2)}"
    path.write_text(f"name: seg\nparameter: t\nsegments:\n  - range: [0, 1/2]\n    pose: {pose}\n"
                    f"  - range: [1/2, 1]\n    pose: {pose}\n")
    report = certify_trajectory(projection, load_trajectory(path, model.spec))
    # the same pose as the one-piece path: singular in ++ and -- at the join t = 1/2
    assert report.verdict == "singular"
    [candidate] = report.candidates
    assert candidate.t.contains(0.5)
    assert set(candidate.singular_modes) == {"++", "--"}


def test_exact_decisions_with_a_square_root_in_the_robot_agree_with_50_digits():
    # the linear Delta's rails sit at (R, 0), (-R/2, ±√3/2·R): √3 is a level of the tower
    from pathlib import Path

    from singcheck.certify.exact import AlgebraicPoint, det_a_vanishes_at
    from singcheck.spec.files import load_robot, load_trajectory

    root = Path(__file__).resolve().parent.parent
    model = build_model(load_robot(root / "robots/linear-delta.yaml"))
    projection = project_robot(model, get_backend("flint"))
    path = build_path(projection, load_trajectory(root / "trajectories/linear-delta-cross.yaml",
                                                  model.spec))
    report = certify_path(path)
    mpmath.mp.dps = 50
    rails = [(mpmath.mpf(1), mpmath.mpf(0)), (-mpmath.mpf(1) / 2, mpmath.sqrt(3) / 2),
             (-mpmath.mpf(1) / 2, -mpmath.sqrt(3) / 2)]

    def det_a(t, label):  # independent: x = -1/4 + t/2, y = -1/4, z = t/4, rods of 3/2
        x, y, z = -mpmath.mpf(1) / 4 + t / 2, -mpmath.mpf(1) / 4, t / 4
        rows = []
        for (cx, cy), sign in zip(rails, label, strict=True):
            d2 = (x - cx) ** 2 + (y - cy) ** 2
            r = z + (1 if sign == "+" else -1) * mpmath.sqrt(mpmath.mpf(9) / 4 - d2)
            rows.append([2 * (x - cx), 2 * (y - cy), 2 * (z - r)])
        return mpmath.det(mpmath.matrix(rows))

    assert report.candidates
    for c in report.candidates:
        point = AlgebraicPoint(c.root.exact)
        t = mpmath.mpf(float(c.t.mid()))
        for m in c.modes:
            eps = mpmath.mpf("1e-7")
            crosses = det_a(t - eps, m.mode) * det_a(t + eps, m.mode) < 0
            assert det_a_vanishes_at(path, point, m.mode) == crosses, (float(t), m.mode)


# -- revolute legs: the 5-bar and the rotary Delta ----------------------------------------


def _bundled(robot: str):
    from pathlib import Path

    from singcheck.spec.files import load_robot

    root = Path(__file__).resolve().parent.parent
    if robot not in _PROJECTIONS:
        model = build_model(load_robot(root / f"robots/{robot}.yaml"))
        _PROJECTIONS[robot] = project_robot(model, get_backend("flint"))
    return _PROJECTIONS[robot]


def _revolute_path(robot: str, text: str):
    projection = _bundled(robot)
    return build_path(projection, parse_trajectory(text, "t.yaml", projection.model.spec))


def _oracle_modes(path, oracle, pose_at, t0) -> dict[str, tuple[int, ...]]:
    """Our mode label → the oracle's branch indices, matched by the joint angles at the
    rational time t0 (the oracle's IK is its own closed form, at 50 digits)."""
    from flint import arb

    ours = [leg.branches(arb(float(t0))) for leg in path.legs]
    theirs = [leg.branches(pose_at(mpmath.mpf(t0.numerator) / t0.denominator))
              for leg in oracle.legs]
    out = {}
    for label in ("".join(s) for s in product("+-", repeat=len(path.legs))):
        indices = []
        for sign, branch, both in zip(label, ours, theirs, strict=True):
            c, s = branch[sign]
            angle = mpmath.atan2(float(s.mid()), float(c.mid()))
            [k] = [k for k in (0, 1) if abs(mpmath.sin((angle - both[k]) / 2)) < 1e-6]
            indices.append(k)
        out[label] = tuple(indices)
    return out


def _revolute_zero_modes(oracle, modes, pose, tiny="1e-30", big="1e-8") -> set[str]:
    """The modes whose 50-digit det A is 0 at the pose (each value must be clearly 0 or
    clearly not)."""
    out = set()
    for label, indices in modes.items():
        joints = oracle.joints(indices, pose)
        value = abs(oracle.det_A(joints, pose))
        assert value < mpmath.mpf(tiny) or value > mpmath.mpf(big), (label, value)
        if value < mpmath.mpf(tiny):
            out.add(label)
    return out


FIVE_BAR_TOUCH = trajectory("3/2", "2", x="t*t - 3", y="sqrt(3)")


def test_five_bar_line_tangent_where_the_distal_links_align_is_singular_at_sqrt_3():
    from tests.robot_oracles import five_bar

    # y = √3 is tangent to the elbows-out singular curve at (0, √3) (it is symmetric in
    # x); x = t² - 3 reaches x = 0 at the quadratic irrational t = √3
    path = _revolute_path("five-bar", FIVE_BAR_TOUCH)
    report = certify_path(path)
    mpmath.mp.dps = 50
    oracle = five_bar()

    def pose_at(t):
        return [t * t - 3, mpmath.sqrt(3)]

    modes = _oracle_modes(path, oracle, pose_at, Fraction(7, 4))
    t0 = mpmath.sqrt(3)
    expected = _revolute_zero_modes(oracle, modes, pose_at(t0))
    assert expected == {"+-"}
    indices = modes["+-"]

    def det(t):
        return oracle.det_A(oracle.joints(indices, pose_at(t)), pose_at(t))

    eps = mpmath.mpf("1e-4")
    assert det(t0 - eps) * det(t0 + eps) > 0  # a tangency: no sign change
    assert report.verdict == "singular"
    [candidate] = report.candidates
    assert candidate.t.contains(float(t0)) or abs(float(candidate.t.mid()) - float(t0)) < 1e-9
    assert set(candidate.singular_modes) == expected
    assert all(m.status != "unknown" for m in candidate.modes)


def test_rotary_delta_touching_the_surface_in_infeasible_modes_only_is_free():
    # on the axis, at z = -(4 + √3)/2 the elbows th = 2π/3 sit right above the centre:
    # the three forearms are vertical, parallel (det A = 0, a double zero in t); that
    # branch is outside the limits [-π/2, 3π/4] at the start, the feasible one is not
    from tests.robot_oracles import rotary_delta

    path = _revolute_path("rotary-delta", trajectory("5/2", "29/10", x="0", y="0", z="-t"))
    report = certify_path(path)
    mpmath.mp.dps = 50
    oracle = rotary_delta()
    tau = (4 + mpmath.sqrt(3)) / 2

    def pose_at(t):
        return [0, 0, -t]

    modes = _oracle_modes(path, oracle, pose_at, Fraction(27, 10))
    two_thirds = oracle.joints(modes["+++"], pose_at(tau))
    assert all(abs(mpmath.cos(q) + mpmath.mpf(1) / 2) < 1e-40 for q in two_thirds)
    singular = _revolute_zero_modes(oracle, modes, pose_at(tau), tiny="1e-25")
    assert "+++" in singular and "---" not in singular
    assert [m.label for m in report.modes if m.feasible] == ["---"]
    assert report.verdict == "singularity-free"
    [candidate] = report.candidates
    assert abs(float(candidate.t.mid()) - float(tau)) < 1e-9
    assert set(candidate.singular_modes) == singular
    assert all(m.status != "unknown" for m in candidate.modes)


def _mp(q: str):
    return mpmath.mpf(Fraction(q).numerator) / Fraction(q).denominator


@pytest.mark.parametrize("robot, text, oracle_name, pose_at", [
    ("five-bar", FIVE_BAR_TOUCH, "five_bar", lambda t: [t * t - 3, mpmath.sqrt(3)]),
    ("five-bar", "trajectories/five-bar-cross.yaml", "five_bar", lambda t: [0, 3 - 2 * t]),
    ("rotary-delta", "trajectories/rotary-delta-cross.yaml", "rotary_delta",
     lambda t: [_mp("7/4") + _mp("3/10") * t, 0, -1]),
    ("rotary-delta", trajectory("5/2", "29/10", x="0", y="0", z="-t"), "rotary_delta",
     lambda t: [0, 0, -t]),
])
def test_exact_decisions_on_revolute_legs_agree_with_50_digits(robot, text, oracle_name,
                                                               pose_at):
    from pathlib import Path

    from singcheck.certify.exact import AlgebraicPoint, det_a_vanishes_at
    from tests import robot_oracles

    if text.startswith("trajectories/"):
        text = (Path(__file__).resolve().parent.parent / text).read_text()
    path = _revolute_path(robot, text)
    report = certify_path(path)
    mpmath.mp.dps = 50
    oracle = getattr(robot_oracles, oracle_name)()
    start = path.trajectory.range.start.rational
    end = path.trajectory.range.end.rational
    modes = _oracle_modes(path, oracle, pose_at, (start + end) / 2 + Fraction(1, 97))
    assert report.candidates
    for c in report.candidates:
        point = AlgebraicPoint(c.root.exact)
        t = mpmath.mpf(c.root.refined(1e-45).t.mid().str(60, radius=False))
        # every mode whose IK is real at the root, decided by the oracle at 50 digits
        real = {m: i for m, i in modes.items() if oracle.joints(i, pose_at(t)) is not None}
        expected = _revolute_zero_modes(oracle, real, pose_at(t), tiny="1e-25")
        assert expected
        for label in real:
            assert det_a_vanishes_at(path, point, label) == (label in expected), label


def _five_bar_pose_zero_modes(pose_at, text, robot="five-bar", samples=(Fraction(1, 3),)):
    """The modes whose 50-digit det A (the oracle's) is 0 at every sample time."""
    from tests.robot_oracles import five_bar

    mpmath.mp.dps = 50
    oracle = five_bar()
    path = _revolute_path(robot, text)
    modes = _oracle_modes(path, oracle, pose_at, samples[0])
    zero = None
    for q in samples:
        t = mpmath.mpf(q.numerator) / q.denominator
        found = _revolute_zero_modes(oracle, modes, pose_at(t))
        zero = found if zero is None else zero & found
    return path, zero


def test_five_bar_resting_where_the_distal_links_align_is_singular_all_along():
    text = trajectory("0", "1", x="0", y="sqrt(3)")
    path, expected = _five_bar_pose_zero_modes(lambda t: [0, mpmath.sqrt(3)], text)
    assert expected == {"+-"}
    report = certify_path(path)
    assert report.verdict == "singular" and "whole path" in report.reason
    assert [m.label for m in report.modes if m.feasible] == ["+-"]
    assert {m for c in report.candidates for m in c.singular_modes} == expected
    # the workspace line: on ξ all along, with the oracle's IK count inside the limits
    from singcheck.report.trajectory import workspace_json, workspace_line
    from singcheck.spaces.path_regions import path_in_workspace
    from tests.robot_oracles import five_bar

    count = 1
    for leg in five_bar().legs:  # angles in [lo, lo + 2π): inside when ≤ hi
        count *= sum(1 for q in leg.branches([0, mpmath.sqrt(3)]) if q <= leg.hi + 1e-30)
    line = workspace_line(workspace_json(path_in_workspace(path, name_region=False)))
    assert line == ("workspace: the path lies on parallel singularity ξ for t ∈ [0, 1] "
                    f"({count} IK solution(s) inside the joint limits all along)")


def test_five_bar_on_the_surface_of_an_infeasible_mode_only_is_free():
    # (0, 2 - √3) is 2 away from the shared elbow (0, -√3): the mode with both elbows
    # there (th1 = -π/3, outside the limits) is singular, the elbows-out mode is not
    text = trajectory("0", "1", x="0", y="2 - sqrt(3)")
    path, zero = _five_bar_pose_zero_modes(lambda t: [0, 2 - mpmath.sqrt(3)], text)
    assert len(zero) == 1 and "+-" not in zero
    report = certify_path(path)
    assert [m.label for m in report.modes if m.feasible] == ["+-"]
    assert report.verdict == "singularity-free"
    assert "lies on ξ(X) = 0" in report.reason


def test_five_bar_arc_around_the_shared_elbow_is_singular_all_along_without_limits():
    # P = (0, -√3) + 2(cos t, sin t): both elbows can sit at (0, -√3), 2 from each base
    from pathlib import Path

    robot = "five-bar-nolimits"
    if robot not in _PROJECTIONS:
        root = Path(__file__).resolve().parent.parent
        text = (root / "robots/five-bar.yaml").read_text().replace(
            "joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}\n", "")
        spec = parse_robot(text, "r.yaml")
        _PROJECTIONS[robot] = project_robot(build_model(spec), get_backend("flint"))
    text = trajectory("1/4", "1", x="2*cos(t)", y="-sqrt(3) + 2*sin(t)")

    def pose_at(t):
        return [2 * mpmath.cos(t), -mpmath.sqrt(3) + 2 * mpmath.sin(t)]

    samples = [Fraction(1, 4) + Fraction(3, 4) * Fraction(k, 8) for k in range(1, 8)]
    path, expected = _five_bar_pose_zero_modes(pose_at, text, robot, samples)
    assert len(expected) == 1
    report = certify_path(path)
    assert report.verdict == "singular" and "whole path" in report.reason
    singular = {m for c in report.candidates for m in c.singular_modes}
    assert singular == expected
    assert all(m.status != "unknown" for c in report.candidates for m in c.modes)


# -- touches at transcendental times (paths mixing t with sin t, cos t) ---------------------


def _orthoglide_scale_touch(lower: str, start: str, end: str, h: str, h_mp):
    """X(t) = (1 - h(t)²/4)·X0: |X| ≤ 2, = 2 exactly where h = 0 (a tangency to the
    sphere from inside, in the four modes whose branches meet ρ = 0 there)."""
    report = certify(orthoglide(lower), trajectory(start, end, **along(X0_TEXT,
                                                                     f"1 - ({h})^2/4")))
    mpmath.mp.dps = 50
    tau = mpmath.findroot(h_mp, float((Fraction(start) + Fraction(end)) / 2))

    def det_a(t, label):  # 50 digits: ρᵢ = xᵢ ± √(4 - |X|² + xᵢ²)
        scale = 1 - h_mp(t) ** 2 / 4
        pose = [scale * (mpmath.mpf(x.numerator) / x.denominator) for x in X0]
        r2 = sum(x * x for x in pose)
        joints = [x + (1 if s == "+" else -1) * mpmath.sqrt(4 - r2 + x * x)
                  for x, s in zip(pose, label, strict=True)]
        return orthoglide_det_a(pose, joints)

    return report, tau, det_a


@pytest.mark.parametrize("h, h_mp, start, end", [
    # μ has the factor (t - cos t)²: τ is the Dottie number, cos τ = τ
    ("t - cos(t)", lambda t: t - mpmath.cos(t), "1/2", "1"),
    # (t - sin t - 1/2)² is a square only on the circle: reduced modulo s² + c² = 1 it
    # is t² - 2ts - t + 1/4 + ... - c², irreducible in Q[t, s, c]
    ("t - sin(t) - 1/2", lambda t: t - mpmath.sin(t) - mpmath.mpf(1) / 2, "1", "2"),
])
def test_orthoglide_touching_the_sphere_at_a_transcendental_time_is_singular(h, h_mp, start,
                                                                            end):
    began = time.process_time()
    report, tau, det_a = _orthoglide_scale_touch("-1", start, end, h, h_mp)
    assert time.process_time() - began < 10
    expected = modes_singular_on_sphere(X0)  # the pose at τ is X0 exactly
    for label in expected:  # a tangency: det A ≠ 0 on either side, no sign change
        eps = mpmath.mpf("1e-3")
        assert det_a(tau - eps, label) * det_a(tau + eps, label) > 0
        assert abs(det_a(tau, label)) < mpmath.mpf("1e-40")
    assert report.root_method == "interval branch-and-bound"
    assert report.verdict == "singular" and not report.undecided
    [candidate] = report.candidates
    assert abs(float(candidate.t.mid()) - float(tau)) < 1e-9 and candidate.t.rad() < 1e-9
    assert set(candidate.singular_modes) == expected
    proofs = {m.mode: m.proof for m in candidate.modes}
    assert {proofs[m] for m in expected} == {"det A = 0 exactly (at a transcendental time)"}
    assert all(m.status != "unknown" for m in candidate.modes)


def test_the_transcendental_touch_is_free_when_limits_exclude_the_singular_modes():
    report, tau, det_a = _orthoglide_scale_touch("1/10", "1", "2", "t - sin(t) - 1/2",
                                                 lambda t: t - mpmath.sin(t) - mpmath.mpf(1) / 2)
    assert abs(det_a(tau, "+++")) > 1  # the feasible mode (ρ = 2X at τ) is regular
    assert [m.label for m in report.modes if m.feasible] == ["+++"]
    assert report.verdict == "singularity-free" and not report.undecided


def test_zero_tests_at_a_transcendental_root_agree_with_50_digits():
    from flint import fmpq

    from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange, reduce_trig
    from singcheck.roots.branch_bound import branch_and_bound
    from singcheck.roots.transcendental import TranscendentalPoint

    t, s, c = TRIG.gens()
    half = TRIG.from_dict({(0, 0, 0): fmpq(1, 2)})
    h = t - s - half  # τ - sin τ = 1/2, τ ≈ 1.4973
    interval = TimeRange(LinearInPi(Fraction(1)), LinearInPi(Fraction(2)))
    [root] = branch_and_bound(h, interval, 1e-9).roots
    point = TranscendentalPoint(root.exact)
    mpmath.mp.dps = 50
    tau = mpmath.findroot(lambda u: u - mpmath.sin(u) - mpmath.mpf(1) / 2, 1.5)

    def value(p):
        return sum(mpmath.mpf(int(k.p)) / int(k.q) * tau ** int(i) * mpmath.sin(tau) ** int(j)
                   * mpmath.cos(tau) ** int(m) for (i, j, m), k in p.terms())

    zeros = [h, h * (t + c), s * s + c * c - 1 + h * s, (t - half) ** 2 - (1 - c * c)]
    nonzeros = [t + s - half, t - c, (t + s - half) * (t - c), s, c - t * s]
    for element, zero in [(e, True) for e in zeros] + [(e, False) for e in nonzeros]:
        element = reduce_trig(element)
        assert (abs(value(element)) < mpmath.mpf("1e-40")) == zero, str(element)
        assert point.is_zero(element) == zero, str(element)


@pytest.mark.parametrize("bump, bump_mp, start, end, tau", [
    # 1 + cos t ≥ 0 touches 0 at t = π (a zero of even order on the circle)
    ("(1 + cos(t))*(1 + t/8)", lambda t: (1 + mpmath.cos(t)) * (1 + t / 8), "3", "4",
     lambda: mpmath.pi),
    # cos τ = 4/5 and sin τ = 3/5 are rational, τ = acos(4/5) is transcendental
    ("(5*cos(t) - 4)^2*(1 + t/8)", lambda t: (5 * mpmath.cos(t) - 4) ** 2 * (1 + t / 8),
     "3/5", "7/10", lambda: mpmath.acos(mpmath.mpf(4) / 5)),
])
def test_touch_where_sin_and_cos_are_algebraic_but_t_is_not(bump, bump_mp, start, end, tau):
    report = certify(orthoglide("-1"), trajectory(start, end,
                                                  **along(X0_TEXT, f"1 - {bump}/4")))
    mpmath.mp.dps = 50
    tau = tau()
    assert abs(bump_mp(tau)) < mpmath.mpf("1e-45")  # the pose at τ is X0, on the sphere
    eps = mpmath.mpf("1e-3")
    assert bump_mp(tau - eps) > 0 < bump_mp(tau + eps)  # inside the sphere on both sides
    assert report.verdict == "singular"
    [candidate] = report.candidates
    assert abs(float(candidate.t.mid()) - float(tau)) < 1e-9
    assert set(candidate.singular_modes) == modes_singular_on_sphere(X0)
    assert all(m.status != "unknown" for m in candidate.modes)


# -- the workspace line of a path lying on ξ = 0 -------------------------------------------


@pytest.mark.parametrize("lower, surfaces, count", [
    ("-1", {"parallel singularity ξ"}, 8),
    # with ρ ≥ 0 the branches ρ = x - x = 0 sit on the limit, whose surface (the leg's
    # constraint at ρ = 0: x² + y² + z² = 4) is the sphere too
    ("0", {"parallel singularity ξ", "rho1 = 0 (min)", "rho2 = 0 (min)", "rho3 = 0 (min)"},
     None),
])
def test_the_workspace_line_says_the_path_lies_on_the_surface(lower, surfaces, count):
    from singcheck.report.trajectory import workspace_json, workspace_line
    from singcheck.spaces.path_regions import path_in_workspace

    x, y, z = X0
    assert x * x + y * y + z * z == 4  # on the sphere, every leg's ρ = 0 surface
    expected_count = 1
    for v in X0:  # ρ = v ± v, both strictly inside [-1, 4] when the limit is -1
        expected_count *= sum(Fraction(lower) < v + sign * v < 4 for sign in (1, -1))
    assert (expected_count if lower == "-1" else None) == count
    report = certify(orthoglide(lower), trajectory("0", "1", x="2/3", y="4/3", z="4/3"))
    assert report.verdict == "singular"
    w = path_in_workspace(report.path, name_region=False,
                          mu_roots=[c.t for c in report.candidates]
                          if report.mu_roots_complete else None)
    assert not w.undecided and not w.crossings and w.one_region is False
    assert {s for s, _ in w.on_surfaces} == surfaces
    assert {where for _, where in w.on_surfaces} == {"[0, 1]"}
    line = workspace_line(workspace_json(w))
    assert "not all decided" not in line
    assert line.startswith("workspace: the path lies on ") and "for t ∈ [0, 1]" in line
    if count is not None:
        assert line.endswith(f"({count} IK solution(s) inside the joint limits all along)")


def test_a_touch_without_an_exact_time_stays_unknown_with_the_reason():
    # the Dottie-number tangency of above, its root stripped of its exact description
    # (as for a path whose angle is not k·t + qπ): no ball proof exists for the four
    # touching modes, so they stay unknown, and say why and where
    from dataclasses import replace

    from singcheck.certify.classification import classify_candidate
    from singcheck.certify.working_modes import working_modes

    report, tau, det_a = _orthoglide_scale_touch("-1", "1/2", "1", "t - cos(t)",
                                                 lambda t: t - mpmath.cos(t))
    [candidate] = report.candidates
    bare = replace(candidate.root, exact=None)
    again = classify_candidate(report.path, working_modes(report.path, 1e-9), bare, 1e-9)
    unknown = {m.mode: m.proof for m in again.modes if m.status == "unknown"}
    assert set(unknown) == modes_singular_on_sphere(X0)
    for label in unknown:  # they are singular indeed (50 digits): unknown, not wrong
        assert abs(det_a(tau, label)) < mpmath.mpf("1e-40")
    assert all("no exact description" in why and f"t ≈ {float(tau):.9g}"[:12] in why
               for why in unknown.values())
    assert again.status == "unknown"


def test_five_bar_elbows_sitting_on_their_limits_all_along_are_feasible_and_singular():
    # P = (0, √3) + 2(cos t, sin t): one branch of each leg keeps its elbow at (0, √3),
    # i.e. th1 = π/3 and th2 = 2π/3, exactly the (closed) limits, all along; there the
    # distal links coincide: det A ≡ 0 in that mode
    from tests.robot_oracles import five_bar

    text = trajectory("1/4", "1", x="2*cos(t)", y="sqrt(3) + 2*sin(t)")

    def pose_at(t):
        return [2 * mpmath.cos(t), mpmath.sqrt(3) + 2 * mpmath.sin(t)]

    samples = [Fraction(1, 4) + Fraction(3, 4) * Fraction(k, 8) for k in range(1, 8)]
    path, zero = _five_bar_pose_zero_modes(pose_at, text, samples=samples)
    [label] = zero
    oracle = five_bar()
    modes = _oracle_modes(path, oracle, pose_at, samples[0])
    for q in samples:
        th1, th2 = oracle.joints(modes[label], pose_at(mpmath.mpf(q.numerator) / q.denominator))
        assert abs(th1 - mpmath.pi / 3) < 1e-40 and abs(th2 - 2 * mpmath.pi / 3) < 1e-40
    report = certify_path(path)
    assert label in [m.label for m in report.modes if m.feasible]
    assert all(m.status != "unknown" for m in report.modes)
    assert report.verdict == "singular" and "whole path" in report.reason
    assert {m for c in report.candidates for m in c.singular_modes} == zero


@pytest.mark.parametrize("scale, start, end, tau, kind", [
    ("1 - (t - 1/2)^2/4", "0", "1", Fraction(1, 2), "touches"),  # |X| ≤ 2, = 2 at 1/2
    ("3/4 + t/2", "0", "1", Fraction(1, 2), "crosses"),  # radial: |X| = 2 at t = 1/2
])
def test_the_workspace_line_tells_a_tangency_from_a_crossing(scale, start, end, tau, kind):
    """The path meets the sphere |X| = 2 (a component of ξ) once, at t = 1/2: the sign of
    4 - |X(t)|², computed here exactly on either side, says whether it crosses or only
    touches; the workspace line must say the same (and never 'crosses' for a touch)."""
    from singcheck.report.trajectory import workspace_json, workspace_line
    from singcheck.spaces.path_regions import XI, path_in_workspace

    cert = certify(orthoglide("-1"), trajectory(start, end, **along(X0_TEXT, scale)))
    w = path_in_workspace(cert.path, name_region=False)
    (meeting,) = [c for c in w.crossings if XI in c.surfaces]
    assert meeting.t.contains(float(tau))  # 1/2: exact as a float

    def slack(t: Fraction) -> Fraction:  # 4 - |X(t)|², X = scale(t)·X0, |X0| = 2
        s = 1 - (t - Fraction(1, 2)) ** 2 / 4 if kind == "touches" else Fraction(3, 4) + t / 2
        return 4 - 4 * s * s

    before, after = slack(tau - Fraction(1, 100)), slack(tau + Fraction(1, 100))
    assert (before * after > 0) == (kind == "touches")
    assert meeting.kind == kind
    line = workspace_line(workspace_json(w))
    if kind == "touches":
        assert "crosses" not in line and "touching it 1" in line, line
    (item,) = [c for c in workspace_json(w)["crossings"] if XI in c["surfaces"]]
    assert item["kind"] == kind


# -- limits met where the robot and its conjugate (√3 ↦ -√3) both are ----------------------


def _feasible_by_samples(oracle, modes, pose_at, start: Fraction, end: Fraction,
                       samples: int = 60) -> set[str]:
    """The modes whose 50-digit joints are inside the (closed) limits at every sample of
    the range, the ends included (a value within 1e-40 of a limit is on it)."""
    eps, pi = mpmath.mpf("1e-40"), mpmath.pi
    out = set()
    for label, indices in modes.items():
        inside = True
        for k in range(samples + 1):
            q = start + (end - start) * Fraction(k, samples)
            t = mpmath.mpf(q.numerator) / q.denominator
            joints = oracle.joints(indices, pose_at(t))
            inside &= joints is not None and all(  # angles in [lo, lo + 2π): v - 2π too
                any(leg.lo - eps <= w <= leg.hi + eps
                    for w in ((v, v - 2 * pi) if leg.revolute else (v,)))
                for leg, v in zip(oracle.legs, joints, strict=True))
        if inside:
            out.add(label)
    return out


@pytest.mark.parametrize("y, sign, start, feasible", [
    # P = (0, √3) + 2(cos t, ±sin t); the elbow-2 branch that is not at (0, √3) is
    # th2 = ±t exactly (a parallelogram: B2 - A2 = P - (0, √3)), so at t = 0 it is on
    # th2 = 0, and so is the conjugate robot's (P = (2, -√3) is 2 from (3, 0) too)
    ("sqrt(3) + 2*sin(t)", 1, Fraction(0), {"++", "+-"}),  # th2 = t: enters at 0
    ("sqrt(3) - 2*sin(t)", -1, Fraction(-1, 2), {"++"}),  # th2 = -t: leaves at 0
])
def test_five_bar_limit_met_where_the_conjugate_robot_meets_it_too(y, sign, start, feasible):
    from tests.robot_oracles import five_bar

    def pose_at(t):
        return [2 * mpmath.cos(t), mpmath.sqrt(3) + sign * 2 * mpmath.sin(t)]

    text = trajectory(str(start), "1", x="2*cos(t)", y=y)
    path = _revolute_path("five-bar", text)
    mpmath.mp.dps = 50
    oracle = five_bar()
    modes = _oracle_modes(path, oracle, pose_at, Fraction(1, 3))
    on_limits = {label for label, i in modes.items()
                 if [abs(v - w) < 1e-40 for v, w in zip(
                     oracle.joints(i, pose_at(mpmath.mpf(1) / 7)),
                     (mpmath.pi / 3, 2 * mpmath.pi / 3), strict=True)] == [True, True]}
    assert on_limits == {"++"}
    for q in (Fraction(1, 3), Fraction(5, 7)):  # the other elbow 2: th2 = ±t
        t = mpmath.mpf(q.numerator) / q.denominator
        assert abs(mpmath.sin((oracle.joints(modes["+-"], pose_at(t))[1] - sign * t) / 2)) \
            < 1e-40  # equal modulo 2π
    assert _feasible_by_samples(oracle, modes, pose_at, start, Fraction(1)) == feasible
    report = certify_path(path)
    assert all(m.status != "unknown" for m in report.modes)
    assert {m.label for m in report.modes if m.feasible} == feasible
    by_label = {m.label: m for m in report.modes}
    assert "th2 = 0 at t ≈ 0 exactly (algebraic" in by_label["++"].proof
    if "+-" not in feasible:  # it leaves through th2 = 0 at t = 0
        [leaving] = [b for b in by_label["+-"].branches if b.status == "infeasible"]
        assert leaving.event_time.contains(0) and "leaves" in leaving.reason
    # ++ sits on ξ all along (the distal links coincide): singular along the whole path
    assert report.verdict == "singular" and "whole path" in report.reason
    from singcheck.spaces.path_regions import path_in_workspace

    w = path_in_workspace(path, name_region=False)
    assert not w.undecided
    # the workspace line: th2 = 0 is met at t = 0 (a branch is there; a range end or not)
    assert [c.surfaces for c in w.crossings if c.t.contains(0)] == [("th2 = 0 (min)",)]


def test_five_bar_where_only_the_conjugate_robot_meets_a_limit_is_free():
    # x = 0, y = t: at τ = 2 - √3 the pose is 2 from (0, -√3), the conjugate robot's
    # elbow on th1 = π/3 (√3 ↦ -√3): there the mode with both elbows at (0, -√3) is
    # singular, feasible for the conjugate robot (on its limit) but not for this one
    from tests.robot_oracles import five_bar

    def pose_at(t):
        return [mpmath.mpf(0), t]

    path = _revolute_path("five-bar", trajectory("0", "1", x="0", y="t"))
    mpmath.mp.dps = 50
    oracle = five_bar()
    modes = _oracle_modes(path, oracle, pose_at, Fraction(1, 3))
    tau = 2 - mpmath.sqrt(3)
    singular = _revolute_zero_modes(oracle, modes, pose_at(tau))
    [elbows_down] = singular
    joints = oracle.joints(modes[elbows_down], pose_at(tau))
    assert abs(mpmath.cos(joints[0]) - mpmath.mpf(1) / 2) < 1e-40  # th1 = -π/3 ...
    assert abs(mpmath.sin(joints[0]) + mpmath.sqrt(3) / 2) < 1e-40  # ... not π/3
    feasible = _feasible_by_samples(oracle, modes, pose_at, Fraction(0), Fraction(1))
    assert elbows_down not in feasible and feasible
    report = certify_path(path)
    assert {m.label for m in report.modes if m.feasible} == feasible
    assert report.verdict == "singularity-free"
    [near] = [c for c in report.candidates if c.t.contains(float(tau))
              or abs(float(c.t.mid()) - float(tau)) < 1e-9]
    assert set(near.singular_modes) == singular


def test_a_limit_polynomial_is_decided_exactly_at_its_conjugates_root():
    """p = t² - 2√3·t - 1 (th1 = π/3 along x = 0, y = t, up to a factor) and its
    conjugate p̄ = t² + 2√3·t - 1 at τ = 2 - √3, a root of their norm (t² - 1)² - 12t²:
    computed here in Q(√3) (pairs a + b√3), p̄(τ) = 0 and p(τ) = 12 - 8√3 ≠ 0.  In Q(τ),
    √3 = 2 - τ: the tower must tell the two apart, both ways."""
    from flint import fmpq_mpoly_ctx

    from singcheck.algebra.radicals import radical_name
    from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange
    from singcheck.certify.exact import vanishes_at_root
    from singcheck.roots.isolation import isolate_real_roots

    def mul(u, v):
        return (u[0] * v[0] + 3 * u[1] * v[1], u[0] * v[1] + u[1] * v[0])

    tau = (Fraction(2), Fraction(-1))
    tau2 = mul(tau, tau)
    for sign, zero in ((-1, False), (1, True)):
        value = (tau2[0] + 2 * sign * 3 * tau[1] - 1, tau2[1] + 2 * sign * tau[0])
        assert (value == (0, 0)) == zero
    ring = fmpq_mpoly_ctx.get(("t", "s", "c", radical_name(3)), "lex")
    t, _, _, r3 = ring.gens()
    t_q = TRIG.gens()[0]
    norm = (t_q * t_q - 1) ** 2 - 12 * t_q * t_q
    iso = isolate_real_roots(norm, TimeRange(LinearInPi(Fraction(0)), LinearInPi(Fraction(1))))
    [root] = iso.roots
    assert root.t.contains(float(2 - mpmath.sqrt(3)))
    assert vanishes_at_root(t * t - 2 * r3 * t - 1, root) is False
    assert vanishes_at_root(t * t + 2 * r3 * t - 1, root) is True


def test_rotary_delta_legs_2_and_3_on_their_limit_at_a_transcendental_time():
    # y = t - cos t is 0 at the Dottie number τ; at (-3/2, 0, -1/2) legs 2 and 3 (each
    # the other's √3-conjugate) both have a branch on th = -π/2: each limit polynomial
    # and its conjugate vanish at τ, decided exactly in Q(τ, sin τ, cos τ)(√3)
    from tests.robot_oracles import rotary_delta

    def pose_at(t):
        return [-mpmath.mpf(3) / 2, t - mpmath.cos(t), -mpmath.mpf(1) / 2]

    path = _revolute_path("rotary-delta", trajectory("0", "1", x="-3/2", y="t - cos(t)",
                                                     z="-1/2"))
    mpmath.mp.dps = 50
    oracle = rotary_delta()
    modes = _oracle_modes(path, oracle, pose_at, Fraction(1, 3))
    tau = mpmath.findroot(lambda t: t - mpmath.cos(t), 0.7)
    eps = mpmath.mpf("1e-6")
    report = certify_path(path)
    assert all(m.status != "unknown" for m in report.modes)

    def offset(theta):  # θ + π/2 taken in (-π, π]
        return (theta + mpmath.pi / 2 + mpmath.pi) % (2 * mpmath.pi) - mpmath.pi

    leaving = 0
    for label, indices in modes.items():
        mode = next(m for m in report.modes if m.label == label)
        for leg in (1, 2):  # th2, th3: the branch at -π/2 at τ crosses it there
            value = oracle.joints(indices, pose_at(tau))[leg]
            on = abs(mpmath.sin((value + mpmath.pi / 2) / 2)) < 1e-40
            branch = mode.branches[leg]
            if on:  # θ + π/2 (mod 2π, in (-π, π)) changes sign: θ crosses -π/2 at τ
                before, after = (offset(oracle.joints(indices, pose_at(tau + d))[leg])
                                 for d in (-eps, eps))
                assert before * after < 0
                assert "exactly (at a transcendental time" in branch.proof
                inside = all(-mpmath.pi / 2 <= offset(oracle.joints(
                    indices, pose_at(tau * k / 20))[leg]) - mpmath.pi / 2 <= 3 * mpmath.pi / 4
                    for k in range(20))
                if inside and before > 0:  # inside on [0, τ), leaves at τ
                    leaving += 1
                    assert branch.status == "infeasible" and \
                        abs(float(branch.event_time.mid()) - float(tau)) < 1e-9, (label, leg)
            if branch.event_time is not None and \
                    abs(float(branch.event_time.mid()) - float(tau)) < 1e-9:
                assert on
    assert leaving
    assert report.verdict == "infeasible"


@pytest.mark.parametrize("y, start, end", [("-t", "-1/4", "0"), ("-t", "-1/4", "1/4")])
def test_linear_delta_slider_on_its_limit_where_the_conjugate_robot_is_too(y, start, end):
    # at (1/4, 0, 1/4 - √15/4) rail 2 and its √3-conjugate (rail 3's place) are as far
    # from the pose, and slider 2's upper branch is exactly on r2 = 1/4: along y = -t it
    # is inside for t < 0 and leaves there at t = 0
    from flint import arb

    from tests.robot_oracles import linear_delta

    z = (1 - mpmath.sqrt(15)) / 4

    def pose_at(t):
        return [mpmath.mpf(1) / 4, -t, z]

    path = _revolute_path("linear-delta", trajectory(start, end, x="1/4", y=y,
                                                     z="1/4 - sqrt(15)/4"))
    mpmath.mp.dps = 50
    oracle = linear_delta()
    modes = {}  # our label → the oracle's branch indices (its ρ = (-b ± √d)/2a, + first)
    for label in ("".join(s) for s in product("+-", repeat=3)):
        modes[label] = tuple(0 if sign == "+" else 1 for sign in label)
    for ours, theirs in zip(path.legs, oracle.legs, strict=True):  # matched by value
        t0 = Fraction(start) / 2
        mine = ours.branches(arb(float(t0)))
        both = theirs.branches(pose_at(mpmath.mpf(t0.numerator) / t0.denominator))
        assert [abs(float(mine[k].mid()) - float(v)) < 1e-9
                for k, v in zip("+-", both, strict=True)] == [True, True]
    top = oracle.legs[1].branches(pose_at(mpmath.mpf(0)))[0]
    assert abs(top - mpmath.mpf(1) / 4) < 1e-40  # r2's upper branch on its limit at t = 0
    for q, inside in ((-1, True), (1, False)):
        value = oracle.legs[1].branches(pose_at(mpmath.mpf(q) / 8))[0]
        assert (value >= mpmath.mpf(1) / 4) == inside
    feasible = _feasible_by_samples(oracle, modes, pose_at, Fraction(start), Fraction(end))
    report = certify_path(path)
    assert all(m.status != "unknown" for m in report.modes)
    assert {m.label for m in report.modes if m.feasible} == feasible
    assert feasible == ({"++-"} if end == "0" else set())
    for m in report.modes:
        branch = m.branches[1]
        if m.label[1] == "+":
            assert "r2 = 1/4 at t ≈ 0 exactly (algebraic" in branch.proof
            if end != "0":
                assert branch.status == "infeasible" and branch.event_time.contains(0)
