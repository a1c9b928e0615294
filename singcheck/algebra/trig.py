"""Trajectories made algebraic: polynomials in t, s = sin t and c = cos t.

Every trajectory coordinate, and everything composed from it (μ(t) = ξ(φ(t)), the
discriminants and joint-limit polynomials along the path), lives in the ring
``TRIG = Q[t, s, c]`` taken modulo ``s² + c² - 1``.  The canonical representative
has degree at most 1 in ``s`` (:func:`reduce_trig`), so two trig polynomials are
equal as functions of t exactly when their reduced forms are equal.

``sin(k t)`` and ``cos(k t)`` for integers k are expanded exactly with Chebyshev
polynomials: ``cos(k t) = T_k(c)`` and ``sin(k t) = s · U_{k-1}(c)``.

>>> str(cos_multiple(2))
'2*c^2 - 1'
>>> str(sin_multiple(2))
'2*s*c'
>>> str(reduce_trig(S**2 + C**2))
'1'
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property

from flint import (
    arb,
    arb_poly,
    ctx,
    fmpq,
    fmpq_mat,
    fmpq_mpoly,
    fmpq_mpoly_ctx,
    fmpq_poly,
    fmpz_poly,
)

from singcheck.algebra.polynomials import exact_terms
from singcheck.budget import checkpoint

#: Q[t, s, c]; exponents are (t, s, c).
TRIG = fmpq_mpoly_ctx.get(("t", "s", "c"), "lex")
T, S, C = TRIG.gens()
_RELATION = S**2 + C**2 - 1


def reduce_trig(p: fmpq_mpoly) -> fmpq_mpoly:
    """The representative of ``p`` modulo ``s² + c² - 1`` with degree ≤ 1 in s.

    FLINT's division with remainder by s² + c² - 1: in the lex order of (t, s, c) its
    leading monomial is s², so the remainder has no term divisible by s², i.e. degree
    ≤ 1 in s, and differs from p by a multiple of s² + c² - 1.  That representative is
    unique (Q[t, c] ⊕ s·Q[t, c] meets the ideal in 0), hence the canonical form.
    """
    if p.degrees()[1] < 2:
        return p
    return divmod(p, _RELATION)[1]


def _chebyshev_in_c(poly: fmpz_poly) -> fmpq_mpoly:
    return TRIG.from_dict({(0, 0, n): int(a) for n, a in enumerate(poly.coeffs()) if a != 0})


def cos_multiple(k: int) -> fmpq_mpoly:
    """``cos(k t)`` as a polynomial in c (exact, any integer k)."""
    return _chebyshev_in_c(fmpz_poly.chebyshev_t(abs(k)))


def sin_multiple(k: int) -> fmpq_mpoly:
    """``sin(k t)`` as ``s`` times a polynomial in c (exact, any integer k)."""
    if k == 0:
        return TRIG.from_dict({})
    u = _chebyshev_in_c(fmpz_poly.chebyshev_u(abs(k) - 1))
    return S * u if k > 0 else -S * u


def uses_t(p: fmpq_mpoly) -> bool:
    """True when ``p`` depends on the bare parameter t (not only through sin/cos)."""
    return p.degrees()[0] > 0


def uses_trig(p: fmpq_mpoly) -> bool:
    """True when ``p`` depends on sin t or cos t."""
    d = p.degrees()
    return d[1] > 0 or d[2] > 0


@dataclass(frozen=True, order=False)
class LinearInPi:
    """An exact real number ``rational + pi_coefficient · π`` (range endpoints)."""

    rational: Fraction
    pi_coefficient: Fraction = Fraction(0)

    def ball(self) -> arb:
        """A rigorous enclosure at the current working precision (remembered per number
        and precision, outside the instance, which stays picklable: range ends are
        asked for their balls dozens of times per certificate)."""
        key = (id(self), ctx.prec)
        hit = _END_BALLS.get(key)
        if hit is None or hit[0] is not self:  # the entry holds self: its id is not reused
            if len(_END_BALLS) > 512:
                _END_BALLS.clear()
            hit = _END_BALLS[key] = (self, arb(fmpq(self.rational.numerator,
                                                    self.rational.denominator)) + arb(
                fmpq(self.pi_coefficient.numerator, self.pi_coefficient.denominator)
            ) * arb.pi())
        return hit[1]

    @cached_property
    def _float(self) -> float:
        return float(self.rational) + float(self.pi_coefficient) * 3.141592653589793

    def __float__(self) -> float:
        return self._float

    def __str__(self) -> str:
        parts = []
        if self.rational or not self.pi_coefficient:
            parts.append(str(self.rational))
        if self.pi_coefficient:
            k = self.pi_coefficient
            term = "pi" if k == 1 else "-pi" if k == -1 else f"{k}*pi"
            parts.append(term if not parts or term.startswith("-") else "+" + term)
        return "".join(parts)


_END_BALLS: dict[tuple[int, int], tuple[LinearInPi, arb]] = {}


@dataclass(frozen=True)
class TimeRange:
    """The closed parameter range ``[start, end]`` of a trajectory, ``start < end``."""

    start: LinearInPi
    end: LinearInPi

    def __str__(self) -> str:
        return f"[{self.start}, {self.end}]"


def derivative(p: fmpq_mpoly) -> fmpq_mpoly:
    """d/dt of a trig polynomial: ∂p/∂t + c·∂p/∂s - s·∂p/∂c (reduced).

    >>> str(derivative(S))
    'c'
    """
    return reduce_trig(p.derivative("t") + C * p.derivative("s") - S * p.derivative("c"))


def evaluate_trig(p: fmpq_mpoly, t: arb, tight: bool = False) -> arb:
    """Rigorous enclosure of ``p(t, sin t, cos t)`` for every t in the ball ``t``.

    ``p`` (reduced) is read as Σᵢ tⁱ (P₀ᵢ(c) + s·P₁ᵢ(c)) with ball-coefficient
    polynomials in c evaluated by FLINT (Horner, outward rounding), so the result
    encloses every value of p over the ball; the split is built once per polynomial
    and working precision (coefficients rounded at that precision) and memoised.

    On a wide ball Horner's rule in c = cos t overestimates badly when P has a high
    degree (its power-basis coefficients are large and alternate: cos 8t = T₈(c) has
    coefficients up to 160).  With ``tight`` (for callers that would otherwise split
    the ball), p is then also enclosed in its Fourier form
    Σᵢ tⁱ Σₖ (aᵢₖ cos kt + bᵢₖ sin kt), each sin kt and cos kt enclosed by Arb
    directly, and the narrowest of the two enclosures and their intersection is
    returned: each contains every value.
    """
    split = _split(p)
    if isinstance(split, arb_poly):  # free of sin and cos: one polynomial in t
        return split(t)
    if _high_harmonic(p):  # Horner's power coefficients cancel: the Fourier form alone
        return _fourier_value(p, t)
    s, c = _sin_cos_multiple(t, 1)
    total = evaluate_split(split, t, s, c)
    return tightened(p, t, total) if tight else total


def tightened(p: fmpq_mpoly, t: arb, total: arb) -> arb:
    """Given ``total`` = :func:`evaluate_trig` (p, t) (not ``tight``): what ``tight``
    would return, without enclosing p by Horner's rule again — on a wide ball the
    narrowest of it, the Fourier form's enclosure and their intersection (each holds
    every value of p over t); on a narrow one ``total`` itself."""
    if t.rad() > _WIDE and not isinstance(_split(p), arb_poly) and not _high_harmonic(p):
        fourier = _fourier_value(p, t)
        if fourier is not None:  # each of the three balls holds every value: the narrowest
            return min((total, fourier, total.intersection(fourier)), key=lambda b: b.rad())
    return total


def split_of(p: fmpq_mpoly):
    """For a caller enclosing ``p`` over many balls: a function giving ``_split(p)`` at
    the current precision, when :func:`evaluate_trig` (not ``tight``) would enclose p by
    :func:`evaluate_split` (a trig polynomial below :data:`FOURIER_ALWAYS`); else None."""
    if p.context() is not TRIG or _high_harmonic(p):
        return None
    return lambda: _split(p)  # (memoised there, per polynomial and precision)


def evaluate_split(split, t: arb, s: arb, c: arb) -> arb:
    """The enclosure :func:`evaluate_trig` (not ``tight``) makes from ``_split(p)`` at
    the current precision, given Arb's balls of sin t and cos t over the ball t: for
    callers that enclose several polynomials over one ball (sin t, cos t once)."""
    if type(split) is tuple:  # free of t: P₀(c) + s·P₁(c)
        p0, p1 = split
        return p0(c) if p1 is None else p0(c) + s * p1(c)
    if isinstance(split, arb_poly):  # free of sin and cos: one polynomial in t
        return split(t)
    total = arb(0)
    for p0, p1 in reversed(split):
        total = total * t + p0(c) + s * p1(c)
    return total


def evaluate_trig_at(p: fmpq_mpoly, t: arb, s: arb, c: arb) -> arb:
    """Rigorous enclosure of ``p(t, s, c)`` for every point of the balls t, s, c (any
    values: a pose angle's sin and cos, not t's), in the form of :func:`evaluate_trig`:
    Σᵢ tⁱ (P₀ᵢ(c) + s·P₁ᵢ(c)) with ball polynomials (``p`` reduced or not: its own
    terms are used, and s² is not replaced, so no relation between s and c is assumed)."""
    split = _split_raw(p)
    if isinstance(split, arb_poly):
        return split(t)
    total = arb(0)
    for parts in reversed(split):
        value = arb(0)
        for part in reversed(parts):
            value = value * s + part(c)
        total = total * t + value
    return total


_RAW_SPLITS: OrderedDict[tuple[int, int], tuple[fmpq_mpoly, object]] = OrderedDict()


def _split_raw(p: fmpq_mpoly):
    """[[P_ij(c) for each power j of s] for each power i of t] as ball polynomials at the
    current precision (p as it is, not reduced), or one polynomial in t when p is free
    of s and c; memoised like :func:`_split`."""
    key = (id(p), ctx.prec)
    hit = _RAW_SPLITS.get(key)
    if hit is not None and hit[0] is p:
        return hit[1]
    dt, ds, dc = p.degrees()
    if ds == 0 and dc == 0:
        by_t = [fmpq(0)] * (dt + 1)
        for (i, _, _), a in p.terms():
            by_t[i] = a
        split = arb_poly(fmpq_poly(by_t))
    else:
        coeffs = [[[fmpq(0)] * (dc + 1) for _ in range(ds + 1)] for _ in range(dt + 1)]
        for (i, j, k), a in p.terms():
            coeffs[i][j][k] = a
        split = [[arb_poly([arb(a) for a in row]) for row in by_t] for by_t in coeffs]
    _RAW_SPLITS[key] = (p, split)
    if len(_RAW_SPLITS) > _SPLITS_KEPT:
        _RAW_SPLITS.popitem(last=False)
    return split


#: balls wider than this (radius) are also enclosed through the Fourier form
_WIDE = 1e-3
#: ... for polynomials of at least this degree in c (lower ones barely wrap)
_FOURIER_MIN_DEGREE = 4


#: a polynomial of at least this degree in (s, c) is always enclosed in its Fourier form:
#: its power coefficients (cos 64t = T₆₄(c): up to 2⁶³) cancel, and Horner on any ball —
#: even a point — loses every bit at double precision
FOURIER_ALWAYS = 24


_HIGH: dict[int, tuple[fmpq_mpoly, bool]] = {}


def _high_harmonic(p: fmpq_mpoly) -> bool:
    """Whether p's degree in (s, c) reaches :data:`FOURIER_ALWAYS` (memoised: asked at
    every enclosure)."""
    hit = _HIGH.get(id(p))
    if hit is None or hit[0] is not p:
        if len(_HIGH) > 1024:
            _HIGH.clear()
        d = p.degrees()
        hit = _HIGH[id(p)] = (p, len(d) == 3 and d[1] + d[2] >= FOURIER_ALWAYS)
    return hit[1]


_LAST_T: tuple = (None, 0, {})  # (t, precision, {k: (sin kt, cos kt)})


def _sin_cos_multiple(t: arb, k: int) -> tuple[arb, arb]:
    """Arb's enclosures of sin kt and cos kt over the ball t, remembered for the last
    ball asked for (a leg's coefficients and discriminant are evaluated at the same t
    one after another).  The memo is replaced whole, never edited for another t, so
    threads sharing it cannot mix two balls' values."""
    global _LAST_T
    last = _LAST_T
    if last[0] is t and last[1] == ctx.prec:
        values = last[2]
    else:
        values = {}
        _LAST_T = (t, ctx.prec, values)
    hit = values.get(k)
    if hit is None:
        hit = values[k] = (t if k == 1 else k * t).sin_cos()
    return hit


