"""Several exact polynomials enclosed at once, by one straight-line function.

:func:`~singcheck.algebra.intervals.evaluate` walks a polynomial's terms in a loop; the
interval engine calls it a dozen times per ball of t (each leg's coefficients and
discriminant, det A's coefficients, their derivatives), and the walking costs several
times the ball arithmetic itself (an ``arb`` product: 75 ns).  A :class:`BallProgram`
is the same sums written out once per polynomial group as a Python function — each
variable read once, each power ``x^e`` (e ≥ 2) formed once by the tight
:func:`~singcheck.algebra.intervals.power` and shared by every polynomial of the group,
then each polynomial's terms multiplied and added in ball arithmetic — compiled once
and called with the balls of the variables.

Rigour: the function performs exactly the operations :func:`evaluate` performs (the
coefficient's ball times the variables' balls and powers, summed), each rounded outward
by Arb, so each result encloses its polynomial's value at every point of the input
balls.  A coefficient ±1 is not multiplied (exact either way).

Safety: the source is generated from the polynomials' exponent vectors alone —
variable *indices* and integer exponents, never a name or any text of a spec — and the
coefficients are passed in as a list of balls; nothing a user wrote reaches ``compile``.
"""

from __future__ import annotations

from collections.abc import Sequence

from flint import arb, ctx, fmpq, fmpq_mpoly

from singcheck.algebra.intervals import Ball, power

#: terms (all polynomials of a group together) above which no program is compiled: the
#: source and its compilation grow with them, and the loop's overhead matters less
MAX_TERMS = 600

_ZERO = arb(0)


class BallProgram:
    """``program(values)``: the balls of the polynomials at the balls ``values`` of their
    ring's generators (a list, in the polynomials' order)."""

    __slots__ = ("_code", "_coefficients", "_polys", "_function")

    def __init__(self, polys: Sequence[fmpq_mpoly]) -> None:
        self._polys = tuple(polys)
        self._coefficients: dict[int, list[arb]] = {}
        source, self._code = _source(self._polys)
        namespace: dict = {}
        exec(compile(source, "<ball program>", "exec"), namespace)  # noqa: S102 - see above
        self._function = namespace["program"]

    def __call__(self, values: Sequence[Ball]) -> list[Ball]:
        coefficients = self._coefficients.get(ctx.prec)
        if coefficients is None:
            coefficients = self._coefficients[ctx.prec] = [arb(c) for c in self._code]
        return self._function(values, coefficients, power, _ZERO)


def _source(polys: tuple[fmpq_mpoly, ...]) -> tuple[str, list[fmpq]]:
    """The function's source and the coefficients it reads (by position)."""
    coefficients: list[fmpq] = []
    used: set[int] = set()
    powers: set[tuple[int, int]] = set()
    sums = []
    for p in polys:
        terms = []
        for exps, c in p.terms():
            factors = []
            for i, e in enumerate(exps):
                if e:
                    used.add(i)
                    if e > 1:
                        powers.add((i, int(e)))
                    factors.append(f"v{i}" if e == 1 else f"p{i}_{int(e)}")
            if not factors:
                coefficients.append(c)
                terms.append(f"C[{len(coefficients) - 1}]")
            elif c == 1 or c == -1:
                terms.append(("-" if c == -1 else "") + "*".join(factors))
            else:
                coefficients.append(c)
                terms.append("*".join([f"C[{len(coefficients) - 1}]", *factors]))
        sums.append(" + ".join(terms).replace("+ -", "- ") if terms else "ZERO")
    lines = ["def program(v, C, power, ZERO):"]
    lines += [f"    v{i} = v[{i}]" for i in sorted(used)]
    lines += [f"    p{i}_{e} = power(v{i}, {e})" for i, e in sorted(powers)]
    lines.append("    return [" + ", ".join(sums) + "]")
    return "\n".join(lines) + "\n", coefficients


_PROGRAMS: dict = {}
_CODE: dict[tuple[str, str], object] = {}


def generated_function(source: str, name: str, namespace: dict):
    """The function ``name`` defined by ``source`` (generated code, never a spec's text),
    executed in ``namespace``; the compiled code is kept by its source (paths of one
    robot and shape share it: only the namespace's values differ)."""
    code = _CODE.get((source, name))
    if code is None:
        if len(_CODE) > 256:
            _CODE.clear()
        code = _CODE[source, name] = compile(source, f"<{name}>", "exec")
    exec(code, namespace)  # noqa: S102 - generated from indices and kinds alone
    return namespace[name]


def ball_program(owner, purpose: str, polys) -> BallProgram | None:
    """The compiled program of the polynomials ``polys(owner)``, once per ``owner`` (a
    leg, a model: the entry holds it, so its id is not reused) and ``purpose``; None when
    they are too large to be worth it (:data:`MAX_TERMS`: use
    :func:`~singcheck.algebra.intervals.evaluate` then)."""
    key = (id(owner), purpose)
    hit = _PROGRAMS.get(key)
    if hit is not None and hit[0] is owner:
        return hit[1]
    if len(_PROGRAMS) > 1024:
        _PROGRAMS.clear()
    group = list(polys(owner))
    program = BallProgram(group) if sum(len(p) for p in group) <= MAX_TERMS else None
    _PROGRAMS[key] = (owner, program)
    return program


class JointSum:
    """``joint_sum(q, j)`` = Σₖ q[k]·∏ j[v]^e over the k-th monomial's (v, e) pairs: det A
    = Σ_α q_α(pose)·ρ^α once its pose coefficients q_α are enclosed (each mode then only
    sums its few joint monomials).  Written out and compiled as :class:`BallProgram` is
    (from exponent pairs alone), each ``j^e`` (e ≥ 2) by the tight
    :func:`~singcheck.algebra.intervals.power`: the operations of the loop it replaces."""

    __slots__ = ("_function",)

    def __init__(self, monomials: Sequence[tuple[tuple[int, int], ...]]) -> None:
        used = sorted({v for alpha in monomials for v, _ in alpha})
        powers = sorted({(v, e) for alpha in monomials for v, e in alpha if e > 1})
        terms = []
        for k, alpha in enumerate(monomials):
            factors = [f"j{v}" if e == 1 else f"p{v}_{e}" for v, e in alpha]
            terms.append("*".join([f"q[{k}]", *factors]))
        lines = ["def joint_sum(q, j, power, ZERO):"]
        lines += [f"    j{v} = j[{v}]" for v in used]
        lines += [f"    p{v}_{e} = power(j{v}, {e})" for v, e in powers]
        lines.append("    return " + (" + ".join(terms) if terms else "ZERO"))
        namespace: dict = {}
        exec(compile("\n".join(lines) + "\n", "<joint sum>", "exec"), namespace)  # noqa: S102
        self._function = namespace["joint_sum"]

    def __call__(self, q: Sequence[Ball], joints: Sequence[Ball]) -> Ball:
        return self._function(q, joints, power, _ZERO)


_SUMS: dict = {}


def joint_sum(owner, monomials) -> JointSum:
    """The compiled :class:`JointSum` of ``monomials(owner)``, once per ``owner``."""
    hit = _SUMS.get(id(owner))
    if hit is None or hit[0] is not owner:
        if len(_SUMS) > 256:
            _SUMS.clear()
        hit = _SUMS[id(owner)] = (owner, JointSum(monomials(owner)))
    return hit[1]
