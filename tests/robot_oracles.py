"""Independent oracles for the bundled robots (tests only; never imports singcheck).

Each robot is written here a second time, from its geometry rather than from its YAML:
closed-form inverse kinematics per leg (both branches) and det A from the legs' vectors,
at 50 significant digits with mpmath.  Along a trajectory (also written here as a
function of t) the oracle samples the path, keeps the working modes whose branches are
real, apart and inside the joint limits at every sample, and finds the sign changes of
det A along each such mode, refined by bisection to far below singcheck's tolerance.

The robots' geometry is repeated on purpose: a typo in a YAML file then shows up as a
disagreement with singcheck's answer instead of being copied into the expected one.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

import mpmath as mp

mp.mp.dps = 50
PI = mp.pi
SQRT3 = mp.sqrt(3)


@dataclass(frozen=True)
class Leg:
    """One leg's inverse kinematics: ``branches(X)`` gives both joint values or None.

    For a revolute joint the values are angles taken in ``[lo, lo + 2π)``.
    """

    joint: str
    branches: Callable[[list], tuple | None]
    lo: object
    hi: object
    revolute: bool = False
    abc: Callable[[list], tuple] | None = None  # the leg's equation's coefficients


@dataclass(frozen=True)
class Oracle:
    robot: str  # the YAML file's stem
    pose: tuple[str, ...]
    legs: tuple[Leg, ...]
    det_A: Callable[[list, list], object]  # (joint values, pose) -> det A, up to a constant

    def joints(self, mode: tuple[int, ...], X) -> list | None:
        out = []
        for leg, k in zip(self.legs, mode, strict=True):
            both = leg.branches(X)
            if both is None:
                return None
            out.append(both[k])
        return out


def last_pose_memo(f):
    """f(X) remembered for the last pose X only (the legs of a pose are asked for once per
    leg and per branch)."""
    last: dict = {}

    def memo(X):
        key = tuple(X)
        if key not in last:
            last.clear()
            last[key] = f(X)
        return last[key]

    return memo


def _revolute(abc: Callable[[list], tuple]) -> Callable[[list], tuple | None]:
    """The two roots θ of ``a cos θ + b sin θ + c = 0``: atan2(b, a) ± acos(-c/√(a²+b²))."""

    def branches(X):
        a, b, c = abc(X)
        r = mp.sqrt(a * a + b * b)
        q = -c / r
        if abs(q) >= 1:
            return None
        base, delta = mp.atan2(b, a), mp.acos(q)
        return base + delta, base - delta

    return branches


def _wrap(lo):
    def wrap(theta):
        return lo + (theta - lo) % (2 * PI)

    return wrap


def revolute_leg(joint: str, abc, lo, hi) -> Leg:
    abc = last_pose_memo(abc)
    raw, wrap = _revolute(abc), _wrap(lo)

    def branches(X):
        both = raw(X)
        return None if both is None else tuple(wrap(v) for v in both)

    return Leg(joint, branches, lo, hi, revolute=True, abc=abc)


def quadratic_leg(joint: str, abc, lo, hi) -> Leg:
    """ρ = (-b ± √(b² - 4ac)) / 2a for ``a ρ² + b ρ + c = 0``."""
    abc = last_pose_memo(abc)

    def branches(X):
        a, b, c = abc(X)
        d = b * b - 4 * a * c
        if d <= 0:
            return None
        return (-b + mp.sqrt(d)) / (2 * a), (-b - mp.sqrt(d)) / (2 * a)

    return Leg(joint, branches, lo, hi, abc=abc)


def det(rows) -> object:
    """A determinant by Gaussian elimination with partial pivoting (plain lists of mpf:
    the same 50 digits as ``mp.det``, without its matrix objects)."""
    m = [list(row) for row in rows]
    n, value = len(m), mp.mpf(1)
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        if m[p][c] == 0:
            return mp.mpf(0)
        if p != c:
            m[c], m[p], value = m[p], m[c], -value
        value *= m[c][c]
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            m[r] = [m[r][k] - f * m[c][k] if k > c else 0 for k in range(n)]
    return value


@functools.lru_cache(maxsize=1 << 14)
def cos_sin(angle) -> tuple:
    """cos and sin of a joint angle (the same branch values recur in every mode)."""
    return mp.cos(angle), mp.sin(angle)


def det3(rows) -> object:
    (a, b, c), (d, e, f), (g, h, i) = rows
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


def cross(u, v):
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def exact(v) -> object:
    """An int or Fraction as an mpf (to 50 digits)."""
    v = Fraction(v)
    return mp.mpf(v.numerator) / v.denominator


# --- the robots --------------------------------------------------------------------------

def five_bar(l1=2, lo1=None) -> Oracle:
    """RR-RRR, A_i = (∓1, 0), distal links l2 = 2, proximal links ``l1`` (2 for the
    bundled robot), θ1 ≥ ``lo1`` (π/3).  det A ∝ det(P - B1, P - B2)."""
    d, l2 = 1, 2
    bases = ((-d, 0), (d, 0))

    def abc(i):
        ax, ay = bases[i]

        def f(X):  # |P - A - l1 (cos, sin)|² - l2² = a cos + b sin + c
            px, py = X[0] - ax, X[1] - ay
            return -2 * l1 * px, -2 * l1 * py, px * px + py * py + l1 * l1 - l2 * l2

        return f

    def det_A(q, X):
        u = [[X[0] - bases[i][0] - l1 * mp.cos(q[i]), X[1] - bases[i][1] - l1 * mp.sin(q[i])]
             for i in range(2)]
        return 4 * (u[0][0] * u[1][1] - u[0][1] * u[1][0])

    legs = (revolute_leg("th1", abc(0), PI / 3 if lo1 is None else lo1, PI),
            revolute_leg("th2", abc(1), mp.mpf(0), 2 * PI / 3))
    return Oracle("five-bar", ("x", "y"), legs, det_A)


RPR_BASE = ((0, 0), (5, 0), (1, 4))
RPR_PLATFORM = ((0, 0), (1, 0), (0, 1))


def rotate2(phi, b):
    c, s = mp.cos(phi), mp.sin(phi)
    return c * b[0] - s * b[1], s * b[0] + c * b[1]


def three_rpr() -> Oracle:
    """3-RPR: det A = 8·det[u_i, A_i × u_i] (u_i = P + R b_i - A_i), independent of ρ."""

    def leg_vector(i, X):
        rb = rotate2(X[2], RPR_PLATFORM[i])
        return X[0] + rb[0] - RPR_BASE[i][0], X[1] + rb[1] - RPR_BASE[i][1]

    def abc(i):
        def f(X):  # u·u - ρ² = 0
            u = leg_vector(i, X)
            return -1, 0, u[0] ** 2 + u[1] ** 2

        return f

    def det_A(q, X):
        rows = []
        for i in range(3):
            u, a = leg_vector(i, X), RPR_BASE[i]
            rows.append([u[0], u[1], a[0] * u[1] - a[1] * u[0]])
        return 8 * det3(rows)

    legs = tuple(quadratic_leg(f"r{i + 1}", abc(i), mp.mpf(1) / 2, 5) for i in range(3))
    return Oracle("3-rpr", ("x", "y", "phi"), legs, det_A)


PRR_RAILS = (((0, 0), (1, 0)), ((5, 0), (0, 1)), ((0, 5), (1, 0)))  # point, direction
PRR_LINK = 3


def three_prr() -> Oracle:
    """3-PRR: slider J_i = O_i + ρ_i d_i, link w_i = P + R b_i - J_i;
    det A ∝ det[w_i, J_i × w_i]."""

    def platform_point(i, X):
        rb = rotate2(X[2], RPR_PLATFORM[i])
        return X[0] + rb[0], X[1] + rb[1]

    def abc(i):
        (ox, oy), (dx, dy) = PRR_RAILS[i]

        def f(X):  # |Q - O - ρ d|² - L² with |d| = 1
            qx, qy = platform_point(i, X)
            qx, qy = qx - ox, qy - oy
            return 1, -2 * (qx * dx + qy * dy), qx * qx + qy * qy - PRR_LINK ** 2

        return f

    def det_A(q, X):
        rows = []
        for i in range(3):
            (ox, oy), (dx, dy) = PRR_RAILS[i]
            jx, jy = ox + q[i] * dx, oy + q[i] * dy
            px, py = platform_point(i, X)
            wx, wy = px - jx, py - jy
            rows.append([wx, wy, jx * wy - jy * wx])
        return 8 * det3(rows)

    legs = (quadratic_leg("r1", abc(0), 2, 6), quadratic_leg("r2", abc(1), 2, 6),
            quadratic_leg("r3", abc(2), -2, 1))
    return Oracle("3-prr", ("x", "y", "phi"), legs, det_A)


DELTA_ANGLES = (0, 2 * PI / 3, 4 * PI / 3)


def rotary_delta() -> Oracle:
    """Clavel's Delta, e = 1/2, la = 1, lb = 2; det A ∝ det of the three forearm vectors."""
    e, la, lb = mp.mpf(1) / 2, 1, 2

    def local(i, X):
        ca, sa = mp.cos(DELTA_ANGLES[i]), mp.sin(DELTA_ANGLES[i])
        return ca * X[0] + sa * X[1], -sa * X[0] + ca * X[1], X[2]

    def abc(i):
        def f(X):
            u, v, z = local(i, X)
            u = u - e
            return -2 * la * u, 2 * la * z, u * u + v * v + z * z + la * la - lb * lb

        return f

    def det_A(q, X):
        rows = []
        for i in range(3):
            ca, sa = mp.cos(DELTA_ANGLES[i]), mp.sin(DELTA_ANGLES[i])
            u, v, z = local(i, X)
            f = (u - e - la * mp.cos(q[i]), v, z + la * mp.sin(q[i]))  # forearm, leg frame
            rows.append([ca * f[0] - sa * f[1], sa * f[0] + ca * f[1], f[2]])
        return 8 * det3(rows)

    legs = tuple(revolute_leg(f"th{i + 1}", abc(i), -PI / 2, 3 * PI / 4) for i in range(3))
    return Oracle("rotary-delta", ("x", "y", "z"), legs, det_A)


