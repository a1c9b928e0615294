"""A generic 50-digit oracle for the field campaign (never imports singcheck).

The robot's constraints are read with SymPy from the same text the user wrote (``^`` is
``**``; decimals are made exact), so the oracle judges singcheck's answer on the input
as given: the inverse kinematics is solved per leg in closed form (a prismatic leg
``a ρ² + b ρ + c``: ρ = (−b ± √D)/(2a); a revolute leg reduced to
``a cos θ + b sin θ + d``: the two elbow branches), A = ∂F/∂X is differentiated by
SymPy and its determinant evaluated with mpmath at 50 digits along the path, per
working mode.  Sign changes of det A are refined by bisection, local minima of |det A|
(and of the joint-limit and discriminant margins) by golden-section search, so that a
tangential touch is seen as a minimum of about 1e-40.

Labels follow the documented convention (docs/outputs.md): ``+`` is the +√ branch,
``-`` the other, ``o`` a leg linear in its joint.  Modes are also matched to
singcheck's by their joints at the start, so a label convention cannot hide a
disagreement.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from fractions import Fraction

import mpmath as mp
import sympy as sp
from sympy.parsing.sympy_parser import parse_expr, standard_transformations

from tests.robot_oracles import _bisect  # (it imports nothing of singcheck's either)

mp.mp.dps = 50
GOLD = (mp.sqrt(5) - 1) / 2
ZERO = mp.mpf(10) ** -30  # |det A| below this at a refined minimum: a touch
NEAR = mp.mpf(10) ** -8  # |det A| or a margin below this but above ZERO: ambiguous
LIMIT_SLACK = mp.mpf(10) ** -35  # a joint this close to a limit is on it (closed limits)
TRIG = {"sin": sp.sin, "cos": sp.cos, "sqrt": sp.sqrt, "pi": sp.pi}


def parse(text, names: dict) -> sp.Expr:
    """An expression of the spec grammar, read by SymPy (exact: decimals are rationals)."""
    text = str(text).strip().replace("^", "**")
    if text.endswith(" deg"):
        return parse_expr(text[:-4], local_dict={**TRIG, **names},
                          transformations=standard_transformations) * sp.pi / 180
    expr = parse_expr(text, local_dict={**TRIG, **names},
                      transformations=standard_transformations, evaluate=True)
    return sp.nsimplify(expr, rational=True) if expr.has(sp.Float) else expr


# --- the robot ----------------------------------------------------------------------

@dataclass
class Leg:
    joint: str
    revolute: bool
    coeffs: object  # X -> (a, b, c) of the leg's equation
    lo: object = None
    hi: object = None

    def branches(self, X):
        """[(label, value, margin)]: margin > 0 where the branch is real and apart."""
        a, b, c = self.coeffs(*X)
        if self.revolute:
            W = a * a + b * b
            delta = W - c * c
            root = mp.sqrt(delta) if delta > 0 else mp.mpf(0)
            out = []
            for label, s in (("+", 1), ("-", -1)):
                cos_t = (-a * c + s * b * root) / W
                sin_t = (-b * c - s * a * root) / W
                out.append((label, mp.atan2(sin_t, cos_t), delta / W))
            return out
        if a == 0:
            return [("o", -c / b, mp.mpf(1))]
        D = b * b - 4 * a * c
        root = mp.sqrt(D) if D > 0 else mp.mpf(0)
        return [("+", (-b + root) / (2 * a), D), ("-", (-b - root) / (2 * a), D)]

    def limit_margin(self, value):
        if self.lo is None:
            return mp.inf
        if not self.revolute:
            return min(value - self.lo, self.hi - value)
        width = self.hi - self.lo
        if width >= 2 * mp.pi:
            return mp.inf
        u = (value - self.lo) % (2 * mp.pi)  # in [0, 2π)
        return min(u, width - u) if u <= width else -min(u - width, 2 * mp.pi - u)


@dataclass
class OracleRobot:
    name: str
    joints: list
    pose: list
    legs: list
    A: object  # (joints..., pose...) -> matrix entries (list of lists)
    A_has_joints: bool
    labels: list = field(default_factory=list)

    def det_A(self, rho, X):
        return mp.det(mp.matrix(self.A(*rho, *X)))


def robot_from_spec(spec: dict) -> OracleRobot:
    """The oracle's model of a robot spec (the dict a YAML robot file holds)."""
    joints = [sp.Symbol(j) for j in spec["joints"]]
    pose = [sp.Symbol(v) for v in spec["pose"]]
    names = {str(s): s for s in joints + pose}
    for key, value in (spec.get("parameters") or {}).items():
        names[key] = parse(value, names)
    F = [parse(c, names) for c in spec["constraints"]]
    limits = spec.get("joint_limits") or {}
    C, S, R = sp.Symbol("C__"), sp.Symbol("S__"), sp.Symbol("R__")
    legs = []
    for j, f in zip(joints, F, strict=True):
        assert f.has(j), (j, f)
        revolute = f.has(sp.cos(j)) or f.has(sp.sin(j))
        if revolute:
            g = sp.expand(f.subs({sp.cos(j): C, sp.sin(j): S}))
            assert not g.has(j), f"{j} outside sin/cos"
            _, rem = sp.reduced(g, [C**2 + S**2 - 1], C, S, order="lex")
            poly = sp.Poly(rem, C, S)
            assert poly.total_degree() <= 1, f"leg {j} is not a cos + b sin + d: {rem}"
            abc = (poly.coeff_monomial(C), poly.coeff_monomial(S), poly.coeff_monomial(1))
        else:
            poly = sp.Poly(sp.expand(f.subs(j, R)), R)
            assert poly.degree() <= 2
            cs = poly.all_coeffs()
            abc = ([0] * (3 - len(cs)) + cs)
            abc = tuple(sp.simplify(c) for c in abc)
        fn = sp.lambdify(pose, list(abc), modules="mpmath")
        lo = hi = None
        if str(j) in limits:
            lo, hi = (mp.mpf(sp.N(parse(v, names), 60)) for v in limits[str(j)])
        legs.append(Leg(str(j), revolute, fn, lo, hi))
    A = sp.Matrix([[sp.diff(f, v) for v in pose] for f in F])
    A_fn = sp.lambdify(joints + pose, A.tolist(), modules="mpmath")
    return OracleRobot(spec["name"], [str(j) for j in joints], [str(v) for v in pose], legs,
                       A_fn, bool(A.free_symbols & set(joints)))