#: a ball of t wider than this (radius) gets the Fourier form of a trig polynomial of
#: degree FOURIER_DEGREE or more in (sin t, cos t) where the interval engine encloses a
#: path (:func:`fourier_enclosure`): tighter than Horner's rule in cos t on a wide ball
#: (the 8-harmonic heart: 431 -> 174 balls of t), no tighter and dearer on a narrow one
#: or at a low degree (heart 1, degrees 3 and 4: the same 71 balls either way)
FOURIER_WIDE = 1e-3
FOURIER_DEGREE = 6


def fourier_enclosure(p: fmpq_mpoly, t: arb) -> arb | None:
    """The Fourier-form enclosure of the trig polynomial p over the ball t (each sin kt,
    cos kt enclosed by Arb: :func:`evaluate_trig`'s ``tight`` form), or None when p's
    degree in (s, c) is below :data:`FOURIER_DEGREE` (its Horner form in c serves)."""
    return _fourier_value(p, t, FOURIER_DEGREE)


def _fourier_value(p: fmpq_mpoly, t: arb, low: int = 0) -> arb | None:
    """The Fourier-form enclosure of p over the ball t (None when p's degree in (s, c)
    is below :data:`_FOURIER_MIN_DEGREE`, or ``low`` when given)."""
    form = _fourier(p)
    if form is None or form[3] < (low or _FOURIER_MIN_DEGREE):
        return None
    terms, harmonics, dt, _ = form
    return fourier_sum(terms, dt, t, {k: _sin_cos_multiple(t, k) for k in harmonics})