def linear_delta() -> Oracle:
    """Vertical rails at radius 1, rods 3/2; det A = 8·det[P - C_i]."""
    rails = [(mp.cos(a), mp.sin(a)) for a in DELTA_ANGLES]
    rod = mp.mpf(3) / 2

    def abc(i):
        cx, cy = rails[i]

        def f(X):  # (ρ - z)² = l² - d²
            d2 = (X[0] - cx) ** 2 + (X[1] - cy) ** 2
            return 1, -2 * X[2], X[2] ** 2 + d2 - rod ** 2

        return f

    def det_A(q, X):
        return 8 * det3([[X[0] - rails[i][0], X[1] - rails[i][1], X[2] - q[i]] for i in range(3)])

    lo, hi = mp.mpf(1) / 4, 3
    legs = (quadratic_leg("r1", abc(0), lo, hi), quadratic_leg("r2", abc(1), lo, hi),
            quadratic_leg("r3", abc(2), -hi, -lo))
    return Oracle("linear-delta", ("x", "y", "z"), legs, det_A)


GS_BASE = ((Fraction(49, 25), Fraction(-2, 5)), (Fraction(49, 25), Fraction(2, 5)),
           (Fraction(-3, 5), Fraction(19, 10)), (Fraction(-4, 3), Fraction(3, 2)),
           (Fraction(-4, 3), Fraction(-3, 2)), (Fraction(-3, 5), Fraction(-19, 10)))
