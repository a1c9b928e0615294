"""Touches on paths whose pose angle is a polynomial g(t), not k·t + qπ (issue 13).

The bundled 3-RPR turns with phi = t² while its position follows the curve
X*(φ) = ((3 sin φ + cos φ)/4, -sin φ), where leg lines 2 and 3 pass through the base
point A1 = (0, 0) (so all three leg lines meet there: singular for every φ), plus
w(t)²·(1, 2) with w = t - cos(t²).  det A then touches 0 where t = cos(t²) (a
transcendental time), without changing sign.  The expected answers are computed here
with 50-digit mpmath (the oracle's det A, independent of singcheck).
"""

from __future__ import annotations

from fractions import Fraction

import mpmath as mp
import pytest
from flint import fmpq

from singcheck import api
from singcheck.algebra.radicals import angle_function, path_ring
from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange
from singcheck.errors import SpecError
from singcheck.report.trajectory import workspace_json, workspace_line
from singcheck.roots.isolation import isolate_real_roots
from singcheck.roots.transcendental import TranscendentalPoint, angle_circle
from singcheck.spaces.path_regions import path_in_workspace
from tests import robot_oracles as oracles
from tests.conftest import ROBOTS

TOUCH = """\
name: rpr-touch
parameter: t
range: [7/10, 9/10]
pose:
  x: (3*sin(t^2) + cos(t^2))/4 + (t - cos(t^2))^2{dx}
  y: -sin(t^2) + 2*(t - cos(t^2))^2{dy}
  phi: t^2
"""


def _pose(t, dx=0, dy=0):
    c, s = mp.cos(t * t), mp.sin(t * t)
    w2 = (t - c) ** 2
    return [(3 * s + c) / 4 + w2 + dx, -s + 2 * w2 + dy, t * t]


def _det(t, dx=0, dy=0):
    oracle = oracles.three_rpr()
    X = _pose(t, dx, dy)
    return oracle.det_A(None, X)  # det A of the 3-RPR does not involve the joints


_ROBOT: list = []


def _run(tmp_path, text):
    if not _ROBOT:
        _ROBOT.append(api.load_robot(ROBOTS / "3-rpr.yaml", backend="flint", cache=False))
    path = tmp_path / "t.yaml"
    path.write_text(text)
    return api.check(_ROBOT[0], api.load_trajectory(path, _ROBOT[0]), regions=False)


def test_a_touch_at_a_transcendental_time_on_a_phi_t_squared_path_is_singular(tmp_path):
    mp.mp.dps = 50
    tau = mp.findroot(lambda t: t - mp.cos(t * t), mp.mpf("0.8"))
    assert abs(_det(tau)) < mp.mpf(10) ** -40  # on the surface at τ
    before, after = _det(tau - mp.mpf("0.001")), _det(tau + mp.mpf("0.001"))
    assert before * after > 0  # no sign change: a touch, which no sign change proves
    samples = [_det(mp.mpf(7) / 10 + k * mp.mpf(2) / 1000) for k in range(101)]
    assert all(v * before > 0 for v in samples if abs(v) > mp.mpf(10) ** -6)
    # the mode is feasible there (every leg length within [1/2, 5])
    X = _pose(tau)
    assert all(any(leg.lo < b < leg.hi for b in leg.branches(X))
               for leg in oracles.three_rpr().legs)

    result = _run(tmp_path, TOUCH.format(dx="", dy=""))
    assert result.verdict == "singular"
    assert len(result.candidates) == 1
    t = result.candidates[0].t
    assert abs(float(t.mid()) - float(tau)) < 1e-8
    line = workspace_line(workspace_json(path_in_workspace(result.path, name_region=False)))
    assert "touching it 1" in line


