"""Workspace / joint-space analysis: open CAD, exact counts, regions, the path's region."""

from __future__ import annotations

import json
import math
from fractions import Fraction

import mpmath
import pytest
from flint import fmpq, fmpq_mpoly_ctx, fmpq_poly

from singcheck.spaces.analysis import (
    JOINTSPACE,
    LIMIT,
    WORKSPACE,
    SliceError,
    analyse,
    jointspace_variety,
    select_surfaces,
    workspace_variety,
)
from singcheck.spaces.cad import open_cad, simplest_between
from singcheck.spaces.regions import connect_regions
from singcheck.spaces.solution_counts import direct_kinematics_count, inverse_kinematics_count
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_cli import singcheck

XY = fmpq_mpoly_ctx.get(("x", "y"), "lex")
X, Y = XY.gens()


# -- the decomposition --------------------------------------------------------------


@pytest.mark.parametrize(("lo", "hi", "simplest"), [
    (Fraction(1, 3), Fraction(1, 2), Fraction(2, 5)),
    (Fraction(2), Fraction(3), Fraction(5, 2)),
    (Fraction(-5, 2), Fraction(-2), Fraction(-7, 3)),
    (Fraction(-1), Fraction(1), Fraction(0)),
    (None, Fraction(-3, 2), Fraction(-2)),
])
def test_simplest_rational_between(lo, hi, simplest):
    assert simplest_between(lo, hi) == simplest


def test_circle_and_line_cells_avoid_the_curves():
    cad = open_cad([X**2 + Y**2 - 1, Y - X])
    # critical x: ±1, ±1/√2 → 5 columns with 2, 4, 4, 4, 2 sectors
    assert len(cad.cells) == 16
    for cell in cad.cells:
        x, y = cell.sample
        assert x * x + y * y != 1 and y != x


@pytest.mark.parametrize(("curve", "regions", "proven"), [
    # two ovals of one irreducible curve: the outside and each oval (same signs inside,
    # told apart by the exact adjacency at the critical values)
    (Y**2 - (X**2 - 1) * (4 - X**2), 3, True),
    # a lemniscate: the outside and two lobes, which touch only at the node
    ((X**2 + Y**2)**2 - 2 * (X**2 - Y**2), 3, True),
    # a cusp y² = x³: inside and outside
    (Y**2 - X**3, 2, True),
    # two circles tangent at (1, 0): two insides and the outside
    ((X**2 + Y**2 - 1) * ((X - 2)**2 + Y**2 - 1), 3, True),
    # y² = x²(x - 1): the isolated point at the origin does not cut the outside
    (Y**2 - X**2 * (X - 1), 2, True),
    # two lines crossing at x = -27/8, a critical value that bisection meets exactly
    ((Y + 2) * (8 * X - 6 * Y + 15), 4, True),
    # two concentric circles cut by a line: 6 components, all with distinct signs
    ((X**2 + Y**2 - 1) * (X**2 + Y**2 - 9) * (X - Y), 6, True),
    # a grid of lines x = ±√3, y = ±√3: 9 components; the four corners share their
    # signs, but lie on different sides of the walls
    ((X**2 - 3) * (Y**2 - 3), 9, True),
])
def test_regions_are_the_connected_components(curve, regions, proven):
    result = connect_regions(open_cad([curve]))
    assert len(result.regions) == regions
    assert result.components_proven is proven


# g = (x - 1)(x - 2)…(x - 10) + 1/10 is irreducible with ten simple real roots r₁ < … <
# r₁₀ near 1, …, 10 (|∏(x - i)| is at least 1 at every local extremum, so adding 1/10
# moves no root past one): every critical value below is a root of g, of degree 10
G10 = math.prod((X - i for i in range(1, 11)), start=XY.from_dict({(0, 0): 1})) + fmpq(1, 10)


