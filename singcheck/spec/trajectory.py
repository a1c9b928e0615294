"""A trajectory spec, one piece or many, and the parsing of one piece.

A piece is a pose φ(t) over a closed range, exact (trig polynomials in ``TRIG``).  A
piece whose sin/cos arguments are rational multiples of π·t is rescaled to τ = g·π·t
(g the gcd of those multiples), under which they are integer multiples of τ: its pose
and range are stored in τ, and :meth:`TrajectorySpec.to_global` maps times back to t.
The parsing helpers take the file's located-error helper (``doc``) and the robot spec.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import restrict
from singcheck.algebra.radicals import radical_name, radical_variables
from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange
from singcheck.spec.grammar import (
    Constant,
    ExprError,
    Node,
    compile_angle_coordinate,
    compile_constant,
    compile_trajectory_coordinate,
    compile_value,
    pi_multiples,
    polynomial_angle,
    polynomial_angles,
)
from singcheck.spec.plainyaml import kind


@dataclass(frozen=True)
class TrajectorySpec:
    path: str
    name: str
    parameter: str
    range: TimeRange
    pose: dict[str, fmpq_mpoly]  # pose variable -> TRIG polynomial, robot's pose order
    lines: dict[str, int] = field(default_factory=dict)
    #: an angle's coordinate is pose[v] + angle_offsets[v]·π (only angles have an entry)
    angle_offsets: dict[str, Fraction] = field(default_factory=dict)
    #: g when the pose is written in τ = g·π·t (sin/cos of k·π·t): ``pose`` and ``range``
    #: are then in τ, and :meth:`to_global` maps a time back to t.
    time_scale: Fraction | None = None
    #: the pieces of a multi-piece path (segments, waypoints, CSV), each a one-piece spec
    #: over its own global sub-range; ``range`` is then the whole path's and ``pose`` empty.
    segments: tuple[TrajectorySpec, ...] = ()
    #: t₀ when the pose is written in the local time u = t − t₀ (interpolated pieces: small
    #: u keeps ball evaluations tight and coefficients small); ``range`` is then in u.
    time_offset: Fraction = Fraction(0)
    #: the working mode the verdict is about (the document's ``mode`` key; None: all)
    mode: str | None = None

    @property
    def not_algebraic(self) -> str:
        """Why the exact engine cannot take this piece ("" when it can): the coordinates
        kept as expression trees (:mod:`~singcheck.spec.real_paths`)."""
        from singcheck.algebra.opaque import opaque_of

        found = []
        for v, p in self.pose.items():
            for name in p.context().names()[3:]:
                hit = opaque_of(name)
                if hit is not None and hit[1] in "XA" and not hit[0].algebraic and \
                        p.degrees()[p.context().names().index(name)] > 0:
                    found.append(f"{v} = {hit[0].text}")
        if not found:
            return ""
        return ("the path is not a polynomial in t, sin t and cos t over Q (" +
                "; ".join(found) + ")")

    def __repr__(self) -> str:  # short: the pose polynomials can run to kilobytes
        pieces = f", {len(self.segments)} pieces" if self.segments else ""
        rng = self.global_range
        return (f"<TrajectorySpec {self.name}: {self.parameter} in [{rng.start}, "
                f"{rng.end}]{pieces}>")

    @property
    def pieces(self) -> tuple[TrajectorySpec, ...]:
        """The one-piece specs to certify, in order (the spec itself for one piece)."""
        return self.segments or (self,)

    @property
    def global_range(self) -> TimeRange:
        """The range in the user's parameter t (``range`` is in the piece's own time)."""
        if self.time_scale is not None:
            g = self.time_scale
            return TimeRange(LinearInPi(self.range.start.pi_coefficient / g),
                             LinearInPi(self.range.end.pi_coefficient / g))
        d = self.time_offset
        return TimeRange(*(LinearInPi(e.rational + d, e.pi_coefficient)
                           for e in (self.range.start, self.range.end)))

    def local_time(self, t: LinearInPi) -> LinearInPi:
        """The exact time of this piece at the user's time t (rational t on a rescaled
        piece)."""
        if self.time_scale is not None:
            return LinearInPi(Fraction(0), self.time_scale * t.rational)
        return LinearInPi(t.rational - self.time_offset, t.pi_coefficient)

    def to_global(self, t):
        """A ball in this piece's time mapped to a ball in t (t = τ/(gπ) or u + t₀,
        rigorous)."""
        from flint import arb, fmpq

        if self.time_scale is not None:
            g = self.time_scale
            return t / (arb.pi() * arb(fmpq(g.numerator, g.denominator)))
        if self.time_offset:
            d = self.time_offset
            return t + arb(fmpq(d.numerator, d.denominator))
        return t

    def to_local(self, t):
        """The inverse of :meth:`to_global`: a ball in t mapped to a ball in this piece's
        own time (τ = g·π·t, or u = t − t₀), rigorous."""
        from flint import arb, fmpq

        if self.time_scale is not None:
            g = self.time_scale
            return t * arb.pi() * arb(fmpq(g.numerator, g.denominator))
        if self.time_offset:
            d = self.time_offset
            return t - arb(fmpq(d.numerator, d.denominator))
        return t


def exactly_less(a: LinearInPi, b: LinearInPi) -> bool:
    """Exactly a < b (π is irrational, so unequal values separate at some precision)."""
    from singcheck.algebra.intervals import working_precision

    if a == b:
        return False
    for bits in (64, 256, 1024, 4096):
        with working_precision(bits):
            d = b.ball() - a.ball()
            if d > 0:
                return True
            if d < 0:
                return False
    raise AssertionError("unreachable: distinct a + bπ values separate")  # pragma: no cover


def time_range(doc, rnode, key: str) -> TimeRange:
    """``[start, end]`` with start < end, exact (a + b·π)."""
    if not kind(rnode) == "sequence" or len(rnode.value) != 2:
        raise doc.error(rnode, key, "expected [start, end], e.g. [-pi, pi]")
    start, end = (doc.expression(item, f"{key}[{i}]", compile_constant)
                  for i, item in enumerate(rnode.value))
    if not exactly_less(start, end):
        raise doc.error(rnode, key, f"empty range: start {start} must be smaller than "
                                    f"end {end}")
    return TimeRange(start, end)


def pose_nodes(doc, pnode, key: str, robot, at) -> dict:
    """The pose mapping's value nodes, in the robot's pose order (every coordinate, no
    other name); ``at``: the node to name when one is missing."""
    pose_map = doc.mapping(pnode, key)
    extra = [v for v in pose_map if v not in robot.pose]
    if extra:
        raise doc.error(pose_map[extra[0]][0], f"{key}.{extra[0]}",
                        f"{extra[0]!r} is not a pose variable of robot {robot.name} "
                        f"(pose: {', '.join(robot.pose)})")
    missing = [v for v in robot.pose if v not in pose_map]
    if missing:
        raise doc.error(at, key,
                        f"missing coordinate(s) {', '.join(missing)} of robot {robot.name}")
    return {v: pose_map[v][1] for v in robot.pose}


def _scale_of(multiples: list[Fraction]) -> Fraction | None:
    """g with every k/g an integer (the gcd of the k), or None without any."""
    from math import gcd, lcm

    ks = [k for k in multiples if k]
    if not ks:
        return None
    return Fraction(gcd(*(k.numerator for k in ks)), lcm(*(k.denominator for k in ks)))


def radical_primes(parameters: dict, trees: list[Node]) -> set[int]:
    """Every prime whose square root a compiled expression may need: those of the
    parameters, of each ``sqrt(q)`` written inline, and 2 and 3 (the sines and
    cosines of multiples of π/12)."""
    primes = {2, 3}
    for value in parameters.values():
        if isinstance(value, Constant):
            primes |= value.surd.primes()

    def walk(node: Node) -> None:
        if node.kind == "call" and node.value == "sqrt":
            try:
                primes.update(compile_value(node, parameters).surd.primes())
            except ExprError:
                pass  # the compiler reports it, with its column
        for a in node.args:
            walk(a)

    for tree in trees:
        walk(tree)
    return primes


def trajectory_piece(doc, rng: TimeRange, rnode, nodes: dict, key: str, parameter: str,
                     robot) -> tuple[TimeRange, dict, Fraction | None, dict]:
    """A piece's pose compiled exactly (with its angles' π offsets), its range in its own
    time: sin/cos of k·π·t (rational k) rescale the piece to τ = g·π·t (then the range
    must be rational, and becomes [g·π·start, g·π·end]).

    A pose the exact compilers refuse (``cos(t - 1)``, ``cos(t/2)``, t beside
    ``sin(pi*t)``, ``sqrt(1 + t^2)``) but that is a real function of t in the grammar
    (:func:`~singcheck.spec.real_paths.real_function`) is kept as expression trees: each
    coordinate becomes an opaque variable of the path ring, enclosed by ball arithmetic
    (the interval engine alone certifies such a path; the exact engine's refusal names
    the coordinate).  A pose that is not even that raises the exact compiler's error."""
    from singcheck.errors import SpecError

    try:
        return _exact_piece(doc, rng, rnode, nodes, key, parameter, robot)
    except (SpecError, ExprError) as e:
        first = e
    opaque = _opaque_piece(doc, nodes, key, parameter, robot, rng, rnode)
    if opaque is None:
        if isinstance(first, ExprError):
            raise doc.error(rnode, key, first.message) from None
        raise first
    return rng, opaque, None, {}


