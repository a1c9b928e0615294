"""The HTML page's animation: the robot moving along the path (plotly frames, a slider).

One figure per trajectory: the robot's drawing (its spec's ``drawing`` key, evaluated
like :mod:`singcheck.report.postures` does, in ball arithmetic at each frame's time and
the feasible mode's joints) beside μ(t) and det A(t), on which a marker runs with the
frames.  The frames are ``samples`` evenly spaced times plus every proven singular time
of the mode (one frame per time, in order), so the animation stops exactly on each
singular posture; those times are marked on μ and det A (red) and in the frame's
slider label.  The curves come from the same float samples as the other figures.
"""

from __future__ import annotations

import numpy as np
from flint import arb

from singcheck.certify.classification import TrajectoryReport
from singcheck.report.postures import (
    drawing_at,
    drawing_box,
    postures,
    traced_points,
)

SAMPLES = 120  # evenly spaced frames; the singular times are added to them
_SINGULAR = "#d62728"
_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf")


def frame_times(report: TrajectoryReport, mode: str, samples: int = SAMPLES):
    """The frames' times: (float, ball, is_singular, segment or None), sorted; the
    singular times are the certified enclosures of the mode's proven singular times."""
    rng = report.trajectory.global_range
    lo, hi = float(rng.start), float(rng.end)
    times = [(float(x), arb(float(x)), False, None) for x in np.linspace(lo, hi, samples)]
    times[0] = (lo, rng.start.ball(), False, 1)
    times[-1] = (hi, rng.end.ball(), False, len(report.trajectory.pieces))
    for m in report.modes:
        if m.label == mode:
            times += [(c.time, c.t, True, c.segment) for c in m.singular_times]
    return sorted(times, key=lambda x: x[0])


def _body_traces(go, bodies, dim: int, singular: bool):
    """One trace per body: its chains as one line broken by gaps, or its points."""
    traces, moving = [], 0
    for body in bodies:
        fixed = body.fixed
        colour = "#777777" if fixed else _COLOURS[moving % len(_COLOURS)]
        moving += not fixed
        if body.chains:
            pts = np.concatenate([np.vstack([c, np.full((1, dim), np.nan)])
                                  for c in body.chains])
            # on a singular frame the moving segments turn red
            style = {"mode": "lines", "line": {"color": _SINGULAR if singular and not fixed
                                               else colour, "width": 3 if fixed else 7}}
        else:
            pts = body.points
            style = {"mode": "markers", "marker": {
                "color": colour, "size": 6 if dim == 3 else 11,
                "line": {"color": _SINGULAR if singular else "black", "width": 2}}}
        coords = {k: [None if np.isnan(v) else float(v) for v in pts[:, i]]
                  for i, k in enumerate("xyz"[:dim])}
        cls = go.Scatter3d if dim == 3 else go.Scatter
        traces.append(cls(name=body.name, showlegend=True, **coords, **style))
    return traces


