"""The certified alternative without elimination: interval branch-and-bound over t.

This is Merlet's approach, written with Arb balls (python-flint), as the yardstick that
singcheck is timed against in ``make bench``.  It never computes ξ(X): it works on
det A along each working mode directly.

1. **Inverse kinematics in closed form.**  Each leg ``a ρ² + b(t) ρ + c(t)`` (a constant)
   has the branches ρ± = (-b ± √D)/(2a), D = b² - 4ac; b, c, D are trig polynomials
   (exact substitution of X = φ(t), no elimination), evaluated in ball arithmetic.
2. **Feasibility per branch**, by branch-and-bound: a box T of the range is cleared when
   D(T) > 0 and lo < ρ(T) < hi are proven; a box on which D(T) < 0 or ρ(T) is certainly
   outside the limits proves the branch infeasible; a box still open at the minimum
   width leaves it unknown (tangent to a limit, say).
3. **det A along each feasible mode**: F(t) = det A(ρ_mode(t), φ(t)), written as
   Σ_α q_α(t) ρ^α with trig-polynomial coefficients q_α, and its derivative
   F'(t) = Σ_α (q_α' ρ^α + q_α ∂_t ρ^α) with ρ' = (-b' ± D'/(2√D))/(2a).  A box is
   excluded when the naive enclosure F(T) or the mean-value form F(m) + F'(T)(T - m)
   excludes 0; where F'(T) excludes 0, F is strictly monotone on T, so opposite proven
   signs at its ends prove exactly one root and equal signs prove none.  Otherwise the
   box is bisected, down to a minimum width (then: unknown, e.g. at a graze).
4. **Refinement** of each root to the tolerance by the interval Newton operator
   N(T) = m - F(m)/F'(T) ∩ T (falls back to bisection on proven signs).

Everything is an Arb ball comparison: the answers are certified, but the method cannot
prove a tangential root (a graze) and its cost grows with the length of the range.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import product

from flint import arb, ctx, fmpq, fmpq_poly, fmpz_poly

from singcheck.algebra.radicals import angle_names
from singcheck.algebra.trig import derivative, reduce_trig
from singcheck.model.robot import leg_coefficients

_MAX_BOXES = 20_000
PIECES = 32
FEASIBILITY_PIECES = 8


class Fourier:
    """A trajectory coordinate as Σ tⁱ (aᵢₖ cos kt + bᵢₖ sin kt), converted exactly from
    its polynomial in c = cos t and s = sin t (Chebyshev bases), so that a box T is
    evaluated through sin kT and cos kT themselves (tight), not a polynomial in cos T
    (whose enclosure widens fast with the degree)."""

    __slots__ = ("terms",)

    def __init__(self, p) -> None:
        p = reduce_trig(p)
        self.terms = []  # (i, k, cos coefficient, sin coefficient)
        if p.is_zero():
            return
        dt = p.degrees()[0]
        for i in range(dt + 1):
            parts = [{}, {}]
            for (ii, j, k), a in p.terms():
                if ii == i:
                    parts[j][k] = a
            found: dict[int, list] = {}
            for j, part in enumerate(parts):
                if not part:
                    continue
                q = fmpq_poly([part.get(k, 0) for k in range(max(part) + 1)])
                while not q.is_zero():
                    n = q.degree()
                    basis = fmpq_poly(fmpz_poly.chebyshev_t(n) if j == 0
                                      else fmpz_poly.chebyshev_u(n))
                    coeff = q.coeffs()[-1] / basis.coeffs()[-1]
                    q -= coeff * basis
                    k = n if j == 0 else n + 1  # T_n(c) = cos nt, s U_n(c) = sin (n+1)t
                    found.setdefault(k, [fmpq(0), fmpq(0)])[j] += coeff
            for k, (a, b) in sorted(found.items()):
                self.terms.append((i, k, arb(a) if a != 0 else None, arb(b) if b != 0 else None))

    def harmonics(self) -> set[int]:
        return {k for _, k, _, _ in self.terms if k}

    def degree_t(self) -> int:
        return max((i for i, _, _, _ in self.terms), default=0)

    def __call__(self, tp: list[arb], sc: dict[int, tuple[arb, arb]]) -> arb:
        total = arb(0)
        for i, k, a, b in self.terms:
            if k == 0:
                term = a
            else:
                sin_k, cos_k = sc[k]
                term = a * cos_k if a is not None else None
                if b is not None:
                    term = b * sin_k if term is None else term + b * sin_k
            total += term if i == 0 else term * tp[i]
        return total


class Poly:
    """A polynomial over Q in the robot's variables, evaluated on balls term by term
    with shared powers (the caller's ``powers`` cache, one per evaluation point)."""

    __slots__ = ("terms",)

    def __init__(self, p) -> None:
        self.terms = [(arb(c), tuple((v, e) for v, e in enumerate(exps) if e))
                      for exps, c in p.terms()]

    def __call__(self, powers) -> arb:
        total = arb(0)
        for c, mono in self.terms:
            term = c
            for v, e in mono:
                term = term * powers(v, e)
            total += term
        return total


def _powers(values: list):
    cache: list[dict[int, arb]] = [{1: v} for v in values]

    def power(v: int, e: int) -> arb:
        hit = cache[v].get(e)
        if hit is None:
            hit = cache[v][e] = values[v] ** e
        return hit

    return power


def _slope(grads: list[tuple[int, Poly]], powers, rates: list[arb]) -> arb:
    """Σ ∂p/∂vᵢ · vᵢ' over the ring variables vᵢ that p involves (the chain rule)."""
    total = arb(0)
    for i, g in grads:
        total += g(powers) * rates[i]
    return total


@dataclass
class Leg:
    """A prismatic leg: a ρ² + b(X) ρ + c(X) (a constant), or a ρ + b(X)."""

    joint: str
    index: int  # the joint's position among the robot's variables
    degree: int
    a: arb  # leading coefficient in the joint (a constant)
    b: Poly  # quadratic: a ρ² + b(X) ρ + c(X); linear: a ρ + b(X)
    db: list[tuple[int, Poly]]  # ∂b/∂v for each ring variable v that b involves
    d: Poly | None  # D = b² - 4ac, expanded (tighter than b² - 4ac on balls)
    dd: list[tuple[int, Poly]] | None  # ∂D/∂v
    limits: tuple[arb, arb] | None

    @property
    def labels(self) -> tuple[str, ...]:
        return ("+", "-") if self.degree == 2 else ("o",)

    def values(self, powers, rates):
        """{label: [(variable, ρ, ρ')]} on the box (ρ' None without ``rates``), None
        where D > 0 is not proven, 'complex' where D < 0 is."""
        b = self.b(powers)
        db = _slope(self.db, powers, rates) if rates is not None else None
        if self.degree == 1:
            return {"o": [(self.index, -b / self.a, -db / self.a if rates is not None else None)]}
        d = self.d(powers)
        if not d > 0:
            return "complex" if d < 0 else None
        root = d.sqrt()
        two_a = 2 * self.a
        if rates is None:
            return {"+": [(self.index, (-b + root) / two_a, None)],
                    "-": [(self.index, (-b - root) / two_a, None)]}
        half = _slope(self.dd, powers, rates) / (2 * root)
        return {"+": [(self.index, (-b + root) / two_a, (-db + half) / two_a)],
                "-": [(self.index, (-b - root) / two_a, (-db - half) / two_a)]}

    def inside(self, entries) -> bool | None:
        """Within the joint limits on the whole box: True, False (certainly out
        somewhere: a point ball is out), None (undecided)."""
        if self.limits is None:
            return True
        rho = entries[0][1]
        lo, hi = self.limits
        if rho > lo and rho < hi:
            return True
        if rho < lo or rho > hi:
            return False
        return None


@dataclass
class RevoluteLeg:
    """A revolute leg P(X) cos θ + Q(X) sin θ + R(X) = 0, with singcheck's branch labels
    (singcheck/model/robot.py): on branch σ (label '+' for σ = 1, '-' for σ = -1),
    W cos θ = -P R + σ Q √Δ, W sin θ = -Q R - σ P √Δ, W = P² + Q², Δ = W - R²; there
    ∂F/∂θ = -P sin θ + Q cos θ = σ √Δ, so θ' = -(P' cos θ + Q' sin θ + R')/(σ √Δ)."""

    joint: str
    cos_index: int
    sin_index: int
    p: Poly
    q: Poly
    r: Poly
    grads: tuple[list[tuple[int, Poly]], ...]  # ∂P, ∂Q, ∂R over the ring variables
    delta: Poly  # Δ = P² + Q² - R², expanded
    w: Poly  # W = P² + Q², expanded
    limits: tuple[arb, arb, arb] | None  # cos c, sin c, cos h: θ ∈ [c - h, c + h]

    labels = ("+", "-")

    def values(self, powers, rates):
        """{label: [(cos θ's variable, cos θ, its rate), (sin θ's, sin θ, rate)]},
        None where Δ > 0 is not proven, 'complex' where Δ < 0 is."""
        delta = self.delta(powers)
        if not delta > 0:
            return "complex" if delta < 0 else None
        p, q, r, w = self.p(powers), self.q(powers), self.r(powers), self.w(powers)
        root = delta.sqrt()
        if rates is not None:
            dp, dq, dr = (_slope(g, powers, rates) for g in self.grads)
        out = {}
        for label, sigma in (("+", 1), ("-", -1)):
            c = (-p * r + sigma * q * root) / w
            s = (-q * r - sigma * p * root) / w
            dc = ds = None
            if rates is not None:
                dtheta = -(dp * c + dq * s + dr) / (sigma * root)
                dc, ds = -s * dtheta, c * dtheta
            out[label] = [(self.cos_index, c, dc), (self.sin_index, s, ds)]
        return out

    def inside(self, entries) -> bool | None:
        """θ within [c - h, c + h] (h < π): exactly where cos(θ - c) >= cos h, tested on
        θ itself through cos(θ - c) = cos θ cos c + sin θ sin c (no atan2 cut to avoid)."""
        if self.limits is None:
            return True
        cos_c, sin_c, cos_h = self.limits
        x = entries[0][1] * cos_c + entries[1][1] * sin_c
        if x > cos_h:
            return True
        if x < cos_h:
            return False
        return None


@dataclass
class Answer:
    verdict: str  # singularity-free | singular | infeasible | unknown
    feasible: list[str]
    singular_times: dict[str, list[arb]] = field(default_factory=dict)
    reason: str = ""
    boxes: int = 0


def _box(lo: arb, hi: arb) -> arb:
    return lo.union(hi)


def _mid(lo: arb, hi: arb) -> arb:
    return ((lo + hi) / 2).mid()


class BranchAndBound:
    """The contender on one (robot model, trajectory spec)."""

    def __init__(self, model, trajectory, tolerance: float = 1e-9) -> None:
        if model.radical_legs:
            raise NotImplementedError("the contender does not handle square roots")
        self.tolerance = tolerance
        self.range = trajectory.range
        names = model.context.names()
        self.nvars = len(names)
        # each pose variable's slots in the ring: (x,) or, for an angle, (cos φ, sin φ)
        self.pose_slots = [tuple(names.index(n) for n in angle_names(v))
                           if v in model.spec.angles else (names.index(v),)
                           for v in model.pose]
        self.phi = [Fourier(trajectory.pose[v]) for v in model.pose]
        self.dphi = [Fourier(derivative(trajectory.pose[v])) for v in model.pose]
        self.harmonics = sorted(set().union(*(f.harmonics() for f in self.phi + self.dphi)))
        self.t_degree = max(f.degree_t() for f in self.phi + self.dphi)
        limits = model.spec.joint_limits

        def grad(p) -> list[tuple[int, Poly]]:
            """∂p/∂v for every ring variable v that p involves: multiplied by v's rate
            (a pose coordinate's from the path, a joint's from its branch)."""
            out = []
            for i, v in enumerate(names):
                g = p.derivative(v)
                if not g.is_zero():
                    out.append((i, Poly(g)))
            return out

        self.legs = []
        for leg in model.legs:
            coeffs = leg_coefficients(leg)
            if leg.kind == "revolute":
                p, q, r = coeffs
                lim = None
                if leg.joint in limits:
                    lo, hi = (v.ball() for v in limits[leg.joint])
                    half = (hi - lo) / 2
                    if half < arb.pi():  # a limit interval narrower than the circle
                        sin_c, cos_c = ((lo + hi) / 2).sin_cos()
                        lim = (cos_c, sin_c, half.cos())
                ci, si = (names.index(n) for n in angle_names(leg.joint))
                self.legs.append(RevoluteLeg(leg.joint, ci, si, Poly(p), Poly(q), Poly(r),
                                             (grad(p), grad(q), grad(r)),
                                             Poly(p * p + q * q - r * r), Poly(p * p + q * q),
                                             lim))
                continue
            lim = None
            if leg.joint in limits:
                lo, hi = limits[leg.joint]
                lim = (arb(fmpq(lo.numerator, lo.denominator)),
                       arb(fmpq(hi.numerator, hi.denominator)))
            a = arb(list(coeffs[0].coeffs())[0])
            if leg.degree == 2:
                _, b, c = coeffs
                d = b * b - 4 * coeffs[0] * c
                self.legs.append(Leg(leg.joint, names.index(leg.joint), 2, a, Poly(b), grad(b),
                                     Poly(d), grad(d), lim))
            else:
                _, b = coeffs
                self.legs.append(Leg(leg.joint, names.index(leg.joint), 1, a, Poly(b), grad(b),
                                     None, None, lim))
        self.det = Poly(model.det_A)
        self.det_grad = grad(model.det_A)
        self.min_width = arb(max(tolerance, 1e-12) / 1000)
        self.boxes = 0

    # -- evaluation --------------------------------------------------------------

    def _pose(self, t: arb, with_derivative: bool):
        """The ring variables' values on a box T (the pose's; the joints' left 0) and,
        with ``with_derivative``, their rates (else None), from sin kT and cos kT: an
        angle φ's cos φ(T), sin φ(T) and rates -sin φ·φ', cos φ·φ' (the chain rule)."""
        sc = {k: (k * t).sin_cos() for k in self.harmonics}
        tp = [arb(1), t]
        for _ in range(self.t_degree - 1):
            tp.append(tp[-1] * t)
        values = [arb(0)] * self.nvars
        rates = [arb(0)] * self.nvars if with_derivative else None
        for slot, f, df in zip(self.pose_slots, self.phi, self.dphi, strict=True):
            x = f(tp, sc)
            dx = df(tp, sc) if with_derivative else None
            if len(slot) == 1:
                values[slot[0]] = x
                if with_derivative:
                    rates[slot[0]] = dx
            else:
                s, c = x.sin_cos()
                values[slot[0]], values[slot[1]] = c, s
                if with_derivative:
                    rates[slot[0]], rates[slot[1]] = -s * dx, c * dx
        return values, rates

    def _joints(self, t: arb, labels: str, with_derivative: bool):
        values, rates = self._pose(t, with_derivative)
        powers = _powers(values)
        joints = []
        for leg, label in zip(self.legs, labels, strict=True):
            v = leg.values(powers, rates)
            if v is None or v == "complex":
                return None
            joints += v[label]
        return values, rates, joints

    def det_a(self, t: arb, labels: str, with_derivative: bool = False):
        """(F(T), F'(T) or None), or None where a branch is not proven real on T."""
        return self.det_a_lazy(t, labels, with_derivative)

    def det_a_lazy(self, t: arb, labels: str, with_derivative: bool | None = False):
        """Like :meth:`det_a`; with ``with_derivative=None`` F'(T) is computed only when
        F(T) contains 0 (the pose and joint values are shared by both)."""
        got = self._joints(t, labels, with_derivative is not False)
        if got is None:
            return None
        values, rates, joints = got
        values = list(values)
        for index, value, _ in joints:
            values[index] = value
        powers = _powers(values)
        value = self.det(powers)
        if with_derivative is False or (with_derivative is None and not value.contains(0)):
            return value, None
        rates = list(rates)
        for index, _, rate in joints:
            rates[index] = rate
        return value, _slope(self.det_grad, powers, rates)

    def _sign(self, point: arb, labels: str) -> int | None:
        r = self.det_a(point, labels)
        if r is None:
            return None
        v = r[0]
        return 1 if v > 0 else -1 if v < 0 else None

    def _pieces(self, n: int) -> list[tuple[arb, arb]]:
        """The range cut into PIECES equal boxes (the top levels of the bisection tree
        fail every test on a wide box: skipping them is cheaper), last piece on top."""
        lo, hi = self.range.start.ball().lower(), self.range.end.ball().upper()
        edges = [lo] + [(lo + (hi - lo) * i / n).mid() for i in range(1, n)] + [hi]
        return [(a, b) for a, b in zip(edges, edges[1:], strict=False)][::-1]

    # -- feasibility ---------------------------------------------------------------

    def leg_feasible(self, leg) -> dict[str, str]:
        """feasible | infeasible | unknown for each branch of one leg over the whole range
        (both branches share the boxes and the evaluations).  A branch left unknown on
        one box (its branches meet there, or it touches a limit) stays under test on the
        later boxes: a box on which the leg is proven complex, or the branch proven out
        of its limits, still makes it infeasible."""
        labels = leg.labels
        status = dict.fromkeys(labels, "feasible")
        stack = [(lo, hi, labels) for lo, hi in self._pieces(FEASIBILITY_PIECES)]
        while stack:
            lo, hi, open_ = stack.pop()
            open_ = tuple(lb for lb in open_ if status[lb] != "infeasible")
            if not open_:
                continue
            self.boxes += 1
            values, _ = self._pose(_box(lo, hi), False)
            v = leg.values(_powers(values), None)
            if v == "complex":
                return dict.fromkeys(labels, "infeasible")
            left = []
            for label in open_:
                inside = None if v is None else leg.inside(v[label])
                if inside is False:
                    status[label] = "infeasible"
                elif inside is None:
                    left.append(label)
            if not left:
                continue
            if hi - lo < self.min_width or self.boxes > _MAX_BOXES:
                for label in left:
                    if status[label] == "feasible":
                        status[label] = "unknown"
                continue
            m = _mid(lo, hi)
            stack += [(m, hi, tuple(left)), (lo, m, tuple(left))]
        return status

    # -- det A along a mode --------------------------------------------------------

    def mode_roots(self, labels: str) -> tuple[list[arb], bool]:
        """Certified roots of det A along the mode, and whether everything was decided."""
        stack = self._pieces(PIECES)
        roots, complete = [], True
        while stack:
            lo, hi = stack.pop()
            self.boxes += 1
            t = _box(lo, hi)
            r = self.det_a_lazy(t, labels, None)
            if r is not None and r[1] is None:
                continue  # F(T) excludes 0
            if r is not None:
                _, slope = r
                m = _mid(lo, hi)
                at_m = self.det_a(m, labels)
                if at_m is not None and not (at_m[0] + slope * (t - m)).contains(0):
                    continue
                if not slope.contains(0):
                    s_lo, s_hi = self._sign(lo, labels), self._sign(hi, labels)
                    if s_lo is not None and s_hi is not None:
                        if s_lo != s_hi:
                            roots.append(self._newton(lo, hi, labels, s_lo))
                        continue
            if hi - lo < self.min_width or self.boxes > _MAX_BOXES:
                complete = False
                continue
            m = _mid(lo, hi)
            stack += [(m, hi), (lo, m)]
        return roots, complete

    def _newton(self, lo: arb, hi: arb, labels: str, s_lo: int) -> arb:
        """Shrink a monotone bracket to the tolerance: interval Newton, else bisection."""
        width = arb(self.tolerance)
        while hi - lo > width:
            m = _mid(lo, hi)
            r = self.det_a(_box(lo, hi), labels, True)
            fm = self.det_a(m, labels)
            if r is not None and fm is not None and not r[1].contains(0):
                n = m - fm[0] / r[1]
                new_lo, new_hi = max(lo, n.lower()), min(hi, n.upper())
                if new_hi - new_lo < (hi - lo) / 2:
                    lo, hi = new_lo, new_hi
                    continue
            s = self._sign(m, labels)
            if s is None:
                break
            if s == s_lo:
                lo = m
            else:
                hi = m
        return _box(lo, hi)

    # -- the whole answer ----------------------------------------------------------

    def run(self) -> Answer:
        self.boxes = 0
        per_leg = []
        for leg in self.legs:
            per_leg.append(list(self.leg_feasible(leg).items()))
        feasible, unsure = [], []
        for choice in product(*per_leg):
            label = "".join(lb for lb, _ in choice)
            states = {st for _, st in choice}
            if "infeasible" in states:
                continue
            (unsure if "unknown" in states else feasible).append(label)
        answer = Answer("singularity-free", feasible)
        undecided = bool(unsure)
        start, end = self.range.start.ball(), self.range.end.ball()
        for label in feasible:
            roots, complete = self.mode_roots(label)
            undecided |= not complete
            inside = []
            for r in roots:
                if r > end or r < start:
                    continue
                if not (r >= start and r <= end):
                    undecided = True  # too close to a range end to place
                    continue
                inside.append(r)
            answer.singular_times[label] = inside
        answer.boxes = self.boxes
        if any(answer.singular_times.values()):
            answer.verdict = "singular"
        elif undecided:
            answer.verdict, answer.reason = "unknown", "a box stayed ambiguous"
        elif not feasible:
            answer.verdict = "infeasible"
        return answer


def contender(model, trajectory, tolerance: float = 1e-9) -> Answer:
    """Build and run the branch-and-bound contender (everything per call, like singcheck)."""
    old = ctx.prec
    ctx.prec = 53
    try:
        return BranchAndBound(model, trajectory, tolerance).run()
    finally:
        ctx.prec = old
