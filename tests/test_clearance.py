"""The robot's own working mode and its certified clearance, checked against the test's
own 50-digit mpmath model: closed-form IK branches per mode, the leg-normalised Jacobian
and its smallest singular value (mpmath SVD) sampled along the path, the minimum refined
by golden-section search.  Never against singcheck's own numbers."""

from __future__ import annotations

import json
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import mpmath
import pytest

from singcheck.algebra.trig import LinearInPi
from singcheck.api import check, load_robot, load_trajectory, robot_from_spec
from singcheck.errors import SpecError
from singcheck.spec.files import parse_robot, parse_trajectory

ROOT = Path(__file__).resolve().parent.parent
mpmath.mp.dps = 50
TOL = 1e-6  # the tolerance: hi - lo <= 1e-6 * max(k, 1e-3)


# ---------------------------------------------------------------------------------
# the oracle: κ = smallest singular value of the rows of ∂F/∂X scaled to unit length

def _kappa(rows) -> mpmath.mpf:
    n = [[e / mpmath.sqrt(sum(x * x for x in r)) for e in r] for r in rows]
    return min(mpmath.svd_r(mpmath.matrix(n), compute_uv=False))


def _minimum(f, lo, hi, samples=2000):
    """min of f on [lo, hi]: the best sample, refined by golden section around it (and
    the range ends)."""
    lo, hi = mpmath.mpf(lo), mpmath.mpf(hi)
    step = (hi - lo) / samples
    best = min(range(samples + 1), key=lambda i: f(lo + i * step))
    a, b = max(lo, lo + (best - 2) * step), min(hi, lo + (best + 2) * step)
    g = (mpmath.sqrt(5) - 1) / 2
    for _ in range(200):
        c, d = b - g * (b - a), a + g * (b - a)
        if f(c) < f(d):
            b = d
        else:
            a = c
    t = (a + b) / 2
    return min((f(t), t), (f(lo), lo), (f(hi), hi))


# the Orthoglide (l = 2): leg i is |X - ρ_i e_i| = l, branch + is ρ_i = X_i + √(l² - …)
def _orthoglide_rows(p, mode):
    rows = []
    for i, sign in enumerate(mode):
        others = sum(p[j] ** 2 for j in range(3) if j != i)
        rho = p[i] + (1 if sign == "+" else -1) * mpmath.sqrt(4 - others)
        rows.append([p[j] - (rho if j == i else 0) for j in range(3)])
    return rows


def _heart2(t):
    return (mpmath.mpf(4) / 5 * mpmath.sin(t) ** 3,
            mpmath.mpf(13) / 20 * mpmath.cos(t) - mpmath.cos(2 * t) / 4
            - mpmath.cos(3 * t) / 20 - mpmath.cos(4 * t) / 20,
            mpmath.mpf(1))


# the 5-bar of robots/five-bar.yaml: bases (∓1, 0), l1 = l2 = 2; leg i is
# a cos θ + b sin θ + d = 0 with a = -2·l1·X, b = -2·l1·Y, d = X² + Y² + l1² - l2²
# (X, Y = P - base); branch σ: cos θ = (-a d + σ b √Δ)/W, sin θ = (-b d - σ a √Δ)/W
def _five_bar_joints(x, y, mode):
    out = []
    for base, sign in zip((-1, 1), mode, strict=True):
        big_x, big_y = x - base, y
        a, b = -4 * big_x, -4 * big_y
        d = big_x ** 2 + big_y ** 2
        w = a * a + b * b
        root = mpmath.sqrt(w - d * d)
        sigma = 1 if sign == "+" else -1
        out.append(((-a * d + sigma * b * root) / w, (-b * d - sigma * a * root) / w))
    return out


def _five_bar_rows(x, y, mode):
    return [[x - base - 2 * c, y - 2 * s]
            for base, (c, s) in zip((-1, 1), _five_bar_joints(x, y, mode), strict=True)]


def _five_bar_free(t):  # trajectories/five-bar-free.yaml
    return -1 + 2 * t, mpmath.mpf(5) / 2


