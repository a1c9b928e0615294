"""Paths as people have them: segments, waypoints, natural cubic splines, CSV tables.

Every form becomes a multi-piece :class:`~singcheck.spec.files.TrajectorySpec` whose
``segments`` are one-piece specs over consecutive sub-ranges of the global parameter:

* ``segments:`` — a list of ``{range: [a, b], pose: {...}}``, each pose anything a
  one-piece trajectory may be (polynomials, sin/cos of integer multiples of t, of
  rational multiples of π·t);
* ``waypoints:`` — a list of ``{t: .., x: .., ...}`` (exact numbers), joined by
  straight lines (``interpolation: linear``) or the natural cubic spline through them
  (``interpolation: cubic``, the default);
* a CSV table (``t,x,y,z`` header, one pose per row, decimals read exactly), interpolated
  the same way.

Everything is exact: spline coefficients are the rational solution of the spline's
tridiagonal system.  Consecutive segments must share their end and start times, and
the pose at the end of one must *equal* the pose at the start of the next, decided
exactly by :func:`singcheck.algebra.trig_values.sum_is_zero`; otherwise the spec is
refused with one line naming both segments.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

from flint import fmpq, fmpq_mpoly

from singcheck.algebra.intervals import working_precision
from singcheck.algebra.opaque import is_opaque
from singcheck.algebra.trig import TRIG, LinearInPi, T, TimeRange, evaluate_trig
from singcheck.algebra.trig_values import sum_is_zero
from singcheck.budget import checkpoint
from singcheck.errors import SpecError
from singcheck.spec.grammar import ExprError, _exact_number, _short
from singcheck.spec.plainyaml import kind
from singcheck.spec.trajectory import TrajectorySpec, pose_nodes, time_range, trajectory_piece

INTERPOLATIONS = ("linear", "cubic")


def _line(node) -> int:
    return node.start_mark.line + 1


MAX_WAYPOINTS = 5000
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE](?P<exponent>[+-]?\d+))?(?:/\d+)?\Z")


def multi_piece(doc, root, top, name: str, parameter: str, robot,
                lines: dict[str, int]) -> TrajectorySpec:
    """The ``segments:`` or ``waypoints:`` form of a trajectory document."""
    if "segments" in top and "waypoints" in top:
        raise doc.error(top["waypoints"][0], "waypoints",
                        "give either segments or waypoints, not both")
    if "interpolation" in top and "waypoints" not in top:
        raise doc.error(top["interpolation"][0], "interpolation",
                        "only applies to waypoints")
    form = "segments" if "segments" in top else "waypoints"
    for k in ("range", "pose"):
        if k in top:
            raise doc.error(top[k][0], k, f"not allowed with {form} (each piece has its own)")
    node = top[form][1]
    if form == "segments":
        pieces = _segments(doc, node, name, parameter, robot)
    else:
        kind = "cubic"
        if "interpolation" in top:
            kind = doc.text(top["interpolation"][1], "interpolation")
            if kind not in INTERPOLATIONS:
                raise doc.error(top["interpolation"][1], "interpolation",
                                f"{kind!r} is not one of {', '.join(INTERPOLATIONS)}")
        times, values, row_lines = _waypoints(doc, node, parameter, robot)
        pieces = interpolated_pieces(doc.path, name, parameter, times, values, kind,
                                     row_lines)
        lines = {**lines, "interpolation": kind}
    return _whole(doc.path, name, parameter, pieces, lines)


def _whole(path: str, name: str, parameter: str, pieces, lines) -> TrajectorySpec:
    rng = TimeRange(pieces[0].global_range.start, pieces[-1].global_range.end)
    return TrajectorySpec(path, name, parameter, rng, {}, lines, segments=tuple(pieces))


def _segments(doc, node, name: str, parameter: str, robot):
    if not kind(node) == "sequence" or not node.value:
        raise doc.error(node, "segments", "expected a non-empty list of "
                                          "{range: [a, b], pose: {...}}")
    pieces, nodes = [], []
    for i, item in enumerate(node.value):
        key = f"segments[{i + 1}]"
        m = doc.mapping(item, key)
        for k, (knode, _) in m.items():
            if k not in ("range", "pose"):
                raise doc.error(knode, f"{key}.{k}", "unknown key in a segment "
                                                     "(allowed: range, pose)")
        for k in ("range", "pose"):
            if k not in m:
                raise doc.error(item, f"{key}.{k}", "missing required key in a segment")
        rnode = m["range"][1]
        rng = time_range(doc, rnode, f"{key}.range")
        coords = pose_nodes(doc, m["pose"][1], f"{key}.pose", robot, m["pose"][0])
        rng, poly, scale, offsets = trajectory_piece(doc, rng, rnode, coords, f"{key}.pose",
                                                     parameter, robot)
        piece = TrajectorySpec(doc.path, f"{name}[{i + 1}]", parameter, rng, poly,
                               {"segment": _line(item)}, angle_offsets=offsets,
                               time_scale=scale)
        if pieces and pieces[-1].global_range.end != piece.global_range.start:
            raise doc.error(rnode, f"{key}.range",
                            f"segment {i + 1} starts at {piece.global_range.start} but "
                            f"segment {i} ends at {pieces[-1].global_range.end}: ranges "
                            "must be consecutive")
        pieces.append(piece)
        nodes.append(item)
    check_joins(pieces, doc.path, [_line(n) for n in nodes])
    return pieces


def check_joins(pieces, path: str, lines: list[int | None]) -> None:
    """Each segment must start exactly where the previous one ends (same pose)."""
    for i, (left, right) in enumerate(zip(pieces, pieces[1:], strict=False)):
        checkpoint()
        at = left.global_range.end
        for v in left.pose:
            where = f"segments {i + 1} and {i + 2} at {left.parameter} = {at}"
            if is_opaque(left.pose[v].context()) or is_opaque(right.pose[v].context()):
                _join_by_balls(left, right, v, at, where, path, lines[i + 1], i)
                continue
            if left.pose[v].context() is not TRIG or right.pose[v].context() is not TRIG:
                raise SpecError(f"cannot check exactly that {where} meet: square roots in "
                                "segments are not supported", path=path, line=lines[i + 1],
                                key=v)
            pi = LinearInPi(Fraction(0), Fraction(1))  # an angle's offset q·π is q·t at t = π
            offset = left.angle_offsets.get(v, 0) - right.angle_offsets.get(v, 0)
            same = sum_is_zero([(left.pose[v], left.local_time(at)),
                                (-right.pose[v], right.local_time(at)),
                                (T * _q(Fraction(offset)), pi)])
            if same is True:
                continue
            if same is None:
                raise SpecError(f"cannot check exactly that {where} meet (put joins at "
                                "rational times or rational multiples of pi)", path=path,
                                line=lines[i + 1], key=v)
            with working_precision(128):
                a = evaluate_trig(left.pose[v], left.local_time(at).ball())
                b = evaluate_trig(right.pose[v], right.local_time(at).ball())
            raise SpecError(f"the pose jumps between {where}: {v} is {float(a.mid()):.9g} "
                            f"at the end of segment {i + 1} and {float(b.mid()):.9g} at the "
                            f"start of segment {i + 2}", path=path, line=lines[i + 1], key=v)


def _join_by_balls(left, right, v: str, at, where: str, path: str, line, i: int) -> None:
    """A join where a side is kept as an expression tree (not algebraic): continuous when
    both sides' enclosures at the join are exact balls and equal (cos 0 = 1 is exact in
    Arb), a jump when they are disjoint; otherwise it cannot be decided, and is refused."""
    from flint import arb

    from singcheck.algebra.radicals import evaluate_path

    with working_precision(256):
        a, b = (evaluate_path(side.pose[v], side.local_time(at).ball()) +
                arb.pi() * _q(Fraction(side.angle_offsets.get(v, 0))) for side in (left, right))
    if a.is_exact() and b.is_exact() and a == b:
        return
    if not a.overlaps(b):
        raise SpecError(f"the pose jumps between {where}: {v} is {float(a.mid()):.9g} at the "
                        f"end of segment {i + 1} and {float(b.mid()):.9g} at the start of "
                        f"segment {i + 2}", path=path, line=line, key=v)
    raise SpecError(f"cannot check exactly that {where} meet: {v} is given there by an "
                    "expression that is not a trig polynomial over Q (end a segment where it "
                    "is exact, e.g. where the argument of its sin/cos is 0)", path=path,
                    line=line, key=v)


def _waypoints(doc, node, parameter: str, robot):
    if not kind(node) == "sequence":
        fields = ", ".join(f"{v}: .." for v in (parameter, *robot.pose))
        raise doc.error(node, "waypoints", f"expected a list of {{{fields}}}")
    names = (parameter, *robot.pose)
    times: list[Fraction] = []
    values: dict[str, list[Fraction]] = {v: [] for v in robot.pose}
    lines = []
    for i, item in enumerate(node.value):
        key = f"waypoints[{i + 1}]"
        m = doc.mapping(item, key)
        for k, (knode, _) in m.items():
            if k not in names:
                raise doc.error(knode, f"{key}.{k}", f"{k!r} is neither the parameter nor a "
                                                     f"pose variable ({', '.join(names)})")
        missing = [k for k in names if k not in m]
        if missing:
            raise doc.error(item, key, f"missing {', '.join(missing)}")
        times.append(doc.number(m[parameter][1], f"{key}.{parameter}"))
        for v in robot.pose:
            values[v].append(doc.number(m[v][1], f"{key}.{v}"))
        lines.append(_line(item))
    _check_table(doc.path, parameter, times, lines, getattr(node, "start_mark", None)
                 and _line(node))
    return times, values, lines


def _check_table(path: str, parameter: str, times, lines, where) -> None:
    if len(times) < 2:
        raise SpecError(f"at least two waypoints are needed, got {len(times)}", path=path,
                        line=lines[0] if lines else where)
    if len(times) > MAX_WAYPOINTS:
        raise SpecError(f"more than {MAX_WAYPOINTS} waypoints", path=path, line=lines[-1])
    for i in range(1, len(times)):
        if not times[i - 1] < times[i]:
            raise SpecError(f"{parameter} must increase from one waypoint to the next "
                            f"({times[i - 1]} then {times[i]})", path=path, line=lines[i])


@dataclass(frozen=True)
class CsvFormat:
    """How a CSV table of poses is read: its ``interpolation`` (linear or cubic), a column
    map ``columns`` ((variable, header) pairs: the pose variable, or the parameter, read
    from the column with that header; other columns are then ignored) and exact factors
    ``scale`` ((variable, factor) pairs: ``x`` in millimetres is scaled by 1/1000)."""

    interpolation: str = "cubic"
    columns: tuple[tuple[str, str], ...] = ()
    scale: tuple[tuple[str, Fraction], ...] = ()


def csv_name(path: str) -> str:
    """A CSV trajectory's name: its file's name without ``.csv``."""
    return re.sub(r"\.csv\Z", "", path.replace("\\", "/").rsplit("/", 1)[-1], flags=re.I)


def parse_csv(text: str, path: str, robot, interpolation: str | CsvFormat,
              trajectory_name: str | None = None) -> TrajectorySpec:
    """A CSV table of poses: header ``PARAMETER,POSE...`` then one exact row per waypoint;
    with a column map (:class:`CsvFormat`), the header names the columns the map picks
    and other columns are ignored.  ``trajectory_name``: default, the file's name."""
    table = interpolation if isinstance(interpolation, CsvFormat) else \
        CsvFormat(interpolation)
    text = text.removeprefix("\ufeff")  # a byte-order mark some spreadsheets write
    rows = [(n, line) for n, line in enumerate(text.splitlines(), 1)
            if line.strip() and not line.lstrip().startswith("#")]
    if not rows:
        raise SpecError("the file is empty", path=path, line=1)
    header_line, header = rows[0]
    names = [c.strip() for c in header.split(",")]
    picked = None
    if table.columns or table.scale:
        names, picked = _mapped(table, names, robot, path, header_line)
    parameter = names[0]
    if not re.fullmatch(r"[A-Za-z_][A-Za-z_0-9]*", parameter) or parameter in robot.pose:
        raise SpecError(f"the first column must name the parameter (e.g. t), not "
                        f"{parameter!r}", path=path, line=header_line)
    for v in names[1:]:
        if v not in robot.pose:
            raise SpecError(f"column {v!r} is not a pose variable of robot {robot.name} "
                            f"(pose: {', '.join(robot.pose)}; to pick and rename columns: "
                            f"--columns {robot.pose[0]}={v},...)", path=path,
                            line=header_line)
        if names.count(v) > 1:
            raise SpecError(f"column {v!r} appears twice", path=path, line=header_line)
    missing = [v for v in robot.pose if v not in names]
    if missing:
        raise SpecError(f"missing column(s) {', '.join(missing)} (header: "
                        f"{','.join(names)})", path=path, line=header_line)
    times: list[Fraction] = []
    values: dict[str, list[Fraction]] = {v: [] for v in robot.pose}
    lines = []
    factors = dict(table.scale)
    for n, line in rows[1:]:
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != (len(names) if picked is None else picked[1]):
            raise SpecError(f"{len(cells)} values for "
                            f"{len(names) if picked is None else picked[1]} columns",
                            path=path, line=n)
        if picked is not None:
            cells = [cells[i] for i in picked[0]]
        exact = []
        for name, cell in zip(names, cells, strict=True):
            number = _NUMBER.match(cell)
            if not number:
                raise SpecError(f"{name}: {cell!r} is not a number", path=path, line=n)
            try:
                exact.append(_cell_value(cell))
            except ExprError as e:
                raise SpecError(f"{name}: {e.message}", path=path, line=n) from None
            except ZeroDivisionError:
                raise SpecError(f"{name}: {_short(cell)!r} divides by zero", path=path,
                                line=n) from None
        exact = [value * factors.get(name, 1) for name, value in zip(names, exact,
                                                                      strict=True)]
        times.append(exact[0])
        for name, value in zip(names[1:], exact[1:], strict=True):
            values[name].append(value)
        lines.append(n)
    _check_table(path, parameter, times, lines, header_line)
    stem = trajectory_name or csv_name(path)
    pieces = interpolated_pieces(path, stem, parameter, times, values, table.interpolation,
                                 lines)
    return _whole(path, stem, parameter, pieces, {"interpolation": table.interpolation})


