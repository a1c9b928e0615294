"""Rendering of certification reports: a rich table for people, JSON for programs.

The JSON document is described in docs/outputs.md ("JSON output") and by its JSON
Schema, singcheck/schemas/report.schema.json (``singcheck schema report``); bump
``SCHEMA_VERSION`` on any incompatible change.
"""

from __future__ import annotations

import json
from typing import Any

from singcheck.algebra.intervals import endpoints
from singcheck.certify.classification import NOT_NEEDED, TrajectoryReport
from singcheck.elimination.projection import RobotProjection
from singcheck.version import __version__

SCHEMA_VERSION = 1

_VERDICT_STYLE = {
    "singularity-free": "bold green",
    "singular": "bold red",
    "infeasible": "bold yellow",
    "near-singular": "bold yellow",
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
        "t": c.time,
        "t_interval": _interval(c.t),
        "pose": {v: float(b.mid()) for v, b in zip(pose_names, c.pose, strict=True)},
        "joints": c.joints,
        "singular_modes": c.singular_modes,
        "status": c.status,
        "modes": [{"mode": m.mode, "status": m.status, "proof": m.proof} for m in c.modes],
        "segment": c.segment,
        "on_surface": _on_surface(c),
    }


def _on_surface(c) -> list[float] | None:
    """[t0, t1] of a candidate whose singular modes are singular all along it (det A ≡ 0
    on the piece), else None."""
    if c.on_surface is None:
        return None
    return [float(c.on_surface[0].mid()), float(c.on_surface[1].mid())]


def _range(spec) -> list[str]:
    rng = spec.global_range
    return [str(rng.start), str(rng.end)]


def _trajectory_head(spec) -> dict[str, Any]:
    """Name, file, parameter and range of a trajectory; of a document that could not be
    read as one (a :class:`~singcheck.spec.files.Document`): its name, or FILE:LINE
    when it has none, and null parameter and range."""
    if hasattr(spec, "label"):
        return {"name": spec.label, "path": spec.path, "parameter": None, "range": None}
    return {
        "name": spec.name,
        "path": spec.path,
        "parameter": spec.parameter,
        "range": _range(spec),
    }


def segments_json(report: TrajectoryReport) -> list[dict[str, Any]]:
    """Per piece of the path (one for a one-piece path): its range in the user's
    parameter, how its roots were isolated, and its time rescaling if any."""
    pieces = report.pieces or [report]
    return [{"segment": i, "range": _range(spec), "root_isolation": piece.root_method,
             "time_scale": None if spec.time_scale is None else f"tau = {spec.time_scale}*pi*"
                                                                 f"{spec.parameter}"}
            for i, (spec, piece) in enumerate(zip(report.trajectory.pieces, pieces,
                                                  strict=True), 1)]


#: a path of more pieces than this has its pieces summarised, not listed, in the table
MAX_LISTED_SEGMENTS = 6
#: undecided stretches the table lists in full without -v (the rest: a count)
MAX_UNDECIDED_SHOWN = 5


def segments_line(segments: list[dict[str, Any]]) -> str:
    """The table's line on a path's pieces: each piece listed for a few, else summarised
    (a 50-row CSV is 49 pieces: their count, the whole range, the isolation methods)."""
    def one(s):
        return f"{s['segment']}: [{s['range'][0]}, {s['range'][1]}] ({s['root_isolation']})"

    if len(segments) <= MAX_LISTED_SEGMENTS:
        return "  segments: " + "; ".join(one(s) for s in segments)
    methods = list(dict.fromkeys(str(s["root_isolation"]) for s in segments))
    first, last = segments[0], segments[-1]
    return (f"  segments: {len(segments)} pieces (1: [{first['range'][0]}, "
            f"{first['range'][1]}]; …; {last['segment']}: [{last['range'][0]}, "
            f"{last['range'][1]}]), roots by {' and '.join(methods)}")


def time_limited_json(spec, reason: str) -> dict[str, Any]:
    """The trajectory object of a certification stopped by its time limit: unknown.  The
    reason says why, without repeating the verdict (``time limit (2 s) reached``)."""
    while reason.startswith("unknown: "):
        reason = reason.removeprefix("unknown: ")
    return {**_trajectory_head(spec), "verdict": "unknown", "reason": reason,
            "root_isolation": None, "candidates": [], "working_modes": [], "undecided": []}