def _opaque_piece(doc, nodes: dict, key: str, parameter: str, robot, rng: TimeRange,
                  rnode) -> dict | None:
    """The pose as opaque variables, one ring for the piece (None when some coordinate
    is not a real function of the parameter in the grammar).  A coordinate not proven
    defined at the range's ends (√ of a negative number, a division by 0) is refused."""
    from singcheck.algebra.opaque import opaque_name
    from singcheck.spec.real_paths import real_function

    functions = {}
    for v, node in nodes.items():
        text = doc.text(node, f"{key}.{v}")
        tree = doc.expression(node, f"{key}.{v}", lambda n: n)
        try:
            functions[v] = real_function(tree, text, parameter, robot.parameters,
                                         _algebraic(tree, parameter, robot))
        except ExprError:
            return None
        for end in (rng.start, rng.end):
            if not functions[v](end.ball()).is_finite():
                raise doc.error(node, f"{key}.{v}", f"{text!r} is not defined at "
                                f"{parameter} = {end} (or not provably: a square root of a "
                                "negative number, a division by zero)")
    names = {v: opaque_name("A" if v in robot.angles else "X", f)
             for v, f in functions.items()}
    extra = [opaque_name(k, functions[v]) for v in functions if v in robot.angles
             for k in ("C", "S")]
    ring = fmpq_mpoly_ctx.get(("t", "s", "c", *dict.fromkeys([*names.values(), *extra])),
                              "lex")
    gens = dict(zip(ring.names(), ring.gens(), strict=True))
    return {v: gens[name] for v, name in names.items()}


