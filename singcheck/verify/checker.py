"""The checks of a certificate (docs/certificate.md): the robot and the path read again
from their texts, every enclosure recomputed on every piece of the proof's cover, and
the claim derived from what is proven.  Nothing of the proof is trusted but the cover's
cut points, the signs to check and the witnesses of infeasibility, each re-checked.

A prismatic leg F(ρ, X) = a ρ² + b ρ + c (a, b, c polynomials of the pose X) has the
branches ρ± = (−b ± √D)/(2a), D = b² − 4ac (the label '+' or '-', in joint order, of a
working mode); a linear leg (a ≡ 0) the one branch −c/b (label 'o'); a revolute leg
a cos θ + b sin θ + d the branches of :func:`branches_on`.  On a piece T the pose is
enclosed from the path's expressions, D's enclosure must be > 0 (real, distinct
branches: the branch is continuous on T), a ≠ 0, and the branch's enclosure inside the
closed joint limits; det A = det(∂F/∂X) along a mode is enclosed from the branches.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import product

from singcheck.verify.numbers import PI, Iv, NotDecided, cos, sin
from singcheck.verify.reader import (
    NotRational,
    Refused,
    coefficient,
    constant,
    derivative,
    mul,
    parse_expr,
    parse_yaml,
    poly,
)

ROBOT_KEYS = {"name", "description", "joints", "pose", "parameters", "constraints",
              "joint_limits", "drawing"}
PATH_KEYS = {"name", "parameter", "range", "pose"}


class NotRecheckable(Exception):
    """A robot or path this checker cannot re-check (the reason says which)."""


def _names(value, what: str) -> list[str]:
    if not isinstance(value, list) or not value or not all(
            isinstance(v, str) and v.isidentifier() for v in value):
        raise Refused(f"{what}: expected a list of names")
    if len(set(value)) != len(value):
        raise Refused(f"{what}: a name given twice")
    return value


class Robot:
    """Joints, pose, each leg's a, b, c, the Jacobian ∂F/∂X and the limits."""

    def __init__(self, text: str) -> None:
        spec = parse_yaml(text)
        if not isinstance(spec, dict) or not {"name", "joints", "pose", "constraints"} <= \
                set(spec) or set(spec) - ROBOT_KEYS:
            raise Refused("a robot spec needs name, joints, pose, constraints (and no "
                          "other key than " + ", ".join(sorted(ROBOT_KEYS)) + ")")
        self.name = spec["name"]
        self.joints = _names(spec["joints"], "joints")
        self.pose = _names(spec["pose"], "pose")
        self.params: dict[str, Fraction] = {}
        for key, text_ in (spec.get("parameters") or {}).items():
            try:
                self.params[key] = constant(parse_expr(text_), self.params)
            except NotRational as e:
                raise NotRecheckable(f"parameter {key} is not rational ({e})") from None
        n = len(self.joints)  # the box: (v, cos v, sin v) per joint, then per pose variable
        if len(self.pose) != n:
            raise Refused("as many pose variables as joints")
        vs = tuple(x for v in self.joints + self.pose for x in (v, f"cos({v})", f"sin({v})"))
        cons = spec["constraints"]
        if not isinstance(cons, list) or len(cons) != n:
            raise Refused("constraints: one per joint")
        self.legs: list = [None] * n
        for text_ in cons:
            try:
                f = poly(parse_expr(text_), vs, self.params)
            except NotRational as e:
                raise NotRecheckable(str(e)) from None
            used = [k for k in range(n) if any(e[3 * k] + e[3 * k + 1] + e[3 * k + 2]
                                               for e in f)]
            if len(used) != 1 or self.legs[used[0]] is not None:
                raise Refused("each constraint must involve exactly one joint, its own")
            k = used[0]
            jac = [_d_pose(f, 3 * n + 3 * j) for j in range(n)]
            if any(e[3 * k + 1] + e[3 * k + 2] for e in f):  # revolute: a c + b s + d
                if any(e[3 * k] for e in f):
                    raise NotRecheckable(f"{self.joints[k]} is both a length and an angle")
                f = _on_circle(f, 3 * k + 1, 3 * k + 2)
                jac = [_on_circle(p, 3 * k + 1, 3 * k + 2) for p in jac]
                if any(e[3 * k + 1] + e[3 * k + 2] > 1 for e in f):
                    raise NotRecheckable(f"leg {self.joints[k]} is not a·cos + b·sin + d")
                a, b = coefficient(f, 3 * k + 1, 1), coefficient(f, 3 * k + 2, 1)
                d = coefficient(coefficient(f, 3 * k + 1, 0), 3 * k + 2, 0)
                disc = _combine((1, mul(a, a)), (1, mul(b, b)), (-1, mul(d, d)))
                self.legs[k] = (k, a, b, d, disc, jac, "r")
                continue
            degree = max(e[3 * k] for e in f)
            if degree not in (1, 2):
                raise NotRecheckable(f"{self.joints[k]} appears with degree {degree}")
            a, b, c = (coefficient(f, 3 * k, d) for d in (2, 1, 0))
            disc = _combine((1, mul(b, b)), (-4, mul(a, c)))
            self.legs[k] = (k, a, b, c, disc, jac, "p")
        self.limits: dict[int, tuple] = {}
        for key, pair in (spec.get("joint_limits") or {}).items():
            if key not in self.joints or not isinstance(pair, list) or len(pair) != 2:
                raise Refused(f"joint_limits: {key}")
            k = self.joints.index(key)
            if self.legs[k][6] == "r":  # θ inside [lo, hi] ⟺ cos(θ − m) ≥ cos(w/2)
                lo, hi = (value(parse_expr(x), self.params, INTERVAL) for x in pair)
                if (hi - lo).lo < (PI * 2).hi:  # (width 2π or more: no limit)
                    m, half = (lo + hi) / 2, (hi - lo) / 2
                    self.limits[k] = (cos(m), sin(m), cos(half))
                continue
            try:
                self.limits[k] = tuple(constant(parse_expr(x), self.params) for x in pair)
            except NotRational as e:
                raise NotRecheckable(f"joint_limits of {key}: {e}") from None
        self.angles = {j for j in range(n) for leg in self.legs for p in leg[1:4]
                       for e in p if e[3 * n + 3 * j + 1] + e[3 * n + 3 * j + 2]}
        self.labels = ["+-" if leg[1] or leg[6] == "r" else "o" for leg in self.legs]
        self.modes = ["".join(m) for m in product(*self.labels)]