def test_a_phi_t_squared_path_that_comes_close_is_proven_free(tmp_path):
    mp.mp.dps = 50
    dx, dy = mp.mpf(1) / 1000, mp.mpf(2) / 1000
    values = [_det(mp.mpf(7) / 10 + k * mp.mpf(2) / 4000, dx, dy) for k in range(401)]
    assert all(v > 0 for v in values) or all(v < 0 for v in values)
    # it does come close: a dip to under a tenth of det A's size at the range ends
    assert min(abs(v) for v in values) < min(abs(values[0]), abs(values[-1])) / 10
    result = _run(tmp_path, TOUCH.format(dx=" + 1/1000", dy=" + 2/1000"))
    assert result.verdict == "singularity-free"


def test_a_square_on_the_pose_angle_circle_is_decided_exactly():
    """(sin(t²) - t/2)², written reduced (1 - cos² - t·sin + t²/4: not a square as a
    polynomial), touches 0 where sin(t²) = t/2; its conjugate sin(t²) + t/2 does not."""
    mp.mp.dps = 50
    tau = mp.findroot(lambda t: mp.sin(t * t) - t / 2, mp.mpf("0.5"))
    g = TRIG.gens()[0] ** 2
    names = angle_function(g, Fraction(0))
    ring = path_ring([], [names])
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    t, C, S = gens["t"], gens[names[0]], gens[names[1]]
    p = 1 - C * C - t * S + t * t / 4  # = (S - t/2)² on the circle
    interval = TimeRange(LinearInPi(Fraction(2, 5)), LinearInPi(Fraction(1)))
    iso = isolate_real_roots(p, interval)
    assert not iso.undecided
    assert len(iso.roots) == 1
    root = iso.roots[0]
    assert abs(float(root.t.mid()) - float(tau)) < 1e-8
    point = TranscendentalPoint(root.exact)
    assert point.is_zero(S - t / 2)
    assert point.is_zero(p)
    assert not point.is_zero(S + t / 2)
    assert not point.is_zero(t - C)  # cos(τ²) ≠ τ there (the other test's touch)


@pytest.mark.parametrize("angle", ["t^2 + 1", "t"])
def test_cos_of_the_angle_in_a_coordinate_needs_that_angle(tmp_path, angle):
    """cos(t^2) in a coordinate is the pose angle's cos only when phi is t^2: otherwise
    the path is not exact (only the interval engine takes it, and says why)."""
    text = TOUCH.format(dx="", dy="").replace("phi: t^2", f"phi: {angle}")
    path = tmp_path / "t.yaml"
    path.write_text(text)
    if not _ROBOT:
        _ROBOT.append(api.load_robot(ROBOTS / "3-rpr.yaml", backend="flint", cache=False))
    spec = api.load_trajectory(path, _ROBOT[0])
    assert "cos(t^2)" in spec.not_algebraic
    with pytest.raises(SpecError, match="only the interval engine takes it"):
        api.check(_ROBOT[0], spec, engine="exact", regions=False)


def test_two_independent_angles_a_structural_touch_is_found_through_the_norm():
    """(sin(t²) - sin(t)/2)²: a touch at a point (τ, cos τ, cos τ²) whose transcendence
    degree is not known (Schanuel's conjecture), so no generic-point test applies.  The
    norm over both sines is a square, its factor changes sign at τ (bracketed), and the
    conjugates other than p itself ((sin t²+ sin(t)/2)²) are enclosed away from 0 there:
    so p vanishes at τ, proven.  The same path lifted by 10⁻⁶ has no zero, and none is
    claimed."""
    mp.mp.dps = 50
    tau = mp.findroot(lambda t: mp.sin(t * t) - mp.sin(t) / 2, mp.mpf("0.47"))
    assert mp.sin(tau * tau) + mp.sin(tau) / 2 > mp.mpf("0.1")  # the conjugate is not 0
    g = TRIG.gens()[0] ** 2
    names = angle_function(g, Fraction(0))
    ring = path_ring([], [names])
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    s, c, S = gens["s"], gens["c"], gens[names[1]]
    p = (S - s / 2) ** 2
    interval = TimeRange(LinearInPi(Fraction(484, 1000)), LinearInPi(Fraction(486, 1000)))
    iso = isolate_real_roots(p, interval, tolerance=1e-5)  # coarse: fewer boxes
    assert not iso.undecided
    [root] = iso.roots
    assert float(root.t.lower()) <= tau <= float(root.t.upper())
    lift = ring.from_dict({(0,) * len(ring.names()): fmpq(1, 10 ** 6)})
    lifted = isolate_real_roots(p + lift, interval, tolerance=1e-5)
    assert not lifted.roots and not lifted.undecided
    assert angle_circle(p) is None
    assert angle_circle(S * S + c) is None  # any use of sin t, cos t with the angle


