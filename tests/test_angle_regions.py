"""Workspace regions of robots with angles (the half-angle chart) and square roots (√3).

Every count and every region statement is checked against the oracles of
``tests/robot_oracles.py`` (the robots' geometry written a second time, closed-form
inverse kinematics at 50 digits with mpmath), never against singcheck's own numbers; an
angle's chart coordinate is turned back into radians here, φ = 2·atan(w).
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath as mp
import pytest
from flint import fmpq, fmpq_mpoly_ctx

from singcheck.elimination.cas import get_backend
from singcheck.elimination.projection import project_robot
from singcheck.model.robot import build_model
from singcheck.spaces.analysis import (
    PARALLEL,
    WORKSPACE,
    analyse,
    select_surfaces,
    workspace_variety,
)
from singcheck.spaces.chart import Chart
from singcheck.spec.files import load_robot
from tests import robot_oracles as oracles
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_cli import singcheck

mp.mp.dps = 50


def _projection(name):
    return project_robot(build_model(load_robot(ROBOTS / f"{name}.yaml")), get_backend("flint"))


def _mp(q) -> mp.mpf:
    q = Fraction(q)
    return mp.mpf(q.numerator) / q.denominator


def _oracle_count(oracle, X) -> int:
    """IK solutions inside the limits at the pose X (50 digits, the oracle's own IK)."""
    total = 1
    for leg in oracle.legs:
        both = leg.branches(X)
        if both is None:
            return 0
        total *= sum(1 for v in both if leg.lo <= v <= leg.hi)
    return total


def _pose(chart: Chart, axes, point) -> list:
    """The oracle's pose (radians for an angle) at a chart point."""
    values = dict(zip(axes, point, strict=True))
    return [2 * mp.atan(_mp(values[a])) if v in chart.angles else _mp(values[a])
            for v, a in zip(chart.names, chart.axes, strict=True)]


def _sign_at(poly, values: dict) -> int:
    """The sign of a polynomial at a 50-digit point (mpmath, term by term)."""
    names = poly.context().names()
    total = mp.mpf(0)
    for exps, c in poly.terms():
        term = mp.mpf(int(c.p)) / int(c.q)
        for n, e in zip(names, exps, strict=True):
            term *= values[n] ** int(e)
        total += term
    assert abs(total) > mp.mpf(10) ** -30, "a path point on a surface"
    return 1 if total > 0 else -1


def _check_cells(projection, oracle, fixed, kinds=None):
    """Every cell's count against the oracle; returns the analysis."""
    model = projection.model
    chart = Chart.of(model.pose, model.angles)
    components = workspace_variety(projection)
    if kinds is not None:
        components = [c for c in components if c.kind in kinds]
    else:
        free = len([a for a in chart.axes if a not in fixed])
        components, _ = select_surfaces(components, WORKSPACE, "auto", free)
    analysis = analyse(WORKSPACE, model, components, fixed)
    assert analysis.cells
    for c in analysis.cells:
        point = {**dict(zip(analysis.axes, c.cell.sample, strict=True)), **fixed}
        X = _pose(chart, chart.axes, [point[a] for a in chart.axes])
        assert c.count == _oracle_count(oracle, X), (c.cell.sample, c.count)
    return analysis


def _path_in_region(analysis, chart, region_name, oracle, pose_of_t, t0, t1, samples=24):
    """The named region's sign vector and its count hold at 50-digit points of the path
    (computed here from the path's own formula, the count by the oracle's IK); returns
    that count."""
    number = int(region_name.split()[0][1:])
    region = next(r for r in analysis.regions.regions if r.number == number)
    count = analysis.region_count(number)
    for k in range(samples + 1):
        t = _mp(t0) + (_mp(t1) - _mp(t0)) * k / samples
        X = pose_of_t(t)
        values = {a: mp.tan(x / 2) if v in chart.angles else x
                  for v, a, x in zip(chart.names, chart.axes, X, strict=True)}
        assert tuple(_sign_at(f, values) for f in analysis.cad.factors) == region.signs
        assert _oracle_count(oracle, X) == count
    return count


def _trajectory(robot, text, tmp_path):
    from singcheck.api import load_trajectory

    path = tmp_path / "path.yaml"
    path.write_text(text)
    return load_trajectory(path, robot)


def _check(robot_name, text, tmp_path):
    from singcheck.api import check, load_robot

    robot = load_robot(ROBOTS / f"{robot_name}.yaml", backend="flint", cache=False)
    return robot, check(robot, _trajectory(robot, text, tmp_path)).workspace


# -- the chart -------------------------------------------------------------------------


def test_chart_polynomial_is_the_substitution_with_denominators_cleared():
    ctx = fmpq_mpoly_ctx.get(("x", "cos(phi)", "sin(phi)"), "lex")
    x, c, s = ctx.gens()
    p = x * c ** 2 - 3 * s * c + x * x + s - 1
    chart = Chart.of(("x", "phi"), frozenset({"phi"}))
    assert chart.axes == ("x", "tan(phi/2)")
    q = chart.polynomial(p)
    for xv, w in [(Fraction(1, 3), Fraction(2, 7)), (Fraction(-2), Fraction(5, 3)), (0, 0)]:
        cv, sv = (1 - w * w) / (1 + w * w), 2 * w / (1 + w * w)
        expected = (xv * cv ** 2 - 3 * sv * cv + xv * xv + sv - 1) * (1 + w * w) ** 2
        got = q.subs({"x": fmpq(Fraction(xv).numerator, Fraction(xv).denominator),
                      "tan(phi/2)": fmpq(w.numerator, w.denominator)})
        value = got.leading_coefficient() if not got.is_zero() else fmpq(0)
        assert Fraction(int(value.p), int(value.q)) == expected
    # the circle itself is no polynomial of the chart: c² + s² - 1 ↦ 0, and a factor
    # 1 + w² (never zero) is dropped
    assert chart.polynomial(c * c + s * s - 1).is_zero()
    assert chart.polynomial(1 + c).total_degree() == 0  # 2/(1 + w²) · (1 + w²) = 2


# -- square roots: the Deltas --------------------------------------------------------------


def test_linear_delta_slice_counts_match_the_oracle_and_a_path_is_named(tmp_path):
    projection = _projection("linear-delta")
    analysis = _check_cells(projection, oracles.linear_delta(), {"y": Fraction(1, 4)})
    assert {c.count for c in analysis.cells} == {0, 1, 2}
    _, w = _check("linear-delta", "name: p\nparameter: t\nrange: [0, 1/2]\n"
                  "pose: {x: -1/4 + t/2, y: 1/4, z: t/4}\n", tmp_path)
    assert w.one_region and w.region.endswith("of the workspace plane y = 1/4")
    chart = Chart.of(("x", "y", "z"), frozenset())
    assert _path_in_region(analysis, chart, w.region, oracles.linear_delta(),
                           lambda t: [-mp.mpf(1) / 4 + t / 2, mp.mpf(1) / 4, t / 4],
                           0, Fraction(1, 2)) == 1


@pytest.mark.slow
def test_rotary_delta_free_path_is_named_in_its_plane_without_xi(tmp_path):
    projection = _projection("rotary-delta")
    assert not projection.expanded
    analysis = _check_cells(projection, oracles.rotary_delta(), {"z": Fraction(-2)})
    assert not [c for c in analysis.components if c.kind == PARALLEL]
    _, w = _check("rotary-delta", (TRAJECTORIES / "rotary-delta-free.yaml").read_text(),
                  tmp_path)
    assert w.one_region
    assert w.region.endswith("plane z = -2 cut by its serial-singularity and joint-limit "
                             "surfaces only")
    chart = Chart.of(("x", "y", "z"), frozenset())
    assert _path_in_region(analysis, chart, w.region, oracles.rotary_delta(),
                           lambda t: [mp.cos(t) / 2, mp.sin(t) / 2, mp.mpf(-2)],
                           -math.pi, math.pi) == 1


# -- angles: the 3-RPR and the 5-bar ---------------------------------------------------------


def test_3rpr_plane_in_the_chart_counts_and_a_turning_path_match_the_oracle(tmp_path):
    # the plane y = 1 in (x, tan(phi/2)), ξ included; the path moves and turns in it
    text = "name: p\nparameter: t\nrange: [0, 1]\npose: {x: 5/2 + t/2, y: 1, phi: t}\n"
    robot, w = _check("3-rpr", text, tmp_path)
    assert w.one_region
    assert w.region.endswith("of the workspace plane y = 1 (in the chart tan(phi/2): cut "
                             "along phi = π)")
    fixed = {"y": Fraction(1)}
    analysis = _check_cells(robot.projection, oracles.three_rpr(), fixed)
    assert analysis.axes == ("x", "tan(phi/2)")
    assert {c.count for c in analysis.cells} == {0, 1}
    assert [c for c in analysis.components if c.kind == PARALLEL]
    chart = Chart.of(("x", "y", "phi"), frozenset({"phi"}))
    assert _path_in_region(analysis, chart, w.region, oracles.three_rpr(),
                           lambda t: [mp.mpf(5) / 2 + t / 2, mp.mpf(1), t], 0, 1) == 1


def test_3rpr_turning_path_is_named_in_the_chart(tmp_path):
    text = "name: p\nparameter: t\nrange: [0, 1]\npose: {x: 2, y: 1, phi: pi/2 + t/2}\n"
    robot, w = _check("3-rpr", text, tmp_path)
    assert w.one_region
    assert w.region.endswith("of the workspace line x = 2, y = 1 (in the chart "
                             "tan(phi/2): cut along phi = π)")
    fixed = {"x": Fraction(2), "y": Fraction(1)}
    analysis = _check_cells(robot.projection, oracles.three_rpr(), fixed)
    chart = Chart.of(("x", "y", "phi"), frozenset({"phi"}))
    assert _path_in_region(analysis, chart, w.region, oracles.three_rpr(),
                           lambda t: [mp.mpf(2), mp.mpf(1), mp.pi / 2 + t / 2],
                           0, 1) == 1


def test_five_bar_workspace_counts_match_the_oracle_and_the_free_path_is_named(tmp_path):
    projection = _projection("five-bar")
    analysis = _check_cells(projection, oracles.five_bar(), {})
    assert {c.count for c in analysis.cells} >= {0, 1}
    _, w = _check("five-bar", (TRAJECTORIES / "five-bar-free.yaml").read_text(), tmp_path)
    assert w.one_region and w.region.endswith("of the workspace line y = 5/2")


# -- what is refused, and why ------------------------------------------------------------------


@pytest.mark.parametrize("pose, time_range", [
    ("{x: 2, y: 1, phi: pi}", "[0, 1]"),  # on the cut
    ("{x: 1, y: 2, phi: t}", "[3, 33/10]"),  # across it, crossing no surface
])
def test_a_path_reaching_pi_gets_no_region_and_says_why(pose, time_range, tmp_path):
    text = f"name: p\nparameter: t\nrange: {time_range}\npose: {pose}\n"
    _, w = _check("3-rpr", text, tmp_path)
    assert w.one_region is True and w.region is None
    assert "the angle phi reaches π" in w.region_reason


def test_six_axes_are_refused_in_one_line(tmp_path):
    _, w = _check("gough-stewart", (TRAJECTORIES / "gough-stewart-translate.yaml").read_text(),
                  tmp_path)
    assert w.one_region and w.region is None
    assert "too many variables for a cylindrical decomposition" in w.region_reason
    result = singcheck("workspace", str(ROBOTS / "gough-stewart.yaml"), "--backend", "flint")
    assert result.returncode == 2
    assert "too many variables" in result.stderr and "Traceback" not in result.stderr


def test_an_angle_limit_with_a_transcendental_tangent_is_refused(tmp_path):
    text = (ROBOTS / "five-bar.yaml").read_text().replace(
        "joint_limits: {th1: [pi/3, pi]", "joint_limits: {th1: [1, 3]")
    robot = tmp_path / "five-bar-1rad.yaml"
    robot.write_text(text)
    result = singcheck("workspace", str(robot), "--backend", "flint", "-q")
    assert result.returncode == 2
    assert "multiple of pi/12" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert "five-bar-1rad.yaml" in result.stderr


def test_cli_workspace_prints_the_regions_of_an_angle_robot():
    result = singcheck("workspace", str(ROBOTS / "3-rpr.yaml"), "--slice", "x=2", "--slice",
                       "y=1", "--format", "json", "-q", "--backend", "flint")
    assert result.returncode == 0, (result.stdout + result.stderr)
    import json

    doc = json.loads(result.stdout)
    assert doc["axes"] == ["tan(phi/2)"]
    assert doc["regions"] and doc["components_proven"] is True


def test_five_bar_joint_space_in_the_chart_matches_an_independent_direct_kinematics():
    from singcheck.spaces.analysis import JOINTSPACE, jointspace_variety

    model = build_model(load_robot(ROBOTS / "five-bar.yaml"))
    analysis = analyse(JOINTSPACE, model, jointspace_variety(model, get_backend("flint")))
    assert analysis.axes == ("tan(th1/2)", "tan(th2/2)")
    assert analysis.regions.components_proven
    inside = set()
    for c in analysis.cells:
        th1, th2 = (2 * mp.atan(_mp(w)) for w in c.cell.sample)
        # the elbows B_i = A_i + 2(cos θ_i, sin θ_i); P is on both circles of radius 2
        b1 = (-1 + 2 * mp.cos(th1), 2 * mp.sin(th1))
        b2 = (1 + 2 * mp.cos(th2), 2 * mp.sin(th2))
        gap = mp.sqrt((b1[0] - b2[0]) ** 2 + (b1[1] - b2[1]) ** 2)
        assert abs(gap - 4) > mp.mpf(10) ** -30 and gap > 0
        assert c.count == (2 if gap < 4 else 0), c.cell.sample
        within = mp.pi / 3 < th1 < mp.pi and 0 < th2 < 2 * mp.pi / 3
        assert c.within_limits == within, c.cell.sample
        if within:
            inside.add(c.count)
    assert inside == {0, 2}


def test_a_chart_region_map_survives_the_cache(tmp_path):
    from singcheck.spaces.region_map import RegionMap, RegionMapCache

    projection = _projection("3-rpr")
    fixed = {"x": Fraction(2), "y": Fraction(1)}
    analysis = analyse(WORKSPACE, projection.model, workspace_variety(projection), fixed)
    cache = RegionMapCache(tmp_path)
    key = cache.key([c.polynomial for c in analysis.components], fixed)
    cache.store(key, RegionMap.of(analysis))
    back = cache.load(key)
    assert back is not None and back.variables == ("tan(phi/2)",)
    assert len(analysis.cells) == 3
    for c in analysis.cells:  # every cell's sample is located in its own region again
        assert back.region_at(list(c.cell.sample)) == c.region is not None


def test_a_decomposition_too_costly_to_project_is_refused_up_front():
    # the rotary Delta's 3-D workspace: normed surfaces of degree 8, projection bound 8⁴
    result = singcheck("workspace", str(ROBOTS / "rotary-delta.yaml"), "--backend", "flint",
                       "-q")
    assert result.returncode == 2
    assert "too costly" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    # the line names the file and what to ask for instead
    assert "rotary-delta.yaml" in result.stderr and "--slice z=VALUE" in result.stderr


def test_3rpr_plane_regions_are_proven_and_match_the_checked_segments(monkeypatch):
    # the plane y = 1 in (x, tan(phi/2)): critical values of degree 10 and 12, once
    # joined by checked segments only (regions not proven to be components)
    from singcheck.spaces import plane_adjacency
    from singcheck.spaces.analysis import decomposition, space_chart
    from singcheck.spaces.cad import fiber
    from singcheck.spaces.regions import connect_regions

    projection = _projection("3-rpr")
    axes = space_chart(projection.model, WORKSPACE).axes
    _, _, cad = decomposition(axes, workspace_variety(projection), {"y": Fraction(1)})
    base = fiber(cad.levels, cad.variables, ())
    assert max(plane_adjacency.minimal_polynomial(r).degree() for r in base) >= 10
    exact = connect_regions(cad)
    assert exact.components_proven and len(exact.regions) == 36

    def partition(regions):
        return sorted(sorted(c.index for c in r.cells) for r in regions.regions)

    # the joins by checked segments alone (an independent proof of each join) give the
    # same partition: no two of the exact regions are joined by a free segment
    monkeypatch.setattr(plane_adjacency, "exact_joins", lambda *args: None)
    segments = connect_regions(cad)
    assert not segments.components_proven
    assert partition(segments) == partition(exact)
