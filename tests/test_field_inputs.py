"""Field inputs (bench/field_campaign.py): paths a user writes, against a 50-digit oracle.

Each test runs ``singcheck run ROBOT PATH --format json`` with default options, as a
user does, and compares its verdict, feasible working modes and singular times with
``tests/field_oracle.py`` (SymPy reads the same constraint text; closed-form inverse
kinematics per leg; det A at 50 digits along each mode, sign changes bisected, minima of
|det A| refined; it never imports singcheck).  The regression test of the interval
engine's range-end windows writes its own oracle (the biglide's det A = 4·y·(q − p)).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import mpmath as mp
import pytest
import yaml

from tests import field_oracle as fo

ROOT = Path(__file__).resolve().parent.parent
TOL = 1e-6
BIGLIDE, FIVE, ORTHO = "robots/biglide.yaml", "robots/five-bar.yaml", "robots/orthoglide.yaml"
RPR, RDELTA, GS = "robots/3-rpr.yaml", "robots/rotary-delta.yaml", "robots/gough-stewart.yaml"
SKEW = "robots/skew-biglide.yaml"


def path(rng: str, **pose: str) -> str:
    return (f"name: p\nparameter: t\nrange: {rng}\npose:\n"
            + "".join(f"  {k}: {v}\n" for k, v in pose.items()))


def waypoints(interpolation: str, *rows: dict) -> str:
    return (f"name: p\nparameter: t\ninterpolation: {interpolation}\nwaypoints:\n"
            + "".join("  - {" + ", ".join(f"{k}: {v}" for k, v in r.items()) + "}\n"
                      for r in rows))


def files(tmp_path: Path, robot: str, traj: str, edits=(), csv: bool = False):
    text = (ROOT / robot).read_text()
    for old, new in edits:
        assert old in text
        text = text.replace(old, new)
    robot_file = tmp_path / "robot.yaml"
    robot_file.write_text(text)
    traj_file = tmp_path / ("p.csv" if csv else "p.yaml")
    traj_file.write_text(traj)
    return robot_file, traj_file


def singcheck(robot_file: Path, traj_file: Path) -> dict:
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", str(robot_file),
                          str(traj_file), "--format", "json", "-q"], capture_output=True,
                         text=True, cwd=ROOT, timeout=600,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert out.stdout, out.stderr
    return json.loads(out.stdout)["trajectories"][0]


def oracle(robot_file: Path, traj_file: Path) -> fo.OracleVerdict:
    spec = yaml.safe_load(robot_file.read_text())
    robot = fo.robot_from_spec(spec)
    if traj_file.suffix == ".csv":
        lines = traj_file.read_text().split()
        head = lines[0].split(",")
        rows = [dict(zip(["t", *head[1:]], line.split(","), strict=True)) for line in lines[1:]]
        pieces = fo.path_pieces({}, spec, csv_rows=rows)
    else:
        pieces = fo.path_pieces(yaml.safe_load(traj_file.read_text()), spec)
    return fo.judge(robot, pieces)


def singular_times(result: dict) -> list[float]:
    return sorted({t for m in result["working_modes"] if m["feasible"]
                   for t in m["singular_times"]})


def close_to_any(t: float, times) -> bool:
    return any(abs(t - float(u)) <= TOL for u in times)


def assert_agrees(result: dict, truth: fo.OracleVerdict, *, touch_may_be_unknown=False):
    """singcheck's verdict, feasible modes (with their joints at the start) and singular
    times are the oracle's; a tangential touch may be ``unknown`` with a window on it."""
    assert not truth.ambiguous, truth.ambiguous
    feasible = {m["label"]: m for m in result["working_modes"] if m["feasible"]}
    expected = {label: r for label, r in truth.modes.items() if r.feasible}
    assert set(feasible) == set(expected), (result["reason"], truth.verdict)
    for label, r in expected.items():
        got = list(feasible[label]["joints_at_start"].values())
        for a, b in zip(r.start, got, strict=True):
            d = float(a) - b
            assert min(abs(d), abs(abs(d) - 2 * float(mp.pi))) < 1e-6, (label, r.start, got)
    if touch_may_be_unknown and result["verdict"] == "unknown":
        assert result["reason"]
        for t in truth.times:
            assert any(u["t_interval"][0] - TOL <= t <= u["t_interval"][1] + TOL
                       for u in result["undecided"]), (t, result["undecided"])
        return
    assert result["verdict"] == truth.verdict, result["reason"]
    times = singular_times(result)
    spans = [m["on_surface"] for m in result["working_modes"] if m["on_surface"]]
    for t in truth.times:
        assert close_to_any(t, times), (t, times)
    for t in times:
        assert close_to_any(t, truth.times) or any(a - TOL <= t <= b + TOL for a, b in spans), \
            (t, truth.times)
    assert bool(spans) == bool(truth.on_surface)


