"""Certification of a path made of pieces (segments, waypoints, splines, rescaled time).

Each piece is certified on its own closed sub-range (:func:`certify_path`): its
candidates, its working modes' feasibility, its undecided boxes.  The whole path's
answer is composed from them, in the user's parameter t:

* **Times.**  A piece written in τ = g·π·t reports balls in τ; they are mapped to t by
  t = τ/(gπ) in ball arithmetic (rigorous).  Candidates carry their segment number.
* **Joins.**  The pose is continuous at a join (checked exactly when the spec was read),
  so μ takes the same value ξ(X_join) on both sides.  Two candidates whose balls hold
  the join are one root exactly when μ vanishes *at* the join, which is decided
  exactly (:func:`singcheck.algebra.trig_values.sum_is_zero`); it is then counted once.
* **Working modes.**  A mode is feasible for the path only when it is feasible on every
  piece, each on its closed range, and continuous at every join.  Continuity: every
  leg's constraint a·ρ² + b·ρ + c has a constant leading coefficient a and the same
  coefficients on both sides of the join (same pose), so the branch labelled ``+``
  (resp. ``-``) is the same root on both sides; feasibility on the closed ranges
  proves the discriminant > 0 at the join (a serial singularity there makes the mode
  infeasible on both pieces).  The joint values of both sides at the join are also
  compared in ball arithmetic: provably different values would break the mode.
* **Verdict.**  From the composed modes and candidates, as for one piece; when every
  piece has a feasible mode but none is feasible throughout, the reason names the join
  where the feasible mode changes.
"""

from __future__ import annotations

import time

from flint import arb

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.trig_values import sum_is_zero
from singcheck.budget import checkpoint, remaining
from singcheck.certify.classification import (
    EXACT_CORROBORATION_BUDGET,
    REGULAR,
    SINGULAR,
    VERDICT_FREE,
    VERDICT_INFEASIBLE,
    Candidate,
    TrajectoryReport,
    certify_path,
    corroborate_exactly,
    verdict_of,
)
from singcheck.certify.engines import EXACT_NOT_RUN, combined, corroborated_verdict
from singcheck.certify.path import AUTO, build_path
from singcheck.certify.working_modes import FEASIBLE, INFEASIBLE, UNKNOWN, WorkingMode
from singcheck.elimination.projection import RobotProjection
from singcheck.roots.enclosures import RealRoot
from singcheck.spec.files import TrajectorySpec


def certify_trajectory(projection: RobotProjection, spec: TrajectorySpec,
                       tolerance: float = 1e-9, engine: str = AUTO) -> TrajectoryReport:
    """The verdict for a whole path, one piece or many (see the module docstring);
    ``engine``: :data:`~singcheck.certify.path.ENGINES`."""
    if not spec.segments and spec.time_scale is None:
        return certify_path(build_path(projection, spec, engine), tolerance)
    defer = engine == AUTO and len(spec.pieces) > 1
    reports, ends = [], []
    for piece in spec.pieces:
        checkpoint()
        report = certify_path(build_path(projection, piece, engine), tolerance,
                              defer_corroboration=defer)
        reports.append(report)
        # the branches at both ends now, while the piece's ball polynomials are at hand
        # (made again from thousand-digit coefficients when the joins are composed)
        ends.append((_branch_values(report, piece.global_range.start),
                     _branch_values(report, piece.global_range.end)))
    if defer:
        reports = corroborate_pieces(reports)
    return compose(spec, reports, ends)


#: seconds the exact engine may spend, over all the pieces of one path together,
#: corroborating the pieces the interval engine decided on its own (a piece it left
#: windows on is decided by the exact engine, within the trajectory's time limit)
PATH_CORROBORATION_BUDGET = EXACT_CORROBORATION_BUDGET
#: of which at most this many seconds go to pieces without a proven crossing (det A
#: proven ≠ 0 along them by the intervals already): the pieces holding the singular
#: times the verdict names come first
FREE_PIECES_BUDGET = 1.0


#: seconds of the trajectory's time limit kept for composing the pieces' reports when
#: the exact corroboration's budget is cut to fit in it
TIME_LIMIT_MARGIN = 1.0


