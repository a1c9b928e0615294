"""The robot's own working mode, and how close the considered modes come to a singularity.

A robot runs in one working mode.  The certification looks at every mode (the
elimination proof of a singular time needs the others proven regular), then
:func:`restrict` turns its report into the report about one mode: that mode's
feasibility, its candidates (each ``real`` where the mode is proven singular, ``spurious``
where it is proven regular), the stretches left undecided for it, and the verdict from
those alone; a disagreement of the two engines stays the verdict ``error``.

The mode is named by its label (``--mode +-``, ``mode:`` in a trajectory document) or
found from the joints at the start of the path (:func:`mode_at_start`): the mode whose
joints there are proven within :data:`START_TOLERANCE` of the given values, all others
proven farther.

:func:`clearances` gives each considered mode's certified minimum of κ
(:mod:`.clearance`); :func:`gate` turns a singularity-free verdict into
``near-singular`` where a minimum is proven below a threshold.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import product

from flint import arb

from singcheck.certify.classification import (
    REGULAR,
    SINGULAR,
    VERDICT_FREE,
    TrajectoryReport,
    verdict_of,
)
from singcheck.certify.clearance import Clearance, minimum_clearance, singular_clearance
from singcheck.certify.engines import EXACT_NOT_RUN
from singcheck.certify.working_modes import FEASIBLE, start_branches
from singcheck.errors import SpecError
from singcheck.model.robot import REVOLUTE

#: --start-joints picks the mode whose joints at the start are within this of the values
#: given (for a revolute joint: the distance of (cos θ, sin θ) to (cos v, sin v), which is
#: 2·sin(|θ - v|/2), about |θ - v| radians)
START_TOLERANCE = 1e-6
VERDICT_NEAR = "near-singular"


def leg_labels(model) -> list[tuple[str, ...]]:
    """Per leg, its branch labels: ``+``, ``-`` (quadratic or revolute) or ``o``."""
    return [("+", "-") if leg.kind == REVOLUTE or leg.degree == 2 else ("o",)
            for leg in model.legs]


def mode_labels(model) -> list[str]:
    """Every working mode's label, in the report's order."""
    return ["".join(choice) for choice in product(*leg_labels(model))]


def check_label(model, label: str, path: str | None = None, key: str | None = None) -> None:
    """Raise :class:`SpecError` (one line, listing the labels) for a label the robot does
    not have (``path``, ``key``: where the label was written)."""
    labels = mode_labels(model)
    if label not in labels:
        raise SpecError(f"unknown working mode {label!r}: {model.name} has the modes "
                        f"{', '.join(labels)} (one character per leg: + and - the two "
                        "branches, o the only branch of a linear leg)", path=path, key=key)


def _value_ball(value) -> arb:
    """An exact ``a + b·π`` (:class:`~singcheck.algebra.trig.LinearInPi`) as a ball."""
    return value.ball()


def _matches(leg, branch, value: arb, tolerance: float) -> bool | None:
    """Proven within ``tolerance`` (True), proven farther (False), or not decided."""
    if branch is None:
        return None
    if leg.kind == REVOLUTE:
        if not isinstance(branch, tuple) or not all(isinstance(b, arb) for b in branch):
            return False  # not real there
        square = (branch[0] - value.cos()) ** 2 + (branch[1] - value.sin()) ** 2
    else:
        if not isinstance(branch, arb):
            return False
        square = (branch - value) ** 2
    bound = arb(tolerance) ** 2  # compared squared: no square root of a ball around 0
    if square < bound:
        return True
    if square > bound:
        return False
    return None


def mode_at_start(report: TrajectoryReport, values: dict, tolerance: float = START_TOLERANCE
                  ) -> str:
    """The label of the one mode whose joints at the path's start match ``values`` (joint
    name → exact value); :class:`SpecError` when none or several may."""
    first = report.pieces[0] if report.pieces else report
    path = first.path
    model = path.projection.model
    names = [leg.joint for leg in model.legs]
    for name in values:
        if name not in names:
            raise SpecError(f"{name!r} is not a joint of {model.name} "
                            f"(joints: {', '.join(names)})")
    starts = start_branches(path)
    sure, maybe = [], []
    for choice in product(*leg_labels(model)):
        label = "".join(choice)
        verdicts = [_matches(model.legs[i], starts[i].get(choice[i]),
                             _value_ball(values[name]), tolerance)
                    for i, name in enumerate(names) if name in values]
        if False in verdicts:
            continue
        maybe.append(label)
        if all(v is True for v in verdicts):
            sure.append(label)
    given = ", ".join(f"{k} = {float(_value_ball(v).mid()):.9g}" for k, v in values.items())
    if len(maybe) == 1 and sure:
        return sure[0]
    if not maybe:
        shown = "; ".join(f"{m.label}: " + ", ".join(
            f"{k} ≈ {m.joints_at_start.get(k, float('nan')):.9g}" for k in values)
            for m in first.modes)
        raise SpecError(f"no working mode has {given} at the start of {report.name} "
                        f"(within {tolerance:g}); at the start: {shown}",
                        path=report.trajectory.path, key="--start-joints")
    raise SpecError(f"{given} at the start of {report.name} matches several working "
                    f"modes ({', '.join(maybe)}, within {tolerance:g}): give the other "
                    "joints too, or --mode", path=report.trajectory.path, key="--start-joints")


def restrict(report: TrajectoryReport, label: str) -> TrajectoryReport:
    """The report about the working mode ``label`` alone (see the module docstring)."""
    modes = [m for m in report.modes if m.label == label]
    if not modes:
        check_label(report.path.projection.model, label)
    mode = modes[0]
    candidates = []
    for c in report.candidates:
        own = [pm for pm in c.modes if pm.mode == label]
        if not own:
            continue  # a candidate about another mode only (its own zeros, a window)
        status = {SINGULAR: "real", REGULAR: "spurious"}.get(own[0].status, "unknown")
        candidates.append(replace(c, modes=own, status=status,
                                  joints={k: v for k, v in c.joints.items() if k == label}))
    mode = replace(mode, singular_times=[c for c in candidates if label in c.singular_modes])
    undecided = _undecided_for(report, label)
    verdict, reason = verdict_of([mode], candidates, undecided)
    if report.verdict == "error":  # the engines disagree: that stays the answer
        verdict, reason = report.verdict, report.reason
    elif verdict == VERDICT_FREE:
        windows = _open_windows(report, label)
        if windows:
            verdict, reason = "unknown", (f"the exact engine proves working mode {label} "
                                          "free of parallel singularities, but the interval "
                                          f"engine could not confirm det A ≠ 0 in {windows}")
        else:
            reason = f"working mode {label} is proven free of parallel singularities"
    return replace(report, verdict=verdict, reason=reason, candidates=candidates,
                   modes=[mode], undecided=undecided)


def _undecided_for(report: TrajectoryReport, label: str) -> list:
    """The stretches root isolation left open that still matter for the mode: on a path
    of one piece, those where its det A is not proven ≠ 0; a window of the interval
    engine alone only when it is about this mode."""
    from singcheck.certify.interval_engine import mode_values

    out = []
    single = not report.pieces
    own = [m for m in report.modes if m.label == label]
    for t, why in report.undecided:
        if " along mode " in why and f" along mode {label} " not in why:
            continue
        if single and own and own[0].status == FEASIBLE:
            _, _, values = mode_values(report.path, own, t)
            v = values[label]
            if isinstance(v, arb) and not v.contains(0):
                continue
        out.append((t, why))
    return out


def _open_windows(report: TrajectoryReport, label: str) -> str:
    """Where the interval engine left det A along the mode not proven ≠ 0 ('' if
    nowhere)."""
    parts = []
    for i, piece in enumerate(report.pieces or [report], 1):
        check = piece.corroboration
        if check is None or check.status == EXACT_NOT_RUN:
            continue
        search = check.searches.get(label)
        for w in (search.windows if search else []):
            where = f"segment {i}: " if report.pieces else ""
            parts.append(f"{where}t ∈ [{w.lo:.9g}, {w.hi:.9g}] (|det A| ≤ {w.bound:.3g})")
    return "; ".join(parts[:3]) + (f" and {len(parts) - 3} more" if len(parts) > 3 else "")


def considered(report: TrajectoryReport) -> list[str]:
    """The labels of the modes the verdict is about and that are feasible."""
    return [m.label for m in report.modes if m.status == FEASIBLE]


def clearances(report: TrajectoryReport, length=1, rel_tol: float | None = None
               ) -> dict[str, Clearance]:
    """Each considered feasible mode's certified minimum of κ over the whole path (its
    pieces' minima combined; 0 exactly for a mode proven singular somewhere)."""
    from singcheck.certify.clearance import REL_TOL, wanted_gap

    rel = REL_TOL if rel_tol is None else rel_tol
    out: dict[str, Clearance] = {}
    for mode in report.modes:
        if mode.status != FEASIBLE:
            continue
        if mode.singular_times:
            c = mode.singular_times[0]
            out[mode.label] = singular_clearance(mode.label, float(c.t.mid()))
            continue
        parts = []
        for piece in report.pieces or [report]:
            own = next(m for m in piece.modes if m.label == mode.label)
            parts.append(minimum_clearance(piece.path, own, length, rel))
        lo = min(p.lo for p in parts)
        best = min(parts, key=lambda p: p.hi)
        met = best.hi - lo <= wanted_gap(best.hi, rel)
        out[mode.label] = replace(best, lo=lo, met=met,
                                  evaluations=sum(p.evaluations for p in parts))
    return out


def gate(report: TrajectoryReport, found: dict[str, Clearance], threshold: float
         ) -> tuple[str, str]:
    """The verdict once the clearance threshold is applied: a singularity-free path whose
    certified minimum in a considered mode is below ``threshold`` is ``near-singular``
    (the time and value named); one that cannot be placed against it is ``unknown``."""
    if report.verdict != VERDICT_FREE:
        return report.verdict, report.reason
    below = [c for c in found.values() if c.hi < threshold]
    if below:
        c = min(below, key=lambda c: c.hi)
        return VERDICT_NEAR, (f"working mode {c.mode} stays nonsingular but its clearance κ "
                              f"falls to {c.estimate:.6g} (≤ {c.hi:.6g}, proven) at t ≈ "
                              f"{c.t:.6g}, below --min-clearance {threshold:g}")
    open_ = [c for c in found.values() if c.lo < threshold]
    if open_:
        c = open_[0]
        return "unknown", (f"every considered mode is free of parallel singularities, but "
                           f"whether the clearance of mode {c.mode} falls below "
                           f"{threshold:g} is not decided (κ_min ∈ [{c.lo:.9g}, "
                           f"{c.hi:.9g}])")
    return report.verdict, report.reason + (f"; its clearance stays at or above {threshold:g}")