def _mapped(table: CsvFormat, header: list[str], robot, path: str, line: int):
    """The variables a column map reads, parameter first then the pose in the robot's
    order, and ((the column index of each), the number of columns in the header)."""
    columns = dict(table.columns)
    others = [v for v in columns if v not in robot.pose]
    if len(others) > 1:
        raise SpecError(f"the column map names {', '.join(others)}: only one of them, the "
                        f"parameter, may be other than a pose variable of robot "
                        f"{robot.name} (pose: {', '.join(robot.pose)})", path=path, line=line)
    parameter = others[0] if others else header[0]
    for v, _ in table.scale:
        if v != parameter and v not in robot.pose:
            raise SpecError(f"the scale names {v!r}, neither the parameter {parameter!r} "
                            f"nor a pose variable of robot {robot.name} (pose: "
                            f"{', '.join(robot.pose)})", path=path, line=line)
    variables = [parameter, *robot.pose]
    index = []
    for v in variables:
        column = columns.get(v, v if v != parameter or others else header[0])
        if column not in header:
            raise SpecError(f"no column {column!r} for {v} (header: {','.join(header)})",
                            path=path, line=line)
        if header.count(column) > 1:
            raise SpecError(f"column {column!r} appears twice", path=path, line=line)
        index.append(header.index(column))
    return variables, (index, len(header))


