"""Certified isolation of the real roots of a trig polynomial on a time range.

``isolate_real_roots(poly, interval)`` returns balls in t, each proven to hold exactly
one root of ``poly(t, sin t, cos t)``, proves every gap between them root-free, and
reports whatever it cannot prove as :class:`~singcheck.roots.enclosures.Undecided` with
a reason.  It picks one of three methods:

* **exact univariate** (no sin/cos, here): the squarefree factors of the polynomial in t
  over Z; Descartes' rule of signs with Vincent–Collins–Akritas bisection (exact
  integer arithmetic) gives rational intervals each holding exactly one root, with a
  sign change at their ends, refined by bisection on exact signs;
* **tangent half-angle** (sin/cos only): :mod:`singcheck.roots.half_angle`;
* **interval branch-and-bound** (t mixed with sin/cos): :mod:`singcheck.roots.branch_bound`.
"""

from __future__ import annotations

from flint import arb, fmpq, fmpq_mpoly, fmpq_mpoly_ctx, fmpq_poly

from singcheck.algebra.intervals import excludes_zero, working_precision
from singcheck.algebra.polynomials import may_be_slow, products_may_be_slow, restrict
from singcheck.algebra.radicals import (
    angle_function_of,
    conjugates,
    evaluate_path,
    norm_radicals,
    radical_prime,
    radical_variables,
    reduce_relations,
)
from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange, reduce_trig, uses_t, uses_trig
from singcheck.budget import checkpoint
from singcheck.roots.branch_bound import branch_and_bound, vanishes_at_multiple_of_pi
from singcheck.roots.enclosures import (
    AT_ANGLE_ZERO,
    AT_POINT,
    BRANCH_AND_BOUND,
    EXACT,
    IN_MIXED,
    IN_T,
    ExactTime,
    IdenticallyZeroError,
    RealRoot,
    RootIsolation,
    Undecided,
    locate_root,
)
from singcheck.roots.half_angle import _half_angle
from singcheck.roots.rational import (
    arb_to_fmpq,
    exact_tolerance,
    no_root_between,
    nonzero_on,
    real_roots_exact,
    to_fraction,
)
from singcheck.roots.transcendental import (
    ONE_MINUS_C2,
    NotExact,
    TranscendentalPoint,
    angle_circle,
    split_s,
)


def as_univariate_t(p: fmpq_mpoly) -> fmpq_poly:
    """A trig polynomial free of s and c as a univariate polynomial in t."""
    coeffs = [fmpq(0)] * (p.degrees()[0] + 1)
    for (i, _j, _k), c in p.terms():  # free of s and c here: one term per power of t
        coeffs[i] += c
    return fmpq_poly(coeffs)


def _outside(rr, start: fmpq, end: fmpq) -> bool:
    """Proven, exactly: the root of the isolating interval ``rr`` lies outside [start,
    end] (it is ``lo`` when ``lo == hi``, else strictly between them)."""
    if rr.lo == rr.hi:
        return rr.lo < start or rr.lo > end
    return rr.hi <= start or rr.lo >= end


def _exact_univariate(p: fmpq_mpoly, interval: TimeRange, tolerance: float) -> RootIsolation:
    roots, undecided = [], []
    ends = [fmpq(e.rational.numerator, e.rational.denominator)
            for e in (interval.start, interval.end) if not e.pi_coefficient]
    poly = as_univariate_t(p)
    if len(ends) == 2 and (nonzero_on(poly, *ends) or no_root_between(poly, *ends)):
        return RootIsolation((), (), EXACT)  # quick proofs: ball arithmetic, Descartes on [a, b]
    for rr, mult in real_roots_exact(poly):  # up to the degree of μ
        checkpoint()
        for q in ends:
            rr.pin(q)
        if len(ends) == 2 and _outside(rr, *ends):
            continue

        def make(tol: float, rr=rr) -> arb:
            rr.bisect_to(exact_tolerance(tol))
            return rr.ball()

        exact = LinearInPi(to_fraction(rr.lo)) if rr.lo == rr.hi else None
        where, t = locate_root(make, exact, interval, tolerance)
        if where is None:
            undecided.append(Undecided(t, "a root lies too close to a range end to decide"))
        elif where:
            roots.append(RealRoot(make(tolerance), mult, make,
                                  exact=ExactTime(IN_T, lambda rr=rr: rr)))
    return RootIsolation(tuple(roots), tuple(undecided), EXACT)




