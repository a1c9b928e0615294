"""Figures of a plane decomposition: regions filled by their number of solutions, the
curves of the discriminant variety drawn, each region labelled well inside it.

The colour of a pixel is the count of the open CAD cell holding the pixel's centre:
its column is found against the critical values, its sector against the exact fibre
roots at the pixel column's x (for drawing only: the counts themselves are the exact
ones of :mod:`singcheck.spaces.analysis`).  The same lookup gives each pixel its region,
and a region's label goes where its pixels are farthest from every other region and
from the window's edge (a Euclidean distance transform); a region too thin for a label
there is listed in a legend instead, with a marker at that point.  The curves are the
zero sets of the variety's named surfaces, each in its own style, drawn by contouring
the polynomial on a fine float grid (a picture, not a proof).
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from flint import fmpq

from singcheck.atomic import safe_file_name
from singcheck.spaces.analysis import LIMIT, PARALLEL, SERIAL, SpaceAnalysis
from singcheck.spaces.cad import fiber

SIZE = 560  # pixels a side: finer than the figure's axes at 120 dpi
THIN = 1 / 80  # a region none of whose pixels is this far (of the image's side) from its
#                border is "thin": listed in the legend, not labelled on the figure


def _window(analysis: SpaceAnalysis) -> tuple[float, float, float, float]:
    """A box around the cells with a positive count (or every sample)."""
    inside = [c.cell.sample for c in analysis.cells if c.count and c.within_limits] or \
        [c.cell.sample for c in analysis.cells]
    xs = [float(s[0]) for s in inside]
    ys = [float(s[1]) for s in inside]
    pad = max(max(xs) - min(xs), max(ys) - min(ys), 1.0) * 0.35
    return min(xs) - pad, max(xs) + pad, min(ys) - pad, max(ys) + pad


def cell_images(analysis: SpaceAnalysis, size: int = SIZE):
    """Two size×size arrays over the window, rows along y: each pixel's count (NaN where
    unknown) and its region number (-1 where no region is known); and the window."""
    import numpy as np

    x0, x1, y0, y1 = _window(analysis)
    cad = analysis.cad
    by_index = {c.cell.index: c for c in analysis.cells}
    # roots refined to well under a pixel, so that their midpoints place them
    xs = np.linspace(x0, x1, size)
    ys = np.linspace(y0, y1, size)
    step = Fraction(min(x1 - x0, y1 - y0) / size / 64).limit_denominator(1 << 40)
    pixel = fmpq(step.numerator, step.denominator)

    def centres(roots) -> list[float]:
        for r in roots:
            r.bisect_to(pixel)
        return [float((r.lo + r.hi) / 2) for r in roots]

    base = centres(fiber(cad.levels, cad.variables, ()))
    counts = np.full((size, size), np.nan)
    regions = np.full((size, size), -1, dtype=int)
    for col, x in enumerate(xs):
        i = sum(1 for b in base if b < x)
        roots = centres(fiber(cad.levels, cad.variables, (Fraction(float(x)),)))
        sectors = np.searchsorted(np.array(sorted(roots)), ys)
        for j in np.unique(sectors):
            # a pixel column within float rounding of a critical value: its neighbour's
            cell = next((by_index[(k, int(j))] for k in (i, i - 1, i + 1)
                         if (k, int(j)) in by_index), None)
            if cell is None:
                continue
            rows = sectors == j
            counts[rows, col] = np.nan if cell.count is None else cell.count
            regions[rows, col] = -1 if cell.region is None else cell.region
    return counts, regions, (x0, x1, y0, y1)


def count_image(analysis: SpaceAnalysis, size: int = SIZE):
    """A size×size array of counts (NaN where unknown) over the window, and the window."""
    counts, _, window = cell_images(analysis, size)
    return counts, window


def label_points(regions, window) -> dict[int, tuple[float, float, float]]:
    """Per region in the image: (x, y, depth), the pixel of the region farthest from any
    other region and from the window's edge, and that distance in pixels."""
    import numpy as np
    from scipy.ndimage import distance_transform_edt

    x0, x1, y0, y1 = window
    rows, cols = regions.shape
    out = {}
    for number in np.unique(regions):
        if number < 0:
            continue
        mask = np.pad(regions == number, 1)  # the window's edge is a border too
        depth = distance_transform_edt(mask)[1:-1, 1:-1]
        r, c = np.unravel_index(int(np.argmax(depth)), depth.shape)
        out[int(number)] = (x0 + (x1 - x0) * c / (cols - 1), y0 + (y1 - y0) * r / (rows - 1),
                            float(depth[r, c]))
    return out