def error_json(spec, kind: str, message: str) -> dict[str, Any]:
    """The trajectory object of a trajectory whose check failed (``kind``: backend, spec
    — a document that is no valid trajectory, or a path refused as too costly — or
    internal): verdict ``error``, the reason, and nothing certified."""
    return {**time_limited_json(spec, message), "verdict": "error",
            "error": {"kind": kind, "message": message}}


def trajectory_json(report: TrajectoryReport) -> dict[str, Any]:
    doc = {
        **_trajectory_head(report.trajectory),
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
                "proof": m.proof,
                "singular_times": [c.time for c in m.singular_times],
                "on_surface": next((_on_surface(c) for c in m.singular_times
                                    if c.on_surface is not None), None),
            }
            for m in report.modes
        ],
        "undecided": [{"t_interval": _interval(t), "reason": r} for t, r in report.undecided],
        "segments": segments_json(report),
        "corroboration": None if report.corroboration is None
        else report.corroboration.to_json(),
    }
    if report.verdict == "error":  # the two engines disagree
        doc["error"] = {"kind": "inconsistent", "message": report.reason}
    return doc


def workspace_json(w) -> dict[str, Any]:
    """The path against the workspace's regions (:mod:`singcheck.path_regions`)."""
    return {
        "one_region": w.one_region,
        "region": w.region,
        "crossings": [{"t_interval": _interval(c.t), "surfaces": list(c.surfaces),
                       "kind": c.kind} for c in w.crossings],
        "ik_counts": [s.count for s in w.stretches],
        "exit_time_interval": None if w.exit_time is None else _interval(w.exit_time),
        "undecided": w.undecided,
        "on_surfaces": [{"surface": surface, "t_range": where}
                        for surface, where in w.on_surfaces],
        **({"region_not_named": w.region_reason} if w.region_reason else {}),
    }


def _meets(crossings: list[dict[str, Any]]) -> str:
    """"crosses the discriminant variety 4 time(s)", or, when some meeting is a proven
    tangency or not judged, "meets … (crossing it 1, touching it 1, 1 not judged)"."""
    n = len(crossings)
    kinds = [c.get("kind") for c in crossings]
    if all(k == "crosses" for k in kinds):
        return f"crosses the discriminant variety {n} time(s)"
    parts = [f"{verb} it {kinds.count(kind)}" for verb, kind in
             (("crossing", "crosses"), ("touching", "touches")) if kind in kinds]
    if None in kinds:
        parts.append(f"{kinds.count(None)} not judged (a range end, or signs not proven)")
    return f"meets the discriminant variety {n} time(s) ({', '.join(parts)})"


def workspace_line(w: dict[str, Any]) -> str:
    """One sentence for the table report."""
    counts = w["ik_counts"]
    if w["one_region"] is None:
        return "workspace: crossings not all decided: " + "; ".join(w["undecided"])
    if w.get("on_surfaces"):
        ranges: dict[str, list[str]] = {}
        for item in w["on_surfaces"]:
            ranges.setdefault(item["t_range"], []).append(item["surface"])
        text = "workspace: the path lies on " + "; on ".join(
            f"{', '.join(surfaces)} for t ∈ {where}" for where, surfaces in ranges.items())
        if not w["crossings"]:
            return text + (f" ({counts[0]} IK solution(s) inside the joint limits all along)"
                           if counts and counts[0] is not None else "")
        return text + (f"; it {_meets(w['crossings'])}; IK solutions inside the limits "
                       "along it: " + " → ".join("?" if c is None else str(c) for c in counts))
    if w["one_region"]:
        where = f"region {w['region']}" if w["region"] else "one region of the workspace"
        text = (f"workspace: the whole path lies in {where} "
                f"({counts[0]} IK solution(s) inside the joint limits all along)")
        if w.get("region_not_named"):
            text += f"; {w['region_not_named']}"
        return text
    text = (f"workspace: the path {_meets(w['crossings'])}; IK solutions inside the limits "
            "along it: " + " → ".join("?" if c is None else str(c) for c in counts))
    if w["exit_time_interval"]:
        lo, hi = w["exit_time_interval"]
        text += f"; it leaves the workspace at t ∈ [{lo:.9g}, {hi:.9g}]"
    return text