def _mixed(p: fmpq_mpoly, interval: TimeRange, tolerance: float,
           irreducible: bool = False) -> RootIsolation:
    """t mixed with sin t, cos t: each factor of p in Q[t, s, c] by its own method (a
    factor free of t or of s, c exactly; the rest by branch-and-bound), so that a
    repeated factor costs one isolation and pure factors keep their exact roots.

    The factors are first the cheap ones (:func:`_cheap_factors`: p's content in t, its
    content in (s, c), and the squarefree factors of what is left); only when those
    leave a stretch undecided is p factored into irreducibles (FLINT's multivariate
    factorization: most of the exact engine's time on the helix), so that distinct
    factors sharing a zero, or a factor that is a square on the circle, are told apart
    as before.  ``irreducible``: p is such a factor already, taken as it is.

    Roots of different factors are merged: balls that overlap are refined apart; a root
    two factors share (proven only for the same exact point) is kept once; two balls
    that stay overlapping otherwise become an undecided stretch."""
    if irreducible:
        return _through_norm(p, interval, tolerance) or branch_and_bound(p, interval, tolerance)
    cheap = _cheap_factors(p)
    if cheap is not None:
        quick = _by_factors(cheap, interval, tolerance)
        if not quick.undecided:
            return quick
    _, factors = p.factor()
    if len(factors) == 1 and factors[0][1] == 1:
        return _through_norm(p, interval, tolerance) or branch_and_bound(p, interval, tolerance)
    return _by_factors(factors, interval, tolerance)


def _by_factors(factors, interval: TimeRange, tolerance: float) -> RootIsolation:
    """The roots of a product from each factor's (``factors``: (polynomial,
    multiplicity), each isolated as it is), merged as :func:`_mixed` says."""
    roots: list[tuple[RealRoot, int]] = []
    undecided: list[Undecided] = []
    for f, mult in factors:
        if f.is_constant():
            continue
        checkpoint()
        iso = isolate_real_roots(f, interval, tolerance, irreducible=True)
        roots += [(r, int(mult)) for r in iso.roots]
        undecided += list(iso.undecided)
    merged, apart = _merge_apart(
        [RealRoot(r.t, None if r.multiplicity is None else r.multiplicity * mult, r._refine,
                  exact=r.exact) for r, mult in roots], tolerance,
        "two factors of the function have roots that could not be separated")
    return RootIsolation(tuple(merged), tuple(undecided + apart), BRANCH_AND_BOUND)


def _cheap_factors(p: fmpq_mpoly) -> list[tuple[fmpq_mpoly, int]] | None:
    """Factors of a trig polynomial p mixing t with sin t, cos t, without factoring it
    into irreducibles: its content in t (the gcd of its coefficients as a polynomial in
    s, c over Q[t]), its content in (s, c) (the gcd of its coefficients in t over
    Q[s, c]), and the squarefree factors of the quotient (each free of any factor in t
    or in s, c alone: mixed).  Their product is p up to a constant; None outside the
    trig ring (a pose angle's ring: the full factorization)."""
    if p.context() is not TRIG:
        return None
    by_trig: dict[tuple[int, int], dict] = {}
    by_t: dict[int, dict] = {}
    for (i, j, k), a in zip(p.monoms(), p.coeffs(), strict=True):
        by_trig.setdefault((j, k), {})[i] = a
        by_t.setdefault(i, {})[(0, j, k)] = a
    in_t = _gcd_in_t(by_trig.values())
    in_trig = _gcd_of(by_t.values())
    rest, remainder = divmod(p, in_t * in_trig)
    if not remainder.is_zero():  # (cannot happen: they are coprime divisors of p)
        return None
    _, parts = rest.factor_squarefree()
    return [(in_t, 1), (in_trig, 1), *((f, int(m)) for f, m in parts)]


def _gcd_in_t(groups) -> fmpq_mpoly:
    """The monic gcd of the polynomials in t alone whose coefficients are the dicts
    ``groups`` ({power of t: coefficient}), as a polynomial of TRIG: univariate gcds
    (FLINT's fmpq_poly), a fifth of the multivariate ones' cost."""
    g = None
    for terms in groups:
        q = [0] * (max(terms) + 1)
        for i, a in terms.items():
            q[i] = a
        q = fmpq_poly(q)
        g = q if g is None else g.gcd(q)
        if g.degree() == 0:
            return TRIG.from_dict({(0, 0, 0): 1})
    g = g / g[g.degree()]
    return TRIG.from_dict({(i, 0, 0): a for i, a in enumerate(g.coeffs()) if a != 0})


