"""Exact adjacency of a plane open CAD's cells across a critical value α.

Free segments (:mod:`singcheck.regions`) prove that two cells are connected; they cannot
prove that two cells are *not*.  Here the line x = α itself is studied, exactly, so that
joining cells across every critical value gives exactly the connected components.

* **The fibre.**  α is a real root of an irreducible m ∈ Q[x] (its isolating interval
  picks the factor).  Each factor f_i of the variety is taken in Q(α)[y] (coefficients
  reduced mod m; an element is 0 exactly when its remainder is).  If some f_i(α, y) is 0
  the line x = α lies in the variety: nothing is adjacent across it.  Otherwise the
  squarefree part h_i of each f_i(α, ·) is found: f_i itself when a modular image
  proves gcd(f_i, ∂f_i/∂y) = 1 over Q(α), else by Euclid in Q(α)[y]; likewise the number
  c_ij of distinct roots two factors share (0 by a modular image, else the degree of
  gcd(h_i, h_j)).  Arb isolates the roots of each h_i from ball coefficients (α enclosed
  as tightly as needed); a root ball whose conjugate meets no other root ball holds a
  real root (h_i has real coefficients).  Roots of h_i and h_j are one point exactly
  when their balls meet and c_ij pairs of balls meet, one to one: each common root
  makes such a pair, so there is no other.
* **Bands.**  Rationals s₀ < y₁ < s₁ < … < y_k < s_k separate the fibre's real points; a
  bracket a < α < b is narrowed until every line y = s_j is free on [a, b] (exact).
  Then no section crosses a line on [a, b]: the sections over (a, α) in a bounded band
  converge to its one fibre point, and those in the unbounded bands go to ±∞.
* **Adjacency.**  In a bounded band the lowest sector on the left touches the open
  segment {α} × (s_{j-1}, y_j), which avoids the variety, and so does the lowest on the
  right: they are joined; likewise the highest sectors through (y_j, s_j).  Sectors
  between two sections that meet at y_j are pinched there and touch nothing.  Below s₀
  only the highest sectors touch {α} × (-∞, s₀); above s_k only the lowest.  So the
  sectors adjacent across α are exactly, for each j, the left and the right sector
  holding the line y = s_j.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import combinations

from flint import acb, acb_poly, arb, arb_poly, fmpq, fmpq_poly, fmpz, nmod_poly

from singcheck.algebra.intervals import working_precision
from singcheck.budget import checkpoint
from singcheck.elimination.cas.forked import until_deadline
from singcheck.roots.rational import RationalRoot, ball_ends, to_fraction
from singcheck.spaces.cad import fiber, sector_of, simplest_between
from singcheck.spaces.segments import segment_is_free

WALL = "wall"  # the line x = α lies in the variety

#: Euclid in Q(α)[y] is run only where a factor has a multiple root over α or two
#: factors meet there (elsewhere a modular proof suffices), and only while deg α times
#: the square of the degree in y stays within this bound: its coefficients grow fast (a
#: 3-PRR plane's factor of degree 40 in y over quadratic α's, 3200, took 3 to 6 s per α).
#: Past it, cells are joined by free segments, and the regions are then not proven to be
#: the components.  The degree of α is not bounded as such: the planes of y² = g(x) with
#: g of degree 10, 32, 64 and 128 are exact in 0.06, 0.2, 2.6 and 46 s of CPU.
MAX_EUCLID_COST = 1024


class NotDecided(ArithmeticError):
    """The fibre could not be certified at the precisions tried."""


# ---------------------------------------------------------------------------------
# Q(α)[y]: lists of fmpq_poly (coefficient of y^i), reduced mod m, no zero leading term


def minimal_polynomial(root: RationalRoot) -> fmpq_poly:
    """The irreducible factor of ``root.poly`` vanishing at the isolated root."""
    if root.lo == root.hi:
        return fmpq_poly([-root.lo, 1])
    for f, _ in root.poly.factor()[1]:
        if f.degree() >= 1 and (f(root.lo) > 0) != (f(root.hi) > 0):
            return f
    raise NotDecided("no factor changes sign on the isolating interval")


#: the size (coefficient bits × degree of p × degree of m) above which an inverse in
#: Q(α) is computed in a forked child a deadline can stop: 925 bits × 2 × 10 took 2 ms,
#: 19,461 × 9 × 10 0.28 s, 50,122 × 9 × 10 1.5 s (a fork costs 12-20 ms)
SLOW_INVERSE = 400_000


def _bits(p: fmpq_poly) -> int:
    """The largest coefficient's size in bits (numerator and denominator)."""
    return max((abs(c.numer()).bit_length() + c.denom().bit_length() for c in p.coeffs()),
               default=0)