def test_a_touch_at_a_zero_of_the_angle_polynomial_is_an_exact_point(tmp_path):
    """phi = t² at the constant position (2, 2), on the 3-RPR's surface at φ = 0
    (x + y = 4 there): det A(φ(t)) touches 0 at t = 0, where g = t² vanishes and
    everything is rational (cos 0 = 1, sin 0 = 0)."""
    mp.mp.dps = 50
    oracle = oracles.three_rpr()

    def det(t):
        return oracle.det_A(None, [mp.mpf(2), mp.mpf(2), t * t])

    assert det(mp.mpf(0)) == 0
    assert det(mp.mpf("-0.01")) * det(mp.mpf("0.01")) > 0  # the same sign: a touch
    values = [det(mp.mpf(k) / 100) for k in range(-50, 51) if k]
    assert all(v * values[0] > 0 for v in values)  # no other zero on [-1/2, 1/2]
    assert all(any(leg.lo < b < leg.hi for b in leg.branches([2, 2, mp.mpf(0)]))
               for leg in oracle.legs)
    text = TOUCH.format(dx="", dy="").replace("[7/10, 9/10]", "[-1/2, 1/2]")
    text = text.replace(text[text.index("  x:"):text.index("  phi:")], "  x: 2\n  y: 2\n")
    result = _run(tmp_path, text)
    assert result.verdict == "singular"
    assert len(result.candidates) == 1
    assert result.candidates[0].t.is_exact() and result.candidates[0].t == 0


# -- zeros of the angle's polynomial g at irrational times, and with 2q not an integer ----

ANGLE_ZERO = """\
name: angle-zero
parameter: t
range: [{lo}, {hi}]
pose:
  x: {x}
  y: {y}
  phi: {phi}
"""

# a pose on the 3-RPR's singular surface at φ = π/3, found in Q(√3) (rational points of
# that conic: only (0, 0)): (1/2 + 3√3/10, -1/2 - 3√3/10); P(t) = 3t/2 - t³/6 has
# P(√3) = √3 and P'(√3) = 0, so x = 1/2 + 3P(t)/10 sits there at t = √3 with speed 0
_X_SQRT3 = "1/2 + 9*t/20 - t^3/20{dx}"
_Y_SQRT3 = "-1/2 - 9*t/20 + t^3/20"


def _det_along(x, y, phi):
    return lambda t: oracles.three_rpr().det_A(None, [x(t), y(t), phi(t)])