CASES = {
    "biglide-double-close-cos": (BIGLIDE, path("[0, 2]", x="t/2",
                                               y="1 - cos(t - 1) - 1/100000000"), ()),
    "biglide-ends-at-pi": (BIGLIDE, path("[pi/2, pi]", x="1/2", y="sin(t)/2"), ()),
    "biglide-very-short": (BIGLIDE, path("[0, 1/100000]", x="1/2", y="t - 3/1000000"), ()),
    "biglide-limit-touched-inside": (BIGLIDE, path("[0, pi]", x="12/5*sin(t)", y="6/5"),
                                     (("{p: [-4, 4]", "{p: [0, 4]"),)),
    "biglide-cross-at-knot": (BIGLIDE, waypoints("cubic", {"t": 0, "x": 0, "y": 0.5},
                                                 {"t": 1, "x": 0.5, "y": 0},
                                                 {"t": 2, "x": 1, "y": -0.5}), ()),
    "five-bar-horizontal-tangent": (FIVE, path("[-1, 1]", x="sin(t)/2", y="sqrt(3)"), ()),
    "five-bar-circle-tangent": (FIVE, path("[-1/4, 1/4]", x="sqrt(3) - t/2",
                                           y="sqrt(3) + 1 + sqrt(3)*t/2"),
                                (("joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}\n", ""),)),
    "five-bar-decimal-variant": (FIVE, path("[0, 1]", x="0.1", y="3.95 - t/2"),
                                 (("{d: 1, l1: 2, l2: 2}", "{d: 0.5, l1: 1.5, l2: 2.5}"),
                                  ("{th1: [pi/3, pi], th2: [0, 2*pi/3]}",
                                   "{th1: [0.5, 3], th2: [0.1, 2.6]}"))),
    "ortho-millimetres": (ORTHO, path("[-pi, pi]", x="1000 + 500*cos(t)", y="500 + 500*sin(t)",
                                      z="1000"),
                          (("{l: 2}", "{l: 2000}"),
                           ("{rho1: [0, 4], rho2: [0, 4], rho3: [0, 4]}",
                            "{rho1: [0, 4000], rho2: [0, 4000], rho3: [0, 4000]}"))),
    "3-rpr-through-singular": (RPR, path("[-1, 1]", x="1 + t/5", y="t/7", phi="t/3"), ()),
    "3-rpr-constant-singular": (RPR, path("[0, 1]", x="1", y="0", phi="0"), ()),
    "rotary-delta-real-offset": (RDELTA, path("[0, 1]", x="7/4 + 3*t/10", y="0", z="-1"),
                                 (("{e: 1/2,", "{e: cos(1/2)/2,"),)),
    # the rail at 1 rad written as users do: rho2^2 has the coefficient c^2 + s^2, which
    # balls prove ≠ 0 but nothing proves = 1 (it was refused, exit 2: "divide it out")
    "skew-rail-at-one-radian": (SKEW, path("[-pi, pi]", x="-1 + cos(t)", y="-1 + sin(t)/2"),
                                (("{l1: 2, l2: 3/2}", "{l1: 2, l2: 3/2, c: cos(1), s: sin(1)}"),
                                 ("(x - 3/5*rho2)^2 + (y - 4/5*rho2)^2",
                                  "(x - c*rho2)^2 + (y - s*rho2)^2"))),
}