def _xgcd(pair: tuple[fmpq_poly, fmpq_poly]):
    p, m = pair
    return p.xgcd(m)


class _Field:
    """Q[x]/(m) for an irreducible m, and polynomials in y over it (Euclid's algorithm
    with exact remainders; an element is zero exactly when its remainder mod m is)."""

    def __init__(self, m: fmpq_poly) -> None:
        self.m = m

    def reduce(self, p: fmpq_poly) -> fmpq_poly:
        return p % self.m if p.degree() >= self.m.degree() else p

    def inverse(self, p: fmpq_poly) -> fmpq_poly:
        """1/p in Q[x]/(m), by FLINT's extended Euclid; where the coefficients have grown
        (a fibre's Euclid over Q(α) can reach 50,000-bit coefficients, one ``xgcd`` then
        taking seconds) it runs where the deadline can stop it."""
        checkpoint()
        costly = _bits(p) * max(p.degree(), 1) * self.m.degree() > SLOW_INVERSE
        g, s, _ = until_deadline(_xgcd, (p, self.m), "an inverse in a number field", costly)
        if g.degree() != 0:
            raise NotDecided("a zero divisor: m is not irreducible")
        return self.reduce(s / g.leading_coefficient())

    def trim(self, a: list) -> list:
        while a and a[-1].is_zero():
            a.pop()
        return a

    def monic(self, a: list) -> list:
        inv = self.inverse(a[-1])
        return [self.reduce(c * inv) for c in a]

    def divmod(self, a: list, b: list) -> tuple[list, list]:
        b = self.monic(b)
        a = list(a)
        q = [fmpq_poly([])] * max(len(a) - len(b) + 1, 0)
        while len(a) >= len(b):
            checkpoint()
            c, shift = a[-1], len(a) - len(b)
            q[shift] = c
            for i in range(len(b) - 1):
                a[shift + i] = self.reduce(a[shift + i] - c * b[i])
            a.pop()
            self.trim(a)
        return q, a

    def gcd(self, a: list, b: list) -> list:
        while b:
            checkpoint()
            a, b = b, self.divmod(a, b)[1]
        return self.monic(a)


# ---------------------------------------------------------------------------------
# the fibre over α


def _in_y(f, field: _Field) -> list:
    """A factor (in x, y) as an element of Q(α)[y]."""
    coeffs: dict[int, dict[int, fmpq]] = {}
    for (i, j), c in f.terms():
        coeffs.setdefault(j, {})[i] = c
    return field.trim([field.reduce(fmpq_poly([coeffs.get(j, {}).get(i, 0)
                                               for i in range(max(coeffs.get(j, {0: 0})) + 1)]))
                       for j in range(max(coeffs) + 1)])


def _images(m: fmpq_poly, wanted: int = 2) -> list[tuple[int, int]]:
    """Up to ``wanted`` pairs (p, r): a prime p ∤ lc(m)·denominators with a root r of m
    mod p.  x ↦ r is then a ring homomorphism from the p-integral part of Q[x]/(m) ≅ Q(α)
    onto F_p (it kills m)."""
    out = []
    num, den = m.numer(), m.denom()
    for p in _primes():
        if num.leading_coefficient() % p == 0 or den % p == 0:
            continue
        roots = nmod_poly([int(c) % p for c in num.coeffs()], p).roots()
        if roots:
            out.append((p, int(roots[0][0])))
            if len(out) == wanted:
                break
    return out


_PRIMES: list[int] = []


def _primes(count: int = 24) -> list[int]:
    """The first ``count`` primes above 2^62, each proven prime (FLINT's is_prime: a
    composite modulus would make F_p no field and its gcds no proof)."""
    n = _PRIMES[-1] if _PRIMES else 2 ** 62
    while len(_PRIMES) < count:
        n += 1
        if fmpz(n).is_prime():
            _PRIMES.append(n)
    return _PRIMES[:count]


