"""The polynomial model and its projections, against the paper's formulas."""

from __future__ import annotations

import pytest
from flint import fmpq_mpoly_ctx

from singcheck.elimination.projection import joint_space_singularities
from singcheck.errors import UnsupportedRobotError
from singcheck.model.robot import build_model, determinant
from singcheck.spec.files import parse_robot

R = fmpq_mpoly_ctx.get(("rho1", "rho2", "rho3", "x", "y", "z"), "lex")
r1, r2, r3, x, y, z = R.gens()
P = fmpq_mpoly_ctx.get(("x", "y", "z"), "lex")
px, py, pz = P.gens()


def test_det_A_is_the_papers(orthoglide):
    # paper, Eq. (singlr): det A = -8ρ1ρ2ρ3 + 8ρ1ρ2 z + 8ρ1ρ3 y + 8ρ2ρ3 x
    paper = -8 * r1 * r2 * r3 + 8 * r1 * r2 * z + 8 * r1 * r3 * y + 8 * r2 * r3 * x
    assert orthoglide.det_A == paper


def test_det_B_is_the_product_of_the_legs(orthoglide):
    assert orthoglide.det_B == -8 * (x - r1) * (y - r2) * (z - r3)


def test_joint_space_singularities_are_the_papers_epsilon(orthoglide):
    from singcheck.elimination.cas import get_backend

    eps = joint_space_singularities(orthoglide, get_backend("sympy"))
    J = eps.context()
    a, b, c = J.gens()
    paper = (a**4 * b**2 + a**4 * c**2 + a**2 * b**4 + 2 * a**2 * b**2 * c**2 + a**2 * c**4
             + b**4 * c**2 + b**2 * c**4 - 16 * a**2 * b**2 - 16 * a**2 * c**2 - 16 * b**2 * c**2)
    assert eps == paper / paper.leading_coefficient()


def test_singularity_surface_factor_structure(orthoglide_projection):
    xi = orthoglide_projection.singularity_surface
    raw = orthoglide_projection.singularity_surface_as_computed
    _, factors = raw.factor()
    degrees = sorted((f.total_degree(), m) for f, m in factors)
    # norm of det A over the 8 modes: ξ14 · sphere^5 (README, "factor structure")
    assert degrees == [(2, 5), (14, 1)]
    sphere = px**2 + py**2 + pz**2 - 4
    assert any(f == sphere for f, _ in factors)
    # singcheck keeps the squarefree part: same zero set, simple factors, degree 16
    assert xi.total_degree() == 16
    assert sorted((f.total_degree(), m) for f, m in xi.factor()[1]) == [(2, 1), (14, 1)]


def test_joint_limit_surfaces_are_the_papers(orthoglide_projection):
    # paper, Eq. (cnstrnt): ρi = 0 -> x²+y²+z²-4 ; ρ1 = 4 -> x²+y²+z²-8x+12 …
    surfaces = {(s.joint, s.bound): s.polynomial for s in
                orthoglide_projection.joint_limit_surfaces}
    sphere = px**2 + py**2 + pz**2 - 4
    assert surfaces[("rho1", "min")] == sphere
    assert surfaces[("rho2", "min")] == sphere
    assert surfaces[("rho1", "max")] == px**2 + py**2 + pz**2 - 8 * px + 12
    assert surfaces[("rho2", "max")] == px**2 + py**2 + pz**2 - 8 * py + 12
    assert surfaces[("rho3", "max")] == px**2 + py**2 + pz**2 - 8 * pz + 12


def test_workspace_boundary_is_the_leg_discriminants(orthoglide_projection):
    d1, d2, d3 = orthoglide_projection.workspace_boundary
    assert d1 == -4 * (py**2 + pz**2 - 4)
    assert d3 == -4 * (px**2 + py**2 - 4)


def test_determinant_of_a_3x3_matches_sarrus():
    ctx = fmpq_mpoly_ctx.get(tuple("abcdefghi"), "lex")
    a, b, c, d, e, f, g, h, i = ctx.gens()
    m = ((a, b, c), (d, e, f), (g, h, i))
    assert determinant(m) == a * e * i + b * f * g + c * d * h - c * e * g - b * d * i - a * f * h


