"""Classification proofs beyond the paper's example: robots built for the purpose."""

from __future__ import annotations

import pytest
from flint import arb, fmpq

from singcheck.algebra.intervals import endpoints
from singcheck.certify.classification import certify_path
from singcheck.certify.path import build_path
from singcheck.elimination.cas import get_backend
from singcheck.elimination.projection import project_robot
from singcheck.model.robot import build_model
from singcheck.spec.files import parse_robot, parse_trajectory

# Two legs on the same rail with different lengths: det A = 4y(q - p), so every working
# mode is singular where y = 0, and the elimination proof (one vanishing mode) cannot
# apply: the proofs must come from exact evaluation or a sign change.
BIGLIDE = """\
name: biglide
joints: [p, q]
pose: [x, y]
constraints:
  - (x - p)^2 + y^2 - 4
  - (x - q)^2 + y^2 - 9/4
joint_limits: {p: [-4, 4], q: [-4, 4]}
"""


def certify(robot_text: str, trajectory_text: str):
    model = build_model(parse_robot(robot_text, "r.yaml"))
    projection = project_robot(model, get_backend("sympy"))
    return certify_path(build_path(projection, parse_trajectory(trajectory_text, "t.yaml",
                                                                 model.spec)))


def ellipse(start: str, end: str) -> str:
    return (f"name: e\nparameter: t\nrange: [{start}, {end}]\npose:\n  x: cos(t)\n"
            "  y: sin(t)/2\n")


def test_all_modes_singular_at_once_are_proven_by_sign_change_and_exactly():
    report = certify(BIGLIDE, ellipse("-pi/2", "3*pi/2"))
    assert report.verdict == "singular"
    assert [round(float(c.t.mid()), 9) for c in report.candidates] == [0.0, 3.141592654]
    at_zero, at_pi = report.candidates
    assert {m.proof for m in at_zero.modes} == {"det A = 0 exactly"}
    assert {m.proof for m in at_pi.modes} == {"sign change"}
    assert all(m.status == "singular" for c in report.candidates for m in c.modes)
    assert len([m for m in report.modes if m.feasible]) == 4


def test_a_path_avoiding_y_zero_is_free():
    text = "name: e\nparameter: t\nrange: [0, 2*pi]\npose:\n  x: cos(t)\n  y: 1 + sin(t)/4\n"
    report = certify(BIGLIDE, text)
    assert report.verdict == "singularity-free"
    assert report.candidates == []


def test_a_path_leaving_the_workspace_is_infeasible():
    # y reaches 3/2 + 1 > 3/2 = l2: leg 2 has no real solution there
    text = "name: e\nparameter: t\nrange: [0, 2*pi]\npose:\n  x: 0\n  y: 1 + 3/2*sin(t)\n"
    report = certify(BIGLIDE, text)
    assert report.verdict == "infeasible"
    assert "q" in report.reason and "serial singularity" in report.reason


def test_joint_limits_make_modes_infeasible_at_a_certified_time():
    tight = BIGLIDE.replace("{p: [-4, 4], q: [-4, 4]}", "{p: [0, 4], q: [-4, 4]}")
    text = "name: e\nparameter: t\nrange: [0, 2*pi]\npose:\n  x: cos(t)\n  y: 1 + sin(t)/4\n"
    report = certify(tight, text)
    modes = {m.label: m for m in report.modes}
    # p = x + sqrt(4 - y^2) >= 0 along the whole path; p = x - sqrt(...) < 0 always
    assert modes["++"].feasible and modes["+-"].feasible
    assert not modes["-+"].feasible and "outside [0, 4]" in modes["-+"].reason


def test_json_endpoints_keep_exact_floats_and_round_the_rest_outward():
    assert endpoints(arb(0)) == (0.0, 0.0)
    lo, hi = endpoints(arb(fmpq(1, 3)))
    assert lo < 1 / 3 < hi


@pytest.mark.parametrize("start, end", [("0", "pi"), ("-pi", "0")])
def test_roots_at_range_ends_are_kept(start, end):
    report = certify(BIGLIDE, ellipse(start, end))
    assert len(report.candidates) == 2  # y = 0 at both ends
    assert report.verdict == "singular"


