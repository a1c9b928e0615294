"""Two engines, one verdict: the exact engine's answer held against the interval engine's.

The exact engine (μ = ξ(φ(t)) by elimination, its certified real roots, each classified
per working mode: :mod:`.classification`) and the interval engine (det A enclosed along
each feasible mode's branches: :mod:`.interval_engine`) share no elimination step.  Every
verdict is checked against the second computation:

* a mode the exact engine found singular at a root τ (in its ball T) must not be proven
  ≠ 0 by the intervals on a piece containing T;
* a crossing the intervals prove (opposite signs around a window) must hold a singular
  time the exact engine found for that mode;
* a mode singular along the whole path (det A ≡ 0) must have no piece where the
  intervals prove det A ≠ 0;
* a ``singularity-free`` verdict needs the intervals to prove det A ≠ 0 along every
  feasible mode on the whole range: where they cannot (a window left after refining),
  the verdict is ``unknown``, naming the window and the proven bound |det A| ≤ ε there.

Any disagreement is the verdict ``error`` (``error.kind`` ``inconsistent``) with both
findings in the reason: never a silent answer.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from singcheck.certify.interval_engine import ModeSearch, search_det_a

CONFIRMED = "confirmed"  # the intervals prove the same answer on their own
CONSISTENT = "consistent"  # nothing the intervals proved contradicts it
INCOMPLETE = "incomplete"  # the intervals could not prove what the verdict needs
INCONSISTENT = "inconsistent"  # the two engines disagree: a bug in one of them
NOT_NEEDED = "not needed"  # no feasible mode: the verdict rests on no elimination
EXACT_NOT_RUN = "exact engine not run"  # the interval engine's verdict alone (and why)

VERDICT_ERROR = "error"


def corroborated_verdict(verdict: str, reason: str, corroboration: Corroboration
                         ) -> tuple[str, str]:
    """The verdict once the interval engine has been heard: ``error`` when the engines
    disagree, ``unknown`` for a free path the intervals could not confirm."""
    if corroboration.status == INCONSISTENT:
        return VERDICT_ERROR, ("the two engines disagree (exact engine: " + verdict + "; "
                               + corroboration.detail + ")")
    if corroboration.status == INCOMPLETE and verdict == "singularity-free":
        return "unknown", ("the exact engine proves every feasible mode free of parallel "
                           "singularities, but " + corroboration.detail)
    return verdict, reason


@dataclass
class Corroboration:
    """The interval engine's findings beside the exact engine's verdict."""

    status: str
    detail: str = ""
    searches: dict[str, ModeSearch] = field(default_factory=dict)

    def to_json(self) -> dict:
        return {
            "engine": "interval",
            "status": self.status,
            "detail": self.detail,
            "modes": {label: {"proven_pieces": len(s.proven),
                              "crossings": [[w.lo, w.hi] for w in s.crossings],
                              "windows": [{"t_interval": [w.lo, w.hi],
                                           "abs_det_A_at_most": w.bound,
                                           "crossing": w.crossing}
                                          for w in s.windows]}
                      for label, s in self.searches.items()},
        }


_ORDER = [NOT_NEEDED, CONFIRMED, CONSISTENT, EXACT_NOT_RUN, INCOMPLETE, INCONSISTENT]


def combined(parts: list[Corroboration | None]) -> Corroboration:
    """The corroboration of a path of pieces: the worst status of its pieces', with the
    details of the pieces that have it, each distinct detail once with the segments
    that have it (a 2000-piece path's says so in a line, not in 2000).

    >>> free = "ball arithmetic proves det A ≠ 0 along every feasible working mode"
    >>> parts = [Corroboration(CONFIRMED, free)] * 3 + [Corroboration(CONSISTENT, "x")]
    >>> combined(parts * 2).detail
    'segments 4, 8: x'
    >>> combined(parts[:3]).detail[:25]
    'segments 1–3: ball arithm'
    """
    parts = [p or Corroboration(NOT_NEEDED) for p in parts]
    worst = max((p.status for p in parts), key=_ORDER.index)
    if len(parts) == 1:
        return parts[0]
    by_detail: dict[str, list[int]] = {}
    for i, p in enumerate(parts, 1):
        if p.status == worst:
            by_detail.setdefault(p.detail, []).append(i)
    detail = "; ".join(f"{segment_list(numbers)}: {text}"
                       for text, numbers in by_detail.items())
    return Corroboration(worst, detail)


def segment_list(numbers: list[int]) -> str:
    """``segment 4`` or ``segments 1–3, 5`` (increasing numbers, runs as ranges)."""
    runs: list[list[int]] = []
    for n in numbers:
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    text = ", ".join(str(a) if a == b else f"{a}–{b}" for a, b in runs)
    return f"segments {text}" if len(numbers) > 1 else f"segment {text}"


def _window_text(label: str, w) -> str:
    return f"mode {label} on t ∈ [{w.lo:.9g}, {w.hi:.9g}] (|det A| ≤ {w.bound:.3g} there)"


def corroborate(path, modes, candidates, undecided, verdict: str, identically_zero: str,
                searches: dict | None = None) -> Corroboration:
    """The interval engine's check of one piece's verdict (see the module docstring).
    ``undecided``: the (t ball, reason) stretches the exact engine left open (a crossing
    there is no conflict: the verdict is already unknown); ``identically_zero``: the
    proof name of a mode singular along the whole piece; ``searches``: the interval
    engine's findings when it has run already (else it runs here)."""
    from singcheck.certify.working_modes import FEASIBLE

    feasible = [m for m in modes if m.status == FEASIBLE]
    if not feasible:
        return Corroboration(NOT_NEEDED, "no feasible working mode: nothing rests on μ")
    whole = {pm.mode for c in candidates for pm in c.modes
             if pm.proof == identically_zero}
    hints = {m.label: [c.t for c in candidates if m.label in c.singular_modes]
             for m in feasible}
    if searches is None or any(m.label not in searches for m in feasible) or (
            verdict == "singularity-free" and any(searches[m.label].windows for m in feasible)):
        # (a first pass on a budget that left windows on a free path: search again, whole)
        searches = search_det_a(path, feasible, refine={m.label for m in feasible} - whole,
                                hints=hints)
    conflicts, confirmed = [], []
    for mode in feasible:
        s = searches[mode.label]
        if mode.label in whole:
            if s.proven:
                lo, hi, _ = s.proven[0]
                conflicts.append(f"the exact engine finds det A ≡ 0 along mode {mode.label}, "
                                 f"but ball arithmetic proves det A ≠ 0 on t ∈ "
                                 f"[{lo:.9g}, {hi:.9g}]")
            continue
        singular = [c for c in candidates if mode.label in c.singular_modes]
        open_times = [c.t for c in candidates
                      if any(pm.mode == mode.label and pm.status == "unknown"
                             for pm in c.modes)] + [t for t, _ in undecided]
        for c in singular:
            if s.nonzero_on(c.t):
                conflicts.append(f"the exact engine finds mode {mode.label} singular at t ≈ "
                                 f"{float(c.t.mid()):.9g}, but ball arithmetic proves det A "
                                 "≠ 0 there")
        for w in s.crossings:
            if any(w.overlaps(t) for t in open_times) and \
                    not any(w.overlaps(c.t) for c in singular):
                continue  # the exact engine left it open: the verdict is unknown already
            if not any(w.overlaps(c.t) for c in singular):
                conflicts.append(f"ball arithmetic proves det A changes sign along mode "
                                 f"{mode.label} in t ∈ [{w.lo:.9g}, {w.hi:.9g}], where the "
                                 "exact engine finds no singular time")
            else:
                confirmed.append(mode.label)
    if conflicts:
        return Corroboration(INCONSISTENT, "; ".join(conflicts), searches)
    if verdict == "singularity-free":
        open_windows = [(m.label, w) for m in feasible for w in searches[m.label].windows]
        if open_windows:
            return Corroboration(INCOMPLETE, "the interval engine could not confirm det A ≠ 0 "
                                 "in " + "; ".join(_window_text(label, w)
                                                   for label, w in open_windows[:3])
                                 + (f" and {len(open_windows) - 3} more window(s)"
                                    if len(open_windows) > 3 else ""), searches)
        return Corroboration(CONFIRMED, "ball arithmetic proves det A ≠ 0 along every "
                             "feasible working mode on the whole range", searches)
    if verdict == "singular" and confirmed:
        return Corroboration(CONFIRMED, "ball arithmetic proves a sign change of det A "
                             f"along mode {confirmed[0]} at a singular time the exact engine "
                             "found", searches)
    return Corroboration(CONSISTENT, "nothing ball arithmetic proves contradicts the verdict",
                         searches)