GS_PLATFORM = ((Fraction(2, 3), Fraction(-3, 4)), (Fraction(2, 3), Fraction(3, 4)),
               (Fraction(3, 10), Fraction(19, 20)), (Fraction(-49, 50), Fraction(1, 5)),
               (Fraction(-49, 50), Fraction(-1, 5)), (Fraction(3, 10), Fraction(-19, 20)))


def rotation_zyx(cz, sz, cy, sy, cx, sx):
    """Rz·Ry·Rx from the cosines and sines (works over Fraction and mpf alike)."""
    return ((cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx),
            (sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx),
            (-sy, cy * sx, cy * cx))


def gough_stewart_legs(p, R, base=GS_BASE, platform=GS_PLATFORM):
    """u_i = p + R b_i - a_i for the six legs (b_i, a_i in their planes z = 0)."""
    out = []
    for (ax, ay), (bx, by) in zip(base, platform, strict=True):
        out.append([p[0] + R[0][0] * bx + R[0][1] * by - ax,
                    p[1] + R[1][0] * bx + R[1][1] * by - ay,
                    p[2] + R[2][0] * bx + R[2][1] * by])
    return out


def plucker_matrix(p, R, base=GS_BASE, platform=GS_PLATFORM):
    """Rows (u_i, a_i × u_i): the legs' lines in Plücker coordinates."""
    rows = []
    for u, (ax, ay) in zip(gough_stewart_legs(p, R, base, platform), base, strict=True):
        rows.append([*u, *cross([ax, ay, 0], u)])
    return rows