@pytest.mark.parametrize(("curve", "regions"), [
    # y² = g: g > 0 on (r₂, r₃), (r₄, r₅), (r₆, r₇), (r₈, r₉): 4 ovals; left of r₁ and
    # right of r₁₀ two branches, each bounding one region; and the outside: 7
    (Y**2 - G10, 7),
    # y² = -g: 5 ovals (on (r₁, r₂), …, (r₉, r₁₀)) and the outside: 6
    (Y**2 + G10, 6),
    # the same ovals and branches of y² = g cut by the axis y = 0 (meeting it at each
    # double root): each of the 7 split in an upper and a lower half: 14
    ((Y**2 - G10) * Y, 14),
    # the graph y = g crossing the axis at r₁, …, r₁₀: above both, below both, the 9
    # lenses between them and the two ends: 13
    ((Y - G10) * Y, 13),
    # y = g, y = -g and y = 0 all through each (r_i, 0): in each half-plane the region
    # above |g| and one between the axis and |g| per interval (11): 24
    ((Y - G10) * (Y + G10) * Y, 24),
])
def test_regions_are_the_components_at_critical_values_of_degree_10(curve, regions):
    from singcheck.spaces.cad import fiber
    from singcheck.spaces.plane_adjacency import minimal_polynomial

    cad = open_cad([curve])
    base = fiber(cad.levels, cad.variables, ())
    assert {minimal_polynomial(r).degree() for r in base} == {10}
    result = connect_regions(cad)
    assert len(result.regions) == regions
    assert result.components_proven  # same signs everywhere inside the ovals: only the
    # exact adjacency proves them apart


XYZ = fmpq_mpoly_ctx.get(("x", "y", "z"), "lex")
X3, Y3, Z3 = XYZ.gens()


@pytest.mark.parametrize(("surfaces", "regions", "proven"), [
    # a sphere cut by a plane: the two half-balls and the two outer half-spaces
    ([X3**2 + Y3**2 + Z3**2 - 1, Z3], 4, True),
    # a torus: inside the tube and outside (joined around the hole, across columns)
    ([(X3**2 + Y3**2 + Z3**2 + 3)**2 - 16 * (X3**2 + Y3**2)], 2, True),
    # a cylinder through a sphere: in both, in the cylinder above / below the sphere,
    # the shell between them, outside both; above and below share their signs
    ([X3**2 + Y3**2 - 1, X3**2 + Y3**2 + Z3**2 - 4], 5, False),
])
def test_regions_in_three_dimensions(surfaces, regions, proven):
    result = connect_regions(open_cad(surfaces))
    assert len(result.regions) == regions
    assert result.components_proven is proven


def test_a_count_that_differs_separates_regions_with_the_same_signs():
    # in 3-D (no exact adjacency): the two ovals turned round the x axis, one
    # irreducible surface with the same sign inside both
    cad = open_cad([Y3**2 + Z3**2 - (X3**2 - 1) * (4 - X3**2)])
    plain = connect_regions(cad)
    assert len(plain.regions) == 3 and not plain.components_proven
    # an invariant (a solution count) that differs between the two proves them apart
    count = {c.index: int(c.sample[0] > 0) for r in plain.regions for c in r.cells}
    assert connect_regions(cad, count).components_proven


def test_brackets_step_around_a_critical_value_met_exactly():
    from singcheck.roots.rational import RationalRoot
    from singcheck.spaces.regions import _brackets

    alpha = Fraction(-27, 8)  # the midpoint of the isolating interval: bisection finds it
    root = RationalRoot(fmpq_poly([27, 8]), fmpq(-7, 2), fmpq(-13, 4))
    for round_ in range(3):
        a, b = _brackets([root], 0, round_)
        assert a < alpha < b