def _cell_value(cell: str) -> Fraction:
    """A CSV cell's exact value (a decimal, or a fraction of two), with the bounds of a
    number in a spec: each literal of at most MAX_LITERAL_BITS bits, refused before it
    is built (a 308-digit time once overflowed a float further on)."""
    sign = -1 if cell.startswith("-") else 1
    numerator, _, denominator = cell.lstrip("+-").partition("/")
    value = _exact_number(numerator, 1)
    return sign * (value / _exact_number(denominator, 1) if denominator else value)


def interpolated_pieces(path: str, name: str, parameter: str, times: list[Fraction],
                        values: dict[str, list[Fraction]], kind: str, lines: list[int]):
    """One polynomial piece per interval [tᵢ, tᵢ₊₁] between waypoints, written in the
    local time u = t − tᵢ ∈ [0, tᵢ₊₁ − tᵢ]."""
    if kind == "linear":
        per_coord = {v: linear_pieces(times, ys) for v, ys in values.items()}
    else:
        per_coord = natural_cubic_splines(times, values)
    pieces = []
    for i in range(len(times) - 1):
        rng = TimeRange(LinearInPi(Fraction(0)), LinearInPi(times[i + 1] - times[i]))
        pieces.append(TrajectorySpec(path, f"{name}[{i + 1}]", parameter, rng,
                                     {v: polys[i] for v, polys in per_coord.items()},
                                     {"segment": lines[i]}, time_offset=times[i]))
    _check_interpolates(per_coord, times, values, path, lines)
    return pieces