# --- the path -----------------------------------------------------------------------

@dataclass
class Piece:
    t0: object  # mp numbers
    t1: object
    coords: object  # t -> list of pose values
    harmonics: float = 1.0


def natural_cubic(ts: list[Fraction], ys: list[Fraction]):
    """Second derivatives of the natural cubic spline, exactly (Thomas algorithm)."""
    n = len(ts) - 1
    h = [ts[i + 1] - ts[i] for i in range(n)]
    M = [Fraction(0)] * (n + 1)
    if n < 2:
        return M
    # rows i = 1..n-1: h[i-1] M[i-1] + 2(h[i-1]+h[i]) M[i] + h[i] M[i+1] = rhs
    a = [h[i - 1] for i in range(1, n)]
    b = [2 * (h[i - 1] + h[i]) for i in range(1, n)]
    c = [h[i] for i in range(1, n)]
    d = [6 * ((ys[i + 1] - ys[i]) / h[i] - (ys[i] - ys[i - 1]) / h[i - 1]) for i in range(1, n)]
    m = n - 1
    for i in range(1, m):
        w = a[i] / b[i - 1]
        b[i] -= w * c[i - 1]
        d[i] -= w * d[i - 1]
    x = [Fraction(0)] * m
    x[-1] = d[-1] / b[-1]
    for i in range(m - 2, -1, -1):
        x[i] = (d[i] - c[i] * x[i + 1]) / b[i]
    M[1:n] = x
    return M


