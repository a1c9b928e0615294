"""The JSON Schemas (Draft 2020-12) of robot specs, trajectory documents and the JSON
report: every bundled spec and every output format validates against them, an unknown
key fails the spec schemas as it fails the parser, and the bundled specs' modelines
point at the schema files (the parser reads them as the comments they are)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml

from tests.conftest import ROBOTS, ROOT, TRAJECTORIES
from tests.test_cli import singcheck

jsonschema = pytest.importorskip("jsonschema")

SCHEMAS = ROOT / "singcheck" / "schemas"
BUNDLED = [*sorted(ROBOTS.glob("*.yaml")), *sorted(TRAJECTORIES.glob("*.yaml")),
           *sorted((ROOT / "tests" / "data").glob("*/*.yaml")),
           *sorted((ROOT / "docs" / "tutorial").glob("*.yaml"))]
ROBOT_FILES = [p for p in BUNDLED if re.search(r"^joints:", p.read_text(), re.M)]
TRAJECTORY_FILES = [p for p in BUNDLED if p not in ROBOT_FILES]
MODELINE = re.compile(r"# yaml-language-server: \$schema=(\S+)\n")


def validator(name: str, definition: str | None = None):
    schema = json.loads((SCHEMAS / f"{name}.schema.json").read_text())
    if definition:
        schema = {"$schema": schema["$schema"], "$defs": schema["$defs"],
                  "$ref": f"#/$defs/{definition}"}
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def errors(v, instance) -> list[str]:
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
            for e in v.iter_errors(instance)]


@pytest.mark.parametrize("name", ["robot", "trajectory", "report", "certificate"])
def test_the_schema_command_prints_the_schema_file(name):
    out = singcheck("schema", name)
    assert out.returncode == 0, out.stderr
    assert out.stdout == (SCHEMAS / f"{name}.schema.json").read_text()
    schema = json.loads(out.stdout)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


def test_the_schema_command_refuses_another_name():
    out = singcheck("schema", "robots")
    assert out.returncode == 2 and "'robots' is not one of" in out.stderr


def test_the_schemas_ship_as_package_data():
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    setuptools = project["tool"]["setuptools"]
    assert "singcheck.schemas" in setuptools["packages"]
    assert setuptools["package-data"]["singcheck.schemas"] == ["*.schema.json"]
    from singcheck.schemas import NAMES, schema

    assert [schema(n)["title"] for n in NAMES] == [
        "singcheck robot spec", "singcheck trajectory spec",
        "singcheck JSON report (schema_version 1)", "singcheck certificate (version 1)"]


@pytest.mark.parametrize("path", ROBOT_FILES, ids=lambda p: p.name)
def test_every_bundled_robot_validates(path):
    assert errors(validator("robot"), yaml.safe_load(path.read_text())) == []


@pytest.mark.parametrize("path", TRAJECTORY_FILES, ids=lambda p: p.name)
def test_every_bundled_trajectory_document_validates(path):
    documents = [d for d in yaml.safe_load_all(path.read_text()) if d is not None]
    assert documents
    for document in documents:
        assert errors(validator("trajectory"), document) == []


@pytest.mark.parametrize("path, kind", [(p, "robot") for p in ROBOT_FILES] +
                         [(p, "trajectory") for p in TRAJECTORY_FILES
                          if p.parent.name != "crashes"],  # fuzz finds, kept as found
                         ids=lambda x: str(x))
def test_every_bundled_spec_names_its_schema_in_a_modeline(path, kind):
    first = path.read_text().splitlines(keepends=True)[0]
    match = MODELINE.fullmatch(first)
    assert match, f"{path}: the first line is not a yaml-language-server modeline"
    target = (path.parent / match.group(1)).resolve()
    assert target == (SCHEMAS / f"{kind}.schema.json").resolve()


def test_the_parser_reads_the_modeline_as_a_comment():
    from singcheck.spec.files import load_robot, load_trajectories

    for path in ROBOT_FILES:
        assert load_robot(path).name
    robot = load_robot(ROBOTS / "orthoglide.yaml")
    assert [t.name for t in load_trajectories([TRAJECTORIES / "heart1.yaml"], robot)] == [
        "heart1"]


@pytest.mark.parametrize("kind, good, bad, key", [
    ("robot", ROBOTS / "orthoglide.yaml", "joint_limit: {rho1: [0, 4]}\n", "joint_limit"),
    ("trajectory", TRAJECTORIES / "heart1.yaml", "ranges: [0, 1]\n", "ranges"),
])
def test_an_unknown_key_fails_the_schema_and_the_parser(tmp_path, kind, good, bad, key):
    text = good.read_text() + bad
    v = validator(kind)
    found = errors(v, yaml.safe_load(text))
    assert found and any(f"'{key}' was unexpected" in e for e in found), found
    # the parser refuses it too, naming the key and its line
    path = tmp_path / f"bad-{kind}.yaml"
    path.write_text(text)
    args = ["run", str(path), str(TRAJECTORIES / "heart1.yaml")] if kind == "robot" else \
        ["run", str(ROBOTS / "orthoglide.yaml"), str(path)]
    out = singcheck(*args)
    assert out.returncode == 2
    assert f"{key}: unknown key" in out.stderr and f"{path.name}:{text.count(chr(10))}:" \
        in out.stderr


@pytest.mark.parametrize("document, where", [
    ({"name": "p", "parameter": "t", "range": [0, 1], "pose": {"x": "t"},
      "segments": [{"range": [0, 1], "pose": {"x": "t"}}]}, "range and segments"),
    ({"name": "p", "parameter": "t"}, "neither pose nor pieces"),
    ({"name": "p", "parameter": "pi", "range": [0, 1], "pose": {"x": "t"}}, "reserved name"),
    ({"name": "p", "parameter": "t", "waypoints": [{"t": 0, "x": 1}, {"t": 1, "x": 2}],
      "interpolation": "quadratic"}, "interpolation"),
])
def test_the_trajectory_schema_refuses_what_the_parser_refuses(document, where):
    assert errors(validator("trajectory"), document), where


# --- outputs ---------------------------------------------------------------------------

def _run(*args: str) -> str:
    out = singcheck("run", *args, "--backend", "flint", "-q")
    assert out.returncode in (0, 1, 3), out.stderr
    return out.stdout


def test_the_json_report_validates_with_regions_pieces_and_angles(tmp_path):
    report = validator("report")
    pieces = tmp_path / "pick-and-place.yaml"
    pieces.write_text("name: pick-and-place\nparameter: t\nsegments:\n"
                      "  - range: [0, 1]\n    pose: {x: 1/4 + 13/20*t, y: 3/5 + 1/2*t, z: 1}\n"
                      "  - range: [1, 2]\n    pose: {x: 3/5 + 3/10*t, y: 19/10 - 4/5*t, z: 1}\n")
    heart = json.loads(_run(str(ROBOTS / "orthoglide.yaml"),
                            str(TRAJECTORIES / "heart1.yaml"), str(TRAJECTORIES / "helix.yaml"),
                            str(pieces), "--format", "json"))
    assert len(heart["trajectories"][2]["segments"]) == 2
    assert errors(report, heart) == []
    assert {"workspace", "segments"} <= set(heart["trajectories"][0])
    angles = json.loads(_run(str(ROBOTS / "five-bar.yaml"),
                             str(TRAJECTORIES / "five-bar-cross.yaml"), "--format", "json",
                             "--no-regions"))
    assert errors(report, angles) == []


def test_jsonl_lines_validate_errors_and_time_limits_included(tmp_path):
    line = validator("report", "jsonl_line")
    bad = tmp_path / "bad.yaml"
    good = (TRAJECTORIES / "heart2.yaml").read_text()
    # 101 documents: the last one, past the first 100, is a spec error in its own line
    bad.write_text("".join(good.replace("name: heart2", f"name: h{i}") + "---\n"
                           for i in range(100)) + "name: broken\nparameter: t\n")
    out = singcheck("run", str(ROBOTS / "orthoglide.yaml"), str(bad), "--format", "jsonl",
                    "--no-regions", "--backend", "flint", "-q")
    assert out.returncode == 2, out.stderr
    docs = [json.loads(text) for text in out.stdout.splitlines()]
    assert len(docs) == 101
    for doc in docs:
        assert errors(line, doc) == []
    (broken,) = [d for d in docs if d["verdict"] == "error"]
    assert broken["error"]["kind"] == "spec" and broken["parameter"] is None
    slow = tmp_path / "slow.yaml"
    slow.write_text("name: slow\nparameter: t\nrange: [0, 1]\n"
                    "pose: {x: cos(12*t)/2, y: sin(11*t)/2, z: -2}\n")
    stopped = json.loads(_run(str(ROBOTS / "rotary-delta.yaml"), str(slow), "--format",
                              "jsonl", "--time-limit", "0.2"))
    assert stopped["verdict"] == "unknown" and stopped["root_isolation"] is None
    assert errors(line, stopped) == []


def test_the_report_schema_requires_the_core_fields_and_allows_new_ones():
    report = validator("report")
    doc = json.loads(_run(str(ROBOTS / "orthoglide.yaml"), str(TRAJECTORIES / "heart1.yaml"),
                          "--format", "json", "--no-regions"))
    trajectory = doc["trajectories"][0]
    trajectory["on_surface"] = False  # fields being added elsewhere are allowed
    trajectory["engine"] = "exact"
    trajectory["candidates"][0]["corroboration"] = {"interval": "agrees"}
    assert errors(report, doc) == []
    for key in ("verdict", "reason", "candidates", "working_modes"):
        broken = json.loads(json.dumps(doc))
        del broken["trajectories"][0][key]
        assert any(f"'{key}' is a required property" in e for e in errors(report, broken))
    broken = json.loads(json.dumps(doc))
    broken["trajectories"][0]["verdict"] = "probably fine"
    assert errors(report, broken)
    broken["trajectories"][0]["verdict"] = "error"  # an error must say which kind
    assert any("'error' is a required property" in e for e in errors(report, broken))


def test_the_docs_and_readme_name_the_schema_command():
    text = (ROOT / "README.md").read_text() + Path(ROOT / "docs" / "spec.md").read_text()
    assert "singcheck schema robot" in text and "yaml-language-server" in text
