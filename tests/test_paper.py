"""Acceptance: the paper's Orthoglide and its three trajectories (Jha et al. 2015).

The expected figures come from the paper (Table "Singular postures on Trajectory 1",
Eq. (sol)); singcheck's code never contains them.
"""

from __future__ import annotations

import math

import pytest

pytestmark = pytest.mark.slow

# Table 1 of the paper: S1..S4 with (x, y, z) and (ρ1, ρ2, ρ3) in the working mode of the
# prototype, to two decimals.
PAPER_TABLE = [
    (-1.13, 0.35, 1.00, 0.55, 1.66, 2.60),
    (-0.65, 0.80, 1.00, 0.88, 2.40, 2.71),
    (0.65, 0.80, 1.00, 2.18, 2.40, 2.71),
    (1.13, 0.35, 1.00, 2.83, 1.66, 2.60),
]


def test_heart1_has_four_candidates_two_real(certify):
    report = certify("heart1")
    ts = [float(c.t.mid()) for c in report.candidates]
    assert len(ts) == 4
    assert ts == pytest.approx([-1.512, -0.978, 0.978, 1.512], abs=2e-3)
    assert [c.status for c in report.candidates] == ["spurious", "spurious", "real", "real"]
    assert report.verdict == "singular"


def test_heart1_enclosures_are_certified_and_tight(certify):
    for c in certify("heart1").candidates:
        assert c.t.rad() <= 1e-9


def test_heart1_feasible_mode_is_the_prototypes(certify):
    report = certify("heart1")
    feasible = [m for m in report.modes if m.feasible]
    assert [m.label for m in feasible] == ["+++"]
    assert len(report.modes) == 8
    assert [float(c.t.mid()) for c in feasible[0].singular_times] == pytest.approx(
        [0.978, 1.512], abs=2e-3)


def _truncated(v: float) -> float:
    """The paper's table truncates to two decimals (1.1369 is printed 1.13)."""
    return math.copysign(math.floor(abs(v) * 100) / 100, v)


def test_heart1_table_matches_the_papers(certify):
    report = certify("heart1")
    for c, row in zip(report.candidates, PAPER_TABLE, strict=True):
        pose = [float(b.mid()) for b in c.pose]
        joints = list(c.joints["+++"].values())
        assert [_truncated(v) for v in pose + joints] == pytest.approx(list(row), abs=1e-9)


def test_heart1_times_match_the_papers_truncated_values(certify):
    # paper, Eq. (sol): t = [-1.51, -0.97, 0.97, 1.51]
    ts = [_truncated(float(c.t.mid())) for c in certify("heart1").candidates]
    assert ts == pytest.approx([-1.51, -0.97, 0.97, 1.51], abs=1e-9)


def test_heart1_real_singularities_are_proven_per_mode(certify):
    for c in certify("heart1").candidates:
        modes = {m.mode: m for m in c.modes}
        if c.status == "real":
            assert modes["+++"].status == "singular"
            assert modes["+++"].proof in ("elimination", "sign change")
        else:
            assert modes["+++"].status == "regular"
        assert all(m.status != "unknown" for m in c.modes)


@pytest.mark.parametrize("name", ["heart2", "helix"])
def test_heart2_and_helix_are_singularity_free(certify, name):
    report = certify(name)
    assert report.verdict == "singularity-free", report.reason
    assert [m.label for m in report.modes if m.feasible] == ["+++"]
    assert not report.undecided


def test_helix_uses_branch_and_bound(certify):
    assert certify("helix").root_method == "interval branch-and-bound"
    assert certify("heart1").root_method == "tangent half-angle"