def spline_pieces(rows: list[dict], variables: list[str], cubic: bool) -> list[Piece]:
    """The waypoints' interpolation, piece by piece, exactly (rational coefficients)."""
    ts = [Fraction(str(r["t"])) for r in rows]
    ys = {v: [Fraction(str(r[v])) for r in rows] for v in variables}
    Ms = {v: natural_cubic(ts, ys[v]) if cubic else [Fraction(0)] * len(ts) for v in variables}
    out = []
    for i in range(len(ts) - 1):
        t0, t1, h = ts[i], ts[i + 1], ts[i + 1] - ts[i]
        polys = []
        for v in variables:
            y0, y1, m0, m1 = ys[v][i], ys[v][i + 1], Ms[v][i], Ms[v][i + 1]
            # S(u) = y0 + B u + m0/2 u^2 + (m1 - m0)/(6h) u^3, u = t - t0
            B = (y1 - y0) / h - h * (2 * m0 + m1) / 6
            polys.append((y0, B, m0 / 2, (m1 - m0) / (6 * h)))

        def coords(t, polys=polys, t0=t0):
            u = t - mp.mpf(t0.numerator) / t0.denominator
            return [mp.mpf(p0.numerator) / p0.denominator
                    + u * (mp.mpf(p1.numerator) / p1.denominator
                           + u * (mp.mpf(p2.numerator) / p2.denominator
                                  + u * mp.mpf(p3.numerator) / p3.denominator))
                    for p0, p1, p2, p3 in polys]
        out.append(Piece(mp.mpf(t0.numerator) / t0.denominator,
                         mp.mpf(t1.numerator) / t1.denominator, coords))
    return out


def expression_piece(t0, t1, pose: dict, variables: list[str], params: dict,
                     parameter: str = "t") -> Piece:
    tsym = sp.Symbol(parameter)
    names = {parameter: tsym, **params}
    exprs = [parse(pose[v], names) for v in variables]
    fn = sp.lambdify(tsym, exprs, modules="mpmath")
    # how fast it oscillates: the largest |k| in sin/cos(k t + c)
    k = 0.0
    for e in exprs:
        for g in e.atoms(sp.sin, sp.cos):
            coeff = sp.Poly(g.args[0], tsym).coeff_monomial(tsym) if g.args[0].is_polynomial(
                tsym) else 1
            try:
                k = max(k, abs(float(coeff)))
            except TypeError:
                pass
    lo, hi = (mp.mpf(sp.N(parse(x, {}), 60)) for x in (t0, t1))
    return Piece(lo, hi, lambda t: [mp.mpf(v) for v in fn(t)], k)


def robot_params(spec: dict) -> dict:
    names = {s: sp.Symbol(s) for s in spec["joints"] + spec["pose"]}
    params = {}
    for key, value in (spec.get("parameters") or {}).items():
        params[key] = parse(value, {**names, **params})
    return params


def path_pieces(traj: dict, robot_spec: dict, csv_rows=None, interpolation="cubic"):
    variables = robot_spec["pose"]
    params = robot_params(robot_spec)
    if csv_rows is not None:
        return spline_pieces(csv_rows, variables, interpolation == "cubic")
    if "waypoints" in traj:
        rows = [{("t" if k == traj["parameter"] else k): v for k, v in r.items()}
                for r in traj["waypoints"]]
        return spline_pieces(rows, variables, traj.get("interpolation", "cubic") == "cubic")
    if "segments" in traj:
        return [expression_piece(s["range"][0], s["range"][1], s["pose"], variables, params,
                                 traj["parameter"]) for s in traj["segments"]]
    return [expression_piece(traj["range"][0], traj["range"][1], traj["pose"], variables,
                             params, traj["parameter"])]


# --- one-dimensional search ----------------------------------------------------------

def golden_min(f, a, b, iterations=130):
    """The minimum of f on [a, b] (f unimodal there), by golden-section search."""
    c, d = b - GOLD * (b - a), a + GOLD * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - GOLD * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + GOLD * (b - a)
            fd = f(d)
    t = (a + b) / 2
    return t, f(t)


# --- the verdict ---------------------------------------------------------------------

