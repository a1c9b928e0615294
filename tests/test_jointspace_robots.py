"""Joint-space regions of the robots with square roots and pose angles (issue 12).

Every region's count of direct-kinematic solutions is checked against an independent
solve written here at 50 digits with mpmath, from the robots' geometry (not their YAML):
for the Deltas the platform centre is where three spheres of equal radius meet (two
linear equations and a quadratic, in closed form); for the 3-RPR the orientation φ is
scanned over (-π, π], each sign change of the eliminated equation refined by bisection
and the pose it gives checked against all three legs.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath as mp
import pytest

from singcheck.elimination.cas import get_backend
from singcheck.model.robot import build_model
from singcheck.spaces.analysis import (
    JOINTSPACE,
    analyse,
    jointspace_variety,
    select_surfaces,
    space_chart,
)
from singcheck.spaces.solution_counts import direct_kinematics_count
from singcheck.spec.files import load_robot
from tests.conftest import ROBOTS
from tests.test_cas import _backend
from tests.test_cli import singcheck

mp.mp.dps = 50
RAIL_ANGLES = (0, 2 * mp.pi / 3, 4 * mp.pi / 3)
TINY = mp.mpf(10) ** -30


def _mp(q) -> mp.mpf:
    q = Fraction(q)
    return mp.mpf(q.numerator) / q.denominator


def _three_spheres(centres, radius) -> int:
    """Real points at distance ``radius`` from the three centres: the radical line of the
    spheres (two linear equations) met by the first sphere (a quadratic)."""
    c1, c2, c3 = (mp.matrix([mp.mpf(v) for v in c]) for c in centres)
    n2, n3 = 2 * (c1 - c2), 2 * (c1 - c3)
    d = mp.matrix([n2[1] * n3[2] - n2[2] * n3[1], n2[2] * n3[0] - n2[0] * n3[2],
                   n2[0] * n3[1] - n2[1] * n3[0]])
    rows = mp.matrix([[n2[0], n2[1], n2[2]], [n3[0], n3[1], n3[2]], [d[0], d[1], d[2]]])
    rhs = mp.matrix([sum(c1[k] ** 2 - c2[k] ** 2 for k in range(3)),
                     sum(c1[k] ** 2 - c3[k] ** 2 for k in range(3)), 0])
    p0 = mp.lu_solve(rows, rhs) - c1
    a = sum(d[k] ** 2 for k in range(3))
    b = 2 * sum(p0[k] * d[k] for k in range(3))
    c = sum(p0[k] ** 2 for k in range(3)) - mp.mpf(radius) ** 2
    disc = b * b - 4 * a * c
    assert abs(disc) > TINY  # a sample point is off ε: no double solution
    return 2 if disc > 0 else 0


def _linear_delta_count(r) -> int:
    """Vertical rails at radius 1 (0°, 120°, 240°), rods 3/2 from the sliders at r_i."""
    centres = [(mp.cos(a), mp.sin(a), _mp(ri)) for a, ri in zip(RAIL_ANGLES, r, strict=True)]
    return _three_spheres(centres, mp.mpf(3) / 2)


def _rotary_delta_count(w) -> int:
    """Arms of length 1 from the shoulders at radius 1/2, θ_i = 2·atan(w_i); the elbow of
    leg i at (u cos α_i, u sin α_i, -sin θ_i), u = 1/2 + cos θ_i; forearms of length 2."""
    centres = []
    for a, wi in zip(RAIL_ANGLES, w, strict=True):
        theta = 2 * mp.atan(_mp(wi))
        u = mp.mpf(1) / 2 + mp.cos(theta)
        centres.append((u * mp.cos(a), u * mp.sin(a), -mp.sin(theta)))
    return _three_spheres(centres, 2)


RPR_BASE = ((0, 0), (5, 0), (1, 4))
RPR_PLATFORM = ((0, 0), (1, 0), (0, 1))


def _rpr_legs(r, phi):
    """(w_i, r_i²) with leg i: |P + w_i|² = r_i², w_i = R(φ)b_i - A_i."""
    c, s = mp.cos(phi), mp.sin(phi)
    out = []
    for (ax, ay), (bx, by), ri in zip(RPR_BASE, RPR_PLATFORM, r, strict=True):
        out.append(((c * bx - s * by - ax, s * bx + c * by - ay), _mp(ri) ** 2))
    return out


def _rpr_position(r, phi):
    """P from legs 2, 3 minus leg 1 (w_1 = 0): 2 P·w_i = r_i² - r_1² - |w_i|²; and the
    residual of leg 1 with its denominator cleared, and the denominator."""
    (_, q1), (w2, q2), (w3, q3) = _rpr_legs(r, phi)
    a, b, c, d = 2 * w2[0], 2 * w2[1], 2 * w3[0], 2 * w3[1]
    e = q2 - q1 - w2[0] ** 2 - w2[1] ** 2
    f = q3 - q1 - w3[0] ** 2 - w3[1] ** 2
    det = a * d - b * c
    nx, ny = e * d - b * f, a * f - e * c
    return (nx / det, ny / det), nx ** 2 + ny ** 2 - q1 * det ** 2, det


def _rpr_count(r, steps=2048) -> int:
    """Real (x, y, φ), φ in (-π, π]: sign changes of the leg-1 residual over a grid of φ,
    each refined by bisection to 50 digits and checked on all three legs."""
    grid = [-mp.pi + 2 * mp.pi * k / steps for k in range(steps + 1)]
    values = [_rpr_position(r, phi)[1] for phi in grid]
    roots = 0
    for k in range(steps):
        if values[k] == 0 or values[k] * values[k + 1] > 0:
            assert values[k] != 0
            continue
        lo, hi, flo = grid[k], grid[k + 1], values[k]
        for _ in range(170):
            mid = (lo + hi) / 2
            fmid = _rpr_position(r, mid)[1]
            if fmid * flo > 0:
                lo, flo = mid, fmid
            else:
                hi = mid
        (x, y), _, det = _rpr_position(r, lo)
        assert abs(det) > TINY
        for w, q in _rpr_legs(r, lo):
            assert abs((x + w[0]) ** 2 + (y + w[1]) ** 2 - q) < mp.mpf(10) ** -40
        roots += 1
    return roots


def _neighbours_differ(analysis) -> bool:
    """Some two cells of one column, next to each other (one wall between them), have
    different counts: a region whose count differs from its neighbour's."""
    by_index = {c.cell.index: c.count for c in analysis.cells}
    for index, count in by_index.items():
        above = (*index[:-1], index[-1] + 1)
        if above in by_index and by_index[above] != count:
            return True
    return False


