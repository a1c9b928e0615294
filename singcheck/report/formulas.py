"""The paper's formulas, written out: det A, det B, ξ, ε, the limit surfaces and ρ(t).

Pure functions from the exact model to text (plain or LaTeX) and JSON-ready dicts.  The
joint-space parametrisation of a working mode is the paper's form
``ρ_i = P(t) ± (1/k)·√Q(t)`` with P rational and Q an integer polynomial in s = sin t,
c = cos t (and t): from the leg constraint ``a ρ² + b ρ + c = 0``,
``P = -b/(2a)`` and ``(b² - 4ac)/(4a²) = Q/k²`` with the smallest such integer k.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from flint import fmpq, fmpq_mpoly

from singcheck.certify.path import PathModel


@dataclass(frozen=True)
class JointFormula:
    joint: str
    centre: fmpq_mpoly  # P(t)
    scale: Fraction  # 1/k (0 for a linear leg)
    radicand: fmpq_mpoly | None  # Q(t), integer coefficients

    def text(self, sign: str = "±") -> str:
        if self.radicand is None:
            return f"{self.joint} = {self.centre}"
        k = "" if self.scale == 1 else f"{self.scale}*"
        return f"{self.joint} = {self.centre} {sign} {k}sqrt({self.radicand})"

    def latex(self) -> str:
        if self.radicand is None:
            return f"{_latex_name(self.joint)} = {latex(self.centre)}"
        k = "" if self.scale == 1 else _latex_fraction(self.scale)
        return (f"{_latex_name(self.joint)} = {latex(self.centre)} \\pm {k}"
                f"\\sqrt{{{latex(self.radicand)}}}")


def _square_part(n: int) -> tuple[int, int]:
    """(m, r) with n = m² r and r squarefree-ish (trial division; n small here)."""
    m, r, p = 1, n, 2
    while p * p <= r:
        while r % (p * p) == 0:
            r //= p * p
            m *= p
        p += 1 if p == 2 else 2
    return m, r


@dataclass(frozen=True)
class RevoluteFormula:
    """A revolute leg's branches ``cos θ = (-a·d ± b·√Δ)/W``, ``sin θ = (-b·d ∓ a·√Δ)/W``
    with ``a cos θ + b sin θ + d = 0`` along the path, ``W = a² + b²``, ``Δ = W - d²``."""

    joint: str
    a: fmpq_mpoly
    b: fmpq_mpoly
    d: fmpq_mpoly
    delta: fmpq_mpoly

    def text(self, sign: str = "±") -> str:
        j = self.joint
        return (f"cos({j}) = (-({self.a})*({self.d}) {sign} ({self.b})*sqrt({self.delta})) / W, "
                f"sin({j}) = (-({self.b})*({self.d}) ∓ ({self.a})*sqrt({self.delta})) / W, "
                f"W = ({self.a})^2 + ({self.b})^2")

    def latex(self) -> str:
        j = _latex_name(self.joint)
        a, b, d, r = (latex(p) for p in (self.a, self.b, self.d, self.delta))
        w = f"({a})^2 + ({b})^2"
        return (f"\\cos {j} = \\frac{{-({a})({d}) \\pm ({b})\\sqrt{{{r}}}}}{{{w}}},\\ "
                f"\\sin {j} = \\frac{{-({b})({d}) \\mp ({a})\\sqrt{{{r}}}}}{{{w}}}")


def joint_formula(path: PathModel, leg_index: int) -> JointFormula | RevoluteFormula:
    leg = path.legs[leg_index]
    joint = leg.leg.joint
    if leg.revolute:
        return RevoluteFormula(joint, *leg.coefficients, leg.discriminant)
    if leg.leg.degree == 1:
        b, c = leg.coefficients
        return JointFormula(joint, -c / b.leading_coefficient(), Fraction(0), None)
    a, b, _ = leg.coefficients
    a0 = a.leading_coefficient()
    centre = -b / (2 * a0)
    r = leg.discriminant / (4 * a0 * a0)  # ρ = centre ± sqrt(r)
    den = 1
    for _, coeff in r.terms():
        den = den * int(fmpq(coeff).q) // math.gcd(den, int(fmpq(coeff).q))
    m_den, rest = _square_part(den)
    k = m_den * rest  # k² is a multiple of den
    q = r * (k * k)
    content = 0
    for _, coeff in q.terms():
        content = math.gcd(content, int(fmpq(coeff).p))
    m, _ = _square_part(content)
    return JointFormula(joint, centre, Fraction(m, k), q / (m * m))


def _latex_fraction(q: Fraction) -> str:
    if q.denominator == 1:
        return str(q.numerator)
    sign = "-" if q < 0 else ""
    return f"{sign}\\frac{{{abs(q.numerator)}}}{{{q.denominator}}}"


_LATEX_NAMES = {"s": "\\mathbf{s}", "c": "\\mathbf{c}", "t": "t"}


def _latex_name(name: str) -> str:
    if name in _LATEX_NAMES:
        return _LATEX_NAMES[name]
    head = name.rstrip("0123456789")
    digits = name[len(head):]
    greek = {"rho": "\\rho", "xi": "\\xi", "theta": "\\theta"}.get(head, head)
    return f"{greek}_{{{digits}}}" if digits else greek


def latex(p: fmpq_mpoly) -> str:
    """A polynomial in LaTeX, highest terms first (``\\frac`` coefficients)."""
    if p.is_zero():
        return "0"
    names = p.context().names()
    out = []
    for exps, coeff in p.terms():
        c = Fraction(int(fmpq(coeff).p), int(fmpq(coeff).q))
        factors = "".join(
            _latex_name(v) + (f"^{{{e}}}" if e > 1 else "") for v, e in zip(names, exps,
                                                                           strict=True) if e)
        sign = "-" if c < 0 else "+"
        c = abs(c)
        coef = "" if c == 1 and factors else _latex_fraction(c)
        out.append(f"{sign} {coef}{factors}".rstrip())
    text = " ".join(out)
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


DROPPED = "in the degenerate set W = 0 of a revolute leg (the leg does not depend on its angle)"


def surface_factors(projection) -> list[dict]:
    """The irreducible factors of ξ as the backend computed it, each with its degree and
    multiplicity, and whether ξ (what singcheck uses: their squarefree product without
    the factors of the degenerate set) keeps it; text and JSON both show this list."""
    if not projection.expanded:
        return []
    xi = projection.singularity_surface
    out = []
    for f, m in projection.singularity_surface_as_computed.factor()[1]:
        used = divmod(xi, f)[1].is_zero()
        out.append({"factor": f, "degree": int(f.total_degree()), "multiplicity": int(m),
                    "used": used, "dropped_because": None if used else DROPPED})
    return out


def robot_formulas(projection, epsilon: fmpq_mpoly | None) -> dict:
    """Every robot-level formula as plain text, keyed for JSON and display."""
    model = projection.model
    return {
        "det_A": model.det_A,
        "det_B": model.det_B,
        "singularity_surface": projection.singularity_surface,
        "singularity_surface_factors": surface_factors(projection),
        "joint_space_singularities": epsilon,
        "workspace_boundary": {leg.joint: d for leg, d in
                               zip(model.legs, projection.workspace_boundary, strict=True)},
        "joint_limit_surfaces": {f"{s.joint} = {s.value}": s.polynomial
                                 for s in projection.joint_limit_surfaces},
    }


def render(projection, epsilon, path: PathModel | None, style: str) -> str:
    """``style``: "text", "latex" or "json"."""
    import json

    f = robot_formulas(projection, epsilon)
    model = projection.model
    joints = [joint_formula(path, i) for i in range(len(path.legs))] if path else []
    if style == "json":
        doc = {
            "robot": model.name, "joints": list(model.joints), "pose": list(model.pose),
            "det_A": str(f["det_A"]), "det_B": str(f["det_B"]),
            "singularity_surface": str(f["singularity_surface"]) if projection.expanded
            else None,
            "singularity_surface_degree": int(f["singularity_surface"].total_degree())
            if projection.expanded else None,
            "singularity_surface_not_expanded": projection.not_expanded or None,
            "singularity_surface_factors": [{**g, "factor": str(g["factor"])}
                                            for g in f["singularity_surface_factors"]],
            "joint_space_singularities": None if epsilon is None else str(epsilon),
            "workspace_boundary": {k: str(v) for k, v in f["workspace_boundary"].items()},
            "joint_limit_surfaces": {k: str(v) for k, v in f["joint_limit_surfaces"].items()},
        }
        if path:
            doc["trajectory"] = {
                "name": path.trajectory.name,
                "pose": {v: str(p) for v, p in zip(model.pose, path.phi, strict=True)},
                "joints": {j.joint: {"centre": str(j.centre), "scale": str(j.scale),
                                     "radicand": None if j.radicand is None else
                                     str(j.radicand)} if isinstance(j, JointFormula) else
                           {"cos_sin": j.text()} for j in joints},
                "notation": "s = sin t, c = cos t; joint = centre ± scale·sqrt(radicand)",
            }
        return json.dumps(doc, indent=2) + "\n"
    show = latex if style == "latex" else str
    eq = " &= " if style == "latex" else " = "
    nl = " \\\\\n" if style == "latex" else "\n"
    lines = [f"det A{eq}{show(f['det_A'])}", f"det B{eq}{show(f['det_B'])}",
             f"xi(X){eq}{show(f['singularity_surface'])}" if projection.expanded else
             f"xi(X) not expanded: {projection.not_expanded}"]
    factors = f["singularity_surface_factors"]
    irreducible = len(factors) == 1 and factors[0]["used"] and factors[0]["multiplicity"] == 1
    for i, g in enumerate([] if irreducible else factors, 1):  # one factor: ξ itself
        power = f", power {g['multiplicity']}" if g["multiplicity"] > 1 else ""
        kept = "" if g["used"] else ", dropped"
        lines.append(f"xi factor {i} (degree {g['degree']}{power}{kept}){eq}{show(g['factor'])}")
    if epsilon is not None:
        lines.append(f"epsilon(rho){eq}{show(epsilon)}")
    lines += [f"workspace boundary ({j}){eq}{show(d)}"
              for j, d in f["workspace_boundary"].items()]
    lines += [f"limit surface ({k}){eq}{show(p)}" for k, p in f["joint_limit_surfaces"].items()]
    if path:
        lines += [f"{v}(t){eq}{show(p)}" for v, p in zip(model.pose, path.phi, strict=True)]
        lines += [j.latex() if style == "latex" else j.text() for j in joints]
    if style == "latex":
        body = nl.join(line.replace(" &= ", " &= ", 1) if " &= " in line
                       else line.replace(" = ", " &= ", 1) for line in lines)
        return ("% s = sin t, c = cos t\n\\begin{align*}\n" + body + "\n\\end{align*}\n")
    used = [str(i) for i, g in enumerate(factors, 1) if g["used"]]
    dropped = [str(i) for i, g in enumerate(factors, 1) if not g["used"]]
    header = f"robot {model.name}: joints {', '.join(model.joints)}; pose {', '.join(model.pose)}\n"
    source = ("ξ = det A (free of the joints, no elimination)" if projection.backend == "none"
              else f"ξ as computed by {projection.backend}")
    if projection.expanded and irreducible:
        header += (f"{source} is irreducible: xi(X) below, made monic (degree "
                   f"{int(f['singularity_surface'].total_degree())})\n")
    elif projection.expanded:
        header += (f"{source}: {len(factors)} irreducible "
                   f"factor{'s' if len(factors) != 1 else ''} (below); xi(X) is the squarefree "
                   f"product of factor{'s' if len(used) != 1 else ''} {', '.join(used)} "
                   f"(degree {int(f['singularity_surface'].total_degree())})")
        if dropped:
            header += (f"; factor{'s' if len(dropped) != 1 else ''} {', '.join(dropped)} "
                       f"{'are' if len(dropped) != 1 else 'is'} dropped: {DROPPED}")
        header += "\n"
    else:
        header += f"ξ(X) was not expanded: {projection.not_expanded}\n"
    if path:
        header += f"trajectory {path.trajectory.name}: s = sin t, c = cos t\n"
    return header + "\n".join(lines) + "\n"