def _assert_encloses(c, oracle_min, kappa_at_t):
    lo, hi = c["interval"]
    assert hi - lo <= TOL * max(c["min"], 1e-3)
    assert c["tolerance_met"] is True
    assert lo - 1e-12 <= oracle_min <= hi + 1e-12  # the true minimum is in [lo, hi]
    assert lo <= c["min"] <= hi
    # the reported time is where the minimum is: κ there (oracle) is within the interval
    assert lo - 1e-12 <= kappa_at_t <= hi + 1e-9


@pytest.fixture(scope="module")
def five_bar():
    return load_robot(str(ROOT / "robots/five-bar.yaml"), "flint", cache=False)


def test_five_bar_clearance_matches_the_oracle(five_bar):
    traj = load_trajectory(str(ROOT / "trajectories/five-bar-free.yaml"), five_bar)
    doc = check(five_bar, traj, regions=False, clearance=True).to_dict()
    assert set(doc["clearance"]) == {"+-"}  # the one feasible mode

    def kappa(t):
        return _kappa(_five_bar_rows(*_five_bar_free(t), "+-"))

    oracle, where = _minimum(kappa, 0, 1)
    c = doc["clearance"]["+-"]
    _assert_encloses(c, oracle, kappa(mpmath.mpf(c["t"])))
    assert abs(c["t"] - float(where)) < 1e-3
    assert doc["clearance_settings"]["angle_length"] == "1"
    assert doc["clearance_settings"]["angle_length_default"] is True


@pytest.mark.slow
def test_orthoglide_heart2_clearance_matches_the_oracle():
    robot = load_robot(str(ROOT / "robots/orthoglide.yaml"), "sympy", cache=False)
    traj = load_trajectory(str(ROOT / "trajectories/heart2.yaml"), robot)
    doc = check(robot, traj, regions=False, clearance=True).to_dict()
    assert doc["verdict"] == "singularity-free"
    assert set(doc["clearance"]) == {"+++"}

    def kappa(t):
        return _kappa(_orthoglide_rows(_heart2(t), "+++"))

    oracle, _ = _minimum(kappa, -mpmath.pi, mpmath.pi, samples=1500)
    c = doc["clearance"]["+++"]
    _assert_encloses(c, oracle, kappa(mpmath.mpf(c["t"])))


def _run(*args, stdin=None):
    return subprocess.run([sys.executable, "-m", "singcheck", "run", *args, "-q",
                           "--no-regions", "--no-cache", "--backend", "flint"],
                          capture_output=True, text=True, cwd=ROOT, input=stdin)


def test_min_clearance_gates_on_either_side_of_the_oracle_minimum():
    oracle, _ = _minimum(lambda t: _kappa(_five_bar_rows(*_five_bar_free(t), "+-")), 0, 1)
    above, below = float(oracle) * (1 + 1e-4), float(oracle) * (1 - 1e-4)
    near = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--format",
                "json", "--min-clearance", repr(above))
    assert near.returncode == 1, near.stderr
    t = json.loads(near.stdout)["trajectories"][0]
    assert t["verdict"] == "near-singular"
    assert "+-" in t["reason"] and "t ≈ 0.50" in t["reason"]
    free = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--format",
                "json", "--min-clearance", repr(below))
    assert free.returncode == 0, free.stderr
    assert json.loads(free.stdout)["trajectories"][0]["verdict"] == "singularity-free"
    # singular keeps priority over the gate
    cross = _run("robots/five-bar.yaml", "trajectories/five-bar-cross.yaml", "--format",
                 "json", "--min-clearance", "0.9")
    t = json.loads(cross.stdout)["trajectories"][0]
    assert cross.returncode == 1 and t["verdict"] == "singular"
    assert t["clearance"]["+-"]["interval"] == [0.0, 0.0]