#: over ~3 s each here (singcheck's interval engine on the rotary Delta's real offset;
#: the oracle on the 3-RPR standing still)
SLOW = {"rotary-delta-real-offset", "3-rpr-constant-singular"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n
                                  for n in sorted(CASES)])
def test_field_input_matches_the_oracle(tmp_path, name):
    robot, traj, edits = CASES[name]
    robot_file, traj_file = files(tmp_path, robot, traj, edits)
    assert_agrees(singcheck(robot_file, traj_file), oracle(robot_file, traj_file))


def test_a_leg_stretched_at_a_simple_time_is_proven_infeasible(tmp_path):
    """x = 0, y = 3/2·cos(t − 1) on [0, 2]: the biglide's leg of length 3/2 is fully
    stretched at t = 1 (y = 3/2), where its two branches q = ±√(9/4 − y²) meet (the
    oracle: D = 9/4 − y² ≥ 0, = 0 only there, a touch), so no mode follows the path.
    Balls see no sign change of D; only the interval engine takes the shifted cosine,
    and the answer was ``unknown``.  D is now decided exactly at the simplest rational
    of the window left: 0 at t = 1."""
    mp.mp.dps = 50
    d = [mp.mpf(9) / 4 - (mp.mpf(3) / 2 * mp.cos(mp.mpf(k) / 500 - 1)) ** 2
         for k in range(1001)]
    assert min(d) == d[500] == 0 and all(v > 0 for k, v in enumerate(d) if k != 500)
    robot_file, traj_file = files(tmp_path, BIGLIDE, path("[0, 2]", x="0",
                                                          y="3/2*cos(t - 1)"))
    truth = oracle(robot_file, traj_file)
    assert truth.verdict == "infeasible"
    result = singcheck(robot_file, traj_file)
    assert result["verdict"] == "infeasible", result["reason"]
    for mode in result["working_modes"]:
        assert "the two branches of q meet at t = 1, decided exactly" in mode["reason"]


def test_a_csv_table_matches_the_oracle(tmp_path):
    """A four-row CSV log on the Orthoglide, read with the default cubic spline."""
    table = "t,x,y,z\n0,0.25,0.6,1\n1,0.9,1.1,1\n2,1.2,0.3,1\n3,0.4,0.2,1.1\n"
    robot_file, traj_file = files(tmp_path, ORTHO, table, csv=True)
    truth = oracle(robot_file, traj_file)
    assert truth.verdict == "singular" and len(truth.times) == 2
    assert_agrees(singcheck(robot_file, traj_file), truth)


@pytest.mark.parametrize(("rng", "x", "y", "at", "text"), [
    ("[0, 2]", "t/2 - 1/2", "1 - cos(t - 1)", 1.0, "1"),
    ("[5, 7]", "t/2 - 3", "1 + cos(t/2)", float(mp.pi) * 2, "2*pi"),
])
def test_a_tangency_at_a_simple_time_is_proven_singular(tmp_path, rng, x, y, at, text):
    """y = 1 − cos(t − 1) touches the biglide's singularity y = 0 at t = 1 without a sign
    change, y = 1 + cos(t/2) at t = 2π; only the interval engine takes these arguments,
    and a touch is no sign change, so it once answered ``unknown`` with a window there.
    The window's simplest rational (or multiple of π) is tried exactly: det A = 0 there
    (the rational pose (0, 0); the factor y of det A at (π − 3, 0)), so every mode is
    singular there, proven.  Oracle: fo.judge (det A along each mode at 50 digits, the
    touch found as a minimum of |det A|)."""
    robot_file, traj_file = files(tmp_path, BIGLIDE, path(rng, x=x, y=y))
    truth = oracle(robot_file, traj_file)
    assert truth.verdict == "singular" and len(truth.times) == 1
    assert abs(truth.times[0] - at) < 1e-9
    result = singcheck(robot_file, traj_file)
    assert_agrees(result, truth)
    assert result["undecided"] == [] and result["reason"].endswith(f"at t = {text} (exactly)")
    (c,) = result["candidates"]
    assert all(m["proof"].startswith("det A = 0 exactly") for m in c["modes"])