def test_fibre_over_a_critical_value_is_exact():
    from singcheck.spaces.cad import fiber
    from singcheck.spaces.plane_adjacency import WALL, fibre_points

    circle = open_cad([X**2 + Y**2 - 1])
    base = fiber(circle.levels, circle.variables, ())  # x = ±1
    (point,) = fibre_points(circle.factors, base[1])  # a double root: one point, y = 0
    assert point.contains(0)
    # √2 is a root of both the wall x² - 2 and the circle's discriminant: a wall
    walls = open_cad([X**2 - 2, X**2 + Y**2 - 2])
    base = fiber(walls.levels, walls.variables, ())
    assert all(fibre_points(walls.factors, r) == WALL for r in base)


# -- the paper's statements ---------------------------------------------------------


def _counts(analysis, inside_only=True) -> set:
    return {c.count for c in analysis.cells if c.within_limits or not inside_only}


def test_orthoglide_workspace_has_regions_with_1_and_8_ik_solutions(orthoglide_projection):
    model = orthoglide_projection.model
    components, left_out = select_surfaces(workspace_variety(orthoglide_projection),
                                           WORKSPACE, "auto", 3)
    assert left_out == ["ξ(X): some working mode is singular"]
    analysis = analyse(WORKSPACE, model, components)
    assert _counts(analysis) == {0, 1, 8}  # the paper's Fig. 1(b): 1 and 8, never 2
    eight = next(c for c in analysis.cells if c.count == 8)
    assert inverse_kinematics_count(model, eight.cell.sample) == 8


def test_orthoglide_without_limits_has_8_working_modes_and_2_assembly_modes(
        orthoglide, orthoglide_projection):
    ws = [c for c in workspace_variety(orthoglide_projection, parallel=False)
          if c.kind != LIMIT]
    assert max(_counts(analyse(WORKSPACE, orthoglide, ws, use_limits=False))) == 8
    from singcheck.elimination.cas import get_backend

    js = [c for c in jointspace_variety(orthoglide, get_backend("flint")) if c.kind != LIMIT]
    js, _ = select_surfaces(js, JOINTSPACE, "counts", 3)
    assert max(_counts(analyse(JOINTSPACE, orthoglide, js, use_limits=False))) == 2


def test_orthoglide_joint_space_has_a_region_with_2_dk_solutions(orthoglide):
    from singcheck.elimination.cas import get_backend

    components = jointspace_variety(orthoglide, get_backend("flint"))
    analysis = analyse(JOINTSPACE, orthoglide, components, {"rho3": Fraction(2)})
    inside = {analysis.region_count(c.region) for c in analysis.cells if c.within_limits}
    assert inside == {0, 2}
    assert all(c.count is not None for c in analysis.cells)


def test_ik_root_placement_against_the_limits(orthoglide):
    from singcheck.spaces.solution_counts import ik_root_placement

    # each leg: ρ = 1 ± √2, one root below 0 and one inside [0, 4]
    assert ik_root_placement(orthoglide, (1, 1, 1)) == ((1, 1, 0),) * 3
    # x = 5: leg 1 has ρ1 = 5 ± 2 (3 inside, 7 above); legs 2, 3 unreachable (x² > 4)
    assert ik_root_placement(orthoglide, (5, 0, 0)) == ((0, 1, 1), (0, 0, 0), (0, 0, 0))
    assert ik_root_placement(orthoglide, (1, 1, 1), use_limits=False) == ((0, 2, 0),) * 3


def test_direct_kinematics_counts(orthoglide):
    assert direct_kinematics_count(orthoglide, (1, 1, 1)).count == 2
    assert direct_kinematics_count(orthoglide, (4, 4, 4)).count == 0
    # three spheres with one centre: infinitely many poses, honestly undecided
    assert direct_kinematics_count(orthoglide, (0, 0, 0)).count is None


def _ik_count_mp(model, pose) -> int:
    """An independent count: 50-digit floats and the quadratic formula."""
    mpmath.mp.dps = 50
    x, y, z = (mpmath.mpf(q.numerator) / q.denominator for q in map(Fraction, pose))
    total = 1
    for i in range(3):
        rest = [v for j, v in enumerate((x, y, z)) if j != i]
        d = 4 - rest[0] ** 2 - rest[1] ** 2
        if d < 0:
            return 0
        own = (x, y, z)[i]
        total *= sum(1 for r in (own + mpmath.sqrt(d), own - mpmath.sqrt(d)) if 0 <= r <= 4)
    return total


