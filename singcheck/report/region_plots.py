"""Figures of a plane decomposition: regions coloured by their number of solutions.

The colour of a pixel is the count of the open CAD cell holding the pixel's centre:
its column is found against the critical values, its sector against the exact fibre
roots at the pixel column's x (for drawing only: the counts themselves are the exact
ones of :mod:`singcheck.space_analysis`, and each region is labelled at its exact
sample point).
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from singcheck.spaces.analysis import SpaceAnalysis
from singcheck.spaces.cad import fiber


def _window(analysis: SpaceAnalysis) -> tuple[float, float, float, float]:
    """A box around the cells with a positive count (or every sample)."""
    inside = [c.cell.sample for c in analysis.cells if c.count and c.within_limits] or \
        [c.cell.sample for c in analysis.cells]
    xs = [float(s[0]) for s in inside]
    ys = [float(s[1]) for s in inside]
    pad = max(max(xs) - min(xs), max(ys) - min(ys), 1.0) * 0.35
    return min(xs) - pad, max(xs) + pad, min(ys) - pad, max(ys) + pad


def count_image(analysis: SpaceAnalysis, size: int = 240):
    """A size×size array of counts (NaN where unknown) over the window, and the window."""
    import numpy as np

    x0, x1, y0, y1 = _window(analysis)
    cad = analysis.cad
    counts = {c.cell.index: c.count for c in analysis.cells}
    base = [float((r.lo + r.hi) / 2) for r in fiber(cad.levels, cad.variables, ())]
    xs = np.linspace(x0, x1, size)
    ys = np.linspace(y0, y1, size)
    image = np.full((size, size), np.nan)
    for col, x in enumerate(xs):
        i = sum(1 for b in base if b < x)
        roots = [float((r.lo + r.hi) / 2)
                 for r in fiber(cad.levels, cad.variables, (Fraction(float(x)),))]
        for row, y in enumerate(ys):
            j = sum(1 for r in roots if r < y)
            # a pixel column within float rounding of a critical value: its neighbour's
            value = next((counts[(k, j)] for k in (i, i - 1, i + 1) if (k, j) in counts),
                         None)
            image[row, col] = np.nan if value is None else value
    return image, (x0, x1, y0, y1)


def write_region_figure(analysis: SpaceAnalysis, out_dir: str | Path,
                        formats: tuple[str, ...] = ("png", "svg")) -> list[Path]:
    """One figure of a plane decomposition; returns the files written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    if len(analysis.axes) != 2:
        raise ValueError("region figures need a plane: fix all but two axes with --slice")
    image, (x0, x1, y0, y1) = count_image(analysis)
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    values = sorted({int(v) for v in np.unique(image[~np.isnan(image)])})
    cmap = plt.get_cmap("viridis", max(len(values), 2))
    index = np.full(image.shape, np.nan)
    for k, v in enumerate(values):
        index[image == v] = k
    mesh = ax.imshow(index, origin="lower", extent=(x0, x1, y0, y1), aspect="auto",
                     cmap=cmap, vmin=-0.5, vmax=max(len(values), 2) - 0.5,
                     interpolation="nearest")
    bar = fig.colorbar(mesh, ax=ax, ticks=range(len(values)))
    bar.ax.set_yticklabels([str(v) for v in values])
    bar.set_label("real solutions" + (" within the joint limits"
                                      if analysis.space == "workspace" else ""))
    if analysis.regions is not None:
        for region in analysis.regions.regions:
            count = analysis.region_count(region.number)
            s = region.cells[0].sample
            if count and x0 <= s[0] <= x1 and y0 <= s[1] <= y1:
                ax.annotate(f"R{region.number}", (float(s[0]), float(s[1])), fontsize=7,
                            color="white", ha="center")
    where = ", ".join(f"{k} = {v}" for k, v in analysis.fixed.items())
    ax.set_title(f"{analysis.robot} · {analysis.space}" + (f" at {where}" if where else ""))
    ax.set_xlabel(analysis.axes[0])
    ax.set_ylabel(analysis.axes[1])
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = f"{analysis.robot}-{analysis.space}" + "".join(
        f"-{k}={v}".replace("/", "_") for k, v in analysis.fixed.items())
    written = []
    for fmt in formats:
        target = out / f"{stem}.{fmt}"
        fig.savefig(target, dpi=120, bbox_inches="tight")
        written.append(target)
    plt.close(fig)
    return written
