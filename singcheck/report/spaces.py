"""Rendering of workspace / joint-space analyses: a rich table, or JSON (docs/spaces.md)."""

from __future__ import annotations

from collections import Counter
from typing import Any

from singcheck.spaces.analysis import JOINTSPACE, WORKSPACE, SpaceAnalysis
from singcheck.version import __version__

SCHEMA_VERSION = 1


def _point(axes, sample) -> dict[str, str]:
    return {a: str(q) for a, q in zip(axes, sample, strict=True)}


def analysis_json(a: SpaceAnalysis, left_out: list[str], exit_code: int) -> dict[str, Any]:
    cells = [{"index": list(c.cell.index), "sample": _point(a.axes, c.cell.sample),
              "count": c.count, "reason": c.reason or None,
              "within_limits": c.within_limits, "region": c.region} for c in a.cells]
    regions = None
    if a.regions is not None:
        regions = []
        for r in a.regions.regions:
            members = [c for c in a.cells if c.region == r.number]
            regions.append({"number": r.number, "count": a.region_count(r.number),
                            "cells": len(members), "sample": _point(a.axes, r.cells[0].sample),
                            "within_limits": members[0].within_limits,
                            "signs": list(r.signs)})
    return {
        "schema_version": SCHEMA_VERSION,
        "singcheck_version": __version__,
        "space": a.space,
        "robot": a.robot,
        "counted": a.counted,
        "axes": list(a.axes),
        "slice": {k: str(v) for k, v in a.fixed.items()},
        "discriminant_variety": [{"kind": c.kind, "label": c.label, "polynomial":
                                  str(c.polynomial), "degree": int(c.polynomial.total_degree())}
                                 for c in a.components],
        "surfaces_left_out": left_out,
        "counts": summary(a),
        "regions": regions,
        "components_proven": None if a.regions is None else a.regions.components_proven,
        "components_reason": None if a.regions is None else (a.regions.reason or None),
        "cells": cells,
        "timings_s": {k.removesuffix("_s"): round(v, 4) for k, v in a.timings.items()},
        "exit_code": exit_code,
    }


def summary(a: SpaceAnalysis) -> dict[str, dict[str, int]]:
    """For each count met inside the space studied: how many cells (and regions)."""
    inside = [c for c in a.cells if c.within_limits]
    cells = Counter(c.count for c in inside)
    regions = Counter(a.region_count(n) for n in {c.region for c in inside}) \
        if a.regions is not None else Counter()
    out = {}
    for count in sorted(cells, key=lambda k: (k is None, k)):
        entry = {"cells": cells[count]}
        if a.regions is not None:
            entry["regions"] = regions[count]
        out["unknown" if count is None else str(count)] = entry
    return out


def render(console, doc: dict[str, Any], verbose: bool = False) -> None:
    from rich.table import Table

    where = ", ".join(doc["axes"])
    if doc["slice"]:
        where += " at " + ", ".join(f"{k} = {v}" for k, v in doc["slice"].items())
    console.print(f"[bold]{doc['robot']} · {doc['space']} ({where})[/bold]: "
                  f"number of {doc['counted']}")
    variety = Table(title="discriminant variety", title_justify="left")
    for col in ("kind", "surface", "degree"):
        variety.add_column(col, justify="right" if col == "degree" else "left")
    for c in doc["discriminant_variety"]:
        variety.add_row(c["kind"], c["label"], str(c["degree"]))
    console.print(variety)
    for label in doc["surfaces_left_out"]:
        console.print(f"  left out of this decomposition (the count does not change across "
                      f"it; --surfaces all or --slice keeps it): {label}")
    outside = "outside the workspace" if doc["space"] == WORKSPACE else \
        "outside the joint limits"
    if doc["regions"] is not None:
        _regions_table(console, doc, outside, verbose)
    counts = ", ".join(f"{k} ({v['cells']} cells" + (f", {v['regions']} regions" if
                                                      "regions" in v else "") + ")"
                       for k, v in doc["counts"].items())
    console.print(f"counts met{' inside the joint limits' if doc['space'] == JOINTSPACE else ''}"
                  f": {counts}")
    if doc["components_proven"] is not None:
        proven = "yes" if doc["components_proven"] else f"no: {doc['components_reason']}"
        console.print(f"regions are exactly the connected components: {proven}")


def _hidden(doc, r) -> bool:
    return (doc["space"] == WORKSPACE and r["count"] == 0) or not r["within_limits"]


def _regions_table(console, doc, outside: str, verbose: bool) -> None:
    from rich.table import Table

    table = Table(title="regions", title_justify="left")
    for col in ("region", "solutions", "cells", *[f"sample {a}" for a in doc["axes"]]):
        table.add_column(col, justify="right")
    hidden = 0
    for r in doc["regions"]:
        if _hidden(doc, r) and not verbose:
            hidden += 1
            continue
        count = "unknown" if r["count"] is None else str(r["count"])
        table.add_row(f"R{r['number']}", count, str(r["cells"]),
                      *[r["sample"][a] for a in doc["axes"]])
    console.print(table)
    if hidden:
        console.print(f"  {hidden} region(s) {outside} not listed (-v lists them)")
