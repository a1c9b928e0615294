"""Certificates anyone can re-check without a CAS (docs/certificate.md).

A certificate holds a **claim** — the robot's and the trajectory's spec texts as read,
the verdict, every working mode with its status, per feasible mode the enclosures of its
singular times (and ``clearance`` when one was computed) — and a **proof**: a cover of the
range by rational cut points, per feasible mode the sign of det A on each piece ('0' on
the pieces inside a claimed singular time), and per infeasible mode a witness time and
leg.  :mod:`singcheck.verify`, which imports nothing of singcheck's engines, recomputes
every enclosure from the texts and accepts or refuses it.

The claim is singcheck's verdict (both engines, :mod:`.engines`); the cover is found by
branch-and-bound in the checker's own rational interval arithmetic, starting from a
uniform grid and the claimed singular times, so that every piece it emits is one the
checker can decide.  A claim it cannot support (a tangency, a mode singular along a
stretch, a constant like sqrt(3), a spline) is written with ``proof: null`` and the
reason in ``not_recheckable``: the checker then fails it, never passes it.
"""

from __future__ import annotations

import json
import os
from fractions import Fraction
from pathlib import Path

from singcheck.roots.rational import simplest_between
from singcheck.verify.checker import NotRecheckable, Robot, outside, piece_values, singular_at
from singcheck.verify.checker import Path as PathSpec
from singcheck.verify.numbers import ONE, Iv, NotDecided
from singcheck.verify.reader import Refused

#: pieces of the first, uniform cover
GRID = 32
#: the deepest halving of a piece of the grid
MAX_DEPTH = 60
#: piece evaluations per certificate at most
BUDGET = 200_000
VERDICTS = ("singular", "singularity-free", "infeasible")


def _text(q: Fraction) -> str:
    return str(q.numerator) if q.denominator == 1 else f"{q.numerator}/{q.denominator}"


def _claim(robot_text: str, trajectory_text: str, result: dict) -> dict:
    claim = {"trajectory": result["name"], "verdict": result["verdict"],
             "robot_spec": robot_text, "trajectory_spec": trajectory_text,
             "modes": {m["label"]: m["status"] for m in result.get("working_modes", [])},
             "singular_times": {}}
    if result.get("clearance") is not None:
        claim["clearance"] = result["clearance"]
    return claim


def _spans(result: dict, feasible: list[str]) -> dict[str, list[tuple[Fraction, Fraction]]]:
    """Per feasible mode, the singular times' enclosures (the report's, widened by their
    width so that float rounding of the ends cannot leave the root out), merged."""
    spans: dict[str, list] = {m: [] for m in feasible}
    for c in result.get("candidates", []):
        for pm in c.get("modes", []):
            if pm["status"] != "singular" or pm["mode"] not in spans:
                continue
            if c.get("on_surface") or c.get("t_interval") is None:
                raise NotRecheckable(f"working mode {pm['mode']} is singular along a "
                                     "stretch of the path (det A ≡ 0 there)")
            lo, hi = (Fraction(x) for x in c["t_interval"])
            pad = max(hi - lo, Fraction(1, 2 ** 40))
            spans[pm["mode"]].append((lo - pad, hi + pad))
    for m, found in spans.items():
        merged: list = []
        for a, b in sorted(found):
            if merged and a <= merged[-1][1]:
                merged[-1] = (merged[-1][0], max(merged[-1][1], b))
            else:
                merged.append((a, b))
        spans[m] = merged
    return spans