@pytest.mark.parametrize("case", ["sqrt2-touch", "sqrt3-third-pi-touch"])
def test_a_touch_at_an_irrational_zero_of_the_angle_polynomial_is_singular(tmp_path, case):
    """At a zero τ of g the point (τ, cos qπ, sin qπ) is algebraic: τ = √2 for
    phi = (t² - 2)² at the constant position (2, 2) (on the surface at φ = 0, as above);
    τ = √3 for phi = (t² - 3)² + π/3, where cos, sin = 1/2, √3/2 (2q not an integer),
    at a position on the surface at φ = π/3 reached with speed 0.  det A touches 0 there
    (50-digit mpmath) and singcheck proves the touch exactly (issue 13)."""
    mp.mp.dps = 50
    if case == "sqrt2-touch":
        tau, lo, hi = mp.sqrt(2), "1", "2"
        det = _det_along(lambda t: mp.mpf(2), lambda t: mp.mpf(2), lambda t: (t * t - 2) ** 2)
        text = ANGLE_ZERO.format(lo=lo, hi=hi, x="2", y="2", phi="(t^2 - 2)^2")
    else:
        tau, lo, hi = mp.sqrt(3), "8/5", "9/5"
        det = _det_along(lambda t: mp.mpf(1) / 2 + 9 * t / 20 - t ** 3 / 20,
                         lambda t: -mp.mpf(1) / 2 - 9 * t / 20 + t ** 3 / 20,
                         lambda t: (t * t - 3) ** 2 + mp.pi / 3)
        text = ANGLE_ZERO.format(lo=lo, hi=hi, x=_X_SQRT3.format(dx=""), y=_Y_SQRT3,
                                 phi="(t^2 - 3)^2 + pi/3")
    assert abs(det(tau)) < mp.mpf(10) ** -40  # on the surface at τ
    eps = mp.mpf(10) ** -3
    assert det(tau - eps) * det(tau + eps) > 0  # the same sign on both sides: a touch
    result = _run(tmp_path, text)
    assert result.verdict == "singular", result.reason
    [candidate] = [c for c in result.candidates
                   if float(c.t.lower()) <= tau <= float(c.t.upper())]
    assert candidate.root.multiplicity % 2 == 0


def test_a_near_miss_of_a_touch_with_two_q_not_an_integer_is_proven_free(tmp_path):
    """The same path moved by 1/1000 in x: det A keeps one sign on the whole range
    (50-digit samples), and singcheck proves it free rather than `unknown`."""
    mp.mp.dps = 50
    det = _det_along(lambda t: mp.mpf(1) / 2 + 9 * t / 20 - t ** 3 / 20 + mp.mpf(1) / 1000,
                     lambda t: -mp.mpf(1) / 2 - 9 * t / 20 + t ** 3 / 20,
                     lambda t: (t * t - 3) ** 2 + mp.pi / 3)
    values = [det(mp.mpf(8) / 5 + k * mp.mpf(1) / 2000) for k in range(401)]
    assert all(v > 0 for v in values) or all(v < 0 for v in values)
    text = ANGLE_ZERO.format(lo="8/5", hi="9/5", x=_X_SQRT3.format(dx=" + 1/1000"),
                             y=_Y_SQRT3, phi="(t^2 - 3)^2 + pi/3")
    result = _run(tmp_path, text)
    assert result.verdict == "singularity-free", result.reason


def test_the_zero_test_at_a_zero_of_g_with_two_q_not_an_integer():
    """AngleZero decides exactly at (√3, sin π/3, cos π/3): s - √3/2·… written with t:
    2s - t vanishes there (sin π/3 = √3/2), 2s - t + 10⁻³⁰ does not, 4c² - 1 does, and
    2c - 1 + s - t/2 (a sum of two zeros) does; decided by the annihilating polynomial
    and its root bound, never by a ball alone."""
    from flint import fmpq, fmpq_poly

    from singcheck.roots.angle_zeros import AngleZero
    from singcheck.roots.rational import real_roots_exact

    [(root, _)] = [(r, m) for r, m in real_roots_exact(fmpq_poly([-3, 0, 1])) if r.lo > 0]
    point = AngleZero(root, Fraction(1, 3))
    t, s, c = TRIG.gens()
    assert point.is_zero(2 * s - t)
    assert not point.is_zero(2 * s - t + fmpq(1, 10 ** 30))
    assert point.is_zero(4 * c * c - 1)
    assert point.is_zero(2 * c - 1 + s - t / 2)
    assert not point.is_zero(c - 1)


