"""Certified real-root isolation, checked against roots known in closed form."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import pytest
from flint import arb, fmpq, fmpq_poly, fmpz_poly

from singcheck.algebra.trig import (
    C,
    LinearInPi,
    S,
    T,
    TimeRange,
    cos_multiple,
    reduce_trig,
    sin_multiple,
)
from singcheck.roots.enclosures import IdenticallyZeroError
from singcheck.roots.isolation import isolate_real_roots

mpmath.mp.dps = 50
PI = mpmath.pi


def rng(a, b, pa=0, pb=0) -> TimeRange:
    return TimeRange(LinearInPi(Fraction(a), Fraction(pa)), LinearInPi(Fraction(b), Fraction(pb)))


def contains(ball: arb, x) -> bool:
    lo, hi = mpmath.mpf(ball.lower().str(60, radius=False)), \
        mpmath.mpf(ball.upper().str(60, radius=False))
    # arb's printed endpoints are rounded; widen by a hair below the test's precision
    return lo - mpmath.mpf(10) ** -40 <= x <= hi + mpmath.mpf(10) ** -40


def assert_roots(iso, expected, width=1e-9):
    assert iso.certified
    assert len(iso.roots) == len(expected), [float(r.t.mid()) for r in iso.roots]
    for root, x in zip(iso.roots, sorted(expected), strict=True):
        assert contains(root.t, x), (root.t, x)
        assert 2 * float(root.t.rad()) <= width


def test_flint_returns_real_roots_first_with_zero_imaginary_part():
    roots = (fmpz_poly([-2, 0, 1]) * fmpz_poly([1, 0, 1])).complex_roots()
    assert [r.imag == 0 for r, _ in roots] == [True, True, False, False]
    assert float(roots[0][0].real.mid()) < float(roots[1][0].real.mid())


def test_polynomial_roots_and_a_complex_pair():
    p = (T - fmpq(1, 3)) * (T - 2) * (T**2 + 1)
    assert_roots(isolate_real_roots(p, rng(0, 5)), [mpmath.mpf(1) / 3, 2])
    assert isolate_real_roots(p, rng(0, 5)).method == "exact univariate"


def test_repeated_root_has_its_multiplicity():
    iso = isolate_real_roots((T - 1) ** 2 * (T + 1), rng(-2, 2))
    assert_roots(iso, [-1, 1])
    assert [r.multiplicity for r in iso.roots] == [1, 2]


def test_roots_at_and_just_outside_the_range_ends():
    p = T * (T - 1) * (3 * T - 4)  # roots 0, 1, 4/3
    assert_roots(isolate_real_roots(p, rng(0, 1)), [0, 1])
    eps = Fraction(1, 10**12)
    assert_roots(isolate_real_roots(p, rng(eps, Fraction(4, 3) - eps)), [1])


def test_roots_outside_the_range_are_left_out_whatever_their_distance():
    """Roots far outside, an irrational one just inside or just outside an end (√2 against
    ends 1.4142135623 and 1.4142135624), and rational ones on the ends: each placed
    exactly (the isolating interval decides the far ones without refining them)."""
    p = (T + 7) * (T - fmpq(1, 3)) * (T**2 - 2) * (T - 9) * (T - 1) * (T**2 + T + 5)
    r2 = mpmath.sqrt(2)
    assert_roots(isolate_real_roots(p, rng(0, Fraction(14142135624, 10**10))),
                 [mpmath.mpf(1) / 3, 1, r2])
    assert_roots(isolate_real_roots(p, rng(0, Fraction(14142135623, 10**10))),
                 [mpmath.mpf(1) / 3, 1])
    assert_roots(isolate_real_roots(p, rng(1, 9)), [1, r2, 9])
    assert_roots(isolate_real_roots(p, rng(-7, -1)), [-7, -r2])
    assert isolate_real_roots(p, rng(2, 8)).roots == ()


def test_sine_on_minus_pi_to_pi_has_three_roots():
    iso = isolate_real_roots(S, rng(0, 0, -1, 1))
    assert iso.method == "tangent half-angle"
    assert_roots(iso, [-PI, 0, PI])


def test_sine_over_several_periods():
    assert_roots(isolate_real_roots(S, rng(0, 20)), [k * PI for k in range(7)])
    assert_roots(isolate_real_roots(S, rng(0, Fraction(1, 2), -3, 0)),
                 [k * PI for k in range(-3, 1)])


def test_cos_2t_is_one_half_at_four_points():
    iso = isolate_real_roots(cos_multiple(2) - fmpq(1, 2), rng(0, 0, 0, 2))
    assert_roots(iso, [PI / 6, 5 * PI / 6, 7 * PI / 6, 11 * PI / 6])


def test_high_degree_trig_product_with_known_roots():
    # (2s - 1)(5c - 3)(sin 7t) * (c^2 + 2)^15: degree > 40 in (s, c)
    p = (2 * S - 1) * (5 * C - 3) * sin_multiple(7) * (C**2 + 2) ** 15
    expected = [PI / 6, 5 * PI / 6, mpmath.atan2(4, 3), -mpmath.atan2(4, 3)]
    expected += [k * PI / 7 for k in range(-7, 8)]
    iso = isolate_real_roots(p, rng(0, 0, -1, 1))
    assert_roots(iso, expected)


def test_mixed_t_and_sine_by_branch_and_bound():
    iso = isolate_real_roots(S - T / 20, rng(0, 20))
    assert iso.method == "interval branch-and-bound"
    f = lambda t: mpmath.sin(t) - t / 20  # noqa: E731
    # independent cross-check (test only): sign changes of a fine scan, then findroot
    grid = [mpmath.mpf(i) / 100 for i in range(1, 2001)]
    brackets = [(a, b) for a, b in zip(grid, grid[1:], strict=False) if f(a) * f(b) < 0]
    expected = [0] + [mpmath.findroot(f, (a, b), solver="bisect") for a, b in brackets]
    assert_roots(iso, expected)


def test_a_product_of_pure_and_repeated_mixed_factors_has_each_root_once():
    """(t² - 2)·(2 sin t + cos t)·(sin t - t/20)²·(cos t - t/30) on [0, 20]: the cheap
    factors (contents in t and in sin, cos; squarefree parts) give every root, each
    once (its multiplicity where it is exact), against 50-digit mpmath roots of each
    factor."""
    from singcheck.roots.isolation import _cheap_factors

    p = reduce_trig((T * T - 2) * (2 * S + C) * (S - T / 20) ** 2 * (C - T / 30))
    parts = _cheap_factors(p)
    product = 1
    for q, m in parts:
        product = product * q ** m
    assert (reduce_trig(p - product * p.leading_coefficient()
                        / product.leading_coefficient())).is_zero()
    iso = isolate_real_roots(p, rng(0, 20))
    factors = [lambda t: t * t - 2, lambda t: 2 * mpmath.sin(t) + mpmath.cos(t),
               lambda t: mpmath.sin(t) - t / 20, lambda t: mpmath.cos(t) - t / 30]
    grid = [mpmath.mpf(i) / 200 for i in range(4001)]
    expected, multiplicity = [], {}
    for k, f in enumerate(factors):
        for a, b in zip(grid, grid[1:], strict=False):
            if f(a) == 0 or f(a) * f(b) < 0:
                x = a if f(a) == 0 else mpmath.findroot(f, (a, b), solver="bisect")
                expected.append(x)
                multiplicity[float(x)] = 2 if k == 2 else 1
    assert_roots(iso, expected)
    known = [(r.multiplicity, multiplicity[k]) for r, k in
             zip(iso.roots, sorted(multiplicity), strict=True) if r.multiplicity is not None]
    assert known and all(a == b for a, b in known)  # (a sign change's root: unknown)


def test_no_root_is_certified_empty():
    iso = isolate_real_roots(2 + S + T / 100, rng(0, 20))
    assert iso.roots == () and iso.certified


@pytest.mark.slow
def test_branch_and_bound_alone_leaves_a_double_root_undecided_not_guessed():
    # (sin t - t/20)^2 touches zero without crossing: no sign change proves it
    from singcheck.algebra.trig import reduce_trig
    from singcheck.roots.branch_bound import branch_and_bound

    iso = branch_and_bound(reduce_trig((S - T / 20) ** 2), rng(2, 4), 1e-9)
    assert not iso.certified
    assert all("tangency" in u.reason and "in t ∈ [" in u.reason for u in iso.undecided)


def test_a_square_on_the_circle_has_its_double_roots_decided_exactly():
    # reduced modulo s² + c² = 1, (sin t - t/20)² = 1 - c² - ts/10 + t²/400 is irreducible
    # in Q[t, s, c]: its zeros are found through its norm over sin t, each decided exactly
    iso = isolate_real_roots((S - T / 20) ** 2 + 0 * T, rng(1, 20))
    assert iso.certified

    def f(t):
        return mpmath.sin(t) - t / 20

    grid = [1 + mpmath.mpf(i) / 100 for i in range(1901)]
    brackets = [(a, b) for a, b in zip(grid, grid[1:], strict=False) if f(a) * f(b) < 0]
    assert_roots(iso, [mpmath.findroot(f, (a, b), solver="bisect") for a, b in brackets])


def test_identically_zero_is_refused():
    with pytest.raises(IdenticallyZeroError):
        isolate_real_roots(S**2 + C**2 - 1, rng(0, 1))


def test_refinement_keeps_the_root():
    for p, r in [(S - T / 20, rng(1, 4)), (5 * C - 3, rng(0, 2)), (T**2 - 2, rng(0, 2))]:
        (root,) = isolate_real_roots(p, r).roots
        fine = root.refined(1e-30)
        assert 2 * float(fine.t.rad()) <= 1e-30
        assert fine.t.overlaps(root.t)
    (root,) = isolate_real_roots(T**2 - 2, rng(0, 2)).roots
    assert contains(root.refined(1e-30).t, mpmath.sqrt(2))


def test_pi_endpoint_is_exact():
    # 1 + cos t vanishes exactly at t = pi, a range end
    iso = isolate_real_roots(1 + C, rng(0, 0, 0, 1))
    assert_roots(iso, [PI])
    assert isolate_real_roots(1 + C, rng(0, 3)).roots == ()
    assert math.isclose(float(isolate_real_roots(1 + C, rng(0, 4)).roots[0].t.mid()), math.pi)


def test_descartes_isolation_agrees_with_flint_complex_roots():
    import random

    from singcheck.roots.rational import real_roots_exact

    rng = random.Random(11)
    for _ in range(40):
        degree = rng.randint(1, 40)
        f = fmpz_poly([rng.randint(-10**6, 10**6) for _ in range(degree)] + [rng.randint(1, 99)])
        f *= fmpz_poly([rng.randint(-5, 5), rng.randint(1, 3)])  # a rational root
        if rng.random() < 0.3:
            f *= fmpz_poly([0, 1])  # a root at 0
        ours = real_roots_exact(fmpq_poly(f))
        flint_real = sorted(float(r.real.mid()) for r, _ in f.complex_roots() if r.imag == 0)
        assert len(ours) == len(flint_real)
        for (rr, _), x in zip(ours, flint_real, strict=True):
            rr.bisect_to(fmpq(1, 10**12))
            assert float(rr.lo) - 1e-9 <= x <= float(rr.hi) + 1e-9


def _random_trig(rng, degree: int, with_t: bool = False):
    from singcheck.algebra.trig import reduce_trig

    p = 0 * S
    for _ in range(12):
        i = rng.randint(0, 2) if with_t else 0
        j, k = rng.randint(0, degree), rng.randint(0, degree)
        p += fmpq(rng.randint(-9, 9), rng.randint(1, 9)) * T**i * S**j * C**k
    return reduce_trig(p)


def testhalf_angle_polynomial_is_the_substitution():
    import random

    from singcheck.roots.half_angle import half_angle_polynomial

    rng = random.Random(5)
    for _ in range(20):
        p = _random_trig(rng, 7)
        m, d = half_angle_polynomial(p)
        for u in (fmpq(0), fmpq(3, 7), fmpq(-5, 2), fmpq(1)):
            w = 1 + u * u
            direct = p.subs({"s": 2 * u / w, "c": (1 - u * u) / w}).subs({"t": 0})
            assert m(u) == w**d * direct.leading_coefficient()


def test_deflated_half_angle_is_the_substitution_deflated():
    """N(u^k) is M(u) = (1+u²)^d p(2u/(1+u²), (1-u²)/(1+u²)) up to a constant factor
    (exact rationals at sample points), with and without sin t, and k is the largest
    deflation: no other exponent of N's u^k is a common multiple."""
    import random

    from singcheck.roots.half_angle import deflated_half_angle

    rng = random.Random(11)
    for case in range(24):
        p = _random_trig(rng, 6).subs({"t": 0})
        if case % 2:  # free of s (even paths such as heart 1): the shortcut's case
            p = reduce_trig(p.subs({"s": 0}) + C**3 - C)
        if p.is_zero() or p.is_constant():
            continue
        n, k = deflated_half_angle(p)
        d = max(j + kk for (_, j, kk), _ in p.terms())
        ratio = None
        for u in (fmpq(3, 7), fmpq(-5, 2), fmpq(1), fmpq(2), fmpq(-1, 3)):
            w = 1 + u * u
            direct = w**d * p.subs({"s": 2 * u / w, "c": (1 - u * u) / w}).leading_coefficient()
            mine = n(u**k)
            if direct == 0:
                assert mine == 0
                continue
            ratio = ratio if ratio is not None else mine / direct
            assert mine == ratio * direct and ratio != 0
        exponents = [i for i, c in enumerate(n.coeffs()) if c != 0]
        assert math.gcd(*exponents) == 1 or exponents == [0] or len(exponents) == 1