def fourier_sum(terms: list, dt: int, t: arb, multiples: dict) -> arb:
    """Σ tⁱ (a cos kT + b sin kT) over the Fourier terms (i, k, a, b) of
    :func:`_fourier` (degree ``dt`` in t), with Arb's balls of sin kT and cos kT from
    ``multiples`` (k → (sin kT, cos kT); a missing k is enclosed and added)."""
    powers = [arb(1), t]
    for _ in range(dt - 1):
        powers.append(powers[-1] * t)
    total = arb(0)
    for i, k, a, b in terms:
        if k == 0:
            term = a
        else:
            sc = multiples.get(k)
            if sc is None:
                sc = multiples[k] = (k * t).sin_cos()
            sin_k, cos_k = sc
            term = a * cos_k if a is not None else b * sin_k
            if a is not None and b is not None:
                term += b * sin_k
        total += term if i == 0 else term * powers[i]
    return total


_FOURIERS: OrderedDict[tuple[int, int], tuple[fmpq_mpoly, object]] = OrderedDict()


def _fourier(p: fmpq_mpoly):
    """(terms, harmonics, degree in t) with terms (i, k, a, b) for tⁱ(a cos kt + b sin kt),
    balls at the current precision, None when p's degree in (s, c) is low; memoised like
    the split (the exact form once per polynomial, its balls per precision).

    The power bases are changed to the Chebyshev ones (cᵐ = Σₖ Mₖₘ Tₖ(c) with
    Tₖ(c) = cos kt, s·cᵐ = Σₖ Nₖₘ s·Uₖ(c) with s·Uₖ(c) = sin (k+1)t) exactly, by one
    rational matrix product per part (:func:`fourier_form`); each ball coefficient is
    then the exact one rounded outward.  (A ball product would be useless for a high
    harmonic: cos 256t = T₂₅₆(c) has power coefficients near 2²⁵⁵ that cancel.)"""
    key = (id(p), ctx.prec)
    hit = _FOURIERS.get(key)
    if hit is not None and hit[0] is p:
        _FOURIERS.move_to_end(key)
        return hit[1]
    exact = fourier_form(p)
    form = None
    if exact is not None:
        terms = [(i, k, None if a is None else arb(a), None if b is None else arb(b))
                 for i, k, a, b in exact]
        form = (terms, sorted({k for _, k, _, _ in terms if k}),
                max((i for i, _, _, _ in terms), default=0), _sc_degree(p))
    _FOURIERS[key] = (p, form)
    if len(_FOURIERS) > _SPLITS_KEPT:
        _FOURIERS.popitem(last=False)
    return form