def _gcd_of(groups) -> fmpq_mpoly:
    """The gcd of the polynomials whose terms are the dicts ``groups`` (in TRIG)."""
    g = None
    for terms in groups:
        q = TRIG.from_dict(terms)
        g = q if g is None else g.gcd(q)
        if g.is_constant():
            return TRIG.from_dict({(0, 0, 0): 1})
    return g


def _merge_apart(roots: list[RealRoot], tolerance: float, why: str
                 ) -> tuple[list[RealRoot], list[Undecided]]:
    """Roots of different functions, in time order: balls that overlap are refined
    apart; a root both have (proven only for the same exact point: equal exact balls, or
    the same t = kπ) is kept once; two balls that stay overlapping otherwise become an
    undecided stretch, with the reason ``why``."""
    merged: list[RealRoot] = []
    undecided: list[Undecided] = []
    for r in sorted(roots, key=lambda r: float(r.t.mid())):
        checkpoint()
        if merged and merged[-1].t.overlaps(r.t):
            prev, tol = merged[-1], tolerance
            for _ in range(6):
                if not prev.t.overlaps(r.t):
                    break
                tol /= 1e4
                prev, r = prev.refined(tol), r.refined(tol)
            if prev.t.overlaps(r.t):
                if (prev.t.is_exact() and r.t.is_exact() and prev.t == r.t) or \
                        (prev.exact is not None and prev.exact.kind == AT_POINT
                         and prev.exact == r.exact):
                    merged[-1] = RealRoot(prev.t, None, prev._refine,
                                          exact=prev.exact or r.exact)
                    continue
                merged.pop()
                undecided.append(Undecided(prev.t.union(r.t), why))
                continue
            merged[-1] = prev
        merged.append(r)
    return merged, undecided


def _through_norm(p: fmpq_mpoly, interval: TimeRange, tolerance: float
                  ) -> RootIsolation | None:
    """The zeros of an irreducible p mixing t with sin t, cos t that is a square on the
    circle (a structural tangency), isolated through its norm over sin t; None when p's
    norm is squarefree (then p has no such tangency: plain branch-and-bound).

    p may be a square on the circle s² + c² = 1 without being one in Q[t, s, c] (e.g.
    (t - sin t)² = t² - 2t·s + 1 - c²): its zeros are then tangencies, which no sign
    change proves, and the branch-and-bound would end in thousands of undecided boxes.
    Every zero τ of p = p₀ + s·p₁ is a zero of its norm N = p₀² - p₁²(1 - c²) in Q[t, c],
    so of one of N's irreducible factors k, as a function of t; those have simple zeros,
    bracketed by branch-and-bound.  At each one, whether p vanishes is decided exactly
    (:meth:`~singcheck.roots.transcendental.TranscendentalPoint.is_zero`; at t = kπ by
    :func:`~singcheck.roots.branch_bound.vanishes_at_multiple_of_pi`): p's zeros are
    exactly those where it does, every other stretch is root-free.

    A norm that :func:`~singcheck.algebra.polynomials.may_be_slow` is factored in a
    forked child that the current deadline stops
    (:func:`~singcheck.elimination.cas.forked.until_deadline`): one FLINT factorization
    of a stacked Orthoglide's μ-norm took 17.9 s, past a 2 s limit."""
    circle = angle_circle(p)  # a pose angle's (C, S), renamed (c, s) for the algebra
    p0, p1 = split_s(p if circle is None else circle.to_trig(p))
    if p0.is_zero() or p1.is_zero():
        return None
    from singcheck.elimination.cas.forked import until_deadline

    # (huge coefficients make even the norm's products long: formed where the deadline
    # can stop them, as the factorizations below)
    norm = until_deadline(lambda q: q[0] * q[0] - q[1] * q[1] * ONE_MINUS_C2, (p0, p1),
                          "μ's norm over sin t", products_may_be_slow((p0, p0), (p1, p1)))

    slow = may_be_slow(norm)  # then factored where the deadline can stop it
    if all(m == 1 for _, m in until_deadline(lambda q: q.factor_squarefree(), norm,
                                             "the squarefree part of μ's norm", slow)[1]):
        return None
    roots: list[RealRoot] = []
    undecided: list[Undecided] = []
    for k, _ in until_deadline(lambda q: q.factor(), norm, "the factorization of μ's norm",
                               slow)[1]:
        if k.is_constant():
            continue
        checkpoint()
        iso = branch_and_bound(k if circle is None else circle.from_trig(k), interval,
                               tolerance)
        undecided += [Undecided(b.t, "possible tangency: the zeros of μ there are zeros of "
                                "a factor of its norm over sin t, which could not be "
                                f"isolated in t ∈ [{float(b.t.lower()):.9g}, "
                                f"{float(b.t.upper()):.9g}] ({b.reason})")
                      for b in iso.undecided]
        for r in iso.roots:
            checkpoint()
            zero = _vanishes_at(p, r)
            if zero is None:
                undecided.append(Undecided(r.t, "possible tangency: could not decide exactly "
                                           "whether μ vanishes at the zero of a factor of "
                                           f"its norm at t ≈ {float(r.t.mid()):.9g}"))
            elif zero:
                roots.append(r)
    roots, apart = _merge_apart(roots, tolerance, "two zeros of factors of the norm of μ "
                                "over sin t could not be separated")
    return RootIsolation(tuple(roots), tuple(undecided + apart), BRANCH_AND_BOUND)