def _check_interpolates(per_coord: dict, times: list[Fraction], values: dict, path: str,
                        lines: list[int]) -> None:
    """Each piece takes its two waypoints' values at its ends, exactly (so consecutive
    pieces meet: the check :func:`check_joins` makes of any segments, here at the cost
    of two exact evaluations of a polynomial in u per piece and coordinate)."""
    zero = fmpq(0)
    for v, polys in per_coord.items():
        ys = values[v]
        for i, p in enumerate(polys):
            checkpoint()
            h = _q(times[i + 1] - times[i])
            for u, y, line in ((zero, ys[i], lines[i]), (h, ys[i + 1], lines[i + 1])):
                if p(u, zero, zero) != _q(y):  # pragma: no cover - by construction
                    raise SpecError(f"internal error: piece {i + 1} of {v} misses its "
                                    f"waypoint {v} = {y}", path=path, line=line, key=v)


def _q(x: Fraction) -> fmpq:
    return fmpq(x.numerator, x.denominator)


def linear_pieces(ts: list[Fraction], ys: list[Fraction]) -> list[fmpq_mpoly]:
    """The straight line from each waypoint to the next, in u = t − tᵢ."""
    one = TRIG.from_dict({(0, 0, 0): 1})
    return [one * _q(y0) + T * _q((y1 - y0) / (t1 - t0))
            for t0, t1, y0, y1 in zip(ts, ts[1:], ys, ys[1:], strict=False)]