def corroborate_pieces(reports: list[TrajectoryReport], budget: float | None = None,
                       free_budget: float | None = None) -> list[TrajectoryReport]:
    """The exact engine's corroboration of the pieces the interval engine decided
    (``exact_pending``), within one ``budget`` (default
    :data:`PATH_CORROBORATION_BUDGET`) for the whole path: the pieces with a proven
    crossing first (the singular times the verdict names), then the others in order,
    these within ``free_budget`` (default :data:`FREE_PIECES_BUDGET`) of it.  A piece
    left when the budget is spent keeps the interval engine's verdict, and its
    corroboration says so (``exact engine not run``, with how many pieces the exact
    engine did corroborate)."""
    budget = PATH_CORROBORATION_BUDGET if budget is None else budget
    free_budget = FREE_PIECES_BUDGET if free_budget is None else free_budget
    left = remaining()  # the trajectory's time limit: the interval verdicts must fit in it
    cut = left is not None and left - TIME_LIMIT_MARGIN < budget
    if cut:
        budget = max(0.0, left - TIME_LIMIT_MARGIN)
    pending = [i for i, r in enumerate(reports) if r.exact_pending is not None]
    crossing = [i for i in pending if reports[i].candidates]
    order = crossing + [i for i in pending if not reports[i].candidates]
    out = list(reports)
    start = time.monotonic()
    free_start = None
    done: list[int] = []
    for i in order:
        checkpoint()
        now = time.monotonic()
        left = budget - (now - start)
        if not reports[i].candidates:
            free_start = now if free_start is None else free_start
            left = min(left, free_budget - (now - free_start))
        if left <= 0:
            break
        report = corroborate_exactly(reports[i], left)
        if report is None:  # out of budget: this piece and those after it stay pending
            break
        out[i] = report
        done.append(i)
    if len(done) < len(pending):
        whole = (f"{budget:.3g} s: what the trajectory's time limit left" if cut else
                 f"{budget:g} s")
        why = (f"the exact engine's budget for the whole path ({whole}, of which "
               f"{free_budget:g} s for pieces without a proven crossing) ran out after "
               f"it corroborated {len(done)} of the {len(pending)} pieces the interval "
               "engine decided on its own")
        corroborated = set(done)
        for i in pending:
            if i not in corroborated:
                out[i] = corroborate_exactly(reports[i], 0, why)
    return out


def joins(spec: TrajectorySpec) -> list:
    """The exact times (in t) where one piece ends and the next starts."""
    return [p.global_range.end for p in spec.pieces[:-1]]


def _global_candidate(c: Candidate, piece: TrajectorySpec, segment: int) -> Candidate:
    root = RealRoot(piece.to_global(c.t), c.root.multiplicity)
    on_surface = None if c.on_surface is None else tuple(piece.to_global(t)
                                                         for t in c.on_surface)
    return Candidate(root, c.pose, c.joints, c.modes, c.status, segment, on_surface)


def _same_root_at_join(report: TrajectoryReport, left: Candidate, right: Candidate,
                       at) -> bool:
    """True when both candidates are the root of μ exactly at the join ``at``."""
    ball = at.ball()
    if not (left.t.overlaps(ball) and right.t.overlaps(ball)):
        return False
    piece = report.path.trajectory
    return sum_is_zero([(report.path.mu, piece.local_time(at))]) is True


def _branch_values(report: TrajectoryReport, at) -> list[dict]:
    """Per leg, its branches enclosed at the join ``at`` (from the pose's balls where the
    robot allows it: :meth:`~singcheck.certify.path.PathModel.leg_branches_at`, no leg
    composed along the piece — along a long spline, whose coefficients have thousands of
    digits, composing them cost more than certifying the piece)."""
    t = report.path.trajectory.local_time(at).ball()
    with working_precision(128):
        return report.path.leg_branches_at(t)


def _continuous(label: str, left: list[dict], right: list[dict]) -> bool:
    """False when the branches of ``label`` provably differ on the two sides."""
    for ch, a, b in zip(label, left, right, strict=True):
        va, vb = a[ch], b[ch]
        if isinstance(va, arb) and isinstance(vb, arb) and not va.overlaps(vb):
            return False
    return True


def _piece(i: int, count: int) -> str:
    """How a reason names the piece ``i`` (0-based): nothing for a path of one piece."""
    return f"segment {i + 1}: " if count > 1 else ""