_KIND_STYLE = {  # colours cycle within a kind; the kind sets the line style and width
    PARALLEL: (("#d62728", "#9b1b1b"), "-", 2.2),
    SERIAL: (("#1f77b4", "#17becf", "#2c5aa0", "#5fa2dd"), "-", 1.6),
    LIMIT: (("#444444", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#9467bd"),
            "--", 1.1),
}


def _curves(ax, analysis: SpaceAnalysis, window, size: int = 900):
    """Each named surface's zero set in its own style; the legend handles."""
    import numpy as np
    from matplotlib.lines import Line2D

    from singcheck.report.plots import numpy_polynomial

    x0, x1, y0, y1 = window
    gx, gy = np.meshgrid(np.linspace(x0, x1, size), np.linspace(y0, y1, size))
    handles, used = [], {}
    for comp in analysis.components:
        names = comp.polynomial.context().names()
        values = numpy_polynomial(comp.polynomial)(
            [gx if v == analysis.axes[0] else gy if v == analysis.axes[1] else 0.0 * gx
             for v in names])
        if not np.nanmin(values) < 0 < np.nanmax(values):
            continue  # no sign change in the window: nothing to draw here
        colours, style, width = _KIND_STYLE.get(comp.kind, (("black",), ":", 1.0))
        k = used.get(comp.kind, 0)
        used[comp.kind] = k + 1
        colour = colours[k % len(colours)]
        dashes = style if k < len(colours) else ":"
        ax.contour(gx, gy, values, levels=[0], colors=[colour], linewidths=width,
                   linestyles=[dashes])
        handles.append(Line2D([], [], color=colour, lw=width, ls=dashes,
                              label=f"{comp.kind}: {comp.label}"))
    return handles


def write_region_figure(analysis: SpaceAnalysis, out_dir: str | Path,
                        formats: tuple[str, ...] = ("png", "svg"),
                        size: int = SIZE) -> list[Path]:
    """One figure of a plane decomposition; returns the files written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.lines import Line2D

    if len(analysis.axes) != 2:
        raise ValueError("region figures need a plane: fix all but two axes with --slice")
    image, regions, window = cell_images(analysis, size)
    x0, x1, y0, y1 = window
    fig, ax = plt.subplots(figsize=(11, 6.4))
    values = sorted({int(v) for v in np.unique(image[~np.isnan(image)])})
    palette = ["#f2f2f2", "#b9dcf2", "#ffd59e", "#c7e9c0", "#e5c8f0", "#fdd0c7"]
    colours = {v: ("#f2f2f2" if v == 0 else palette[1 + k % (len(palette) - 1)])
               for k, v in enumerate(v for v in values if v)} | {0: palette[0]}
    rgb = np.ones(image.shape + (3,))
    for v in values:
        rgb[image == v] = matplotlib.colors.to_rgb(colours[v])
    ax.imshow(rgb, origin="lower", extent=(x0, x1, y0, y1), aspect="equal",
              interpolation="nearest")
    handles = _curves(ax, analysis, window)
    fills = [matplotlib.patches.Patch(facecolor=colours[v], edgecolor="0.6",
                                      label=f"{v} solution{'s' if v != 1 else ''}")
             for v in values]
    thin = []
    if analysis.regions is not None:
        for number, (x, y, depth) in sorted(label_points(regions, window).items()):
            count = analysis.region_count(number)
            strong = bool(count)
            if depth >= THIN * size:
                ax.annotate(f"R{number}", (x, y), fontsize=8 if strong else 6.5,
                            ha="center", va="center", fontweight="bold" if strong else None,
                            color="black" if strong else "0.45")
            elif strong:  # thin: a marker here and a line in the legend
                ax.plot([x], [y], marker="x", color="black", ms=5, ls="none")
                thin.append(Line2D([], [], marker="x", color="black", ls="none",
                                   label=f"R{number} ({count}): thin, at ({x:.2f}, {y:.2f})"))
    where = ", ".join(f"{k} = {v}" for k, v in analysis.fixed.items())
    robot = analysis.robot.replace("$", r"\$")  # plain text, not mathtext
    ax.set_title(f"{robot} · {analysis.space}" + (f" at {where}" if where else "")
                 + ": regions and the discriminant variety")
    ax.set_xlabel(analysis.axes[0])
    ax.set_ylabel(analysis.axes[1])
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    counted = "real solutions" + (" within the joint limits"
                                  if analysis.space == "workspace" else "")
    ax.legend(handles=fills + handles + thin, fontsize=7, loc="upper left",
              bbox_to_anchor=(1.02, 1.0), title=f"fill: {counted}", title_fontsize=7,
              frameon=False)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    stem = safe_file_name(f"{analysis.robot}-{analysis.space}" + "".join(
        f"-{k}={v}" for k, v in analysis.fixed.items()))
    written = []
    for fmt in formats:
        target = out / f"{stem}.{fmt}"
        with matplotlib.rc_context({"svg.fonttype": "none"}):  # SVG text stays text
            fig.savefig(target, dpi=120, bbox_inches="tight")
        written.append(target)
    plt.close(fig)
    return written
