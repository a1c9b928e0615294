"""Paths the exact pipeline used to refuse or leave undecided, checked against oracles
written here (closed-form inverse kinematics and det A at 50 digits with mpmath)."""

from __future__ import annotations

import mpmath as mp
import pytest

from singcheck.api import check, load_robot, load_trajectory

_ROBOTS: dict = {}


def _run(robot: str, doc: str):
    """The certificate of one trajectory (regions off: only the verdict is checked)."""
    if robot not in _ROBOTS:
        _ROBOTS[robot] = load_robot(f"robots/{robot}.yaml", backend="flint", cache=False)
    r = _ROBOTS[robot]
    return check(r, load_trajectory(doc, r), regions=False).certificate


def _doc(tmp_path, name: str, rng: str, pose: dict) -> str:
    lines = [f"name: {name}", "parameter: t", f"range: {rng}", "pose:"]
    lines += [f"  {v}: {e}" for v, e in pose.items()]
    path = tmp_path / f"{name}.yaml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _orthoglide_det(x, y, z):
    """det A/8 of the Orthoglide (leg length 2) in its mode +++ (ρᵢ = Xᵢ + √(4 − …))."""
    a = -mp.sqrt(4 - y * y - z * z)
    b = -mp.sqrt(4 - x * x - z * z)
    c = -mp.sqrt(4 - x * x - y * y)
    return mp.det(mp.matrix([[a, y, z], [x, b, z], [x, y, c]]))


def _sign_changes(f, lo, hi, n):
    mp.mp.dps = 50
    out, prev = [], None
    for i in range(n + 1):
        t = lo + (hi - lo) * mp.mpf(i) / n
        v = f(t)
        if prev is not None and mp.sign(v) != mp.sign(prev[1]):
            out.append((float(prev[0]), float(t)))
        prev = (t, v)
    return out


def _singular_times(report) -> list[float]:
    return sorted(float(c.t.mid()) for c in report.candidates if c.singular_modes)


def test_high_harmonic_crossings_are_found_where_det_a_changes_sign(tmp_path):
    """x = 1/2 + sin t/2 + cos 64t/50: the exact engine refuses (degree 1024); the
    intervals must place every singular time in a sign change of the oracle's det A."""
    x = "1/2 + sin(t)/2 + cos(64*t)/50"
    doc = _doc(tmp_path, "cos64", "[-pi, pi]", {"x": x, "y": "1/2", "z": 1})
    report = _run("orthoglide", doc)

    def det(t):
        return _orthoglide_det(mp.mpf(1) / 2 + mp.sin(t) / 2 + mp.cos(64 * t) / 50,
                               mp.mpf(1) / 2, mp.mpf(1))

    changes = _sign_changes(det, -mp.pi, mp.pi, 20000)
    assert report.verdict == "singular"
    times = _singular_times(report)
    assert len(times) == len(changes) == 10
    for t, (lo, hi) in zip(times, changes, strict=True):
        assert lo - 1e-6 <= t <= hi + 1e-6


def test_cos_256t_is_proven_free(tmp_path):
    """x = 1/2 + cos 256t/4 stays in [1/4, 3/4] (y = 1/2, z = 1), where the oracle's
    det A is negative: free (it was `unknown`: the pose's power form lost every bit)."""
    doc = _doc(tmp_path, "cos256", "[0, 1]", {"x": "1/2 + cos(256*t)/4", "y": "1/2", "z": 1})
    mp.mp.dps = 50
    assert all(_orthoglide_det(mp.mpf(i) / 400, mp.mpf(1) / 2, 1) < 0
               for i in range(100, 301))
    report = _run("orthoglide", doc)
    assert report.verdict == "singularity-free"