#: the norm over two circles is factored only for a polynomial this small (FLINT's
#: multivariate factoring is one uninterruptible call): larger ones keep the plain
#: branch-and-bound
_MAX_DOUBLE_NORM_TERMS, _MAX_DOUBLE_NORM_DEGREE = 300, 24


def _split_odd(p: fmpq_mpoly, i: int, j: int) -> tuple[fmpq_mpoly, fmpq_mpoly]:
    """(a, b) free of variable i with p ≡ a + xᵢ·b modulo xᵢ² + xⱼ² - 1."""
    ctx = p.context()
    gens = ctx.gens()
    one_minus = 1 - gens[j] * gens[j]
    parts: list[fmpq_mpoly] = [ctx.from_dict({}), ctx.from_dict({})]
    for exps, coeff in p.terms():
        e = list(exps)
        k = e[i]
        e[i] = 0
        parts[k % 2] += ctx.from_dict({tuple(e): coeff}) * one_minus ** (k // 2)
    return parts[0], parts[1]


def _through_double_norm(p: fmpq_mpoly, interval: TimeRange, tolerance: float
                         ) -> RootIsolation | None:
    """The zeros of p(t, sin t, cos t, sin G, cos G) (one pose angle G = g(t) + qπ
    besides t's own sin and cos: two independent trig arguments) when its norm over both
    sines has a repeated factor — a structural tangency, e.g. (sin(t²) - sin(t)/2)²,
    which no sign change can prove; None otherwise (then plain branch-and-bound).

    The norm N = ∏ p(±s, ±S) (s = sin t, S = sin G; reduced, a polynomial in t, c, C) is
    zero wherever p is.  Each irreducible factor k of N is isolated by branch-and-bound
    on its own (a bracketed zero is proven by a sign change).  At such a zero N = 0, so
    some conjugate p(σs, τS) vanishes; when every conjugate that is not p itself (as a
    reduced polynomial) is enclosed away from 0 there, p vanishes: the zero is p's,
    proven without knowing whether the point (τ, cos τ, cos G(τ)) is generic on k = 0
    (which would need Schanuel's conjecture).  If p's own enclosure excludes 0 the zero
    is a conjugate's only; anything else is an undecided window, with the reason."""
    ctx = p.context()
    names = ctx.names()
    if len(names) != 5 or not names[3].startswith("cos(") or \
            angle_function_of(names[3]) is None or not names[4].startswith("sin("):
        return None
    if len(p) > _MAX_DOUBLE_NORM_TERMS or p.total_degree() > _MAX_DOUBLE_NORM_DEGREE:
        return None
    a, b = _split_odd(p, 1, 2)  # over s = sin t
    n1 = a * a - (1 - ctx.gens()[2] ** 2) * b * b
    a2, b2 = _split_odd(n1, 4, 3)  # over S = sin G
    norm = a2 * a2 - (1 - ctx.gens()[3] ** 2) * b2 * b2
    if norm.is_zero() or all(m == 1 for _, m in norm.factor_squarefree()[1]):
        return None
    gens = ctx.gens()
    conjugates = []
    for sigma, tau in ((1, -1), (-1, 1), (-1, -1)):
        q = reduce_relations(p.compose(gens[0], sigma * gens[1], gens[2], gens[3],
                                       tau * gens[4]))
        if q != p:
            conjugates.append(q)
    factors = [k for k, _ in norm.factor()[1] if not k.is_constant()]
    if sum(len(k) for k in factors) > 2 * len(p) + 64:
        return None  # the branch-and-bound on factors this large costs more than on p
    roots: list[RealRoot] = []
    undecided: list[Undecided] = []
    for k in factors:
        checkpoint()
        iso = branch_and_bound(k, interval, tolerance)
        undecided += [Undecided(w.t, "possible tangency: the zeros of μ there are zeros of "
                                "a factor of its norm over sin t and the angle's sine, "
                                f"which could not be isolated ({w.reason})")
                      for w in iso.undecided]
        for r in iso.roots:
            checkpoint()
            verdict = None
            for step in range(4):
                rr = r.refined(tolerance * 10.0 ** (-4 * step)) if step else r
                with working_precision(64 << step):
                    if excludes_zero(evaluate_path(p, rr.t)):
                        verdict = False
                    elif all(excludes_zero(evaluate_path(q, rr.t)) for q in conjugates):
                        verdict = True
                if verdict is not None:
                    break
            if verdict:
                roots.append(RealRoot(r.t, None, r._refine, exact=None))
            elif verdict is None:
                undecided.append(Undecided(r.t, "possible tangency: p and a conjugate "
                                           "(sin t or the angle's sine negated) may both "
                                           f"vanish near t ≈ {float(r.t.mid()):.9g}"))
    roots, apart = _merge_apart(roots, tolerance, "two zeros of factors of the norm of μ "
                                "over two sines could not be separated")
    return RootIsolation(tuple(roots), tuple(undecided + apart), BRANCH_AND_BOUND)


def _windows_through_double_norm(p: fmpq_mpoly, iso: RootIsolation, tolerance: float
                                 ) -> RootIsolation:
    """Each window the branch-and-bound left undecided, tried again through the norm
    over both sines (:func:`_through_double_norm`) on that window alone: its roots
    replace the window when that decides it.  The branch-and-bound proved every other
    stretch, so a root of p lies in a window; only the windows cost the norm's work."""
    if not iso.undecided:
        return iso
    roots, undecided = list(iso.roots), []
    for window in iso.undecided:
        checkpoint()
        lo, hi = arb_to_fmpq(window.t.lower()), arb_to_fmpq(window.t.upper())
        sub = TimeRange(LinearInPi(to_fraction(lo)), LinearInPi(to_fraction(hi)))
        found = _through_double_norm(p, sub, tolerance) if lo < hi else None
        if found is None or found.undecided:
            undecided.append(window)
            continue
        roots += found.roots
    roots.sort(key=lambda r: float(r.t.mid()))
    return RootIsolation(tuple(roots), tuple(undecided), iso.method, iso.exact)


def _vanishes_at(p: fmpq_mpoly, root: RealRoot) -> bool | None:
    """Whether p is exactly 0 at a bracketed zero of a norm factor (None: undecided)."""
    time = root.exact
    if time is None:
        return None
    if time.end is not None and p.context() is TRIG:  # a zero met exactly at a range end
        from singcheck.algebra.trig_values import sum_is_zero

        return sum_is_zero([(p, time.end)])
    if time.kind == IN_MIXED:
        try:
            return TranscendentalPoint(time).is_zero(p)
        except NotExact:
            return None
    if time.kind == AT_ANGLE_ZERO and angle_circle(p) is not None:
        from singcheck.roots.angle_zeros import AngleZero

        try:
            return AngleZero(time.locate(), time.angle_q).is_zero(angle_circle(p).to_trig(p))
        except NotExact:
            return None
    if time.kind == AT_POINT and (time.t_value == 0 or time.pi_multiple is not None):
        zero = vanishes_at_multiple_of_pi(p, 0 if time.t_value == 0 else time.pi_multiple)
        # with a pose angle's C, S left in p, only "zero whatever C, S are" is a proof
        return zero if zero or p.context() is TRIG else None
    return None


def isolate_real_roots(poly: fmpq_mpoly, interval: TimeRange,
                       tolerance: float = 1e-9, exact_zero=None,
                       irreducible: bool = False) -> RootIsolation:
    """Every real root of ``poly(t, sin t, cos t)`` on the closed range, certified.

    A polynomial with square roots among its coefficients (a :func:`path_ring`
    element) goes through :func:`_with_radicals`; ``exact_zero(p, root)`` (True, False,
    or None when it cannot say) decides exactly whether p vanishes at a root of its norm
    where balls cannot tell p from a conjugate (the caller's exact arithmetic:
    :func:`singcheck.certify.exact.vanishes_at_root`).  ``irreducible``: poly is an
    irreducible factor (from a factorization here), taken as it is when reducing it
    modulo s² + c² = 1 leaves it unchanged (a reduced polynomial's factors are reduced:
    their degrees in s add up to at most 1)."""
    if poly.context() is not TRIG:
        if radical_variables(poly.context()):
            return _with_radicals(poly, interval, tolerance, exact_zero)
        p = reduce_relations(poly)
        if p.is_zero():
            raise IdenticallyZeroError("the function is identically zero along the path")
        if not any(p.degrees()[3:]):
            return isolate_real_roots(restrict(p, TRIG), interval, tolerance)
        if angle_circle(p) is not None:  # t and one pose angle g(t) + qπ, g ∈ Q[t]
            return _mixed(p, interval, tolerance, irreducible and p == poly)
        # angle functions: t mixed with them (two arguments: the windows the
        # branch-and-bound leaves, a structural tangency, through the norm over both sines)
        return _windows_through_double_norm(p, branch_and_bound(p, interval, tolerance),
                                            tolerance)
    p = reduce_trig(poly)
    if p.is_zero():
        raise IdenticallyZeroError("the function is identically zero along the path")
    if uses_t(p) and uses_trig(p):
        return _mixed(p, interval, tolerance, irreducible and p == poly)
    if uses_trig(p):
        return _half_angle(p, interval, tolerance)
    return _exact_univariate(p, interval, tolerance)


def _with_radicals(p: fmpq_mpoly, interval: TimeRange, tolerance: float,
                   exact_zero=None) -> RootIsolation:
    """Roots of a polynomial over Q(√2, √3, …): those of its norm N = ∏ p^σ (over Q,
    isolated as above), kept only where proven to be roots of p itself.

    Each ball T of N holds exactly one root τ of N.  If p excludes 0 on T, τ is a root of
    a conjugate only: dropped.  If every conjugate p^σ (σ ≠ id) excludes 0 on T, then
    p(τ) = 0: kept.  Otherwise T is refined (and the precision raised) a few times; a
    root where p and a conjugate both still hold 0 (both may vanish there) is decided
    by ``exact_zero`` when given (its times are the isolation's ``exact``); what stays
    ambiguous is reported undecided, never guessed."""
    ctx = p.context()
    rest = [n for n in ctx.names() if radical_prime(n) is None]
    from singcheck.elimination.cas.forked import until_deadline

    norm = until_deadline(norm_radicals, p, "μ's norm over its square roots",
                          may_be_slow(p))  # large coefficients: seconds in one resultant
    norm = restrict(norm, TRIG if len(rest) == 3 else
                    fmpq_mpoly_ctx.get(tuple(rest), "lex"))
    iso = isolate_real_roots(norm, interval, tolerance)
    sigmas = conjugates(p)
    roots, undecided, exact = [], list(iso.undecided), []
    for root in iso.roots:
        checkpoint()
        r, verdict = root, None
        for step, bits in enumerate((53, 128, 256, 512)):
            if step:
                r = r.refined(tolerance * 10.0 ** (-4 * step))
            with working_precision(bits):
                if excludes_zero(evaluate_path(p, r.t)):
                    verdict = False
                elif all(excludes_zero(evaluate_path(p, r.t, s)) for s in sigmas):
                    verdict = True
            if verdict is not None:
                break
        if verdict is None and exact_zero is not None:
            verdict = exact_zero(p, r)
            if verdict is not None:
                exact.append((r, verdict))
        if verdict:
            roots.append(r)
        elif verdict is None:
            undecided.append(Undecided(r.t, "a root of the norm over the square roots could "
                                       "not be told apart from a root of a conjugate near "
                                       f"t ≈ {float(r.t.mid()):.6g}"))
    return RootIsolation(tuple(roots), tuple(undecided), iso.method, tuple(exact))
