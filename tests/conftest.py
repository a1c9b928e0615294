"""Shared fixtures: the bundled robots and trajectories, parsed once per session."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ROBOTS = ROOT / "robots"
TRAJECTORIES = ROOT / "trajectories"

# The region statement's own budget (2 s beside the verdict) is for users; the tests
# check what it says, on a machine that may be loaded, so they give it a minute (the
# test of the budget itself sets its own).  Subprocesses inherit it.
os.environ.setdefault("SINGCHECK_REGION_BUDGET", "60")


@pytest.fixture(scope="session")
def orthoglide():
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    return build_model(load_robot(ROBOTS / "orthoglide.yaml"))


@pytest.fixture(scope="session")
def orthoglide_projection(orthoglide):
    from singcheck.elimination.cas import get_backend
    from singcheck.elimination.projection import project_robot

    return project_robot(orthoglide, get_backend("sympy"))


@pytest.fixture(scope="session")
def certify(orthoglide_projection):
    """certify(name) -> TrajectoryReport for a bundled Orthoglide trajectory (cached)."""
    from singcheck.certify.classification import certify_path
    from singcheck.certify.path import build_path
    from singcheck.spec.files import load_trajectory

    cache = {}

    def run(name: str):
        if name not in cache:
            spec = load_trajectory(TRAJECTORIES / f"{name}.yaml", orthoglide_projection.model.spec)
            cache[name] = certify_path(build_path(orthoglide_projection, spec))
        return cache[name]

    return run
