"""The robot drawn at the start of a path and at each of its proven singular times.

What is drawn is the robot spec's ``drawing`` key: bodies of segments and points whose
coordinates are exact polynomials in the joints and the pose.  A posture evaluates them
in Arb ball arithmetic at the pose φ(t) and at the joints of one working mode (its IK
branch per leg, :meth:`~singcheck.certify.path.LegAlongPath.branches`), at the
certified enclosure of the time; the picture takes the balls' midpoints.  The times and
the mode come from the certified report: the start of the range, and each singular time
of each feasible mode (a candidate proven singular in that mode, so a *real*
singularity).  Nothing here decides anything.

The path is traced by every drawn point that depends on the pose only (the end
effector, say), sampled in floats.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from flint import acb, arb

from singcheck.algebra.intervals import evaluate
from singcheck.algebra.opaque import is_opaque_constant, opaque_ball
from singcheck.algebra.radicals import angle_names, radical_prime
from singcheck.certify.classification import TrajectoryReport
from singcheck.spec.files import RobotSpec


@dataclass
class DrawnBody:
    name: str
    chains: list[np.ndarray]  # each (n ≥ 2, dim): segments joined in turn
    points: np.ndarray  # (m, dim), possibly empty
    fixed: bool = False  # no joint or pose variable in it (a rail, a base)


@dataclass
class Posture:
    t: float  # midpoint of the certified time enclosure
    t_interval: tuple[float, float]
    mode: str
    kind: str  # start | singular
    feasible: bool
    bodies: list[DrawnBody]


def _mid(value) -> float:
    if isinstance(value, acb):
        value = value.real
    return float(arb(value).mid())


def _values(spec: RobotSpec, joints: list, pose: list) -> list:
    """Balls of the spec's variables, in its context's order, from joint and pose values
    (balls or anything ``arb`` takes; an angle in radians, or a revolute branch's
    (cos θ, sin θ) pair): an angle's ``cos(v)``, ``sin(v)``, a parameter's ``sqrt(p)``
    and a parameter outside the exact field (``K[[…]]``) are enclosed by Arb."""
    named = {}
    for n, v in zip((*spec.joints, *spec.pose), (*joints, *pose), strict=True):
        if n in spec.angles:
            pair = v if isinstance(v, tuple) else (arb(v).cos(), arb(v).sin())
            named.update(zip(angle_names(n), pair, strict=True))
        else:
            named[n] = v if isinstance(v, (arb, acb)) else arb(v)
    return [named[n] if n in named else opaque_ball(n, arb(0)) if is_opaque_constant(n)
            else arb(radical_prime(n)).sqrt() for n in spec.context.names()]


def draw_bodies(spec: RobotSpec, joints: list, pose: list) -> list[DrawnBody]:
    """The drawing at these joint and pose values (see :func:`_values`)."""
    values = _values(spec, joints, pose)

    def point(coords) -> list[float]:
        return [_mid(evaluate(c, values)) for c in coords]

    dim = spec.drawing_dimension or 0
    return [DrawnBody(body.name,
                      [np.array([point(p) for p in chain]) for chain in body.chains],
                      np.array([point(p) for p in body.points]).reshape(-1, dim),
                      not any(_moves(c, _indices(spec, (*spec.joints, *spec.pose)))
                              for p in (*body.points, *sum(body.chains, ())) for c in p))
            for body in spec.drawing]


def _indices(spec: RobotSpec, names) -> list[int]:
    """The context indices of these joints or pose variables (an angle: cos and sin)."""
    context = spec.context.names()
    return [context.index(v) for n in names for v in spec.variables(n)]


def _moves(c, indices: list[int]) -> bool:
    """Whether the polynomial involves one of these variables (a parameter's sqrt(p)
    is a variable of the context too, but it never moves)."""
    return any(c.degrees()[i] > 0 for i in indices)  # the zero polynomial: -1


def _on_piece(report: TrajectoryReport, index: int, t: arb):
    """The model of the path's piece ``index`` (0-based) and the ball ``t`` of the user's
    time in that piece's own time (the inverse of ``TrajectorySpec.to_global``: τ = g·π·t
    on a rescaled piece, u = t − t₀ on an interpolated one)."""
    if not report.pieces:
        return report.path, t
    return report.pieces[index].path, report.trajectory.pieces[index].to_local(t)


def piece_index(report: TrajectoryReport, t: float) -> int:
    """The (first) piece whose range holds the time t, 0-based (for drawing only)."""
    pieces = report.trajectory.pieces
    for i, spec in enumerate(pieces):
        if t <= float(spec.global_range.end):
            return i
    return len(pieces) - 1


def drawing_at(report: TrajectoryReport, label: str, t: arb,
               segment: int | None = None) -> list[DrawnBody] | None:
    """The robot's drawing at the user's time ``t`` (a ball) in working mode ``label``, on
    the given piece (1-based; default: the one holding t's midpoint); None where a joint
    of the mode is not proven real on the ball."""
    index = piece_index(report, _mid(t)) if segment is None else segment - 1
    path, local = _on_piece(report, index, t)
    per_leg = [leg.branches(local) for leg in path.legs]
    joints = [per_leg[i][ch] for i, ch in enumerate(label)]
    if any(j is None or isinstance(j, acb) or isinstance(j, tuple) and
           not all(isinstance(v, arb) for v in j) for j in joints):
        return None
    return draw_bodies(path.projection.model.spec, joints, path.pose_at(local))


def postures(report: TrajectoryReport) -> list[Posture]:
    """The start posture and one per proven singular time, for each feasible mode (for
    a path with no feasible mode: the start posture of the first mode real there)."""
    if not report.path.projection.model.spec.drawing:
        return []
    start = report.trajectory.global_range.start.ball()
    feasible = [m for m in report.modes if m.feasible]
    if not feasible:
        feasible = [m for m in report.modes if drawing_at(report, m.label, start, 1)][:1]
    out = []
    for mode in feasible:
        times = [("start", start, 1)] + [("singular", c.t, c.segment)
                                         for c in mode.singular_times]
        for kind, t, segment in times:
            bodies = drawing_at(report, mode.label, t, segment)
            if bodies is None:  # the branch's reality is not proven on this ball
                continue
            out.append(Posture(_mid(t), (float(t.lower()), float(t.upper())), mode.label,
                               kind, mode.feasible, bodies))
    return out


def traced_points(report: TrajectoryReport, t: np.ndarray) -> list[np.ndarray]:
    """Each distinct drawn point that moves with the pose alone (preferring the drawing's
    single points), sampled along the path at the user's times ``t``: arrays of shape
    (len(t), dim)."""
    model = report.path.projection.model
    spec = model.spec
    joint_index = _indices(spec, spec.joints)
    pose_index = _indices(spec, spec.pose)
    located = [(piece_index(report, float(x)), float(x)) for x in t]
    located = [(i, _on_piece(report, i, arb(x))) for i, x in located]

    def pose_only(p) -> bool:
        return not any(_moves(c, joint_index) for c in p) and \
            any(_moves(c, pose_index) for c in p)

    # the drawing's single points (a platform) when some move with the pose alone, else
    # every end point of a segment that does
    traced = [p for body in spec.drawing for p in body.points if pose_only(p)] or \
        [q for body in spec.drawing for chain in body.chains for q in chain if pose_only(q)]
    samples = [_values(spec, [arb(0)] * len(spec.joints), path.pose_at(local))
               for _, (path, local) in located]
    seen, out = set(), []
    for p in traced:
        if tuple(map(str, p)) not in seen:
            seen.add(tuple(map(str, p)))
            out.append(np.array([[_mid(evaluate(c, values)) for c in p]
                                 for values in samples]))
    return out


_SINGULAR = "#d62728"


def drawing_box(drawings: list[list[DrawnBody]], traces: list[np.ndarray]) -> np.ndarray:
    """One cube (dim × [lo, hi]) holding every drawn point and trace, a margin around."""
    pts = [b.points for bodies in drawings for b in bodies] + \
        [c for bodies in drawings for b in bodies for c in b.chains] + traces
    allp = np.concatenate([q for q in pts if len(q)])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 0.5) * 1.08
    return np.stack([centre - half, centre + half], axis=1)


def _shade_common_plane(ax, bodies: list[DrawnBody]) -> None:
    """When every moving point of a 3-D posture lies in one plane (the Orthoglide's legs
    at a parallel singularity), shade their convex hull in that plane (drawing only)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    from scipy.spatial import ConvexHull, QhullError

    pts = [b.points for b in bodies if not b.fixed] + \
        [c for b in bodies if not b.fixed for c in b.chains]
    pts = np.unique(np.round(np.concatenate([q for q in pts if len(q)]), 12), axis=0)
    if len(pts) < 4:
        return
    centre = pts.mean(axis=0)
    _, sv, basis = np.linalg.svd(pts - centre)
    if sv[2] > 1e-6 * sv[0]:
        return  # not coplanar
    flat = (pts - centre) @ basis[:2].T
    try:
        hull = ConvexHull(flat)
    except QhullError:
        return
    ax.add_collection3d(Poly3DCollection([pts[hull.vertices]], facecolor=_SINGULAR,
                                         alpha=0.12, edgecolor=_SINGULAR, linewidth=0.6))


def posture_figure(plt, report: TrajectoryReport, title: str, samples: int = 600):
    """One panel per posture: the bodies, the traced path, the posture's point on it."""
    posts = postures(report)
    if not posts:
        return None
    spec = report.path.projection.model.spec
    dim = spec.drawing_dimension
    # the axes are named when the pose's positions (its variables but angles) are they
    axes = [v for v in spec.pose if v not in spec.angles]
    rng = report.trajectory.global_range
    lo, hi = float(rng.start), float(rng.end)
    traces = traced_points(report, np.linspace(lo, hi, samples))
    box = drawing_box([p.bodies for p in posts], traces)
    n = len(posts)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig = plt.figure(figsize=(4.2 * cols, 4.0 * rows + 0.4))
    colours = plt.get_cmap("tab10").colors
    for k, post in enumerate(posts):
        ax = fig.add_subplot(rows, cols, k + 1, **({"projection": "3d"} if dim == 3 else {}))
        singular = post.kind == "singular"
        if singular and dim == 3:
            _shade_common_plane(ax, post.bodies)
        for trace in traces:
            ax.plot(*trace.T, color="grey", lw=0.8, ls="--")
        moving = 0
        for body in post.bodies:
            colour = "0.45" if body.fixed else colours[moving % len(colours)]
            moving += not body.fixed
            for chain in body.chains:
                if singular and not body.fixed:  # the singular posture: a red halo
                    ax.plot(*chain.T, color=_SINGULAR, lw=7, alpha=0.3, solid_capstyle="round")
                ax.plot(*chain.T, color=colour, lw=1.4 if body.fixed else 2.4,
                        label=body.name if chain is body.chains[0] else None)
            if len(body.points):
                ax.plot(*body.points.T, ls="none", marker="o", ms=6, color=colour,
                        markeredgecolor=_SINGULAR if singular and not body.fixed else "black",
                        label=None if body.chains else body.name)
        what = "singular" if singular else "start"
        mode = post.mode + ("" if post.feasible else " (infeasible)")
        ax.set_title(f"{what} · t = {post.t:.6f} · mode {mode}", fontsize=9,
                     color=_SINGULAR if singular else "black")
        if len(axes) == dim:
            ax.set_xlabel(axes[0], fontsize=8)
            ax.set_ylabel(axes[1], fontsize=8)
            if dim == 3:
                ax.set_zlabel(axes[2], fontsize=8)
        ax.set_xlim(*box[0])
        ax.set_ylim(*box[1])
        if dim == 3:
            ax.set_zlim(*box[2])
            ax.set_box_aspect((1, 1, 1))
            ax.view_init(elev=22, azim=35)
            ax.tick_params(labelsize=6)
        else:
            ax.set_aspect("equal")
            ax.tick_params(labelsize=7)
        if k == 0:
            ax.legend(fontsize=7, loc="upper left")
    fig.suptitle(title)
    fig.tight_layout()
    return fig
