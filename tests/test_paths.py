"""Paths as people have them: segments, waypoints (linear, cubic spline), CSV, k·π·t.

Every singular time is checked against an independent computation written here: the
pieces' polynomials (the straight lines, or the natural cubic spline solved with SymPy
from its defining conditions), and det A along the Orthoglide's working mode +++
evaluated with 50-digit mpmath, its sign changes refined by mpmath's root finder.
"""

from __future__ import annotations

import json
from fractions import Fraction

import mpmath
import pytest
import sympy

from singcheck.certify.pieces import certify_trajectory
from singcheck.errors import SpecError
from singcheck.spec.files import load_trajectory, parse_robot, parse_trajectory
from tests.conftest import ROBOTS
from tests.test_cli import singcheck

mpmath.mp.dps = 50

WAYPOINTS = [(0, "1/4", "3/5"), (1, "9/10", "11/10"), (2, "6/5", "3/10")]  # z = 1

LINEAR_YAML = """\
name: through-waypoints
parameter: t
interpolation: {kind}
waypoints:
  - {{t: 0, x: 1/4, y: 3/5, z: 1}}
  - {{t: 1, x: 9/10, y: 11/10, z: 1}}
  - {{t: 2, x: 6/5, y: 3/10, z: 1}}
"""

SEGMENTS_YAML = """\
name: pick-and-place
parameter: t
segments:
  - range: [0, 1]
    pose: {x: 1/4 + 13/20*t, y: 3/5 + 1/2*t, z: 1}
  - range: [1, 2]
    pose: {x: 3/5 + 3/10*t, y: 19/10 - 4/5*t, z: 1}
"""

CSV = "t,x,y,z\n0,0.25,0.6,1\n1,0.9,1.1,1\n2,1.2,0.3,1\n"


# ---------------------------------------------------------------------------------
# the independent computation


def _linear_pieces():
    """[(t0, t1, [x(t), y(t), z(t)])] as SymPy expressions: the straight lines."""
    t = sympy.Symbol("t")
    out = []
    for (t0, x0, y0), (t1, x1, y1) in zip(WAYPOINTS, WAYPOINTS[1:], strict=False):
        x0, y0, x1, y1 = map(sympy.Rational, (x0, y0, x1, y1))
        out.append((t0, t1, [x0 + (x1 - x0) * (t - t0) / (t1 - t0),
                             y0 + (y1 - y0) * (t - t0) / (t1 - t0), sympy.Integer(1)]))
    return out


def _natural_spline(ts, ys):
    """The natural cubic spline from its conditions (interpolation, C¹, C², S'' = 0 at the
    ends), solved exactly by SymPy; one expression per interval."""
    t = sympy.Symbol("t")
    n = len(ts) - 1
    cs = sympy.symbols(f"a0:{4 * n}")
    piece = [sum(cs[4 * i + k] * t ** k for k in range(4)) for i in range(n)]
    eqs = []
    for i in range(n):
        eqs += [piece[i].subs(t, ts[i]) - ys[i], piece[i].subs(t, ts[i + 1]) - ys[i + 1]]
    for i in range(n - 1):
        for d in (1, 2):
            eqs.append(sympy.diff(piece[i], t, d).subs(t, ts[i + 1])
                       - sympy.diff(piece[i + 1], t, d).subs(t, ts[i + 1]))
    eqs += [sympy.diff(piece[0], t, 2).subs(t, ts[0]),
            sympy.diff(piece[-1], t, 2).subs(t, ts[-1])]
    sol = sympy.solve(eqs, cs, dict=True)[0]
    return [sympy.expand(p.subs(sol)) for p in piece]


def _cubic_pieces():
    ts = [sympy.Integer(w[0]) for w in WAYPOINTS]
    xs = _natural_spline(ts, [sympy.Rational(w[1]) for w in WAYPOINTS])
    ys = _natural_spline(ts, [sympy.Rational(w[2]) for w in WAYPOINTS])
    return [(ts[i], ts[i + 1], [xs[i], ys[i], sympy.Integer(1)]) for i in range(len(xs))]


