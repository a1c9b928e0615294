"""Exact algebraic numbers built from square roots, and angles as (cos, sin) pairs.

**Numbers.**  A :class:`Surd` is an exact element of the multiquadratic field
Q(√2, √3, √5, …): a finite sum Σ q_m·√m over squarefree integers m ≥ 1 with rational
q_m.  The square roots of distinct squarefree integers are linearly independent over Q,
so this representation is canonical: equality and the zero test are exact comparisons
of the dictionaries.  Products use √a·√b = g·√(ab/g²) (g = gcd(a, b)); an inverse
multiplies by the conjugate in one prime at a time (x·σₚ(x) no longer involves √p).

**In polynomials** a surd becomes a polynomial in one variable ``sqrt(p)`` per prime p
(√6 = sqrt(2)·sqrt(3)), reduced modulo ``sqrt(p)² = p``; :func:`norm_radicals` takes a
polynomial back to Q by resultants with ``sqrt(p)² - p`` (the product over both signs of
each root: every conjugate's zero set together).

**Angles.**  An angle v enters a polynomial as ``cos(v)`` and ``sin(v)`` with
``cos(v)² + sin(v)² = 1``; :func:`reduce_relations` keeps the representative of degree
≤ 1 in each ``sin(v)`` (and ≤ 1 in each ``sqrt(p)``), so two reduced polynomials are
equal on the circles exactly when they are equal.  ``cos(Σ kᵢvᵢ + qπ)`` is expanded
exactly by :func:`expand_trig` (de Moivre), with ``cos(qπ)``, ``sin(qπ)`` exact surds
when 12q is an integer (:func:`cos_pi`).

>>> str(Surd.sqrt(Fraction(12)) * Surd.sqrt(Fraction(3)))
'6'
>>> str(cos_pi(Fraction(1, 12)))
'1/4*sqrt(2) + 1/4*sqrt(6)'
"""

from __future__ import annotations

import math
import re
from fractions import Fraction

from flint import arb, ctx, fmpq, fmpq_mpoly, fmpq_mpoly_ctx, fmpz

from singcheck.algebra.intervals import power
from singcheck.algebra.opaque import has_opaque_coordinates, is_opaque, opaque_ball, opaque_of
from singcheck.algebra.polynomials import memo_per_object
from singcheck.algebra.trig import TRIG, evaluate_trig, evaluate_trig_at

MAX_RADICAND_BITS = 64
_RADICAL = re.compile(r"sqrt\((\d+)\)\Z")


def radical_name(p: int) -> str:
    """The polynomial variable of √p (p prime)."""
    return f"sqrt({p})"


def radical_prime(name: str) -> int | None:
    """p when ``name`` is the variable of √p, else None."""
    hit = _RADICAL_PRIMES.get(name, _MISSING)
    if hit is _MISSING:
        m = _RADICAL.match(name)
        hit = int(m.group(1)) if m else None
        if len(_RADICAL_PRIMES) < 4096:  # names of variables: few, asked for per path
            _RADICAL_PRIMES[name] = hit
    return hit


_RADICAL_PRIMES: dict[str, int | None] = {}
_MISSING = object()


def angle_names(v: str) -> tuple[str, str]:
    """The polynomial variables of an angle: ``(cos(v), sin(v))``."""
    return f"cos({v})", f"sin({v})"


