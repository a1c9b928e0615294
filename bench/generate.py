"""Random heart-like trajectories for the Orthoglide (exact rational harmonics).

    python bench/generate.py OUT_DIR [COUNT] [HARMONICS] [SEED]

Each trajectory is x = Σ a_k sin(k t), y = Σ b_k cos(k t), z = 1 on [-π, π], with
rational coefficients near the paper's heart shapes, so some cross the singularity
surface and some do not.
"""

from __future__ import annotations

import random
import sys
from fractions import Fraction
from pathlib import Path


def heart_like(rng: random.Random, name: str, harmonics: int = 4) -> str:
    scale = Fraction(rng.randint(60, 120), 100)
    xs = [Fraction(rng.randint(-20, 20), 100) for _ in range(harmonics)]
    ys = [Fraction(rng.randint(-20, 20), 100) for _ in range(harmonics)]
    xs[0] += Fraction(6, 7) * scale
    ys[0] += Fraction(13, 14) * scale
    if harmonics > 2:
        xs[2] -= Fraction(2, 7) * scale  # 8/7 sin³t = 6/7 sin t - 2/7 sin 3t
    if harmonics > 1:
        ys[1] -= Fraction(5, 14) * scale

    def term(c: Fraction, f: str, k: int) -> str:
        arg = "t" if k == 1 else f"{k}*t"
        return f"{c}*{f}({arg})"

    x = " + ".join(term(c, "sin", k) for k, c in enumerate(xs, 1)).replace("+ -", "- ")
    y = " + ".join(term(c, "cos", k) for k, c in enumerate(ys, 1)).replace("+ -", "- ")
    return (f"name: {name}\nparameter: t\nrange: [-pi, pi]\npose:\n  x: {x}\n  y: {y}\n"
            "  z: 1\n")


def waypoints_yaml(n: int = 100, name: str = "spline-100") -> str:
    """n waypoints wandering through the Orthoglide's workspace (3-decimal poses, t = 0 …
    n − 1), joined by the natural cubic spline (the default interpolation)."""
    import math

    rows = []
    for i in range(n):
        x = round(0.45 + 0.35 * math.sin(0.37 * i), 3)
        y = round(0.55 + 0.35 * math.cos(0.23 * i), 3)
        z = round(1 + 0.25 * math.sin(0.11 * i), 3)
        rows.append(f"  - {{t: {i}, x: {x}, y: {y}, z: {z}}}")
    return f"name: {name}\nparameter: t\nwaypoints:\n" + "\n".join(rows) + "\n"


def write(out: Path, count: int, harmonics: int = 4, seed: int = 2015) -> list[Path]:
    rng = random.Random(seed)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for i in range(count):
        path = out / f"heart-{harmonics}h-{i:04d}.yaml"
        path.write_text(heart_like(rng, path.stem, harmonics))
        paths.append(path)
    return paths


def write_stream(out: Path, count: int, harmonics: int = 4, seed: int = 2015) -> Path:
    """The same trajectories as :func:`write`, as one file of YAML documents (``---``
    between them), for ``singcheck run ROBOT - < out``."""
    rng = random.Random(seed)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w") as f:
        for i in range(count):
            f.write("---\n" + heart_like(rng, f"heart-{harmonics}h-{i:04d}", harmonics))
    return out


if __name__ == "__main__":
    args = sys.argv[1:]
    write(Path(args[0]), int(args[1]) if len(args) > 1 else 1000,
          int(args[2]) if len(args) > 2 else 4, int(args[3]) if len(args) > 3 else 2015)
