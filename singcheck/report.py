"""Rendering of certification reports: a rich table for people, JSON for programs.

The JSON document is described in the README ("JSON output"); bump
``SCHEMA_VERSION`` on any incompatible change.
"""

from __future__ import annotations

import json
from typing import Any

from singcheck import __version__
from singcheck.certify import TrajectoryReport
from singcheck.intervals import endpoints
from singcheck.projection import RobotProjection

SCHEMA_VERSION = 1

_VERDICT_STYLE = {
    "singularity-free": "bold green",
    "singular": "bold red",
    "infeasible": "bold yellow",
    "unknown": "bold magenta",
}


def _num(x: float | None, digits: int = 6) -> str:
    return "—" if x is None else f"{x:.{digits}g}"


def _interval(ball) -> list[float]:
    lo, hi = endpoints(ball)
    return [lo, hi]


def candidate_json(report: TrajectoryReport, c) -> dict[str, Any]:
    pose_names = report.path.projection.model.pose
    return {
        "t": float(c.t.mid()),
        "t_interval": _interval(c.t),
        "pose": {v: float(b.mid()) for v, b in zip(pose_names, c.pose, strict=True)},
        "joints": c.joints,
        "singular_modes": c.singular_modes,
        "status": c.status,
        "modes": [{"mode": m.mode, "status": m.status, "proof": m.proof} for m in c.modes],
    }


def trajectory_json(report: TrajectoryReport) -> dict[str, Any]:
    spec = report.path.trajectory
    return {
        "name": spec.name,
        "path": spec.path,
        "parameter": spec.parameter,
        "range": [str(spec.range.start), str(spec.range.end)],
        "verdict": report.verdict,
        "reason": report.reason,
        "root_isolation": report.root_method,
        "candidates": [candidate_json(report, c) for c in report.candidates],
        "working_modes": [
            {
                "label": m.label,
                "feasible": m.feasible,
                "status": m.status,
                "reason": m.reason,
                "joints_at_start": m.joints_at_start,
                "singular_times": [float(c.t.mid()) for c in m.singular_times],
            }
            for m in report.modes
        ],
        "undecided": [{"t_interval": _interval(t), "reason": r} for t, r in report.undecided],
    }


def document(projection: RobotProjection, reports: list[TrajectoryReport], tolerance: float,
             exit_code: int) -> dict[str, Any]:
    model = projection.model
    return {
        "schema_version": SCHEMA_VERSION,
        "singcheck_version": __version__,
        "robot": {"name": model.name, "path": model.spec.path, "joints": list(model.joints),
                  "pose": list(model.pose)},
        "backend": projection.backend,
        "elimination_method": projection.method,
        "singularity_surface_degree": int(projection.singularity_surface.total_degree()),
        "tolerance": tolerance,
        "trajectories": [trajectory_json(r) for r in reports],
        "exit_code": exit_code,
    }


def to_json(doc: dict[str, Any]) -> str:
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


def render_tables(console, projection: RobotProjection, reports: list[TrajectoryReport],
                  verbose: bool = False) -> None:
    """Print one candidates table and one working-modes table per trajectory."""
    from rich.table import Table

    model = projection.model
    for report in reports:
        spec = report.path.trajectory
        title = (f"{model.name} · {spec.name}  ({spec.parameter} ∈ {spec.range}, "
                 f"roots by {report.root_method})")
        table = Table(title=title, title_justify="left")
        table.add_column("#", justify="right")
        table.add_column(spec.parameter, justify="right")
        for v in model.pose:
            table.add_column(v, justify="right")
        feasible = [m.label for m in report.modes if m.feasible]
        for j in model.joints:
            table.add_column(j + (f" [{feasible[0]}]" if feasible else ""), justify="right")
        table.add_column("singular modes")
        table.add_column("status")
        for i, c in enumerate(report.candidates, 1):
            row = [str(i), _num(float(c.t.mid()), 9)]
            row += [_num(float(b.mid()), 4) for b in c.pose]
            joints = c.joints.get(feasible[0], {}) if feasible else {}
            row += [_num(joints.get(j), 4) for j in model.joints]
            row.append(", ".join(c.singular_modes) or "none")
            style = {"real": "red", "spurious": "green"}.get(c.status, "magenta")
            row.append(f"[{style}]{c.status}[/{style}]")
            table.add_row(*row)
        if not report.candidates:
            console.print(f"[bold]{title}[/bold]\n  no candidate: μ(t) = ξ(φ(t)) has no real "
                          "root on the range")
        else:
            console.print(table)
        modes = Table(title="working modes", title_justify="left")
        for col in ("mode", "status", *[f"{j} at start" for j in model.joints],
                    "singular at", "why"):
            modes.add_column(col)
        for m in report.modes:
            if not verbose and m.status == "infeasible" and len(report.modes) > 8:
                continue
            modes.add_row(m.label, m.status,
                          *[_num(m.joints_at_start.get(j), 4) for j in model.joints],
                          ", ".join(_num(float(c.t.mid()), 6) for c in m.singular_times) or "—",
                          m.reason or "")
        console.print(modes)
        if verbose:
            for i, c in enumerate(report.candidates, 1):
                lo, hi = _interval(c.t)
                console.print(f"  candidate {i}: {spec.parameter} ∈ [{lo:.17g}, {hi:.17g}]")
                for m in c.modes:
                    console.print(f"    {m.mode}: {m.status} ({m.proof})")
        for t, reason in report.undecided:
            console.print(f"  undecided near {spec.parameter} ≈ {float(t.mid()):.6g}: {reason}")
        style = _VERDICT_STYLE.get(report.verdict, "bold")
        console.print(f"verdict [{style}]{report.verdict}[/{style}]: {report.reason}\n")