COUPLED = """\
name: coupled
joints: [p, q]
pose: [x, y]
constraints:
  - x - p - q
  - y - p*q
"""

CUBIC = """\
name: cubic
joints: [p, q]
pose: [x, y]
constraints:
  - p^3 - x
  - q - y
"""

NOT_MONIC = """\
name: notmonic
joints: [p, q]
pose: [x, y]
constraints:
  - x*p^2 - 1
  - q - y
"""


@pytest.mark.parametrize("text, line, phrase", [
    (COUPLED, 5, "exactly one actuated joint"),
    (CUBIC, 5, "degree 3 in p"),
    (NOT_MONIC, 5, "depends on the pose"),
])
def test_robots_outside_the_leg_decoupled_class_are_refused(text, line, phrase):
    with pytest.raises(UnsupportedRobotError) as err:
        build_model(parse_robot(text, "r.yaml"))
    message = str(err.value)
    assert message.startswith(f"r.yaml:{line}:")
    assert "constraints[0]" in message
    assert phrase in message


def test_a_wrong_singularity_surface_fails_the_recheck(orthoglide, orthoglide_projection):
    from singcheck.elimination.projection import recheck_singularity_surface
    from singcheck.errors import BackendError

    xi = orthoglide_projection.singularity_surface_as_computed
    recheck_singularity_surface(orthoglide, xi, "test")  # the right one passes
    for wrong in (xi * (px - 1), xi + 1, orthoglide_projection.workspace_boundary[0]):
        with pytest.raises(BackendError, match="fails the re-check"):
            recheck_singularity_surface(orthoglide, wrong, "test")


def test_the_flint_norm_keeps_factored_jacobians_small():
    from singcheck.elimination.projection import norm_over_legs
    from singcheck.spec.files import load_robot
    from tests.conftest import ROBOTS

    model = build_model(load_robot(ROBOTS / "stacked-orthoglide.yaml"))
    _, factors = model.det_A.factor()
    assert len(factors) >= 2  # block-triangular A: det A1 · det A2
    xi = norm_over_legs(model)
    # ξ1(X1) (degree 16, the Orthoglide's) times ξ2(X2 - X1) (degree 16)
    assert xi.total_degree() == 32
    assert sorted(f.total_degree() for f, _ in xi.factor()[1]) == [2, 2, 14, 14]


def test_reduce_relations_is_the_normal_form_modulo_circles_and_square_roots():
    """The representative (degree ≤ 1 in each sin and each square root) takes the same
    values as the polynomial wherever cos² + sin² = 1 and sqrt(q)² = q: checked at
    random points of that variety with 50-digit mpmath, independently of FLINT."""
    import random

    import mpmath
    from flint import fmpq, fmpq_mpoly_ctx

    from singcheck.algebra.radicals import reduce_relations

    mpmath.mp.dps = 50
    ring = fmpq_mpoly_ctx.get(("x", "cos(a)", "sqrt(3)", "sin(a)", "cos(b)", "sin(b)",
                               "sqrt(2)"), "lex")
    gens = ring.gens()
    rnd = random.Random(7)
    for _ in range(20):
        p = ring.from_dict({})
        for _ in range(12):
            term = ring.from_dict({(0,) * 7: fmpq(rnd.randint(-9, 9), rnd.randint(1, 5))})
            for g in gens:
                term *= g ** rnd.randint(0, 4)
            p += term
        r = reduce_relations(p)
        degrees = dict(zip(ring.names(), r.degrees(), strict=True))
        assert all(degrees[v] <= 1 for v in ("sin(a)", "sin(b)", "sqrt(3)", "sqrt(2)"))
        for _ in range(3):
            a, b, x = (mpmath.mpf(rnd.random()) * 7 for _ in range(3))
            point = [x, mpmath.cos(a), mpmath.sqrt(3), mpmath.sin(a), mpmath.cos(b),
                     mpmath.sin(b), mpmath.sqrt(2)]

            def value(q, point=point):
                total = mpmath.mpf(0)
                for exps, c in q.terms():
                    term = mpmath.mpf(int(c.p)) / int(c.q)
                    for v, e in zip(point, exps, strict=True):
                        term *= v ** int(e)
                    total += term
                return total

            assert abs(value(p) - value(r)) <= mpmath.mpf(10) ** -35 * (1 + abs(value(p)))
