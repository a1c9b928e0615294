"""Composition ``p(f₁, …, fₙ)`` of polynomials in pieces that a time limit can stop.

FLINT composes in one call, which no :func:`~singcheck.budget.checkpoint` can interrupt:
the stacked Orthoglide's ξ (57,855 terms) composed with a path of cubes took seconds
past a 2 s time limit.  So the cost is estimated first, from the sizes alone (exact
integer arithmetic on degrees, bit lengths and term counts, :func:`composition_work`):

* above :data:`MAX_COMPOSE_WORK` the composition is refused before any work
  (:class:`TooCostly`);
* up to :data:`PIECE_WORK` it is one FLINT call (the common case: heart 1, heart 2,
  the helix);
* in between it is Horner's scheme in ``p``'s variables, each group of terms whose
  estimate is at most :data:`PIECE_WORK` composed in one FLINT call and every product
  cut into pieces of at most :data:`PIECE_PAIRS` term pairs, with a checkpoint before
  each call: the time limit stops it within about one piece.

Every intermediate is reduced (``reduce``: s² = 1 - c², √q² = q), which is a ring
homomorphism, so the result is the same polynomial as one call's, reduced.
"""

from __future__ import annotations

from collections.abc import Callable

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import (
    _height_bits,
    exact_terms,
    memo_per_object,
    with_unit_coefficients,
)
from singcheck.budget import checkpoint

#: The most work (:func:`composition_work`) one FLINT composition call may get.  On the
#: development machine the rate was 4·10⁸ to 6·10⁹ per second of CPU depending on the
#: shape of the path (stacked Orthoglide, eight paths): 0.02 to 0.25 s a piece.
PIECE_WORK = 100_000_000
#: The most term pairs one multiplication in Horner's scheme may get.
PIECE_PAIRS = 2_000_000
#: The most work a whole composition may cost: refused up front above it (15 s to 8 min
#: of CPU at those rates; the slowest measured shapes 4·10⁸ per second, large
#: coefficients 1.4·10¹⁰).  The stacked Orthoglide's ξ with each coordinate a cube
#: (sin t ± cos t ± k·t)³ costs 2.1·10¹⁰ (4 s in one call, 6 s in pieces); heart 2 on
#: it 7.7·10⁷; with coordinates of 2,000-bit coefficients times (sin t + cos t + t),
#: 7.5·10¹⁰ (5 s).
MAX_COMPOSE_WORK = 200_000_000_000


class TooCostly(ValueError):
    """Work refused up front: its a-priori estimate is over a bound (the message says
    both)."""


def _bits(p: fmpq_mpoly) -> int:
    """The most bits of a numerator or denominator of ``p``'s coefficients."""
    return max((c.height_bits() for _, c in exact_terms(p)), default=0)


_WEIGHTS: dict = {}
_BITS: dict = {}


def _weight(a: fmpq_mpoly) -> tuple[int, int, int]:
    """An argument's degree in the first variable (t), its total degree in the others,
    and the bits of its coefficients (0, 0, 0 for zero), once per argument object."""
    def compute(a: fmpq_mpoly) -> tuple[int, int, int]:
        degrees = [max(0, int(d)) for d in a.degrees()]
        return degrees[0], sum(degrees[1:]), _bits(a)

    return memo_per_object(_WEIGHTS, a, compute, keep=1024)


def _weights(args: list[fmpq_mpoly]) -> list[tuple[int, int, int]]:
    return [_weight(a) for a in args]