def _on_circle(f: dict, ci: int, si: int) -> dict:
    """f reduced modulo cos² + sin² = 1 (sin² → 1 − cos²)."""
    out: dict = {}
    todo = list(f.items())
    while todo:
        e, v = todo.pop()
        if e[si] < 2:
            out[e] = out.get(e, 0) + v
            continue
        e = e[:si] + (e[si] - 2,) + e[si + 1:]
        todo += [(e, v), (e[:ci] + (e[ci] + 2,) + e[ci + 1:], -v)]
    return {e: v for e, v in out.items() if v}


def _combine(*terms) -> dict:
    """Σ k·p over the (k, p) pairs."""
    out: dict = {}
    for k, p in terms:
        for e, v in p.items():
            out[e] = out.get(e, 0) + k * v
    return {e: v for e, v in out.items() if v}


def _d_pose(f: dict, i: int) -> dict:
    """∂f/∂X for the pose variable X at index i, its cos and sin at i + 1, i + 2:
    ∂f/∂X − sin X·∂f/∂cos + cos X·∂f/∂sin."""
    def unit(j):
        return {tuple(int(m == j) for m in range(len(next(iter(f))))): Fraction(1)}
    return _combine((1, derivative(f, i)), (-1, mul(unit(i + 2), derivative(f, i + 1))),
                    (1, mul(unit(i + 1), derivative(f, i + 2))))


