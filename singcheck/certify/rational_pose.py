"""det A = 0 decided exactly at one time where the pose is rational (a range end).

A path that starts or ends on the singularity (a hexapod's home pose, where det A = 0
in many modes) leaves the interval engine a window at that end: balls never prove a
zero.  When the pose variables are rational there (a polynomial path at a rational
end; any trig path at t = 0, or at t = kπ when the bare t is absent), each leg's
branch is rational + rational·√Δᵢ (Δᵢ its discriminant there), so row i of A (which
involves joint i only) is uᵢ + vᵢ·rᵢ with rᵢ = ±√Δᵢ and u, v rational, and

    det A = Σ_S c_S · Π_{i∈S} rᵢ,   c_S = det(M_S), row i of M_S = vᵢ if i ∈ S else uᵢ

(the determinant is multilinear in its rows).  Each Π √Δᵢ is q·√k with q rational and
k a squarefree integer; square roots of distinct squarefree integers are linearly
independent over Q, so det A = 0 exactly when, for every k, the rational sum of the
terms in √k is 0.  Everything is exact (FLINT's rational matrices and integer
factoring).  Robots with square roots among their numbers are not handled (None).
"""

from __future__ import annotations

from fractions import Fraction
from math import isqrt

from flint import fmpq, fmpq_mat, fmpz

from singcheck.algebra.trig import TRIG, LinearInPi
from singcheck.model.robot import REVOLUTE

#: a pose whose legs' discriminant numerators and denominators exceed this many bits is
#: not decided here (their squarefree parts need factoring)
MAX_FACTOR_BITS = 200


def rational_pose(path, end: LinearInPi) -> list[fmpq] | None:
    """The model's pose variables at the piece time ``end``, when all are rational (None
    otherwise)."""
    values = pose_values(path, end)
    return None if any(v is None for v in values) else values


def simple_times(lo: float, hi: float, rng) -> list[LinearInPi]:
    """The times of (lo, hi) where an exact value is tried: its simplest rational, and
    an integer multiple of π in it, each strictly inside the range ``rng`` (the other
    points of a touch are not rational where the pose is)."""
    import math

    from singcheck.roots.rational import simplest_between

    a, b = Fraction(lo), Fraction(hi)
    out = [LinearInPi(simplest_between(a, b))] if a < b else []
    k = math.ceil(lo / math.pi)
    if k and k * math.pi < hi:
        out.append(LinearInPi(Fraction(0), Fraction(k)))
    return [t for t in out if rng.start.ball() < t.ball() < rng.end.ball()]


def pose_values(path, end: LinearInPi) -> list[fmpq | None]:
    """Each of the model's pose variables at the piece time ``end``, exactly, where it
    is rational and known so (None where not: x = √2·t at t = 1)."""
    if end.pi_coefficient:
        if end.rational or end.pi_coefficient.denominator != 1:
            return [None] * len(path.coordinates)
        t, s, c = None, fmpq(0), fmpq(1 if end.pi_coefficient.numerator % 2 == 0 else -1)
    else:
        q = end.rational
        t = fmpq(q.numerator, q.denominator)
        s, c = (fmpq(0), fmpq(1)) if q == 0 else (None, None)
    return [_exact_ball(x, end) if x.context() is not TRIG else _trig_value(x, t, s, c)
            for x in path.coordinates]


def pose_factor_vanishes(model, values: list[fmpq | None]) -> bool:
    """Proven: a factor of det A in the pose variables alone is 0 at the pose ``values``
    (those it involves known exactly), so det A = 0 there along every working mode
    whatever the joints (the biglide's y of det A = 4·y·(q − p) at x = √2, y = 0)."""
    from singcheck.model.robot import det_a_factors

    names = model.context.names()
    known = {names.index(v): value
             for v, value in zip(model.pose_variables, values, strict=True)
             if value is not None}
    for factor, _ in det_a_factors(model):
        used = [i for i, d in enumerate(factor.degrees()) if d]
        if used and all(i in known for i in used):
            point = [known.get(i, fmpq(0)) for i in range(len(names))]
            if factor(*point) == 0:
                return True
    return False