def _image(f, degree: int, p: int, r: int):
    """f(r, y) mod p as an nmod_poly, or None when a denominator of f vanishes mod p or
    the image loses the degree ``degree`` that f keeps over α."""
    coeffs = [0] * (degree + 1)
    for (i, j), c in f.terms():
        if j > degree:
            continue  # (that coefficient vanishes at α, hence at r)
        if c.q % p == 0:
            return None
        coeffs[j] = (coeffs[j] + int(c.p) * pow(int(c.q), -1, p) * pow(r, i, p)) % p
    if coeffs[degree] == 0:
        return None
    return nmod_poly(coeffs, p)


def _no_common_root_mod_p(images, f, df, g=None, dg=None) -> bool:
    """Proof that (f, g) over α have no common root (g defaults to ∂f/∂y): some image
    (p, r) keeps both degrees and gives coprime images.  The principal subresultant
    coefficients are polynomials in the coefficients, so psc_0 maps to psc_0 of the
    images: non-zero there, it is non-zero over Q(α) (the gcd over Q(α) has degree 0)."""
    for p, r in images:
        a = _image(f, df, p, r)
        b = _image(g, dg, p, r) if g is not None else None
        if a is None or (g is not None and b is None):
            continue
        b = a.derivative() if g is None else b
        if b.degree() == (df if g is not None else df - 1) and a.gcd(b).degree() == 0:
            return True
    return False


def _refuse_costly_euclid(m: fmpq_poly, degree: int) -> None:
    if m.degree() * degree ** 2 > MAX_EUCLID_COST:
        raise NotDecided(f"Euclid over a critical value of degree {m.degree()} on a "
                         f"fibre of degree {degree}: too costly")


def squarefree_fibre(factors, m: fmpq_poly):
    """The fibre of ∏ factors over the roots of m, exactly in Q[x]/(m)[y] (isomorphic to
    Q(α)[y] for each root α of the irreducible m): :data:`WALL` when some factor vanishes
    on the whole line, else ``(parts, common)``: the squarefree part h_i = f_i / gcd(f_i,
    ∂f_i/∂y) of each factor that keeps y, and for each pair of parts the degree of
    gcd(h_i, h_j), the number of their distinct common roots.

    Each factor is handled on its own, and Euclid in Q(α)[y] is run only where a quick
    modular proof fails (a factor with a multiple root over α, two that meet there):
    Euclid on the product of all factors (degree 16 in y on a 3-RPR plane, α of degree
    10) spent seconds per step in coefficient growth."""
    field = _Field(m)
    images = _images(m)
    parts, owners, degrees = [], [], []
    for f in factors:
        checkpoint()
        g = _in_y(f, field)
        if not g:
            return WALL
        if len(g) == 1:
            continue  # a non-zero constant on the line: no point of this factor
        if _no_common_root_mod_p(images, f, len(g) - 1):
            parts.append(g)  # squarefree over α
        else:
            _refuse_costly_euclid(m, len(g) - 1)
            dg = field.trim([field.reduce(c * i) for i, c in enumerate(g)][1:])
            d = field.gcd(g, dg)
            parts.append(field.divmod(g, d)[0] if len(d) > 1 else g)
        owners.append(f)
        degrees.append(len(g) - 1)
    common = {}
    for a, b in combinations(range(len(parts)), 2):
        if _no_common_root_mod_p(images, owners[a], degrees[a], owners[b], degrees[b]):
            continue
        checkpoint()
        _refuse_costly_euclid(m, min(len(parts[a]), len(parts[b])) - 1)
        g = field.gcd(parts[a], parts[b])
        if len(g) > 1:
            common[a, b] = len(g) - 1
    return parts, common


def fibre_points(factors, alpha: RationalRoot, memo: dict | None = None) -> list[arb] | str:
    """The distinct real points of the variety on the line x = α (sorted, disjoint
    balls), or :data:`WALL` when the whole line lies in it.  ``memo`` keeps the
    exact fibre per minimal polynomial (conjugate critical values share it)."""
    m = minimal_polynomial(alpha)
    if m.degree() == 1:  # a rational α: met exactly (short brackets around it, cheap
        alpha.pin(-m[0] / m[1])  # fibres over their ends)
    memo = {} if memo is None else memo
    if str(m) not in memo:
        memo[str(m)] = squarefree_fibre(factors, m)
    fibre = memo[str(m)]
    if fibre == WALL:
        return WALL
    parts, common = fibre
    if not parts:
        return []
    for bits in (128, 512, 2048):
        checkpoint()
        points = _real_points(parts, common, alpha, bits)
        if points is not None:
            return points
    raise NotDecided("the real points of the fibre could not be isolated")


