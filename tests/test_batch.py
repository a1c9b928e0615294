"""Batches as CI jobs and shell pipelines run them (issue 15): streams in and out, one
bad path never sinks a batch, signals, and the crash that once lost a whole batch."""

from __future__ import annotations

import json
from fractions import Fraction

import pytest

from tests.conftest import ROOT
from tests.test_cli import singcheck

DATA = ROOT / "tests" / "data" / "batch"
DELTA = str(DATA / "linear-delta-decimal.yaml")


# -- the region step's crash on a linear Delta's plane z = -2/5 ------------------------


def test_separators_of_fibre_points_closer_than_a_double_ulp():
    """Two fibre points 5e-17 apart (the linear Delta's plane z = -2/5): each separator
    lies strictly between consecutive points, checked exactly against the balls."""
    from flint import arb, fmpq

    from singcheck.algebra.intervals import working_precision
    from singcheck.spaces.plane_adjacency import separators

    with working_precision(200):
        a = arb("-0.866025408514986947466435412038 +/- 1.21e-31")
        b = arb("-0.866025408514986897853545875265 +/- 1.64e-31")
        points = [a, b, -b, -a]
    seps = separators(points)  # at the default precision, as the caller does
    assert len(seps) == len(points) + 1
    with working_precision(200):
        for s, p, nxt in zip(seps, points, seps[1:], strict=False):
            q = arb(fmpq(s.numerator, s.denominator))
            r = arb(fmpq(nxt.numerator, nxt.denominator))
            assert q < p < r, (s, p, nxt)


def test_simplest_between_refuses_an_empty_interval():
    from singcheck.spaces.cad import simplest_between

    assert simplest_between(Fraction(1, 3), Fraction(1, 2)) == Fraction(2, 5)
    with pytest.raises(ValueError):
        simplest_between(Fraction(1, 2), Fraction(1, 2))


@pytest.mark.slow
def test_linear_delta_path_at_constant_z_gets_its_region(tmp_path):
    """The path of the bug report's kind: the plane z = -2/5 is decomposed, the path
    named in one region with 8 IK solutions; 8 checked here at t = 0 by hand."""
    out = singcheck("run", DELTA, str(DATA / "delta-short.yaml"), "--backend", "flint",
                    "--format", "json", "-q", env={"SINGCHECK_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 0, out.stderr
    (t,) = json.loads(out.stdout)["trajectories"]
    assert t["workspace"]["one_region"] is True and t["workspace"]["region"]
    # independent count at the start pose (0, 0, -2/5): r = z ± sqrt(L² - d²) per rail
    import math

    rails = [(2, 0), (-1, 0.8660254 * 2), (-1, -0.8660254 * 2)]
    count = 1
    for ax, ay in rails:
        d2 = ax * ax + ay * ay
        roots = [-0.4 + sign * math.sqrt(9 - d2) for sign in (1, -1)]
        count *= sum(-3 < r < 3 for r in roots)
    assert t["workspace"]["ik_counts"] == [count] == [8]
