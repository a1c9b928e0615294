"""The paper's joint-space parametrisations (Eqs. Projection1-3), reproduced exactly."""

from __future__ import annotations

from fractions import Fraction

import pytest

from singcheck.algebra.trig import TRIG, C, S, T, reduce_trig
from singcheck.certify.path import build_path
from singcheck.report.formulas import joint_formula, latex
from singcheck.spec.files import load_trajectory
from singcheck.spec.grammar import compile_polynomial, parse
from tests.conftest import TRAJECTORIES
from tests.test_cli import ORTHO, singcheck

# paper: (centre, 1/k, radicand) per joint, in its own (unreduced) s, c notation
PAPER = {
    "heart1": [
        ("8/7*s^3", Fraction(1, 35), "1996*s^6 - 400*s^8 + 560*s^6*c - 100*s^4*c - 2009*s^4 "
                                     "+ 2190*c^3 - 1379*c^2 - 1320*c + 3988"),
        ("-4/7*c^4 - 2/5*c^3 - 1/7*c^2 + 43/35*c + 2/7", Fraction(1, 7),
         "64*c^6 - 192*c^4 + 192*c^2 + 83"),
        ("1", Fraction(1, 35), "3200 - 400*c^8 - 560*c^7 + 1204*c^6 + 1580*c^5 - 3221*c^4 "
                               "+ 710*c^3 + 3051*c^2 - 860*c"),
    ],
    "heart2": [
        ("4/5*s^3", Fraction(1, 10), "76*s^6 - 16*s^8 + 16*s^6*c + 12*s^4*c - 85*s^4 + 96*c^3 "
                                     "- 66*c^2 - 60*c + 321"),
        ("-2/5*c^4 - 1/5*c^3 - 1/10*c^2 + 4/5*c + 1/5", Fraction(1, 5),
         "16*c^6 - 48*c^4 + 48*c^2 + 59"),
        # the paper prints "-16*c(t)^7" with a stray extra exponent; this is the intended one
        ("1", Fraction(1, 10), "332 - 16*c^8 - 16*c^7 + 52*c^6 + 60*c^5 - 145*c^4 + 24*c^3 "
                               "+ 132*c^2 - 32*c"),
    ],
    "helix": [
        ("s", Fraction(1, 20), "400*s^2 - t^2 + 1200"),
        ("c", Fraction(1, 20), "400*c^2 - t^2 + 1200"),
        ("1/20*t", Fraction(1), "3"),
    ],
}


def trig(text: str):
    return reduce_trig(compile_polynomial(parse(text), TRIG, {"t": T, "s": S, "c": C}, {}))


@pytest.mark.parametrize("name", sorted(PAPER))
def test_joint_parametrisations_are_the_papers(orthoglide_projection, name):
    spec = load_trajectory(TRAJECTORIES / f"{name}.yaml", orthoglide_projection.model.spec)
    path = build_path(orthoglide_projection, spec)
    for i, (centre, scale, radicand) in enumerate(PAPER[name]):
        f = joint_formula(path, i)
        assert f.centre == trig(centre)
        assert f.scale == scale
        # the paper's radicand equals ours modulo s² + c² = 1 (we reduce to degree 1 in s)
        assert f.radicand == trig(radicand)


def test_latex_uses_bold_s_and_c_and_fractions():
    assert latex(trig("8/7*s^3")) == "-\\frac{8}{7}\\mathbf{s}\\mathbf{c}^{2} + " \
        "\\frac{8}{7}\\mathbf{s}"


def test_project_command_prints_the_formulas():
    out = singcheck("project", ORTHO, str(TRAJECTORIES / "heart1.yaml"), "--backend", "flint")
    assert out.returncode == 0, out.stderr
    assert "det A = -8*rho1*rho2*rho3 + 8*rho1*rho2*z + 8*rho1*rho3*y + 8*rho2*rho3*x" \
        in out.stdout
    assert "rho2 = -4/7*c^4 - 2/5*c^3 - 1/7*c^2 + 43/35*c + 2/7 ± 1/7*sqrt(64*c^6 - " \
        "192*c^4 + 192*c^2 + 83)" in out.stdout
    tex = singcheck("project", ORTHO, "--latex", "--backend", "flint")
    assert tex.returncode == 0 and "\\begin{align*}" in tex.stdout and "\\rho_{1}" in tex.stdout
    js = singcheck("project", ORTHO, "--format", "json", "--backend", "flint")
    import json

    doc = json.loads(js.stdout)
    assert doc["singularity_surface_degree"] == 16
    assert doc["joint_space_singularities"].startswith("rho1^4*rho2^2")
    bad = singcheck("project", ORTHO, "missing.yaml")
    assert bad.returncode == 2 and "cannot read the file" in bad.stderr


def test_project_text_and_json_give_the_same_factors_of_xi():
    """The 5-bar (flint): text and JSON list the same irreducible factors of ξ as
    computed, with the same used/dropped marks; the dropped ones are the degenerate set
    W = 0 of the legs, (x ± d)² + y² (W = 4·l1²·|P - A_i|², from the constraints), and
    the product of the used ones is the ξ both print (SymPy, up to a constant)."""
    import json
    import re

    import sympy

    from tests.conftest import ROBOTS

    robot = str(ROBOTS / "five-bar.yaml")
    text = singcheck("project", robot, "--backend", "flint", "--no-epsilon")
    js = singcheck("project", robot, "--backend", "flint", "--no-epsilon", "--format", "json")
    assert text.returncode == 0 and js.returncode == 0, text.stderr + js.stderr
    doc = json.loads(js.stdout)
    x, y = sympy.symbols("x y")

    def poly(s: str) -> sympy.Poly:
        return sympy.Poly(sympy.sympify(s.replace("^", "**"), locals={"x": x, "y": y}), x, y)

    listed = [(int(m.group(1)), m.group(2) is None, m.group(3)) for m in re.finditer(
        r"^xi factor (\d+) \(degree \d+(, dropped)?\) = (.*)$", text.stdout, re.M)]
    factors = doc["singularity_surface_factors"]
    assert [(i, used, poly(f)) for i, used, f in listed] == \
        [(i, g["used"], poly(g["factor"])) for i, g in enumerate(factors, 1)]
    dropped = {poly(g["factor"]).monic() for g in factors if not g["used"]}
    assert dropped == {poly("(x + 1)^2 + y^2").monic(), poly("(x - 1)^2 + y^2").monic()}
    product = sympy.prod(poly(g["factor"]) for g in factors if g["used"])
    xi = poly(doc["singularity_surface"])
    assert product.monic() == xi.monic()
    (xi_line,) = [s for s in text.stdout.splitlines() if s.startswith("xi(X) = ")]
    assert poly(xi_line[len("xi(X) = "):]) == xi
    used = ", ".join(str(i) for i, u, _ in listed if u)
    assert f"xi(X) is the squarefree product of factors {used} (degree 10)" in text.stdout