def gough_stewart() -> Oracle:
    """det A = -64·cos θ·det(Plücker matrix) (the factor cos θ: Euler angles' own
    singularity; derivation in the README)."""

    def pose_parts(X):
        R = rotation_zyx(mp.cos(X[3]), mp.sin(X[3]), mp.cos(X[4]), mp.sin(X[4]),
                         mp.cos(X[5]), mp.sin(X[5]))
        return X[:3], R

    base, platform = ([[exact(v) for v in point] for point in points]
                      for points in (GS_BASE, GS_PLATFORM))  # to 50 digits once

    @last_pose_memo
    def legs_at(X):
        return gough_stewart_legs(*pose_parts(X), base, platform)

    def abc(i):
        def f(X):
            u = legs_at(X)[i]
            return -1, 0, u[0] ** 2 + u[1] ** 2 + u[2] ** 2

        return f

    def det_A(q, X):
        rows = [[*u, *cross([ax, ay, 0], u)] for u, (ax, ay) in zip(legs_at(X), base,
                                                                       strict=True)]
        return -64 * mp.cos(X[4]) * det(rows)

    legs = tuple(quadratic_leg(f"r{i + 1}", abc(i), 1, 5) for i in range(6))
    return Oracle("gough-stewart", ("x", "y", "z", "psi", "theta", "phi"), legs, det_A)


# The 6-RUS rotary hexapod (tests/data/robots/6-rus.yaml): base points 2 u_i, arms of
# length 1 turning in the vertical plane tangent to the base circle (elbow
# 2 u_i + cos θ t_i - sin θ e_z, t_i = (-u_iy, u_ix, 0)), distal links 5/2 to the platform
# points p + R u_i.  Directions u_i with rational cosines and sines.
RUS_DIRECTIONS = ((1, 0), (Fraction(-3, 5), Fraction(4, 5)), (Fraction(-3, 5), Fraction(-4, 5)),
                  (-1, 0), (Fraction(3, 5), Fraction(-4, 5)), (Fraction(3, 5), Fraction(4, 5)))
RUS_BASE, RUS_ARM, RUS_LINK = 2, 1, Fraction(5, 2)


def matmul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def matvec(A, v):
    return [sum(A[i][k] * v[k] for k in range(3)) for i in range(3)]


def euler_zyx(psi, theta, phi):
    """R = Rz(ψ)·Ry(θ)·Rx(φ) and its three partial derivatives, as 3×3 lists."""
    cz, sz, cy, sy, cx, sx = (mp.cos(psi), mp.sin(psi), mp.cos(theta), mp.sin(theta),
                              mp.cos(phi), mp.sin(phi))
    Rz, dRz = [[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]], [[-sz, -cz, 0], [cz, -sz, 0], [0, 0, 0]]
    Ry, dRy = [[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]], [[-sy, 0, cy], [0, 0, 0], [-cy, 0, -sy]]
    Rx, dRx = [[1, 0, 0], [0, cx, -sx], [0, sx, cx]], [[0, 0, 0], [0, -sx, -cx], [0, cx, -sx]]
    return (matmul(matmul(Rz, Ry), Rx), matmul(matmul(dRz, Ry), Rx),
            matmul(matmul(Rz, dRy), Rx), matmul(matmul(Rz, Ry), dRx))


def six_rus() -> Oracle:
    """det A = det[∂F_i/∂(x, y, z, ψ, θ, φ)] / 2⁶ with F_i = |P_i - E_i|² - (5/2)²:
    row i is (d_i, d_i·(∂R/∂ψ) u_i, d_i·(∂R/∂θ) u_i, d_i·(∂R/∂φ) u_i), d_i = P_i - E_i."""

    rotation = last_pose_memo(lambda X: euler_zyx(X[3], X[4], X[5]))

    def parts(i, X):
        ux, uy = (exact(v) for v in RUS_DIRECTIONS[i])
        R, *dR = rotation(X)
        Ru = matvec(R, [ux, uy, 0])
        w = [X[k] + Ru[k] - RUS_BASE * (ux, uy, 0)[k] for k in range(3)]  # P_i - 2 u_i
        return (ux, uy), w, [matvec(D, [ux, uy, 0]) for D in dR]

    def abc(i):
        def f(X):  # |w - la(cos θ t - sin θ e_z)|² - lb² = a cos θ + b sin θ + c
            (ux, uy), w, _ = parts(i, X)
            return (-2 * RUS_ARM * (-uy * w[0] + ux * w[1]), 2 * RUS_ARM * w[2],
                    w[0] ** 2 + w[1] ** 2 + w[2] ** 2 + RUS_ARM ** 2 - exact(RUS_LINK) ** 2)

        return f

    def det_A(q, X):
        rows = []
        for i in range(6):
            (ux, uy), w, dRu = parts(i, X)
            c, s = cos_sin(q[i])
            d = [w[0] + RUS_ARM * c * uy, w[1] - RUS_ARM * c * ux, w[2] + RUS_ARM * s]
            rows.append(d + [sum(d[k] * v[k] for k in range(3)) for v in dRu])
        return det(rows)

    legs = tuple(revolute_leg(f"th{i + 1}", abc(i), -PI, PI) for i in range(6))
    return Oracle("6-rus", ("x", "y", "z", "psi", "theta", "phi"), legs, det_A)