def robot_json(projection: RobotProjection) -> dict[str, Any]:
    model = projection.model
    return {"name": model.name, "path": model.spec.path, "joints": list(model.joints),
            "pose": list(model.pose)}


def document(projection: RobotProjection, trajectories: list[dict[str, Any]],
             tolerance: float, exit_code: int) -> dict[str, Any]:
    return {
        "schema_version": SCHEMA_VERSION,
        "singcheck_version": __version__,
        "robot": robot_json(projection),
        "backend": projection.backend,
        "elimination_method": projection.method,
        "singularity_surface_degree": int(projection.singularity_surface.total_degree())
        if projection.expanded else None,
        "tolerance": tolerance,
        "trajectories": trajectories,
        "exit_code": exit_code,
    }


def to_json(doc: dict[str, Any]) -> str:
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


class JsonLine:
    """The ``--format jsonl`` line of a trajectory object: the object with its
    ``time_s`` last, then the robot (``robot``: :func:`robot_json`).  Picklable, so
    that the worker that checked a trajectory writes its line
    (:class:`singcheck.api.Formatted`)."""

    def __init__(self, robot: dict[str, Any]) -> None:
        self.robot = robot

    def __call__(self, doc: dict[str, Any]) -> str:
        doc = dict(doc)
        doc["time_s"] = doc.pop("time_s", None)
        doc["robot"] = self.robot
        return json.dumps(doc, ensure_ascii=False) + "\n"


def _modes_table(working_modes: list[dict[str, Any]], joints: list[str], verbose: bool):
    """The working modes of one trajectory: status, joints at the start, singular times
    and why (more than eight modes: the infeasible ones only with ``verbose``)."""
    from rich.table import Table

    modes = Table(title="working modes", title_justify="left")
    for col in ("mode", "status", *[f"{j} at start" for j in joints], "singular at", "why"):
        modes.add_column(col)
    for m in working_modes:
        if not verbose and m["status"] == "infeasible" and len(working_modes) > 8:
            continue
        modes.add_row(m["label"], m["status"],
                      *[_num(m["joints_at_start"].get(j), 4) for j in joints],
                      _singular_at(m),
                      m["reason"] or "")
    return modes


def _singular_at(m: dict[str, Any]) -> str:
    """The table's "singular at" cell: the times, or the whole stretch on the surface."""
    if m.get("on_surface"):
        lo, hi = m["on_surface"]
        return f"all of [{_num(lo, 6)}, {_num(hi, 6)}] (det A ≡ 0)"
    return ", ".join(_num(x, 6) for x in m["singular_times"]) or "—"


def row_mode(c: dict[str, Any], feasible: list[str]) -> str | None:
    """The mode a candidate's row is about: the first feasible mode singular there, else
    the first feasible mode whose joints it has."""
    for label in [*c["singular_modes"], *feasible]:
        if label in feasible and label in c["joints"]:
            return label
    return None


def mode_line(mode: dict[str, Any]) -> str:
    """The table's line on the working mode the verdict is about."""
    how = {"--mode": "--mode", "document": "the trajectory's mode key",
           "--start-joints": "--start-joints, joints at the start within "
                             f"{mode.get('start_tolerance', 1e-6):g}"}[mode["chosen_by"]]
    return f"  working mode {mode['label']} only (chosen by {how})"


def clearance_lines(t: dict[str, Any], verbose: bool = False) -> list[str]:
    """The table's lines on the certified clearance κ of each considered mode."""
    settings = t.get("clearance_settings") or {}
    length = settings.get("angle_length", "1")
    note = " (default)" if settings.get("angle_length_default", True) else ""
    head = ("  clearance κ (smallest singular value of the leg-normalised Jacobian; a pose "
            f"angle's column ÷ L = {length}{note}):")
    lines = [head]
    if not t["clearance"]:
        lines.append("    none: no considered working mode is feasible")
    for label, c in t["clearance"].items():
        lo, hi = c["interval"]
        flag = "" if c.get("tolerance_met", True) else " (tolerance not met: the interval " \
            "is what the budget reached)"
        lines.append(f"    {label}: min {_num(c['min'], 9)} ∈ [{lo:.9g}, {hi:.9g}] at "
                     f"{t['parameter']} ≈ {_num(c['t'], 9)}{flag}")
        if verbose and c.get("method"):
            lines.append(f"      proof: {c['method']}")
    if settings.get("min_clearance") is not None:
        lines.append(f"    gate: --min-clearance {settings['min_clearance']:g}")
    return lines