_COMPILED: dict = {}  # id(p) → (p, [(coefficient's enclosure, [(variable, power)])])


def evaluate(p: dict, values: list[Iv]) -> Iv:
    """An enclosure of the polynomial p over the box ``values`` (one per variable)."""
    hit = _COMPILED.get(id(p))
    if hit is None or hit[0] is not p:
        hit = _COMPILED[id(p)] = (p, [(Iv.q(c), [(k, d) for k, d in enumerate(e) if d])
                                      for e, c in p.items()])
    total = Iv(0, 0)
    powers: dict = {}
    for c, factors in hit[1]:
        for k, d in factors:
            if (k, d) not in powers:
                powers[k, d] = values[k] ** d
            c = c * powers[k, d]
        total = total + c
    return total


class Path:
    """The path's parameter, range and pose expressions (trees, evaluated on intervals):
    one piece, or segments joined end to end at rational times, the pose continuous
    there (decided exactly)."""

    def __init__(self, text: str, robot: Robot) -> None:
        spec = parse_yaml(text)
        if not isinstance(spec, dict):
            raise Refused("a trajectory spec must be a mapping")
        keys = set(spec) - {"interpolation"}
        if keys not in (PATH_KEYS, {"name", "parameter", "segments"},
                        {"name", "parameter", "waypoints"}) or \
                (spec.get("interpolation") and "waypoints" not in spec):
            raise Refused("a trajectory spec needs name, parameter, and range and pose, "
                          "segments or waypoints")
        self.name, self.param = spec["name"], spec["parameter"]
        if not isinstance(self.param, str) or not self.param.isidentifier() or \
                self.param in robot.joints + robot.pose + list(robot.params) + ["pi"]:
            raise Refused("parameter: a new name")
        self.known, self.segments, ends, self.joins = {**robot.params}, [], [], []
        raw = _waypoints(spec, robot, self.param) if "waypoints" in spec else []
        for piece in spec.get("segments", [{k: spec.get(k) for k in ("range", "pose")}]) \
                if not raw else []:
            rng, pose = (piece.get(k) if isinstance(piece, dict) else None
                         for k in ("range", "pose"))
            if not isinstance(rng, list) or len(rng) != 2 or not isinstance(pose, dict) or \
                    set(pose) != set(robot.pose) or len(piece) != 2:
                raise Refused("range: [start, end]; pose: every pose variable of the robot")
            raw.append(([parse_expr(x) for x in rng], [parse_expr(pose[v]) for v in robot.pose]))
        for rng, trees in raw:
            if any(_unknown(tree, {*self.known, self.param}) for tree in trees):
                raise Refused("pose: an unknown name")
            start, end = (value(x, self.known, INTERVAL) for x in rng)
            if not start.hi < end.lo:
                raise Refused("range: start must be below end")
            self.segments.append((start, end, trees))
            ends.append(rng)
        self.start, self.end = self.segments[0][0], self.segments[-1][1]
        for k in range(len(ends) - 1):
            try:
                join = constant(ends[k][1], self.known)
                if join != constant(ends[k + 1][0], self.known):
                    raise Refused(f"segments {k + 1} and {k + 2} do not meet")
                here = [[value(t, {**self.known, self.param: join}, EXACT) for t in trees]
                        for trees in (self.segments[k][2], self.segments[k + 1][2])]
            except (NotRational, NotDecided):
                raise NotRecheckable(f"the pose's continuity at the join of segments "
                                     f"{k + 1} and {k + 2} cannot be decided") from None
            if here[0] != here[1]:
                raise Refused(f"the pose jumps between segments {k + 1} and {k + 2}")
            self.joins.append(join)

    def trees_on(self, t: Iv) -> list:
        """The pose expressions of the segment holding all of t."""
        for start, end, trees in self.segments:
            if start.lo <= t.lo and t.hi <= end.hi:
                return trees
        raise NotDecided("a piece across a join of segments")

    def pose_on(self, t: Iv) -> list[Iv]:
        env = {**self.known, self.param: t}
        return [value(tree, env, INTERVAL) for tree in self.trees_on(t)]