def _algebraic(tree: Node, parameter: str, robot) -> bool:
    """Whether the coordinate alone compiles exactly (said in the exact engine's refusal
    of a piece kept as expression trees: only the others are named)."""
    primes = sorted(radical_primes(robot.parameters, [tree]))
    ring = fmpq_mpoly_ctx.get(("t", "s", "c", *(radical_name(p) for p in primes)), "lex")
    try:
        compile_trajectory_coordinate(tree, parameter, robot.parameters, ring)
    except ExprError:
        return False
    return True


def _exact_piece(doc, rng: TimeRange, rnode, nodes: dict, key: str, parameter: str,
                 robot) -> tuple[TimeRange, dict, Fraction | None, dict]:
    """:func:`trajectory_piece` for a pose the exact compilers take."""
    trees = {v: doc.expression(node, f"{key}.{v}", lambda n: n) for v, node in nodes.items()}
    scale = _scale_of([k for tree in trees.values()
                       for k in pi_multiples(tree, parameter, robot.parameters)])
    primes = sorted(radical_primes(robot.parameters, list(trees.values())))
    # cos(g(t)), sin(g(t)) in a coordinate (x: cos(t^2)) where g(t) is a pose angle's
    # polynomial path (phi: t^2): that angle's functions (certified as such paths are)
    functions = []
    for v, tree in trees.items():
        if v not in robot.angles:
            functions += [n for n in polynomial_angles(tree, parameter, robot.parameters,
                                                       scale) if n not in functions]
    if functions:  # (rare: the angles' own trees are compiled once more only then)
        angles = {polynomial_angle(trees[v], parameter, robot.parameters, scale)
                  for v in trees if v in robot.angles}
        functions = [n for n in functions if n in angles]
    ring = fmpq_mpoly_ctx.get(("t", "s", "c", *(radical_name(p) for p in primes),
                               *(n for pair in functions for n in pair)), "lex")
    coords, offsets = {}, {}
    for v, node in nodes.items():
        if v in robot.angles:  # (each expression is parsed once: its tree is reused)
            coords[v], offsets[v] = doc.expression(
                node, f"{key}.{v}", lambda n: compile_angle_coordinate(
                    n, parameter, robot.parameters, ring, scale), trees[v])
        else:
            coords[v] = doc.expression(
                node, f"{key}.{v}", lambda n: compile_trajectory_coordinate(
                    n, parameter, robot.parameters, ring, scale), trees[v])
    used = [i for i, _ in radical_variables(ring)
            if any(p.degrees()[i] > 0 for p in coords.values())]
    names = ("t", "s", "c", *(ring.names()[i] for i in used))
    small = TRIG if not used else fmpq_mpoly_ctx.get(names, "lex")
    index = {n: i for i, n in enumerate(ring.names())}
    extra = [n for pair in functions if any(p.degrees()[index[n]] > 0 for n in pair
                                            for p in coords.values()) for n in pair]
    wide = fmpq_mpoly_ctx.get((*names, *extra), "lex") if extra else small
    coords = {v: restrict(p, small if v in robot.angles else wide) for v, p in coords.items()}
    if scale is not None:
        if rng.start.pi_coefficient or rng.end.pi_coefficient:
            raise doc.error(rnode, "range", f"with sin/cos of k*pi*{parameter} the range "
                                            "must be rational (no pi)")
        rng = TimeRange(LinearInPi(Fraction(0), scale * rng.start.rational),
                        LinearInPi(Fraction(0), scale * rng.end.rational))
    return rng, coords, scale, offsets
