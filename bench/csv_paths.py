"""Long CSV tables of poses for the Orthoglide (issue 27): many rows, default cubic.

    python bench/csv_paths.py OUT_DIR [ROWS]

writes two tables of ROWS rows (default 2000), poses with 6 decimals:

* ``heart-ROWS.csv``: the paper's heart 1 sampled at ROWS equally spaced t in [-π, π]
  (x = 8/7 sin³t, y = 13/14 cos t − 5/14 cos 2t − 1/10 cos 3t − 1/14 cos 4t, z = 1);
* ``circle-drift-ROWS.csv``: t = i/100, x = 0.6 + 0.3 cos t, y = 0.6 + 0.3 sin t,
  z = 1 + t/100.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path


def heart_rows(n: int) -> list[tuple[float, float, float, float]]:
    rows = []
    for i in range(n):
        t = -math.pi + 2 * math.pi * i / (n - 1)
        x = 8 / 7 * math.sin(t) ** 3
        y = (13 / 14 * math.cos(t) - 5 / 14 * math.cos(2 * t) - 1 / 10 * math.cos(3 * t)
             - 1 / 14 * math.cos(4 * t))
        rows.append((t, x, y, 1.0))
    return rows


def circle_drift_rows(n: int) -> list[tuple[float, float, float, float]]:
    return [(i / 100, 0.6 + 0.3 * math.cos(i / 100), 0.6 + 0.3 * math.sin(i / 100),
             1 + i / 100 / 100) for i in range(n)]


def table(rows) -> str:
    """A CSV text: header t,x,y,z, every value with 6 decimals."""
    body = "\n".join(",".join(f"{v:.6f}" for v in row) for row in rows)
    return "t,x,y,z\n" + body + "\n"


def write(out: Path, n: int = 2000) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, rows in ((f"heart-{n}.csv", heart_rows(n)),
                       (f"circle-drift-{n}.csv", circle_drift_rows(n))):
        path = out / name
        path.write_text(table(rows))
        paths.append(path)
    return paths


if __name__ == "__main__":
    args = sys.argv[1:]
    for p in write(Path(args[0]), int(args[1]) if len(args) > 1 else 2000):
        print(p)
