"""The paper's figures, from the same certified report (matplotlib, Agg: no display).

The curves are drawn from floating-point samples, which is fine for a picture; every
mark on them (candidate roots, their status, singular times, feasible modes) comes
from the certified :class:`~singcheck.certify.TrajectoryReport`, never from the samples.

Figures (each written as PNG and SVG):
  1. ``mu``: μ(t) = ξ(φ(t)) with the candidates, real and spurious, labelled.
  2. ``detA``: det A along each feasible working mode, its proven zeros marked.
  3. ``workspace``: the path in the workspace with the singular points and the surface
     ξ(X) = 0 near it (marching cubes, or a contour for a planar robot).
  4. ``jointspace``: the path's image in joint space for every real working mode, with
     the joint-limit box; the feasible mode(s) drawn bold.
  5. ``postures`` (robots with a ``drawing``): the robot at the start and at each proven
     singular time (:mod:`singcheck.report.postures`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from singcheck.certify.classification import TrajectoryReport

FIGURES = ("mu", "detA", "workspace", "jointspace")


def numpy_polynomial(poly):
    """A vectorised float evaluator of an exact polynomial (for drawing only)."""
    terms = [(float(c), [(i, int(e)) for i, e in enumerate(exps) if e])
             for exps, c in poly.terms()]
    nvars = poly.context().nvars()
    top = [max((int(e[i]) for e, _ in poly.terms()), default=0) for i in range(nvars)]

    def f(arrays):
        arrays = [np.asarray(a, dtype=float) for a in arrays]
        shape = np.broadcast(*arrays).shape if arrays else ()
        powers = []
        for a, m in zip(arrays, top, strict=True):
            p = [None, a]
            for _ in range(2, m + 1):
                p.append(p[-1] * a)
            powers.append(p)
        total = np.zeros(shape)
        for coeff, factors in terms:
            term = np.full(shape, coeff)
            for i, e in factors:
                term = term * powers[i][e]
            total = total + term
        return total

    return f


def named_arrays(ctx, table: dict) -> list:
    """The values of ``ctx``'s variables by name, for :func:`numpy_polynomial`: from
    ``table``, an angle's ``cos(v)``/``sin(v)`` from ``table[v]`` when only the angle is
    there, a ``sqrt(p)`` as √p, a parameter outside the exact field as its value,
    anything else 0 (drawing only)."""
    import math

    from flint import arb

    from singcheck.algebra.opaque import is_opaque_constant, opaque_ball
    from singcheck.algebra.radicals import radical_prime

    out = []
    for name in ctx.names():
        if name in table:
            out.append(table[name])
        elif name.startswith(("cos(", "sin(")) and name[4:-1] in table:
            out.append((np.cos if name[0] == "c" else np.sin)(table[name[4:-1]]))
        elif radical_prime(name) is not None:
            out.append(math.sqrt(radical_prime(name)))
        elif is_opaque_constant(name):  # a parameter outside the exact field: its value
            out.append(float(opaque_ball(name, arb(0)).mid()))
        else:
            out.append(0.0)
    return out


def _along(p, t: np.ndarray) -> np.ndarray:
    """A path polynomial (in t, s = sin t, c = cos t, square roots and the opaque
    coordinates of a path kept as expression trees) at the times t."""
    table = {"t": t, "s": np.sin(t), "c": np.cos(t)}
    table.update(_opaque_samples(p.context(), t))
    return numpy_polynomial(p)(named_arrays(p.context(), table))


def _opaque_samples(ctx, t: np.ndarray) -> dict:
    """The opaque variables' values at the times t (the midpoints of their balls:
    drawing only)."""
    from flint import arb

    from singcheck.algebra.opaque import opaque_ball, opaque_of

    out = {}
    for name in ctx.names()[3:]:
        if opaque_of(name) is not None:
            values = []
            for x in t:
                ball = opaque_ball(name, arb(float(x)))
                values.append(float(ball.mid()) if ball.is_finite() else np.nan)
            out[name] = np.array(values)
    return out


@dataclass
class FigureData:
    t: np.ndarray
    mu: np.ndarray  # normalised to max |μ| = 1 on the samples
    candidates: list[dict]  # t, status, label, interval
    pose: list[np.ndarray]
    joints: dict[str, list[np.ndarray]]  # mode -> per-joint values (NaN where not real)
    det_a: dict[str, np.ndarray]  # feasible mode -> det A samples
    singular: dict[str, list[float]]  # feasible mode -> certified singular times
    feasible: list[str]
    limits: dict[str, tuple[float, float]]
    names: dict[str, list[str]] = field(default_factory=dict)
    joins: list[dict] = field(default_factory=list)  # t and pose where pieces meet


def _sample_piece(path, n: int):
    """Samples of one piece in its own time: (own t, pose, μ, joints per leg branch, the
    model's pose variables).  A pose angle is in radians (its π offset included); a
    revolute branch is its (cos θ, sin θ) pair of arrays."""
    from singcheck.model.robot import REVOLUTE

    lo, hi = float(path.trajectory.range.start), float(path.trajectory.range.end)
    t = np.linspace(lo, hi, n)
    offsets = path.trajectory.angle_offsets
    model = path.projection.model
    pose = [_along(p, t) + np.pi * float(offsets.get(v, 0))
            for v, p in zip(model.pose, path.phi, strict=True)]
    variables = [_along(x, t) for x in path.coordinates] if path.coordinates else pose
    mu = _along(path.mu, t) if path.mu is not None else np.full_like(t, np.nan)
    legs = []
    for leg in path.legs:
        values = [_along(c, t) for c in leg.coefficients]
        if leg.leg.kind == REVOLUTE:
            a, b, dd = values
            w = a * a + b * b
            with np.errstate(invalid="ignore"):
                root = np.sqrt(_along(leg.discriminant, t))
            legs.append({label: ((-a * dd + sigma * b * root) / w,
                                 (-b * dd - sigma * a * root) / w)
                         for label, sigma in (("+", 1), ("-", -1))})
        elif len(values) == 2:
            legs.append({"o": -values[1] / values[0]})
        else:
            a, b, c = values
            with np.errstate(invalid="ignore"):
                root = np.sqrt(b * b - 4 * a * c)
            legs.append({"+": (-b + root) / (2 * a), "-": (-b - root) / (2 * a)})
    return t, pose, mu, legs, variables


def _joined(arrays: list):
    """Pieces' samples end to end (a revolute branch's (cos, sin) pairs pairwise)."""
    if isinstance(arrays[0], tuple):
        return tuple(np.concatenate([a[k] for a in arrays]) for k in range(2))
    return np.concatenate(arrays)


def _pair(value) -> tuple:
    return value if isinstance(value, tuple) else (value,)


def _display(value) -> np.ndarray:
    return np.arctan2(value[1], value[0]) if isinstance(value, tuple) else value


def _to_user_time(spec, t: np.ndarray) -> np.ndarray:
    """A piece's own time samples in the user's parameter (drawing only)."""
    if spec.time_scale is not None:
        return t / (float(spec.time_scale) * np.pi)
    return t + float(spec.time_offset)


def figure_data(report: TrajectoryReport, samples: int = 2000) -> FigureData:
    """Everything the figures draw, as arrays and certified marks (a path of several
    pieces is sampled piece by piece, in the user's parameter, its joins recorded)."""
    model = report.path.projection.model
    pieces = report.pieces or [report]
    specs = report.trajectory.pieces
    per = max(50, samples // len(pieces))
    parts = [_sample_piece(r.path, per) for r in pieces]
    t = np.concatenate([_to_user_time(spec, part[0]) for spec, part in zip(specs, parts,
                                                                            strict=True)])
    pose = [np.concatenate([part[1][i] for part in parts]) for i in range(len(model.pose))]
    mu = np.concatenate([part[2] for part in parts])
    mu = mu / (np.max(np.abs(mu)) or 1.0)
    legs = [{label: _joined([part[3][i][label] for part in parts])
             for label in parts[0][3][i]} for i in range(len(model.legs))]
    # displayed joints: a revolute branch as its angle atan2(sin, cos)
    joints = {m.label: [_display(legs[i][ch]) for i, ch in enumerate(m.label)]
              for m in report.modes}
    variables = [np.concatenate([part[4][i] for part in parts])
                 for i in range(len(parts[0][4]))]
    pose_names = [v for p in model.pose for v in model.spec.variables(p)]
    det = numpy_polynomial(model.det_A)
    feasible = [m.label for m in report.modes if m.feasible]
    det_a = {}
    for label in feasible:
        table = dict(zip(pose_names, variables, strict=True))
        for leg, ch in zip(model.legs, label, strict=True):
            table.update(zip(leg.variables, _pair(legs[model.legs.index(leg)][ch]),
                             strict=True))
        det_a[label] = det(named_arrays(model.det_A.context(), table))
    singular = {m.label: [c.time for c in m.singular_times] for m in report.modes
                if m.feasible}
    candidates = []
    for i, c in enumerate(report.candidates, 1):
        candidates.append({"t": c.time, "status": c.status, "label": f"s{i}",
                           "interval": (float(c.t.lower()), float(c.t.upper())),
                           "pose": [float(b.mid()) for b in c.pose]})
    limits = {j: (float(a), float(b)) for j, (a, b) in model.spec.joint_limits.items()}
    ends = np.cumsum([len(part[0]) for part in parts])[:-1]
    joins = [{"t": float(t[k]), "pose": [float(p[k]) for p in pose]} for k in ends]
    return FigureData(t, mu, candidates, pose, joints, det_a, singular, feasible, limits,
                      {"pose": list(model.pose), "joints": list(model.joints),
                       "parameter": [report.trajectory.parameter]}, joins)


def _mark_joins(ax, d: FigureData) -> None:
    """The joins of a path of several pieces: dotted vertical lines at their times."""
    for k, j in enumerate(d.joins):
        ax.axvline(j["t"], color="tab:blue", lw=0.8, ls=":",
                   label="segment joins" if k == 0 else None)


_STATUS_STYLE = {"real": ("red", "o"), "spurious": ("green", "x"), "unknown": ("magenta", "s")}


def _mu_figure(plt, d: FigureData, title: str):
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(d.t, d.mu, color="black", lw=1)
    ax.axhline(0, color="grey", lw=0.5)
    for i, c in enumerate(d.candidates):
        color, marker = _STATUS_STYLE.get(c["status"], ("magenta", "s"))
        ax.plot([c["t"]], [0], marker=marker, color=color, ms=8, ls="none")
        ax.annotate(f"{c['label']} ({c['status']})\nt={c['t']:.6f}", (c["t"], 0),
                    textcoords="offset points", xytext=(0, 14 if i % 2 else -30),
                    ha="center", fontsize=7)
    _mark_joins(ax, d)
    if d.joins:
        ax.legend(fontsize=7)
    ax.set_xlabel(d.names["parameter"][0])
    ax.set_ylabel("μ(t) / max|μ|")
    ax.set_title(title)
    return fig


def _det_figure(plt, d: FigureData, title: str):
    fig, ax = plt.subplots(figsize=(7, 4))
    for label in d.feasible:
        ax.plot(d.t, d.det_a[label], lw=1, label=f"mode {label}")
        ts = d.singular[label]
        if ts:
            ax.plot(ts, [0] * len(ts), "o", color="red", ms=7, label=f"proven zeros ({label})")
    ax.axhline(0, color="grey", lw=0.5)
    _mark_joins(ax, d)
    ax.set_xlabel(d.names["parameter"][0])
    ax.set_ylabel("det A")
    ax.set_title(title)
    if d.feasible:
        ax.legend(fontsize=7)
    return fig


def _workspace_figure(plt, d: FigureData, xi, title: str):
    if xi is None:  # not expanded (too big): the path alone
        title = title.replace("ξ(X) = 0", "ξ(X) not expanded")
    pose = d.names["pose"]
    f = numpy_polynomial(xi) if xi is not None else None
    if len(pose) == 2:
        fig, ax = plt.subplots(figsize=(6, 5))
        (x0, x1), (y0, y1) = _box(d.pose[0]), _box(d.pose[1])
        gx, gy = np.meshgrid(np.linspace(x0, x1, 300), np.linspace(y0, y1, 300))
        if f is not None:
            ax.contour(gx, gy, f(named_arrays(xi.context(), {pose[0]: gx, pose[1]: gy})),
                       levels=[0], colors="orange")
        ax.plot(d.pose[0], d.pose[1], color="black", lw=1)
        _mark_points(ax, d, 2)
        ax.set_xlabel(pose[0])
        ax.set_ylabel(pose[1])
    else:
        from skimage.measure import marching_cubes

        fig = plt.figure(figsize=(6, 5))
        ax = fig.add_subplot(projection="3d")
        boxes = [_box(p) for p in d.pose[:3]]
        n = 48
        axes = [np.linspace(a, b, n) for a, b in boxes]
        grid = list(np.meshgrid(*axes, indexing="ij"))
        values = f(named_arrays(xi.context(), dict(zip(pose, grid, strict=False)))) \
            if f is not None else np.ones_like(grid[0])
        if values.min() < 0 < values.max():
            verts, faces, _, _ = marching_cubes(values, 0.0)
            verts = np.array([b[0] for b in boxes]) + verts * np.array(
                [(b[1] - b[0]) / (n - 1) for b in boxes])
            ax.plot_trisurf(verts[:, 0], verts[:, 1], faces, verts[:, 2], color="orange",
                            alpha=0.35, lw=0)
        ax.plot(d.pose[0], d.pose[1], d.pose[2], color="black", lw=1.2)
        _mark_points(ax, d, 3)
        ax.set_xlabel(pose[0])
        ax.set_ylabel(pose[1])
        ax.set_zlabel(pose[2])
    ax.set_title(title)
    return fig


def _box(values: np.ndarray, margin: float = 0.25) -> tuple[float, float]:
    lo, hi = float(np.min(values)), float(np.max(values))
    pad = max(margin, 0.15 * (hi - lo))
    return lo - pad, hi + pad


def _mark_points(ax, d: FigureData, dims: int) -> None:
    for k, j in enumerate(d.joins):  # the joins of a path of several pieces
        ax.plot(*[[v] for v in j["pose"][:dims]], marker="D", color="tab:blue", ms=5,
                ls="none", label="segment joins" if k == 0 else None)
    for c in d.candidates:
        color, marker = _STATUS_STYLE.get(c["status"], ("magenta", "s"))
        ax.plot(*[[v] for v in c["pose"][:dims]], marker=marker, color=color, ms=8, ls="none")


def _joint_figure(plt, d: FigureData, title: str):
    names = d.names["joints"]
    three = len(names) >= 3
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d") if three else fig.add_subplot()
    for label, values in d.joints.items():
        bold = label in d.feasible
        coords = values[:3] if three else values[:2]
        ax.plot(*coords, lw=2.5 if bold else 0.8, alpha=1 if bold else 0.5,
                label=f"{label}{' (feasible)' if bold else ''}")
    if all(j in d.limits for j in names[:3 if three else 2]):
        _limit_box(ax, [d.limits[j] for j in names[:3 if three else 2]])
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    if three:
        ax.set_zlabel(names[2])
    ax.legend(fontsize=6, loc="upper left")
    ax.set_title(title)
    return fig


def _limit_box(ax, limits) -> None:
    from itertools import product

    corners = list(product(*limits))
    for a in corners:
        for b in corners:
            if sum(x != y for x, y in zip(a, b, strict=True)) == 1 and a < b:
                ax.plot(*[[x, y] for x, y in zip(a, b, strict=True)], color="grey", lw=0.6)


def clearance_curves(report: TrajectoryReport, labels, samples: int = 400) -> dict:
    """κ(t) sampled along each mode (floating point, for the figure only: the marks on it
    are the certified minima): label -> (t in the user's parameter, κ) arrays."""
    from flint import arb

    from singcheck.certify.clearance import kappa_at

    spec = report.path.projection.model.spec
    length = spec.clearance_length if spec.clearance_length is not None else 1
    pieces = report.pieces or [report]
    out = {}
    for label in labels:
        ts, ks = [], []
        for piece in pieces:
            mode = next(m for m in piece.modes if m.label == label)
            lo = float(piece.path.trajectory.range.start)
            hi = float(piece.path.trajectory.range.end)
            for t in np.linspace(lo, hi, max(2, samples // len(pieces))):
                k = kappa_at(piece.path, mode, float(t), length)
                ts.append(float(piece.path.trajectory.to_global(arb(float(t))).mid()))
                ks.append(np.nan if k is None else k)
        out[label] = (np.array(ts), np.array(ks))
    return out


def _clearance_figure(plt, report: TrajectoryReport, clearance: dict, gate, title: str):
    """κ(t) per considered mode, its certified minimum (a marker with the interval) and
    the --min-clearance line."""
    fig, ax = plt.subplots(figsize=(7, 4))
    curves = clearance_curves(report, list(clearance))
    for label, c in clearance.items():
        t, k = curves[label]
        line, = ax.plot(t, k, lw=1, label=f"κ along mode {label}")
        lo, hi = c.lo, c.hi
        ax.errorbar([c.t], [c.estimate], yerr=[[c.estimate - lo], [hi - c.estimate]],
                    fmt="v", color=line.get_color(), ms=7,
                    label=f"certified min ({label}): {c.estimate:.6g} ∈ [{lo:.6g}, {hi:.6g}]")
    if gate is not None:
        ax.axhline(gate, color="red", lw=1, ls="--", label=f"--min-clearance {gate:g}")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel(report.trajectory.parameter)
    ax.set_ylabel("κ (leg-normalised Jacobian)")
    ax.set_title(title)
    if clearance or gate is not None:
        ax.legend(fontsize=7)
    return fig


def write_figures(report: TrajectoryReport, out_dir: str | Path,
                  formats: tuple[str, ...] = ("png", "svg"), dpi: int = 120,
                  clearance: dict | None = None, gate: float | None = None,
                  taken: set[str] | None = None) -> list[Path]:
    """Write the figures for one trajectory into ``out_dir``, named after it
    (:func:`~singcheck.atomic.safe_file_name`: a name from the spec never leaves
    ``out_dir``; ``taken``: the names already written there by this run, kept apart);
    returns the files written.  With ``clearance`` (label ->
    :class:`~singcheck.certify.clearance.Clearance`), also κ(t) per mode with its
    certified minimum and the ``gate`` line."""
    import matplotlib

    from singcheck.atomic import safe_file_name

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    d = figure_data(report)
    # names from the specs, as plain text in the titles ('$' would start mathtext)
    robot = report.path.projection.model.name.replace("$", r"\$")
    name = report.name.replace("$", r"\$")
    makers = {
        "mu": lambda: _mu_figure(plt, d, f"{robot} · {name}: μ(t) and its certified roots"),
        "detA": lambda: _det_figure(plt, d, f"{robot} · {name}: det A along feasible modes"),
        "workspace": lambda: _workspace_figure(
            plt, d, report.path.projection.singularity_surface,
            f"{robot} · {name}: path and ξ(X) = 0"),
        "jointspace": lambda: _joint_figure(plt, d, f"{robot} · {name}: working modes"),
    }
    from singcheck.report.postures import posture_figure

    makers["postures"] = lambda: posture_figure(
        plt, report, f"{robot} · {name}: the robot at the start" + (
            " and at its singular times" if any(m.singular_times for m in report.modes
                                                if m.feasible) else
            " (no singular time on a feasible mode)"))
    if clearance is not None:
        makers["clearance"] = lambda: _clearance_figure(
            plt, report, clearance, gate, f"{robot} · {name}: clearance κ(t)")
    stem = safe_file_name(report.name, taken)
    written = []
    for key in makers:
        fig = makers[key]()
        if fig is None:  # no drawing in the robot spec
            continue
        for fmt in formats:
            target = out / f"{stem}-{key}.{fmt}"
            fig.savefig(target, dpi=dpi, bbox_inches="tight")
            written.append(target)
        plt.close(fig)
    return written


def write_html(reports: list[TrajectoryReport], target: str | Path,
               plotly_js: str = "inline", clearances: list | None = None,
               gate: float | None = None) -> Path:
    """One self-contained interactive page (plotly, its JavaScript inlined once) with
    the same four figures for every trajectory, and the robot moving along it
    (:mod:`singcheck.report.animation`) when its spec has a drawing.  ``plotly_js="cdn"``:
    the page loads plotly's JavaScript from its CDN instead (a few MB smaller; needs the
    network to be viewed).  ``clearances`` (per report, label -> Clearance) adds κ(t)
    per mode with its certified minimum and the ``gate`` line."""
    import plotly.graph_objects as go

    from singcheck.atomic import write_atomically

    parts = []
    first = True
    for index, report in enumerate(reports):
        d = figure_data(report)
        robot = report.path.projection.model.name
        figs = []
        mu = go.Figure(go.Scatter(x=d.t, y=d.mu, mode="lines", name="μ(t)/max|μ|"))
        for c in d.candidates:
            color = _STATUS_STYLE.get(c["status"], ("magenta", "s"))[0]
            mu.add_trace(go.Scatter(x=[c["t"]], y=[0], mode="markers", name=f"{c['label']} "
                                    f"{c['status']}", marker={"color": color, "size": 10},
                                    hovertext=f"t ∈ [{c['interval'][0]:.12g}, "
                                              f"{c['interval'][1]:.12g}]"))
        mu.update_layout(title=f"{robot} · {report.name}: μ(t) and its certified roots")
        figs.append(mu)
        det = go.Figure()
        for label in d.feasible:
            det.add_trace(go.Scatter(x=d.t, y=d.det_a[label], mode="lines", name=label))
            det.add_trace(go.Scatter(x=d.singular[label], y=[0] * len(d.singular[label]),
                                     mode="markers", name=f"proven zeros ({label})",
                                     marker={"color": "red", "size": 10}))
        det.update_layout(title=f"{robot} · {report.name}: det A along feasible modes")
        figs.append(det)
        pose = d.names["pose"]
        if len(pose) >= 3:
            ws = go.Figure(go.Scatter3d(x=d.pose[0], y=d.pose[1], z=d.pose[2], mode="lines",
                                        name="path"))
            for c in d.candidates:
                ws.add_trace(go.Scatter3d(x=[c["pose"][0]], y=[c["pose"][1]],
                                          z=[c["pose"][2]], mode="markers",
                                          name=f"{c['label']} {c['status']}",
                                          marker={"color": _STATUS_STYLE.get(
                                              c["status"], ("magenta",))[0]}))
            ws.update_layout(scene={"xaxis_title": pose[0], "yaxis_title": pose[1],
                                    "zaxis_title": pose[2]})
        else:
            ws = go.Figure(go.Scatter(x=d.pose[0], y=d.pose[1], mode="lines", name="path"))
            for c in d.candidates:
                ws.add_trace(go.Scatter(x=[c["pose"][0]], y=[c["pose"][1]], mode="markers",
                                        name=f"{c['label']} {c['status']}",
                                        marker={"color": _STATUS_STYLE.get(
                                            c["status"], ("magenta",))[0]}))
            ws.update_layout(xaxis_title=pose[0], yaxis_title=pose[1])
        ws.update_layout(title=f"{robot} · {report.name}: path and singular points")
        figs.append(ws)
        js = go.Figure()
        names = d.names["joints"]
        for label, values in d.joints.items():
            width = 6 if label in d.feasible else 2
            if len(names) >= 3:
                js.add_trace(go.Scatter3d(x=values[0], y=values[1], z=values[2],
                                          mode="lines", name=label, line={"width": width}))
            else:
                js.add_trace(go.Scatter(x=values[0], y=values[1], mode="lines", name=label,
                                        line={"width": width}))
        js.update_layout(title=f"{robot} · {report.name}: working modes in joint space")
        if len(names) >= 3:
            js.update_layout(scene={"xaxis_title": names[0], "yaxis_title": names[1],
                                    "zaxis_title": names[2]})
        else:
            js.update_layout(xaxis_title=names[0], yaxis_title=names[1])
        figs.append(js)
        if clearances is not None:
            figs.append(_clearance_html(go, report, clearances[index], gate,
                                        f"{robot} · {report.name}: clearance κ(t)"))
        from singcheck.report.animation import animation_figure

        moving = animation_figure(report, d, f"{robot} · {report.name}: the robot along "
                                  "the path")
        for fig in figs + ([moving] if moving is not None else []):
            script = "cdn" if plotly_js == "cdn" else True  # cdn: a <script src=...>
            parts.append(fig.to_html(full_html=False, auto_play=False,
                                     include_plotlyjs=first and script))
            first = False
    page = ("<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>singcheck figures"
            "</title></head><body>\n" + "\n".join(parts) + "\n</body></html>\n")
    write_atomically(target, page, make_parents=True)
    return Path(target)


def _clearance_html(go, report: TrajectoryReport, clearance: dict, gate, title: str):
    fig = go.Figure()
    curves = clearance_curves(report, list(clearance))
    for label, c in clearance.items():
        t, k = curves[label]
        fig.add_trace(go.Scatter(x=t, y=k, mode="lines", name=f"κ ({label})"))
        fig.add_trace(go.Scatter(
            x=[c.t], y=[c.estimate], mode="markers", name=f"certified min ({label})",
            marker={"symbol": "triangle-down", "size": 11},
            error_y={"type": "data", "symmetric": False, "array": [c.hi - c.estimate],
                     "arrayminus": [c.estimate - c.lo]},
            hovertext=f"min κ ∈ [{c.lo:.9g}, {c.hi:.9g}] at t ≈ {c.t:.9g}"))
    if gate is not None:
        fig.add_hline(y=gate, line_dash="dash", line_color="red",
                      annotation_text=f"--min-clearance {gate:g}")
    fig.update_layout(title=title, yaxis_range=[0, 1.02],
                      xaxis_title=report.trajectory.parameter, yaxis_title="κ")
    return fig