def test_slice_counts_agree_with_an_independent_count(orthoglide_projection):
    model = orthoglide_projection.model
    analysis = analyse(WORKSPACE, model, workspace_variety(orthoglide_projection),
                       {"z": Fraction(1)})
    assert len(analysis.cells) > 50
    for c in analysis.cells:
        assert c.count == _ik_count_mp(model, (*c.cell.sample, 1))
    # every cell of one region has one count
    for r in analysis.regions.regions:
        assert analysis.region_count(r.number) is not None


def test_a_slice_inside_a_surface_is_refused(orthoglide):
    from singcheck.elimination.cas import get_backend

    components = jointspace_variety(orthoglide, get_backend("flint"))
    with pytest.raises(SliceError, match="lies inside the surface rho1 = 0"):
        analyse(JOINTSPACE, orthoglide, components, {"rho1": Fraction(0)})


# -- the trajectory and the regions ---------------------------------------------------


def _path(projection, name):
    from singcheck.certify.path import build_path
    from singcheck.spec.files import load_trajectory

    return build_path(projection, load_trajectory(TRAJECTORIES / f"{name}.yaml",
                                                  projection.model.spec))


def test_heart2_lies_in_one_named_region_heart1_crosses_xi(orthoglide_projection):
    from singcheck.spaces.path_regions import path_in_workspace

    heart2 = path_in_workspace(_path(orthoglide_projection, "heart2"))
    assert heart2.one_region is True
    assert heart2.region.startswith("R") and heart2.region.endswith("plane z = 1")
    assert [s.count for s in heart2.stretches] == [1]
    heart1 = path_in_workspace(_path(orthoglide_projection, "heart1"))
    assert heart1.one_region is False
    assert [c.surfaces for c in heart1.crossings] == [("parallel singularity ξ",)] * 4


def test_leaving_the_workspace_is_infeasible_with_a_certified_exit_time(
        orthoglide_projection):
    from singcheck.certify.classification import certify_path
    from singcheck.spaces.path_regions import path_in_workspace

    path = _path(orthoglide_projection, "leaves-workspace")
    assert certify_path(path).verdict == "infeasible"
    w = path_in_workspace(path)
    # leg 2 stops reaching at x² + z² = 4, i.e. 3 sin t = √3
    exact = mpmath.asin(1 / mpmath.sqrt(3))
    lo, hi = float(w.exit_time.lower()), float(w.exit_time.upper())
    assert lo <= exact <= hi and hi - lo < 1e-6
    assert w.stretches[0].count == 1 and w.stretches[1].count == 0


@pytest.mark.slow
def test_orthoglide_3d_workspace_has_one_region_with_1_and_one_with_8(orthoglide_projection):
    components, _ = select_surfaces(workspace_variety(orthoglide_projection), WORKSPACE,
                                    "auto", 3)
    analysis = analyse(WORKSPACE, orthoglide_projection.model, components)
    inside = [analysis.region_count(r.number) for r in analysis.regions.regions
              if analysis.region_count(r.number)]
    assert sorted(inside) == [1, 8]  # the paper's Fig. 1(b), as regions of the 3-D space
    # every two regions differ in a sign, a wall side or the legs' root placement
    assert analysis.regions.components_proven