_EXACT_FOURIERS: OrderedDict[int, tuple[fmpq_mpoly, object]] = OrderedDict()


def _sc_degree(p: fmpq_mpoly) -> int:
    """p's degree in (s, c) once reduced (s² = 1 - c²)."""
    d = reduce_trig(p).degrees()
    return int(max(d[1], 0) + max(d[2], 0))


def fourier_form(p: fmpq_mpoly) -> list | None:
    """p(t, sin t, cos t) as Σ tⁱ (a cos kt + b sin kt) with exact rational a, b: the
    terms (i, k, a, b) (a or b None where absent), None when p is free of s and c;
    memoised per polynomial."""
    if p.context() is not TRIG:  # (a path ring's polynomial: restrict it first)
        return None
    hit = _EXACT_FOURIERS.get(id(p))
    if hit is not None and hit[0] is p:
        return hit[1]
    q = reduce_trig(p)
    form = None
    if not q.is_zero() and q.degrees()[2] + q.degrees()[1] >= 1:
        parts: dict[tuple[int, int], dict[int, fmpq]] = {}
        for (i, j, k), a in q.terms():
            parts.setdefault((i, j), {})[k] = a
        found: dict[tuple[int, int], list] = {}
        for (i, j), part in parts.items():
            n = max(part)
            column = fmpq_mat(n + 1, 1, [part.get(m, 0) for m in range(n + 1)])
            product = _chebyshev_change(n, j) * column
            for k in range(n + 1):
                value = product[k, 0]
                if value != 0:
                    harmonic = k if j == 0 else k + 1
                    found.setdefault((i, harmonic), [None, None])[j] = value
        form = [(i, k, a, b) for (i, k), (a, b) in sorted(found.items())]
    _EXACT_FOURIERS[id(p)] = (p, form)
    if len(_EXACT_FOURIERS) > _SPLITS_KEPT:
        _EXACT_FOURIERS.popitem(last=False)
    return form


