"""Elimination requests: what the core asks a computer-algebra backend to compute.

A request is plain data: generators of an ideal in Q[variables] and the variables to
eliminate.  A backend returns polynomials in the kept variables whose common zero set
is the Zariski closure of the projection of the ideal's zero set (the generators of the
elimination ideal, or a multiple of it with the same zero set); the core only ever uses
that zero set, via squarefree parts.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import gcd
from typing import Protocol

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.composition import multiply_in_pieces
from singcheck.algebra.polynomials import coefficient_in, may_be_slow, squarefree_part
from singcheck.algebra.radicals import radical_prime
from singcheck.budget import checkpoint


@dataclass(frozen=True)
class EliminationRequest:
    label: str  # what is computed, in the paper's words (e.g. "singularity_surface")
    context: fmpq_mpoly_ctx  # the ring of the generators
    generators: tuple[fmpq_mpoly, ...]
    eliminate: tuple[str, ...]

    @property
    def keep(self) -> tuple[str, ...]:
        return tuple(v for v in self.context.names() if v not in self.eliminate)

    def kept_context(self) -> fmpq_mpoly_ctx:
        return fmpq_mpoly_ctx.get(self.keep, "lex")


@dataclass(frozen=True)
class EliminationResult:
    request: EliminationRequest
    polynomials: tuple[fmpq_mpoly, ...]  # in request.kept_context()
    method: str  # how it was computed, for the report (e.g. "resultant chain")
    backend: str
    #: the polynomial is :func:`norm_chain` of the request itself, computed now (by the
    #: flint backend, here or in its fork; never set on a result read from the cache):
    #: the re-check, which computes that norm, would only repeat the computation
    is_norm: bool = False


class EliminationBackend(Protocol):
    name: str

    def eliminate(self, request: EliminationRequest) -> EliminationResult: ...

    def version(self) -> str: ...


def _circle_pairs(request: EliminationRequest) -> dict[str, str]:
    """cos(v) → sin(v) for every angle whose two variables are both eliminated."""
    elim = set(request.eliminate)
    return {v: "sin(" + v[4:] for v in request.eliminate
            if v.startswith("cos(") and "sin(" + v[4:] in elim}


def _is_circle(f: fmpq_mpoly, c: int, s: int) -> bool:
    ctx = f.context()
    gens = ctx.gens()
    return f == gens[c] ** 2 + gens[s] ** 2 - 1


def leg_structure(request: EliminationRequest):
    """``(g, [(v, f_v), …])`` when every eliminated variable is covered by one *leg* and
    exactly one generator g is left, else None.  A leg is either a single variable v
    with a generator f_v that involves no other eliminated variable and has a constant
    leading coefficient in v, or an angle's pair ``(cos(v), sin(v))`` (then ``v`` in the
    list is that pair) with the circle ``cos² + sin² - 1`` among the generators and one
    generator ``a·cos + b·sin + d`` involving no other eliminated variable.

    Square roots ``sqrt(p)`` being eliminated (after the joints: a robot's √3 with its
    pseudo-leg ``sqrt(p)² - p``) may appear in a joint's leg: the chain eliminates the
    joints first, then each square root by its monic pseudo-leg, so it is still the norm
    (a linear Delta's rail at (-1/2, √3/2) keeps its legs)."""
    names = request.context.names()
    radicals = {v for v in request.eliminate if radical_prime(v) is not None}
    pairs = _circle_pairs(request)
    partners = set(pairs.values())
    circles = {c for c, s in pairs.items()
               if any(_is_circle(f, names.index(c), names.index(s)) for f in request.generators)}
    legs: dict[object, fmpq_mpoly] = {}
    rest = []
    for f in request.generators:
        involved = [v for v in request.eliminate if f.degrees()[names.index(v)] > 0]
        involved = [v for v in involved if v not in radicals] or involved
        pair = [c for c in pairs if set(involved) <= {c, pairs[c]}] if involved else []
        if pair and len(involved) == 2 and _is_circle(f, *(names.index(v) for v in involved)):
            continue  # the circle of that angle
        if len(involved) == 1 and involved[0] not in legs and involved[0] not in pairs \
                and involved[0] not in partners and _constant_lead(f, names, involved[0]):
            legs[involved[0]] = f
        elif pair and pair[0] in circles and (pair[0], pairs[pair[0]]) not in legs and \
                _linear_in(f, names.index(pair[0]), names.index(pairs[pair[0]])):
            legs[(pair[0], pairs[pair[0]])] = f
        else:
            rest.append(f)
    covered = {v for key in legs for v in (key if isinstance(key, tuple) else (key,))}
    if len(rest) != 1 or covered != set(request.eliminate):
        return None
    order = {v: i for i, v in enumerate(request.eliminate)}
    keys = sorted(legs, key=lambda k: order[k[0] if isinstance(k, tuple) else k])
    return rest[0], [(k, legs[k]) for k in keys]


def _linear_in(f: fmpq_mpoly, c: int, s: int) -> bool:
    return all(e[c] + e[s] <= 1 for e, _ in f.terms())


def _constant_lead(f: fmpq_mpoly, names, v: str) -> bool:
    i = names.index(v)
    d = f.degrees()[i]
    return all(sum(e) == d for e, _ in f.terms() if e[i] == d)


def revolute_norm(g: fmpq_mpoly, c: str, s: str, f: fmpq_mpoly, reduce=None) -> fmpq_mpoly:
    """The norm of ``g`` over the two points of ``f = a·c + b·s + d = 0`` on the circle
    ``c² + s² = 1``, free of c and s.

    On branch σ = ±1, ``c = (P + σb·R)/W`` and ``s = (Q - σa·R)/W`` with ``P = -a·d``,
    ``Q = -b·d``, ``W = a² + b²`` and ``R = √Δ``, ``Δ = W - d²``.  With k the total degree
    of g in (c, s), ``W^k·g`` at branch σ is ``G₀ + σR·G₁`` (polynomials over Q[X]), and
    the product over both branches is ``G₀² - Δ·G₁²``.  Where W ≠ 0 it vanishes exactly
    when g vanishes at one of the two (complex) points; on W = 0 (the leg does not
    depend on its angle) it may vanish too: the degenerate set, handled by the caller.
    ``reduce`` (optional, as for :func:`norm_chain`) is applied to every intermediate
    product, which keeps them small; the result is then the same modulo its relations.
    With ``reduce``, g is first taken modulo the leg's own circle ``c² + s² - 1`` (degree
    ≤ 1 in c): it has the same value at both points, whose product the norm is, and no
    larger degree in (c, s) (the rotary Delta's last leg along a path: 2,326 terms ->
    1,592, its norm 13.0 -> 9.1 ms, the same μ).
    A :func:`~singcheck.budget.checkpoint` is reached before every product.
    """
    red = reduce or (lambda x: x)
    ctx = g.context()
    names = ctx.names()
    ci, si = names.index(c), names.index(s)
    if reduce is not None and g.degrees()[ci] + g.degrees()[si] >= 2:
        gens = ctx.gens()
        g = divmod(g, gens[ci] ** 2 + gens[si] ** 2 - 1)[1]
        if g.is_zero():  # zero at both points (at every point of the circle): norm 0
            return g
    one = ctx.from_dict({(0,) * ctx.nvars(): 1})
    zero = ctx.from_dict({})
    a, b = coefficient_in(f, ci, 1), coefficient_in(f, si, 1)
    d = coefficient_in(coefficient_in(f, ci, 0), si, 0)
    w = red(a * a + b * b)
    delta = red(w - d * d)

    def product(x, y):  # in slices that a time limit can stop
        return multiply_in_pieces(x, y, red, PRODUCT_PAIRS)

    def mul(x, y):
        checkpoint()
        return red(x[0] * y[0] + red(delta * x[1]) * y[1]), red(x[0] * y[1] + x[1] * y[0])

    groups: dict[tuple[int, int], dict] = {}
    for exps, coeff in g.terms():
        e = list(exps)
        key = (e[ci], e[si])
        e[ci] = e[si] = 0
        groups.setdefault(key, {})[tuple(e)] = coeff
    k = max(i + j for i, j in groups)
    cpow, spow, wpow = [(one, zero)], [(one, zero)], [one]
    for _ in range(k):
        cpow.append(mul(cpow[-1], (red(-a * d), b)))
        spow.append(mul(spow[-1], (red(-b * d), -a)))
        wpow.append(red(wpow[-1] * w))
    g0, g1 = zero, zero
    for (i, j), terms in groups.items():
        coefficient = red(ctx.from_dict(terms) * wpow[k - i - j])
        x = mul(cpow[i], spow[j])
        g0 += product(coefficient, x[0])
        g1 += product(coefficient, x[1])
    return product(g0, g0) - product(delta, product(g1, g1))


#: The most pairs of terms one uninterrupted product may multiply: about 50 ms of FLINT
#: on the rotary Delta's path-wise norms.  Their last squares multiply 5·10⁶ pairs, which
#: took 0.25 s in one call and let a 0.2 s time limit overrun by that much (more on a
#: slower machine).  Slicing costs a few per cent where it applies.  Sliced by the
#: composition's :func:`~singcheck.algebra.composition.multiply_in_pieces`, whose own
#: bound (:data:`~singcheck.algebra.composition.PIECE_PAIRS`) is twice this one.
PRODUCT_PAIRS = 1_000_000


def norm_chain(g: fmpq_mpoly, legs: list[tuple[object, fmpq_mpoly]],
               reduce=None) -> fmpq_mpoly:
    """A polynomial with the zero set of ``Res_vn(… Res_v1(g, f_1) …, f_n)`` (FLINT).

    When each f_i is monic-like in its v_i (constant leading coefficient), that chain is
    the norm of g over the legs: g multiplied over every common complex root, so it
    vanishes exactly on the projection.  A revolute leg (``v`` a pair cos, sin) takes
    :func:`revolute_norm` instead of a resultant.  Computed one irreducible factor of g
    at a time, reduced to its squarefree part after each step (the next resultant
    vanishes exactly where the previous one has a root of the next leg, so the zero set
    is kept), which keeps factored inputs (stacked stages) small.  ``reduce`` (optional)
    maps each intermediate to an equivalent one modulo relations of the ring (along a
    path: s² + c² = 1), which keeps the same zeros on the variety of those relations.

    **Within the deadline.**  A checkpoint comes before every step, and each FLINT call
    on a polynomial that :func:`~singcheck.algebra.polynomials.may_be_slow` (a
    factorization, a resultant, a squarefree part: one uninterruptible call each) runs
    in a forked child that the current deadline stops
    (:func:`~singcheck.elimination.cas.forked.until_deadline`): a cubic path of the
    rotary Delta spent 1.2 s in one squarefree part, past a 2 s limit.

    **Zero stays zero.**  The norm of the zero polynomial is zero, and so is the norm of g
    once any step of its chain is identically zero (a path on the singularity: det A
    vanishes in some mode all along it); FLINT factors zero into no factor, so without
    this explicit case the product of "no factors" would make the result 1, a
    polynomial that vanishes nowhere.
    """
    if g.is_zero():
        return g
    from singcheck.elimination.cas.forked import until_deadline

    def stoppable(fn, p: fmpq_mpoly, what: str):  # one FLINT call a deadline can stop
        return until_deadline(fn, p, f"the norm chain's {what}",
                              may_be_slow(p, squarefree=what == "squarefree part"))

    names = g.context().names()
    _, factors = stoppable(lambda p: p.factor(), g, "factorization")
    one = g.context().from_dict({(0,) * g.context().nvars(): 1})
    total = one
    later = [{names.index(x) for v, _ in legs[i + 1:]
              for x in (v if isinstance(v, tuple) else (v,))} for i in range(len(legs))]
    for factor, _mult in factors:
        acc, reduced, aside = factor, False, one
        for i, (v, f) in enumerate(legs):
            variables = v if isinstance(v, tuple) else (v,)
            if all(acc.degrees()[names.index(x)] <= 0 for x in variables):
                continue  # a leg that does not touch this factor only raises its power
            checkpoint()
            acc = revolute_norm(acc, v[0], v[1], f, reduce) if isinstance(v, tuple) else \
                stoppable(lambda p, f=f, v=v: p.resultant(f, v), acc, "resultant")
            acc, reduced = reduce(acc) if reduce else acc, True
            if acc.is_zero():
                return acc  # this factor's norm is zero, so the whole norm is zero
            checkpoint()
            if later[i]:
                acc, free = stoppable(lambda p, i=i: _split_free(p, later[i]), acc,
                                      "squarefree part")
                aside *= free
            else:
                acc = stoppable(squarefree_part, acc, "squarefree part")
        if aside != one:
            acc = stoppable(squarefree_part, acc * aside, "squarefree part")
        if len(factors) == 1 and reduced:
            return acc  # squarefree and monic already: the one factor's norm
        total *= acc
    return stoppable(squarefree_part, total, "squarefree part")


def _split_free(p: fmpq_mpoly, variables: set[int]) -> tuple[fmpq_mpoly, fmpq_mpoly]:
    """``(k, b)``: the squarefree part of ``p`` as the product of its squarefree factors
    that involve one of ``variables`` (monic) and those that do not.  The norm is
    multiplicative, and a factor free of a leg's joint only comes out of that leg's
    resultant or revolute norm as a power of itself: set aside, it keeps its zeros
    without being squared at every later leg (the rotary Delta's W = a² + b² factors).
    The zero polynomial is kept whole: ``(0, 1)`` (it has no factors to split)."""
    one = p.context().from_dict({(0,) * p.context().nvars(): 1})
    if p.is_zero():
        return p, one
    _, parts = p.factor_squarefree()
    keep, free = one, one
    for part, _mult in parts:
        if any(part.degrees()[i] > 0 for i in variables):
            keep *= part
        else:
            free *= part
    lc = keep.leading_coefficient()
    return (keep / lc if lc != 0 else keep), free


def _height(p: fmpq_mpoly) -> int:
    """Bits of the 1-norm of ``p``'s primitive integer multiple (an upper bound)."""
    coeffs = p.coeffs()
    if not coeffs:
        return 0
    den = 1
    for c in coeffs:
        den = den * int(c.q) // gcd(den, int(c.q))
    return sum(abs(int(c.p)) * (den // int(c.q)) for c in coeffs).bit_length()


def norm_chain_bound(g: fmpq_mpoly, legs: list[tuple[object, fmpq_mpoly]]) -> tuple[int, int]:
    """``(terms, bits)``: no polynomial that :func:`norm_chain` (without ``reduce``) forms
    from ``g`` and ``legs`` has more than ``terms`` terms or a coefficient (of its
    primitive integer multiple) of more than ``bits`` bits — proven from degrees and
    coefficient sizes alone, before any work.

    Each polynomial carries a degree in every variable (a revolute leg's cos, sin: one
    total degree) and the bits h of its 1-norm, which is subadditive and
    submultiplicative.  ``Res_v(A, f)`` is the Sylvester determinant, deg_v f rows of A's
    coefficients and deg_v A rows of f's, so ``deg_w ≤ deg_v A·deg_w f + deg_v f·deg_w
    A`` and ``h ≤ deg_v A·h_f + deg_v f·h_A``; the subresultants FLINT forms on the way
    are minors of the same matrix, bounded alike.  A revolute norm ``G₀² - Δ·G₁²``
    (:func:`revolute_norm`, k the degree of A in cos, sin): ``deg_w ≤ 2·deg_w A +
    2k·(α + max(α, δ))`` (α of a and b, δ of d), and ``‖G₀‖ + ‖G₁‖ ≤ ‖A‖·X^k`` with X
    the largest of ‖W‖ = ‖a² + b²‖ and ‖P‖ + ‖b‖·√‖Δ‖, ‖Q‖ + ‖a‖·√‖Δ‖, so ``h ≤
    2(h_A + k·h_X) + h_Δ + 1``.  The chain runs
    on g's factors and squarefree parts, but resultants and norms are multiplicative,
    so each polynomial it forms divides the one the same chain forms from g itself:
    the bound is computed on that chain, and a divisor has no larger degrees and, by
    Mahler's measure (M(Q) ≤ M(P) ≤ ‖P‖₂), coefficients of at most ``2^(Σ deg)·‖P‖₁``.
    Terms are bounded by the box of the degrees."""
    ctx = g.context()
    names = ctx.names()
    pairs = [v for v, _ in legs if isinstance(v, tuple)]
    paired = {x for v in pairs for x in v}

    def bounds(p: fmpq_mpoly) -> dict:
        degrees = [max(0, int(d)) for d in p.degrees()]
        out = {v: d for v, d in zip(names, degrees, strict=True) if v not in paired}
        for c, s in pairs:
            ci, si = names.index(c), names.index(s)
            out[c, s] = max((int(e[ci]) + int(e[si]) for e in p.monoms()), default=0)
        out["h"] = _height(p)
        return out

    def size(b: dict) -> int:
        n = 1
        for v, d in b.items():
            if isinstance(v, tuple):
                n *= (d + 1) * (d + 2) // 2
            elif v != "h":
                n *= d + 1
        return n

    def divisor(b: dict) -> dict:
        total = sum(d * (2 if isinstance(v, tuple) else 1) for v, d in b.items() if v != "h")
        return {**b, "h": b["h"] + total + size(b).bit_length()}

    chain = []
    for v, f in legs:
        if isinstance(v, tuple):
            ci, si = names.index(v[0]), names.index(v[1])
            a, b = bounds(coefficient_in(f, ci, 1)), bounds(coefficient_in(f, si, 1))
            d = bounds(coefficient_in(coefficient_in(f, ci, 0), si, 0))
            ab = {w: max(a[w], b[w]) for w in a}
            h_f = _height(f)  # a, b, d scaled together, as parts of f's integer multiple
            h_w = 2 * h_f + 1
            h_delta = max(h_w, 2 * h_f) + 1
            h_x = max(h_w, h_f + max(h_f, (h_delta + 1) // 2) + 1)
            chain.append((v, ab, d, (h_x, h_delta)))
        else:
            chain.append((v, bounds(f), None, None))
    acc = bounds(g)
    largest, bits = size(acc), divisor(acc)["h"]
    for v, f, d, heights in chain:
        if acc[v] == 0:
            continue  # a leg that does not touch it
        if d is not None:
            k, (h_x, h_delta) = acc[v], heights
            h = 2 * (acc["h"] + k * h_x) + h_delta + 1
            acc = {w: 2 * acc[w] + 2 * k * (f[w] + max(f[w], d[w])) for w in acc}
        else:
            m, n = acc[v], f[v]
            h = m * f["h"] + n * acc["h"]
            acc = {w: m * f[w] + n * acc[w] for w in acc}
        acc[v], acc["h"] = 0, h
        largest, bits = max(largest, size(acc)), max(bits, divisor(acc)["h"])
    return largest, bits


#: A request is computed in singcheck's own process, not in a forked child, only when
#: :func:`norm_chain_bound` proves every polynomial of its chain at most this many terms
#: of at most :data:`IN_PROCESS_BITS` bits (README, "Budgets").
IN_PROCESS_TERMS = 1_000_000
IN_PROCESS_BITS = 1024


def chain_memory_bound(terms: int, bits: int, nvars: int) -> int:
    """Bytes that a chain whose polynomials have at most ``terms`` terms of ``bits`` bits
    can hold at once, by a generous count: twelve such polynomials alive (the chain's
    inputs, its accumulator, FLINT's subresultants; a dense chain of 505,161 terms of
    365 bits peaked at 4.7), each term an exponent word per variable and a coefficient
    of ``bits`` bits with GMP's header."""
    return 12 * terms * (8 * nvars + 8 * (bits // 64 + 1) + 32)


def chain_is_small(g: fmpq_mpoly, legs: list, memory_limit: int) -> bool:
    """Whether :func:`norm_chain_bound` proves the chain of ``g`` over ``legs`` small:
    at most :data:`IN_PROCESS_TERMS` terms of :data:`IN_PROCESS_BITS` bits, and
    :func:`chain_memory_bound` at most half of ``memory_limit`` (0: none)."""
    terms, bits = norm_chain_bound(g, legs)
    memory = chain_memory_bound(terms, bits, g.context().nvars())
    return (terms <= IN_PROCESS_TERMS and bits <= IN_PROCESS_BITS
            and (not memory_limit or 2 * memory <= memory_limit))


def proven_small(request: EliminationRequest, memory_limit: int) -> bool:
    """Whether ``request`` is a norm chain (:func:`leg_structure`) that
    :func:`chain_is_small` proves small."""
    structure = leg_structure(request)
    return structure is not None and chain_is_small(*structure, memory_limit)


def prismatic_chain(request: EliminationRequest):
    """``(g, [(v, f_v), …])`` of :func:`leg_structure` when every leg is a single variable
    and the kept variables hold a pose angle's (cos, sin), else None.  Gröbner
    elimination struggles there: Singular computes the resultant chain instead (its
    ``eliminate`` of the 3-PRR's ξ did not finish in 10 minutes; the chain takes
    seconds), and :func:`slow_backend_refusal` turns large ones away from the slow
    backends."""
    kept = request.keep
    if not any(v.startswith("cos(") and "sin(" + v[4:] in kept for v in kept):
        return None
    structure = leg_structure(request)
    if structure is None or any(isinstance(v, tuple) for v, _ in structure[1]):
        return None
    return structure


#: Above this a-priori bound on the terms of its resultant chain (:func:`norm_chain_bound`),
#: a :func:`prismatic_chain` request is refused by SymPy and Macaulay2: on the bundled
#: 3-PRR (bound 714,425 terms; its ξ has 24,389) each ran past 10 minutes, with their
#: Gröbner elimination and with their resultants, where FLINT takes 14 ms and Singular's
#: chain 4 s.  The small robots of the cross-backend test stay under it (the 2-PRR bar:
#: 1,989).
SLOW_CHAIN_TERMS = 100_000


def slow_backend_refusal(request: EliminationRequest, backend: str) -> str | None:
    """The one-line reason why ``backend`` (sympy, macaulay2) turns ``request`` away up
    front, or None when it takes it."""
    structure = prismatic_chain(request)
    if structure is None:
        return None
    terms, _ = norm_chain_bound(*structure)
    if terms <= SLOW_CHAIN_TERMS:
        return None
    what = request.label.replace("_", " ")
    return (f"{backend} cannot compute this {what} in reasonable time: the resultant chain "
            f"over the legs may reach {terms:,} terms (a-priori bound; above "
            f"{SLOW_CHAIN_TERMS:,} with a pose angle it took over 10 minutes on the bundled "
            "3-PRR); use --backend flint or singular")
