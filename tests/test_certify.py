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
