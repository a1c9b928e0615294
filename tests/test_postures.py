"""The robot drawn at its singular postures: which panels, and that every drawn point is
the spec's drawing at the model's joints and pose there, recomputed here independently
(the YAML read by PyYAML, its expressions by SymPy, the IK solved and evaluated with
50-digit mpmath)."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy
import yaml

from singcheck import api
from singcheck.report.postures import postures
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_revolute import CIRCLE
from tests.test_revolute import FIVE_BAR as FIVE_BAR_SPEC

CASES = [("orthoglide", "heart1"), ("skew-biglide", "skew-biglide-ellipse")]


@pytest.fixture(scope="module", params=CASES, ids=lambda c: c[1])
def case(request):
    robot_name, traj_name = request.param
    robot = api.load_robot(ROBOTS / f"{robot_name}.yaml", backend="flint", cache=False)
    traj = api.load_trajectory(TRAJECTORIES / f"{traj_name}.yaml", robot)
    report = api.check(robot, traj, regions=False).certificate
    return robot_name, traj_name, report


def _sympy(text, names):
    return sympy.parse_expr(str(text).replace("^", "**"), local_dict=names)


def _independent(robot_name, traj_name, mode, t):
    """The drawing's points at time t in working mode ``mode``, from the spec files."""
    mpmath.mp.dps = 50
    robot = yaml.safe_load((ROBOTS / f"{robot_name}.yaml").read_text())
    traj = yaml.safe_load((TRAJECTORIES / f"{traj_name}.yaml").read_text())
    names = {n: sympy.Symbol(n) for n in robot["joints"] + robot["pose"]}
    params = {sympy.Symbol(k): sympy.Rational(str(v)) for k, v in
              robot.get("parameters", {}).items()}
    tt = sympy.Symbol("t")
    values = {names[v]: sympy.N(_sympy(traj["pose"][v], {"t": tt}).subs(tt, mpmath.mpf(t)), 50)
              for v in robot["pose"]}
    for joint, constraint, branch in zip(robot["joints"], robot["constraints"], mode,
                                         strict=True):
        f = sympy.Poly(_sympy(constraint, names).subs(params), names[joint])
        a, b, c = (sympy.N(f.coeff_monomial(names[joint] ** k).subs(values), 50)
                   for k in (2, 1, 0))
        root = mpmath.sqrt(mpmath.mpf(str(b * b - 4 * a * c)))
        sign = 1 if branch == "+" else -1
        values[names[joint]] = (-mpmath.mpf(str(b)) + sign * root) / (2 * mpmath.mpf(str(a)))
    out = {}
    for body, items in robot["drawing"].items():
        pts = []
        for item in items:
            for p in (item if isinstance(item[0], list) else [item]):
                pts.append([float(sympy.N(_sympy(e, names).subs(params).subs(values), 30))
                            for e in p])
        out[body] = pts
    return out


def _assert_drawn(post, expected):
    for body in post.bodies:
        drawn = [float(v) for chain in body.chains for p in chain for v in p] + \
            [float(v) for p in body.points for v in p]
        want = [v for p in expected[body.name] for v in p]
        assert drawn == pytest.approx(want, abs=1e-7), (post.t, body.name)


def test_one_panel_at_the_start_and_at_each_real_singular_time(case):
    _, _, report = case
    posts = postures(report)
    real = sorted(float(c.t.mid()) for c in report.candidates if c.status == "real")
    assert real, "the case must have real singularities"
    assert [p.kind for p in posts] == ["start"] + ["singular"] * len(real)
    assert [p.t for p in posts[1:]] == pytest.approx(real, abs=1e-12)
    assert posts[0].t == pytest.approx(float(report.path.trajectory.range.start))
    feasible = [m.label for m in report.modes if m.feasible]
    assert {p.mode for p in posts} == set(feasible) and len(feasible) == 1


def test_drawn_points_are_the_model_at_those_times(case):
    robot_name, traj_name, report = case
    for post in postures(report):
        expected = _independent(robot_name, traj_name, post.mode, post.t)
        _assert_drawn(post, expected)