def _compose_modes(spec, reports, ends=None) -> list[WorkingMode]:
    if ends is not None:
        at_joins = [(ends[i][1], ends[i + 1][0]) for i in range(len(reports) - 1)]
    else:
        at_joins = [(_branch_values(reports[i], j), _branch_values(reports[i + 1], j))
                    for i, j in enumerate(joins(spec))]
    out = []
    for k, first in enumerate(reports[0].modes):
        per_piece = [r.modes[k] for r in reports]
        status, reason = FEASIBLE, ""
        for state in (INFEASIBLE, UNKNOWN):
            hit = next(((i, m) for i, m in enumerate(per_piece) if m.status == state), None)
            if hit:
                status, reason = state, _piece(hit[0], len(reports)) + hit[1].reason
                break
        if status == FEASIBLE:
            for i, (left, right) in enumerate(at_joins):
                if not _continuous(first.label, left, right):
                    status = INFEASIBLE
                    reason = (f"its IK branch is not the same on both sides of the join of "
                              f"segments {i + 1} and {i + 2}")
                    break
        proof = "; ".join(_piece(i, len(reports)) + m.proof
                          for i, m in enumerate(per_piece) if m.proof)
        out.append(WorkingMode(first.label, first.branches, status, reason,
                               first.joints_at_start, proof=proof))
    return out


def _restatus(c: Candidate, feasible: set[str]) -> Candidate:
    """The candidate's status against the path's feasible modes (not the piece's)."""
    states = {m.status for m in c.modes if m.mode in feasible}
    c.status = "real" if SINGULAR in states else \
        "spurious" if states <= {REGULAR} else "unknown"
    c.joints = {label: v for label, v in c.joints.items() if label in feasible}
    return c


def compose(spec: TrajectorySpec, reports: list[TrajectoryReport],
            ends: list | None = None) -> TrajectoryReport:
    """The whole path's report from its pieces' reports (in order); ``ends``: each
    piece's leg branches at its start and end (:func:`_branch_values`), when known."""
    modes = _compose_modes(spec, reports, ends)
    feasible = {m.label for m in modes if m.status == FEASIBLE}
    candidates: list[Candidate] = []
    at = joins(spec)
    for i, (piece, report) in enumerate(zip(spec.pieces, reports, strict=True)):
        for c in report.candidates:
            g = _global_candidate(c, piece, i + 1)
            if (i and candidates and candidates[-1].segment == i and
                    _same_root_at_join(report, candidates[-1], g, at[i - 1])):
                continue  # the root at the join, already counted in the previous piece
            candidates.append(_restatus(g, feasible))
    for mode in modes:
        mode.singular_times = [c for c in candidates if mode.label in c.singular_modes]
    undecided = [(piece.to_global(t), _piece(i, len(reports)) + why)
                 for i, (piece, report) in enumerate(zip(spec.pieces, reports, strict=True))
                 for t, why in report.undecided]
    verdict, reason = verdict_of(modes, candidates, undecided)
    if verdict == VERDICT_INFEASIBLE:
        reason = _mode_change(spec, reports) or reason
    check = combined([r.corroboration for r in reports])
    verdict, reason = corroborated_verdict(verdict, reason, check)
    if verdict == VERDICT_FREE and check.status == EXACT_NOT_RUN:
        alone = sum(1 for r in reports if r.corroboration is not None
                    and r.corroboration.status == EXACT_NOT_RUN)
        reason += (f", by the interval engine alone on {alone} of the {len(reports)} "
                   f"segments ({check.detail})")
    methods = list(dict.fromkeys(r.root_method for r in reports))
    return TrajectoryReport(reports[0].path, verdict, reason, candidates, modes,
                            methods[0] if len(methods) == 1 else " + ".join(methods),
                            undecided, all(r.mu_roots_complete for r in reports), spec,
                            reports, check)


def _mode_change(spec, reports) -> str | None:
    """Where the feasible working mode changes, when every piece has one."""
    sets = [{m.label for m in r.modes if m.status == FEASIBLE} for r in reports]
    if not all(sets):
        return None
    common = sets[0]
    for i, s in enumerate(sets[1:]):
        if not common & s:
            return (f"no working mode is feasible along the whole path: the feasible mode "
                    f"changes at the join of segments {i + 1} and {i + 2} "
                    f"({spec.parameter} = {joins(spec)[i]}: {', '.join(sorted(common))} "
                    f"before, {', '.join(sorted(s))} after)")
        common &= s
    return None  # pragma: no cover - some mode is feasible throughout