def _det_a_plus(x, y, z):
    """det A / 8 of the Orthoglide (l = 2) along mode +++: x − ρ₁ = −√(4 − y² − z²), …"""
    a = -mpmath.sqrt(4 - y ** 2 - z ** 2)
    b = -mpmath.sqrt(4 - x ** 2 - z ** 2)
    c = -mpmath.sqrt(4 - x ** 2 - y ** 2)
    return mpmath.det(mpmath.matrix([[a, y, z], [x, b, z], [x, y, c]]))


def singular_times(pieces, samples: int = 300) -> list:
    """Roots of det A along +++ on each piece: sign changes on a grid, refined (50 digits)."""
    t = sympy.Symbol("t")
    roots = []
    for t0, t1, coords in pieces:
        fs = [sympy.lambdify(t, c, "mpmath") for c in coords]

        def g(s, fs=fs):
            return _det_a_plus(*(f(s) for f in fs))

        grid = [mpmath.mpf(t0) + (mpmath.mpf(t1) - t0) * k / samples for k in range(samples + 1)]
        values = [g(s) for s in grid]
        for a, b, va, vb in zip(grid, grid[1:], values, values[1:], strict=False):
            if va == 0:
                roots.append(a)
            elif va * vb < 0:
                roots.append(mpmath.findroot(g, (a, b), solver="anderson"))
    return roots


def _assert_matches(report, expected):
    real = [c for c in report.candidates if c.status == "real"]
    assert len(real) == len(expected), ([float(c.t.mid()) for c in real], expected)
    for c, root in zip(real, expected, strict=True):
        assert c.singular_modes == ["+++"]
        lo, hi = float(c.t.lower()), float(c.t.upper())
        assert lo - 1e-12 <= float(root) <= hi + 1e-12, (lo, hi, root)


# ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def robot_spec(orthoglide):
    return orthoglide.spec


def _certify(projection, text, robot, path="p.yaml"):
    return certify_trajectory(projection, parse_trajectory(text, path, robot))


def test_linear_waypoints_segments_and_csv_agree_with_the_independent_times(
        orthoglide_projection, robot_spec, tmp_path):
    expected = singular_times(_linear_pieces())
    assert len(expected) == 2  # one on each piece: the test exercises both
    csv = tmp_path / "path.csv"
    csv.write_text(CSV)
    reports = [
        _certify(orthoglide_projection, LINEAR_YAML.format(kind="linear"), robot_spec),
        _certify(orthoglide_projection, SEGMENTS_YAML, robot_spec),
        certify_trajectory(orthoglide_projection,
                           load_trajectory(csv, robot_spec, "linear")),
    ]
    for report in reports:
        assert report.verdict == "singular"
        assert [m.label for m in report.modes if m.feasible] == ["+++"]
        _assert_matches(report, expected)
        assert [c.segment for c in report.candidates] == [1, 2]
        assert len(report.pieces) == 2


def test_cubic_spline_agrees_with_the_independent_spline_and_times(orthoglide_projection,
                                                                   robot_spec):
    pieces = _cubic_pieces()
    spec = parse_trajectory(LINEAR_YAML.format(kind="cubic"), "p.yaml", robot_spec)
    t, u = sympy.symbols("t u")
    for (t0, _, coords), piece in zip(pieces, spec.pieces, strict=True):
        assert piece.time_offset == t0  # each piece is written in u = t - t0
        for v, expr in zip("xyz", coords, strict=True):
            mine = {e[0]: Fraction(int(c.p), int(c.q)) for e, c in piece.pose[v].terms()}
            local = sympy.expand(expr.subs(t, u + t0))
            theirs = {k: Fraction(str(c)) for (k,), c in sympy.Poly(local, u).terms() if c}
            assert mine == theirs, v
    report = certify_trajectory(orthoglide_projection, spec)
    _assert_matches(report, singular_times(pieces))


def test_the_default_interpolation_is_cubic(robot_spec):
    text = LINEAR_YAML.format(kind="cubic").replace("interpolation: cubic\n", "")
    spec = parse_trajectory(text, "p.yaml", robot_spec)
    assert spec.pieces[0].pose["x"].degrees()[0] == 3


