"""Angles in a decomposition: the half-angle chart w = tan(v/2).

An angle v enters the model as the pair (cos v, sin v) on the circle c² + s² = 1; a
cylindrical decomposition needs one real axis per variable instead.  The chart
``w = tan(v/2)``, ``c = (1 - w²)/(1 + w²)``, ``s = 2w/(1 + w²)``, is a bijection from the
open arc v ∈ (-π, π) onto the whole line w ∈ R, rational both ways (w = s/(1 + c)).

A polynomial P(…, c, s) of degree D in (c, s) becomes, with denominators cleared,
``(1 + w²)^D · P(…, (1 - w²)/(1 + w²), 2w/(1 + w²))``, an exact polynomial over Q in w
with the same real zeros as P on the arc (1 + w² never vanishes; its own factors are
dropped).  So the decomposition of the chart's space is the decomposition of the space
**cut along v = π**: a region is a connected component of the complement with the
half-line v = π removed.  A path whose angle stays inside (-π, π) lies in one such region
when it crosses no surface (a true statement); two regions of the chart may still be one
component of the uncut space, joined across v = π.

A sample point with rational w has a rational pose: (c, s) = ((1 - w²)/(1 + w²),
2w/(1 + w²)), so every count at a sample is exact.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.radicals import angle_names


def chart_axis(v: str) -> str:
    """The axis of an angle v in the chart: ``tan(v/2)``."""
    return f"tan({v}/2)"


@dataclass(frozen=True)
class Chart:
    """The axes of a space (pose or joints) with each angle v replaced by tan(v/2)."""

    names: tuple[str, ...]  # the user's variables (pose or joints)
    angles: tuple[str, ...]  # those that are angles
    variables: tuple[str, ...]  # the model's: v, or cos(v), sin(v) for an angle

    @classmethod
    def of(cls, names, angles) -> Chart:
        angles = tuple(v for v in names if v in angles)
        variables: list[str] = []
        for v in names:
            variables += angle_names(v) if v in angles else [v]
        return cls(tuple(names), angles, tuple(variables))

    @property
    def axes(self) -> tuple[str, ...]:
        return tuple(chart_axis(v) if v in self.angles else v for v in self.names)

    @property
    def context(self) -> fmpq_mpoly_ctx:
        return fmpq_mpoly_ctx.get(self.axes, "lex")

    def polynomial(self, p: fmpq_mpoly) -> fmpq_mpoly:
        """``p`` (in a context of the model's variables, no others involved) in the chart,
        denominators cleared and factors 1 + w² dropped: the same real zero set on the
        arcs (-π, π)."""
        ctx = self.context
        names = p.context().names()
        angles = [v for v in self.angles if angle_names(v)[0] in names]
        if not angles:
            return _move(p, ctx)
        extra = tuple(f"h({v})" for v in angles)
        wide = fmpq_mpoly_ctx.get((*names, *extra), "lex")
        pairs = [tuple(names.index(n) for n in angle_names(v)) for v in angles]
        top = [max((e[c] + e[s] for e, _ in p.terms()), default=0) for c, s in pairs]
        terms = {}
        for exps, coeff in p.terms():
            rest = (d - exps[c] - exps[s] for d, (c, s) in zip(top, pairs, strict=True))
            terms[(*exps, *rest)] = coeff
        homogeneous = wide.from_dict(terms)
        gens = dict(zip(ctx.names(), ctx.gens(), strict=True))
        zero = ctx.from_dict({})
        args = []
        for n in (*names, *extra):
            if n in gens:
                args.append(gens[n])
            elif n.startswith("h("):
                w = gens[chart_axis(n[2:-1])]
                args.append(1 + w * w)
            elif n in self.variables and n.startswith(("cos(", "sin(")):
                w = gens[chart_axis(n[4:-1])]
                args.append(1 - w * w if n.startswith("cos(") else 2 * w)
            elif p.degrees()[names.index(n)] > 0:
                raise ValueError(f"{n} is not a variable of the chart")
            else:
                args.append(zero)
        out = homogeneous.compose(*args, ctx=ctx)
        for v in angles:
            w = gens[chart_axis(v)]
            while not out.is_zero() and out.degrees()[ctx.names().index(chart_axis(v))] >= 2:
                q, r = divmod(out, 1 + w * w)
                if not r.is_zero():
                    break
                out = q
        return out

    def values(self, point) -> list[Fraction]:
        """The model's variables (cos, sin for an angle) at a chart point (exact)."""
        out: list[Fraction] = []
        for v, x in zip(self.names, point, strict=True):
            x = Fraction(x)
            if v in self.angles:
                out += [(1 - x * x) / (1 + x * x), 2 * x / (1 + x * x)]
            else:
                out.append(x)
        return out


def _move(p: fmpq_mpoly, ctx: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """``p`` in ``ctx`` (variables matched by name; those of ``p`` missing from ``ctx``
    must have degree 0); unchanged when already there."""
    if p.context() is ctx:
        return p
    names = p.context().names()
    index = {n: i for i, n in enumerate(names)}
    out = {}
    for exps, coeff in p.terms():
        if any(e for n, e in zip(names, exps, strict=True) if n not in ctx.names()):
            raise ValueError(f"{p} involves a variable outside {ctx.names()}")
        out[tuple(exps[index[n]] if n in index else 0 for n in ctx.names())] = coeff
    return ctx.from_dict(out)
