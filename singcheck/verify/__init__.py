"""Re-check singcheck certificates without a computer algebra system.

``python -m singcheck.verify CERT...`` (or ``singcheck verify CERT...``) exits 0 when every
claim of every certificate is proven, 1 with one line per failed or not re-checked step,
2 when a file cannot be read (not JSON, not a certificate, an odd spec inside).

This package imports only the standard library (no flint, sympy or mpmath, nothing else
of singcheck): read it to know what a certificate proves.  What it checks, from the
specs' texts alone (docs/certificate.md):

* the claim's working modes are all the robot's (every leg's branches), each proven
  feasible (on every piece of the cover: branches real, distinct, inside the limits) or
  infeasible (a witness time where a branch is complex or outside its limits);
* on every piece, det A along each feasible mode has the sign the proof names;
* the pieces left without a sign lie inside the claimed singular times, and each claimed
  singular time holds a sign change of det A (so a singular time, by continuity);
* the verdict is the one that follows.
"""

from __future__ import annotations

import json
import sys
from fractions import Fraction

from singcheck.verify.checker import NotRecheckable, Path, Robot, outside, piece_values, singular_at
from singcheck.verify.numbers import Iv, NotDecided
from singcheck.verify.reader import Refused

MAX_PIECES = 1_000_000
MAX_BYTES = 64 << 20
VERDICTS = ("singular", "singularity-free", "infeasible")


class Malformed(ValueError):
    """Not a certificate (exit 2)."""


def _q(text) -> Fraction:
    if not isinstance(text, str) or len(text) > 400:
        raise Malformed(f"not an exact rational: {str(text)[:40]!r}")
    try:
        num, _, den = text.partition("/")
        return Fraction(int(num), int(den or "1"))
    except (ValueError, ZeroDivisionError):
        raise Malformed(f"not an exact rational: {text[:40]!r}") from None


def _get(doc, key, kind):
    if not isinstance(doc, dict) or not isinstance(doc.get(key), kind):
        raise Malformed(f"{key}: missing or of the wrong type")
    return doc[key]


def check(cert: dict) -> tuple[list[str], str]:
    """(failed steps, one-line summary) of a certificate; [] when everything is proven."""
    if _get(cert, "format", str) != "singcheck-certificate" or cert.get("version") != 1:
        raise Malformed("not a singcheck certificate (format, version 1)")
    claim = _get(cert, "claim", dict)
    verdict = _get(claim, "verdict", str)
    if not isinstance(cert.get("proof"), dict):
        return [f"not re-checkable: {cert.get('not_recheckable') or 'no proof'}"], verdict
    proof = cert["proof"]
    try:
        robot = Robot(_get(claim, "robot_spec", str))
        path = Path(_get(claim, "trajectory_spec", str), robot)
    except NotRecheckable as e:
        return [f"not re-checkable: {e}"], verdict
    except Refused as e:
        raise Malformed(f"spec refused: {e}") from None
    fails: list[str] = []
    if _get(claim, "trajectory", str) != path.name:
        fails.append(f"the claim names trajectory {claim['trajectory']!r}, the spec "
                     f"{path.name!r}")
    modes = _get(claim, "modes", dict)
    if set(modes) != set(robot.modes) or not set(modes.values()) <= {"feasible",
                                                                      "infeasible"}:
        fails.append("the claim's working modes are not exactly the robot's "
                     f"({', '.join(robot.modes)}), each feasible or infeasible")
        return fails, verdict
    feasible = [m for m in robot.modes if modes[m] == "feasible"]
    cuts = [_q(c) for c in _get(proof, "cuts", list)]
    if len(cuts) >= MAX_PIECES:
        raise Malformed("too many pieces")
    ends = [path.start.hi] + [Iv.q(c).lo for c in cuts] + [path.end.lo]
    if any(ends[i] >= ends[i + 1] for i in range(len(cuts) + 1)):
        fails.append("the cuts are not increasing strictly inside the range")
        return fails, verdict
    n = len(cuts) + 1
    signs = _get(proof, "signs", dict)
    if set(signs) != set(feasible) or any(not isinstance(s, str) or len(s) != n or
                                          set(s) - set("+-0") for s in signs.values()):
        raise Malformed("signs: one string of +, -, 0 per piece for each feasible mode")
    bounds = [path.start.lo] + [Iv.q(c).lo for c in cuts], \
        [Iv.q(c).hi for c in cuts] + [path.end.hi]
    bad: dict[str, str] = {}
    for i in range(n):
        t = Iv(bounds[0][i], bounds[1][i])
        want = [m for m in feasible if m not in bad]
        try:
            legs, dets = piece_values(robot, path, t, [m for m in want if signs[m][i] != "0"])
        except NotDecided as e:
            bad.update({m: f"piece {i + 1}: {e}" for m in want})
            continue
        where = f"on piece {i + 1} (t ∈ [{float(t.lo) / 2**96:.9g}, {float(t.hi) / 2**96:.9g}])"
        for m in want:
            out = [robot.joints[k] for k, ch in enumerate(m) if not legs[k][ch][1]]
            if out:
                bad[m] = f"branch of {', '.join(out)} not proven real and inside the limits {where}"
            elif signs[m][i] != "0" and dets[m].sign() != (1 if signs[m][i] == "+" else -1):
                bad[m] = f"det A not proven {signs[m][i]} {where}"
    fails += [f"working mode {m}: {why}" for m, why in bad.items()]
    witnesses = _get(proof, "infeasible", dict)
    for m in robot.modes:
        if modes[m] != "infeasible":
            continue
        w = witnesses.get(m)
        try:
            t, leg = _q(_get(w, "t", str)), _get(w, "leg", int)
            ok = 0 <= leg < len(robot.joints) and path.start.hi <= Iv.q(t).lo and \
                Iv.q(t).hi <= path.end.lo and outside(robot, path, t, m, leg)
        except (Malformed, NotDecided):
            ok = False
        if not ok:
            fails.append(f"working mode {m}: not proven infeasible (no valid witness)")
    exact = _get(proof, "exact_roots", dict) if "exact_roots" in proof else {}
    fails += _singular_times(claim, feasible, signs, cuts, n, lambda m, a, b: any(
        a <= _q(t) <= b and path.start.hi <= Iv.q(_q(t)).lo and
        Iv.q(_q(t)).hi <= path.end.lo and _singular_at(robot, path, _q(t), m)
        for t in exact.get(m, [])), (path.start, path.end))
    derived = "infeasible" if not feasible else "singular" if any(
        claim.get("singular_times", {}).get(m) for m in feasible) else "singularity-free"
    if verdict != derived:
        fails.append(f"the claim's verdict {verdict!r} is not the one proven ({derived!r})")
    if claim.get("clearance") is not None:
        fails.append("not re-checked: the clearance bounds (no checker for them yet)")
    return fails, f"{path.name}: {derived} ({n} pieces, {len(feasible)} feasible mode(s))"