def test_pi_t_arguments_are_rescaled_exactly(orthoglide_projection, robot_spec):
    text = """\
name: heart-in-pi-t
parameter: t
range: [-1, 1]
pose:
  x: 8/7*sin(pi*t)^3
  y: 13/14*cos(pi*t) - 5/14*cos(2*pi*t) - 1/10*cos(3*pi*t) - 1/14*cos(4*pi*t)
  z: 1
"""
    spec = parse_trajectory(text, "p.yaml", robot_spec)
    assert spec.time_scale == 1 and str(spec.global_range) == "[-1, 1]"
    report = certify_trajectory(orthoglide_projection, spec)
    t = sympy.Symbol("t")
    pi_t = sympy.pi * t
    coords = [sympy.Rational(8, 7) * sympy.sin(pi_t) ** 3,
              sympy.Rational(13, 14) * sympy.cos(pi_t) - sympy.Rational(5, 14) * sympy.cos(2 * pi_t)
              - sympy.Rational(1, 10) * sympy.cos(3 * pi_t) - sympy.Rational(1, 14)
              * sympy.cos(4 * pi_t), sympy.Integer(1)]
    expected = singular_times([(-1, 1, coords)], samples=400)
    assert len(expected) == 2
    _assert_matches(report, expected)


def test_cos_2_pi_t_on_a_unit_range(orthoglide_projection, robot_spec):
    text = ("name: circle\nparameter: t\nrange: [0, 1]\n"
            "pose: {x: 1/2*cos(2*pi*t), y: 1/2*sin(2*pi*t), z: 1}\n")
    spec = parse_trajectory(text, "p.yaml", robot_spec)
    assert spec.time_scale == 2
    report = certify_trajectory(orthoglide_projection, spec)
    t = sympy.Symbol("t")
    circle = [sympy.cos(2 * sympy.pi * t) / 2, sympy.sin(2 * sympy.pi * t) / 2, sympy.Integer(1)]
    assert singular_times([(0, 1, circle)]) == []
    assert report.verdict == "singularity-free"


def test_a_root_at_a_join_is_counted_once(orthoglide_projection, robot_spec):
    # (2/3, 4/3, 4/3) lies on the sphere x² + y² + z² = 4, a factor of ξ
    assert Fraction(2, 3) ** 2 + 2 * Fraction(4, 3) ** 2 == 4
    text = """\
name: through-the-sphere
parameter: t
interpolation: linear
waypoints:
  - {t: 0, x: 1/3, y: 2/3, z: 2/3}
  - {t: 1, x: 2/3, y: 4/3, z: 4/3}
  - {t: 2, x: 1/2, y: 3/2, z: 1}
"""
    report = _certify(orthoglide_projection, text, robot_spec)
    at_join = [c for c in report.candidates if c.t.contains(1)]
    assert len(at_join) == 1 and at_join[0].segment == 1


RAIL = """\
name: rail
joints: [p, q]
pose: [x, y]
constraints:
  - (x - p)^2 + y^2 - 4
  - y - q
joint_limits: {p: [0, 4]}
"""


def test_a_path_whose_feasible_mode_changes_at_a_join():
    from singcheck import api

    robot = api.robot_from_spec(parse_robot(RAIL, "rail.yaml"), "sympy", cache=False)
    text = ("name: across\nparameter: t\ninterpolation: linear\nwaypoints:\n"
            "  - {t: 0, x: 1, y: 1}\n  - {t: 1, x: 2, y: 1}\n  - {t: 2, x: 3, y: 1}\n")
    spec = parse_trajectory(text, "p.yaml", robot.spec)
    report = api.check(robot, spec, regions=False)
    # independently: p = x ± √3 with y = 1; "+" stays in [0, 4] while x ≤ 4 − √3 ≈ 2.27,
    # "-" while x ≥ √3 ≈ 1.73: x ∈ [1, 2] allows only "+", x ∈ [2, 3] only "-".
    root3 = mpmath.sqrt(3)
    assert 1 + root3 <= 4 and 1 - root3 < 0 and 3 + root3 > 4 and 2 - root3 >= 0
    pieces = report.certificate.pieces
    assert [[m.label for m in r.modes if m.feasible] for r in pieces] == [["+o"], ["-o"]]
    assert report.verdict == "infeasible"
    assert "changes at the join of segments 1 and 2" in report.reason