def _cost(a: int, b: int, bits: int, widest: int) -> int:
    """The estimated cost of one image of degree a in t and b in the rest, of ``bits``."""
    return (a + 1) * (2 * b + 1) * (1 + bits // 64) * widest


_TOP_BITS: dict = {}  # the largest coefficient bits of each composed polynomial
_ABW = fmpq_mpoly_ctx.get(("a", "b", "w"), "lex")


def composition_work(p: fmpq_mpoly, args: list[fmpq_mpoly]) -> tuple[int, int, int]:
    """(the a-priori work of ``p(args)``, the largest degree in the first variable (t)
    and in the others of an image of a term).  Nothing is composed and no Python loop
    runs over ``p``'s terms: ``p`` with every coefficient 1 (once per ``p``), composed
    with xᵢ = aᵈᵗ·bᵈʳ·wᵇⁱᵗˢ, cannot cancel, and counts the terms per (a, b, bits).

    Per term, a reduced trig polynomial of degree a in t and b in (s, c) has at most
    (a + 1)(2b + 1) terms; the work is that times the 64-bit words of its coefficients
    (the argument's bits times their exponents, plus ``p``'s largest coefficient) and
    the terms of the longest argument.  An estimate for cutting and refusing work; no
    answer's correctness rests on it."""
    if p.is_zero():
        return 0, 0, 0
    ones, top_bits = with_unit_coefficients(p), memo_per_object(_TOP_BITS, p, _height_bits)
    degrees = p.degrees()
    used = [a for a, d in zip(args, degrees, strict=True) if d > 0]
    widest = max([len(a) for a in used] or [1])
    a, b, w = _ABW.gens()
    images = ones.compose(*[a**dt * b**dr * w**bits for dt, dr, bits in _weights(args)],
                          ctx=_ABW)
    work = sum(int(n) * _cost(int(e[0]), int(e[1]), int(e[2]) + top_bits, widest)
               for e, n in zip(images.monoms(), images.coeffs(), strict=True))
    top = images.degrees()
    return work, max(0, int(top[0])), max(0, int(top[1]))


def term_costs(p: fmpq_mpoly, args: list[fmpq_mpoly]) -> list[int]:
    """Per term of ``p``, its part of :func:`composition_work` (the coefficient's own
    bits counted exactly): a Python loop, run only on compositions cut into pieces."""
    weights = _weights(args)
    widest = max([len(x) for x, d in zip(args, p.degrees(), strict=True) if d > 0] or [1])
    costs = []
    for exps, coeff in zip(p.monoms(), p.coeffs(), strict=True):
        a = b = bits = 0
        for e, (dt, dr, bt) in zip(exps, weights, strict=True):
            if e:
                e = int(e)
                a, b, bits = a + e * dt, b + e * dr, bits + e * bt
        bits += max(coeff.numer().bit_length(), coeff.denom().bit_length())
        costs.append(_cost(a, b, bits, widest))
    return costs


def crude_work(p: fmpq_mpoly, args: list[fmpq_mpoly]) -> tuple[int, int, int]:
    """Upper bounds on the three numbers of :func:`composition_work`, from ``p``'s
    degree in each variable alone: every term is charged what the largest exponents of
    all variables together would cost, so its degrees in t and in the others, its bits
    and hence its cost are at least any real term's.  No Python loop over ``p``'s terms
    and no composition: for ruling out the exact estimate when it cannot matter."""
    a = b = bits = 0
    widest = 1
    for d, x in zip(p.degrees(), args, strict=True):
        if d > 0:
            d = int(d)
            dt, dr, bt = _weight(x)
            a, b, bits = a + d * dt, b + d * dr, bits + d * bt
            widest = max(widest, len(x))
    bits += memo_per_object(_BITS, p, _bits, keep=1024)
    return len(p) * _cost(a, b, bits, widest), a, b


def _small(p: fmpq_mpoly, args: list[fmpq_mpoly]) -> bool:
    """Whether the crude bound (:func:`crude_work`) already keeps the whole composition
    within :data:`PIECE_WORK`: a leg's coefficient, a small robot's ξ."""
    return crude_work(p, args)[0] <= PIECE_WORK


def compose_in_pieces(p: fmpq_mpoly, args: list[fmpq_mpoly], ring: fmpq_mpoly_ctx,
                      reduce: Callable[[fmpq_mpoly], fmpq_mpoly],
                      work: int | None = None) -> fmpq_mpoly:
    """``reduce(p(args))`` in ``ring``, refused or cut into pieces by its estimated
    cost (``work``: :func:`composition_work`'s, when already known)."""
    if work is None:
        if _small(p, args):
            return reduce(p.compose(*args, ctx=ring))
        work = composition_work(p, args)[0]
    if work > MAX_COMPOSE_WORK:
        raise TooCostly(f"composing would cost {work:.3g} by its a-priori estimate "
                        f"(at most {MAX_COMPOSE_WORK:.3g})")
    if work <= PIECE_WORK:
        return reduce(p.compose(*args, ctx=ring))
    items = list(zip(p.monoms(), p.coeffs(), term_costs(p, args), strict=True))
    return _horner(items, 0, p.context(), args, ring, reduce)


def _horner(items: list, var: int, source: fmpq_mpoly_ctx, args: list[fmpq_mpoly],
            ring: fmpq_mpoly_ctx, reduce) -> fmpq_mpoly:
    """Σ over ``items`` (exponents, coefficient, cost) of their images, the exponents of
    the variables before ``var`` left out (the caller multiplies by them)."""
    if var == len(args) or sum(cost for *_, cost in items) <= PIECE_WORK:
        lead = (0,) * var
        checkpoint()
        piece = source.from_dict({lead + tuple(int(e) for e in exps[var:]): c
                                  for exps, c, _ in items})
        return reduce(piece.compose(*args, ctx=ring))
    groups: dict[int, list] = {}
    for item in items:
        groups.setdefault(int(item[0][var]), []).append(item)
    top = max(groups)
    out = ring.from_dict({})
    for k in range(top, -1, -1):
        if k != top:
            out = multiply_in_pieces(out, args[var], reduce)
        if k in groups:
            out += _horner(groups[k], var + 1, source, args, ring, reduce)
    return out


def multiply_in_pieces(a: fmpq_mpoly, b: fmpq_mpoly,
                       reduce: Callable[[fmpq_mpoly], fmpq_mpoly],
                       pairs: int | None = None) -> fmpq_mpoly:
    """``reduce(a·b)``, ``b`` cut so that each product has at most ``pairs`` (default
    :data:`PIECE_PAIRS`) term pairs, with a checkpoint before each.  The same polynomial
    as one product: ``reduce`` (a normal form modulo fixed relations, or the identity)
    is linear."""
    pairs = PIECE_PAIRS if pairs is None else pairs
    checkpoint()
    if len(a) * len(b) <= pairs:
        return reduce(a * b)
    step = max(1, pairs // max(len(a), 1))
    terms = list(zip(b.monoms(), b.coeffs(), strict=True))
    ctx = b.context()
    out = ctx.from_dict({})
    for i in range(0, len(terms), step):
        checkpoint()
        out += reduce(a * ctx.from_dict(dict((tuple(e), c) for e, c in terms[i:i + step])))
    return out