def test_clearance_in_table_jsonl_and_junit():
    table = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--clearance")
    assert table.returncode == 0
    assert "clearance κ" in table.stdout and "+-: min 0.4954738" in table.stdout
    lines = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--clearance",
                 "--format", "jsonl").stdout.splitlines()
    assert json.loads(lines[0])["clearance"]["+-"]["min"] == pytest.approx(0.49547381,
                                                                           abs=1e-7)
    junit = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--clearance",
                 "--format", "junit").stdout
    assert 'name="clearance.five-bar-free.+-"' in junit
    plain = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--format",
                 "json")
    assert "clearance" not in json.loads(plain.stdout)["trajectories"][0]  # only on demand


# ---------------------------------------------------------------------------------
# the robot's own mode: the 5-bar without joint limits, where every mode is feasible

NO_LIMITS = (ROOT / "robots/five-bar.yaml").read_text().replace(
    "joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}\n", "")


def _oracle_singular(mode, pose, lo=0, hi=1, samples=400) -> bool:
    """det of the mode's rows changes sign along the path (the test's own model)."""
    def det(t):
        r = _five_bar_rows(*pose(t), mode)
        return r[0][0] * r[1][1] - r[0][1] * r[1][0]

    values = [det(mpmath.mpf(lo) + (hi - lo) * mpmath.mpf(i) / samples)
              for i in range(samples + 1)]
    return any(a * b < 0 for a, b in zip(values, values[1:], strict=False))


def test_mode_restricts_the_verdict_to_that_mode():
    spec = parse_robot(NO_LIMITS, "nolimits.yaml")
    robot = robot_from_spec(spec, "flint", cache=False)
    text = (ROOT / "trajectories/five-bar-cross.yaml").read_text()
    traj = parse_trajectory(text, "cross.yaml", robot.spec)

    def pose(t):
        return mpmath.mpf(0), 3 - 2 * t

    expected = {m: _oracle_singular(m, pose) for m in ("++", "+-", "-+", "--")}
    assert any(expected.values()) and not all(expected.values())  # a test that can fail
    assert check(robot, traj, regions=False).verdict == "singular"
    for label, singular in expected.items():
        report = check(robot, traj, regions=False, mode=label)
        doc = report.to_dict()
        assert report.verdict == ("singular" if singular else "singularity-free"), label
        assert [m["label"] for m in doc["working_modes"]] == [label]
        assert doc["mode"] == {"label": label, "chosen_by": "--mode"}
        assert all(set(c["joints"]) <= {label} for c in doc["candidates"])
    # the document's own mode key does the same
    free = next(m for m, s in expected.items() if not s)
    own = parse_trajectory(text + f'mode: "{free}"\n', "cross.yaml", robot.spec)
    assert own.mode == free
    doc = check(robot, own, regions=False).to_dict()
    assert doc["verdict"] == "singularity-free"
    assert doc["mode"]["chosen_by"] == "document"
    with pytest.raises(SpecError, match=r"unknown working mode '\+\+\+'.*\+\+, \+-, -\+, --"):
        check(robot, traj, regions=False, mode="+++")


def test_start_joints_pick_the_mode_the_oracle_names():
    spec = parse_robot(NO_LIMITS, "nolimits.yaml")
    robot = robot_from_spec(spec, "flint", cache=False)
    traj = parse_trajectory((ROOT / "trajectories/five-bar-free.yaml").read_text(),
                            "free.yaml", robot.spec)
    x, y = _five_bar_free(mpmath.mpf(0))
    for label in ("+-", "-+"):
        angles = [mpmath.atan2(s, c) for c, s in _five_bar_joints(x, y, label)]
        given = {name: LinearInPi(Fraction(mpmath.nstr(a, 15)))
                 for name, a in zip(("th1", "th2"), angles, strict=True)}
        doc = check(robot, traj, regions=False, start_joints=given).to_dict()
        assert doc["mode"]["label"] == label
        assert doc["mode"]["chosen_by"] == "--start-joints"
        off = {"th1": given["th1"], "th2": LinearInPi(given["th2"].rational + Fraction(1, 10**5))}
        with pytest.raises(SpecError, match="no working mode has"):
            check(robot, traj, regions=False, start_joints=off)
    with pytest.raises(SpecError, match="matches several working modes"):
        check(robot, traj, regions=False, start_joints={"th1": given["th1"]})