def test_a_jump_at_a_join_is_an_error_naming_both_segments(tmp_path):
    bad = tmp_path / "jump.yaml"
    bad.write_text(SEGMENTS_YAML.replace("19/10 - 4/5*t", "2 - 4/5*t"))
    out = singcheck("run", str(ROBOTS / "orthoglide.yaml"), str(bad), "--backend", "sympy")
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{bad}:6" in lines[0]
    assert "segments 1 and 2" in lines[0] and "jumps" in lines[0]


@pytest.mark.parametrize("text, line, words", [
    ("t,x,y\n0,1,1\n1,1,1\n", 1, "missing column(s) z"),
    ("t,x,y,z\n0,1,1,1\n1,one,1,1\n", 3, "'one' is not a number"),
    ("t,x,y,z\n0,1,1,1\n", 2, "at least two"),
])
def test_bad_csv_is_one_located_line_and_exit_2(tmp_path, text, line, words):
    bad = tmp_path / "bad.csv"
    bad.write_text(text)
    out = singcheck("run", str(ROBOTS / "orthoglide.yaml"), str(bad), "--backend", "sympy")
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{bad}:{line}:" in lines[0] and words in lines[0], lines


def test_csv_decimals_are_exact(robot_spec, tmp_path):
    csv = tmp_path / "p.csv"
    csv.write_text("t,x,y,z\n0,0.1,0.3,1\n0.5,0.2,0.3,1\n")
    spec = load_trajectory(csv, robot_spec, "linear")
    x = spec.pieces[0].pose["x"]  # 0.1 + (0.2 - 0.1)/0.5 * t, exactly
    assert {e[0]: Fraction(int(c.p), int(c.q)) for e, c in x.terms()} == \
        {0: Fraction(1, 10), 1: Fraction(1, 5)}


def test_segment_errors(robot_spec):
    gap = SEGMENTS_YAML.replace("range: [1, 2]", "range: [3/2, 2]")
    with pytest.raises(SpecError, match="consecutive"):
        parse_trajectory(gap, "p.yaml", robot_spec)
    empty = SEGMENTS_YAML.replace("range: [1, 2]", "range: [1, 1]")
    with pytest.raises(SpecError, match="empty range"):
        parse_trajectory(empty, "p.yaml", robot_spec)
    with pytest.raises(SpecError, match="not allowed with segments"):
        parse_trajectory(SEGMENTS_YAML + "range: [0, 1]\n", "p.yaml", robot_spec)


def test_joins_of_trig_segments_are_checked_exactly(robot_spec):
    # cos(pi*t) at t = 1/3 is 1/2 exactly; sin(pi*t) there is √3/2, not 0.866
    ok = """\
name: arc-then-line
parameter: t
segments:
  - range: [0, 1/3]
    pose: {x: cos(pi*t), y: 0, z: 1}
  - range: [1/3, 1]
    pose: {x: 1/2 + t - 1/3, y: 0, z: 1}
"""
    assert len(parse_trajectory(ok, "p.yaml", robot_spec).pieces) == 2
    bad = ok.replace("x: cos(pi*t)", "x: sin(pi*t)").replace("1/2 + t", "433/500 + t")
    with pytest.raises(SpecError, match="jumps between segments 1 and 2"):
        parse_trajectory(bad, "p.yaml", robot_spec)