def _singular_at(robot, path, t: Fraction, mode: str) -> bool:
    try:
        return singular_at(robot, path, t, mode)
    except NotDecided:
        return False


def _singular_times(claim: dict, feasible: list[str], signs: dict, cuts: list, n: int,
                    root_in, ends: tuple[Iv, Iv]) -> list[str]:
    """The runs of '0' pieces inside the claimed singular times, each of which holds a
    sign change or an exact root (``root_in(mode, a, b)``, a root inside the range).  A
    run at a range end lies in a span that reaches past that end (``ends``); no sign
    change can be seen there, so its span needs an exact root (a path starting on the
    singularity)."""
    fails = []
    times = claim.get("singular_times", {})
    if not isinstance(times, dict) or set(times) - set(feasible):
        raise Malformed("singular_times: per feasible working mode")
    for m in feasible:
        spans = [(_q(a), _q(b)) for a, b in times.get(m, [])]
        if any(a >= b for a, b in spans) or any(spans[i][1] >= spans[i + 1][0]
                                                for i in range(len(spans) - 1)):
            fails.append(f"working mode {m}: singular times not disjoint increasing spans")
            continue
        crossing = [False] * len(spans)
        i, s = 0, signs[m]
        while i < n:
            if s[i] != "0":
                i += 1
                continue
            j = i
            while j + 1 < n and s[j + 1] == "0":
                j += 1
            lo, hi = (cuts[i - 1] if i > 0 else None), (cuts[j] if j < n - 1 else None)
            k = next((k for k, (a, b) in enumerate(spans) if (
                a <= lo if lo is not None else Iv.q(a).hi <= ends[0].lo) and (
                hi <= b if hi is not None else ends[1].hi <= Iv.q(b).lo)), None)
            if k is None:
                fails.append(f"working mode {m}: det A not proven ≠ 0 on pieces {i + 1} to "
                             f"{j + 1}, outside every claimed singular time")
            elif 0 < i and j < n - 1 and s[i - 1] != s[j + 1] and s[j + 1] != "0":
                crossing[k] = True
            i = j + 1
        for (a, b), ok in zip(spans, crossing, strict=False):
            if not ok and not root_in(m, a, b):
                fails.append(f"not re-checked: working mode {m} singular in t ∈ "
                             f"[{float(a):.12g}, {float(b):.12g}] (neither a sign change of "
                             "det A nor an exact rational root proven there)")
    return fails


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: python -m singcheck.verify CERT.json ... (exit 0: every claim "
              "proven; 1: a step failed or is not re-checked; 2: a file unreadable)")
        return 0 if argv else 2
    code = 0
    for name in argv:
        try:
            with open(name, "rb") as f:
                raw = f.read(MAX_BYTES + 1)
            if len(raw) > MAX_BYTES:
                raise Malformed("larger than 64 MiB")
            fails, summary = check(json.loads(raw.decode("utf-8")))
        except (OSError, ValueError, TypeError, ArithmeticError, RecursionError) as e:
            print(f"{name}: unreadable: {str(e).splitlines()[0] if str(e) else type(e).__name__}")
            code = 2
            continue
        for line in fails:
            print(f"{name}: {line}")
        if not fails:
            print(f"{name}: proven: {summary}")
        code = max(code, 1 if fails else 0)
    return code