def _waypoints(spec: dict, robot: Robot, param: str) -> list:
    """The pieces between waypoints, [(range, pose trees)]: straight lines, or the
    natural cubic spline (second derivatives M with M₀ = Mₙ = 0 solving
    hᵢ₋₁Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ)Mᵢ + hᵢMᵢ₊₁ = 6(Δᵢ − Δᵢ₋₁), Δᵢ = (yᵢ₊₁ − yᵢ)/hᵢ; on a piece
    y = yᵢ + (Δᵢ − h(2Mᵢ + Mᵢ₊₁)/6)u + Mᵢu²/2 + (Mᵢ₊₁ − Mᵢ)u³/6h, u = t − tᵢ)."""
    kind, rows = spec.get("interpolation", "cubic"), spec["waypoints"]
    names = [param, *robot.pose]
    if kind not in ("linear", "cubic") or not isinstance(rows, list) or \
            not 2 <= len(rows) <= 10_000 or any(not isinstance(r, dict) or set(r) != set(names)
                                                for r in rows):
        raise Refused(f"waypoints: 2 or more {{{', '.join(names)}}}, interpolation linear "
                      "or cubic")
    table = [[constant(parse_expr(r[v])) for v in names] for r in rows]
    ts = [row[0] for row in table]
    if any(a >= b for a, b in zip(ts, ts[1:], strict=False)):
        raise Refused(f"waypoints: {param} must increase")
    n, hs = len(ts) - 1, [b - a for a, b in zip(ts, ts[1:], strict=False)]
    coefficients = []  # per pose variable, per piece: [c0, c1, c2, c3] in u
    for j in range(1, len(names)):
        ys = [row[j] for row in table]
        slope = [(ys[i + 1] - ys[i]) / hs[i] for i in range(n)]
        m = [Fraction(0)] * (n + 1)
        if kind == "cubic" and n > 1:  # Thomas' algorithm over Q
            diag, rhs = [Fraction(0)] * (n + 1), [Fraction(0)] * (n + 1)
            for i in range(1, n):
                w = hs[i - 1] / diag[i - 1] if i > 1 else Fraction(0)
                diag[i] = 2 * (hs[i - 1] + hs[i]) - w * hs[i - 1]
                rhs[i] = 6 * (slope[i] - slope[i - 1]) - w * rhs[i - 1]
            for i in range(n - 1, 0, -1):
                m[i] = (rhs[i] - hs[i] * m[i + 1]) / diag[i]
        coefficients.append([[ys[i], slope[i] - hs[i] * (2 * m[i] + m[i + 1]) / 6, m[i] / 2,
                              (m[i + 1] - m[i]) / (6 * hs[i])] for i in range(n)])
    out = []
    for i in range(n):
        u = ("-", ("var", param), ("num", ts[i]))
        trees = []
        for per_piece in coefficients:
            c = per_piece[i]
            trees.append(("+", ("num", c[0]), ("*", u, ("+", ("num", c[1]), ("*", u, (
                "+", ("num", c[2]), ("*", u, ("num", c[3]))))))))
        out.append(([("num", ts[i]), ("num", ts[i + 1])], trees))
    return out


def _unknown(tree, names: set) -> bool:
    if tree[0] == "var":
        return tree[1] not in names
    return any(_unknown(s, names) for s in tree[1:] if isinstance(s, tuple))