def _roots_of(h: list, a: arb, bits: int) -> list[tuple[acb, bool]] | None:
    """The roots of the squarefree h (coefficients in Q(α), evaluated at the ball a of
    α), each as (isolating complex ball, proven real); None when not separated."""
    coeffs = [arb_poly([arb(c) for c in q.coeffs()])(a) if not q.is_zero() else arb(0)
              for q in h]
    try:
        # refined well below the balls' own isolation radius, so that roots of two
        # parts closer than that (two fibre points 5e-17 apart on a Delta's plane) meet
        # only when they are one point
        roots = acb_poly([acb(c) for c in coeffs]).roots(tol=arb(2) ** (-bits // 2),
                                                         maxprec=4 * bits)
    except ValueError:
        return None
    out = []
    for i, z in enumerate(roots):
        real = False
        if z.imag.contains(0):  # h has real coefficients: a ball whose mirror image meets
            mirror = z.conjugate()  # no other root ball holds a real root
            if any(j != i and mirror.overlaps(w) for j, w in enumerate(roots)):
                return None
            real = True
        out.append((z, real))
    return out


def _real_points(parts: list, common: dict, alpha: RationalRoot, bits: int
                 ) -> list[arb] | None:
    """The distinct real points of the parts' roots, or None at too low a precision.

    A root of h_i and one of h_j are the same point exactly when their balls overlap and
    the number of overlapping pairs is the number of common roots (gcd degree): each
    common root makes one overlapping pair, so equal counts leave no other."""
    alpha.bisect_to(fmpq(1, 2 ** (bits + 16)))
    with working_precision(bits + 64):
        a = alpha.ball()
        roots = [_roots_of(h, a, bits) for h in parts]
        if any(r is None for r in roots):
            return None
        parent = {(i, k): (i, k) for i, rs in enumerate(roots) for k in range(len(rs))}

        def find(u):
            while parent[u] != u:
                u = parent[u]
            return u

        for i, j in combinations(range(len(parts)), 2):
            pairs = [(u, v) for u, (z, _) in enumerate(roots[i])
                     for v, (w, _) in enumerate(roots[j]) if z.overlaps(w)]
            if len(pairs) != common.get((i, j), 0) or \
                    len({u for u, _ in pairs}) != len(pairs) or \
                    len({v for _, v in pairs}) != len(pairs):
                return None
            for u, v in pairs:
                parent[find((i, u))] = find((j, v))
        classes: dict = {}
        for i, rs in enumerate(roots):
            for k, (z, real) in enumerate(rs):
                classes.setdefault(find((i, k)), []).append((z, real))
        real = [min((z.real for z, _ in members), key=lambda x: x.rad())
                for members in classes.values() if any(r for _, r in members)]
    real.sort(key=lambda r: r.mid())
    if any(x.overlaps(y) for x, y in zip(real, real[1:], strict=False)):
        return None
    return real


def separators(points: list[arb]) -> list[Fraction]:
    """Rationals s₀ < y₁ < s₁ < … < y_k < s_k (k + 1 of them)."""
    if not points:
        return [Fraction(0)]
    ends = [tuple(map(to_fraction, ball_ends(p))) for p in points]
    out = [simplest_between(None, ends[0][0])]
    out += [simplest_between(lo_hi[1], nxt[0]) for lo_hi, nxt in zip(ends, ends[1:],
                                                                     strict=False)]
    out.append(simplest_between(ends[-1][1], None))
    return out


# ---------------------------------------------------------------------------------
# adjacency across α


def exact_joins(cad, base, i: int, brackets, memo: dict | None = None
                ) -> list[tuple[int, int]] | None:
    """The (left sector, right sector) pairs adjacent across the i-th critical value of
    a plane CAD, or None when they could not be decided (the caller falls back to free
    segments, which prove joins but not separations).

    The pairs are those holding the same separator s_j on both sides: the line y = s_j
    is free on [a, b], so the sector holding (a, s_j) reaches (b, s_j).  By the band
    argument above no other sectors touch across α.
    """

    try:
        points = fibre_points(cad.factors, base[i], memo)
    except NotDecided:
        return None
    if points == WALL:
        return []
    seps = separators(points)
    for round_ in range(6):
        checkpoint()
        a, b = brackets(base, i, round_)
        if all(segment_is_free(cad, (a, s), 0, a, b) for s in seps):
            left, right = (fiber(cad.levels, cad.variables, (x,)) for x in (a, b))
            return [(sector_of(left, s), sector_of(right, s)) for s in seps]
    return None