def leg_discriminant_at(model, leg, pose: list[fmpq | None]) -> fmpq | None:
    """The discriminant of ``leg`` (b² − 4ac, or Δ = a² + b² − d² for a revolute leg) at
    the pose ``pose`` exactly, when the values its coefficients involve are known (None
    otherwise, or for a linear leg)."""
    from singcheck.certify.path import _leg_coefficients

    if leg.kind != REVOLUTE and leg.degree == 1:
        return None
    point = {name: value for name, value in zip(model.pose_variables, pose, strict=True)
             if value is not None}
    coeffs = [_value(p, point) for p in _leg_coefficients(leg)]
    if any(v is None for v in coeffs):
        return None
    a, b, c = coeffs
    return a * a + b * b - c * c if leg.kind == REVOLUTE else b * b - 4 * a * c


def _trig_value(x, t, s, c) -> fmpq | None:
    """A coordinate polynomial in (t, sin t, cos t) at the end, when the values it
    involves are known."""
    dt, ds, dc = x.degrees()
    if (dt > 0 and t is None) or ((ds > 0 or dc > 0) and s is None):
        return None
    value = fmpq(0)
    for (i, j, k), coeff in x.terms():
        term = coeff
        if i:
            term *= t ** i
        if j:
            term *= s ** j
        if k:
            term *= c ** k
        value += term
    return value


def _exact_ball(x, end: LinearInPi) -> fmpq | None:
    """x at the end, when its enclosure there is an exact ball (radius 0: every operation
    was exact, as sin 0 = 0 is): that ball *is* the value, a dyadic rational; else its
    exact value when every variable of its ring has one (:func:`_exact_value`)."""
    from singcheck.algebra.radicals import evaluate_path

    ball = evaluate_path(x, end.ball())
    if not ball.is_finite() or not ball.is_exact():
        return _exact_value(x, end)
    man, exp = ball.mid().man_exp()
    return fmpq(man * fmpz(2) ** int(exp)) if exp >= 0 else fmpq(man, fmpz(2) ** int(-exp))


#: sin(bπ) for the b in [0, 2) where it is rational (Niven: 0, ±1/2, ±1)
_RATIONAL_SINES = {Fraction(0): 0, Fraction(1, 6): Fraction(1, 2), Fraction(1, 2): 1,
                   Fraction(5, 6): Fraction(1, 2), Fraction(1): 0,
                   Fraction(7, 6): Fraction(-1, 2), Fraction(3, 2): -1,
                   Fraction(11, 6): Fraction(-1, 2)}


def _sine(a: Fraction, b: Fraction) -> Fraction | None:
    """sin(a + bπ) when it is rational and known so exactly (a = 0), else None."""
    if a:
        return None
    value = _RATIONAL_SINES.get(b % 2)
    return None if value is None else Fraction(value)