_CHEBYSHEV: dict[tuple[int, int], fmpq_mat] = {}


def _chebyshev_change(n: int, part: int) -> fmpq_mat:
    """The (n+1)×(n+1) rational matrix taking power coefficients c⁰…cⁿ to Chebyshev
    ones: T₀…Tₙ for ``part`` 0, U₀…Uₙ for ``part`` 1 (from c·Tₖ = (Tₖ₊₁ + T|ₖ₋₁|)/2 and
    c·Uₖ = (Uₖ₊₁ + Uₖ₋₁)/2 with U₋₁ = 0).

    Its cost grows as n² in Python (0.4 s of CPU at n = 512, 1.5 s at 1024: a rotary
    Delta path with sin(255t) ran 8.9 s past a 1 s limit here), so a
    :func:`~singcheck.budget.checkpoint` comes before each column and each row."""
    key = (n, part)
    hit = _CHEBYSHEV.get(key)
    if hit is None:
        columns = [[fmpq(1)] + [fmpq(0)] * n]
        for _ in range(n):
            checkpoint()
            prev, nxt = columns[-1], [fmpq(0)] * (n + 1)
            for k, a in enumerate(prev):
                if a == 0:
                    continue
                if k + 1 <= n:
                    nxt[k + 1] += a / 2
                if k >= 1:
                    nxt[k - 1] += a / 2
                elif part == 0:  # c·T₀ = T₁
                    nxt[1] += a / 2
            columns.append(nxt)
        entries: list = []
        for k in range(n + 1):
            checkpoint()
            entries += [columns[m][k] for m in range(n + 1)]
        hit = _CHEBYSHEV[key] = fmpq_mat(n + 1, n + 1, entries)
    return hit


#: id(p) -> (p, {precision: split}); the entry holds p, so its id is not reused
_SPLITS: OrderedDict[int, tuple[fmpq_mpoly, dict]] = OrderedDict()
_SPLITS_KEPT = 512


