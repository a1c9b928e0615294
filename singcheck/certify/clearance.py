"""How close a working mode comes to a parallel singularity: the certified clearance.

**The measure.**  Along a working mode, κ(t) is the smallest singular value of the
*leg-normalised* Jacobian N = D^(-1/2)·A, where A = ∂F/∂X (one row per leg's
constraint, one column per pose variable) and D = diag(|row_i of A|²): each leg's
constraint gradient scaled to unit length.  Scaling a row does not move its zero set,
so κ is free of how each constraint happens to be written (a leg's equation times 2
has the same κ).  κ ∈ [0, 1]: 0 exactly where A is singular (a parallel singularity:
det A = 0), 1 where the rows are orthonormal (the Orthoglide at its isotropic pose).
A pose angle's column of A is in length per radian; it is multiplied by 1/L, with L the
robot spec's ``clearance: {length: L}`` (default 1), so that κ compares lengths with
lengths.  A row that vanishes (a leg's gradient is 0, so det A = 0) counts as κ = 0.

**What is proven.**  κ² = λ_min(M) with M = N·Nᵀ, the symmetric matrix of the cosines
between the normalised rows (M_ii = 1, M_ij = a_i·a_j / (|a_i|·|a_j|)).  On a ball T
of the parameter, the entries of M are enclosed by ball arithmetic (FLINT's arb: the
pose φ(T), the mode's closed-form branches ρ(T), then A and the Gram matrix; every
operation rounds outward), giving M(t) = M₀ + E(t) for every t ∈ T with M₀ the exact
(dyadic) matrix of the midpoints and |E_ij| ≤ r_ij the radii.

* **Lower bound on T** (Weyl's inequality): λ_min(M(t)) ≥ λ_min(M₀) - ‖E(t)‖₂ ≥
  ℓ₀ - ‖r‖_F.  The number ℓ₀ comes from a floating-point eigenvalue of M₀ lowered a
  little, and is *proven* a lower bound of λ_min(M₀) by a Cholesky factorisation of
  M₀ - ℓ₀·I in ball arithmetic whose every pivot is proven > 0 (Sylvester: a
  symmetric matrix is positive definite exactly when its leading minors, the products
  of the pivots, are).  So κ ≥ √max(0, ℓ₀ - ‖r‖_F) on all of T.  This bound is first
  order in the width of T, which near a smooth minimum would need very many pieces.
* **Second-order lower bound on T** (centred form, :func:`piece_lower`): the derivative
  M' along the path is enclosed over T too (the pose's derivative, each joint's from its
  leg's constraint, ρ' = -(∂F_i/∂X·X')/(∂F_i/∂ρ), then A' and the Gram matrix's).  By
  the mean value theorem per entry, M(t) = M(t_c) + h·(G₀ + F) with G₀ the midpoints of
  the enclosure of M' and |F| ≤ its radii; h ↦ λ_min(M(t_c) + h·G₀) is concave (a
  minimum of linear functions vᵀ(…)v), so on |h| ≤ w/2 it is at least its smaller value
  at h = ±w/2 (each bounded as above), and Weyl takes off (w/2)·‖radii of M'‖_F, a
  second-order term.  The larger of the two lower bounds is used.
* **Upper bound at a point** (Rayleigh): for any vector v ≠ 0, λ_min(M(t₀)) ≤
  vᵀM(t₀)v / vᵀv; v is the floating-point eigenvector of M₀ at t₀ and the quotient is
  enclosed in ball arithmetic, so κ(t₀) ≤ the square root of its upper end.

**The minimum over the path** is found by branch-and-bound over t, best first: the
range is cut into pieces, each gets its lower bound and its midpoint an upper bound;
the piece of least lower bound is halved, until the gap between the least upper bound
found (at a point) and the least lower bound (over the pieces left) is at most
``rel_tol``·max(κ, 10⁻³), or the evaluation budget or the narrowest piece is reached
(then the interval is reported as it is, with ``met`` false).  A mode that the
certification proved singular at a time τ has κ(τ) = 0: its minimum is exactly 0.

Only modes given as feasible are looked at (their branches are real and continuous on
the whole range); a piece where the branches are not proven real gets the lower bound 0
and is halved like any other.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

from flint import arb

from singcheck.algebra.intervals import evaluate, fraction_ball
from singcheck.algebra.radicals import radical_balls
from singcheck.budget import checkpoint
from singcheck.certify.covers import halves, pieces

#: hi - lo ≤ REL_TOL·max(κ, FLOOR) is the default tolerance on the minimum
REL_TOL = 1e-6
FLOOR = 1e-3
#: ball evaluations per mode per 2π of range (at least this many on any range)
BUDGET = 6000
#: the narrowest piece halved again, relative to the range's length
MIN_WIDTH = 2.0 ** -44

METHOD = ("ball arithmetic (arb) on M = NNᵀ, N = D^(-1/2)·A, branch-and-bound over t: on "
          "each piece λ_min(M) ≥ a Weyl bound around a ball-Cholesky-proven ℓ₀ and a "
          "centred (second-order) form with M' along the path; at points an enclosed "
          "Rayleigh quotient")
METHOD_SINGULAR = "0 exactly: det A = 0 at a proven singular time of the mode"


@dataclass(frozen=True)
class Clearance:
    """The certified minimum of κ along one working mode: lo ≤ min κ ≤ hi, with hi
    attained (as an upper bound) at the time ``t`` (the user's parameter)."""

    mode: str
    estimate: float  # κ at t in floating point (lo ≤ estimate ≤ hi)
    lo: float
    hi: float
    t: float
    met: bool  # the tolerance was met
    method: str
    evaluations: int = 0

    def to_json(self) -> dict:
        return {"min": self.estimate, "interval": [self.lo, self.hi], "t": self.t,
                "tolerance_met": self.met, "method": self.method}


def wanted_gap(kappa: float, rel_tol: float = REL_TOL) -> float:
    """The largest hi - lo accepted for a minimum near ``kappa``."""
    return rel_tol * max(kappa, FLOOR)


def normalised_gram(rows: list[list]) -> list[list] | None:
    """M = N·Nᵀ (N: the rows scaled to unit length) as a symmetric ball matrix, or None
    when some row's length is not proven non-zero."""
    n = len(rows)
    lengths = []
    for r in rows:
        d = sum((e * e for e in r), arb(0))
        if not d > 0:
            return None
        lengths.append(d.sqrt())
    m = [[arb(1) if i == j else None for j in range(n)] for i in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            g = sum((a * b for a, b in zip(rows[i], rows[j], strict=True)), arb(0))
            m[i][j] = m[j][i] = g / (lengths[i] * lengths[j])
    return m


def _finite(m: list[list]) -> bool:
    return all(e.is_finite() for row in m for e in row)


def _mid_matrix(m: list[list]) -> list[list[arb]]:
    return [[arb(e.mid()) for e in row] for row in m]


def positive_definite(m0: list[list[arb]]) -> bool:
    """Proven: the symmetric ball matrix is positive definite (every member of it): a
    Cholesky factorisation in ball arithmetic with every pivot proven > 0."""
    n = len(m0)
    low = [[arb(0)] * n for _ in range(n)]
    for j in range(n):
        pivot = m0[j][j] - sum((low[j][k] * low[j][k] for k in range(j)), arb(0))
        if not pivot > 0:
            return False
        low[j][j] = pivot.sqrt()
        for i in range(j + 1, n):
            low[i][j] = (m0[i][j] - sum((low[i][k] * low[j][k] for k in range(j)),
                                        arb(0))) / low[j][j]
    return True


def _float_eigh(m0: list[list[arb]]) -> tuple[float, list[float]]:
    """The smallest eigenvalue of the (symmetric) midpoint matrix and its eigenvector, in
    floating point (numpy when installed, else mpmath at double precision): only a
    guess, which the proofs above check."""
    a = [[float(e) for e in row] for row in m0]
    try:
        import numpy
    except ImportError:  # numpy is optional (the plot extras)
        import mpmath

        with mpmath.workprec(53):
            values, vectors = mpmath.eigsy(mpmath.matrix(a))
            k = min(range(len(a)), key=lambda i: values[i])
            return float(values[k]), [float(vectors[i, k]) for i in range(len(a))]
    values, vectors = numpy.linalg.eigh(numpy.array(a))
    return float(values[0]), [float(x) for x in vectors[:, 0]]


def _radius_norm(m: list[list]) -> arb:
    """The Frobenius norm of the ball matrix's radii, rounded outward: a bound of
    ‖M - M₀‖ (spectral ≤ Frobenius) for every member M of ``m`` around its midpoints M₀."""
    total = arb(0)
    for row in m:
        for e in row:
            total += arb(e.rad()) ** 2
    return total.sqrt()


def lambda_lower(m: list[list]) -> float:
    """A proven lower bound of λ_min(M(t)) for every member M(t) of the ball matrix
    ``m`` (Weyl around the midpoint matrix, whose own bound a ball Cholesky proves)."""
    if not _finite(m):
        return 0.0
    m0 = _mid_matrix(m)
    n = len(m)
    radius = _radius_norm(m)
    estimate, _ = _float_eigh(m0)
    ell = 0.0
    for delta in (1e-13, 1e-10, 1e-7, 1e-4):
        candidate = estimate - delta * (1 + abs(estimate))
        if candidate <= 0:
            break
        shifted = [[m0[i][j] - (arb(candidate) if i == j else 0) for j in range(n)]
                   for i in range(n)]
        if positive_definite(shifted):
            ell = candidate
            break
    bound = arb(ell) - radius
    return max(0.0, float(bound.lower()))


def lambda_upper(m: list[list]) -> tuple[float, float]:
    """(a proven upper bound of λ_min over the ball matrix's members at a point — the
    Rayleigh quotient of the floating-point eigenvector, enclosed — and the float
    estimate of λ_min)."""
    if not _finite(m):
        return math.inf, math.inf
    m0 = _mid_matrix(m)
    estimate, vector = _float_eigh(m0)
    v = [arb(x) for x in vector]
    n = len(m)
    num = sum((v[i] * m[i][j] * v[j] for i in range(n) for j in range(n)), arb(0))
    den = sum((x * x for x in v), arb(0))
    return float((num / den).upper()), estimate


def _radicals(model) -> list[arb]:
    return [b for _, b in sorted(radical_balls(model.context, None).items())]


_DERIVATIVES: dict = {}


def _a_derivatives(model) -> list[list[list[tuple[int, object]]]]:
    """∂A_ij/∂v for every variable v of the model's context (the non-zero ones), once
    per model."""
    from singcheck.algebra.polynomials import memo_per_object

    def build(model):
        names = model.context.names()
        return [[[(k, e.derivative(name)) for k, name in enumerate(names)
                  if not e.derivative(name).is_zero()] for e in row] for row in model.A]

    return memo_per_object(_DERIVATIVES, model, build)


def _real(joints: list) -> bool:
    for j in joints:
        parts = j if isinstance(j, tuple) else (j,)
        if not all(isinstance(p, arb) for p in parts):
            return False
    return True


def _rows_and_derivatives(path, joints: list, variables: list, dvariables: list | None,
                          length):
    """The rows of A at the mode's joints and the pose (balls), the angle columns times
    1/``length``, and (when ``dvariables``, the pose variables' derivatives in t, are
    given) their derivatives along the path: each joint's derivative from the leg's
    constraint, ρ' = -(∂F_i/∂X · X')/(∂F_i/∂ρ) (None when ∂F_i/∂ρ is not proven ≠ 0),
    then Σ_v ∂A_ij/∂v · v'.  None when a joint is not a real ball."""
    from singcheck.certify.path import _flat_joints

    model = path.projection.model
    if not _real(joints):
        return None, None
    point = _flat_joints(joints) + list(variables) + _radicals(model)
    powers: dict = {}
    raw = [[evaluate(e, point, powers) for e in row] for row in model.A]
    inverse = 1 / fraction_ball(length)
    scale = [inverse if v in model.angles else None for v in model.pose]

    def scaled(rows):
        return [[e if s is None else e * s for e, s in zip(row, scale, strict=True)]
                for row in rows]

    if dvariables is None:
        return scaled(raw), None
    # X' in A's columns: x' for a coordinate, φ' = cos φ·(sin φ)' - sin φ·(cos φ)' for
    # an angle
    rate, k = [], 0
    for v in model.pose:
        if v in model.angles:
            c, s_ = variables[k], variables[k + 1]
            rate.append(c * dvariables[k + 1] - s_ * dvariables[k])
            k += 2
        else:
            rate.append(dvariables[k])
            k += 1
    djoints: list = []
    for i, (leg, j) in enumerate(zip(model.legs, joints, strict=True)):
        row = raw[leg.constraint_index]
        b = evaluate(model.B[leg.constraint_index][i], point, powers)
        if not (b > 0 or b < 0):
            return scaled(raw), None
        q = -sum((e * r for e, r in zip(row, rate, strict=True)), arb(0)) / b
        djoints += [-j[1] * q, j[0] * q] if isinstance(j, tuple) else [q]
    dpoint = djoints + list(dvariables) + [arb(0)] * len(_radicals(model))
    drows = [[sum((evaluate(d, point, powers) * dpoint[k] for k, d in entry), arb(0))
              for entry in row] for row in _a_derivatives(model)]
    return scaled(raw), scaled(drows)


def gram_derivative(rows: list[list], drows: list[list]) -> list[list] | None:
    """M' (d/dt of :func:`normalised_gram`) from the rows and their derivatives:
    M_ij' = g_ij'/√(d_i d_j) - ½·M_ij·(d_i'/d_i + d_j'/d_j), M_ii' = 0."""
    n = len(rows)
    d, dd = [], []
    for r, dr in zip(rows, drows, strict=True):
        di = sum((e * e for e in r), arb(0))
        if not di > 0:
            return None
        d.append(di)
        dd.append(2 * sum((a * b for a, b in zip(r, dr, strict=True)), arb(0)))
    out = [[arb(0)] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            g = sum((a * b for a, b in zip(rows[i], rows[j], strict=True)), arb(0))
            dg = sum((a * b for a, b in zip(drows[i], rows[j], strict=True)), arb(0)) + \
                sum((a * b for a, b in zip(rows[i], drows[j], strict=True)), arb(0))
            root = (d[i] * d[j]).sqrt()
            out[i][j] = out[j][i] = dg / root - g / root * (dd[i] / d[i] + dd[j] / d[j]) / 2
    return out


def _mode_joints(path, mode, t: arb, with_rate: bool):
    pose, variables = path.pose_and_variables_at(t)
    per_leg = path.leg_branches_at(t, variables)
    joints = [leg[b.label] for leg, b in zip(per_leg, mode.branches, strict=True)]
    rates = path.pose_rates_at(t) if with_rate else None
    return joints, variables, rates


def gram_at(path, mode, t: arb, length, with_rate: bool = False):
    """(M, M') over the ball ``t`` for one mode (M' only ``with_rate``; either None when
    not enclosed there)."""
    joints, variables, rates = _mode_joints(path, mode, t, with_rate)
    if any(j is None for j in joints):
        return None, None
    rows, drows = _rows_and_derivatives(path, joints, variables, rates, length)
    if rows is None:
        return None, None
    m = normalised_gram(rows)
    dm = None if m is None or drows is None else gram_derivative(rows, drows)
    return m, dm


def kappa_at(path, mode, t: float, length=1) -> float | None:
    """κ at one time (floating point, for figures): None where not enclosed."""
    m, _ = gram_at(path, mode, arb(t), length)
    if m is None:
        return None
    return math.sqrt(max(0.0, _float_eigh(_mid_matrix(m))[0]))


def piece_lower(m_centre, m_piece, dm_piece, half: arb) -> float:
    """A proven lower bound of λ_min(M(t)) for every t of a piece of half-width
    ``half``: the larger of Weyl around the piece's enclosure ``m_piece`` (first order)
    and the centred form (second order): M(t) = M(t_c) + h·M'(ξ) per entry (mean
    values, ξ in the piece), M'(ξ) = G₀ + F with G₀ the midpoints of the enclosure
    ``dm_piece`` and |F| ≤ its radii, so λ_min(M(t)) ≥ λ_min(M(t_c) + h·G₀) - |h|·‖F‖_F,
    and h ↦ λ_min(M(t_c) + h·G₀) is concave (a minimum of linear functions vᵀ(…)v):
    at least its smaller value at h = ±half (both enclosed from ``m_centre``)."""
    best = 0.0 if m_piece is None else lambda_lower(m_piece)
    if m_centre is None or dm_piece is None or not _finite(dm_piece):
        return best
    n = len(m_centre)
    g0 = _mid_matrix(dm_piece)
    spread = _radius_norm(dm_piece) * half
    ends = [lambda_lower([[m_centre[i][j] + sign * half * g0[i][j] for j in range(n)]
                          for i in range(n)]) for sign in (1, -1)]
    centred = float((arb(min(ends)) - spread).lower())
    return max(best, centred)


def _to_global(path, t: arb) -> float:
    return float(path.trajectory.to_global(t).mid())


def minimum_clearance(path, mode, length=1, rel_tol: float = REL_TOL,
                      budget: int | None = None) -> Clearance:
    """The certified minimum of κ along ``mode`` (given as feasible) over the path's
    closed range, by best-first branch-and-bound (see the module docstring)."""
    interval = path.trajectory.range
    width = float(interval.end) - float(interval.start)
    smallest = max(width * MIN_WIDTH, 1e-300)
    periods = max(1.0, width / (2 * math.pi))
    left = budget if budget is not None else int(BUDGET * periods)
    best = (math.inf, math.inf, 0.0)  # (upper bound of κ², float κ², local t)
    heap: list = []
    count = 0

    def visit(piece: arb) -> None:
        nonlocal best, left, count
        checkpoint()
        left -= 1
        mid = arb(piece.mid())
        m_centre, _ = gram_at(path, mode, mid, length)
        m_piece, dm_piece = gram_at(path, mode, piece, length, with_rate=True)
        low = piece_lower(m_centre, m_piece, dm_piece, arb(piece.rad()))
        if m_centre is not None:
            up, estimate = lambda_upper(m_centre)
            if up < best[0]:
                best = (up, estimate, float(mid))
        count += 1
        heapq.heappush(heap, (low, count, piece))

    for end in (interval.start.ball(), interval.end.ball()):  # a minimum at a range end
        m_end, _ = gram_at(path, mode, end, length)
        if m_end is not None:
            up, estimate = lambda_upper(m_end)  # over the whole ball: holds at the end
            if up < best[0]:
                best = (up, estimate, float(end.mid()))
    for piece in pieces(interval):
        visit(piece)
    met = False
    while heap:
        low, _, piece = heap[0]
        hi = _root_up(best[0])
        lo = _root_down(low)
        if hi - lo <= wanted_gap(hi, rel_tol):
            met = True
            break
        if left <= 0 or float(piece.rad()) * 2 <= smallest:
            break
        heapq.heappop(heap)
        for half in halves(piece):
            visit(half)
    low = heap[0][0] if heap else 0.0
    hi = _root_up(best[0]) if best[0] < math.inf else 1.0
    lo = min(_root_down(low), hi)
    estimate = min(max(math.sqrt(max(best[1], 0.0)), lo), hi) if best[1] < math.inf else hi
    t = _to_global(path, arb(best[2]))
    return Clearance(mode.label, estimate, lo, hi, t, met, METHOD, count)


def _root_up(x: float) -> float:
    """An upper bound of √x (the float square root, one ulp up: rounding)."""
    return math.inf if x == math.inf else math.nextafter(math.sqrt(max(x, 0.0)), math.inf)


def _root_down(x: float) -> float:
    """A lower bound of √x (≥ 0)."""
    return max(0.0, math.nextafter(math.sqrt(max(x, 0.0)), 0.0))


def singular_clearance(mode_label: str, t: float) -> Clearance:
    """A mode proven singular at ``t``: its minimum clearance is exactly 0."""
    return Clearance(mode_label, 0.0, 0.0, 0.0, t, True, METHOD_SINGULAR)