@pytest.mark.parametrize("pose", [
    {"x": 0, "y": "sqrt(3) + t"},            # crossing at t = 0
    {"x": "t/2", "y": "sqrt(3) + t^2"},      # touching at t = 0
    {"x": "sqrt(7)/4*t", "y": "sqrt(3) - t"},
])
def test_five_bar_meets_the_singularity_at_a_conjugate_root(tmp_path, pose):
    """At P = (0, √3) the 5-bar's feasible mode has its elbows at (∓2, √3) (the
    triangles A₁B₁P, A₂B₂P are equilateral): the distal links are aligned, singular.
    The conjugate path (√3 ↦ −√3) meets the mirror singularity at the same t = 0, so
    no ball tells the two apart: decided exactly."""
    mp.mp.dps = 50
    p = mp.matrix([0, mp.sqrt(3)])
    b1 = mp.matrix([-1, 0]) + 2 * mp.matrix([mp.cos(2 * mp.pi / 3), mp.sin(2 * mp.pi / 3)])
    b2 = mp.matrix([1, 0]) + 2 * mp.matrix([mp.cos(mp.pi / 3), mp.sin(mp.pi / 3)])
    assert abs(mp.norm(p - b1) - 2) < 1e-40 and abs(mp.norm(p - b2) - 2) < 1e-40
    u, v = p - b1, p - b2
    assert abs(u[0] * v[1] - u[1] * v[0]) < 1e-40
    doc = _doc(tmp_path, "five", "[-1, 1]", pose)
    report = _run("five-bar", doc)
    assert report.verdict == "singular"
    assert _singular_times(report) == [0.0]


# -- paths that are not polynomials in (t, sin t, cos t): the interval engine alone ------

@pytest.mark.parametrize(("name", "rng", "pose", "lo", "hi"), [
    ("shift", "[-pi, pi]", {"x": "1 + cos(t - 1)/2", "y": "1/2", "z": 1}, -mp.pi, mp.pi),
    ("drift", "[0, 2]", {"x": "1 + cos(2*pi*t)/2 + t/10", "y": "1 + sin(2*pi*t)/2", "z": 1},
     0, 2),
    ("half", "[-pi, pi]", {"x": "1 + cos(t/2)/2", "y": "1/2", "z": 1}, -mp.pi, mp.pi),
])
def test_expression_paths_match_the_oracle(tmp_path, name, rng, pose, lo, hi):
    """cos(t − 1), a drifting circle in 2πt and cos(t/2) on the Orthoglide: each
    singular time lies in a sign change of the oracle's det A (mode +++, the one inside
    the limits here), and there are as many."""
    doc = _doc(tmp_path, name, rng, pose)
    report = _run("orthoglide", doc)
    mp.mp.dps = 30

    def coordinate(text):
        return lambda t: mp.mpf(eval(str(text), {"cos": mp.cos, "sin": mp.sin, "pi": mp.pi,  # noqa: S307 - our own test strings
                                                  "t": t}))

    x, y, z = (coordinate(pose[v]) for v in ("x", "y", "z"))
    changes = _sign_changes(lambda t: _orthoglide_det(x(t), y(t), z(t)), mp.mpf(lo),
                            mp.mpf(hi), 4000)
    times = _singular_times(report)
    assert report.verdict == ("singular" if changes else "singularity-free")
    assert len(times) == len(changes)
    for t, (a, b) in zip(times, changes, strict=True):
        assert a - 1e-6 <= t <= b + 1e-6
    assert report.corroboration.status == "exact engine not run"
    assert "not a polynomial in t, sin t and cos t" in report.corroboration.detail