def _biglide_sine_oracle(x):
    """The zeros of det A = 4·y·(q − p) on y = sin(2πt)/2, t ∈ [0, 1]: those of y (q − p
    stays away from 0 in every mode, checked at 50 digits), found by mpmath."""
    mp.mp.dps = 50
    y = lambda t: mp.sin(2 * mp.pi * t) / 2  # noqa: E731
    roots = sorted({mp.findroot(y, mp.mpf(g)) for g in ("0", "0.49", "0.99")})
    assert [float(r) for r in roots] == [0.0, 0.5, 1.0]
    for k in range(101):
        t = mp.mpf(k) / 100
        for s1 in (1, -1):
            for s2 in (1, -1):
                p = x(t) + s1 * mp.sqrt(4 - y(t) ** 2)
                q = x(t) + s2 * mp.sqrt(mp.mpf(9) / 4 - y(t) ** 2)
                assert abs(q - p) > mp.mpf("0.4")
    return [float(r) for r in roots]


def test_a_factor_of_det_a_in_the_pose_decides_an_irrational_end(tmp_path):
    """x = √2·t, y = sin(2πt)/2 on [0, 1]: the biglide is singular at t = 0, 1/2 and 1 in
    all four modes.  At t = 1 the pose (√2, 0) is not rational, so the rational-pose
    determinant cannot decide it, and singcheck once dropped that end silently, then
    left it an undecided window; det A = 4·y·(q − p) has the factor y, in the pose
    alone, which is exactly 0 there: every mode is singular at t = 1, proven so."""
    roots = _biglide_sine_oracle(lambda t: mp.sqrt(2) * t)
    robot_file, traj_file = files(tmp_path, BIGLIDE,
                                  path("[0, 1]", x="sqrt(2)*t", y="sin(2*pi*t)/2"))
    result = singcheck(robot_file, traj_file)
    assert result["verdict"] == "singular" and result["undecided"] == []
    for mode in result["working_modes"]:
        assert len(mode["singular_times"]) == 3
        for t, r in zip(mode["singular_times"], roots, strict=True):
            assert abs(t - r) <= TOL
    (end,) = [c for c in result["candidates"] if c["t"] == 1.0]
    assert {m["proof"] for m in end["modes"]} == {
        "det A = 0 exactly (a factor of det A in the pose alone is 0 there)"}


def test_a_mode_singular_at_an_end_has_its_other_singular_times_listed(tmp_path):
    """x = t/2, y = sin(2πt)/2 + t²/100 on [0, 2.3] (only the interval engine takes π·t):
    det A = 0 exactly at t = 0 along all four modes.  Those modes were not searched
    further, so their one window was the whole range, settled by the zero at t = 0: the
    report gave t = 0 only, its enclosure [0, 2.3].  Now every zero of y is a singular
    time of every mode, one candidate each, nothing undecided.  Oracle: det A = 4·y·(q − p)
    (q − p ≠ 0: checked at 50 digits), so the singular times are the zeros of y,
    bracketed by sign changes on a 2,300-point grid and refined by mpmath."""
    mp.mp.dps = 50
    y = lambda t: mp.sin(2 * mp.pi * t) / 2 + t**2 / 100  # noqa: E731
    grid = [mp.mpf(k) / 1000 for k in range(1, 2301)]
    roots = [0.0] + [float(mp.findroot(y, (a, b), solver="anderson"))
                     for a, b in zip(grid, grid[1:], strict=False) if y(a) * y(b) < 0]
    assert len(roots) == 5
    for t in grid[::10]:
        for s1 in (1, -1):
            for s2 in (1, -1):
                p = t / 2 + s1 * mp.sqrt(4 - y(t) ** 2)
                q = t / 2 + s2 * mp.sqrt(mp.mpf(9) / 4 - y(t) ** 2)
                assert abs(q - p) > mp.mpf("0.4")
    robot_file, traj_file = files(tmp_path, BIGLIDE, path(
        "[0, 2.3]", x="t/2", y="sin(2*pi*t)/2 + t^2/100"))
    result = singcheck(robot_file, traj_file)
    assert result["verdict"] == "singular" and result["undecided"] == []
    assert len(result["candidates"]) == len(roots)
    for c, r in zip(result["candidates"], roots, strict=True):
        a, b = c["t_interval"]
        assert a - 1e-12 <= r <= b + 1e-12 and b - a < 1e-6
        assert {m["mode"] for m in c["modes"]} == {"++", "+-", "-+", "--"}
    for mode in result["working_modes"]:
        assert len(mode["singular_times"]) == len(roots)