# A planar 3-RRR (tests/data/robots/3-rrr.yaml): base revolutes at A_i = 2 u_i + J u_i
# (J the quarter turn), arms 1, distal links 1 to the platform points p + R(φ) u_i.
RRR_DIRECTIONS = ((1, 0), (Fraction(-3, 5), Fraction(4, 5)), (Fraction(-3, 5), Fraction(-4, 5)))
RRR_ARM, RRR_LINK = 1, 1


def three_rrr() -> Oracle:
    """det A ∝ det[d_i, (R u_i) × d_i] (d_i = B_i - E_i: distal link i), zero where the
    three distal links' lines meet in a point (or are parallel)."""

    directions = [[exact(v) for v in u] for u in RRR_DIRECTIONS]
    bases = [(2 * ux - uy, 2 * uy + ux) for ux, uy in directions]

    def base(i):
        return bases[i]

    @last_pose_memo
    def platform_points(X):
        return [(rx, ry, X[0] + rx, X[1] + ry) for rx, ry in
                (rotate2(X[2], u) for u in directions)]

    def platform(i, X):
        return platform_points(X)[i]

    def abc(i):
        def f(X):  # |B - A - la (cos θ, sin θ)|² - lb²
            ax, ay = base(i)
            _, _, bx, by = platform(i, X)
            wx, wy = bx - ax, by - ay
            return (-2 * RRR_ARM * wx, -2 * RRR_ARM * wy,
                    wx * wx + wy * wy + RRR_ARM ** 2 - RRR_LINK ** 2)

        return f

    def det_A(q, X):
        rows = []
        for i in range(3):
            ax, ay = base(i)
            rx, ry, bx, by = platform(i, X)
            c, s = cos_sin(q[i])
            dx, dy = bx - ax - RRR_ARM * c, by - ay - RRR_ARM * s
            rows.append([dx, dy, rx * dy - ry * dx])
        return det3(rows)

    legs = tuple(revolute_leg(f"th{i + 1}", abc(i), -PI, PI) for i in range(3))
    return Oracle("3-rrr", ("x", "y", "phi"), legs, det_A)


# --- the trajectories ----------------------------------------------------------------

@dataclass(frozen=True)
class Path:
    name: str  # the YAML file's stem
    oracle: Callable[[], Oracle]
    start: object
    end: object
    pose: Callable[[object], list]
    singular: bool  # what the path was designed to do (checked against the oracle too)


def _s(t):
    return mp.sin(t)


def _c(t):
    return mp.cos(t)