def _rrr_det(x, y, f, signs):
    """det A of the planar 3-RRR of tests/data/robots/3-rrr.yaml, elbows chosen by
    ``signs`` (closed-form: the elbow is where the circles about Aᵢ and Pᵢ meet)."""
    bases = [(2, 1), (-2, 1), (mp.mpf(-2) / 5, mp.mpf(-11) / 5)]
    c, s = mp.cos(f), mp.sin(f)
    points = [((x + c, y + s), (-s, c)),
              ((x - 3 * c / 5 - 4 * s / 5, y - 3 * s / 5 + 4 * c / 5),
               (3 * s / 5 - 4 * c / 5, -3 * c / 5 - 4 * s / 5)),
              ((x - 3 * c / 5 + 4 * s / 5, y - 3 * s / 5 - 4 * c / 5),
               (3 * s / 5 + 4 * c / 5, -3 * c / 5 + 4 * s / 5))]
    rows = []
    for (ax, ay), ((px, py), (dx, dy)), sigma in zip(bases, points, signs, strict=True):
        vx, vy = px - ax, py - ay
        d2 = vx * vx + vy * vy
        h = mp.sqrt(1 - d2 / 4)
        n = mp.sqrt(d2)
        bx = (ax + px) / 2 - sigma * h * vy / n
        by = (ay + py) / 2 + sigma * h * vx / n
        ux, uy = px - bx, py - by
        rows.append([ux, uy, ux * dx + uy * dy])
    return mp.det(mp.matrix(rows))


def test_three_rrr_with_a_shifted_angle_matches_the_oracle(tmp_path):
    """3-RRR with x = cos(t/2)/5, y = sin(t − 1)/5, φ = cos(t − 1)/10: every mode is
    feasible (no limits), and the singular times per mode are the oracle's sign changes
    of det A along each elbow choice (modes are matched by their sets of times)."""
    import itertools

    pose = {"x": "cos(t/2)/5", "y": "sin(t - 1)/5", "phi": "cos(t - 1)/10"}
    doc = tmp_path / "rrr.yaml"
    doc.write_text("name: rrr\nparameter: t\nrange: [-pi, pi]\npose:\n" +
                   "".join(f"  {k}: {v}\n" for k, v in pose.items()))
    robot = load_robot("tests/data/robots/3-rrr.yaml", backend="flint", cache=False)
    report = check(robot, load_trajectory(str(doc), robot), regions=False).certificate
    mp.mp.dps = 30
    oracle = []
    for signs in itertools.product((1, -1), repeat=3):
        changes = _sign_changes(
            lambda t, signs=signs: _rrr_det(mp.cos(t / 2) / 5, mp.sin(t - 1) / 5,
                                            mp.cos(t - 1) / 10, signs), -mp.pi, mp.pi, 3000)
        if changes:
            oracle.append(changes)
    found = [sorted(float(c.t.mid()) for c in m.singular_times) for m in report.modes
             if m.singular_times]
    assert report.verdict == "singular"
    assert len(found) == len(oracle) == 3
    for times in found:
        match = [o for o in oracle if len(o) == len(times) and all(
            a - 1e-6 <= t <= b + 1e-6 for t, (a, b) in zip(times, o, strict=True))]
        assert len(match) == 1


def test_real_angle_limits(tmp_path):
    """The 5-bar with limits in plain radians ([1, 3.1] and [0.05, 2]): the path down
    the symmetry axis meets the singularity at y = √3, t = (3 − √3)/2, with both
    elbows (th1 = 2π/3, th2 = π/3 there) inside those limits."""
    text = open("robots/five-bar.yaml").read().replace(
        "joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}",
        "joint_limits: {th1: [1, 3.1], th2: [0.05, 2]}")
    robot_file = tmp_path / "five-bar-radians.yaml"
    robot_file.write_text(text)
    robot = load_robot(str(robot_file), backend="flint", cache=False)
    assert 1 < 2 * mp.pi / 3 < 3.1 and 0.05 < mp.pi / 3 < 2
    report = check(robot, load_trajectory("trajectories/five-bar-cross.yaml", robot)
                   ).certificate
    assert report.verdict == "singular"
    assert _singular_times(report) == pytest.approx([(3 - 3 ** 0.5) / 2], abs=1e-8)
    free = check(robot, load_trajectory("trajectories/five-bar-free.yaml", robot)).certificate
    assert free.verdict == "singularity-free"


