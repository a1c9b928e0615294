"""Field campaign: new inputs a user would write, against an independent 50-digit oracle.

Each input is a robot (a bundled spec, or a small variant of one: other lengths,
decimal or real parameters, decimal joint limits) and a path (expressions in t with
shifts and rational multiples, sqrt and pi, segments, waypoints, splines, CSV tables),
run as a user runs it: ``singcheck run ROBOT PATH --format json`` with default options,
one process per input.  The oracle (``tests/field_oracle.py``, which never imports
singcheck) reads the same text with SymPy, solves the inverse kinematics per leg in
closed form and follows det A at 50 digits along every working mode.  The table says,
per input, the oracle's verdict and singular times, singcheck's, whether they agree,
and singcheck's wall time.

Agreement: the same verdict and the same singular times within 1e-6, and the same
feasible modes (matched by their joints at the start).  ``unknown`` with a reason is
accepted where the oracle finds a tangential touch (a minimum of |det A| of ~1e-40 with
no sign change: balls cannot prove it) or where the oracle itself is unsure (a margin or
|det A| below 1e-8 that is not a proven zero).  A wrong ``singularity-free`` or a wrong
singular time is a defect.

Run: ``python bench/field_campaign.py [NAME ...]`` (all inputs without names);
``--oracle-only`` skips singcheck and prints the oracle's findings.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mpmath as mp
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from tests import field_oracle as fo  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
TOL = 1e-6


def path(rng: str, **pose: str) -> str:
    return (f"name: p\nparameter: t\nrange: {rng}\npose:\n"
            + "".join(f"  {k}: {v}\n" for k, v in pose.items()))


def segments(*pieces) -> str:
    out = "name: p\nparameter: t\nsegments:\n"
    for rng, pose in pieces:
        coords = ", ".join(f"{k}: {v}" for k, v in pose.items())
        out += f"  - range: {rng}\n    pose: {{{coords}}}\n"
    return out


def waypoints(interpolation: str, *rows: dict) -> str:
    out = f"name: p\nparameter: t\ninterpolation: {interpolation}\nwaypoints:\n"
    for r in rows:
        out += f"  - {{{', '.join(f'{k}: {v}' for k, v in r.items())}}}\n"
    return out


def csv(*rows) -> str:
    return "\n".join(",".join(str(v) for v in r) for r in rows) + "\n"


def variant(base: str, *edits: tuple[str, str]) -> tuple[str, tuple]:
    return (base, edits)


ORTHO, BIGLIDE, SKEW = "robots/orthoglide.yaml", "robots/biglide.yaml", "robots/skew-biglide.yaml"
FIVE, RPR, PRR = "robots/five-bar.yaml", "robots/3-rpr.yaml", "robots/3-prr.yaml"
LDELTA, RDELTA = "robots/linear-delta.yaml", "robots/rotary-delta.yaml"
GS = "robots/gough-stewart.yaml"
RRR = "tests/data/robots/3-rrr.yaml"
LIMITS_5BAR = "joint_limits: {th1: [pi/3, pi], th2: [0, 2*pi/3]}\n"
#: the biglide with legs of 2 mm and 1.5 mm, in metres
MICRO_BIGLIDE = variant(BIGLIDE, ("- 4\n", "- 0.002^2\n"), ("- 9/4", "- 0.0015^2"),
                        ("[-4, 4], q: [-4, 4]", "[-0.004, 0.004], q: [-0.004, 0.004]"))

#: (name, robot file or variant, trajectory text (YAML, or CSV when the name ends in .csv),
#:  what it is meant to show)
INPUTS: list[tuple] = [
    # --- biglide: det A = 4 y (q - p), singular exactly where y = 0 ----------------------
    ("biglide-shifted-sine", BIGLIDE, path("[0, 2]", x="t/4", y="sin(3*t - 1)/2"),
     "crosses y = 0 at t = 1/3 and (1 + pi)/3: shifted argument, interval engine"),
    ("biglide-tangent-cos", BIGLIDE, path("[0, 2]", x="t/2 - 1/2", y="1 - cos(t - 1)"),
     "touches y = 0 at t = 1 without crossing (a tangency of a shifted cosine)"),
    ("biglide-starts-singular", BIGLIDE, path("[0, pi/2]", x="cos(t)/2", y="sin(t)"),
     "the range starts exactly at a singular pose"),
    ("biglide-ends-at-pi", BIGLIDE, path("[pi/2, pi]", x="1/2", y="sin(t)/2"),
     "the range ends exactly at the singular time pi"),
    ("biglide-on-the-rail", BIGLIDE, path("[0, 1]", x="t - 1/2", y="0"),
     "singular along the whole range (det A = 0 identically)"),
    ("biglide-very-short", BIGLIDE, path("[0, 1/100000]", x="1/2", y="t - 3/1000000"),
     "a range of 1e-5 crossing at 3e-6"),
    ("biglide-waypoints-linear", BIGLIDE,
     waypoints("linear", {"t": 0, "x": 0.5, "y": 0.5}, {"t": 1, "x": 1, "y": -0.25},
               {"t": 2, "x": 1.5, "y": 0.5}),
     "piecewise linear through decimal waypoints: crossings at 2/3 and 4/3"),
    ("biglide-spline-csv.csv", BIGLIDE, csv(("t", "x", "y"), (0, 0, 1), (1, 0.5, -0.5),
                                            (2, 1, 1), (3, 1.5, 0.75)),
     "a CSV table, natural cubic spline through four rows"),
    ("biglide-decimal-legs", variant(BIGLIDE, ("- 4\n", "- 1.75^2\n"), ("- 9/4", "- 1.25^2"),
                                     ("[-4, 4], q: [-4, 4]", "[-3.5, 3.5], q: [-3.5, 3.5]")),
     path("[0, 4]", x="1/4", y="cos(t/2)"),
     "legs 1.75 and 1.25, decimal limits; cos(t/2) crosses at t = pi"),
    ("biglide-real-leg", variant(BIGLIDE, ("constraints:",
                                           "parameters: {a: 2*cos(1/10)}\nconstraints:"),
                                 ("- 4\n", "- a^2\n")),
     path("[0, 1]", x="0.3", y="1/2 - t"),
     "a real leg length 2*cos(1/10): interval engine alone, a crossing at t = 1/2"),
    # --- skew biglide ------------------------------------------------------------------
    ("skew-decimal-ellipse", variant(SKEW, ("{l1: 2, l2: 3/2}", "{l1: 1.8, l2: 1.25}"),
                                     ("[-1, 4], rho2: [-1, 4]", "[-1.5, 4.5], rho2: [-1.5, 4.5]")),
     path("[-pi, pi]", x="-1 + cos(t)", y="-1 + sin(t)/2"),
     "the bundled ellipse on a robot with decimal legs and limits"),
    ("skew-segments", SKEW,
     segments(("[0, 1]", {"x": "-1/2 + t/2", "y": "-1/2"}),
              ("[1, 1 + pi]", {"x": "cos(t - 1)/2 - 1/2", "y": "-1/2 - sin(t - 1)/2"})),
     "a line then a half circle in a shifted argument"),
    ("skew-csv-linear.csv", SKEW, csv(("t", "x", "y"), (0, -1, -1), (0.5, -0.5, -1.2),
                                      (1, 0, -1.0), (1.5, 0.5, -0.6), (2, 1, -0.2)),
     "a CSV log with decimal times, read with the default cubic spline"),
    # --- five-bar ----------------------------------------------------------------------
    ("five-bar-variant-line", variant(FIVE, ("{d: 1, l1: 2, l2: 2}", "{d: 0.5, l1: 1.5, l2: 2.5}"),
                                      ("{th1: [pi/3, pi], th2: [0, 2*pi/3]}",
                                       "{th1: [0.5, 3], th2: [0.1, 2.6]}")),
     path("[0, 1]", x="0.1", y="3.95 - t/2"),
     "other lengths, decimal angle limits; a vertical line"),
    ("five-bar-horizontal-tangent", FIVE, path("[-1, 1]", x="sin(t)/2", y="sqrt(3)"),
     "the line y = sqrt(3) touches the singular curve at (0, sqrt 3) (t = 0)"),
    ("five-bar-degree-limits", variant(FIVE, ("{th1: [pi/3, pi], th2: [0, 2*pi/3]}",
                                              "{th1: [55 deg, 175 deg], th2: [5 deg, 125 deg]}")),
     path("[-pi, pi]", x="cos(t)/2", y="5/2 + sin(2*t)/4"),
     "limits in degrees not multiples of 15; a figure-eight"),
    ("five-bar-leaves-limits", FIVE, path("[0, 2]", x="t", y="5/2"),
     "moves right until th2 leaves [0, 2pi/3]"),
    ("five-bar-starts-singular", FIVE, path("[0, 1]", x="0", y="sqrt(3) + sin(t)"),
     "starts at the singular pose (0, sqrt 3), moves up"),
    # --- Orthoglide --------------------------------------------------------------------
    ("ortho-variant-third", variant(ORTHO, ("{l: 2}", "{l: 1.9}"),
                                    ("{rho1: [0, 4], rho2: [0, 4], rho3: [0, 4]}",
                                     "{rho1: [0.5, 3.5], rho2: [0.5, 3.5], rho3: [0.5, 3.5]}")),
     path("[0, 3*pi]", x="1 + cos(t/3)/2", y="1/2 + sin(t/3)/2", z="1"),
     "l = 1.9, limits [0.5, 3.5]; a half circle in t/3"),
    ("ortho-segments", ORTHO,
     segments(("[0, 1]", {"x": "t", "y": "1/2", "z": "1"}),
              ("[1, 3]", {"x": "1 + (t - 1)/4", "y": "1/2 + (t - 1)/3", "z": "1"})),
     "two straight segments, the second towards the singularity"),
    ("ortho-csv.csv", ORTHO, csv(("t", "x", "y", "z"), (0, 0.25, 0.6, 1), (1, 0.9, 1.1, 1),
                                 (2, 1.2, 0.3, 1), (3, 0.4, 0.2, 1.1)),
     "a four-row CSV table, cubic spline"),
    ("ortho-constant", ORTHO, path("[0, 1]", x="1/2", y="1/2", z="1"),
     "standing still at a regular pose"),
    ("ortho-leaves-limits", ORTHO, path("[0, 3/2]", x="2*t", y="1/2", z="1"),
     "pushes rho1 past 4 in the only mode that starts inside"),
    ("ortho-pi-and-sqrt", ORTHO, path("[0, pi]", x="1/2 + t/pi", y="sqrt(1 + t^2)/3", z="1"),
     "pi and sqrt in the path's coefficients"),
    # --- 3-RPR, 3-PRR -------------------------------------------------------------------
    ("3-rpr-third-turn", RPR, path("[0, 2]", x="2 + cos(t)/2", y="2 + sin(t)/2", phi="t/3"),
     "turns by t/3 on a circle"),
    ("3-rpr-constant-tilt", RPR, path("[0, 1]", x="2", y="2", phi="pi/6"),
     "a constant pose turned by pi/6"),
    ("3-rpr-decimal-base", variant(RPR, ("(x + cos(phi) - 5)", "(x + cos(phi) - 4.5)"),
                                   ("(x - sin(phi) - 1)", "(x - sin(phi) - 1.5)")),
     path("[0, 1]", x="3/2 + t", y="1", phi="0.2"),
     "base points moved to decimals; a straight line at phi = 0.2"),
    ("3-prr-half-turn", PRR, path("[0, 1]", x="3/2 + sin(t)/2", y="2 - cos(t)/2", phi="-t/2"),
     "the bundled arc, turning the other way by t/2"),
    # --- Deltas, Gough-Stewart ---------------------------------------------------------
    ("linear-delta-helix", variant(LDELTA, ("{R: 1, l: 3/2, s3: sqrt(3)}",
                                            "{R: 0.9, l: 1.6, s3: sqrt(3)}")),
     path("[0, 2*pi]", x="cos(t)/4", y="sin(t)/4", z="t/10"),
     "R = 0.9, l = 1.6; a rising helix"),
    ("linear-delta-shifted", LDELTA, path("[0, 1]", x="-1/4 + sin(t/2)", y="-1/4", z="t/4"),
     "the bundled crossing written with a shifted sine"),
    ("rotary-delta-half-sine",
     variant(RDELTA, ("{th1: [-pi/2, 3*pi/4], th2: [-pi/2, 3*pi/4], th3: [-pi/2, 3*pi/4]}",
                      "{th1: [-1.2, 2.2], th2: [-1.2, 2.2], th3: [-1.2, 2.2]}")),
     path("[0, 2]", x="1.6 + sin(t/2)/2", y="0", z="-1"),
     "decimal limits; moves out along x towards the coplanar forearms"),
    ("gough-stewart-tilt", GS, path("[0, 2]", x="0", y="0", z="2", psi="t", theta="sin(t)/10",
                                     phi="cos(2*t)/10 - 1/10"),
     "turns while tilting"),
    ("gough-stewart-constant", GS, path("[0, 1]", x="1/10", y="-1/10", z="2", psi="1/5",
                                         theta="0", phi="0"),
     "standing still, turned by 1/5 rad"),
    ("3-rrr-from-home", RRR, path("[0, 1]", x="sin(t)/5", y="cos(2*t)/10 - 1/10", phi="0"),
     "leaves the home pose (singular in some modes) without turning"),
    # --- second round: narrow clearances, limits touched, zeros at joins and ends -------
    ("biglide-narrow-clearance", BIGLIDE, path("[0, 1]", x="t", y="(t - 1/2)^2 + 1/1000000"),
     "comes within 1e-6 of y = 0 without touching: free"),
    ("biglide-narrow-cos", BIGLIDE, path("[0, 2]", x="t/2", y="1 - cos(t - 1) + 1/10000"),
     "within 1e-4 of y = 0, a shifted cosine: free, interval engine alone"),
    ("biglide-touch-pi-6", BIGLIDE, path("[0, 1]", x="1/2", y="(2*sin(t) - 1)^2/4"),
     "touches y = 0 at t = pi/6 (a double root of a polynomial in sin t)"),
    ("biglide-limit-at-end", variant(BIGLIDE, ("{p: [-4, 4]", "{p: [0, 4]")),
     path("[0, 1]", x="12/5*t", y="6/5"),
     "p = x + 8/5 reaches its limit 4 exactly at the end of the range"),
    ("biglide-limit-touched-inside", variant(BIGLIDE, ("{p: [-4, 4]", "{p: [0, 4]")),
     path("[0, pi]", x="12/5*sin(t)", y="6/5"),
     "p reaches its limit 4 at t = pi/2 and comes back"),
    ("biglide-zero-at-knot", BIGLIDE,
     waypoints("linear", {"t": 0, "x": 0, "y": 0.5}, {"t": 1, "x": 0.5, "y": 0},
               {"t": 2, "x": 1, "y": 0.5}),
     "a V through y = 0 at the knot t = 1 (touch at a join)"),
    ("biglide-cross-at-knot", BIGLIDE,
     waypoints("cubic", {"t": 0, "x": 0, "y": 0.5}, {"t": 1, "x": 0.5, "y": 0},
               {"t": 2, "x": 1, "y": -0.5}),
     "a cubic spline crossing y = 0 exactly at its middle knot"),
    ("biglide-short-at-pi-2", BIGLIDE, path("[pi/2, pi/2 + 1/1000000]", x="1/2", y="cos(t)"),
     "a range of 1e-6 starting exactly at the singular time pi/2"),
    ("biglide-ends-shifted", BIGLIDE, path("[0, 1]", x="1/2", y="sin(t - 1)"),
     "ends exactly on y = 0 at t = 1, a shifted sine (interval engine)"),
    ("3-rpr-constant-singular", RPR, path("[0, 1]", x="1", y="0", phi="0"),
     "standing still where the three leg lines meet at (1, 0): singular all along"),
    ("3-rpr-through-singular", RPR, path("[-1, 1]", x="1 + t/5", y="t/7", phi="t/3"),
     "passes the concurrent-legs pose (1, 0, 0) at t = 0 turning by t/3"),
    ("rotary-delta-real-offset", variant(RDELTA, ("{e: 1/2,", "{e: cos(1/2)/2,")),
     path("[0, 1]", x="7/4 + 3*t/10", y="0", z="-1"),
     "a real base offset cos(1/2)/2: interval engine with revolute legs"),
    ("linear-delta-csv.csv", LDELTA, csv(("t", "x", "y", "z"), (0, -0.25, -0.25, 0),
                                         (0.5, 0, -0.25, 0.125), (1, 0.25, -0.25, 0.25),
                                         (1.5, 0.3, -0.1, 0.3)),
     "a CSV table in 3-D through the linear Delta's crossing"),
    ("five-bar-real-line", variant(FIVE, ("{d: 1, l1: 2, l2: 2}",
                                          "{d: 1, l1: 2*cos(1/100), l2: 2}")),
     path("[-1, 1]", x="t/3", y="5/2"),
     "a real proximal length: free line, interval engine with revolute legs"),
    # --- third round: pi-rescaled times, ends at +-pi, units, long and late ranges ------
    ("biglide-2pi-rescaled", BIGLIDE, path("[0, 1]", x="t", y="sin(2*pi*t)/2"),
     "sin(2*pi*t) beside a bare t: singular at both range ends and at 1/2"),
    ("biglide-2pi-sqrt2", BIGLIDE, path("[0, 1]", x="sqrt(2)*t", y="sin(2*pi*t)/2"),
     "the same, ending at the irrational pose (sqrt 2, 0)"),
    ("biglide-ends-at-plus-minus-pi", BIGLIDE, path("[-pi, pi]", x="cos(t)/2", y="sin(t)/2"),
     "a circle about a rail point: singular at -pi, 0 and pi"),
    ("biglide-rail-then-leave", BIGLIDE,
     segments(("[0, 1]", {"x": "t/2", "y": "0"}), ("[1, 2]", {"x": "t/2", "y": "t - 1"})),
     "along the rail (singular all along), then away from it"),
    ("ortho-millimetres", variant(ORTHO, ("{l: 2}", "{l: 2000}"),
                                  ("{rho1: [0, 4], rho2: [0, 4], rho3: [0, 4]}",
                                   "{rho1: [0, 4000], rho2: [0, 4000], rho3: [0, 4000]}")),
     path("[-pi, pi]", x="1000 + 500*cos(t)", y="500 + 500*sin(t)", z="1000"),
     "the Orthoglide in millimetres (l = 2000) on a circle of radius 500"),
    ("biglide-micro", MICRO_BIGLIDE,
     path("[0, 1]", x="1/2000", y="(t - 1/3)/1000"),
     "legs of 2 mm and 1.5 mm in metres: a crossing at t = 1/3"),
    ("biglide-micro-narrow", MICRO_BIGLIDE,
     path("[0, 1]", x="1/2000", y="((t - 1/2)^2 + 1/1000000)/1000"),
     "the same robot within 1e-9 of its singularity: free"),
    ("biglide-long-range", BIGLIDE, path("[0, 1000]", x="1/2", y="cos(t/500)"),
     "a slow path over t in [0, 1000]: singular at 250*pi"),
    ("biglide-late-range", BIGLIDE, path("[1000, 1001]", x="1/2", y="t - 1000.5"),
     "a range far from 0: singular at 1000.5"),
    ("biglide-decimal-range", BIGLIDE, path("[0.25, 1.75]", x="t/3", y="t - 0.75"),
     "decimal range ends: singular at 0.75"),
    ("gough-stewart-waypoints", GS,
     waypoints("linear", {"t": 0, "x": 0, "y": 0, "z": 2, "psi": 1.3, "theta": 0, "phi": 0},
               {"t": 1, "x": 0.1, "y": 0, "z": 2, "psi": 1.8, "theta": 0.05, "phi": 0},
               {"t": 2, "x": 0.1, "y": 0.1, "z": 2.1, "psi": 1.8, "theta": 0.05, "phi": 0.05}),
     "six coordinates through decimal waypoints, turning past psi ~ 1.55"),
    # --- fourth round: close double crossings, one-mode selections, mode switches -------
    ("biglide-double-close", BIGLIDE, path("[0, 1]", x="t", y="(t - 1/2)^2 - 1/100000000"),
     "two crossings 2e-4 apart (polynomial: exact engine)"),
    ("biglide-double-close-cos", BIGLIDE, path("[0, 2]", x="t/2", y="1 - cos(t - 1) - 1/100000000"),
     "two crossings about 2.8e-4 apart in a shifted cosine (interval engine)"),
    ("biglide-mode-switch", variant(BIGLIDE, ("{p: [-4, 4]", "{p: [-1, 1]")),
     path("[0, 1]", x="2*t - 1", y="6/5"),
     "p+ leaves [-1, 1] at x = -0.6 before p- enters it at 0.6: no mode lasts"),
    ("3-rrr-one-mode", variant(RRR, ("constraints:",
                                     "joint_limits: {th1: [-2.5, -0.5], th2: [0.2, 1.2], "
                                     "th3: [0.5, 1.5]}\nconstraints:")),
     path("[0, 1]", x="sin(t)/5", y="cos(2*t)/10 - 1/10", phi="0.05"),
     "decimal limits keep the mode ++- of the home pose; a decimal constant angle"),
    ("rotary-delta-degrees", variant(RDELTA, ("{th1: [-pi/2, 3*pi/4], th2: [-pi/2, 3*pi/4], "
                                              "th3: [-pi/2, 3*pi/4]}",
                                              "{th1: [-80 deg, 130 deg], th2: [-80 deg, 130 deg],"
                                              " th3: [-80 deg, 130 deg]}")),
     "trajectories/rotary-delta-cross.yaml",
     "limits in degrees, not multiples of 15, on the bundled crossing"),
    ("3-prr-decimal-limits", variant(PRR, ("{r1: [2, 6], r2: [2, 6], r3: [-2, 1]}",
                                           "{r1: [2.5, 5.5], r2: [2.5, 5.5], r3: [-1.5, 0.5]}")),
     path("[0, 1]", x="3/2 + sin(t)/2", y="2 - cos(t)/2", phi="0.1*t + 0.3"),
     "decimal limits; the bundled arc turning by 0.1*t + 0.3 (irrational cosines)"),
    # --- fifth round: serial touches, pi-rescaled circles, Euler-angle lock ------------
    ("biglide-serial-touch", BIGLIDE, path("[0, pi]", x="0", y="3/2*sin(t)"),
     "y reaches 3/2 at t = pi/2: leg q's two branches meet (serial singularity)"),
    ("biglide-serial-touch-shifted", BIGLIDE, path("[0, 2]", x="0", y="3/2*cos(t - 1)"),
     "the same serial touch at t = 1 in a shifted cosine (interval engine)"),
    ("biglide-2pi-circle", BIGLIDE, path("[0, 1]", x="cos(2*pi*t)/2", y="sin(2*pi*t)/2"),
     "a circle in 2*pi*t (rescaled exactly): singular at 0, 1/2 and 1"),
    ("biglide-third-pi", BIGLIDE, path("[0, 4]", x="1/2", y="sin(pi*t/3)/2"),
     "sin(pi*t/3): singular at 0 and 3"),
    ("gough-stewart-pitch-lock", GS, path("[1.4, 1.7]", x="0", y="0", z="2", psi="0",
                                          theta="t", phi="0"),
     "pitch theta through pi/2, where Z-Y-X Euler angles lock (cos theta in det A)"),
    # --- sixth round: square roots in robots and tangent lines ------------------------
    ("ortho-sqrt-leg", variant(ORTHO, ("{l: 2}", "{l: sqrt(5)}")), "trajectories/heart1.yaml",
     "leg length sqrt(5) on heart 1: the exact engine through norms over Q(sqrt 5)"),
    ("skew-real-rail", variant(SKEW, ("constraints:", "parameters: {l1: 2, l2: 3/2, "
                                      "c: cos(1), s: sin(1)}\nconstraints:"),
                               ("parameters: {l1: 2, l2: 3/2}\n", ""),
                               ("(x - 3/5*rho2)^2 + (y - 4/5*rho2)^2",
                                "rho2^2 - 2*rho2*(c*x + s*y) + x^2 + y^2")),
     path("[-pi, pi]", x="-1 + cos(t)", y="-1 + sin(t)/2"),
     "the rail at angle 1 rad (cos 1, sin 1: real parameters), its leg expanded so that "
     "rho2^2 has coefficient 1 (written as (x - c*rho2)^2 + (y - s*rho2)^2 it is refused, "
     "exit 2: c^2 + s^2 is not seen to be 1): interval engine"),
    ("five-bar-circle-top", variant(FIVE, (LIMITS_5BAR, "")),
     path("[-1, 1]", x="t/4", y="sqrt(3) + 2"),
     "no limits; the line touches the circle of radius 2 about (0, sqrt 3) at its top"),
    ("five-bar-circle-tangent", variant(FIVE, (LIMITS_5BAR, "")),
     path("[-1/4, 1/4]", x="sqrt(3) - t/2", y="sqrt(3) + 1 + sqrt(3)*t/2"),
     "no limits; tangent to that circle at 30 degrees, sqrt 3 in the path"),
    # --- seventh round (eighth session): odd multiplicities, decimal frequencies, turns --
    ("biglide-triple-sine", BIGLIDE, path("[-1, 1]", x="1/2", y="sin(t)^3"),
     "crosses y = 0 at t = 0 with multiplicity 3 (sin t cubed)"),
    ("biglide-triple-poly", BIGLIDE, path("[0, 2]", x="t/2", y="(t - 1)^3/2"),
     "a crossing of multiplicity 3 at t = 1 (polynomial)"),
    ("biglide-triple-shifted", BIGLIDE, path("[0, 2]", x="t/2", y="sin(t - 1)^3"),
     "the same in a shifted sine: a sign change whose derivative vanishes there"),
    ("biglide-sqrt-amplitude", BIGLIDE, path("[0, 2*pi]", x="1/3", y="sqrt(2)/2*sin(t) + 1/2"),
     "crosses where sin t = -1/sqrt 2: t = 5pi/4 and 7pi/4"),
    ("biglide-fast-ripple", BIGLIDE, path("[0, 1]", x="1/2", y="1/2 + sin(40*t)/1000"),
     "a fast small ripple far from the singularity: free"),
    ("five-bar-decimal-frequency", FIVE,
     path("[0, 2]", x="0.3*cos(1.7*t)", y="5/2 + 0.2*sin(1.7*t)"),
     "an arc at the decimal frequency 1.7"),
    ("ortho-cubic-z", ORTHO, path("[0, 2]", x="1/2 + t/4", y="1/2", z="1 + t^3/10 - t/2"),
     "z a cubic in t"),
    ("ortho-diagonal", ORTHO, path("[0, 1]", x="1/4 + t", y="1/4 + t", z="1/4 + t"),
     "along the diagonal x = y = z"),
    ("3-rpr-decimal-wobble", RPR,
     path("[0, 3]", x="2 + 0.4*cos(t)", y="2 + 0.4*sin(t)", phi="0.5*sin(2*t) + 0.1"),
     "a circle while phi wobbles by 0.5*sin(2t) + 0.1"),
    ("3-prr-full-turn", PRR, path("[0, 2*pi]", x="3/2", y="2", phi="t"),
     "turns a full turn on the spot"),
    ("linear-delta-five-waves", LDELTA,
     path("[0, 10*pi]", x="cos(t)/5", y="sin(t)/5", z="0.1*sin(5*t)"),
     "five turns of a wavy circle"),
    ("rotary-delta-tilted-circle", RDELTA,
     path("[-pi, pi]", x="cos(t)/2", y="sin(t)/2", z="-2 + sin(t)/5"),
     "the bundled free circle, tilted"),
    ("3-rrr-slow-turn", RRR, path("[0, 1]", x="1/10", y="1/10", phi="t/7"),
     "turns slowly by t/7 away from the home pose"),
    ("skew-waypoints-cubic", SKEW,
     waypoints("cubic", {"t": 0, "x": -1.5, "y": -1}, {"t": 0.5, "x": -1.2, "y": -0.7},
               {"t": 1, "x": -0.8, "y": -0.6}, {"t": 1.5, "x": -0.3, "y": -0.8},
               {"t": 2, "x": 0, "y": -1.1}, {"t": 2.5, "x": -0.2, "y": -1.4}),
     "six decimal waypoints, cubic spline"),
    # --- ninth round: issue 27's kinds of input on other robots and paths ----------------
    ("3-rrr-wobble-circle", RRR, path("[0, 2*pi]", x="cos(t)/10", y="sin(t)/10",
                                      phi="sin(2*t)/5"),
     "a small circle while the platform wobbles by sin(2t)/5 (an orientation path)"),
    ("3-rrr-decimal-turn", RRR, path("[0, 2]", x="0.2*cos(t) - 0.2", y="0.05*t",
                                     phi="0.3*t"),
     "decimal coefficients, turning by 0.3 t from the home pose"),
    ("rotary-delta-two-harmonics", RDELTA,
     path("[-pi, pi]", x="cos(t)/3 + cos(2*t)/10", y="sin(t)/3 - sin(2*t)/10",
          z="-2 + cos(3*t)/10"),
     "a trefoil-like loop with three harmonics in z"),
    ("ortho-heart-ripple", ORTHO,
     path("[-pi, pi]", x="8/7*sin(t)^3", y="13/14*cos(t) - 5/14*cos(2*t) - 1/10*cos(3*t)"
          " - 1/14*cos(4*t)", z="1 + cos(128*t)/100"),
     "heart 1 with a fast z ripple (degree far past the exact engine's bound)"),
    ("ortho-decimal-frequency", ORTHO,
     path("[0, 6]", x="0.5 + 0.4*sin(1.3*t + 0.2)", y="0.6", z="1"),
     "a decimal frequency and phase in x"),
    ("biglide-2pi-touches", BIGLIDE, path("[0, 5/2]", x="t/3", y="(1 - cos(2*pi*t))/4"),
     "touches y = 0 at t = 0, 1, 2 (period 1): exact engine in tau = 2 pi t"),
    ("five-bar-sqrt2-line", FIVE, path("[0, 1]", x="sqrt(2)/4*t", y="5/2 - t/2"),
     "a slope with sqrt(2) in the path, moving down towards the singular curve"),
    ("3-rpr-wobble-decimal", variant(RPR, ("{r1: [1/2, 5], r2: [1/2, 5], r3: [1/2, 5]}",
                                           "{r1: [0.6, 4.8], r2: [0.6, 4.8], r3: [0.6, 4.8]}")),
     path("[0, 3]", x="2 + t/3", y="1.5", phi="0.1*sin(3*t)"),
     "decimal limits, an orientation wobble along a straight line"),
    ("3-prr-half-angle", PRR, path("[0, 2]", x="3/2 + sin(t)/2", y="2 - cos(t)/2",
                                   phi="t/2 - 1/5"),
     "the bundled arc turning by t/2 - 1/5"),
    ("gough-stewart-yaw-wave", GS, path("[0, 3]", x="0", y="0", z="2 + sin(2*t)/10",
                                        psi="t/5", theta="0", phi="0"),
     "yawing by t/5 while the height waves"),
    ("linear-delta-long-csv.csv", LDELTA,
     csv(("t", "x", "y", "z"), *[(i / 20, round(0.2 * __import__("math").cos(i / 20), 4),
                                  round(0.2 * __import__("math").sin(i / 20), 4),
                                  round(0.05 * i / 20, 4)) for i in range(301)]),
     "a 301-row CSV log of a rising circle, cubic spline"),
    ("biglide-decimal-touch", BIGLIDE, path("[-1, 1]", x="0.25", y="0.3*t^2"),
     "a decimal parabola touching y = 0 at t = 0"),
]

SAMPLES = {"ortho-constant": 8, "3-rpr-constant-tilt": 8,
           "gough-stewart-constant": 8}


def materialise(item, work: Path):
    name, robot, traj, _ = item
    if isinstance(robot, tuple):
        base, edits = robot
        text = (ROOT / base).read_text()
        for old, new in edits:
            assert old in text, (name, old)
            text = text.replace(old, new)
        robot_file = work / f"{name.removesuffix('.csv')}-robot.yaml"
        robot_file.write_text(text)
    else:
        robot_file = ROOT / robot
    if "\n" not in traj:  # a bundled trajectory file
        return robot_file, ROOT / traj
    traj_file = work / (name if name.endswith(".csv") else f"{name}.yaml")
    traj_file.write_text(traj)
    return robot_file, traj_file


def oracle(item, robot_file: Path, traj_file: Path) -> fo.OracleVerdict:
    spec = yaml.safe_load(robot_file.read_text())
    robot = fo.robot_from_spec(spec)
    if traj_file.suffix == ".csv":
        lines = traj_file.read_text().split()
        head = lines[0].split(",")
        rows = [dict(zip(["t"] + head[1:], line.split(","), strict=True)) for line in lines[1:]]
        pieces = fo.path_pieces({}, spec, csv_rows=rows)
    else:
        pieces = fo.path_pieces(yaml.safe_load(traj_file.read_text()), spec)
    return fo.judge(robot, pieces, SAMPLES.get(item[0], 600))


def run_singcheck(robot_file: Path, traj_file: Path) -> tuple[dict | None, float, str]:
    cmd = ["nice", "-n", "10", sys.executable, "-m", "singcheck", "run", str(robot_file),
           str(traj_file), "--format", "json", "-q"]
    start = time.perf_counter()
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=400,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - start, "timeout 400 s"
    wall = time.perf_counter() - start
    try:
        return json.loads(out.stdout)["trajectories"][0], wall, ""
    except (ValueError, KeyError, IndexError):
        return None, wall, f"exit {out.returncode}: {out.stderr.strip()[-300:]}"


def _angle_close(a: float, b: float) -> bool:
    d = (a - b) % (2 * 3.141592653589793)
    return min(d, 2 * 3.141592653589793 - d) < 1e-6


def singcheck_times(result: dict) -> tuple[list[float], list]:
    times, surfaces = set(), []
    for m in result.get("working_modes", []):
        if m.get("feasible"):
            times.update(m.get("singular_times") or [])
            if m.get("on_surface"):
                surfaces.append((m["label"], *m["on_surface"]))
    return sorted(times), surfaces


def compare(item, truth: fo.OracleVerdict, result: dict | None, problem: str) -> tuple[str, str]:
    """(agreement, note): agree | acceptable | DISAGREE | undetermined."""
    if result is None:
        return "DISAGREE", f"no answer: {problem}"
    verdict = result["verdict"]
    notes = []
    # feasible modes, matched by their joints at the start
    robot_joints = None
    oracle_feasible = {k: r for k, r in truth.modes.items() if r.feasible}
    sc_feasible = {m["label"]: m for m in result.get("working_modes", []) if m.get("feasible")}
    for label, r in oracle_feasible.items():
        m = sc_feasible.get(label)
        if m is None:
            notes.append(f"oracle mode {label} feasible, singcheck's not")
            continue
        robot_joints = list(m["joints_at_start"].values())
        same = all(_angle_close(float(a), b) or abs(float(a) - b) < 1e-6
                   for a, b in zip(r.start, robot_joints, strict=True))
        if not same:
            notes.append(f"mode {label}: joints at start differ "
                         f"{[mp.nstr(a, 6) for a in r.start]} vs {robot_joints}")
    for label in sc_feasible:
        if label not in oracle_feasible:
            notes.append(f"singcheck mode {label} feasible, the oracle's not "
                         f"({truth.modes[label].reason if label in truth.modes else '?'})")
    times, surfaces = singcheck_times(result)
    touch = any(r.touches or r.end_zeros for r in oracle_feasible.values())
    if verdict == truth.verdict:
        if verdict == "singular":
            spans = [(a, b) for _, a, b in surfaces]
            extra = [t for t in times if not any(abs(t - u) <= TOL for u in truth.times)
                     and not any(a - TOL <= t <= b + TOL for a, b in spans)]
            missing = [u for u in truth.times if not any(abs(t - u) <= TOL for t in times)]
            if surfaces or truth.on_surface:
                if bool(surfaces) != bool(truth.on_surface):
                    notes.append(f"on_surface {surfaces} vs oracle {truth.on_surface}")
            windows = [u["t_interval"] for u in result.get("undecided", [])]
            named = [u for u in missing if any(a - TOL <= u <= b + TOL for a, b in windows)]
            missing = [u for u in missing if u not in named]
            if extra or missing:
                notes.append(f"times: extra {extra}, missing {missing}")
            elif named and not notes:
                return "acceptable", (f"singular times {named} lie in windows singcheck "
                                      f"names as undecided")
    elif verdict == "unknown" and (touch or truth.ambiguous):
        if not result.get("reason"):
            notes.append("unknown without a reason")
        else:
            return ("acceptable" if not notes else "DISAGREE",
                    "; ".join(notes) or f"unknown: {result['reason'][:150]}")
    else:
        notes.append(f"verdict {verdict} vs oracle {truth.verdict}: "
                     f"{result.get('reason', '')[:200]}")
    if notes:
        return ("undetermined" if truth.ambiguous else "DISAGREE"), "; ".join(notes)
    return "agree", ""


def fmt_times(ts, surfaces=()) -> str:
    ts = [t for i, t in enumerate(ts) if i == 0 or abs(t - ts[i - 1]) > 1e-9]
    out = ", ".join(f"{t:.7g}" for t in ts[:4]) + (" …" if len(ts) > 4 else "")
    if surfaces:
        out += (" " if out else "") + " ".join(f"{m}:[{a:.4g},{b:.4g}]" for m, a, b in surfaces)
    return out


def main(argv: list[str]) -> int:
    oracle_only = "--oracle-only" in argv
    names = [a for a in argv if not a.startswith("--")]
    chosen = [i for i in INPUTS if not names or i[0] in names]
    rows = []
    with tempfile.TemporaryDirectory(prefix="field-") as tmp:
        work = Path(tmp)
        for item in chosen:
            robot_file, traj_file = materialise(item, work)
            t0 = time.perf_counter()
            truth = oracle(item, robot_file, traj_file)
            oracle_s = time.perf_counter() - t0
            if oracle_only:
                print(f"{item[0]}: {truth.verdict} {fmt_times(truth.times, truth.on_surface)}"
                      f"  ({oracle_s:.1f} s)")
                for r in truth.modes.values():
                    print(f"   {r.label}: feasible={r.feasible} {r.reason} start="
                          f"{[mp.nstr(a, 6) for a in r.start]} crossings="
                          f"{[mp.nstr(t, 10) for t in r.crossings]} ends="
                          f"{[mp.nstr(t, 10) for t in r.end_zeros]} touches="
                          f"{[(mp.nstr(t, 10), mp.nstr(v, 3)) for t, v in r.touches]}"
                          f" min|detA|={mp.nstr(r.min_abs_det, 3) if r.min_abs_det else '-'}"
                          f" on_surface={r.on_surface}")
                if truth.ambiguous:
                    print("   ambiguous:", truth.ambiguous)
                continue
            result, wall, problem = run_singcheck(robot_file, traj_file)
            agreement, note = compare(item, truth, result, problem)
            sc_verdict = result["verdict"] if result else "—"
            sc_times = fmt_times(*singcheck_times(result)) if result else ""
            rows.append((item[0], f"{truth.verdict} {fmt_times(truth.times, truth.on_surface)}",
                         f"{sc_verdict} {sc_times}", agreement, wall, note))
            print(f"{item[0]:<30} {rows[-1][1]:<38} {rows[-1][2]:<38} {agreement:<12} "
                  f"{wall:6.1f} s  {note}", flush=True)
    if rows:
        bad = [r for r in rows if r[3] == "DISAGREE"]
        print(f"\n{len(rows)} inputs: {sum(r[3] == 'agree' for r in rows)} agree, "
              f"{sum(r[3] == 'acceptable' for r in rows)} acceptable (unknown with a reason, or "
              f"a time inside a window singcheck names undecided), "
              f"{sum(r[3] == 'undetermined' for r in rows)} undetermined, {len(bad)} disagree")
        return 1 if bad else 0
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