def value(tree, env: dict, leaf: dict):
    """The value of an expression tree in an arithmetic: ``leaf`` says what numbers, π,
    sin, cos and sqrt are in it (:data:`INTERVAL`, :data:`EXACT`); + - * / ^ are its
    operators; ``env`` gives the names."""
    op = tree[0]
    if op in ("num", "pi"):
        return leaf[op](*tree[1:])
    if op == "var":
        if tree[1] not in env:
            raise Refused(f"unknown name {tree[1]!r}")
        x = env[tree[1]]
        return leaf["num"](x) if isinstance(x, Fraction) else x
    v = [value(s, env, leaf) for s in tree[1:] if isinstance(s, tuple)]
    if op in ("sin", "cos", "sqrt"):
        return leaf[op](v[0])
    if op == "neg":
        return -v[0]
    if op == "^":
        return v[0] ** tree[2]
    a, b = v
    if op == "/" and not isinstance(b, Iv) and b == 0:
        raise NotDecided("division by zero")
    return a + b if op == "+" else a - b if op == "-" else a * b if op == "*" else a / b


def _exact_root(x: Fraction):
    """√x exactly: a rational, or a :class:`_Surd` (x > 0 not a square)."""
    if x < 0:
        raise NotDecided("the square root of a negative number at an exact time")
    root, kernel = _square_free(x.numerator * x.denominator)
    return _surd({kernel: Fraction(root, x.denominator)})


class _Surd(dict):
    """Σ c_k·√k exactly, k squarefree positive integers (1: the rational part), with some
    k > 1 (a rational is a Fraction: :func:`_surd`): x = √2·t at t = 1.  Square roots of
    distinct squarefree integers are linearly independent over Q: two are equal exactly
    when their coefficients are; √k·√l = s·√m with kl = s²·m.  Never divided by, nor a
    sin, cos or square root argument (NotDecided)."""

    def __add__(self, o):
        out = dict(self)
        for k, c in _terms(o).items():
            out[k] = out.get(k, 0) + c
        return _surd(out)

    def __mul__(self, o):
        out: dict = {}
        for (k, c), (m, d) in product(self.items(), _terms(o).items()):
            root, kernel = _square_free(k * m)
            out[kernel] = out.get(kernel, 0) + c * d * root
        return _surd(out)

    __radd__, __rmul__ = __add__, __mul__
    __neg__ = lambda self: self * -1  # noqa: E731
    __sub__ = lambda self, o: self + -o  # noqa: E731
    __rsub__ = lambda self, o: self * -1 + o  # noqa: E731
    __truediv__ = lambda self, o: self * (1 / _rational(o))  # noqa: E731
    __rtruediv__ = lambda self, o: 1 / _rational(self)  # noqa: E731
    __pow__ = lambda self, n: _rational(self) if n < 0 else (  # noqa: E731
        self * self ** (n - 1) if n else Fraction(1))


def _terms(x) -> dict:
    if isinstance(x, _Surd):
        return x
    if isinstance(x, _Pi):
        raise NotDecided("π beside a square root at an exact time")
    return {1: Fraction(x)} if x else {}


def _surd(terms: dict):
    """The number Σ c_k·√k: a Fraction when it is rational, else a :class:`_Surd`."""
    terms = {k: c for k, c in terms.items() if c}
    if all(k == 1 for k in terms):
        return terms.get(1, Fraction(0))
    return _Surd(terms)


class _Pi(tuple):
    """(q, p): q + p·π exactly, p ≠ 0 (a sin or cos argument: 2πt at t = 1/4)."""

    def __add__(self, o):
        q, p = _qp(o)
        return _pi(self[0] + q, self[1] + p)

    def __neg__(self):
        return _Pi((-self[0], -self[1]))

    def __mul__(self, o):
        return _pi(self[0] * _rational(o), self[1] * _rational(o))

    __radd__, __rmul__ = __add__, __mul__
    __sub__ = lambda self, o: self + -o  # noqa: E731
    __rsub__ = lambda self, o: -self + o  # noqa: E731
    __truediv__ = lambda self, o: self * (1 / _rational(o))  # noqa: E731
    __pow__ = lambda self, n: self if n == 1 else _rational(self)  # noqa: E731
    __rtruediv__ = lambda self, o: _rational(self)  # noqa: E731