def test_json_gains_segments_and_keeps_schema_1(tmp_path):
    path = tmp_path / "w.yaml"
    path.write_text(LINEAR_YAML.format(kind="linear"))
    out = singcheck("run", str(ROBOTS / "orthoglide.yaml"), str(path), "--format", "json",
                    "--backend", "sympy")
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["schema_version"] == 1
    t = doc["trajectories"][0]
    assert t["range"] == ["0", "2"]
    assert [s["range"] for s in t["segments"]] == [["0", "1"], ["1", "2"]]
    assert {s["root_isolation"] for s in t["segments"]} == {"exact univariate"}
    assert [c["segment"] for c in t["candidates"]] == [1, 2]
    for key in ("candidates", "working_modes", "verdict", "root_isolation", "undecided"):
        assert key in t


def test_plot_marks_the_joins_of_a_multi_piece_path(orthoglide_projection, robot_spec,
                                                    tmp_path):
    from singcheck.report.plots import figure_data, write_figures

    report = _certify(orthoglide_projection, LINEAR_YAML.format(kind="linear"), robot_spec)
    d = figure_data(report, samples=400)
    assert float(d.t[0]) == 0 and float(d.t[-1]) == 2
    assert [j["t"] for j in d.joins] == [1.0]
    assert d.joins[0]["pose"] == pytest.approx([0.9, 1.1, 1.0])  # the middle waypoint
    written = write_figures(report, tmp_path)
    assert {p.name for p in written} >= {"through-waypoints-mu.png",
                                         "through-waypoints-workspace.svg"}


def test_quick_root_exclusion_on_a_rational_range():
    from flint import fmpq, fmpq_poly

    from singcheck.roots.rational import no_root_between, nonzero_on

    p = fmpq_poly([2, -7, 3])  # 3t² − 7t + 2 = (3t − 1)(t − 2): roots 1/3 and 2
    for a, b, free in [(0, fmpq(1, 4), True), (fmpq(1, 2), fmpq(3, 2), True),
                       (0, 1, False), (fmpq(1, 3), 1, False), (1, 3, False)]:
        assert no_root_between(p, fmpq(a), fmpq(b)) is free
        assert not (nonzero_on(p, fmpq(a), fmpq(b)) and not free)  # never a false "free"


def test_run_reads_a_csv_with_the_interpolation_asked(tmp_path):
    csv = tmp_path / "path.csv"
    csv.write_text(CSV)
    expected = {"linear": singular_times(_linear_pieces()),
                "cubic": singular_times(_cubic_pieces())}
    for kind, roots in expected.items():
        out = singcheck("run", str(ROBOTS / "orthoglide.yaml"), str(csv), "--format", "json",
                        "--backend", "sympy", "--interpolation", kind)
        assert out.returncode == 1, out.stderr
        found = [c["t_interval"] for c in json.loads(out.stdout)["trajectories"][0]
                 ["candidates"] if c["status"] == "real"]
        assert len(found) == len(roots)
        for (lo, hi), root in zip(found, roots, strict=True):
            assert lo - 1e-12 <= float(root) <= hi + 1e-12, kind


def test_a_serial_singularity_at_a_join_breaks_every_mode():
    from singcheck import api

    robot = api.robot_from_spec(parse_robot(RAIL, "rail.yaml"), "sympy", cache=False)
    text = ("name: touch\nparameter: t\ninterpolation: linear\nwaypoints:\n"
            "  - {t: 0, x: 1, y: 1}\n  - {t: 1, x: 1, y: 2}\n  - {t: 2, x: 3/2, y: 1}\n")
    # independently: leg p's discriminant 4 − y² vanishes exactly at the join (y = 2)
    assert 4 - Fraction(2) ** 2 == 0
    report = api.check(robot, parse_trajectory(text, "p.yaml", robot.spec), regions=False)
    assert report.verdict == "infeasible"
    assert not [m for m in report.working_modes if m.feasible]
    assert all("meet at t ≈ 1" in m.reason for m in report.working_modes)