@pytest.mark.slow
def test_gough_stewart_through_decimal_waypoints(tmp_path):
    """Six coordinates through three decimal waypoints (linear), turning past the
    Plücker singularity near psi ≈ 1.55 (the oracle alone takes ~20 s: SymPy's 6×6 A)."""
    traj = waypoints("linear",
                     {"t": 0, "x": 0, "y": 0, "z": 2, "psi": 1.3, "theta": 0, "phi": 0},
                     {"t": 1, "x": 0.1, "y": 0, "z": 2, "psi": 1.8, "theta": 0.05, "phi": 0},
                     {"t": 2, "x": 0.1, "y": 0.1, "z": 2.1, "psi": 1.8, "theta": 0.05,
                      "phi": 0.05})
    robot_file, traj_file = files(tmp_path, GS, traj)
    assert_agrees(singcheck(robot_file, traj_file), oracle(robot_file, traj_file))


@pytest.mark.parametrize(("rng", "y", "guess", "edits"), [
    ("[1/4, 3/4]", "sin(2*pi*t)/2", "0.49", ()),
    ("[-1/4, 1/4]", "sin(2*pi*t)/2", "0.01", ()),
    ("[0, 1]", "1/2 - t", "0.4", (("constraints:", "parameters: {a: 2*cos(1/10)}\nconstraints:"),
                                  ("- 4\n", "- a^2\n"))),
])
def test_a_crossing_on_a_piece_boundary_is_counted_once(tmp_path, rng, y, guess, edits):
    """A root in the middle of the range lies where the interval engine halves it: two
    pieces, each proven to hold one simple crossing, overlap there by their balls'
    rounded ends, and singcheck once reported that one root twice per mode (singular
    times 0.4999999999 and 0.5000000001).  The oracle: the biglide's det A is
    4·y·(q − p) with q − p bounded away from 0 (checked here at 50 digits on the path), so
    its zeros are those of y(t), one simple root in the range."""
    mp.mp.dps = 50
    a = 2 * mp.cos(mp.mpf(1) / 10) if edits else mp.mpf(2)
    lo, hi = (mp.mpf(eval(e.replace("pi", "mp.pi"))) for e in rng.strip("[]").split(","))  # noqa: S307 - our own strings
    f = {"sin(2*pi*t)/2": lambda t: mp.sin(2 * mp.pi * t) / 2,
         "1/2 - t": lambda t: mp.mpf(1) / 2 - t}[y]
    root = mp.findroot(f, mp.mpf(guess))
    assert lo < root < hi
    assert all((f(lo + (hi - lo) * k / 400) > 0) == (f(lo + (hi - lo) * (k + 1) / 400) > 0)
               or lo + (hi - lo) * k / 400 <= root <= lo + (hi - lo) * (k + 1) / 400
               for k in range(400))
    for k in range(401):  # q − p never 0: legs a and 3/2 meet the rail apart
        t = lo + (hi - lo) * k / 400
        for s1 in (1, -1):
            for s2 in (1, -1):
                p = t + s1 * mp.sqrt(a**2 - f(t) ** 2)
                q = t + s2 * mp.sqrt(mp.mpf(9) / 4 - f(t) ** 2)
                assert abs(q - p) > mp.mpf("0.1")
    robot_file, traj_file = files(tmp_path, BIGLIDE, path(rng, x="t", y=y), edits)
    result = singcheck(robot_file, traj_file)
    assert result["verdict"] == "singular", result["reason"]
    for mode in result["working_modes"]:
        assert mode["feasible"]
        assert len(mode["singular_times"]) == 1, (mode["label"], mode["singular_times"])
        assert abs(mode["singular_times"][0] - float(root)) <= TOL