def test_mode_errors_are_one_line_exit_2():
    bad = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--mode", "+++")
    assert bad.returncode == 2
    assert "++, +-, -+, --" in bad.stderr and "Traceback" not in bad.stderr
    bad = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--start-joints",
               "phi=1")
    assert bad.returncode == 2 and "not a joint" in bad.stderr
    bad = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml", "--start-joints",
               "th1=2.5")
    assert bad.returncode == 2 and "no working mode has th1 = 2.5" in bad.stdout + bad.stderr
    help_text = subprocess.run([sys.executable, "-m", "singcheck", "run", "--help"],
                               capture_output=True, text=True, cwd=ROOT).stdout
    assert "--start-joints" in help_text and "1e-6" in help_text
    assert "the branch with +√D" in help_text


# ---------------------------------------------------------------------------------
# explanations

def test_a_revolute_joint_at_pi_is_reported_as_pi(five_bar):
    """At t = π/2 (a ball, not a point) leg 2's + branch is at θ = π exactly (the
    oracle), where atan2 of its enclosure used to say 0."""
    text = "name: at-pi\nparameter: t\nrange: [pi/2, pi/2 + 1/10]\npose:\n  x: -1\n" \
           "  y: 2*sin(t)\n"
    traj = parse_trajectory(text, "pi.yaml", five_bar.spec)
    doc = check(five_bar, traj, regions=False).to_dict()
    x, y = mpmath.mpf(-1), 2 * mpmath.sin(mpmath.pi / 2)
    for m in doc["working_modes"]:
        for name, (c, s) in zip(("th1", "th2"), _five_bar_joints(x, y, m["label"]),
                                strict=True):
            expected = float(mpmath.atan2(s, c))
            if expected <= -float(mpmath.pi) + 1e-12:
                expected = float(mpmath.pi)
            assert m["joints_at_start"][name] == pytest.approx(expected, abs=1e-9)
    assert any(m["joints_at_start"]["th2"] == pytest.approx(3.141592653589793)
               for m in doc["working_modes"])


def test_infeasible_names_each_mode_its_joint_and_time(five_bar):
    text = "name: out\nparameter: t\nrange: [0, 1]\npose:\n  x: -1 + 3*t\n  y: 5/2\n"
    traj = parse_trajectory(text, "out.yaml", five_bar.spec)
    report = check(five_bar, traj, regions=False)
    assert report.verdict == "infeasible"
    # the oracle: along mode +- (θ1 = atan2 of the + branch of leg 1) θ1 falls through
    # its lower limit π/3; bisection on θ1 - π/3
    def over(t):
        c, s = _five_bar_joints(-1 + 3 * t, mpmath.mpf(5) / 2, "+-")[0]
        return mpmath.atan2(s, c) - mpmath.pi / 3

    a, b = mpmath.mpf(0), mpmath.mpf(1)
    assert over(a) > 0 > over(b)
    for _ in range(100):
        m = (a + b) / 2
        a, b = (m, b) if over(m) > 0 else (a, m)
    leaves = (a + b) / 2
    assert f"mode +-: th1 leaves [1/3*pi, pi] at t ≈ {float(leaves):.6g}" in report.reason
    for label in ("++", "-+", "--"):
        assert f"mode {label}:" in report.reason or f", {label}" in report.reason


def test_clearance_length_key_is_read_and_checked(tmp_path):
    spec = (ROOT / "robots/3-rpr.yaml").read_text()
    assert "clearance" not in spec
    robot = tmp_path / "r.yaml"
    robot.write_text(spec + "clearance: {length: 1/2}\n")
    assert parse_robot(robot.read_text(), str(robot)).clearance_length == Fraction(1, 2)
    robot.write_text(spec + "clearance: {length: 0}\n")
    with pytest.raises(SpecError, match="clearance.length: must be positive"):
        parse_robot(robot.read_text(), str(robot))