@pytest.mark.slow
def test_helix_is_named_in_the_3d_workspace_and_the_map_is_cached(
        orthoglide_projection, tmp_path):
    from singcheck.spaces import path_regions
    from singcheck.spaces.region_map import RegionMapCache

    cache = RegionMapCache(tmp_path)
    helix = _path(orthoglide_projection, "helix")
    path_regions._SUBSPACES.clear()
    first = path_regions.path_in_workspace(helix, region_cache=cache)
    assert first.one_region and first.region.startswith("R")
    assert first.region.endswith("of the workspace cut by its serial-singularity and "
                                 "joint-limit surfaces only")
    (entry,) = (tmp_path / "regions").glob("*.json")
    path_regions._SUBSPACES.clear()
    assert path_regions.path_in_workspace(helix, region_cache=cache).region == first.region
    entry.write_text(entry.read_text().replace('"cells"', '"cels"'))  # damaged: recomputed
    path_regions._SUBSPACES.clear()
    assert path_regions.path_in_workspace(helix, region_cache=cache).region == first.region
    path_regions._SUBSPACES.clear()


# -- the command line -----------------------------------------------------------------


@pytest.mark.slow
def test_cli_workspace_slice_json():
    out = singcheck("workspace", str(ROBOTS / "orthoglide.yaml"), "--slice", "z=1",
                    "--backend", "flint", "--format", "json", "-q")
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["space"] == "workspace" and doc["slice"] == {"z": "1"}
    assert set(doc["counts"]) == {"0", "1", "8"}
    assert {c["kind"] for c in doc["discriminant_variety"]} == {
        "serial singularity", "parallel singularity", "joint limit"}
    assert all(c["region"] is not None for c in doc["cells"])


@pytest.mark.parametrize(("arg", "message"), [
    ("w=1", "w is not one of the axes"),
    ("z=pi", "must be rational"),
    ("z", "write AXIS=VALUE"),
])
def test_cli_bad_slices_exit_2(arg, message):
    out = singcheck("workspace", str(ROBOTS / "orthoglide.yaml"), "--slice", arg,
                    "--backend", "flint", "-q")
    assert out.returncode == 2
    assert message in out.stderr and "Traceback" not in out.stderr


@pytest.mark.slow
def test_cli_run_states_the_region():
    out = singcheck("run", str(ROBOTS / "orthoglide.yaml"),
                    str(TRAJECTORIES / "heart2.yaml"), "--backend", "flint", "-q")
    assert out.returncode == 0, out.stderr
    assert "the whole path lies in region R" in out.stdout


def test_region_figure_colours_by_exact_counts(orthoglide_projection, tmp_path):
    import numpy as np

    from singcheck.report.region_plots import (
        THIN,
        cell_images,
        label_points,
        write_region_figure,
    )

    analysis = analyse(WORKSPACE, orthoglide_projection.model,
                       workspace_variety(orthoglide_projection), {"z": Fraction(1)})
    image, regions, window = cell_images(analysis, size=240)
    assert set(np.unique(image).tolist()) == {0.0, 1.0, 8.0}  # no pixel left unknown
    assert regions.min() >= 1
    # a pixel's count is the independent count at its centre, wherever that count holds
    # half a pixel around it (the picture locates curves to a fraction of a pixel)
    x0, x1, y0, y1 = window
    xs, ys = np.linspace(x0, x1, 240), np.linspace(y0, y1, 240)
    hx, hy = (x1 - x0) / 478, (y1 - y0) / 478
    checked = 0
    for r in range(0, 240, 7):
        for c in range(0, 240, 7):
            around = {_ik_count_mp(orthoglide_projection.model,
                                   (Fraction(float(xs[c] + dx)), Fraction(float(ys[r] + dy)),
                                    Fraction(1)))
                      for dx in (-hx, 0, hx) for dy in (-hy, 0, hy)}
            if len(around) == 1:
                assert image[r, c] == around.pop(), (r, c)
                checked += 1
    assert checked > 1000
    # each label sits deep inside its region, where the independent count is the region's
    points = label_points(regions, window)
    inside = {c.region for c in analysis.cells if c.count}
    assert inside <= set(points)
    for number in inside:
        x, y, depth = points[number]
        assert depth >= THIN * 240, number  # none of the z = 1 regions with solutions is thin
        pose = (Fraction(x), Fraction(y), Fraction(1))
        assert _ik_count_mp(orthoglide_projection.model, pose) == analysis.region_count(number)
    # the heart-1 crescent regions R8, R10, R19, R20 around R9: labels apart from each other
    xy = np.array([points[n][:2] for n in inside])
    gaps = np.linalg.norm(xy[:, None] - xy[None], axis=-1) + np.eye(len(xy)) * 9
    assert gaps.min() > 0.3
    files = write_region_figure(analysis, tmp_path, size=240)
    assert [f.suffix for f in files] == [".png", ".svg"]
    assert files[0].read_bytes()[:4] == b"\x89PNG"
    svg = files[1].read_text()
    for label in ("parallel singularity: ξ(X)", "serial singularity: leg rho1",
                  "joint limit: rho1 = 0 (min)", "R9", "R21", "8 solutions"):
        assert label in svg, label