def test_at_a_singular_posture_the_legs_are_degenerate(case):
    """Independent meaning of the picture: on the skew biglide the two legs are aligned
    (their directions' cross product vanishes); on the Orthoglide the three leg
    directions are coplanar (their determinant vanishes)."""
    import numpy as np

    _, _, report = case
    for post in postures(report):
        legs = next(b for b in post.bodies if b.name == "legs")
        directions = np.array([c[1] - c[0] for c in legs.chains])
        det = np.linalg.det(directions) if len(directions) == 3 else \
            directions[0, 0] * directions[1, 1] - directions[0, 1] * directions[1, 0]
        assert (abs(det) < 1e-7) == (post.kind == "singular"), (post.kind, det)


def test_the_posture_figure_is_written_with_one_panel_per_posture(case, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from singcheck.report.plots import write_figures
    from singcheck.report.postures import posture_figure

    _, traj_name, report = case
    fig = posture_figure(plt, report, "t")
    assert len(fig.axes) == len(postures(report))
    titles = [ax.get_title() for ax in fig.axes]
    assert titles[0].startswith("start · t = -3.141593 · mode")
    assert all(t.startswith("singular · t = ") for t in titles[1:])
    if report.path.projection.model.spec.drawing_dimension == 3:  # the legs' common plane
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        shaded = [any(isinstance(c, Poly3DCollection) for c in ax.collections)
                  for ax in fig.axes]
        assert shaded == [False] + [True] * (len(titles) - 1)
    plt.close(fig)
    files = write_figures(report, tmp_path, ("png",), dpi=40)
    assert tmp_path / f"{traj_name}-postures.png" in files


HEART_IN_TWO = """\
name: heart1-in-two
parameter: t
segments:
  - range: [-1, 0]
    pose: {x: 8/7*sin(pi*t)^3, z: 1,
           y: 13/14*cos(pi*t) - 5/14*cos(2*pi*t) - 1/10*cos(3*pi*t) - 1/14*cos(4*pi*t)}
  - range: [0, 1]
    pose: {x: 8/7*sin(pi*t)^3, z: 1,
           y: 13/14*cos(pi*t) - 5/14*cos(2*pi*t) - 1/10*cos(3*pi*t) - 1/14*cos(4*pi*t)}
"""


def test_a_path_in_two_rescaled_pieces_is_drawn_at_its_own_times(tmp_path):
    """Heart 1 as two segments in t = τ/π: the postures are heart 1's, at times
    divided by π, and each is drawn from the segment holding it."""
    import math

    path = tmp_path / "heart1-in-two.yaml"
    path.write_text(HEART_IN_TWO)
    robot = api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False)
    report = api.check(robot, api.load_trajectory(path, robot), regions=False).certificate
    assert len(report.pieces) == 2
    posts = postures(report)
    assert [p.kind for p in posts] == ["start", "singular", "singular"]
    assert posts[0].t == -1
    for post in posts:
        expected = _independent("orthoglide", "heart1", post.mode, post.t * math.pi)
        _assert_drawn(post, expected)


def test_an_interpolated_path_is_traced_through_its_waypoints(tmp_path):
    """A CSV of poses (a spline whose pieces run in local time u = t - t_i): the traced
    end effector and the drawn platform pass through every row at its time."""
    import numpy as np
    from flint import arb

    from singcheck.report.postures import drawing_at, traced_points

    rows = [(0, 0.25, 0.6, 1), (1, 0.9, 1.1, 1), (2, 1.2, 0.3, 1), (3, 0.5, 0.2, 1)]
    path = tmp_path / "pick.csv"
    path.write_text("t,x,y,z\n" + "".join(",".join(map(str, r)) + "\n" for r in rows))
    robot = api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False)
    report = api.check(robot, api.load_trajectory(path, robot), regions=False).certificate
    assert len(report.pieces) == 3
    (trace,) = traced_points(report, np.array([r[0] for r in rows], dtype=float))
    assert trace.ravel().tolist() == pytest.approx([v for r in rows for v in r[1:]], abs=1e-12)
    mode = next(m.label for m in report.modes if m.feasible)
    for t, *pose in rows:
        bodies = drawing_at(report, mode, arb(t))
        platform = next(b for b in bodies if b.name == "platform")
        assert platform.points.ravel().tolist() == pytest.approx(pose, abs=1e-12)