@pytest.mark.parametrize(("x", "message"), [
    ("sqrt(t - 1/2)", "is not defined at t = 0"),
    ("exp(t)", "unknown function 'exp'"),
])
def test_expression_paths_refused_up_front(tmp_path, x, message):
    from singcheck.errors import SpecError

    doc = _doc(tmp_path, "bad", "[0, 1]", {"x": x, "y": "1/2", "z": 1})
    robot = load_robot("robots/orthoglide.yaml", backend="flint", cache=False)
    with pytest.raises(SpecError, match=message):
        load_trajectory(doc, robot)


def test_exact_engine_refuses_an_expression_path_with_the_reason(tmp_path):
    from singcheck.errors import SpecError

    doc = _doc(tmp_path, "shift", "[0, 1]", {"x": "1 + cos(t - 1)/2", "y": "1/2", "z": 1})
    robot = load_robot("robots/orthoglide.yaml", backend="flint", cache=False)
    with pytest.raises(SpecError, match=r"x = 1 \+ cos\(t - 1\)/2\): only the interval"):
        check(robot, load_trajectory(doc, robot), engine="exact", regions=False)


def test_expression_path_derivative_encloses_the_true_rate():
    """The forward-mode derivative of a tree, at points and over a ball, against
    mpmath's numerical derivative at 30 digits."""
    from flint import arb

    from singcheck.spec.grammar import parse
    from singcheck.spec.real_paths import real_function

    text = "cos(t - 1)/2 + sqrt(1 + t^2)*sin(2*pi*t)/(3 + t)"
    f = real_function(parse(text), text, "t", {})
    mp.mp.dps = 30

    def g(t):
        return mp.cos(t - 1) / 2 + mp.sqrt(1 + t * t) * mp.sin(2 * mp.pi * t) / (3 + t)

    for x in ("-0.7", "0.25", "1.5"):
        value, rate = f.with_derivative(arb(x))
        assert value.contains(arb(mp.nstr(g(mp.mpf(x)), 25)))
        assert abs(float(rate.mid()) - float(mp.diff(g, mp.mpf(x)))) < 1e-12
    _, wide = f.with_derivative(arb("0.5", "0.1"))
    for k in range(21):  # every rate over [0.4, 0.6] is inside the ball's enclosure
        assert wide.contains(arb(mp.nstr(mp.diff(g, mp.mpf("0.4") + mp.mpf(k) / 100), 20)))


def test_expression_path_clearance_and_plot(tmp_path):
    """A path kept as expression trees gets its clearance (the tree's derivative) and
    its figures, where it used to end in an error."""
    from singcheck.report.plots import _sample_piece

    doc = _doc(tmp_path, "half", "[-pi, pi]", {"x": "1 + cos(t/2)/2", "y": "1/2", "z": 1})
    robot = load_robot("robots/orthoglide.yaml", backend="flint", cache=False)
    report = check(robot, load_trajectory(doc, robot), regions=False, clearance=True)
    assert report.verdict == "singularity-free"
    kappa = report.extra["clearance"]["+++"]
    assert 0 < kappa["interval"][0] <= kappa["interval"][1]
    t, pose, mu, _, _ = _sample_piece(report.certificate.path, 50)
    assert abs(pose[0][0] - (1 + mp.cos(-mp.pi / 2) / 2)) < 1e-12


# -- a path that starts on the singularity: det A = 0 exactly at a rational pose ---------

def _modes_singular_at(oracle, X) -> int:
    """How many elbow choices make det A vanish at X (50 digits: |det A| < 10⁻³⁰)."""
    import itertools

    mp.mp.dps = 50
    count = 0
    for mode in itertools.product((0, 1), repeat=len(oracle.legs)):
        q = oracle.joints(mode, X)
        if q is not None and abs(oracle.det_A(q, X)) < mp.mpf(10) ** -30:
            count += 1
    return count


