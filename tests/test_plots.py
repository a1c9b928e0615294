"""Figures: what is drawn and marked comes from the certified report; files are written."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from singcheck.report.plots import FIGURES, figure_data, write_figures
from tests.conftest import TRAJECTORIES
from tests.test_cli import ORTHO, singcheck

HERE = Path(__file__).parent


@pytest.fixture(scope="module")
def heart1(certify):
    return certify("heart1")


def test_marks_are_the_certified_candidates(heart1):
    d = figure_data(heart1)
    assert [c["status"] for c in d.candidates] == ["spurious", "spurious", "real", "real"]
    assert [c["t"] for c in d.candidates] == [float(c.t.mid()) for c in heart1.candidates]
    assert d.feasible == ["+++"]
    assert d.singular["+++"] == pytest.approx([0.9778, 1.5119], abs=1e-4)
    assert np.max(np.abs(d.mu)) == pytest.approx(1.0)
    # the samples agree with the marks: det A of the feasible mode changes sign there
    det = d.det_a["+++"]
    assert np.sum(det[:-1] * det[1:] < 0) == 2


def test_joint_space_shows_all_eight_modes_and_the_feasible_one_inside(heart1):
    d = figure_data(heart1)
    assert len(d.joints) == 8
    inside = np.all([(np.nanmin(v) >= 0) & (np.nanmax(v) <= 4) for v in d.joints["+++"]])
    assert inside
    assert d.limits == {"rho1": (0.0, 4.0), "rho2": (0.0, 4.0), "rho3": (0.0, 4.0)}


def test_every_figure_is_written_non_empty(heart1, tmp_path):
    files = write_figures(heart1, tmp_path)
    assert sorted(p.name for p in files) == sorted(
        f"heart1-{k}.{fmt}" for k in (*FIGURES, "postures") for fmt in ("png", "svg"))
    assert all(p.stat().st_size > 1000 for p in files)


def test_mu_figure_matches_the_reference_at_low_resolution(heart1, tmp_path):
    from matplotlib.testing.compare import compare_images

    write_figures(heart1, tmp_path, ("png",), dpi=30)
    result = compare_images(str(HERE / "golden" / "heart1-mu-30dpi.png"),
                            str(tmp_path / "heart1-mu.png"), tol=8)
    assert result is None, result


def test_plot_and_run_plot_commands(tmp_path):
    out = singcheck("plot", ORTHO, str(TRAJECTORIES / "heart2.yaml"), "--out", str(tmp_path),
                    "--backend", "flint")
    assert out.returncode == 0, out.stderr
    assert len(out.stdout.split()) == 10  # five figures (postures: the robot has a drawing)
    run = singcheck("run", ORTHO, str(TRAJECTORIES / "helix.yaml"), "--plot",
                    str(tmp_path / "run"), "--backend", "flint", "-q")
    assert run.returncode == 0
    assert (tmp_path / "run" / "helix-workspace.svg").stat().st_size > 1000


def test_html_page_is_self_contained_and_holds_every_figure(tmp_path):
    out = singcheck("plot", ORTHO, str(TRAJECTORIES / "heart1.yaml"),
                    str(TRAJECTORIES / "helix.yaml"), "--out", str(tmp_path), "--format",
                    "html", "--backend", "flint")
    assert out.returncode == 0, out.stderr
    page = (tmp_path / "singcheck.html").read_text()
    assert page.count('class="plotly-graph-div"') == 10  # four figures and the animation, each
    assert "<script src=" not in page.replace('<script src="data', "")  # JS inlined
    assert "s3 real" in page and "s1 spurious" in page
    assert (tmp_path / "singcheck.html").stat().st_mode & 0o044  # readable by others


def test_region_figure_names_need_no_quoting_in_a_shell(tmp_path):
    """A slice of an angle axis, tan(phi/2) = 1/2, names its figure files with letters,
    digits, '.', '_', '-' and '=' only (no parentheses or slashes)."""
    import re

    out = singcheck("plot", str(HERE.parent / "robots" / "3-rpr.yaml"), "--regions",
                    "workspace", "--slice", "tan(phi/2)=1/2", "--out", str(tmp_path),
                    "--backend", "flint", "-q")
    assert out.returncode == 0, out.stderr
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["3-rpr-workspace-tan-phi_2=1_2.png", "3-rpr-workspace-tan-phi_2=1_2.svg"]
    assert all(re.fullmatch(r"[A-Za-z0-9._=-]+", n) for n in names)
