"""JUnit XML for CI test reports: a ``testsuite`` per robot, a ``testcase`` per trajectory.

singularity-free passes; singular and infeasible are ``<failure>`` (the message gives the
singular times of the feasible modes); unknown and per-trajectory errors are ``<error>``.
``time`` attributes are the seconds each trajectory took.  Built with ElementTree, so the
text is escaped; the tests validate it against the JUnit schema in
``tests/data/junit-report.xsd`` (three-decimal times, known attributes only).
"""

from __future__ import annotations

import platform
import xml.etree.ElementTree as ET
from datetime import UTC, datetime
from typing import Any


def _seconds(x: float) -> str:
    """A ``time`` attribute: seconds with three decimals, as Surefire writes them (the
    schema's pattern allows no more)."""
    return f"{x:.3f}"


def _singular_times(t: dict[str, Any]) -> str:
    parts = [f"{m['label']} at {t['parameter']} ≈ " + ", ".join(f"{x:.9g}" for x in
                                                                 m["singular_times"])
             for m in t["working_modes"] if m["feasible"] and m["singular_times"]]
    return "; ".join(parts)


def _details(t: dict[str, Any]) -> str:
    reason = t["reason"]
    if not reason.startswith(t["verdict"]):
        reason = f"{t['verdict']}: {reason}"
    lines = [f"{t['name']} ({t['path']}): {reason}"]
    for c in t["candidates"]:
        if c["status"] == "real":
            lo, hi = c["t_interval"]
            lines.append(f"  singular at {t['parameter']} ∈ [{lo:.17g}, {hi:.17g}] in mode(s) "
                         + ", ".join(c["singular_modes"]))
    for u in t.get("undecided", []):
        lo, hi = u["t_interval"]
        lines.append(f"  undecided on [{lo:.9g}, {hi:.9g}]: {u['reason']}")
    return "\n".join(lines)


def testcase(robot: dict[str, Any], t: dict[str, Any]) -> ET.Element:
    # no ``file`` attribute: CI readers' JUnit schemas have none; the file
    # is named in the failure or error text
    case = ET.Element("testcase", name=t["name"], classname=f"singcheck.{robot['name']}",
                      time=_seconds(t.get("time_s", 0)))
    verdict = t["verdict"]
    if verdict == "singular":
        times = _singular_times(t)
        message = f"singular: {times}" if times else f"singular: {t['reason']}"
    elif verdict in ("infeasible", "near-singular"):
        message = f"{verdict}: {t['reason']}"
    elif verdict in ("unknown", "error"):
        kind = t.get("error", {}).get("kind", "")
        el = ET.SubElement(case, "error", message=t["reason"],
                           type=f"error.{kind}" if kind else "unknown")
        el.text = _details(t)
        return case
    else:
        return case
    el = ET.SubElement(case, "failure", message=message, type=verdict)
    el.text = _details(t)
    return case


def clearance_properties(trajectories: list[dict[str, Any]]) -> dict[str, str]:
    """``clearance.TRAJECTORY.MODE`` = "min κ in [lo, hi] at t = …" per considered mode
    (suite properties: the JUnit schema gives a testcase none)."""
    out = {}
    for t in trajectories:
        for label, c in (t.get("clearance") or {}).items():
            lo, hi = c["interval"]
            out[f"clearance.{t['name']}.{label}"] = (f"{c['min']:.9g} in [{lo:.9g}, {hi:.9g}] "
                                                      f"at {t['parameter']} = {c['t']:.9g}")
    return out


def junit_xml(robot: dict[str, Any], trajectories: list[dict[str, Any]],
              properties: dict[str, str]) -> str:
    """The whole report: one suite (this run's robot) holding one case per trajectory."""
    failures = sum(t["verdict"] in ("singular", "infeasible", "near-singular")
                   for t in trajectories)
    errors = sum(t["verdict"] in ("unknown", "error") for t in trajectories)
    total = sum(t.get("time_s", 0) for t in trajectories)
    counts = {"tests": str(len(trajectories)), "failures": str(failures),
              "errors": str(errors), "time": _seconds(total)}
    root = ET.Element("testsuites", name="singcheck", **counts)
    suite = ET.SubElement(root, "testsuite", name=robot["name"], **counts, skipped="0",
                          timestamp=datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%S"),
                          hostname=platform.node() or "localhost")
    props = ET.SubElement(suite, "properties")
    for name, value in {**properties, **clearance_properties(trajectories)}.items():
        if value is not None:  # not known on this run (ξ not expanded: no degree)
            ET.SubElement(props, "property", name=name, value=str(value))
    for t in trajectories:
        suite.append(testcase(robot, t))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, "unicode") + "\n"