@dataclass
class ModeResult:
    label: str
    feasible: bool
    ambiguous: list = field(default_factory=list)  # reasons the truth is unsure
    reason: str = ""
    start: list = field(default_factory=list)  # joints at the start
    crossings: list = field(default_factory=list)
    touches: list = field(default_factory=list)  # (t, min |det A|): no sign change
    end_zeros: list = field(default_factory=list)  # det A = 0 at a range end
    limit_touches: list = field(default_factory=list)  # times a joint sits on a limit
    near: list = field(default_factory=list)  # (t, min |det A|) small but not zero
    on_surface: tuple | None = None
    min_abs_det: object = None


@dataclass
class OracleVerdict:
    verdict: str  # singular | singularity-free | infeasible
    times: list
    modes: dict
    ambiguous: list
    on_surface: list


def _grid(piece: Piece, base: int):
    n = max(base, int(base * piece.harmonics * float(piece.t1 - piece.t0) / (2 * math.pi)))
    return [piece.t0 + (piece.t1 - piece.t0) * i / n for i in range(n + 1)]


def judge(robot: OracleRobot, pieces: list[Piece], samples: int = 600) -> OracleVerdict:
    """The truth along the path: feasibility, singular times and touches per mode."""
    nlegs = len(robot.legs)

    def at(t, piece):
        X = piece.coords(t)
        return X, [leg.branches(X) for leg in robot.legs]

    # one label per leg branch; the modes are the products
    sample = at(pieces[0].t0, pieces[0])[1]
    modes = list(itertools.product(*[range(len(b)) for b in sample]))
    label_of = {m: "".join(sample[i][k][0] for i, k in enumerate(m)) for m in modes}
    results = {label_of[m]: ModeResult(label_of[m], True) for m in modes}
    for m in modes:
        results[label_of[m]].start = [sample[i][k][1] for i, k in enumerate(m)]

    def margins(t, piece, m):
        X, br = at(t, piece)
        out = []
        for i, k in enumerate(m):
            _, value, apart = br[i][k]
            out.append(apart)
            out.append(robot.legs[i].limit_margin(value))
        return out

    def det(t, piece, m):
        X, br = at(t, piece)
        rho = [br[i][k][1] for i, k in enumerate(m)]
        return robot.det_A(rho, X)

    for piece in pieces:
        ts = _grid(piece, samples)
        values = [at(t, piece) for t in ts]
        for m in modes:
            r = results[label_of[m]]
            if not r.feasible:
                continue
            # feasibility: every margin positive at every sample and at its refined minima
            series = []
            for _, br in values:
                row = []
                for i, k in enumerate(m):
                    _, value, apart = br[i][k]
                    row += [apart, robot.legs[i].limit_margin(value)]
                series.append(row)
            for q in range(2 * nlegs):
                col = [s[q] for s in series]
                if col[0] == mp.inf:
                    continue
                # the limits are closed (docs/method.md): a limit reached exactly is inside
                slack = LIMIT_SLACK if q % 2 else 0
                worst = min(col)
                if worst <= -slack:
                    j = col.index(worst)
                    r.feasible = False
                    what = "discriminant" if q % 2 == 0 else "limit"
                    r.reason = (f"leg {q // 2 + 1} {what} margin {mp.nstr(worst, 5)} "
                                f"at t={mp.nstr(ts[j], 8)}")
                    if abs(worst) < NEAR:
                        r.ambiguous.append(f"{r.reason} (touches 0)")
                    break
                for j in range(len(col)):
                    lo_ok = j == 0 or col[j] <= col[j - 1]
                    hi_ok = j == len(col) - 1 or col[j] <= col[j + 1]
                    if lo_ok and hi_ok and col[j] < 0.05 * (1 + max(col)):
                        a, b = ts[max(j - 1, 0)], ts[min(j + 1, len(ts) - 1)]
                        t_min, v = golden_min(
                            lambda t, piece=piece, m=m, q=q: margins(t, piece, m)[q], a, b, 100)
                        v = min(v, col[j])
                        if abs(v) <= slack:
                            r.limit_touches.append(t_min)
                            continue
                        if v <= 0:
                            r.feasible = False
                            r.reason = (f"leg {q // 2 + 1} margin {mp.nstr(v, 5)} "
                                        f"at t={mp.nstr(t_min, 8)}")
                            if abs(v) < NEAR:
                                r.ambiguous.append(r.reason + " (touches 0)")
                            break
                        if v < NEAR:
                            r.ambiguous.append(f"leg {q // 2 + 1} margin {mp.nstr(v, 5)} at "
                                               f"t={mp.nstr(t_min, 8)}")
                if not r.feasible:
                    break
            if not r.feasible:
                continue
            # det A along the mode
            if robot.A_has_joints:
                ds = [robot.det_A([br[i][k][1] for i, k in enumerate(m)], X) for X, br in values]
            else:
                ds = [robot.det_A([0] * nlegs, X) for X, _ in values]
            scale = max(abs(d) for d in ds)
            if scale < mp.mpf(10) ** -35:
                r.on_surface = (piece.t0, piece.t1)
                continue
            r.min_abs_det = min([abs(d) for d in ds] + ([r.min_abs_det] if r.min_abs_det else []))

            def f(t, piece=piece, m=m):
                return det(t, piece, m)

            tiny = mp.mpf(10) ** -40
            nz = [(ts[j], d) for j, d in enumerate(ds) if abs(d) >= tiny]
            for j, d in enumerate(ds):
                if abs(d) < tiny:  # an exact zero at a sample: a crossing, a touch or an end
                    before = [e for t, e in nz if t < ts[j]]
                    after = [e for t, e in nz if t > ts[j]]
                    if before and after and (before[-1] > 0) != (after[0] > 0):
                        r.crossings.append(ts[j])
                    elif before and after:
                        r.touches.append((ts[j], abs(d)))
                    else:
                        r.end_zeros.append(ts[j])
            for (ta, da), (tb, db) in zip(nz, nz[1:], strict=False):
                if (da > 0) != (db > 0):
                    if any(ta < t < tb for t in r.crossings):
                        continue  # an exact zero at a sample between them
                    r.crossings.append(_bisect(f, ta, tb, da, steps=110))
            for j in range(len(ds)):
                lo_ok = j == 0 or abs(ds[j]) <= abs(ds[j - 1])
                hi_ok = j == len(ds) - 1 or abs(ds[j]) <= abs(ds[j + 1])
                strict = ((j > 0 and abs(ds[j]) < abs(ds[j - 1]))
                          or (j < len(ds) - 1 and abs(ds[j]) < abs(ds[j + 1])))
                # a dip of |det A| (not a plateau, and well below its largest value)
                if (not (lo_ok and hi_ok and strict) or abs(ds[j]) < tiny
                        or abs(ds[j]) > scale / 10):
                    continue
                a, b = ts[max(j - 1, 0)], ts[min(j + 1, len(ts) - 1)]
                if any(a <= c <= b for c in r.crossings):
                    continue
                t_min, v = golden_min(lambda t: abs(f(t)), a, b)
                if v < ZERO:
                    r.touches.append((t_min, v))
                elif v < NEAR * scale:
                    r.near.append((t_min, v))
                    r.ambiguous.append(f"|det A| = {mp.nstr(v, 3)} at t={mp.nstr(t_min, 10)}")
    feasible = [r for r in results.values() if r.feasible]
    ambiguous = [f"{r.label}: {a}" for r in results.values() for a in r.ambiguous]
    if not feasible:
        return OracleVerdict("infeasible", [], results, ambiguous, [])
    times = sorted({float(t) for r in feasible for t in r.crossings}
                   | {float(t) for r in feasible for t, _ in r.touches}
                   | {float(t) for r in feasible for t in r.end_zeros})
    merged = []
    for t in times:
        if not merged or abs(t - merged[-1]) > 1e-9:
            merged.append(t)
    surfaces = [(r.label, float(r.on_surface[0]), float(r.on_surface[1]))
                for r in feasible if r.on_surface]
    verdict = "singular" if merged or surfaces else "singularity-free"
    return OracleVerdict(verdict, merged, results, ambiguous, surfaces)
