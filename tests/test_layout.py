"""The package's house rules, checked on its source: stages import downwards only, no
import cycles, and click / rich / matplotlib stay in their own packages."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "singcheck"

# the pipeline, bottom to top; a module may import its own stage and those below it
# (verify, the certificate checker, is the floor under all: it imports nothing of singcheck)
STAGES = ["verify", "algebra", "spec", "model", "elimination", "roots", "certify", "spaces",
          "report", "api", "cli"]
FOUNDATION = {"errors", "budget", "atomic", "version",  # importable by every stage
              "collector",  # the garbage collector's tuning (imports only gc)
              "schemas"}  # data files (the JSON Schemas) and a reader
ONLY_IN = {"click": {"cli"}, "rich": {"report"}, "matplotlib": {"report"}}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every module ``path`` imports (function-level imports included), absolute."""
    module = _module_name(path)
    here = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = here[: len(here) - node.level + 1] if node.level else []
            name = ".".join(base + ([node.module] if node.module else []))
            out.add(name)
            out |= {f"{name}.{a.name}" for a in node.names}  # `from pkg import module`
    return out


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    return {m: {i for i in _imports(p) if i in files} - {m} for m, p in files.items()}


API_LEVEL = {"api", "cluster"}  # modules at the api stage (cluster: the API on Dask)


def _stage(module: str) -> str:
    """The stage a module belongs to; the package itself re-exports the API."""
    parts = module.split(".")
    stage = parts[1] if len(parts) > 1 else "api"
    return "api" if stage in API_LEVEL else stage


def upward_imports(graph: dict[str, set[str]]) -> list[str]:
    """Imports from a stage into a higher one (the foundation is below every stage)."""
    upward = []
    for module, deps in graph.items():
        stage = _stage(module)
        if stage not in STAGES:
            continue
        for dep in deps:
            target = _stage(dep)
            if target in FOUNDATION or target == stage:
                continue
            if target not in STAGES or STAGES.index(target) > STAGES.index(stage):
                upward.append(f"{module} imports {dep}")
    return upward


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every cycle a depth-first walk meets (one per back edge)."""
    state: dict[str, int] = {}
    cycles = []

    def visit(node, trail):
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycles.append(trail[trail.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    return cycles


def test_stages_import_downwards_only():
    assert not upward_imports(_graph())


def test_foundation_modules_import_no_stage():
    graph = _graph()
    for name in FOUNDATION:
        deps = {_stage(d) for d in graph[f"singcheck.{name}"]}
        assert deps <= FOUNDATION, (name, deps)


def test_no_import_cycles():
    assert not import_cycles(_graph())


def test_the_checks_catch_what_they_forbid():
    """On a made-up package: an upward import and a cycle are both reported."""
    graph = {"singcheck.model.robot": {"singcheck.cli.commands", "singcheck.errors"},
             "singcheck.cli.commands": {"singcheck.model.robot"},
             "singcheck.errors": set()}
    assert upward_imports(graph) == ["singcheck.model.robot imports singcheck.cli.commands"]
    assert import_cycles(graph) == [["singcheck.cli.commands", "singcheck.model.robot",
                                     "singcheck.cli.commands"]]


def test_heavy_libraries_stay_in_their_package():
    for path in PACKAGE.rglob("*.py"):
        module = _module_name(path)
        for imported in _imports(path):
            top = imported.split(".")[0]
            if top in ONLY_IN:
                assert _stage(module) in ONLY_IN[top], f"{module} imports {top}"


def test_every_stage_package_says_what_it_owns():
    for stage in STAGES:
        init = PACKAGE / stage / "__init__.py"
        if stage == "api":
            init = PACKAGE / "api.py"
        doc = ast.get_docstring(ast.parse(init.read_text()))
        assert doc and len(doc.splitlines()) >= 2, stage


def test_readme_architecture_names_every_module():
    """The architecture page's table lists each stage package with every module it
    holds."""
    page = (PACKAGE.parent / "docs" / "architecture.md").read_text()
    section = page[page.index("# Architecture"):]
    section = section[:section.index("\n## ")]
    rows = {line.split("|")[1].strip(" `/"): line for line in section.splitlines()
            if line.startswith("| `")}
    for stage in STAGES:
        if stage == "api":
            continue
        folder = PACKAGE / stage
        modules = {p.stem for p in folder.glob("*.py") if p.stem != "__init__"}
        modules |= {p.name for p in folder.iterdir() if (p / "__init__.py").exists()}
        assert stage in rows, f"{stage}/ is missing from docs/architecture.md's table"
        missing = [m for m in modules if f"`{m}" not in rows[stage]]
        assert not missing, f"docs/architecture.md: {stage}/ does not name {missing}"
    assert set(rows) - {"api.py"} == set(STAGES) - {"api"}, "the table names a stage " \
        "that is not in the tree"