def test_csv_with_a_byte_order_mark_and_huge_exponents(robot_spec, tmp_path):
    bom = tmp_path / "bom.csv"
    bom.write_bytes("\ufefft,x,y,z\n0,0.5,0.5,1\n1,0.6,0.5,1\n".encode())
    assert len(load_trajectory(bom, robot_spec).pieces) == 1
    huge = tmp_path / "huge.csv"
    huge.write_text("t,x,y,z\n0,1e99999999,0.5,1\n1,0.6,0.5,1\n")
    with pytest.raises(SpecError, match=r"huge.csv:2: x: .*too large"):
        load_trajectory(huge, robot_spec)
    text = "name: a\nparameter: t\nrange: [0, 1]\npose: {x: 1e99999999*t, y: 0, z: 1}\n"
    with pytest.raises(SpecError, match="too large"):  # refused before 10^e is built
        parse_trajectory(text, "a.yaml", robot_spec)


def test_the_workspace_statement_covers_every_piece(orthoglide_projection, robot_spec):
    from singcheck.spaces.path_regions import XI, pieces_in_workspace

    report = _certify(orthoglide_projection, LINEAR_YAML.format(kind="linear"), robot_spec)
    w = pieces_in_workspace(report)
    roots = singular_times(_linear_pieces())
    assert [c.surfaces for c in w.crossings] == [(XI,)] * 2  # only the two μ roots
    for c, root in zip(w.crossings, roots, strict=True):
        assert float(c.t.lower()) - 1e-12 <= float(root) <= float(c.t.upper()) + 1e-12
    assert [s.count for s in w.stretches] == [1, 1, 1]  # one stretch across the join


def test_a_crossing_exactly_at_a_join_is_counted_once():
    from singcheck import api

    robot = api.robot_from_spec(parse_robot(RAIL, "rail.yaml"), "sympy", cache=False)
    text = ("name: touch\nparameter: t\ninterpolation: linear\nwaypoints:\n"
            "  - {t: 0, x: 1, y: 1}\n  - {t: 1, x: 1, y: 2}\n  - {t: 2, x: 3/2, y: 1}\n")
    report = api.check(robot, parse_trajectory(text, "p.yaml", robot.spec))
    crossings = report.to_dict()["workspace"]["crossings"]
    # independently: 4 − y² = 0 only at y = 2, i.e. t = 1 exactly, on both pieces
    at_join = [c for c in crossings if c["t_interval"][0] <= 1 <= c["t_interval"][1]]
    assert len(at_join) == 1 and "serial singularity of leg p" in at_join[0]["surfaces"]


def test_pieces_compose_with_multi_document_files(orthoglide_projection, robot_spec):
    from singcheck.spec.files import parse_trajectories

    text = LINEAR_YAML.format(kind="linear") + "---\n" + SEGMENTS_YAML
    specs = list(parse_trajectories(text, "two.yaml", robot_spec))
    assert [len(s.pieces) for s in specs] == [2, 2]
    reports = [certify_trajectory(orthoglide_projection, s) for s in specs]
    expected = singular_times(_linear_pieces())
    for report in reports:  # the same path, written two ways
        _assert_matches(report, expected)
    jump = text.replace("19/10 - 4/5*t", "2 - 4/5*t")
    with pytest.raises(SpecError, match=r"two.yaml:\d+: y: the pose jumps .*\(document 2\)"):
        list(parse_trajectories(jump, "two.yaml", robot_spec))


def test_project_prints_one_piece_in_its_own_time(tmp_path):
    path = tmp_path / "w.yaml"
    path.write_text(LINEAR_YAML.format(kind="cubic"))
    robot = str(ROBOTS / "orthoglide.yaml")
    out = singcheck("project", robot, str(path), "--no-epsilon", "--backend", "sympy")
    assert out.returncode == 2 and "--segment" in out.stderr
    out = singcheck("project", robot, str(path), "--no-epsilon", "--backend", "sympy",
                    "--segment", "2")
    assert out.returncode == 0, out.stderr
    assert "u = t - 1" in out.stderr
    line = next(x for x in out.stdout.splitlines() if x.startswith("x(t) = "))
    t, u = sympy.symbols("t u")
    t0, _, coords = _cubic_pieces()[1]
    printed = sympy.sympify(line.split("=", 1)[1].replace("^", "**"), locals={"t": u})
    assert sympy.expand(printed - coords[0].subs(t, u + t0)) == 0
