"""Helpers on exact multivariate polynomials over Q (FLINT ``fmpq_mpoly``).

Moving a polynomial to a smaller ring, its constant value, its coefficient in a power of
one variable, and its squarefree part: the small exact operations every stage uses.
"""

from __future__ import annotations

from flint import fmpq, fmpq_mpoly, fmpq_mpoly_ctx


def memo_per_object(cache: dict, obj, compute, keep: int = 256):
    """``compute(obj)``, once per object: the entry keeps the object, so its id is not
    reused while it is there (the cache is emptied past ``keep`` entries)."""
    hit = cache.get(id(obj))
    if hit is None or hit[0] is not obj:
        if len(cache) > keep:
            cache.clear()
        hit = cache[id(obj)] = (obj, compute(obj))
    return hit[1]


_TERMS: dict = {}


def exact_terms(p: fmpq_mpoly) -> list:
    """``list(p.terms())``, once per polynomial object: reading the terms out of FLINT
    costs more than using them when the coefficients run to thousands of digits (a long
    cubic spline's pieces), and two stages read the same pose polynomial's (the cost
    estimate of a composition, the ball split)."""
    return memo_per_object(_TERMS, p, lambda p: list(p.terms()), keep=512)


def with_unit_coefficients(p: fmpq_mpoly) -> fmpq_mpoly:
    """``p`` with every coefficient replaced by 1, once per polynomial object: composed
    with monomials it cannot cancel, so the image's degrees and term counts bound those
    of ``p``'s own image (two a-priori size estimates read it from the same det A)."""
    return memo_per_object(_UNIT, p, lambda q: q.context().from_dict(
        dict.fromkeys(q.monoms(), 1)), keep=64)


_UNIT: dict = {}


def restrict(p: fmpq_mpoly, ctx: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """``p`` (free of the dropped variables) re-expressed in the smaller context ``ctx``.

    The variables are matched by name and the terms moved by FLINT in C
    (``project_to_context``, a composition with the generators), after an exact check
    that no dropped variable occurs: tens of thousands of terms in a millisecond."""
    names = p.context().names()
    kept = set(ctx.names())
    degrees = p.degrees()
    if any(degrees[i] > 0 for i, v in enumerate(names) if v not in kept):
        raise ValueError(f"{p} still involves an eliminated variable")
    return p.project_to_context(ctx)


def constant_value(p: fmpq_mpoly) -> fmpq:
    """The value of a constant polynomial (0 for the zero polynomial), exactly."""
    return p.leading_coefficient() if not p.is_zero() else fmpq(0)


def coefficient_in(f: fmpq_mpoly, var_index: int, degree: int) -> fmpq_mpoly:
    """The coefficient of ``x_var^degree`` in ``f`` (a polynomial in the other variables,
    still in ``f``'s context)."""
    terms = {}
    for exps, coeff in f.terms():
        if exps[var_index] == degree:
            e = list(exps)
            e[var_index] = 0
            terms[tuple(e)] = coeff
    return f.context().from_dict(terms)


def squarefree_part(p: fmpq_mpoly) -> fmpq_mpoly:
    """The product of the distinct irreducible factors of ``p``, made monic (exact).

    It has the same zero set as ``p`` and simple factors, so its roots along a path are
    the candidates without multiplicity blow-up.  **The zero polynomial is returned as
    it is**: it vanishes everywhere, and FLINT factors it into no factor at all, whose
    product would be 1, a polynomial that vanishes nowhere (a path lying on the
    singularity surface would lose every candidate).
    """
    if p.is_zero():
        return p
    _, factors = p.factor_squarefree()
    out = p.context().from_dict({(0,) * p.context().nvars(): 1})
    for f, _mult in factors:
        out *= f
    lc = out.leading_coefficient()
    return out / lc if lc != 0 else out


#: :func:`may_be_slow`'s bound on terms × the largest degree × the coefficients' 64-bit
#: words, for a factorization or a resultant.  Calibrated on this machine (a shared 2-core
#: one, CPU seconds of the FLINT call alone, ``bench/calibrate_slow.py``: 2,288 calls from
#: the bundled robots and paths, the crash corpus, 1,100 random and fuzz-like paths and
#: random sparse polynomials): below it no factorization or resultant that the
#: certification formed took over 21 ms (a stacked Orthoglide resultant of 1,504 terms of
#: degree 10).  Random sparse polynomials show what the measure misses: a resultant of
#: 2,690 terms of degree 6 in 5 variables took 3.6 s, and a factorization of 20 terms of
#: degree 100 took 66 ms (a resultant costs what its output does, not its input).
SLOW_SIZE = 20_000

#: the same bound for a squarefree part (``squarefree=True``): one gcd with the
#: derivatives, cheaper than a factorization of the same size.  Below it the squarefree
#: parts of the norm chain took at most 32 ms (929 terms of degree 20, a 3-RRR path; 18
#: ms in another run of that shape), random sparse ones at most 43 ms (150 terms of
#: degree 64 in 3 variables); the rotary Delta's circle forms two under it (2,326 terms
#: of degree 14: 7 ms; 377 of degree 28, 108-bit coefficients: 5 ms), where a fork and
#: the pickled result cost 20 and 13 ms.  Above it: 92 ms at 8,911 terms of degree 10
#: (the first over 50 ms, at 1.8 times the bound), 0.41 s at 6,429 of degree 312, 3.3 s
#: for a random 57,325 terms of degree 32 with 3,000-bit coefficients.
SLOW_SQUAREFREE_SIZE = 50_000


def may_be_slow(p: fmpq_mpoly, squarefree: bool = False) -> bool:
    """Whether one FLINT factorization or resultant of ``p`` (``squarefree``: its
    squarefree part) may run long enough (over about 50 ms, up to seconds) to be worth
    running where a deadline can stop it
    (:func:`singcheck.elimination.cas.forked.until_deadline`): its terms times its
    degree, times its coefficients' 64-bit words (a path written with 10⁻⁹¹ carries
    thousand-digit coefficients into μ), over :data:`SLOW_SIZE`
    (:data:`SLOW_SQUAREFREE_SIZE`)."""
    size = len(p) * max(1, max(p.degrees(), default=0))
    bound = SLOW_SQUAREFREE_SIZE if squarefree else SLOW_SIZE
    return size > bound or size * (1 + _height_bits(p) // 64) > bound


def products_may_be_slow(*pairs: tuple[fmpq_mpoly, fmpq_mpoly]) -> bool:
    """Whether the FLINT products of these pairs may run for a large fraction of a second
    (terms times terms times the coefficients' 64-bit words): then they are formed where
    a deadline can stop them too."""
    work = 0
    for a, b in pairs:
        work += len(a) * len(b) * (1 + _height_bits(a) // 64) * (1 + _height_bits(b) // 64)
    return work > SLOW_PRODUCT


#: :func:`products_may_be_slow`'s bound (a 600-term product of 64-bit coefficients: 0.4
#: ms; of 4,800-bit ones, seconds)
SLOW_PRODUCT = 5_000_000


def _height_bits(p: fmpq_mpoly) -> int:
    """The most bits of a numerator or denominator of p's coefficients."""
    return max((c.height_bits() for c in p.coeffs()), default=0)