def _qp(x) -> tuple[Fraction, Fraction]:
    return x if isinstance(x, _Pi) else (_rational(x), Fraction(0))


def _pi(q: Fraction, p: Fraction):
    return _Pi((q, p)) if p else q


#: sin(kπ/6) for k mod 12, where it is rational
_SIXTHS = {0: 0, 1: Fraction(1, 2), 3: 1, 5: Fraction(1, 2), 6: 0, 7: Fraction(-1, 2),
           9: -1, 11: Fraction(-1, 2)}


def _exact_trig(x, quarter: int) -> Fraction:
    """sin(x + quarter·π/2) exactly, where it is rational: x = 0, or x a rational multiple
    of π with a rational sine (k·π/6)."""
    q, p = _qp(x)
    k = (p + Fraction(quarter, 2)) * 6
    if q or k.denominator != 1 or int(k) % 12 not in _SIXTHS:
        raise NotDecided("sin or cos at an exact time with no rational value")
    return Fraction(_SIXTHS[int(k) % 12])


def _rational(x) -> Fraction:
    if isinstance(x, _Pi):
        raise NotDecided("π where a rational is needed, at an exact time")
    if isinstance(x, _Surd):
        raise NotDecided("a square root where a rational is needed, at an exact time")
    return Fraction(x)


INTERVAL = {"num": Iv.q, "pi": lambda: PI, "sin": sin, "cos": cos, "sqrt": Iv.sqrt}
EXACT = {"num": Fraction, "pi": lambda: _Pi((Fraction(0), Fraction(1))),
         "sqrt": lambda x: _exact_root(_rational(x)),
         "sin": lambda x: _exact_trig(x, 0), "cos": lambda x: _exact_trig(x, 1)}


def _inside(lim, v) -> bool:
    if lim is None:
        return True
    if isinstance(v, tuple):  # an angle's (cos, sin)
        return (v[0] * lim[0] + v[1] * lim[1] - lim[2]).lo >= 0
    return Iv.q(lim[0]).hi <= v.lo and v.hi <= Iv.q(lim[1]).lo


def _outside(lim, v) -> bool:
    if lim is None or v is None:
        return False
    if isinstance(v, tuple):
        return (v[0] * lim[0] + v[1] * lim[1] - lim[2]).negative()
    return v.hi < Iv.q(lim[0]).lo or v.lo > Iv.q(lim[1]).hi


def _box(robot: Robot, pose: list) -> list:
    zero = Iv(0, 0)
    return [zero] * (3 * len(robot.joints)) + [
        x for j, v in enumerate(pose)
        for x in ((v, cos(v), sin(v)) if j in robot.angles else (v, zero, zero))]


def branches_on(robot: Robot, pose: list[Iv]) -> list[dict]:
    """Per leg, label → (enclosure of the branch, proven real, separated and inside the
    limits?) over the pose box; enclosure None when it could not be enclosed.  A
    revolute leg's branch is the pair (cos θ, sin θ) = ((−ad + σb√Δ)/w, (−bd − σa√Δ)/w),
    w = a² + b², Δ = w − d², σ = +1 for '+'."""
    box = _box(robot, pose)
    out = []
    for k, a, b, c, disc, _, kind in robot.legs:
        labels = "+-" if a or kind == "r" else "o"
        try:
            av, bv = evaluate(a, box), evaluate(b, box)
            d = evaluate(disc, box) if labels == "+-" else None
            root = d.sqrt() if d is not None and d.positive() else None
            if kind == "r":
                cv, w = evaluate(c, box), av ** 2 + bv ** 2
                values = {lab: None if root is None else ((-av * cv + sg * bv * root) / w,
                                                          (-bv * cv - sg * av * root) / w)
                          for lab, sg in (("+", 1), ("-", -1))}
                real = root is not None
            elif a:
                values = {lab: None if root is None else (sg * root - bv) / (av * 2)
                          for lab, sg in (("+", 1), ("-", -1))}
                real = root is not None and av.sign() != 0
            else:
                values = {"o": -evaluate(c, box) / bv}
                real = bv.sign() != 0
        except NotDecided:
            values, real = {label: None for label in labels}, False
        out.append({label: (v, v is not None and real and _inside(robot.limits.get(k), v))
                    for label, v in values.items()})
    return out