def test_a_path_leaving_the_home_pose_is_singular_at_its_start(tmp_path):
    """The 3-RRR's home pose (0, 0, 0) is singular in some elbow choices (the distal
    links meet at the centre).  The interval engine alone cannot prove a zero; the exact
    test at the rational pose finds exactly the oracle's modes singular at t = 0."""
    from singcheck.certify.classification import BY_RATIONAL_POSE
    from tests.robot_oracles import three_rrr

    expected = _modes_singular_at(three_rrr(), [mp.mpf(0)] * 3)
    assert expected >= 1
    doc = tmp_path / "home.yaml"
    doc.write_text("name: home\nparameter: t\nrange: [0, 1]\npose:\n"
                   "  x: t/10\n  y: t/20\n  phi: t/20\n")
    robot = load_robot("tests/data/robots/3-rrr.yaml", backend="flint", cache=False)
    report = check(robot, load_trajectory(str(doc), robot), regions=False).certificate
    assert report.verdict == "singular"
    first = report.candidates[0]
    assert first.time == 0.0
    assert len(first.singular_modes) == expected
    assert all(m.proof == BY_RATIONAL_POSE for m in first.modes)
    assert "at t = 0 (exactly" in report.reason


@pytest.mark.slow
def test_six_rus_leaving_home_is_singular_at_the_start_in_the_oracles_modes(tmp_path):
    """x: t/4 from the 6-RUS home pose: the exact engine refuses it (too costly), and
    it used to end unknown; 44 of the 64 modes are singular at t = 0 (oracle)."""
    from tests.robot_oracles import six_rus

    home = [mp.mpf(0), mp.mpf(0), mp.mpf(-2), mp.mpf(0), mp.mpf(0), mp.mpf(0)]
    expected = _modes_singular_at(six_rus(), home)
    assert expected == 44
    doc = tmp_path / "x.yaml"
    doc.write_text("name: x\nparameter: t\nrange: [0, 1]\npose:\n  x: t/4\n  y: 0\n  z: -2\n"
                   "  psi: 0\n  theta: 0\n  phi: 0\n")
    robot = load_robot("tests/data/robots/6-rus.yaml", backend="flint", cache=False)
    report = check(robot, load_trajectory(str(doc), robot), regions=False).certificate
    assert report.verdict == "singular"
    assert report.candidates[0].time == 0.0
    assert len(report.candidates[0].singular_modes) == expected


def test_square_classes_decide_sums_of_square_roots():
    """√2·√2 − 2 = 0 although its coefficients on the masks are not all 0; √2·√3 − 2 ≠ 0
    (the checker's exact zero test at a rational pose)."""
    from fractions import Fraction

    from singcheck.verify.checker import _is_zero

    assert _is_zero({0b11: Fraction(1), 0: Fraction(-2)}, [Fraction(2), Fraction(2)])
    assert not _is_zero({0b11: Fraction(1), 0: Fraction(-2)}, [Fraction(2), Fraction(3)])
    assert _is_zero({0b01: Fraction(1), 0b10: Fraction(-2)}, [Fraction(8), Fraction(2)])