PATHS = (
    Path("five-bar-cross", five_bar, 0, 1, lambda t: [mp.mpf(0), 3 - 2 * t], True),
    Path("five-bar-free", five_bar, 0, 1, lambda t: [-1 + 2 * t, mp.mpf(5) / 2], False),
    Path("3-rpr-cross", three_rpr, 0, 1, lambda t: [2 + _c(t), 2 + _s(t), t], True),
    Path("3-rpr-free", three_rpr, 0, 1, lambda t: [3 - _c(t), mp.mpf(1) / 2 + _s(t), t],
         False),
    Path("3-prr-cross", three_prr, 0, 1, lambda t: [mp.mpf(3) / 2 + _s(t) / 2, 2 - _c(t) / 2, t],
         True),
    Path("3-prr-free", three_prr, 0, 1, lambda t: [mp.mpf(3) / 2 + t, mp.mpf(2), mp.mpf(0)],
         False),
    Path("rotary-delta-cross", rotary_delta, 0, 1,
         lambda t: [mp.mpf(7) / 4 + 3 * t / 10, mp.mpf(0), mp.mpf(-1)], True),
    Path("rotary-delta-free", rotary_delta, -PI, PI,
         lambda t: [_c(t) / 2, _s(t) / 2, mp.mpf(-2)], False),
    Path("linear-delta-cross", linear_delta, 0, 1,
         lambda t: [-mp.mpf(1) / 4 + t / 2, -mp.mpf(1) / 4, t / 4], True),
    Path("linear-delta-free", linear_delta, 0, 1,
         lambda t: [-mp.mpf(1) / 4 + t / 2, mp.mpf(1) / 4, t / 4], False),
    Path("gough-stewart-rotate", gough_stewart, 0, 2,
         lambda t: [_s(t) / 4, mp.mpf(0), mp.mpf(2), t, mp.mpf(0), mp.mpf(0)], True),
    Path("gough-stewart-translate", gough_stewart, -PI, PI,
         lambda t: [_c(t) / 2, _s(t) / 2, mp.mpf(2), mp.mpf(0), mp.mpf(0), mp.mpf(0)], False),
)


@dataclass
class OracleMode:
    mode: tuple[int, ...]
    joints_at_start: list
    singular_times: list


@dataclass
class OracleAnswer:
    feasible: list[OracleMode]

    @property
    def singular_times(self) -> list:
        return sorted(t for m in self.feasible for t in m.singular_times)

    @property
    def verdict(self) -> str:
        if not self.feasible:
            return "infeasible"
        return "singular" if self.singular_times else "singularity-free"


def _inside(leg: Leg, value) -> bool:
    return leg.lo <= value <= leg.hi


def _bisect(f, a, b, fa, steps=150):
    for _ in range(steps):
        m = (a + b) / 2
        fm = f(m)
        if fm == 0:
            return m
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
    return (a + b) / 2


def solve(path: Path, samples: int = 400) -> OracleAnswer:
    """The oracle's answer for a path: feasible modes (sampled) and det A's sign changes
    along each, refined by bisection.

    A branch is kept when it is real, apart from the other branch and inside its limits
    at every sample; a working mode is feasible when each of its branches is kept.
    """
    oracle = path.oracle()
    start, end = mp.mpf(path.start), mp.mpf(path.end)
    ts = [start + (end - start) * k / samples for k in range(samples + 1)]
    poses = [path.pose(t) for t in ts]
    kept = []
    for leg in oracle.legs:
        both = [leg.branches(X) for X in poses]
        kept.append([k for k in (0, 1)
                     if all(b is not None and _inside(leg, b[k]) for b in both)])
    feasible = []
    for mode in itertools.product(*kept):
        def g(t, mode=mode):
            X = path.pose(t)
            return oracle.det_A(oracle.joints(mode, X), X)

        values = [oracle.det_A(oracle.joints(mode, X), X) for X in poses]
        roots = [_bisect(g, ts[k], ts[k + 1], values[k])
                 for k in range(samples) if (values[k] > 0) != (values[k + 1] > 0)]
        feasible.append(OracleMode(mode, oracle.joints(mode, poses[0]), roots))
    return OracleAnswer(feasible)


# --- a conservative judgement of any path (the campaign) --------------------------------

#: |det A| below this, computed at 50 digits, is an exact zero (a singular pose)
ZERO = mp.mpf(10) ** -40
#: a joint's margin (to its limits, or between its two branches) under this is marginal
MARGIN = mp.mpf(10) ** -3
#: along a moving path, min |det A| / max |det A| over the samples above this is "bounded
#: away from 0"; at a constant pose, |det A| above ABSOLUTE is
RELATIVE = mp.mpf(10) ** -3
ABSOLUTE = mp.mpf(10) ** -20

OK, MARGINAL, BAD = 0, 1, 2


def _branch_margins(leg: Leg, abc, both) -> list:
    """Per branch: the smaller of its distance to the other branch and to the limits
    (negative when not real, or outside a limit)."""
    a, b, c = abc
    if leg.revolute:
        gap = 1 - abs(c / mp.sqrt(a * a + b * b))
    else:
        d = b * b - 4 * a * c
        gap = mp.sign(d) * mp.sqrt(abs(d)) / abs(a)
    if both is None:
        return [gap, gap]
    unlimited = leg.hi - leg.lo >= 2 * PI
    return [gap if unlimited else min(gap, v - leg.lo, leg.hi - v) for v in both]