def _tree_value(node, t: tuple[Fraction, Fraction], parameter: str, constants: dict):
    """An expression tree's exact value a + bπ as (a, b), or None where it is not known
    exactly this way (a product of two π parts, a sine that is irrational, …)."""
    k = node.kind
    if k == "num":
        return (node.value, Fraction(0)) if isinstance(node.value, Fraction) else None
    if k == "name":
        if node.value == parameter:
            return t
        if node.value == "pi":
            return Fraction(0), Fraction(1)
        value = constants.get(node.value)
        return (value, Fraction(0)) if isinstance(value, Fraction) else None
    args = [_tree_value(a, t, parameter, constants) for a in node.args]
    if any(a is None for a in args):
        return None
    if k == "neg":
        return -args[0][0], -args[0][1]
    if k in ("add", "sub"):
        sign = 1 if k == "add" else -1
        return args[0][0] + sign * args[1][0], args[0][1] + sign * args[1][1]
    if k == "mul":
        (a, b), (c, d) = args
        if b and d:
            return None
        return a * c, a * d + b * c
    if k == "div":
        (a, b), (c, d) = args
        if d or not c:
            return None
        return a / c, b / c
    if k == "pow":
        (a, b), (e, f) = args
        if b or f or e.denominator != 1 or e < 0:
            return None
        return a ** int(e), Fraction(0)
    if k == "call":
        (a, b), = args
        if node.value == "sin":
            value = _sine(a, b)
        elif node.value == "cos":
            value = _sine(a, b + Fraction(1, 2))
        elif b or a < 0:
            value = None
        else:  # sqrt of a rational square
            num, den = isqrt(a.numerator), isqrt(a.denominator)
            value = Fraction(num, den) if Fraction(num * num, den * den) == a else None
        return None if value is None else (value, Fraction(0))
    return None


def _exact_value(x, end: LinearInPi) -> fmpq | None:
    """x at the end exactly, when t (or its sine and cosine) and every opaque
    coordinate of its ring have exact rational values there: a coordinate's expression
    tree evaluated in Q + Qπ, with the rational sines of rational multiples of π
    (y = sin(2πt)/2 at t = 1 is 0, though its ball there is not exact)."""
    from singcheck.algebra.opaque import opaque_of

    t = (end.rational, end.pi_coefficient)
    s, c = _sine(*t), _sine(t[0], t[1] + Fraction(1, 2))
    values: list = [None if t[1] else t[0], s, c]
    for name in x.context().names()[3:]:
        hit = opaque_of(name)
        if hit is None or hit[1] != "X":
            values.append(None)
            continue
        f = hit[0]
        value = _tree_value(f.tree, t, f.parameter, dict(f.constants))
        values.append(value[0] if value is not None and not value[1] else None)
    total = Fraction(0)
    for exps, coeff in x.terms():
        term = Fraction(int(coeff.p), int(coeff.q))
        for v, e in zip(values, exps, strict=True):
            if e:
                if v is None:
                    return None
                term *= v ** int(e)
        total += term
    return fmpq(total.numerator, total.denominator)


def _legs_at(model, point: dict) -> list | None:
    """Per leg (in constraint order): (joint variable names, {label: [(u, v) per
    variable]}, Δ) with each joint variable u + v·√Δ on the branch, or None."""
    from singcheck.certify.path import _leg_coefficients

    out = {}
    for leg in model.legs:
        coeffs = [_value(p, point) for p in _leg_coefficients(leg)]
        if any(v is None for v in coeffs):
            return None
        names = leg.variables
        if leg.kind == REVOLUTE:
            a, b, d = coeffs
            w = a * a + b * b
            if w == 0:
                return None
            delta = w - d * d
            branches = {label: [(-a * d / w, sigma * b / w), (-b * d / w, -sigma * a / w)]
                        for label, sigma in (("+", 1), ("-", -1))}
        elif leg.degree == 1:
            b, c = coeffs
            if b == 0:
                return None
            delta, branches = fmpq(0), {"o": [(-c / b, fmpq(0))]}
        else:
            a, b, c = coeffs
            if a == 0:
                return None
            delta = b * b - 4 * a * c
            branches = {label: [(-b / (2 * a), sigma / (2 * a))]
                        for label, sigma in (("+", 1), ("-", -1))}
        if delta < 0:
            return None
        out[leg.constraint_index] = (names, branches, delta)
    return [out[i] for i in sorted(out)]


def _value(p, point: dict) -> fmpq | None:
    """p at the point (a dict of every variable p uses), exactly."""
    names = p.context().names()
    total = fmpq(0)
    for exps, coeff in p.terms():
        term = coeff
        for name, e in zip(names, exps, strict=True):
            if e:
                if name not in point:
                    return None
                term *= point[name] ** e
        total += term
    return total