def _squarefree(n: int) -> tuple[int, int]:
    """(k, m) with n = k²·m and m squarefree (n ≥ 1)."""
    k, m = 1, 1
    for p, e in fmpz(n).factor():
        k *= int(p) ** (e // 2)
        if e % 2:
            m *= int(p)
    return k, m


def _primes(m: int) -> list[int]:
    return [int(p) for p, _ in fmpz(m).factor()] if m > 1 else []


class Surd:
    """An exact element Σ q_m·√m of Q(√2, √3, …) (m squarefree, q_m ≠ 0)."""

    __slots__ = ("terms",)

    def __init__(self, terms: dict[int, Fraction] | None = None) -> None:
        self.terms = {m: Fraction(q) for m, q in (terms or {}).items() if q}

    @classmethod
    def rational(cls, q) -> Surd:
        return cls({1: Fraction(q)})

    @classmethod
    def sqrt(cls, q: Fraction) -> Surd:
        """√q of a rational q ≥ 0, exactly (√(a/b) = √(ab)/b)."""
        q = Fraction(q)
        if q < 0:
            raise ValueError("the square root of a negative number is not real")
        if q == 0:
            return cls()
        n = q.numerator * q.denominator
        if max(n.bit_length(), 1) > MAX_RADICAND_BITS:
            raise ValueError(f"the radicand {q} is too large")
        k, m = _squarefree(n)
        return cls({m: Fraction(k, q.denominator)})

    def is_rational(self) -> bool:
        return set(self.terms) <= {1}

    def rational_value(self) -> Fraction:
        if not self.is_rational():
            raise ValueError(f"{self} is not rational")
        return self.terms.get(1, Fraction(0))

    def primes(self) -> set[int]:
        return {p for m in self.terms for p in _primes(m)}

    def __bool__(self) -> bool:
        return bool(self.terms)

    def __eq__(self, other) -> bool:
        if isinstance(other, (int, Fraction)):
            other = Surd.rational(other)
        return isinstance(other, Surd) and self.terms == other.terms

    def __hash__(self) -> int:
        return hash(frozenset(self.terms.items()))

    def __neg__(self) -> Surd:
        return Surd({m: -q for m, q in self.terms.items()})

    def __add__(self, other) -> Surd:
        other = _as_surd(other)
        out = dict(self.terms)
        for m, q in other.terms.items():
            out[m] = out.get(m, Fraction(0)) + q
        return Surd(out)

    __radd__ = __add__

    def __sub__(self, other) -> Surd:
        return self + (-_as_surd(other))

    def __rsub__(self, other) -> Surd:
        return _as_surd(other) - self

    def __mul__(self, other) -> Surd:
        other = _as_surd(other)
        out: dict[int, Fraction] = {}
        for a, p in self.terms.items():
            for b, q in other.terms.items():
                g = math.gcd(a, b)
                m = (a // g) * (b // g)
                out[m] = out.get(m, Fraction(0)) + p * q * g
        return Surd(out)

    __rmul__ = __mul__

    def conjugate(self, p: int) -> Surd:
        """σₚ: √p ↦ -√p."""
        return Surd({m: (-q if m % p == 0 else q) for m, q in self.terms.items()})

    def inverse(self) -> Surd:
        if not self:
            raise ZeroDivisionError("division by zero")
        x, factor = self, Surd.rational(1)
        while not x.is_rational():
            p = min(x.primes())
            c = x.conjugate(p)
            factor, x = factor * c, x * c
        return factor * Surd.rational(1 / x.rational_value())

    def __truediv__(self, other) -> Surd:
        return self * _as_surd(other).inverse()

    def __rtruediv__(self, other) -> Surd:
        return _as_surd(other) * self.inverse()

    def __pow__(self, e: int) -> Surd:
        out, base = Surd.rational(1), self
        while e:
            if e & 1:
                out = out * base
            base, e = base * base, e >> 1
        return out

    def ball(self) -> arb:
        """A rigorous enclosure at the current working precision."""
        total = arb(0)
        for m, q in self.terms.items():
            total += arb(fmpq(q.numerator, q.denominator)) * arb(m).sqrt()
        return total

    def __float__(self) -> float:
        return float(sum(float(q) * math.sqrt(m) for m, q in self.terms.items()))

    def __str__(self) -> str:
        if not self.terms:
            return "0"
        parts = []
        for m in sorted(self.terms):
            q = self.terms[m]
            if m == 1:
                parts.append(str(q))
            else:
                coeff = "" if q == 1 else "-" if q == -1 else f"{q}*"
                parts.append(f"{coeff}sqrt({m})")
        return " + ".join(parts).replace("+ -", "- ")

    __repr__ = __str__


def _as_surd(x) -> Surd:
    return x if isinstance(x, Surd) else Surd.rational(x)


def cos_pi(q: Fraction) -> Surd | None:
    """cos(qπ) exactly when 12q is an integer (the angles with surd cosines we use).
    The same Surd object for the same q (a surd is never changed in place): the working
    modes ask for a 5-bar's limits at every path."""
    q = Fraction(q)
    hit = _COS_PI.get(q, _MISSING)
    if hit is _MISSING:
        if len(_COS_PI) > 4096:
            _COS_PI.clear()
        hit = _COS_PI[q] = _cos_pi(q)
    return hit


_COS_PI: dict[Fraction, Surd | None] = {}
_MISSING = object()


def _cos_pi(q: Fraction) -> Surd | None:
    if (12 * q).denominator != 1:
        return None
    j = int(12 * q) % 24
    if j > 12:
        j = 24 - j  # cos is even and 2π-periodic
    sign = 1
    if j > 6:
        j, sign = 12 - j, -1  # cos(π - x) = -cos x
    if not _COS_TABLE:
        _COS_TABLE.update({0: Surd.rational(1),
                           1: (Surd.sqrt(Fraction(6)) + Surd.sqrt(Fraction(2))) / 4,
                           2: Surd.sqrt(Fraction(3)) / 2,
                           3: Surd.sqrt(Fraction(2)) / 2,
                           4: Surd.rational(Fraction(1, 2)),
                           5: (Surd.sqrt(Fraction(6)) - Surd.sqrt(Fraction(2))) / 4,
                           6: Surd()})
    return _COS_TABLE[j] * sign


#: cos(jπ/12) for j = 0 … 6, built on first use (exact surd arithmetic: not at import,
#: and not again for every angle of every path)
_COS_TABLE: dict[int, Surd] = {}


def sin_pi(q: Fraction) -> Surd | None:
    """sin(qπ) = cos((1/2 - q)π), exactly when 12q is an integer."""
    return cos_pi(Fraction(1, 2) - Fraction(q))


def surd_polynomial(value: Surd, ctx: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """``value`` as a polynomial in the ``sqrt(p)`` variables of ``ctx``."""
    names = ctx.names()
    out = ctx.from_dict({})
    for m, q in value.terms.items():
        term = ctx.from_dict({(0,) * ctx.nvars(): fmpq(q.numerator, q.denominator)})
        for p in _primes(m):
            name = radical_name(p)
            if name not in names:
                raise ValueError(f"√{p} has no variable in this ring")
            term *= ctx.gens()[names.index(name)]
        out += term
    return out


def constant_surd(p: fmpq_mpoly) -> Surd | None:
    """The exact number a polynomial in the ``sqrt(q)`` variables alone stands for (its
    terms Σ c·√q₁·…·√qₖ summed in the multiquadratic field), or None when it involves any
    other variable.  Inverse of :func:`surd_polynomial`.

    >>> ctx = fmpq_mpoly_ctx.get(("x", "sqrt(2)", "sqrt(3)"), "lex")
    >>> _, r2, r3 = ctx.gens()
    >>> str(constant_surd(r2 * r3 / 2 + r3 ** 2))
    '3 + 1/2*sqrt(6)'
    >>> constant_surd(ctx.gens()[0] + r2) is None
    True
    """
    primes = {i: q for i, q in radical_variables(p.context())}
    total = Surd()
    for exps, coeff in p.terms():
        if any(e and i not in primes for i, e in enumerate(exps)):
            return None
        term = Surd.rational(Fraction(int(coeff.p), int(coeff.q)))
        for i, e in enumerate(exps):
            if e:
                term = term * Surd.sqrt(Fraction(primes[i])) ** e
        total = total + term
    return total


def radical_variables(ctx: fmpq_mpoly_ctx) -> list[tuple[int, int]]:
    """[(index, p)] for every ``sqrt(p)`` variable of ``ctx`` (read once per context:
    asked at every candidate)."""
    def read(ctx: fmpq_mpoly_ctx) -> tuple:
        return tuple((i, p) for i, p in ((i, radical_prime(n))
                                          for i, n in enumerate(ctx.names()))
                     if p is not None)

    return list(memo_per_object(_RADICAL_VARIABLES, ctx, read))


_RADICAL_VARIABLES: dict = {}


def angle_variables(ctx: fmpq_mpoly_ctx) -> list[tuple[int, int]]:
    """[(cos index, sin index)] for every angle pair ``cos(v)``, ``sin(v)`` of ``ctx``
    (and (c, s) of a path ring whose first variables are t, s = sin t, c = cos t)."""
    names = ctx.names()
    out = [(2, 1)] if names[:3] == ("t", "s", "c") else []
    for i, name in enumerate(names):
        if name.startswith("cos(") and name.endswith(")"):
            partner = "sin(" + name[4:]
            if partner in names:
                out.append((i, names.index(partner)))
    return out


def reduce_relations(p: fmpq_mpoly) -> fmpq_mpoly:
    """The representative of ``p`` modulo ``cos(v)² + sin(v)² = 1`` (each angle of its
    ring) and ``sqrt(q)² = q`` (each radical): degree ≤ 1 in every ``sin(v)`` and
    every ``sqrt(q)``.  A polynomial without those variables is returned unchanged.

    FLINT's division with remainder, in C: in a lexicographic order that puts every
    ``sin(v)`` and ``sqrt(q)`` first (:func:`_relations_order`), the relations' leading
    monomials sin(v)², sqrt(q)² are pairwise coprime, so the relations are a Gröbner
    basis and the remainder is the unique polynomial congruent to ``p`` with no monomial
    divisible by any of them: exactly the representative above.  (It was a Python loop
    over p's terms: 2.2 s of a 6-RUS hexapod's 3.2 s model.)"""
    ctx = p.context()
    angles = angle_variables(ctx)
    radicals = radical_variables(ctx)
    degrees = p.degrees()
    if all(degrees[s] < 2 for _, s in angles) and all(degrees[i] < 2 for i, _ in radicals):
        return p
    order, relations = _relations_order(ctx, angles, radicals)
    q = p.project_to_context(order)
    for relation in relations:
        q = divmod(q, relation)[1]
    return q.project_to_context(ctx)


def _relations_order(ctx: fmpq_mpoly_ctx, angles, radicals):
    """(the ring of ``ctx`` reordered lexicographically with every sine and square root
    first, the relations sin(v)² + cos(v)² - 1 and sqrt(q)² - q in it), once per ring."""
    def build(ctx: fmpq_mpoly_ctx) -> tuple:
        names = ctx.names()
        first = [s for _, s in angles] + [i for i, _ in radicals]
        order = fmpq_mpoly_ctx.get(tuple(names[i] for i in first) +
                                   tuple(n for i, n in enumerate(names) if i not in first),
                                   "lex")
        g = dict(zip(order.names(), order.gens(), strict=True))
        relations = [g[names[s]] ** 2 + g[names[c]] ** 2 - 1 for c, s in angles] + \
                    [g[names[i]] ** 2 - q for i, q in radicals]
        return order, relations

    return memo_per_object(_RELATIONS, ctx, build)


_RELATIONS: dict = {}


def modulo_circles(p: fmpq_mpoly) -> fmpq_mpoly:
    """``p`` modulo ``cos(v)² + sin(v)² - 1`` of each angle pair of its ring: the same
    function wherever the angles are real, often with far fewer terms.  FLINT's division
    with remainder, one circle after the other (their leading monomials are coprime, so
    they form a Gröbner basis and an earlier reduction is not undone): a representative
    of degree ≤ 1 in the leading variable of each circle in the ring's order, not
    necessarily :func:`reduce_relations`'s (which works term by term in Python)."""
    gens = p.context().gens()
    for c, s in angle_variables(p.context()):
        if p.degrees()[c] >= 2 or p.degrees()[s] >= 2:
            p = divmod(p, gens[c] ** 2 + gens[s] ** 2 - 1)[1]
    return p


def norm_radicals(p: fmpq_mpoly) -> fmpq_mpoly:
    """∏ of ``p`` over both signs of every ``sqrt(q)`` it involves (resultants with
    ``sqrt(q)² - q``), reduced: a polynomial free of radicals whose zero set is the
    union of the conjugates' zero sets."""
    ctx = p.context()
    names = ctx.names()
    for i, q in radical_variables(ctx):
        if p.degrees()[i] == 0:
            continue
        r = ctx.gens()[i]
        p = reduce_relations(p.resultant(r * r - q, names[i]))
    return p


def radical_balls(ctx: fmpq_mpoly_ctx, signs: dict[int, int] | None = None) -> dict[int, arb]:
    """index → ball of ±√q for every radical variable (``signs``: prime → ±1), and of
    every opaque constant of a robot's ring (a parameter outside the exact field,
    :mod:`singcheck.spec.real_constants`: its value's ball).  A robot's ring puts them
    after the joints and the pose, so the sorted balls complete a point of the ring."""
    variables = radical_variables(ctx)
    constants = opaque_constants(ctx)
    if not variables and not constants:
        return {}
    signs = signs or {}
    out = {i: arb(q).sqrt() * signs.get(q, 1) for i, q in variables}
    for i, name in constants:
        out[i] = opaque_ball(name, arb(0))
    return out


def opaque_constants(ctx: fmpq_mpoly_ctx) -> tuple[tuple[int, str], ...]:
    """((index, name), …) for every opaque constant (kind ``K``) of ``ctx``, read once
    per context (asked wherever :func:`radical_balls` is)."""
    hit = _OPAQUE_CONSTANTS.get(id(ctx))
    if hit is None or hit[0] is not ctx:
        out = tuple((i, n) for i, n in enumerate(ctx.names())
                    if n.startswith("K") and (opaque_of(n) or (None, ""))[1] == "K")
        if len(_OPAQUE_CONSTANTS) > 256:
            _OPAQUE_CONSTANTS.clear()
        hit = _OPAQUE_CONSTANTS[id(ctx)] = (ctx, out)
    return hit[1]


_OPAQUE_CONSTANTS: dict[int, tuple[fmpq_mpoly_ctx, tuple]] = {}


def expand_trig(coefficients: dict[str, int], pi_part: Fraction,
                pairs: dict[str, tuple[fmpq_mpoly, fmpq_mpoly]],
                constant) -> tuple[fmpq_mpoly, fmpq_mpoly]:
    """``(cos θ, sin θ)`` for θ = Σ kᵥ·v + qπ, exactly (de Moivre):
    e^{iθ} = ∏ (cos v + i sin v)^{kᵥ} · (cos qπ + i sin qπ); ``pairs[v]`` is
    ``(cos(v), sin(v))`` and ``constant`` turns a surd into a ring element."""
    re_, im = constant(cos_pi(pi_part)), constant(sin_pi(pi_part))
    for v, k in sorted(coefficients.items()):
        c, s = pairs[v]
        if k < 0:
            s, k = -s, -k
        pr, pi_ = constant(Surd.rational(1)), constant(Surd())
        base_r, base_i = c, s
        while k:
            if k & 1:
                pr, pi_ = pr * base_r - pi_ * base_i, pr * base_i + pi_ * base_r
            base_r, base_i = base_r * base_r - base_i * base_i, 2 * base_r * base_i
            k >>= 1
        re_, im = re_ * pr - im * pi_, re_ * pi_ + im * pr
    return reduce_relations(re_), reduce_relations(im)


#: the angle functions of the path rings: name of the expression -> (P, q), the angle
#: being P(t, sin t, cos t) + q·π (a path whose angle is not k·t + qπ)
_ANGLE_FUNCTIONS: dict[str, tuple[fmpq_mpoly, Fraction]] = {}


def angle_function(p: fmpq_mpoly, q: Fraction) -> tuple[str, str]:
    """The path ring variables ``(cos(g), sin(g))`` standing for cos and sin of the angle
    g(t) = p(t, sin t, cos t) + q·π along a path (p a ``TRIG`` polynomial)."""
    q = Fraction(q)
    text = str(p) + (f" + {q}*pi" if q else "")
    _ANGLE_FUNCTIONS[text] = (p, q)
    return angle_names(text)


def angle_function_of(name: str) -> tuple[fmpq_mpoly, Fraction] | None:
    return _ANGLE_FUNCTIONS.get(name[4:-1]) if name.startswith(("cos(", "sin(")) else None


def path_ring(primes, functions=(), opaque=()) -> fmpq_mpoly_ctx:
    """Q[t, s, c] with a ``sqrt(p)`` variable per prime, the (cos, sin) variables of
    each angle function and the ``opaque`` variables (coordinates enclosed from their
    expression trees), ``TRIG`` itself for none."""
    primes = sorted(set(primes))
    if not primes and not functions and not opaque:
        return TRIG
    names = ("t", "s", "c", *(radical_name(p) for p in primes),
             *(n for pair in functions for n in pair), *opaque)
    return fmpq_mpoly_ctx.get(names, "lex")


def into_ring(p: fmpq_mpoly, ring: fmpq_mpoly_ctx) -> fmpq_mpoly:
    """``p`` in a ring that has all of its variables (matched by name; moved by FLINT)."""
    if p.context() is ring:
        return p
    missing = set(p.context().names()) - set(ring.names())
    if missing:
        raise ValueError(f"{', '.join(sorted(missing))} not in the ring")
    return p.project_to_context(ring)


_PARTS: dict[int, tuple[fmpq_mpoly, list]] = {}


def _parts(p: fmpq_mpoly) -> list[tuple[tuple[int, ...], fmpq_mpoly]]:
    """[(radical exponents, TRIG polynomial)] with p = Σ √…^e · P_e(t, s, c), memoised
    (each P_e is kept alive with p, so ``evaluate_trig``'s own memo stays valid)."""
    hit = _PARTS.get(id(p))
    if hit is not None and hit[0] is p:
        return hit[1]
    groups: dict[tuple[int, ...], dict] = {}
    for exps, coeff in p.terms():
        groups.setdefault(tuple(exps[3:]), {})[tuple(exps[:3])] = coeff
    parts = [(k, TRIG.from_dict(v)) for k, v in groups.items()]
    if len(_PARTS) > 512:
        _PARTS.clear()
    _PARTS[id(p)] = (p, parts)
    return parts


_RENAMED: dict[int, tuple[fmpq_mpoly, fmpq_mpoly | None]] = {}


def _on_angle_circle(p: fmpq_mpoly) -> fmpq_mpoly | None:
    """For a polynomial of a ring (t, s, c, cos(g), sin(g)) that uses only t and the
    angle's cos and sin: the same polynomial in ``TRIG`` with C, S renamed c, s (to be
    evaluated at the angle's balls); None otherwise.  Memoised per polynomial: the
    branch-and-bound evaluates one polynomial on thousands of boxes, and summing it
    part by part (one ``TRIG`` polynomial per monomial in C, S) cost forty times more."""
    hit = _RENAMED.get(id(p))
    if hit is not None and hit[0] is p:
        return hit[1]
    names = p.context().names()
    out = None
    degrees = p.degrees()
    if len(names) == 5 and names[3].startswith("cos(") and names[4].startswith("sin(") \
            and angle_function_of(names[3]) is not None and degrees[1] == degrees[2] == 0:
        out = TRIG.from_dict({(e[0], e[4], e[3]): coeff for e, coeff in p.terms()})
    if len(_RENAMED) > 512:
        _RENAMED.clear()
    _RENAMED[id(p)] = (p, out)
    return out


_DESCRIPTORS: dict[int, tuple[fmpq_mpoly_ctx, list]] = {}
_LAST_EXTRA: tuple = (None, None, 0, None, [])  # (ctx, t, precision, signs, balls)


def _descriptors(ctx: fmpq_mpoly_ctx) -> list:
    """Per variable after t, s, c: ("sqrt", q) or ("angle", key, g, k, is_cos), once per
    ring (a ring lives as long as the process: FLINT keeps its contexts)."""
    hit = _DESCRIPTORS.get(id(ctx))
    if hit is not None and hit[0] is ctx:
        return hit[1]
    out = []
    for name in ctx.names()[3:]:
        q = radical_prime(name)
        if q is not None:
            out.append(("sqrt", q))
            continue
        if opaque_of(name) is not None:  # a coordinate enclosed from its expression tree
            out.append(("opaque", name))
            continue
        g, k = angle_function_of(name)
        out.append(("angle", name[4:-1], g, k, name.startswith("cos(")))
    _DESCRIPTORS[id(ctx)] = (ctx, out)
    return out


def _extra_balls(ring: fmpq_mpoly_ctx, t: arb, signs) -> list:
    """Balls of the variables after t, s, c: ±√q, or cos/sin of an angle function;
    remembered for the last ball, ring and precision asked for (a polynomial and its
    derivative are enclosed on the same box one after the other).  The list returned
    is shared: callers only read it."""
    global _LAST_EXTRA
    last = _LAST_EXTRA
    if last[1] is t and last[0] is ring and last[2] == ctx.prec and last[3] == signs:
        return last[4]
    signs_ = signs or {}
    out = []
    cache: dict[str, tuple[arb, arb]] = {}
    for d in _descriptors(ring):
        if d[0] == "sqrt":
            out.append(arb(d[1]).sqrt() * signs_.get(d[1], 1))
            continue
        if d[0] == "opaque":
            out.append(opaque_ball(d[1], t))
            continue
        _, key, g, k, is_cos = d
        if key not in cache:
            angle = evaluate_trig(g, t) + arb.pi() * arb(fmpq(k.numerator, k.denominator))
            cache[key] = angle.sin_cos()
        out.append(cache[key][1] if is_cos else cache[key][0])
    _LAST_EXTRA = (ring, t, ctx.prec, signs, out)
    return out


def evaluate_path(p: fmpq_mpoly, t: arb, signs: dict[int, int] | None = None,
                  tight: bool = False) -> arb:
    """Rigorous enclosure of a path polynomial (in a :func:`path_ring`) for every t in
    the ball ``t``, each ``sqrt(q)`` at its value √q (or -√q where ``signs[q] = -1``) and
    each angle function's cos/sin at the ball of its angle over ``t``; ``tight`` as for
    :func:`~singcheck.algebra.trig.evaluate_trig`."""
    if p.context() is TRIG:
        return evaluate_trig(p, t, tight)
    renamed = _on_angle_circle(p)
    if renamed is not None:  # t and one angle's C, S: Horner in C with S, t outside
        (c_ball, s_ball) = _extra_balls(p.context(), t, signs)
        return evaluate_trig_at(renamed, t, s_ball, c_ball)
    values = _extra_balls(p.context(), t, signs)
    total = arb(0)
    for exps, part in _parts(p):
        term = evaluate_trig(part, t, tight)
        for v, e in zip(values, exps, strict=True):
            if e:
                term *= power(v, e)
        total += term
    return total


def path_derivative(p: fmpq_mpoly) -> fmpq_mpoly:
    """d/dt of a path polynomial: ∂/∂t + c·∂/∂s - s·∂/∂c, plus g'(t)·(-sin g·∂/∂cos g +
    cos g·∂/∂sin g) for each angle function g (reduced)."""
    from singcheck.algebra.trig import derivative

    ctx = p.context()
    if ctx is TRIG:
        return derivative(p)
    if has_opaque_coordinates(ctx):  # (an opaque constant's derivative is 0)
        raise ValueError("no derivative of a path given by an expression tree (not "
                         "polynomial in t, sin t, cos t)")
    gens = dict(zip(ctx.names(), ctx.gens(), strict=True))
    out = p.derivative("t") + gens["c"] * p.derivative("s") - gens["s"] * p.derivative("c")
    for name in ctx.names()[3:]:
        if name.startswith("cos(") and angle_function_of(name) is not None:
            g, _ = angle_function_of(name)
            sin_name = "sin(" + name[4:]
            dg = into_ring(derivative(g), ctx)
            out += dg * (gens[name] * p.derivative(sin_name) - gens[sin_name] * p.derivative(name))
    return reduce_relations(out)


def has_angle_functions(ctx: fmpq_mpoly_ctx) -> bool:
    """Whether the ring has variables that are functions of t other than t, sin t, cos t
    (a pose angle's cos and sin, or an opaque coordinate: :mod:`~singcheck.spec.real_paths`)."""
    return is_opaque(ctx) or any(angle_function_of(n) is not None for n in ctx.names()[3:])


def conjugates(p: fmpq_mpoly) -> list[dict[int, int]]:
    """Every sign choice on the square roots ``p`` involves, except all-positive."""
    from itertools import product

    primes = [q for i, q in radical_variables(p.context()) if p.degrees()[i] > 0]
    return [dict(zip(primes, signs, strict=True))
            for signs in product((1, -1), repeat=len(primes)) if -1 in signs]