def det(m: list, mul=lambda a, b: a * b, add=lambda a, b, sign: a + b if sign > 0 else a - b):
    """Cofactor expansion along the first row (a robot has a few legs)."""
    if len(m) == 1:
        return m[0][0]
    total = None
    for j, head in enumerate(m[0]):
        term = mul(head, det([row[:j] + row[j + 1:] for row in m[1:]], mul, add))
        total = term if total is None else add(total, term, -1 if j % 2 else 1)
    return total


def piece_values(robot: Robot, path: Path, t: Iv, modes: list[str]):
    """(branches per leg, {mode: det A enclosure or None}) over the piece t."""
    pose = path.pose_on(t)
    legs = branches_on(robot, pose)
    dets = {}
    for mode in modes:
        box = _box(robot, pose)
        for k, ch in enumerate(mode):
            v = legs[k][ch][0]
            if v is None:
                break
            if isinstance(v, tuple):
                box[3 * k + 1], box[3 * k + 2] = v
            else:
                box[3 * k] = v
        else:
            dets[mode] = det([[evaluate(p, box) for p in leg[5]] for leg in robot.legs])
            continue
        dets[mode] = None
    return legs, dets


def outside(robot: Robot, path: Path, t: Fraction, mode: str, leg: int) -> bool:
    """Proven: at time t the branch of ``leg`` in ``mode`` is not real, or is outside the
    closed joint limits."""
    k, a, b, c, disc, _, kind = robot.legs[leg]
    pose = path.pose_on(Iv.q(t))
    if (a or kind == "r") and evaluate(disc, _box(robot, pose)).negative():
        return True
    return _outside(robot.limits.get(k), branches_on(robot, pose)[leg][mode[leg]][0])


# Numbers of Q(√d₀, …, √dₙ₋₁) as {mask: q}: Σ q·Π_{i in mask} √dᵢ.  A number whose
# coefficients all vanish is 0 (whatever relations the √dᵢ have): all that is needed.
def _mq_mul(x: dict, y: dict, ds: list) -> dict:
    out: dict = {}
    for m1, c1 in x.items():
        for m2, c2 in y.items():
            c = c1 * c2
            for i, d in enumerate(ds):
                if m1 >> i & m2 >> i & 1:
                    c *= d
            out[m1 ^ m2] = out.get(m1 ^ m2, 0) + c
    return {m: c for m, c in out.items() if c}


def _mq_add(x: dict, y: dict, sign: int = 1) -> dict:
    out = dict(x)
    for m, c in y.items():
        out[m] = out.get(m, 0) + sign * c
    return {m: c for m, c in out.items() if c}


def _mq_poly(p: dict, values: list, ds: list) -> dict:
    total: dict = {}
    for e, c in p.items():
        term = {0: c}
        for k, d in enumerate(e):
            for _ in range(d):
                term = _mq_mul(term, values[k], ds)
        total = _mq_add(total, term)
    return total