@pytest.mark.parametrize("m, expected", [
    ([-8, 0, 0, 1], [2]),  # u^3 = 8: deflation 3, odd
    ([8, 0, 0, 1], [-2]),  # u^3 = -8
    ([-64, 0, 0, 0, 0, 0, 1], [-2, 2]),  # u^6 = 64: deflation 6, even
    ([0, 0, -2, 0, 1], [-mpmath.sqrt(2), 0, mpmath.sqrt(2)]),  # u^2 (u^2 - 2)
    ([1, 0, 1], []),  # u^2 = -1: no real root
])
def test_deflated_half_angle_roots(m, expected):
    from singcheck.roots.half_angle import _half_angle_roots

    roots = sorted(_half_angle_roots(fmpq_poly(m)), key=lambda r: float(r.ball(1e-12).mid()))
    assert len(roots) == len(expected)
    for r, u in zip(roots, expected, strict=True):
        assert contains(r.ball(1e-20), 2 * mpmath.atan(u))
    if expected and expected[len(expected) // 2] == 0 and len(expected) == 3:
        assert roots[1].multiplicity == 2 and roots[1].exact is not None


def test_trig_evaluation_encloses_the_function():
    import random

    from singcheck.algebra.trig import evaluate_trig

    rng = random.Random(8)
    for _ in range(20):
        p = _random_trig(rng, 6, with_t=True)
        centre, radius = rng.uniform(-3, 3), rng.choice([0.0, 1e-6, 0.1, 0.5])
        ball = arb(centre, radius)
        box = evaluate_trig(p, ball)
        if radius == 0:
            assert float(box.rad()) < 1e-10
        for x in (centre + radius * i / 4 for i in range(-4, 5)):
            x = mpmath.mpf(x)
            value = sum(mpmath.mpf(int(c.p)) / int(c.q) * x**int(i) * mpmath.sin(x)**int(j)
                        * mpmath.cos(x)**int(k) for (i, j, k), c in p.terms())
            assert contains(box, value)


def test_tight_trig_evaluation_encloses_and_is_narrower_on_wide_balls():
    """The Fourier-form enclosure (``tight``) still holds every value (50-digit mpmath
    at points of the ball) and is much narrower than Horner in cos t for cos 12t."""
    import random

    from singcheck.algebra.trig import evaluate_trig, reduce_trig

    rng = random.Random(17)
    high = reduce_trig(3 * cos_multiple(12) - sin_multiple(9) * T + C**10 * S / 7)
    for p in [high, *(_random_trig(rng, 12, with_t=True) for _ in range(10))]:
        for centre, radius in [(0.3, 0.5), (-2.0, 0.2), (1.0, 1e-4), (2.5, 0.05)]:
            ball = arb(centre, radius)
            loose, tight = evaluate_trig(p, ball), evaluate_trig(p, ball, tight=True)
            assert tight.rad() <= loose.rad()
            for x in (centre + radius * i / 8 for i in range(-8, 9)):
                x = mpmath.mpf(x)
                value = sum(mpmath.mpf(int(c.p)) / int(c.q) * x**int(i) * mpmath.sin(x)**int(j)
                            * mpmath.cos(x)**int(k) for (i, j, k), c in p.terms())
                assert contains(tight, value)
    wide = arb(0.3, 0.5)
    assert evaluate_trig(high, wide, tight=True).rad() < evaluate_trig(high, wide).rad() / 100


def test_newton_refinement_keeps_the_root_and_reaches_the_width():
    """Refining an isolating interval (interval Newton, bisection where Newton cannot
    work) keeps a sign change at exact rational ends and the true root inside."""
    from singcheck.roots.rational import real_roots_exact

    cases = [(fmpz_poly([-2, 0, 1]), [mpmath.sqrt(2), -mpmath.sqrt(2)]),
             # x^7 - 3x + 1: three real roots
             (fmpz_poly([1, -3, 0, 0, 0, 0, 0, 1]),
              mpmath.polyroots([1, 0, 0, 0, 0, 0, -3, 1], maxsteps=200, extraprec=200)),
             # a tight pair near 1/3: (3x - 1)^2 - 10^-12, squarefree
             (fmpz_poly([10**12 - 1, -6 * 10**12, 9 * 10**12]), None)]
    for f, roots in cases:
        real = sorted(mpmath.mpf(mpmath.re(r)) for r in (roots or []) if abs(mpmath.im(r)) < 1e-30)
        if roots is None:
            real = sorted(mpmath.mpf(1) / 3 + s * mpmath.mpf(10) ** -6 / 3 for s in (-1, 1))
        isolated = [rr for rr, _ in real_roots_exact(fmpq_poly(f))]
        assert len(isolated) == len(real)
        for rr, x in zip(isolated, real, strict=True):
            for width in (fmpq(1, 10**9), fmpq(1, 10**30)):
                rr.bisect_to(width)
                assert rr.hi - rr.lo <= width
                lo, hi = fmpq_poly(f)(rr.lo), fmpq_poly(f)(rr.hi)
                assert lo * hi <= 0  # exact: a sign change (or a root) at the ends
                assert mpmath.mpf(int(rr.lo.p)) / int(rr.lo.q) <= x <= \
                    mpmath.mpf(int(rr.hi.p)) / int(rr.hi.q)


def test_descartes_variation_count_stops_at_two():
    from singcheck.roots.rational import _variations

    for coeffs, expected in [([1, 2, 3], 0), ([1, 0, -1], 1), ([1, -1, 1], 2),
                             ([-1, 0, 0, 2, -3, 4], 2), ([0, 0, 5, 0, -5], 1), ([], 0)]:
        assert _variations(coeffs, up_to=2) == expected


def test_reduce_trig_is_the_same_function_with_degree_at_most_one_in_sine():
    """The canonical form keeps the function (50-digit values at several t) and has
    degree ≤ 1 in s; high powers of s included."""
    import random

    from singcheck.algebra.trig import reduce_trig

    rng = random.Random(5)
    for _ in range(10):
        p = 0 * S
        for _ in range(15):
            p += fmpq(rng.randint(-9, 9), rng.randint(1, 9)) * T**rng.randint(0, 2) \
                * S**rng.randint(0, 9) * C**rng.randint(0, 9)
        r = reduce_trig(p)
        assert r.degrees()[1] <= 1
        for x in (mpmath.mpf("0.3"), mpmath.mpf("-2.1"), mpmath.mpf(5)):
            def value(q, x=x):
                return sum(mpmath.mpf(int(c.p)) / int(c.q) * x**int(i) * mpmath.sin(x)**int(j)
                           * mpmath.cos(x)**int(k) for (i, j, k), c in q.terms())
            assert abs(value(p) - value(r)) < mpmath.mpf(10) ** -30 * (1 + abs(value(p)))


def test_root_of_power_isolates_the_kth_root_among_the_roots_of_h_of_u_to_the_k():
    """u = ±|v|^(1/k) from v's own interval (no isolation of h(u^k)): the interval holds
    the 50-digit root and no other real root of h(u^k) (all of them computed by mpmath),
    and h(u^k) changes sign at its ends; a rational k-th power comes out exact."""
    import random

    from singcheck.roots.rational import real_roots_exact, root_of_power

    rng_ = random.Random(17)
    cases = 0
    for _ in range(12):
        degree = rng_.randint(1, 5)
        h = fmpz_poly([rng_.randint(-30, 30) for _ in range(degree)] + [rng_.randint(1, 5)])
        h *= fmpz_poly([rng_.choice([-9, -4, -2, 2, 4, 9]), rng_.choice([1, 4])])  # v = ±9/4…
        for rr, _ in real_roots_exact(fmpq_poly(h)):
            if rr.lo == rr.hi == 0:
                continue
            for k in (2, 3, 4):
                v_sign = 1 if rr.lo + rr.hi > 0 else -1
                for sign in ((1, -1) if k % 2 == 0 else (v_sign,)):
                    if k % 2 == 0 and v_sign < 0:
                        continue
                    cases += 1
                    u = root_of_power(rr, k, sign)
                    g = [mpmath.mpf(int(c.p)) / int(c.q) for c in u.poly.coeffs()]
                    reals = [x.real for x in mpmath.polyroots(g[::-1], maxsteps=200,
                                                              extraprec=100)
                             if abs(x.imag) < mpmath.mpf(10) ** -30]
                    a = mpmath.mpf(int(rr.lo.p)) / int(rr.lo.q)
                    b = mpmath.mpf(int(rr.hi.p)) / int(rr.hi.q)
                    v, = [x.real for x in mpmath.polyroots(
                        [mpmath.mpf(int(c.p)) / int(c.q) for c in rr.poly.coeffs()[::-1]],
                        maxsteps=200, extraprec=100)
                        if abs(x.imag) < mpmath.mpf(10) ** -30 and a <= x.real <= b]
                    target = sign * abs(v) ** (mpmath.mpf(1) / k)
                    lo = mpmath.mpf(int(u.lo.p)) / int(u.lo.q)
                    hi = mpmath.mpf(int(u.hi.p)) / int(u.hi.q)
                    inside = [x for x in reals if lo - mpmath.mpf(10) ** -40 <= x
                              <= hi + mpmath.mpf(10) ** -40]
                    assert len(inside) == 1 and abs(inside[0] - target) < mpmath.mpf(10) ** -30
                    if u.lo == u.hi:
                        assert u.poly(u.lo) == 0
                    else:
                        assert u.poly(u.lo) * u.poly(u.hi) < 0
    assert cases > 20


def test_exact_isolation_of_roots_spread_over_many_octaves():
    """Roots at 1 exactly, at dyadic points on both sides of 1, far beyond it (u = tan(t/2)
    near t = ±π) and near 0, with complex pairs: one interval per known root, holding it
    and no other, with a sign change at its ends (or the exact point)."""
    from singcheck.roots.rational import real_roots_exact

    roots = [Fraction(1), Fraction(4), Fraction(1, 3), Fraction(4096), Fraction(1, 4096),
             Fraction(3, 2), Fraction(1000), Fraction(-7, 5), Fraction(-65536), Fraction(5, 4)]
    f = fmpq_poly([1])
    for r in roots:
        f *= fmpq_poly([fmpq(-r.numerator, r.denominator), 1])
    f *= fmpq_poly([2, 0, 1]) * fmpq_poly([10**6 + 1, -2000, 1])  # ±i√2, 1000 ± i
    isolated = real_roots_exact(f)
    assert len(isolated) == len(roots)
    for (rr, mult), r in zip(isolated, sorted(roots), strict=True):
        assert mult == 1
        q = fmpq(r.numerator, r.denominator)
        assert rr.lo <= q <= rr.hi
        assert all(not rr.lo <= fmpq(o.numerator, o.denominator) <= rr.hi
                   for o in roots if o != r)
        assert (rr.lo == rr.hi == q) or rr.poly(rr.lo) * rr.poly(rr.hi) < 0


def test_refinement_on_wilkinsons_polynomial():
    """Refining the real roots of Wilkinson's perturbed polynomial (x-1)…(x-20) + 2^-23 x^19,
    ill-conditioned (Newton's unproven guesses there can miss, and the proven steps must
    take over): each interval, 10^-12 wide, holds exactly one real root computed by
    mpmath at 50 digits, with a sign change."""
    from singcheck.roots.rational import real_roots_exact

    f = fmpq_poly([1])
    for i in range(1, 21):
        f *= fmpq_poly([-i, 1])
    f += fmpq_poly([0] * 19 + [fmpq(1, 2**23)])
    coeffs = [mpmath.mpf(int(c.p)) / int(c.q) for c in f.coeffs()[::-1]]
    reals = sorted(x.real for x in mpmath.polyroots(coeffs, maxsteps=400, extraprec=400)
                   if abs(x.imag) < mpmath.mpf(10) ** -30)
    isolated = real_roots_exact(f)
    assert len(isolated) == len(reals) == 10
    for (rr, _), x in zip(isolated, reals, strict=True):
        rr.bisect_to(fmpq(1, 10**12))
        assert rr.hi - rr.lo <= fmpq(1, 10**12)
        lo, hi = (mpmath.mpf(int(q.p)) / int(q.q) for q in (rr.lo, rr.hi))
        assert lo <= x <= hi
        assert rr.poly(rr.lo) * rr.poly(rr.hi) < 0


@pytest.mark.parametrize("scale", [1, 10**400])
def test_refinement_guesses_in_floats_or_balls_and_confirms_exactly(scale):
    """bisect_to: √2 as a root of scale·(x² - 2) refined to 2⁻⁴⁰, whether the float
    guess applies (scale 1) or the coefficients do not fit a float (10⁴⁰⁰, the ball
    guess): the interval is short and holds √2, checked exactly (lo² < 2 < hi²)."""
    from singcheck.roots.rational import RationalRoot, _float_coefficients

    poly = fmpq_poly([-2 * scale, 0, scale])
    assert (_float_coefficients(poly) is None) == (scale != 1)
    rr = RationalRoot(poly, fmpq(1), fmpq(2))
    rr.bisect_to(fmpq(1, 2**40))
    assert rr.hi - rr.lo <= fmpq(1, 2**40)
    assert rr.lo * rr.lo < 2 < rr.hi * rr.hi


@pytest.mark.parametrize("roots", [
    [Fraction(1, 3), Fraction(2, 3)],            # Descartes' bound met below 1
    [Fraction(1, 3), Fraction(5, 2)],            # one on each side of 1
    [Fraction(7, 2), Fraction(9, 2)],            # both above 1
    [Fraction(1, 5), Fraction(1, 1), Fraction(3)],  # one exactly at 1
])
def test_positive_roots_on_both_sides_of_one_are_all_isolated(roots):
    """Known rational roots, with a complex pair (x² + x + 1, none positive) whose
    coefficients add sign variations Descartes must not mistake for roots."""
    from singcheck.roots.rational import real_roots_exact

    f = fmpq_poly([1, 1, 1])
    for r in roots:
        f *= fmpq_poly([-fmpq(r.numerator, r.denominator), 1])
    isolated = [rr for rr, _ in real_roots_exact(f, nonnegative_only=True)]
    assert len(isolated) == len(roots)
    for rr, r in zip(isolated, sorted(roots), strict=True):
        assert rr.lo <= fmpq(r.numerator, r.denominator) <= rr.hi