def natural_cubic_splines(ts: list[Fraction], values: dict[str, list[Fraction]]
                          ) -> dict[str, list[fmpq_mpoly]]:
    """:func:`natural_cubic_spline` of each coordinate through the same times: the
    elimination's pivots depend on the times alone, so they are computed once (the
    costly part over thousands of waypoints: exact rationals growing with the rows); a
    coordinate constant along the path is that constant, piece by piece (its spline)."""
    n = len(ts) - 1
    t = [_q(x) for x in ts]
    h = [t[i + 1] - t[i] for i in range(n)]
    pivots = _pivots(h)
    out = {}
    for v, ys in values.items():
        if all(y == ys[0] for y in ys):
            const = TRIG.from_dict({(0, 0, 0): _q(ys[0])})
            out[v] = [const] * n
        else:
            out[v] = _spline_pieces(h, [_q(y) for y in ys], pivots)
    return out


def _pivots(h: list[fmpq]) -> tuple[list[fmpq], list[fmpq]]:
    """The pivots dᵢ of Thomas' elimination on the spline's tridiagonal system, and the
    multipliers wᵢ = hᵢ₋₁/dᵢ₋₁ of its right-hand side."""
    diag: list[fmpq] = []
    factors: list[fmpq] = []
    for i in range(1, len(h)):
        checkpoint()
        d = 2 * (h[i - 1] + h[i])
        if diag:
            w = h[i - 1] / diag[-1]
            d -= w * h[i - 1]
            factors.append(w)
        diag.append(d)
    return diag, factors