def _dyadic(x: int, width: int) -> Fraction:
    """A short dyadic rational near x/2^P, to a small fraction of ``width``."""
    bits = max(8, (ONE // max(width, 1)).bit_length() + 8)
    return Fraction(round(Fraction(x, ONE) * 2 ** bits), 2 ** bits)


class _Prover:
    def __init__(self, robot: Robot, path: PathSpec, feasible: list[str], spans: dict):
        self.robot, self.path, self.feasible, self.spans = robot, path, feasible, spans
        self.cuts: list[Fraction] = []
        self.signs: dict[str, list[str]] = {m: [] for m in feasible}
        self.left = BUDGET
        self.undecided = 0

    def _inside(self, m: str, lo, hi) -> bool:
        """Whether the piece [lo, hi] lies in a claimed singular time of ``m`` (a piece at
        a range end, in one reaching past that end: the checker's rule)."""
        return any((a <= lo if lo is not None else Iv.q(a).hi <= self.path.start.lo) and
                   (hi <= b if hi is not None else self.path.end.hi <= Iv.q(b).lo)
                   for a, b in self.spans[m])

    def piece(self, lo: Fraction | None, hi: Fraction | None, depth: int) -> None:
        """Prove the piece [lo, hi] (None: the range's end) or halve it."""
        t = Iv(self.path.start.lo if lo is None else Iv.q(lo).lo,
               self.path.end.hi if hi is None else Iv.q(hi).hi)
        want = [m for m in self.feasible if not self._inside(m, lo, hi)]
        self.left -= 1
        try:
            legs, dets = piece_values(self.robot, self.path, t, want)
            out = {m: "0" if m not in want else "+" if dets[m].sign() > 0 else
                   "-" if dets[m].sign() < 0 else "?" for m in self.feasible}
            real = all(legs[k][ch][1] for m in self.feasible for k, ch in enumerate(m))
        except NotDecided:
            out, real = {m: "?" for m in self.feasible}, False
        if (not real or "?" in out.values()) and depth < MAX_DEPTH and self.left > 0:
            mid = _dyadic((t.lo + t.hi) // 2, t.hi - t.lo)
            if (lo is None or lo < mid) and (hi is None or mid < hi) and \
                    self.path.start.hi < Iv.q(mid).lo and Iv.q(mid).hi < self.path.end.lo:
                self.piece(lo, mid, depth + 1)
                self.piece(mid, hi, depth + 1)
                return
        self.undecided += (not real) or "?" in out.values()
        if hi is not None:
            self.cuts.append(hi)
        for m in self.feasible:
            self.signs[m].append(out[m].replace("?", "0"))


def _exact_roots(robot: Robot, path: PathSpec, spans: dict) -> dict[str, list[str]]:
    """Per mode, the simplest rational of each singular time where det A = 0 exactly
    (a root the checker proves without a sign change: a tangency at t = 0, say)."""
    out: dict[str, list[str]] = {}
    ends = [Fraction(e.lo, ONE) for e in (path.start, path.end) if e.lo == e.hi]
    for m, found in spans.items():
        for a, b in found:
            for t in [simplest_between(a, b)] + [e for e in ends if a <= e <= b]:
                try:
                    if path.start.hi <= Iv.q(t).lo and Iv.q(t).hi <= path.end.lo and \
                            singular_at(robot, path, t, m):
                        out.setdefault(m, []).append(_text(t))
                        break
                except NotDecided:
                    pass
    return out


def _witness(robot: Robot, path: PathSpec, mode: str, times: list[Fraction]) -> dict | None:
    for t in times:
        for leg in range(len(robot.joints)):
            try:
                if outside(robot, path, t, mode, leg):
                    return {"t": _text(t), "leg": leg}
            except NotDecided:
                pass
    return None


def _read(what: str, kind, *args):
    try:
        return kind(*args)
    except Refused as e:
        raise Refused(f"the {what}, as the checker reads it: {e}") from None


def build_certificate(robot_text: str, trajectory_text: str, result: dict) -> dict:
    """The certificate of one trajectory's ``result`` (a trajectory object of the JSON
    report) on the robot and trajectory read from those texts."""
    cert = {"format": "singcheck-certificate", "version": 1,
            "claim": _claim(robot_text, trajectory_text, result), "proof": None}
    try:
        if result["verdict"] not in VERDICTS:
            raise NotRecheckable(f"the verdict is {result['verdict']}: nothing is claimed")
        modes = cert["claim"]["modes"]
        if any(s not in ("feasible", "infeasible") for s in modes.values()):
            raise NotRecheckable("the feasibility of a working mode is unknown")
        if str(result.get("path", "")).lower().endswith(".csv"):
            raise NotRecheckable("CSV tables of poses are not re-checked yet")
        robot = _read("robot spec", Robot, robot_text)
        path = _read("trajectory spec", PathSpec, trajectory_text, robot)
        feasible = [m for m in robot.modes if modes.get(m) == "feasible"]
        spans = _spans(result, feasible)
    except (NotRecheckable, Refused, NotDecided) as e:
        cert["not_recheckable"] = str(e)
        return cert
    cert["claim"]["singular_times"] = {
        m: [[_text(a), _text(b)] for a, b in s] for m, s in spans.items() if s}
    prover = _Prover(robot, path, feasible, spans)
    lo, hi = path.start.hi, path.end.lo
    points = {_dyadic(lo + (hi - lo) * k // GRID, (hi - lo) // GRID) for k in range(1, GRID)}
    points |= {x for s in spans.values() for span in s for x in span
               if lo < Iv.q(x).lo and Iv.q(x).hi < hi}
    points |= set(path.joins)  # a piece lies in one segment
    ends: list = [None, *sorted(points), None]
    for a, b in zip(ends, ends[1:], strict=False):
        prover.piece(a, b, 0)
    span_all = sorted({x for s in spans.values() for x in s}, reverse=True)
    samples = [c for c in prover.cuts if not any(a <= c <= b for a, b in span_all)]
    cert["proof"] = {
        "cuts": [_text(c) for c in prover.cuts],
        "signs": {m: "".join(s) for m, s in prover.signs.items()},
        "exact_roots": _exact_roots(robot, path, spans),
        "infeasible": {m: _witness(robot, path, m, samples[:: max(1, len(samples) // 200)])
                       for m in robot.modes if modes.get(m) == "infeasible"},
    }
    if prover.undecided:
        cert["incomplete"] = (f"{prover.undecided} piece(s) left undecided by the prover: "
                              "the checker will refuse this certificate")
    return cert


def write_certificate(directory: str | os.PathLike, cert: dict, used: set[str]) -> Path:
    """``DIRECTORY/<trajectory name>.cert.json`` (its name made safe and unique among
    ``used`` by :func:`~singcheck.atomic.safe_file_name`, the one helper for every file
    name made from input), written atomically."""
    from singcheck.atomic import safe_file_name, write_atomically

    name = safe_file_name(cert["claim"]["trajectory"], used)
    target = Path(directory) / f"{name}.cert.json"
    write_atomically(target, json.dumps(cert, ensure_ascii=False, separators=(",", ":"))
                     + "\n", make_parents=True)
    return target
