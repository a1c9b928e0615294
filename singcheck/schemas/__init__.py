"""JSON Schemas (Draft 2020-12) of singcheck's files: robot specs, trajectory documents,
and the JSON report (``singcheck schema robot|trajectory|report`` prints them).

Editors complete and check a spec that names its schema in a modeline, e.g. as the first
line of a robot file::

    # yaml-language-server: $schema=../singcheck/schemas/robot.schema.json
"""

from __future__ import annotations

from importlib.resources import files

NAMES = ("robot", "trajectory", "report", "certificate")


def schema_text(name: str) -> str:
    """The schema ``name`` (robot, trajectory, report or certificate) as JSON text."""
    if name not in NAMES:
        raise ValueError(f"no schema {name!r} (one of {', '.join(NAMES)})")
    return (files(__package__) / f"{name}.schema.json").read_text(encoding="utf-8")


def schema(name: str) -> dict:
    """The schema ``name`` as a dict."""
    import json

    return json.loads(schema_text(name))
