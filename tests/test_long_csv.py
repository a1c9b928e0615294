"""Long CSV paths (issue 27): many cubic pieces, one exact-corroboration budget.

The singular times are checked against an independent computation written here: the
natural cubic spline through the CSV's rows, its second derivatives solved from the
spline's tridiagonal system by mpmath's dense LU at 60 digits (no exact arithmetic, no
singcheck code), then det A along the Orthoglide's working mode +++ at 50 digits with
mpmath (tests/test_paths.py's ``_det_a_plus``), its sign changes refined by mpmath's
root finder.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time

import mpmath
import pytest

from singcheck.certify import pieces
from singcheck.certify.engines import EXACT_NOT_RUN, segment_list
from singcheck.certify.pieces import certify_trajectory
from singcheck.spec.files import load_trajectory
from tests.conftest import ROOT
from tests.test_paths import _det_a_plus

ROWS = 60  # 59 cubic pieces: enough to exercise the shared budget, quick to certify


def heart_csv(n: int) -> str:
    """Heart 1 sampled at n equally spaced t in [-π, π], 6 decimals (z = 1)."""
    lines = ["t,x,y,z"]
    for i in range(n):
        t = -math.pi + 2 * math.pi * i / (n - 1)
        x = 8 / 7 * math.sin(t) ** 3
        y = (13 / 14 * math.cos(t) - 5 / 14 * math.cos(2 * t) - 1 / 10 * math.cos(3 * t)
             - 1 / 14 * math.cos(4 * t))
        lines.append(f"{t:.6f},{x:.6f},{y:.6f},1")
    return "\n".join(lines) + "\n"


def _rows(text: str) -> list[list[mpmath.mpf]]:
    with mpmath.workdps(60):
        return [[mpmath.mpf(c) for c in line.split(",")] for line in text.split()[1:]]


def spline_oracle(ts, ys):
    """The natural cubic spline through (ts, ys) as a function of t (60-digit mpmath):
    hᵢ₋₁Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ)Mᵢ + hᵢMᵢ₊₁ = 6(Δᵢ − Δᵢ₋₁), M₀ = Mₙ = 0, solved densely."""
    n = len(ts) - 1
    with mpmath.workdps(60):
        h = [ts[i + 1] - ts[i] for i in range(n)]
        d = [(ys[i + 1] - ys[i]) / h[i] for i in range(n)]
        a = mpmath.zeros(n - 1, n - 1)
        b = mpmath.zeros(n - 1, 1)
        for r in range(n - 1):
            i = r + 1
            a[r, r] = 2 * (h[i - 1] + h[i])
            if r:
                a[r, r - 1] = h[i - 1]
            if r < n - 2:
                a[r, r + 1] = h[i]
            b[r] = 6 * (d[i] - d[i - 1])
        m = [mpmath.mpf(0)] + list(mpmath.lu_solve(a, b)) + [mpmath.mpf(0)]

    def s(t):
        i = max(0, min(n - 1, sum(1 for x in ts[1:-1] if x <= t)))
        u, v = t - ts[i], ts[i + 1] - t
        return (m[i] * v ** 3 / (6 * h[i]) + m[i + 1] * u ** 3 / (6 * h[i])
                + (ys[i] / h[i] - m[i] * h[i] / 6) * v
                + (ys[i + 1] / h[i] - m[i + 1] * h[i] / 6) * u)

    return s


def oracle_singular_times(text: str, per_piece: int = 8) -> list:
    """The sign changes of det A along +++ along the spline through the CSV's rows."""
    rows = _rows(text)
    ts = [r[0] for r in rows]
    x = spline_oracle(ts, [r[1] for r in rows])
    y = spline_oracle(ts, [r[2] for r in rows])

    def g(t):
        return _det_a_plus(x(t), y(t), mpmath.mpf(1))

    grid = [ts[i] + (ts[i + 1] - ts[i]) * k / per_piece
            for i in range(len(ts) - 1) for k in range(per_piece)] + [ts[-1]]
    values = [g(t) for t in grid]
    roots = []
    for a, b, va, vb in zip(grid, grid[1:], values, values[1:], strict=False):
        if va * vb < 0:
            roots.append(mpmath.findroot(g, (a, b), solver="anderson"))
    return roots


@pytest.fixture(scope="module")
def heart_path(orthoglide, tmp_path_factory):
    path = tmp_path_factory.mktemp("csv") / f"heart-{ROWS}.csv"
    text = heart_csv(ROWS)
    path.write_text(text)
    return load_trajectory(path, orthoglide.spec), oracle_singular_times(text)


def _assert_singular_at(report, expected):
    assert report.verdict == "singular", report.reason
    assert [m.label for m in report.modes if m.feasible] == ["+++"]
    real = [c for c in report.candidates if c.status == "real"]
    assert len(real) == len(expected), ([float(c.t.mid()) for c in real], expected)
    for c, root in zip(real, expected, strict=True):
        assert c.singular_modes == ["+++"]
        lo, hi = float(c.t.lower()), float(c.t.upper())
        assert hi - lo < 1e-6, (lo, hi)
        assert lo - 1e-12 <= float(root) <= hi + 1e-12, (lo, hi, root)


