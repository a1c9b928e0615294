"""The HTML page with the robot moving along the path, opened in headless Chromium:
no console error, one frame per sample, the frames stop on every real singular time.

Chromium is a dependency of the test suite (``make setup`` installs Debian's
``chromium``): without it the test is skipped, with the reason, only outside CI."""

from __future__ import annotations

import os

import pytest

from singcheck import api
from singcheck.report.animation import SAMPLES
from singcheck.report.plots import write_html
from tests import browser
from tests.conftest import ROBOTS, TRAJECTORIES

READY = ("document.querySelectorAll('.plotly-graph-div').length && "
         "[...document.querySelectorAll('.plotly-graph-div')].every(g => g._fullLayout)")
ANIMATED = ("[...document.querySelectorAll('.plotly-graph-div')]"
            ".filter(g => g._transitionData && g._transitionData._frames.length)")


def _need_chromium():
    if browser.chromium() is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is not installed (make setup installs Debian's chromium)")
        pytest.skip("chromium is not installed (make setup installs Debian's chromium)")


def _reports():
    out = []
    for robot_name, names in (("orthoglide", ["heart1", "heart2"]),
                              ("skew-biglide", ["skew-biglide-ellipse"])):
        robot = api.load_robot(ROBOTS / f"{robot_name}.yaml", backend="flint", cache=False)
        for name in names:
            traj = api.load_trajectory(TRAJECTORIES / f"{name}.yaml", robot)
            out.append(api.check(robot, traj, regions=False).certificate)
    return out


def test_the_page_animates_the_robot_in_chromium_without_errors(tmp_path):
    _need_chromium()
    reports = _reports()
    page_file = write_html(reports, tmp_path / "singcheck.html")
    with browser.open_page(page_file, READY) as page:
        animated = page.evaluate(f"{ANIMATED}.map(g => ({{"
                                 "frames: g._transitionData._frames.map(f => f.name),"
                                 "steps: g.layout.sliders[0].steps.map(s => s.label),"
                                 "stepFrames: g.layout.sliders[0].steps.map(s => s.args[0][0]),"
                                 "traces: g._transitionData._frames[0].traces.length}))")
        # go to the first singular frame of the first figure and read the legs back
        legs = page.evaluate(f"""(async () => {{
            const g = {ANIMATED}[0];
            const k = g.layout.sliders[0].steps.findIndex(s => s.label.includes('singular'));
            await Plotly.animate(g, [g.layout.sliders[0].steps[k].args[0][0]],
                {{mode: 'immediate', frame: {{duration: 0, redraw: true}},
                  transition: {{duration: 0}}}});
            const legs = g.data.find(d => d.name === 'legs');
            return {{x: legs.x, y: legs.y, z: legs.z, colour: legs.line.color}};
        }})()""")
        page.screenshot(tmp_path / "page.png")
        errors = page.errors
    assert errors == [], errors
    assert (tmp_path / "page.png").stat().st_size > 10_000
    assert len(animated) == len(reports)  # every bundled robot has a drawing
    for report, fig in zip(reports, animated, strict=True):
        real = sorted(float(c.t.mid()) for c in report.candidates if c.status == "real")
        assert len(fig["frames"]) == SAMPLES + len(real)  # one frame per sample
        assert fig["stepFrames"] == fig["frames"]  # one slider step per frame, in order
        marked = [float(s.split()[0]) for s in fig["steps"] if s.endswith("singular")]
        assert marked == pytest.approx(real, abs=1e-3)
        times = [float(s.split()[0]) for s in fig["steps"]]
        assert times == sorted(times)
    # heart 1's first singular posture: the three legs meet at the platform, coplanar
    import numpy as np

    pts = np.array([[legs[k][i] for k in "xyz"] for i in range(len(legs["x"]))
                    if legs["x"][i] is not None])
    directions = pts[1::2] - pts[0::2]
    assert directions.shape == (3, 3)
    assert abs(np.linalg.det(directions)) < 1e-6
    assert legs["colour"] == "#d62728"  # drawn red on a singular frame