def _biglide_path(limits: str, x: str):
    model = build_model(parse_robot(BIGLIDE.replace("{p: [-4, 4], q: [-4, 4]}", limits),
                                    "r.yaml"))
    projection = project_robot(model, get_backend("sympy"))
    text = f"name: e\nparameter: t\nrange: [0, 2*pi]\npose:\n  x: {x}\n  y: 1 + sin(t)/4\n"
    return build_path(projection, parse_trajectory(text, "t.yaml", model.spec))


def _branch(t, sign: int, length2, x_of) -> object:
    import mpmath as mp

    y = 1 + mp.sin(t) / 4
    return x_of(t) + sign * mp.sqrt(length2 - y * y)


def test_the_leg_sweep_proves_only_what_holds_at_every_sample():
    """The one-walk quick proofs (certify/sweep.py): every fact it proves holds at 2000
    points of the path at 50 digits, and the facts that fail there are not proven."""
    import mpmath as mp

    from singcheck.certify.sweep import sweep_quick_proofs
    from singcheck.certify.working_modes import start_branches

    mp.mp.dps = 50
    path = _biglide_path("{p: [0, 4], q: [-1, 1]}", "cos(t)")
    limits = path.projection.model.spec.joint_limits
    proven, tried = sweep_quick_proofs(path, limits, start_branches(path))
    samples = [2 * mp.pi * k / 1999 for k in range(2000)]
    legs = {0: (4, (0, 4)), 1: (mp.mpf(9) / 4, (-1, 1))}  # l², limits
    for (i, label) in tried:
        length2, (lo, hi) = legs[i]
        if label is None:
            holds = all(length2 - (1 + mp.sin(t) / 4) ** 2 > 0 for t in samples)
        else:
            sign = 1 if label == "+" else -1
            holds = all(lo < _branch(t, sign, length2, mp.cos) < hi for t in samples)
        assert holds == ((i, label) in proven), (i, label)
    # p = cos t + √(4 - y²) stays in (0, 4); q = cos t + √(9/4 - y²) starts outside
    # [-1, 1] (not swept: decided at the start), q = cos t - √(…) starts inside, leaves
    assert {(0, None), (1, None), (0, "+")} <= proven
    assert (1, "+") not in tried and (0, "-") not in tried
    assert (1, "-") in tried and (1, "-") not in proven


def test_a_branch_the_sweep_cannot_prove_leaves_its_limits_at_the_right_time():
    """p = 2 cos t + √(4 - y²) starts inside [0, 4] and goes below 0: the sweep tries and
    fails, the limit crossing is isolated; its time agrees with mpmath's root."""
    import mpmath as mp

    from singcheck.certify.working_modes import working_modes

    mp.mp.dps = 50
    path = _biglide_path("{p: [0, 4], q: [-4, 4]}", "2*cos(t)")
    modes = {m.label: m for m in working_modes(path)}
    branch = next(b for b in modes["++"].branches if b.joint == "p")
    assert branch.status == "infeasible" and "p leaves [0, 4]" in branch.reason
    root = mp.findroot(lambda t: _branch(t, 1, 4, lambda u: 2 * mp.cos(u)), 2.5)
    assert abs(float(branch.event_time.mid()) - float(root)) < 1e-8


@pytest.mark.parametrize("lo, hi", [(-1, 1), (-3, 1), (0, 2), (-2, -1), (1, 3), (-1, 0)])
@pytest.mark.parametrize("e", [2, 3, 4, 5])
def test_a_balls_power_holds_every_power_and_an_even_one_no_negative(lo, hi, e):
    """intervals.power: x^e for 41 exact points of [lo, hi] lies in the ball, an even
    power of a ball around 0 stays ≥ 0 and the far end is tight (python-flint's ``**``
    gives NaN for a ball around 0)."""
    from fractions import Fraction

    from singcheck.algebra.intervals import power

    ball = arb(fmpq(lo)).union(arb(fmpq(hi)))
    p = power(ball, e)
    assert p.is_finite()
    for k in range(41):
        x = Fraction(lo) + (Fraction(hi) - Fraction(lo)) * k / 40
        assert p.contains(arb(fmpq(x.numerator, x.denominator) ** e)), (x, p)
    powers = [Fraction(lo) ** e, Fraction(hi) ** e] + ([0] if lo < 0 < hi else [])
    least, most = min(powers) if e % 2 or lo >= 0 or hi <= 0 else 0, max(powers)
    slack = 1e-6 * float(max(abs(least), abs(most)))  # a ball's radius has 30 bits
    low, high = float(p.lower()), float(p.upper())  # (outward-rounded ends, exact floats)
    assert least - slack <= low <= least and most <= high <= most + slack