def test_a_drawing_with_angles_and_square_roots_is_evaluated_by_name():
    """A revolute joint (an angle: its cos and sin are the spec's variables) and an exact
    √3 parameter: the drawn points are the trigonometry done here with mpmath."""
    from singcheck.report.postures import draw_bodies
    from singcheck.spec.files import parse_robot

    spec = parse_robot("""\
name: arm
joints: [th, q]
pose: [x, y]
parameters: {l: 2, h: sqrt(3)/2}
constraints:
  - (x - l*cos(th))^2 + (y - l*sin(th))^2 - 1
  - (x - q)^2 + (y - h)^2 - 1
drawing:
  crank: [[[0, 0], [l*cos(th), l*sin(th)], [x, y]]]
  slider: [[q, h]]
""", "arm.yaml")
    assert spec.angles == {"th"}
    th, q, x, y = mpmath.mpf(1) / 3, mpmath.mpf(5) / 4, mpmath.mpf(1) / 2, mpmath.mpf(2)
    crank, slider = draw_bodies(spec, [float(th), float(q)], [float(x), float(y)])
    assert crank.chains[0].ravel().tolist() == pytest.approx(
        [0, 0, float(2 * mpmath.cos(th)), float(2 * mpmath.sin(th)), 0.5, 2], abs=1e-12)
    assert slider.points.ravel().tolist() == pytest.approx([1.25, float(mpmath.sqrt(3) / 2)],
                                                           abs=1e-12)


# test_revolute's 5-bar (l1 = 1, l2 = 2, bases at (∓1, 0)) and its circle, with a drawing
FIVE_BAR = FIVE_BAR_SPEC + """\
drawing:
  base: [[[-e, 0], [e, 0]]]
  cranks: [[[-e, 0], [-e + l1*cos(th1), l1*sin(th1)]], [[e, 0], [e + l1*cos(th2), l1*sin(th2)]]]
  rods: [[[-e + l1*cos(th1), l1*sin(th1)], [x, y]], [[e + l1*cos(th2), l1*sin(th2)], [x, y]]]
  platform: [[x, y]]
"""


def test_a_five_bar_with_revolute_actuators_is_drawn_as_a_closed_chain(tmp_path):
    """Revolute joints reach the drawing as (cos θ, sin θ): every posture closes the
    chain (cranks of length 1, rods of length 2 meeting at the path's point at t, by
    50-digit mpmath), and at the singular times the two rods are parallel."""
    from singcheck.api import check, robot_from_spec
    from singcheck.report.plots import write_figures
    from singcheck.spec.files import parse_robot, parse_trajectory

    robot = robot_from_spec(parse_robot(FIVE_BAR, "fivebar.yaml"), "flint", cache=False)
    report = check(robot, parse_trajectory(CIRCLE, "circle.yaml", robot.spec),
                   regions=False).certificate
    posts = postures(report)
    assert any(p.kind == "singular" for p in posts)
    for post in posts:
        bodies = {b.name: b for b in post.bodies}
        t = mpmath.mpf(post.t)
        point = [float(mpmath.cos(t) / 2), float(2 + mpmath.sin(t) / 2)]
        assert bodies["platform"].points.ravel().tolist() == pytest.approx(point, abs=1e-9)
        for crank, rod in zip(bodies["cranks"].chains, bodies["rods"].chains, strict=True):
            assert float(np.hypot(*(crank[1] - crank[0]))) == pytest.approx(1, abs=1e-9)
            assert rod[0].tolist() == pytest.approx(crank[1].tolist(), abs=1e-12)
            assert float(np.hypot(*(rod[1] - rod[0]))) == pytest.approx(2, abs=1e-9)
        (a0, a1), (b0, b1) = bodies["rods"].chains
        u, v = a1 - a0, b1 - b0
        assert (abs(u[0] * v[1] - u[1] * v[0]) < 1e-7) == (post.kind == "singular")
    files = write_figures(report, tmp_path, ("png",), dpi=30)
    assert len(files) == 5