def test_the_report_with_mode_and_clearance_validates_against_its_schema():
    from tests.test_schemas import errors, validator

    out = _run("robots/five-bar.yaml", "trajectories/five-bar-free.yaml",
               "trajectories/five-bar-cross.yaml", "--format", "json", "--mode", "+-",
               "--min-clearance", "0.6")
    doc = json.loads(out.stdout)
    assert [t["verdict"] for t in doc["trajectories"]] == ["near-singular", "singular"]
    assert errors(validator("report"), doc) == []
    broken = json.loads(out.stdout)
    broken["trajectories"][0]["clearance"]["+-"].pop("interval")
    assert errors(validator("report"), broken)  # the schema does check the new keys


def test_the_clearance_figure_follows_the_oracle(five_bar, tmp_path):
    pytest.importorskip("matplotlib")
    from singcheck.certify.modes import clearances
    from singcheck.report.plots import clearance_curves, write_figures

    traj = load_trajectory(str(ROOT / "trajectories/five-bar-free.yaml"), five_bar)
    report = check(five_bar, traj, regions=False).certificate
    t, k = clearance_curves(report, ["+-"], samples=50)["+-"]
    for ti, ki in zip(t, k, strict=True):
        assert ki == pytest.approx(float(_kappa(_five_bar_rows(*_five_bar_free(
            mpmath.mpf(ti)), "+-"))), abs=1e-9)
    found = clearances(report)
    assert min(k) >= found["+-"].lo  # samples never below the certified lower bound
    files = write_figures(report, tmp_path, formats=("png",), clearance=found, gate=0.6)
    assert tmp_path / "five-bar-free-clearance.png" in files
    plain = write_figures(report, tmp_path / "plain", formats=("png",))
    assert not any("clearance" in p.name for p in plain)  # only when asked