def test_a_polynomial_in_t_and_the_angle_is_enclosed_at_the_angles_balls():
    """evaluate_path on a ring (t, s, c, cos(t^2), sin(t^2)) goes through one Horner form
    in C with S and t outside (the 3-PRR's phi = t² path: 6 s → 0.4 s); its balls hold
    the 50-digit values at points and over small boxes."""
    from flint import arb

    from singcheck.algebra.radicals import evaluate_path

    mp.mp.dps = 50
    ring = path_ring([], [angle_function(TRIG.gens()[0] ** 2, 0)])
    t, C, S = ring.gens()[0], ring.gens()[3], ring.gens()[4]
    p = 3 * t ** 2 * C ** 3 - t * S * C + 5 * S ** 2 - 7 * C / 3 + t ** 4
    for x in ("0.3", "-1.7", "2.25"):
        tm = mp.mpf(x)
        exact = (3 * tm ** 2 * mp.cos(tm ** 2) ** 3 - tm * mp.sin(tm ** 2) * mp.cos(tm ** 2)
                 + 5 * mp.sin(tm ** 2) ** 2 - mp.mpf(7) / 3 * mp.cos(tm ** 2) + tm ** 4)
        ball = evaluate_path(p, arb(x))
        assert ball.rad() < 1e-10
        assert abs(float(ball.mid()) - float(exact)) <= float(ball.rad()) + 1e-15
        box = evaluate_path(p, arb(x, "0.01"))  # every value on [x - 0.01, x + 0.01]
        for k in range(-10, 11):
            tk = tm + mp.mpf(k) / 1000
            v = (3 * tk ** 2 * mp.cos(tk ** 2) ** 3 - tk * mp.sin(tk ** 2) * mp.cos(tk ** 2)
                 + 5 * mp.sin(tk ** 2) ** 2 - mp.mpf(7) / 3 * mp.cos(tk ** 2) + tk ** 4)
            assert float(box.lower()) <= float(v) <= float(box.upper())


def test_a_pose_angle_offset_with_a_huge_denominator_is_not_taken_exactly(tmp_path):
    """q = 1/1000001: cos qπ's minimal polynomial would come from a Chebyshev polynomial
    of degree 10⁶ (the process was killed for memory); the exact test declines it up
    front and the path is certified as before, in well under a second of work."""
    import time

    mp.mp.dps = 50
    det = _det_along(lambda t: mp.mpf(2), lambda t: mp.mpf(2),
                     lambda t: (t * t - 2) ** 2 + mp.pi / 1000001)
    tau = mp.findroot(det, mp.mpf("1.937"))  # φ ≈ π there: a crossing
    assert det(tau - mp.mpf("0.001")) * det(tau + mp.mpf("0.001")) < 0
    start = time.process_time()
    text = ANGLE_ZERO.format(lo="1", hi="2", x="2", y="2", phi="(t^2 - 2)^2 + pi/1000001")
    result = _run(tmp_path, text)
    assert time.process_time() - start < 20
    assert result.verdict == "singular"
    assert any(float(c.t.lower()) <= tau <= float(c.t.upper()) for c in result.candidates)


def test_a_zero_at_t_0_of_a_path_with_two_arguments_is_an_exact_point(tmp_path):
    """x = 2 + (sin(t)/2 - sin(t²))²/4, y = 2, phi = t²: at t = 0 the pose is (2, 2) at
    φ = 0, on the 3-RPR's surface (det A = 0, computed here), and there sin t, cos t and
    the angle's cos, sin are all exact (g(0) = 0), so the zero and its multiplicity are
    decided exactly; it stayed a cloud of undecided windows around 0 (campaign)."""
    mp.mp.dps = 50
    oracle = oracles.three_rpr()
    assert oracle.det_A(None, [mp.mpf(2), mp.mpf(2), mp.mpf(0)]) == 0
    text = ANGLE_ZERO.format(lo="-1/2", hi="3/4", x="2 + (sin(t)/2 - sin(t^2))^2/4",
                             y="2", phi="t^2")
    result = _run(tmp_path, text)
    assert result.verdict == "singular", result.reason
    at_zero = [c for c in result.candidates if c.t.is_exact() and c.t == 0]
    assert len(at_zero) == 1
    assert not any(float(u[0].lower()) <= 0 <= float(u[0].upper())
                   for u in result.certificate.undecided)