def _spline_pieces(h: list[fmpq], y: list[fmpq], pivots: tuple) -> list[fmpq_mpoly]:
    """The spline's pieces in u = t − tᵢ given its pivots (:func:`_pivots`)."""
    diag, factors = pivots
    n = len(h)
    slope = [(y[i + 1] - y[i]) / h[i] for i in range(n)]
    m = [fmpq(0)] * (n + 1)
    rhs: list[fmpq] = []
    for i in range(1, n):
        checkpoint()
        r = 6 * (slope[i] - slope[i - 1])
        if rhs:
            r -= factors[i - 2] * rhs[-1]
        rhs.append(r)
    for i in range(n - 1, 0, -1):
        checkpoint()  # the exact Mᵢ grow with the rows: each step costs more
        m[i] = (rhs[i - 1] - h[i] * m[i + 1]) / diag[i - 1]
    out = []
    for i in range(n):
        checkpoint()
        # S = yᵢ + (Δᵢ − h(2Mᵢ + Mᵢ₊₁)/6)u + Mᵢu²/2 + (Mᵢ₊₁ − Mᵢ)u³/6h: the expanded
        # form of natural_cubic_spline's, written term by term (no products of
        # polynomials with thousand-digit coefficients)
        terms = {(0, 0, 0): y[i], (1, 0, 0): slope[i] - h[i] * (2 * m[i] + m[i + 1]) / 6,
                 (2, 0, 0): m[i] / 2, (3, 0, 0): (m[i + 1] - m[i]) / (6 * h[i])}
        out.append(TRIG.from_dict({e: c for e, c in terms.items() if c != 0}))
    return out


def natural_cubic_spline(ts: list[Fraction], ys: list[Fraction]) -> list[fmpq_mpoly]:
    """The natural cubic spline through the points, exactly, each piece in u = t − tᵢ: its
    second derivatives Mᵢ solve hᵢ₋₁Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ)Mᵢ + hᵢMᵢ₊₁ = 6(Δᵢ − Δᵢ₋₁),
    M₀ = Mₙ = 0 (Thomas' algorithm over Q), and on [tᵢ, tᵢ₊₁], with h = tᵢ₊₁ − tᵢ,
    S = Mᵢ(h − u)³/6h + Mᵢ₊₁u³/6h + (yᵢ/h − Mᵢh/6)(h − u) + (yᵢ₊₁/h − Mᵢ₊₁h/6)u."""
    n = len(ts) - 1
    t = [_q(x) for x in ts]
    y = [_q(v) for v in ys]
    h = [t[i + 1] - t[i] for i in range(n)]
    slope = [(y[i + 1] - y[i]) / h[i] for i in range(n)]
    m = [fmpq(0)] * (n + 1)
    if n > 1:  # interior unknowns M₁ … Mₙ₋₁
        diag, rhs = [], []
        for i in range(1, n):
            checkpoint()
            d = 2 * (h[i - 1] + h[i])
            r = 6 * (slope[i] - slope[i - 1])
            if diag:
                w = h[i - 1] / diag[-1]
                d -= w * h[i - 1]
                r -= w * rhs[-1]
            diag.append(d)
            rhs.append(r)
        for i in range(n - 1, 0, -1):
            checkpoint()  # the exact Mᵢ grow with the rows: each step costs more
            m[i] = (rhs[i - 1] - h[i] * m[i + 1]) / diag[i - 1]
    one = TRIG.from_dict({(0, 0, 0): 1})
    out = []
    for i in range(n):
        checkpoint()
        a, b = one * h[i] - T, T
        out.append(a ** 3 * (m[i] / (6 * h[i])) + b ** 3 * (m[i + 1] / (6 * h[i]))
                   + a * (y[i] / h[i] - m[i] * h[i] / 6)
                   + b * (y[i + 1] / h[i] - m[i + 1] * h[i] / 6))
    return out