def _split(p: fmpq_mpoly) -> list[tuple[arb_poly, arb_poly]] | tuple | arb_poly:
    """[(P₀ᵢ, P₁ᵢ) for i = 0 … deg_t p] as ball polynomials at the current precision;
    a polynomial free of t: the pair (P₀, P₁) itself (P₁ None when p is free of s, whose
    term s·P₁(c) is then an exact 0); free of sin and cos: one ball polynomial in t.
    Memoised per polynomial and precision (the first one in dropped past
    :data:`_SPLITS_KEPT`)."""
    hit = _SPLITS.get(id(p))
    if hit is not None and hit[0] is p:
        split = hit[1].get(ctx.prec)
        if split is not None:  # (not moved to the end: first in, first dropped)
            return split
    else:
        hit = (p, {})
    exact = hit[1].get("exact")
    if exact is None:  # the exact split once per polynomial, whatever the precision
        exact = hit[1]["exact"] = _exact_split(p)
    split = hit[1][ctx.prec] = _balls_of(exact)
    _SPLITS[id(p)] = hit
    if len(_SPLITS) > _SPLITS_KEPT:
        _SPLITS.popitem(last=False)
    return split


def sin_cos_parts(q: fmpq_mpoly) -> tuple[fmpq_poly, fmpq_poly | None]:
    """(P₀, P₁) with q = P₀(c) + s·P₁(c), univariate in c, for a reduced ``q`` free of t
    (P₁ None when q is free of s): P₀ = q(s = 0) and s·P₁ = q - P₀."""
    if q.degrees()[1] <= 0:
        return _in_c(q), None
    p0 = q.subs({"s": 0})
    return _in_c(p0), _in_c((q - p0) / S)


def _in_c(q: fmpq_mpoly) -> fmpq_poly:
    """A polynomial of the trig ring in c alone as a univariate polynomial in c."""
    cs = q.coeffs()
    top = q.degrees()[2]
    if len(cs) == top + 1:  # dense: its terms are c^top, …, c^0 in that order
        return fmpq_poly(cs[::-1])
    by_power = [fmpq(0)] * (top + 1)
    for (_, _, k), a in q.terms():
        by_power[k] = a
    return fmpq_poly(by_power)


def _split_at_precision(p: fmpq_mpoly):
    """:func:`_split` at the current precision (FLINT rounds each rational coefficient
    outward when it makes the ball polynomial from an exact one)."""
    return _balls_of(_exact_split(p))


def _exact_split(p: fmpq_mpoly):
    """The shape of :func:`_split` with exact polynomials (``fmpq_poly``): reading a
    polynomial's terms costs more than rounding them (a long spline's coefficients run
    to thousands of digits), so it is done once per polynomial, not per precision."""
    dt, ds, dc = p.degrees()
    q = p if ds <= 0 and dc <= 0 else reduce_trig(p)  # free of s and c: reduced already
    dt, ds, dc = q.degrees()
    if ds <= 0 and dc <= 0:
        by_t = [fmpq(0)] * (max(dt, 0) + 1)
        for (i, _, _), a in exact_terms(q):
            by_t[i] = a
        return fmpq_poly(by_t)
    if dt <= 0 and dc >= 0:
        return sin_cos_parts(q)
    rows = [([0] * (dc + 1), [0] * (dc + 1)) for _ in range(dt + 1)]
    # (monomials and coefficients: a third faster to read than terms())
    for (i, j, k), a in zip(q.monoms(), q.coeffs(), strict=True):
        rows[i][j][k] = a
    return [(fmpq_poly(r0), fmpq_poly(r1)) for r0, r1 in rows]


def _balls_of(exact):
    """:func:`_exact_split`'s polynomials as ball polynomials at the current precision."""
    if isinstance(exact, fmpq_poly):
        return arb_poly(exact)
    if type(exact) is tuple:
        p0, p1 = exact
        return (arb_poly(p0), arb_poly(p1) if p1 is not None else None)
    return [tuple(arb_poly(row) for row in by_t) for by_t in exact]


#: :func:`_split` under a public name: the ball polynomials :func:`evaluate_split` takes
ball_split = _split
