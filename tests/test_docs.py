"""The front door (issue #30): a README a newcomer reads, the documentation site built
strictly, and a tutorial whose pasted outputs are what the commands print today."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys

import pytest

from tests.conftest import ROOT

DOCS = ROOT / "docs"
README = (ROOT / "README.md").read_text()
TUTORIAL = (DOCS / "tutorial.md").read_text()


def test_the_readme_is_short_and_starts_with_the_two_set_up_commands():
    lines = README.splitlines()
    assert len(lines) <= 250
    head = "\n".join(lines[:40])
    assert "apt-get install -y make && make demo" in head
    assert "apt-get install -y make && make test" in head


def test_every_link_of_the_readme_exists_and_every_figure_is_linked():
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README)
    local = [t for t in targets if "://" not in t]
    assert local
    for target in local:
        assert (ROOT / target).exists(), target
    figures = {f"docs/{p.name}" for p in DOCS.glob("*.png") if not p.name.startswith("tutorial-")}
    assert figures <= set(local), sorted(figures - set(local))


def test_the_readme_table_names_every_bundled_robot():
    robots = sorted(p.stem for p in (ROOT / "robots").glob("*.yaml"))
    assert len(robots) + len(list((ROOT / "robots").glob("*.py"))) == 11
    for name in robots:
        assert f"| `{name}`" in README, name
    for path in (ROOT / "trajectories").glob("*.yaml"):
        assert f"`{path.stem}`" in README, path.stem


def test_every_page_is_in_the_site_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    pages = sorted(p.name for p in DOCS.glob("*.md"))
    assert len(pages) >= 12
    for page in pages:
        assert re.search(rf": {re.escape(page)}\n", nav), page


def test_the_site_builds_strictly(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("material")
    out = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                          str(tmp_path / "site")], cwd=ROOT, capture_output=True, text=True,
                         env={**os.environ, "NO_MKDOCS_2_WARNING": "1"}, timeout=300)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "site" / "tutorial" / "index.html").exists()
    assert (tmp_path / "site" / "tutorial-3-rrr-line-postures.png").exists()


def test_make_docs_is_strict_and_in_ci():
    makefile = (ROOT / "Makefile").read_text()
    assert "\ndocs: setup\n" in makefile and "mkdocs build --strict" in makefile
    ci = (ROOT / ".ci" / "run").read_text()
    for target in ("make test", "make lint", "make docs", "make demo"):
        assert target in ci


# --- the tutorial, re-run ---------------------------------------------------------------

def _console_blocks(text: str) -> list[tuple[str, list[str]]]:
    blocks = re.findall(r"```console\n\$ (.*?)\n(.*?)```", text, re.S)
    return [(command, body.splitlines()) for command, body in blocks]


def _noise(line: str) -> bool:
    """Lines that depend on the machine: which backend `auto` found."""
    return line.startswith("singcheck: backend:") or line.startswith("singcheck: projecting")


@pytest.fixture(scope="module")
def tutorial_dir(tmp_path_factory):
    """The repository's tutorial files, and the first version of the spec (without the
    joint limits) as the reader writes it in step 2."""
    where = tmp_path_factory.mktemp("tutorial")
    shutil.copytree(DOCS / "tutorial", where / "docs" / "tutorial")
    spec = (DOCS / "tutorial" / "3-rrr.yaml").read_text()
    (where / "my-3-rrr.yaml").write_text("".join(
        line for line in spec.splitlines(keepends=True) if not line.startswith("joint_limits")))
    shutil.copy(DOCS / "tutorial" / "line.yaml", where / "line.yaml")
    return where


def test_the_tutorial_shows_what_the_commands_print(tutorial_dir):
    blocks = _console_blocks(TUTORIAL)
    runs = [(c, body) for c, body in blocks if c.startswith("singcheck run") and
            "..." not in body]
    assert len(runs) == 3
    for command, body in runs:
        args = command.split()[1:]
        out = subprocess.run([sys.executable, "-m", "singcheck", *args], cwd=tutorial_dir,
                             capture_output=True, text=True, timeout=600,
                             env={**os.environ, "PYTHONPATH": str(ROOT),
                                  "SINGCHECK_CACHE_DIR": str(tutorial_dir / "cache")})
        assert out.returncode == (0 if "fixed" in command else 1), out.stderr
        shown = [line for line in body if not line.startswith("singcheck:")]
        assert [line.rstrip() for line in out.stdout.rstrip("\n").splitlines()] == shown, \
            command
        notes = [line for line in body if line.startswith("singcheck:") and not _noise(line)]
        assert [line for line in out.stderr.splitlines() if not _noise(line)] == notes


def test_the_tutorial_verbose_lines_and_figures_are_real(tutorial_dir):
    env = {**os.environ, "PYTHONPATH": str(ROOT),
           "SINGCHECK_CACHE_DIR": str(tutorial_dir / "cache")}
    blocks = dict(_console_blocks(TUTORIAL))
    verbose = next(c for c in blocks if c.endswith(" -v"))
    out = subprocess.run([sys.executable, "-m", "singcheck", *verbose.split()[1:]],
                         cwd=tutorial_dir, capture_output=True, text=True, env=env,
                         timeout=600)
    printed = out.stdout.splitlines()
    for line in blocks[verbose]:
        if line != "...":
            assert line in printed, line
    pytest.importorskip("matplotlib")
    plot = next(c for c in blocks if c.startswith("singcheck plot"))
    out = subprocess.run([sys.executable, "-m", "singcheck", *plot.split()[1:]],
                         cwd=tutorial_dir, capture_output=True, text=True, env=env,
                         timeout=600)
    assert out.returncode == 0, out.stderr
    listed = [line for line in blocks[plot] if line.startswith("figures/")]
    assert out.stdout.splitlines() == listed
    for name in listed:
        assert (tutorial_dir / name).stat().st_size > 0


def test_the_readme_first_run_is_what_singcheck_prints(tmp_path):
    command, body = _console_blocks(README)[0]
    assert command == "singcheck run robots/orthoglide.yaml trajectories/heart1.yaml"
    out = subprocess.run([sys.executable, "-m", "singcheck", *command.split()[1:]], cwd=ROOT,
                         capture_output=True, text=True, timeout=600,
                         env={**os.environ, "PYTHONPATH": str(ROOT),
                              "SINGCHECK_CACHE_DIR": str(tmp_path)})
    assert out.returncode == 1, out.stderr
    printed = [line.rstrip() for line in out.stdout.rstrip("\n").splitlines()]
    shown = [line for line in body if not line.startswith("…")]
    assert len(shown) == 12
    for line in shown:
        assert line in printed, line
    assert printed[:10] == shown[:10] and printed[-2:] == shown[-2:]