def test_the_html_page_has_the_clearance_figure(tmp_path):
    pytest.importorskip("plotly")
    out = subprocess.run([sys.executable, "-m", "singcheck", "plot", "robots/five-bar.yaml",
                          "trajectories/five-bar-free.yaml", "--out", str(tmp_path),
                          "--format", "html", "--plotly", "cdn", "--min-clearance", "0.6",
                          "-q"], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    page = (tmp_path / "singcheck.html").read_text()
    assert "clearance \\u03ba(t)" in page or "clearance κ(t)" in page  # JSON-escaped
    assert "--min-clearance 0.6" in page and "certified min (+-)" in page


def _rpr_rows(t, length):
    """∂F/∂(x, y, φ) of robots/3-rpr.yaml on 3-rpr-free (x = 3 - cos t, y = 1/2 + sin t,
    φ = t), the φ column divided by ``length``."""
    x, y, phi = 3 - mpmath.cos(t), mpmath.mpf(1) / 2 + mpmath.sin(t), t
    c, s = mpmath.cos(phi), mpmath.sin(phi)
    u2, v2 = x + c - 5, y + s
    u3, v3 = x - s - 1, y + c - 4
    rows = [[2 * x, 2 * y, 0],
            [2 * u2, 2 * v2, 2 * u2 * -s + 2 * v2 * c],
            [2 * u3, 2 * v3, 2 * u3 * -c + 2 * v3 * -s]]
    return [[r[0], r[1], r[2] / length] for r in rows]


@pytest.mark.parametrize("length", [None, Fraction(1, 2), Fraction(3)])
def test_the_angle_column_is_scaled_by_the_clearance_length(length):
    text = (ROOT / "robots/3-rpr.yaml").read_text()
    if length is not None:
        text += f"clearance: {{length: {length}}}\n"
    robot = robot_from_spec(parse_robot(text, "3-rpr.yaml"), "flint", cache=False)
    traj = load_trajectory(str(ROOT / "trajectories/3-rpr-free.yaml"), robot)
    doc = check(robot, traj, regions=False, clearance=True).to_dict()
    scale = mpmath.mpf(length.numerator) / length.denominator if length else 1
    oracle, _ = _minimum(lambda t: _kappa(_rpr_rows(t, scale)), 0, 1, samples=600)
    assert doc["clearance"], doc["reason"]
    for c in doc["clearance"].values():  # det A is free of the joints: every mode alike
        _assert_encloses(c, oracle, _kappa(_rpr_rows(mpmath.mpf(c["t"]), scale)))
    assert doc["clearance_settings"]["angle_length"] == str(length or 1)
    assert doc["clearance_settings"]["angle_length_default"] is (length is None)


def test_the_orthoglide_isotropic_pose_has_clearance_one():
    """At (4/3, 4/3, 4/3) mode +++ has ρ_i = 4/3 + 2/3: the rows (P - ρ_i e_i)/2 are
    (-1/3, 2/3, 2/3) and its permutations, orthonormal: κ = 1 exactly."""
    robot = load_robot(str(ROOT / "robots/orthoglide.yaml"), "sympy", cache=False)
    text = "name: iso\nparameter: t\nrange: [0, 1]\npose: {x: 4/3, y: 4/3, z: 4/3}\n"
    traj = parse_trajectory(text, "iso.yaml", robot.spec)
    doc = check(robot, traj, regions=False, clearance=True, mode="+++").to_dict()
    lo, hi = doc["clearance"]["+++"]["interval"]
    assert 1 - 1e-6 <= lo <= 1 <= hi + 1e-15 and hi <= 1 + 1e-12


def test_infeasible_names_the_leg_whose_branches_are_complex(five_bar):
    text = "name: off\nparameter: t\nrange: [0, 1/10]\npose:\n  x: -3 + t\n  y: 2\n"
    report = check(five_bar, parse_trajectory(text, "off.yaml", five_bar.spec),
                   regions=False)
    # the oracle: leg 2 (base (1, 0)) has Δ = W - d² < 0 all along, leg 1 has Δ > 0
    for i in range(11):
        t = mpmath.mpf(i) / 100
        x, y = -3 + t, mpmath.mpf(2)
        for base, negative in ((-1, False), (1, True)):
            a, b, d = -4 * (x - base), -4 * y, (x - base) ** 2 + y ** 2
            assert (a * a + b * b - d * d < 0) is negative
    assert report.verdict == "infeasible"
    assert "modes ++, +-, -+, --: th2 has no real solution along the path: both its " \
           "branches are complex from the start to the end" in report.reason


def test_a_spent_budget_reports_the_interval_honestly(five_bar):
    from singcheck.certify.clearance import minimum_clearance
    from singcheck.report.trajectory import clearance_lines

    traj = load_trajectory(str(ROOT / "trajectories/five-bar-free.yaml"), five_bar)
    report = check(five_bar, traj, regions=False).certificate
    mode = next(m for m in report.modes if m.feasible)
    c = minimum_clearance(report.path, mode, budget=4)
    oracle, _ = _minimum(lambda t: _kappa(_five_bar_rows(*_five_bar_free(t), "+-")), 0, 1)
    assert c.met is False and c.hi - c.lo > TOL * c.hi  # not refined enough ...
    assert c.lo <= oracle <= c.hi  # ... but still an enclosure
    lines = clearance_lines({"parameter": "t", "clearance": {"+-": c.to_json()}})
    assert "tolerance not met" in lines[1]


def test_the_gate_is_unknown_when_the_interval_straddles_the_threshold(five_bar):
    from singcheck.certify.clearance import Clearance
    from singcheck.certify.modes import gate

    traj = load_trajectory(str(ROOT / "trajectories/five-bar-free.yaml"), five_bar)
    report = check(five_bar, traj, regions=False).certificate
    wide = {"+-": Clearance("+-", 0.45, 0.4, 0.5, 0.5, False, "test")}
    assert gate(report, wide, 0.45)[0] == "unknown"
    assert gate(report, wide, 0.55)[0] == "near-singular"
    assert gate(report, wide, 0.35)[0] == "singularity-free"