def render_tables(console, robot: dict[str, Any], trajectories: list[dict[str, Any]],
                  verbose: bool = False) -> None:
    """Print one candidates table and one working-modes table per trajectory.

    Works from the JSON-shaped dicts of :func:`trajectory_json`, so reports computed in
    worker processes render the same way.
    """
    from rich.table import Table

    joints, pose = robot["joints"], robot["pose"]
    for t in trajectories:
        segments = t.get("segments") or []
        pieces = f", {len(segments)} segments" if len(segments) > 1 else ""
        isolated = t["root_isolation"] is not None
        sought = t["root_isolation"] != NOT_NEEDED
        title = f"{robot['name']} · {t['name']}" + (
            f"  ({t['parameter']} ∈ [{t['range'][0]}, {t['range'][1]}]{pieces}"
            + (f", roots by {t['root_isolation']})" if sought and isolated else ")")
            if t["range"] else f"  ({t['path']})")
        feasible = [m["label"] for m in t["working_modes"] if m["feasible"]]
        if t["candidates"]:
            table = Table(title=title, title_justify="left")
            for col in ("#", *(["segment"] if pieces else []), t["parameter"], *pose,
                        *joints, "joints of"):
                table.add_column(col, justify="right")
            table.add_column("singular modes")
            table.add_column("status")
            for i, c in enumerate(t["candidates"], 1):
                own = row_mode(c, feasible)
                shown = c["joints"].get(own, {}) if own else {}
                style = {"real": "red", "spurious": "green"}.get(c["status"], "magenta")
                table.add_row(str(i), *([str(c.get("segment", 1))] if pieces else []),
                              _num(c["t"], 9), *[_num(c["pose"][v], 4) for v in pose],
                              *[_num(shown.get(j), 4) for j in joints], own or "—",
                              ", ".join(c["singular_modes"]) or "none",
                              f"[{style}]{c['status']}[/{style}]")
            console.print(table)
        elif not isolated:
            console.print(f"[bold]{title}[/bold]\n  not certified: the check ended before "
                          "the real roots of μ(t) were isolated")
        elif not sought:
            console.print(f"[bold]{title}[/bold]\n  candidates not sought: no working mode "
                          "is feasible, so no singularity can be met (μ not isolated)")
        else:
            console.print(f"[bold]{title}[/bold]\n  no candidate: μ(t) = ξ(φ(t)) has no real "
                          "root on the range")
        if t["working_modes"]:  # none when the check ended before the feasibility proofs
            console.print(_modes_table(t["working_modes"], joints, verbose))
        if verbose:
            for i, c in enumerate(t["candidates"], 1):
                lo, hi = c["t_interval"]
                console.print(f"  candidate {i}: {t['parameter']} ∈ [{lo:.17g}, {hi:.17g}]")
                for m in c["modes"]:
                    console.print(f"    {m['mode']}: {m['status']} ({m['proof']})")
        shown = t["undecided"] if verbose or len(t["undecided"]) <= MAX_UNDECIDED_SHOWN \
            else t["undecided"][:MAX_UNDECIDED_SHOWN - 1]
        for u in shown:
            lo, hi = u["t_interval"]
            console.print(f"  undecided for {t['parameter']} in [{lo:.9g}, {hi:.9g}]: "
                          f"{u['reason']}")
        if len(shown) < len(t["undecided"]):
            console.print(f"  … and {len(t['undecided']) - len(shown)} more undecided "
                          "stretch(es): all of them with -v or --format json")
        if t.get("mode"):
            console.print(mode_line(t["mode"]))
        if t.get("clearance") is not None:
            for line in clearance_lines(t, verbose):
                console.print(line)
        if pieces:
            console.print(segments_line(segments))
        if t.get("workspace"):
            console.print(workspace_line(t["workspace"]))
        style = _VERDICT_STYLE.get(t["verdict"], "bold")
        reason = t["reason"].removeprefix(f"{t['verdict']}: ")
        console.print(f"verdict [{style}]{t['verdict']}[/{style}]: {reason}\n")