def test_the_oracle_finds_heart_1s_two_crossings(heart_path):
    _, expected = heart_path
    # the spline through 60 samples follows heart 1, singular on +++ at 0.977817, 1.51191
    assert [round(float(r), 2) for r in expected] == [0.98, 1.51]


def test_long_spline_singular_times_with_the_whole_budget(orthoglide_projection,
                                                          heart_path):
    spec, expected = heart_path
    report = certify_trajectory(orthoglide_projection, spec)
    _assert_singular_at(report, expected)
    assert len(report.pieces) == ROWS - 1


def test_no_budget_left_the_interval_verdict_stands_and_says_why(
        orthoglide_projection, heart_path, monkeypatch):
    spec, expected = heart_path
    monkeypatch.setattr(pieces, "PATH_CORROBORATION_BUDGET", 0.0)
    report = certify_trajectory(orthoglide_projection, spec)
    _assert_singular_at(report, expected)
    check = report.corroboration
    assert check.status == EXACT_NOT_RUN
    assert f"segments 1–{ROWS - 1}: the exact engine's budget for the whole path (0 s" in \
        check.detail
    assert f"corroborated 0 of the {ROWS - 1} pieces" in check.detail
    assert all(r.path.mu is None for r in report.pieces)


def test_a_near_time_limit_cuts_the_budget_not_the_verdict(orthoglide_projection,
                                                          heart_path, monkeypatch):
    """With the trajectory's time limit almost spent after the interval pass, the exact
    corroboration gets what is left (here nothing), not a time-limit verdict."""
    spec, expected = heart_path
    monkeypatch.setattr(pieces, "remaining", lambda: 0.5)
    report = certify_trajectory(orthoglide_projection, spec)
    _assert_singular_at(report, expected)
    assert "(0 s: what the trajectory's time limit left, of which 1 s" in \
        report.corroboration.detail


def test_crossing_pieces_are_corroborated_first(orthoglide_projection, heart_path,
                                                monkeypatch):
    spec, expected = heart_path
    monkeypatch.setattr(pieces, "FREE_PIECES_BUDGET", 0.0)  # only the crossings' pieces
    report = certify_trajectory(orthoglide_projection, spec)
    _assert_singular_at(report, expected)
    exact = [i for i, r in enumerate(report.pieces, 1) if r.path.mu is not None]
    crossing = sorted({c.segment for c in report.candidates if c.status == "real"})
    assert exact == crossing and len(crossing) == 2
    assert f"corroborated 2 of the {ROWS - 1} pieces" in report.corroboration.detail


def test_a_free_path_says_which_pieces_rest_on_the_intervals_alone(
        orthoglide, orthoglide_projection, tmp_path, monkeypatch):
    rows = ["t,x,y,z"] + [f"{i / 100:.6f},{0.6 + 0.3 * math.cos(i / 100):.6f},"
                          f"{0.6 + 0.3 * math.sin(i / 100):.6f},1" for i in range(40)]
    text = "\n".join(rows) + "\n"
    assert not oracle_singular_times(text)  # the oracle: no sign change of det A
    path = tmp_path / "arc.csv"
    path.write_text(text)
    monkeypatch.setattr(pieces, "FREE_PIECES_BUDGET", 0.0)
    report = certify_trajectory(orthoglide_projection, load_trajectory(path, orthoglide.spec))
    assert report.verdict == "singularity-free"
    assert report.reason.endswith("by the interval engine alone on 39 of the 39 segments "
                                  "(segments 1–39: the exact engine's budget for the whole "
                                  "path (5 s, of which 0 s for pieces without a proven "
                                  "crossing) ran out after it corroborated 0 of the 39 "
                                  "pieces the interval engine decided on its own)")


def test_segment_lists_read_as_ranges():
    assert segment_list([4]) == "segment 4"
    assert segment_list([1, 2, 3, 5, 7, 8]) == "segments 1–3, 5, 7–8"


@pytest.mark.slow
def test_a_2000_row_csv_is_certified_within_20_s():
    """Issue 27's target is 10 s on 2 cores with default options (20 s: slack for CI)."""
    start = time.monotonic()
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml",
                          "bench/paths/heart-2000.csv", "--format", "json"],
                         capture_output=True, text=True, cwd=ROOT, timeout=300)
    wall = time.monotonic() - start
    assert out.returncode == 1, out.stderr
    (doc,) = json.loads(out.stdout)["trajectories"]
    assert doc["verdict"] == "singular"
    real = [c["t"] for c in doc["candidates"] if c["status"] == "real"]
    assert [round(t, 3) for t in real] == [0.978, 1.512]
    assert wall < 20, f"{wall:.1f} s"