def test_segments_with_an_expression_piece_join_by_exact_balls(tmp_path):
    """A segment x = 1 + cos(t − 1)/2 ends at t = 1 on x = 3/2 exactly (Arb's cos 0 is
    the exact 1): it joins x = 3/2; a jump to x = 1 is refused; a join where the tree's
    value is not exact cannot be checked and is refused with the reason."""
    from singcheck.errors import SpecError

    robot = load_robot("robots/orthoglide.yaml", backend="flint", cache=False)

    def doc(second_x: str, end: str = "1") -> str:
        path = tmp_path / f"seg{len(list(tmp_path.iterdir()))}.yaml"
        path.write_text(f"name: seg\nparameter: t\nsegments:\n"
                        f"  - range: [0, {end}]\n    pose: {{x: 1 + cos(t - 1)/2, y: 1/2, z: 1}}\n"
                        f"  - range: [{end}, 2]\n    pose: {{x: {second_x}, y: 1/2, z: 1}}\n")
        return str(path)

    report = check(robot, load_trajectory(doc("3/2"), robot), regions=False).certificate
    mp.mp.dps = 30
    assert all(_orthoglide_det(1 + mp.cos(t - 1) / 2, mp.mpf(1) / 2, 1) > 0
               for t in (mp.mpf(k) / 10 for k in range(11)))
    assert report.verdict == "singularity-free"
    with pytest.raises(SpecError, match="the pose jumps between segments 1 and 2"):
        load_trajectory(doc("1"), robot)
    with pytest.raises(SpecError, match="cannot check exactly that segments 1 and 2"):
        load_trajectory(doc("1 + cos(1/2)/2", "3/2"), robot)


def test_an_expression_path_crosses_a_process_boundary(tmp_path):
    """A Dask worker (a fresh process) unpickles the trajectory: the opaque variables'
    functions travel with the path ring and the verdict there is the same."""
    import pickle
    import subprocess
    import sys

    import singcheck.algebra.pickling  # noqa: F401 - the reducers

    doc = _doc(tmp_path, "shift", "[-pi, pi]", {"x": "1 + cos(t - 1)/2", "y": "1/2", "z": 1})
    robot = load_robot("robots/orthoglide.yaml", backend="flint", cache=False)
    here = check(robot, load_trajectory(doc, robot), regions=False).certificate
    blob = tmp_path / "job.pkl"
    blob.write_bytes(pickle.dumps((robot, load_trajectory(doc, robot))))
    code = ("import pickle, sys; import singcheck.algebra.pickling; "
            "from singcheck.api import check; "
            f"r, t = pickle.load(open({str(blob)!r}, 'rb')); "
            "c = check(r, t, regions=False).certificate; "
            "print(c.verdict, [round(float(x.t.mid()), 6) for x in c.candidates])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[0] == here.verdict == "singular"
    assert out.stdout.strip().endswith(str([round(float(x.t.mid()), 6)
                                            for x in here.candidates]))


def test_prismatic_limits_as_any_real_number(tmp_path):
    """Orthoglide limits [0, 2√2], [0, π], [1/2, 4]: along heart 1, mode +++'s ρ₁ =
    x + √(4 − y² − z²) passes 2√2 near t = π/2 (oracle at 50 digits), so the mode is
    proven infeasible there by ball arithmetic, naming the limit. The region statement is
    not made (no algebraic limit surface)."""
    text = open("robots/orthoglide.yaml").read().replace(
        "joint_limits: {rho1: [0, 4], rho2: [0, 4], rho3: [0, 4]}",
        "joint_limits: {rho1: [0, 2*sqrt(2)], rho2: [0, pi], rho3: [0.5, 4]}")
    robot_file = tmp_path / "orthoglide-real.yaml"
    robot_file.write_text(text)
    robot = load_robot(str(robot_file), backend="flint", cache=False)
    mp.mp.dps = 50

    def rho1(t):
        x = mp.mpf(8) / 7 * mp.sin(t) ** 3
        y = (mp.mpf(13) / 14 * mp.cos(t) - mp.mpf(5) / 14 * mp.cos(2 * t)
             - mp.cos(3 * t) / 10 - mp.cos(4 * t) / 14)
        return x + mp.sqrt(4 - y * y - 1)

    assert rho1(mp.pi / 2) > 2 * mp.sqrt(2)
    heart1 = check(robot, load_trajectory("trajectories/heart1.yaml", robot))
    mode = next(m for m in heart1.certificate.modes if m.label == "+++")
    assert mode.status == "infeasible" and "2*sqrt(2)" in mode.reason
    assert heart1.workspace is None