def test_a_path_whose_quick_proofs_pass_never_composes_its_legs(orthoglide_projection):
    """heart 1: the sweep proves every feasible branch from the pose's balls and the
    candidates are classified from them too; the legs along the path stay uncomposed
    (and compose, when asked, to the leg constraint along the path)."""
    from pathlib import Path

    from singcheck.algebra.trig import TRIG
    from singcheck.spec.files import load_trajectory

    root = Path(__file__).resolve().parent.parent
    spec = load_trajectory(root / "trajectories" / "heart1.yaml",
                           orthoglide_projection.model.spec)
    path = build_path(orthoglide_projection, spec)
    report = certify_path(path)
    assert report.verdict == "singular"
    assert all(leg._along is None for leg in path.legs)
    # leg 1: ρ² - 2xρ + (x² + y² + 1 - 4) with x = 8/7 sin³ t, along the path
    s = TRIG.gens()[1]
    a, b, c = path.legs[0].coefficients
    assert a == TRIG.from_dict({(0, 0, 0): 1})
    assert b == -2 * path.coordinates[0] and path.coordinates[0] == fmpq(8, 7) * s**3 \
        or b == -2 * path.coordinates[0]


def test_a_ball_program_holds_every_value_and_matches_the_term_by_term_enclosure():
    """algebra.ball_programs: a compiled group of polynomials (constants, ±1
    coefficients, powers shared between polynomials, the zero polynomial) gives, at
    balls of the variables, enclosures that hold the exact rational value at 27 points
    of the box and are no wider than intervals.evaluate's (the same operations, less a
    product by ±1); a JointSum holds
    Σ q_k·ρ^α at exact points too."""
    import itertools
    from fractions import Fraction

    from flint import fmpq_mpoly_ctx

    from singcheck.algebra.ball_programs import BallProgram, JointSum
    from singcheck.algebra.intervals import evaluate

    ctx = fmpq_mpoly_ctx.get(("x", "y", "z"), "lex")
    x, y, z = ctx.gens()
    polys = [x**2 - 2 * y + fmpq(1, 3), -x * y * z + fmpq(3, 7) * z**2, ctx.from_dict({}),
             -y, x**3 * y**2 - z**4 + 5]
    program = BallProgram(polys)
    box = [(Fraction(-1, 2), Fraction(3, 4)), (Fraction(2), Fraction(21, 10)),
           (Fraction(-3, 10), Fraction(1, 10))]
    balls = [arb(fmpq(a.numerator, a.denominator)).union(arb(fmpq(b.numerator, b.denominator)))
             for a, b in box]
    got = program(balls)
    for g, e in zip(got, [evaluate(p, balls) for p in polys], strict=True):  # no wider
        assert float(g.rad()) <= float(e.rad()) * (1 + 1e-6) and g.overlaps(e)
    for point in itertools.product(*[(a, (a + b) / 2, b) for a, b in box]):
        exact = [fmpq(v.numerator, v.denominator) for v in point]
        for p, ball in zip(polys, got, strict=True):
            assert ball.contains(arb(p(*exact))), (p, point)
    total = JointSum([((0, 1), (1, 2)), ((2, 1),), ()])
    q = [arb(2), arb(-3), arb(fmpq(1, 3))]
    joints = [arb(fmpq(1, 2)).union(arb(1)), arb(-1).union(arb(1)), arb(fmpq(1, 5))]
    enclosure = total(q, joints)
    for a, b, c in itertools.product((fmpq(1, 2), fmpq(3, 4), 1), (-1, 0, 1), (fmpq(1, 5),)):
        assert enclosure.contains(arb(2 * a * b**2 - 3 * c + fmpq(1, 3)))
