"""ξ(X) too big to expand: μ(t) eliminated along each path instead (issue 12, 6-DOF).

The path-wise elimination is forced on small robots (``max_surface_terms=0``) so that its
answers can be checked against the paper's figures and against ξ(φ(t)) itself."""

from __future__ import annotations

import math

import pytest

from singcheck import api
from singcheck.algebra.polynomials import squarefree_part
from singcheck.certify.path import compose_pose, eliminate_along_path
from tests.conftest import ROBOTS, TRAJECTORIES


@pytest.fixture(scope="module")
def pathwise_orthoglide():
    return api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False,
                          max_surface_terms=0)


def test_the_projection_says_why_xi_was_not_expanded(pathwise_orthoglide):
    projection = pathwise_orthoglide.projection
    assert not projection.expanded and projection.singularity_surface is None
    assert "could reach degree 24" in projection.not_expanded  # 3·2·2·2 (Bézout bound)
    from singcheck.report.formulas import render

    text = render(projection, None, None, "text")
    assert "ξ(X) was not expanded" in text and "xi(X) not expanded" in text


def test_pathwise_heart1_gives_the_papers_singular_times(pathwise_orthoglide):
    traj = api.load_trajectory(TRAJECTORIES / "heart1.yaml", pathwise_orthoglide)
    report = api.check(pathwise_orthoglide, traj, regions=False)
    # the paper, Eq. (sol): t = [-1.51, -0.97, 0.97, 1.51], two decimals (truncated)
    ts = [math.copysign(math.floor(abs(float(c.t.mid())) * 100) / 100, float(c.t.mid()))
          for c in report.candidates]
    assert ts == pytest.approx([-1.51, -0.97, 0.97, 1.51], abs=1e-9)
    assert [c.status for c in report.candidates] == ["spurious", "spurious", "real", "real"]
    assert report.verdict == "singular"


@pytest.mark.parametrize("robot, name", [("orthoglide", "helix"), ("orthoglide", "heart2"),
                                         ("skew-biglide", "skew-biglide-ellipse"),
                                         ("stacked-orthoglide", "stacked-heart")])
def test_pathwise_mu_has_the_zeros_of_xi_along_the_path(robot, name):
    """Substituting first commutes with the resultants (constant leading coefficients):
    the squarefree parts agree exactly, as polynomials in t, sin t, cos t."""
    machine = api.load_robot(ROBOTS / f"{robot}.yaml", backend="flint", cache=False)
    traj = api.load_trajectory(TRAJECTORIES / f"{name}.yaml", machine)
    phi = tuple(traj.pose[v] for v in machine.model.pose)
    mu = eliminate_along_path(machine.model, phi)
    expected = compose_pose(machine.singularity_surface, phi, machine.model.pose)
    assert squarefree_part(_half_angle(mu)) == squarefree_part(_half_angle(expected))


def _half_angle(p):
    """p(t, sin t, cos t) with s = 2u/(1 + u²), c = (1 - u²)/(1 + u²), times (1 + u²)^D:
    a polynomial in (t, u) whose zeros are p's (t ≠ π mod 2π), so two trig polynomials
    with the same zeros have the same squarefree part (an independent check: not the
    reduction modulo s² + c² - 1 that singcheck uses)."""
    from flint import fmpq_mpoly_ctx

    ring = fmpq_mpoly_ctx.get(("t", "u"), "lex")
    t, u = ring.gens()
    top = max(j + k for (_, j, k), _ in p.terms())
    out = ring.from_dict({})
    for (i, j, k), coeff in p.terms():
        out += coeff * t**i * (2 * u) ** j * (1 - u * u) ** k * (1 + u * u) ** (top - j - k)
    return out


def test_the_rotary_delta_is_certified_along_each_path_and_project_says_so():
    """Three revolute legs and √3: the bound on ξ's size is over the limit, so ``project``
    says ξ was not expanded, and ``run`` still certifies (the answers themselves are
    checked against the oracle in tests/test_robots.py)."""
    from tests.test_cli import singcheck

    out = singcheck("project", str(ROBOTS / "rotary-delta.yaml"), "--no-epsilon")
    assert out.returncode == 0, out.stderr
    assert "ξ(X) was not expanded" in out.stdout and "could reach degree" in out.stdout
    out = singcheck("run", str(ROBOTS / "rotary-delta.yaml"),
                    str(TRAJECTORIES / "rotary-delta-cross.yaml"), "--no-cache", "--format",
                    "json", "--backend", "flint")
    assert out.returncode == 1, out.stderr
    import json

    doc = json.loads(out.stdout)
    assert doc["singularity_surface_degree"] is None
    assert doc["trajectories"][0]["verdict"] == "singular"