def singular_at(robot: Robot, path: Path, t: Fraction, mode: str) -> bool:
    """Proven: at the rational time t the mode's branches are real and distinct and
    det A = 0 exactly (the branches in Q(√D₀, …, √k₀, …), D the legs' discriminants
    there, k the square roots in the pose itself: x = √2·t at t = 1)."""
    pose = [value(tree, {**path.known, path.param: t}, EXACT)
            for tree in path.trees_on(Iv.q(t))]
    if any(_rational(pose[j]) for j in robot.angles):
        raise NotDecided("sin or cos of a non-zero pose angle")
    legs = len(robot.legs)
    kernels = sorted({k for x in pose if isinstance(x, _Surd) for k in x if k != 1})
    ds: list = [None] * legs + [Fraction(k) for k in kernels]  # the legs' D set below

    def masked(x) -> dict:  # an exact pose value as Σ c·Π√dᵢ over the bits of ds
        return {0 if k == 1 else 1 << (legs + kernels.index(k)): c
                for k, c in _terms(x).items()}

    values: list = [{} for _ in range(3 * len(robot.joints))] + [
        masked(x) if i == 0 else {0: Fraction(1)} if i == 1 and j in robot.angles
        else {} for j, x in enumerate(pose) for i in range(3)]
    at_pose = list(values)  # the legs' coefficients: polynomials of the pose alone
    for k, a, b, c, disc, _, kind in robot.legs:
        av, bv, cv, d = (_mq_poly(p, at_pose, ds) for p in (a, b, c, disc))
        av, d = _mq_rational(av), _mq_rational(d)
        s = 1 if mode[k] == "+" else -1
        if kind == "r" and d > 0:
            bv = _mq_rational(bv)
            w = av * av + bv * bv
            values[3 * k + 1] = _mq_add(_mq_mul(cv, {0: -av / w}, ds), {1 << k: s * bv / w})
            values[3 * k + 2] = _mq_add(_mq_mul(cv, {0: -bv / w}, ds), {1 << k: -s * av / w})
        elif kind == "p" and a and d > 0 and av != 0:
            values[3 * k] = _mq_add(_mq_mul(bv, {0: -1 / (2 * av)}, ds), {1 << k: s / (2 * av)})
        elif kind == "p" and not a and _mq_rational(bv) != 0:
            values[3 * k], d = _mq_mul(cv, {0: -1 / _mq_rational(bv)}, ds), Fraction(1)
        else:
            return False
        ds[k] = d
    total = det([[_mq_poly(p, values, ds) for p in leg[5]] for leg in robot.legs],
                lambda x, y: _mq_mul(x, y, ds), _mq_add)
    return _is_zero(total, ds)


def _mq_rational(x: dict) -> Fraction:
    """Σ c·Π√dᵢ when rational (a leg's coefficient or discriminant), else NotDecided."""
    if any(m and c for m, c in x.items()):
        raise NotDecided("a leg's coefficient is irrational at an exact pose")
    return Fraction(x.get(0, 0))


def _is_zero(value: dict, ds: list) -> bool:
    """Whether Σ q·Π_{i in mask} √dᵢ is 0: each product is s·√k with k a squarefree
    integer, and square roots of distinct squarefree integers are linearly independent
    over Q, so it is 0 exactly when the coefficients of each √k sum to 0."""
    sums: dict[int, Fraction] = {}
    for mask, q in value.items():
        product = Fraction(1)
        for i, d in enumerate(ds):
            if mask >> i & 1:
                product *= d
        if product == 0:
            continue
        root, kernel = _square_free(product.numerator * product.denominator)
        sums[kernel] = sums.get(kernel, Fraction(0)) + q * Fraction(root, product.denominator)
    return all(v == 0 for v in sums.values())


def _square_free(m: int) -> tuple[int, int]:
    """(s, k) with m = s²·k, k squarefree (m > 0), by trial division."""
    if m.bit_length() > 48:
        raise NotDecided("a discriminant too large to split into square and squarefree parts")
    root, kernel, p = 1, 1, 2
    while p * p <= m:
        e = 0
        while m % p == 0:
            m //= p
            e += 1
        root *= p ** (e // 2)
        kernel *= p if e % 2 else 1
        p += 1 if p == 2 else 2
    return root, kernel * m