def _grade(margin) -> int:
    return OK if margin > MARGIN else BAD if margin < -MARGIN else MARGINAL


@dataclass
class ModeJudgement:
    mode: tuple[int, ...]
    feasibility: int  # OK, MARGINAL (close to a limit or to the other branch) or BAD
    zeros: list  # times where det A vanishes (|det A| < ZERO at a sample) or changes sign
    whole: bool  # det A vanishes at every sample
    bounded: bool  # no zero, and |det A| bounded away from 0 (RELATIVE, ABSOLUTE)


@dataclass
class Judgement:
    """The oracle's answer for one path, with its doubts."""

    modes: list[ModeJudgement]

    def _of(self, *grades):
        return [m for m in self.modes if m.feasibility in grades]

    @property
    def feasible(self) -> list[ModeJudgement]:
        return self._of(OK)

    @property
    def verdict(self) -> str | None:
        """singular, singularity-free or infeasible when certain; None when a mode is
        marginal or det A comes close to 0 without a sign change."""
        sure, doubtful = self._of(OK), self._of(MARGINAL)
        if any(m.zeros for m in sure):
            return "singular"
        if any(not m.bounded for m in sure + doubtful):
            return None
        if sure:
            return "singularity-free"
        return None if doubtful else "infeasible"

    @property
    def required_times(self) -> list:
        return sorted(t for m in self.feasible for t in m.zeros)

    @property
    def allowed_times(self) -> list:
        return sorted(t for m in self._of(OK, MARGINAL) for t in m.zeros)

    @property
    def whole(self) -> bool:
        return any(m.whole for m in self._of(OK, MARGINAL))


def judge(oracle: Oracle, pose: Callable[[object], list], start, end, samples: int = 400,
          constant: bool = False) -> Judgement:
    """Judge a path: grade each working mode's feasibility at every sample (constant: at
    the one pose) and find det A's zeros and sign changes along the modes not proven
    infeasible (bisected to far below 1e-6)."""
    start, end = mp.mpf(start), mp.mpf(end)
    n = 0 if constant else samples
    ts = [start + (end - start) * k / samples for k in range(n + 1)]
    poses = [pose(t) for t in ts]
    branches = []
    grades = [[OK, OK] for _ in oracle.legs]  # per leg and branch: the worst over the samples
    for X in poses:
        branches.append([leg.branches(X) for leg in oracle.legs])
        for i, leg in enumerate(oracle.legs):
            for k, margin in enumerate(_branch_margins(leg, leg.abc(X), branches[-1][i])):
                grades[i][k] = max(grades[i][k], _grade(margin))
    candidates = [mode for mode in itertools.product((0, 1), repeat=len(oracle.legs))
                  if max(grades[i][k] for i, k in enumerate(mode)) != BAD]
    values = {mode: [] for mode in candidates}
    for X, b in zip(poses, branches, strict=True):  # each pose once, for every mode
        for mode in candidates:
            q = None if None in b else [b[i][k] for i, k in enumerate(mode)]
            values[mode].append(None if q is None else oracle.det_A(q, X))
    modes = []
    for mode in itertools.product((0, 1), repeat=len(oracle.legs)):
        if mode not in values:
            modes.append(ModeJudgement(mode, BAD, [], False, False))
            continue
        if None in values[mode]:  # marginal, and not even real at some sample: no verdict
            modes.append(ModeJudgement(mode, MARGINAL, [], False, False))
            continue

        def g(t, mode=mode):
            X = pose(t)
            return oracle.det_A(oracle.joints(mode, X), X)

        v = values[mode]
        zero = [abs(value) < ZERO for value in v]
        zeros = [t for t, z in zip(ts, zero, strict=True) if z]
        zeros += [_bisect(g, ts[k], ts[k + 1], v[k]) for k in range(n)
                  if not zero[k] and not zero[k + 1] and (v[k] > 0) != (v[k + 1] > 0)]
        smallest, largest = min(abs(value) for value in v), max(abs(value) for value in v)
        bounded = not zeros and smallest > (ABSOLUTE if constant else RELATIVE * largest)
        feasibility = max(grades[i][k] for i, k in enumerate(mode))
        modes.append(ModeJudgement(mode, feasibility, sorted(zeros), all(zero), bounded))
    return Judgement(modes)