def animation_figure(report: TrajectoryReport, d, title: str, samples: int = SAMPLES):
    """A plotly figure with one frame per time of :func:`frame_times`, or None when the
    robot has no drawing or no mode is real at the start.  ``d`` is the trajectory's
    :class:`~singcheck.report.plots.FigureData`."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    posts = postures(report)
    if not posts:
        return None
    mode = posts[0].mode
    spec = report.path.projection.model.spec
    dim = spec.drawing_dimension
    robot_type = "scene" if dim == 3 else "xy"
    fig = make_subplots(rows=2, cols=2, column_widths=[0.55, 0.45], horizontal_spacing=0.08,
                        specs=[[{"type": robot_type, "rowspan": 2}, {"type": "xy"}],
                               [None, {"type": "xy"}]],
                        subplot_titles=(f"the robot, mode {mode}", "μ(t) / max|μ|",
                                        f"det A, mode {mode}"))
    times = frame_times(report, mode, samples)
    # None where a joint is not proven real on the ball (only off a feasible mode)
    frames_bodies = [drawing_at(report, mode, ball, segment)
                     for _, ball, _, segment in times]
    first = next(b for b in frames_bodies if b is not None)
    # static traces: the traced path, μ, det A, the singular times
    cls = go.Scatter3d if dim == 3 else go.Scatter
    path_traces = traced_points(report, d.t[:: max(1, len(d.t) // 600)])
    for trace in path_traces:
        fig.add_trace(cls(**{k: trace[:, i] for i, k in enumerate("xyz"[:dim])},
                          mode="lines", name="path", line={"color": "grey", "dash": "dash",
                                                           "width": 2}), row=1, col=1)
    fig.add_trace(go.Scatter(x=d.t, y=d.mu, mode="lines", name="μ", line={"color": "black"},
                             showlegend=False), row=1, col=2)
    det = d.det_a.get(mode)
    if det is not None:
        fig.add_trace(go.Scatter(x=d.t, y=det, mode="lines", name="det A",
                                 line={"color": "#1f77b4"}, showlegend=False), row=2, col=2)
    sing = [t for t, _, s, _ in times if s]
    if sing:
        fig.add_trace(go.Scatter(x=sing, y=[0] * len(sing), mode="markers",
                                 name="proven singular times",
                                 marker={"color": _SINGULAR, "size": 10, "symbol": "x"}),
                      row=1, col=2)
        if det is not None:
            fig.add_trace(go.Scatter(x=sing, y=[0] * len(sing), mode="markers",
                                     showlegend=False, name="proven zeros",
                                     marker={"color": _SINGULAR, "size": 10, "symbol": "x"}),
                          row=2, col=2)
        for row, curve in ((1, d.mu), (2, det)):
            if curve is None or not np.isfinite(curve).any():  # (no μ: interval engine)
                continue
            lo, hi = float(np.nanmin(curve)), float(np.nanmax(curve))
            xs = [v for t in sing for v in (t, t, None)]
            ys = [v for _ in sing for v in (lo, hi, None)]
            fig.add_trace(go.Scatter(x=xs, y=ys, mode="lines", showlegend=False,
                                     hoverinfo="skip", line={"color": _SINGULAR, "width": 1,
                                                             "dash": "dot"}), row=row, col=2)
    # animated traces: the robot's bodies, then the two running markers
    moving_from = len(fig.data)
    for trace in _body_traces(go, first, dim, False):
        fig.add_trace(trace, row=1, col=1)
    ts = np.array([t for t, *_ in times])
    mu_at = np.interp(ts, d.t, d.mu)
    det_at = np.interp(ts, d.t, det) if det is not None else np.zeros_like(ts)
    fig.add_trace(go.Scatter(x=[ts[0]], y=[mu_at[0]], mode="markers", name="now",
                             marker={"color": "#ff7f0e", "size": 12}), row=1, col=2)
    fig.add_trace(go.Scatter(x=[ts[0]], y=[det_at[0]], mode="markers", showlegend=False,
                             marker={"color": "#ff7f0e", "size": 12}), row=2, col=2)
    indices = list(range(moving_from, len(fig.data)))
    frames, steps = [], []
    for k, ((t, _, singular, _), bodies) in enumerate(zip(times, frames_bodies,
                                                                  strict=True)):
        bodies = bodies or first
        name = f"{k}"
        data = _body_traces(go, bodies, dim, singular) + [
            go.Scatter(x=[t], y=[mu_at[k]]), go.Scatter(x=[t], y=[det_at[k]])]
        frames.append(go.Frame(data=data, traces=indices, name=name))
        label = f"{t:.3f}" + (" singular" if singular else "")
        steps.append({"method": "animate", "label": label,
                      "args": [[name], {"mode": "immediate", "frame": {"duration": 0,
                                                                      "redraw": True},
                                        "transition": {"duration": 0}}]})
    fig.frames = frames
    play = {"frame": {"duration": 60, "redraw": True}, "fromcurrent": True,
            "transition": {"duration": 0}}
    fig.update_layout(
        title={"text": title, "y": 0.985, "yanchor": "top"}, height=660, margin={"t": 120},
        updatemenus=[{"type": "buttons", "showactive": False, "x": 0.0, "y": -0.08,
                      "xanchor": "left", "yanchor": "top", "direction": "left",
                      "buttons": [{"label": "▶ play", "method": "animate",
                                   "args": [None, play]},
                                  {"label": "❚❚ pause", "method": "animate",
                                   "args": [[None], {"mode": "immediate",
                                                     "frame": {"duration": 0}}]}]}],
        sliders=[{"active": 0, "steps": steps, "x": 0.14, "len": 0.86, "y": -0.04,
                  "currentvalue": {"prefix": f"{report.trajectory.parameter} = "}}],
        legend={"orientation": "h", "y": 1.1, "x": 0.0, "yanchor": "bottom"})
    fig.update_xaxes(title_text=report.trajectory.parameter, row=2, col=2)
    box = drawing_box([b for b in frames_bodies if b], path_traces)
    names = [v for v in spec.pose if v not in spec.angles]  # the pose's positions
    titles = list(names) if len(names) == dim else ["", "", ""]
    if dim == 3:
        fig.update_scenes(aspectmode="cube", **{
            f"{k}axis": {"range": list(box[i]), "title": titles[i], "autorange": False}
            for i, k in enumerate("xyz")})
    else:
        fig.update_xaxes(range=list(box[0]), title_text=titles[0], row=1, col=1)
        fig.update_yaxes(range=list(box[1]), title_text=titles[1], scaleanchor="x",
                         row=1, col=1)
    return fig

