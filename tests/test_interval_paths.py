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
