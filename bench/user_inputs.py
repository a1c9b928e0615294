"""The inputs users wrote that the exact pipeline refused or stalled on (issue 27), timed.

Each is run as a user would: ``singcheck run ROBOT PATH --format json`` with default
options (regions on, ``--engine auto``), one process per input, wall time measured
around the whole command.  The target: every one answered (a verdict other than
``unknown``/``error``) within 20 s on 2 cores.  The verdicts are checked against
independent oracles in the tests (``tests/test_interval_paths.py``), not here.

Run alone: ``python bench/user_inputs.py``; ``make bench`` includes it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TARGET_S = 20.0

ORTHO, BIGLIDE, FIVE_BAR = "robots/orthoglide.yaml", "robots/biglide.yaml", "robots/five-bar.yaml"
DELTA = "robots/rotary-delta.yaml"
RRR, RUS = "tests/data/robots/3-rrr.yaml", "tests/data/robots/6-rus.yaml"


def _path(rng: str, **pose: str) -> str:
    return (f"name: p\nparameter: t\nrange: {rng}\npose:\n" +
            "".join(f"  {k}: {v}\n" for k, v in pose.items()))


#: (what, robot, trajectory text or a bundled file, the robot's text edited or None)
INPUTS = [
    ("3-RRR phi: pi/12 (constant)", RRR, _path("[0, 1]", x="t/10", y="0", phi="pi/12"), None),
    ("3-RRR phi: t/2", RRR, _path("[0, 1]", x="t/10", y="0", phi="t/2"), None),
    ("3-RRR phi: sin(t)/10", RRR, _path("[-pi, pi]", x="0", y="0", phi="sin(t)/10"), None),
    ("3-RRR phi: -t", RRR, _path("[0, 1]", x="1/10", y="0", phi="-t"), None),
    ("6-RUS x: t/4 from home", RUS,
     _path("[0, 1]", x="t/4", y="0", z="-2", psi="0", theta="0", phi="0"), None),
    ("rotary Delta, 3 harmonics", DELTA,
     _path("[-pi, pi]", x="cos(t)/2 + cos(2*t)/10 + cos(3*t)/20",
           y="sin(t)/2 + sin(2*t)/10 + sin(3*t)/20", z="-2"), None),
    ("Orthoglide cos(256*t)", ORTHO, _path("[0, 1]", x="1/2 + cos(256*t)/4", y="1/2", z="1"),
     None),
    ("Orthoglide 1/2 + sin(t)/2 + cos(64*t)/50", ORTHO,
     _path("[-pi, pi]", x="1/2 + sin(t)/2 + cos(64*t)/50", y="1/2", z="1"), None),
    ("biglide sin(100*t)", BIGLIDE, _path("[0, 1]", x="1/10", y="1/2 + sin(100*t)/2"), None),
    ("Orthoglide cos(t/2)", ORTHO, _path("[-pi, pi]", x="1 + cos(t/2)/2", y="1/2", z="1"), None),
    ("Orthoglide cos(t - 1)", ORTHO, _path("[-pi, pi]", x="1 + cos(t - 1)/2", y="1/2", z="1"),
     None),
    ("Orthoglide drifting circle", ORTHO,
     _path("[0, 2]", x="1 + cos(2*pi*t)/2 + t/10", y="1 + sin(2*pi*t)/2", z="1"), None),
    ("5-bar limits [1, 3.1], [0.05, 2] rad", FIVE_BAR, "trajectories/five-bar-cross.yaml",
     ("joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}",
      "joint_limits: {th1: [1, 3.1], th2: [0.05, 2]}")),
    ("5-bar through (0, sqrt 3), crossing", FIVE_BAR, _path("[-1, 1]", x="0", y="sqrt(3) + t"),
     None),
    ("5-bar through (0, sqrt 3), touching", FIVE_BAR,
     _path("[-1, 1]", x="t/2", y="sqrt(3) + t^2"), None),
    ("5-bar sqrt 7 and sqrt 3", FIVE_BAR, _path("[-1, 1]", x="sqrt(7)/4*t", y="sqrt(3) - t"),
     None),
    ("2000-row CSV (heart)", ORTHO, "bench/paths/heart-2000.csv", None),
    ("3-RPR crossing, default regions", "robots/3-rpr.yaml", "trajectories/3-rpr-cross.yaml",
     None),
]


def run_one(what: str, robot: str, trajectory: str, edit, work: Path) -> dict:
    robot_file = ROOT / robot
    if edit is not None:
        robot_file = work / f"{len(list(work.iterdir()))}-robot.yaml"
        robot_file.write_text((ROOT / robot).read_text().replace(*edit))
    if "\n" in trajectory:
        traj = work / f"{len(list(work.iterdir()))}-path.yaml"
        traj.write_text(trajectory)
    else:
        traj = ROOT / trajectory
    cmd = [sys.executable, "-m", "singcheck", "run", str(robot_file), str(traj),
           "--format", "json", "-q", "--time-limit", "120"]
    start = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)
    wall = time.perf_counter() - start
    try:
        result = json.loads(out.stdout)["trajectories"][0]
        verdict, engine = result["verdict"], (result.get("corroboration") or {}).get("status")
    except (ValueError, KeyError, IndexError):
        verdict, engine = f"exit {out.returncode}: {out.stderr.strip()[-120:]}", None
    answered = verdict in ("singular", "singularity-free", "infeasible", "near-singular")
    return {"input": what, "verdict": verdict, "corroboration": engine, "wall_s": wall,
            "target_s": TARGET_S, "met": answered and wall <= TARGET_S}


def rows() -> list[dict]:
    with tempfile.TemporaryDirectory(prefix="singcheck-inputs-") as tmp:
        return [run_one(*item, Path(tmp)) for item in INPUTS]


def print_rows(found: list[dict]) -> None:
    print(f"\nInputs the exact pipeline refused or stalled on (issue 27), default options, "
          f"target {TARGET_S:g} s each:")
    for r in found:
        mark = "ok " if r["met"] else "MISS"
        print(f"  {mark} {r['wall_s']:6.1f} s  {r['verdict']:<17} {r['input']}"
              f"  [{r['corroboration']}]")
    met = sum(r["met"] for r in found)
    print(f"  {met} of {len(found)} answered within {TARGET_S:g} s")


if __name__ == "__main__":
    print_rows(rows())