def _jointspace(name: str, backend, fixed: dict):
    model = build_model(load_robot(ROBOTS / f"{name}.yaml"))
    components = jointspace_variety(model, backend)
    free = len(model.joints) - len(fixed)
    components, _ = select_surfaces(components, JOINTSPACE, "counts", free)
    return model, analyse(JOINTSPACE, model, components, fixed)


def _check(model, analysis, fixed: dict, oracle) -> None:
    """Every cell's count is the oracle's at its sample (joints in the chart's order)."""
    assert analysis.cells and all(c.count is not None for c in analysis.cells)
    for c in analysis.cells:
        values = dict(zip(analysis.axes, c.cell.sample, strict=True)) | fixed
        point = [values[a] for a in space_chart(model, JOINTSPACE).axes]
        assert c.count == oracle(point), (c.cell.sample, c.count)
    for r in analysis.regions.regions:
        assert analysis.region_count(r.number) is not None
    assert _neighbours_differ(analysis)


def test_linear_delta_joint_space_counts_match_three_spheres():
    fixed = {"r3": Fraction(-1)}
    model, analysis = _jointspace("linear-delta", get_backend("flint"), fixed)
    _check(model, analysis, fixed, _linear_delta_count)
    assert {c.count for c in analysis.cells if c.within_limits} == {0, 2}


def test_rotary_delta_joint_space_counts_match_three_spheres():
    fixed = {"tan(th3/2)": Fraction(0)}
    model, analysis = _jointspace("rotary-delta", _backend("singular"), fixed)
    assert analysis.axes == ("tan(th1/2)", "tan(th2/2)")
    _check(model, analysis, fixed, _rotary_delta_count)
    assert {c.count for c in analysis.cells if c.within_limits} == {0, 2}


@pytest.mark.slow
def test_3rpr_joint_space_counts_match_a_scan_of_the_orientation():
    fixed = {"r2": Fraction(9, 2), "r3": Fraction(7, 2)}
    model, analysis = _jointspace("3-rpr", _backend("singular"), fixed)
    _check(model, analysis, fixed, _rpr_count)
    assert {c.count for c in analysis.cells if c.within_limits} == {0, 2, 4}


def test_direct_kinematics_counts_only_the_robots_own_square_root():
    # the linear Delta at r = (1, 1, -1): two poses; its conjugate (√3 ↦ -√3) has two
    # more, which the count leaves out
    model = build_model(load_robot(ROBOTS / "linear-delta.yaml"))
    assert _linear_delta_count((1, 1, -1)) == 2
    assert direct_kinematics_count(model, (1, 1, -1)).count == 2
    assert _linear_delta_count((3, -3, 3)) == 0
    assert direct_kinematics_count(model, (3, -3, 3)).count == 0


def test_direct_kinematics_counts_poses_with_an_angle():
    model = build_model(load_robot(ROBOTS / "3-rpr.yaml"))
    for r in ((3, 3, 3), (5, 3, 2), (Fraction(1, 2), Fraction(9, 2), Fraction(7, 2))):
        assert direct_kinematics_count(model, r).count == _rpr_count(r, 512), r


def test_a_direct_kinematics_beyond_reach_is_refused_in_one_line():
    result = singcheck("jointspace", str(ROBOTS / "gough-stewart.yaml"), "--backend", "flint",
                       "-q", "--slice", "r1=2", "--slice", "r2=2", "--slice", "r3=2")
    assert result.returncode == 2
    assert "Bézout bound" in result.stderr and len(result.stderr.strip().splitlines()) == 1