def _entry(p, point: dict, joint: dict, delta: fmpq) -> tuple[fmpq, fmpq] | None:
    """An entry of A as u + v·r (r² = Δ) at the point, the leg's joint variables being
    ``joint[name] = (u, v)``."""
    names = p.context().names()
    u_total, v_total = fmpq(0), fmpq(0)
    for exps, coeff in p.terms():
        u, v = coeff, fmpq(0)
        for name, e in zip(names, exps, strict=True):
            if not e:
                continue
            if name in point:
                factor = (point[name] ** e, fmpq(0))
            elif name in joint:
                factor = (fmpq(1), fmpq(0))
                for _ in range(e):
                    a, b = factor
                    c, d = joint[name]
                    factor = (a * c + b * d * delta, a * d + b * c)
            else:
                return None
            u, v = u * factor[0] + v * factor[1] * delta, u * factor[1] + v * factor[0]
        u_total += u
        v_total += v
    return u_total, v_total


def _square_class(q: fmpq) -> tuple[fmpq, int] | None:
    """(s, k) with √q = s·√k, s rational and k a squarefree positive integer (q > 0)."""
    n, d = int(q.p), int(q.q)
    m = n * d  # √(n/d) = √(n·d)/d
    if m.bit_length() > MAX_FACTOR_BITS:
        return None
    root, kernel = 1, 1
    for prime, e in fmpz(m).factor():
        root *= int(prime) ** (e // 2)
        if e % 2:
            kernel *= int(prime)
    return fmpq(root, d), kernel


def det_a_zero_modes(model, pose: list[fmpq], labels: list[str]) -> dict[str, bool] | None:
    """For each mode label (one branch label per leg, in leg order), whether det A = 0
    exactly at the rational pose; None when not decided here (square roots in the
    robot, a branch not real or a degenerate leg there, numbers too large)."""
    if model.spec.radical_variables or len(model.A) != len(model.legs):
        return None
    point = {name: value for name, value in zip(model.pose_variables, pose, strict=True)}
    legs = _legs_at(model, point)
    if legs is None:
        return None
    n = len(legs)
    classes = []
    for _, _, delta in legs:
        if delta == 0:
            classes.append((fmpq(0), 1))
            continue
        found = _square_class(delta)
        if found is None:
            return None
        classes.append(found)
    leg_labels = [leg.joint for leg in sorted(model.legs, key=lambda leg: leg.constraint_index)]
    order = [next(k for k, leg in enumerate(model.legs) if leg.joint == j) for j in leg_labels]
    out: dict[str, bool] = {}
    for label in labels:
        rows_u, rows_v = [], []
        for i, (names, branches, delta) in enumerate(legs):
            mark = label[order[i]]
            if mark not in branches:
                return None
            joint = dict(zip(names, branches[mark], strict=True))
            row = [_entry(p, point, joint, delta) for p in model.A[i]]
            if any(e is None for e in row):
                return None
            rows_u.append([e[0] for e in row])
            rows_v.append([e[1] for e in row])
        sums: dict[int, fmpq] = {}
        for subset in range(1 << n):
            rows = [rows_v[i] if subset >> i & 1 else rows_u[i] for i in range(n)]
            c = fmpq_mat(n, n, [x for row in rows for x in row]).det()
            if c == 0:
                continue
            scale, kernel = fmpq(1), 1
            for i in range(n):
                if subset >> i & 1:
                    s, k = classes[i]
                    scale *= s
                    common = _gcd(kernel, k)
                    scale *= common
                    kernel = kernel * k // (common * common)
            sums[kernel] = sums.get(kernel, fmpq(0)) + c * scale
        out[label] = all(v == 0 for v in sums.values())
    return out


def _gcd(a: int, b: int) -> int:
    from math import gcd

    return gcd(a, b)