def test_cli_plot_regions_needs_a_plane(tmp_path):
    out = singcheck("plot", str(ROBOTS / "orthoglide.yaml"), "--regions", "workspace",
                    "--out", str(tmp_path), "--backend", "flint", "-q")
    assert out.returncode == 2
    assert "fix all but two with --slice" in out.stderr


def test_planar_robot_workspace_regions():
    from singcheck.elimination.cas import get_backend
    from singcheck.elimination.projection import project_robot
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    model = build_model(load_robot(ROBOTS / "skew-biglide.yaml"))
    projection = project_robot(model, get_backend("flint"))
    analysis = analyse(WORKSPACE, model, workspace_variety(projection))
    # two legs, two branches each: 4 IK solutions at most, every count in between met
    assert _counts(analysis) == {0, 1, 2, 4}
    assert analysis.regions is not None and len(analysis.regions.regions) > 10
    for r in analysis.regions.regions:
        assert analysis.region_count(r.number) is not None
    # spot check: a cell with 4 solutions, recounted from the leg polynomials
    four = next(c for c in analysis.cells if c.count == 4)
    assert inverse_kinematics_count(model, four.cell.sample) == 4
    assert inverse_kinematics_count(model, four.cell.sample, use_limits=False) == 4


@pytest.mark.slow
def test_cli_plot_slices_go_to_the_space_owning_their_axis(tmp_path):
    both = singcheck("plot", str(ROBOTS / "orthoglide.yaml"), "--regions", "workspace",
                     "--regions", "jointspace", "--slice", "z=1", "--slice", "rho3=2",
                     "--out", str(tmp_path), "--backend", "flint", "-q")
    assert both.returncode == 0, both.stderr
    assert sorted(p.name for p in tmp_path.glob("*.png")) == [
        "orthoglide-jointspace-rho3=2.png", "orthoglide-workspace-z=1.png"]
    wrong = singcheck("plot", str(ROBOTS / "orthoglide.yaml"), "--regions", "workspace",
                      "--slice", "rho3=2", "--out", str(tmp_path), "--backend", "flint", "-q")
    assert wrong.returncode == 2 and "rho3 is not an axis" in wrong.stderr


def test_a_plane_shared_by_several_paths_is_decomposed_once_up_front(orthoglide_projection):
    from singcheck.spaces import path_regions
    from singcheck.spec.files import load_trajectory

    specs = [load_trajectory(TRAJECTORIES / f"{n}.yaml", orthoglide_projection.model.spec)
             for n in ("heart1", "heart2", "helix")]
    notes: list[str] = []
    path_regions._SUBSPACES.clear()
    path_regions.prepare_region_maps(orthoglide_projection, specs, notify=notes.append)
    # the hearts share z = 1; the helix is alone in 3-D and left to its own run
    assert notes == ["decomposing the workspace (z = 1; 2-D) into regions, once"]
    heart2 = path_regions.path_in_workspace(_path(orthoglide_projection, "heart2"),
                                            notify=notes.append)
    assert heart2.region.startswith("R") and len(notes) == 1  # reused, not recomputed
    path_regions._SUBSPACES.clear()
