"""Robot and trajectory spec files: YAML read through its node tree, exactly.

The YAML is *composed* (``yaml.compose`` with the safe loader), never constructed, so
every scalar is parsed from its source text by :mod:`singcheck.expr` (``0.1`` stays
1/10; YAML never turns it into a float) and every error names its line.  Each failure
is a one-line :class:`~singcheck.errors.SpecError`: ``FILE:LINE: KEY: problem``.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from fractions import Fraction

from flint import fmpq_mpoly, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import restrict
from singcheck.algebra.radicals import angle_names, radical_name, radical_variables
from singcheck.errors import SpecError
from singcheck.spec.grammar import (
    Constant,
    ExprError,
    RealLimit,
    TooLarge,
    angles_in,
    compile_constant,
    compile_polynomial,
    compile_value,
    parse,
)
from singcheck.spec.paths import CsvFormat, csv_name, multi_piece, parse_csv
from singcheck.spec.plainyaml import compose_all as compose_plain
from singcheck.spec.plainyaml import kind
from singcheck.spec.real_constants import (
    RealConstant,
    angle_offsets,
    opaque_parameter,
    outside_field,
    real_constant,
    root_constants,
)
from singcheck.spec.trajectory import (
    TrajectorySpec,
    exactly_less,
    pose_nodes,
    radical_primes,
    time_range,
    trajectory_piece,
)

__all__ = ["RobotSpec", "TrajectorySpec", "load_robot", "load_trajectory",
           "load_trajectories", "parse_robot", "parse_trajectory", "parse_trajectories",
           "Document", "Span", "read_documents"]

ROBOT_KEYS = {"name": True, "description": False, "joints": True, "pose": True,
              "parameters": False, "constraints": True, "joint_limits": False,
              "drawing": False, "clearance": False}
TRAJECTORY_KEYS = {"name": True, "parameter": True, "range": False, "pose": False,
                   "segments": False, "waypoints": False, "interpolation": False,
                   "mode": False}
RESERVED = {"pi", "sin", "cos", "sqrt"}
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z_0-9]*\Z")
MAX_BYTES = 1_000_000
MAX_YAML_DEPTH = 16  # lists and mappings inside one another (specs need 3)
STDIN = "-"  # the path that reads standard input
STDIN_NAME = "<stdin>"  # how its trajectories name their file
MAX_DRAWING_POINTS = 1000  # every point of a drawing is evaluated once per frame drawn


@dataclass(frozen=True)
class DrawingBody:
    """One body of a robot's drawing: chains of segments and single points, each point a
    tuple of 2 or 3 exact polynomials in the joints and pose (parameters substituted)."""

    name: str
    chains: tuple[tuple[tuple[fmpq_mpoly, ...], ...], ...]  # each: ≥ 2 points joined in turn
    points: tuple[tuple[fmpq_mpoly, ...], ...]
    line: int


@dataclass(frozen=True)
class RobotSpec:
    path: str
    name: str
    description: str
    joints: tuple[str, ...]
    pose: tuple[str, ...]
    parameters: dict[str, Fraction | Constant]  # Fraction when rational
    context: fmpq_mpoly_ctx  # joints then pose then radicals (see ``variables``)
    constraints: tuple[fmpq_mpoly, ...]
    constraint_lines: tuple[int, ...]
    joint_limits: dict[str, tuple]  # Fractions; LinearInPi (radians) for an angle joint
    lines: dict[str, int] = field(default_factory=dict)
    angles: frozenset[str] = frozenset()  # joints and pose variables used inside sin/cos
    radicals: tuple[int, ...] = ()  # primes p whose sqrt(p) is a variable of the context

    def __repr__(self) -> str:  # short: the constraints can run to kilobytes
        return (f"<RobotSpec {self.name}: joints {', '.join(self.joints)}; pose "
                f"{', '.join(self.pose)}>")

    def variables(self, name: str) -> tuple[str, ...]:
        """The context's variables of a joint or pose variable: itself, or
        ``(cos(v), sin(v))`` for an angle."""
        return angle_names(name) if name in self.angles else (name,)

    @property
    def joint_variables(self) -> tuple[str, ...]:
        return tuple(v for j in self.joints for v in self.variables(j))

    @property
    def pose_variables(self) -> tuple[str, ...]:
        return tuple(v for x in self.pose for v in self.variables(x))

    @property
    def radical_variables(self) -> tuple[str, ...]:
        return tuple(radical_name(p) for p in self.radicals)

    drawing: tuple[DrawingBody, ...] = ()  # the optional ``drawing`` key
    #: ``clearance: {length: L}``: a pose angle's column of A is divided by L when the
    #: clearance κ is computed (None: not given, 1)
    clearance_length: Fraction | None = None

    @property
    def drawing_dimension(self) -> int | None:
        """2 or 3 (every point of a drawing has as many coordinates), None without one."""
        for body in self.drawing:
            for point in (*body.points, *(p for chain in body.chains for p in chain)):
                return len(point)
        return None


class _Doc:
    """Helpers bound to one file, for located errors."""

    def __init__(self, path: str) -> None:
        self.path = path

    def error(self, node_or_line, key: str | None, message: str) -> SpecError:
        line = node_or_line if isinstance(node_or_line, int) or node_or_line is None \
            else node_or_line.start_mark.line + 1
        return SpecError(message, path=self.path, line=line, key=key)

    def mapping(self, node, key: str | None) -> dict[str, tuple]:
        """{key: (key node, value node)} of a mapping node."""
        if kind(node) != "mapping":
            raise self.error(node, key, f"expected a mapping (key: value), got {_kind(node)}")
        out: dict[str, tuple] = {}
        for k, v in node.value:
            if kind(k) != "scalar":
                raise self.error(k, key, "keys must be plain names")
            if k.value in out:
                raise self.error(k, key, f"duplicate key {k.value!r}")
            out[k.value] = (k, v)
        return out

    def keys(self, node, allowed: dict[str, bool], what: str):
        m = self.mapping(node, None)
        for name, (k, _) in m.items():
            if name not in allowed:
                raise self.error(k, name, f"unknown key in a {what} spec (allowed: "
                                          f"{', '.join(allowed)})")
        for name, required in allowed.items():
            if required and name not in m:
                raise self.error(node, name, f"missing required key in a {what} spec")
        return m

    def scalar(self, node, key: str) -> str:
        if kind(node) != "scalar":
            raise self.error(node, key, f"expected a single value, got {_kind(node)}")
        return str(node.value)

    def text(self, node, key: str) -> str:
        value = self.scalar(node, key).strip()
        if not value:
            raise self.error(node, key, "is empty")
        return value

    def names(self, node, key: str) -> tuple[str, ...]:
        if kind(node) != "sequence" or not node.value:
            raise self.error(node, key, "expected a non-empty list of names, e.g. [x, y]")
        out = []
        for i, item in enumerate(node.value):
            name = self.text(item, f"{key}[{i}]")
            if not _IDENTIFIER.match(name):
                raise self.error(item, f"{key}[{i}]", f"{name!r} is not a valid name")
            if name in RESERVED:
                raise self.error(item, f"{key}[{i}]", f"{name!r} is reserved")
            if name in out:
                raise self.error(item, f"{key}[{i}]", f"{name!r} is listed twice")
            out.append(name)
        return tuple(out)

    def number(self, node, key: str) -> Fraction:
        text = self.text(node, key)
        try:
            value = compile_constant(parse(text))
        except ExprError as e:
            raise self.error(node, key, f"{e} in {_excerpt(text)}") from None
        if value.pi_coefficient:
            raise self.error(node, key, f"must be an exact rational number, not {text!r}")
        return value.rational

    def limit(self, node, key: str) -> Fraction | RealLimit:
        """A prismatic joint's limit: a Fraction when rational, else any finite real
        (``2*sqrt(2)``, ``pi``, ``3*cos(1/3) + 1``) as a :class:`RealLimit`, compared by
        ball arithmetic only."""
        text = self.text(node, key)
        value = self._constant(node, key, text, {})
        if isinstance(value, Constant) and not value.pi_coefficient and \
                value.surd.is_rational():
            return value.surd.rational_value()
        return RealLimit(value, text)

    def angle_limit(self, node, key: str):
        """An angle joint's limit: ``a + b·π`` exactly (LinearInPi, as ever), else any
        finite real (``cos(1/3)`` radians) as a :class:`RealLimit`, compared by ball
        arithmetic only."""
        try:
            return self.expression(node, key, compile_constant)
        except SpecError as e:
            first = e
        text = self.text(node, key)
        try:
            return RealLimit(real_constant(parse(text), text, {}), text)
        except ExprError as e:
            if "not allowed here" in e.message or "unknown function" in e.message:
                raise first from None  # (the exact grammar's own message)
            raise self.error(node, key, f"{e} in {_excerpt(text)}") from None

    def value(self, node, key: str, parameters: dict) -> Fraction | Constant | RealConstant:
        """A parameter's value: a Fraction when rational, a Constant in the exact field
        (surds, π), else a :class:`~singcheck.spec.real_constants.RealConstant` (any
        finite real of the grammar, enclosed by balls)."""
        text = self.text(node, key)
        value = self._constant(node, key, text, parameters)
        if isinstance(value, Constant) and not value.pi_coefficient and \
                value.surd.is_rational():
            return value.surd.rational_value()
        return value

    def _constant(self, node, key: str, text: str, parameters: dict):
        """The exact Constant of a constant expression when the exact field holds it
        (the same compiler as ever), else its :class:`RealConstant`, proven a finite
        real; a located error when it is neither."""
        try:
            tree = parse(text)
        except ExprError as e:
            raise self.error(node, key, f"{e} in {_excerpt(text)}") from None
        try:
            return compile_value(tree, parameters)
        except TooLarge as e:
            raise self.error(node, key, f"{e} in {_excerpt(text)}") from None
        except (ExprError, ValueError, ZeroDivisionError) as e:
            first = e
        try:
            return real_constant(tree, text, parameters)
        except ExprError as e:
            raise self.error(node, key, f"{e} in {_excerpt(text)}") from first

    def expression(self, node, key: str, compile_, tree=None):
        """``compile_`` of the expression at ``node`` (``tree``: its parse, when the
        caller has it already)."""
        text = self.text(node, key)
        try:
            return compile_(parse(text) if tree is None else tree)
        except ExprError as e:
            raise self.error(node, key, f"{e.message} in {_excerpt(text)}" +
                             (f" at column {e.column}" if e.column else "")) from None


def _excerpt(text: str) -> str:
    """An expression quoted in a message: the whole of a short one, the ends of a long one."""
    return repr(text) if len(text) <= 80 else f"{text[:40]!r}…{text[-20:]!r}"


def _kind(node) -> str:
    return {"mapping": "a mapping", "sequence": "a list",
            "scalar": "a single value"}.get(kind(node), "nothing")


def _check_depth(text: str, path: str, offset: int = 0) -> None:
    """Refuse YAML nested deeper than MAX_YAML_DEPTH, from the event stream (PyYAML's
    parser is a state machine; its composer, and our walks, recurse once per level).
    ``offset``: lines of the file before ``text`` (for the line an error names)."""
    import yaml

    depth = 0
    try:
        for event in yaml.parse(text, Loader=_loader()):
            if isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
                depth += 1
                if depth > MAX_YAML_DEPTH:
                    raise SpecError(f"lists and mappings are nested more than "
                                    f"{MAX_YAML_DEPTH} levels deep", path=path,
                                    line=event.start_mark.line + 1 + offset)
            elif isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
                depth -= 1
    except yaml.YAMLError as e:
        raise _yaml_error(e, path, offset) from None


def _yaml_error(e, path: str, offset: int = 0) -> SpecError:
    import yaml

    if isinstance(e, yaml.MarkedYAMLError):
        mark = e.problem_mark or e.context_mark
        line = mark.line + 1 + offset if mark else None
        problem = (e.problem or e.context or "invalid YAML").strip()
        if "maximum nesting depth" in problem:  # libyaml ≥ 0.2.6 stops at 1000 levels,
            # scanning ahead of the events our own bound counts: the same refusal
            return SpecError(f"lists and mappings are nested more than {MAX_YAML_DEPTH} "
                             "levels deep", path=path, line=line)
        return SpecError(f"not valid YAML: {problem}", path=path, line=line)
    return SpecError(f"not valid YAML: {str(e).splitlines()[0]}", path=path)


def _loader():
    """libyaml's safe loader when PyYAML was built with it (the same nodes and marks,
    parsed in C), else the pure-Python one."""
    import yaml

    return getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def _compose(text: str, path: str, first_line: int = 1, empty_ok: bool = False):
    """The node tree of one YAML document, ``text`` starting at line ``first_line`` of
    ``path`` (the lines its nodes and errors name); None for an empty one when
    ``empty_ok``, else an error.  Composed (never constructed) by the quick reader of
    plain specs (:mod:`singcheck.spec.plainyaml`) when the text is in its subset, else
    by PyYAML (imported only then)."""
    offset = first_line - 1
    plain = compose_plain(text, MAX_YAML_DEPTH, offset)
    if plain is not None and len(plain) == 1:
        return plain[0]
    import yaml

    _check_depth(text, path, offset)
    try:
        node = yaml.compose(text, Loader=_loader())
    except yaml.YAMLError as e:
        raise _yaml_error(e, path, offset) from None
    if node is None or (isinstance(node, yaml.ScalarNode) and node.value == ""
                        and node.tag == "tag:yaml.org,2002:null"):  # nothing, or a bare ---
        if empty_ok:
            return None
        raise SpecError("the file is empty", path=path, line=first_line)
    _refuse_tags(node, _Doc(path), set(), offset)
    return node


_PLAIN_TAGS = {f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "null", "bool",
                                                  "map", "seq")}


def _refuse_tags(node, doc: _Doc, seen: set[int], offset: int = 0) -> None:
    """Refuse YAML tags, and aliases (``*name``): a node reached twice is an alias, and
    nested aliases are how a small file expands into an enormous one.  Moves each node's
    mark ``offset`` lines down (a document cut out of a longer file)."""
    if id(node) in seen:
        raise doc.error(node, None, "YAML aliases (*name) are not allowed in specs")
    seen.add(id(node))
    if offset:
        import yaml

        m = node.start_mark
        node.start_mark = yaml.Mark(m.name, m.index, m.line + offset, m.column, None, None)
    if node.tag not in _PLAIN_TAGS:
        raise doc.error(node, None, f"YAML tags like {node.tag} are not allowed")
    children = []
    if kind(node) == "mapping":
        for k, v in node.value:
            children += [k, v]
    elif kind(node) == "sequence":
        children = node.value
    for child in children:
        _refuse_tags(child, doc, seen, offset)


def _read(path: str | os.PathLike, limit: int = MAX_BYTES) -> str:
    """A spec file's text (``-``: standard input, read to its end), at most ``limit``
    bytes of UTF-8."""
    p = os.fspath(path)
    try:
        if p == STDIN:
            data = sys.stdin.buffer.read(limit + 1)
        else:
            with open(p, "rb") as f:
                data = f.read(limit + 1)
    except OSError as e:
        raise SpecError(f"cannot read the file: {e.strerror or e}", path=p) from None
    if len(data) > limit:
        raise SpecError(f"the file is larger than {limit} bytes", path=p)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise SpecError("the file is not UTF-8 text", path=p, line=line) from None


def _line(node) -> int:
    return node.start_mark.line + 1


# ---------------------------------------------------------------------------------
# robots


def parse_robot(text: str, path: str) -> RobotSpec:
    doc = _Doc(path)
    top = doc.keys(_compose(text, path), ROBOT_KEYS, "robot")
    lines = {k: _line(knode) for k, (knode, _) in top.items()}
    name = doc.text(top["name"][1], "name")
    description = doc.scalar(top["description"][1], "description").strip() \
        if "description" in top else ""
    joints = doc.names(top["joints"][1], "joints")
    pose = doc.names(top["pose"][1], "pose")
    for j in joints:
        if j in pose:
            raise doc.error(top["pose"][1], "pose", f"{j!r} is both a joint and a pose variable")
    parameters: dict[str, Fraction] = {}
    if "parameters" in top:
        for pname, (knode, vnode) in doc.mapping(top["parameters"][1], "parameters").items():
            key = f"parameters.{pname}"
            if not _IDENTIFIER.match(pname) or pname in RESERVED:
                raise doc.error(knode, key, f"{pname!r} is not a valid parameter name")
            if pname in joints or pname in pose:
                raise doc.error(knode, key, f"{pname!r} is already a joint or pose variable")
            parameters[pname] = doc.value(vnode, key, parameters)
    cnode = top["constraints"][1]
    if not kind(cnode) == "sequence" or not cnode.value:
        raise doc.error(cnode, "constraints", "expected a non-empty list of polynomials")
    trees = [doc.expression(item, f"constraints[{i}]", lambda n: n)
             for i, item in enumerate(cnode.value)]
    angles = frozenset().union(*(angles_in(t, joints + pose) for t in trees))
    algebraic = [v for name in joints + pose
                 for v in (angle_names(name) if name in angles else (name,))]
    primes = sorted(radical_primes(parameters, trees))
    # a parameter outside the exact field is an opaque constant: a variable of the ring
    # after the square roots, enclosed by balls (:mod:`singcheck.spec.real_constants`)
    outside = {p: opaque_parameter(p, v) for p, v in parameters.items() if outside_field(v)}
    # sin/cos of an angle plus such a constant (cos(th1 + a), a: 0.1): cos a, sin a are
    # opaque constants too, and the call is expanded exactly around them
    offsets = angle_offsets(trees, angles, parameters)
    offset_names = [n for _, c, s in offsets.values() for n in (c, s)]
    # sqrt of such a constant (sqrt(l), l: 2*cos(1/10)): an opaque constant of its own
    roots = root_constants(trees, parameters)
    offset_names += [n for n in roots.values() if isinstance(n, str)]
    wide = fmpq_mpoly_ctx.get((*algebraic, *(radical_name(p) for p in primes),
                               *dict.fromkeys([*outside.values(), *offset_names])), "lex")
    gens = dict(zip(wide.names(), wide.gens(), strict=True))
    variables = {v: gens[v] for v in joints + pose if v not in angles}
    pairs = {v: tuple(gens[n] for n in angle_names(v)) for v in angles}
    opaque = {**{p: gens[n] for p, n in outside.items()},
              **{node: gens[n] if isinstance(n, str) else n for node, n in roots.items()}
              } or None
    calls = {node: (k, gens[c], gens[s]) for node, (k, c, s) in offsets.items()} or None
    compiled, constraint_lines = [], []
    for i, item in enumerate(cnode.value):
        key = f"constraints[{i}]"
        poly = doc.expression(item, key, lambda n: compile_polynomial(n, wide, variables,
                                                                      parameters, pairs,
                                                                      opaque, calls))
        if poly.is_zero():
            raise doc.error(item, key, "is identically zero")
        compiled.append(poly)
        constraint_lines.append(_line(item))
    used = tuple(p for i, p in radical_variables(wide)
                 if any(f.degrees()[i] > 0 for f in compiled))
    constants = tuple(n for i, n in enumerate(wide.names())
                      if (n in outside.values() or n in offset_names)
                      and any(f.degrees()[i] > 0 for f in compiled))
    ctx = fmpq_mpoly_ctx.get((*algebraic, *(radical_name(p) for p in used), *constants),
                             "lex")
    constraints = [restrict(f, ctx) for f in compiled]
    if not len(constraints) == len(joints) == len(pose):
        raise doc.error(top["constraints"][0], "constraints",
                        f"{len(constraints)} constraints for {len(joints)} joints and "
                        f"{len(pose)} pose variables: the system must be square (one "
                        "constraint per actuated joint; a passive joint must be eliminated "
                        "first, e.g. by writing its leg as a squared distance)")
    limits: dict[str, tuple[Fraction, Fraction]] = {}
    if "joint_limits" in top:
        for jname, (knode, vnode) in doc.mapping(top["joint_limits"][1],
                                                 "joint_limits").items():
            key = f"joint_limits.{jname}"
            if jname not in joints:
                raise doc.error(knode, key, f"{jname!r} is not a joint (joints: "
                                            f"{', '.join(joints)})")
            if not kind(vnode) == "sequence" or len(vnode.value) != 2:
                raise doc.error(vnode, key, "expected [min, max]")
            if jname in angles:
                lo, hi = (doc.angle_limit(v, key) for v in vnode.value)
                if not (exactly_less(lo, hi) if not isinstance(lo, RealLimit) and
                        not isinstance(hi, RealLimit) else _below(lo, hi)):
                    raise doc.error(vnode, key, f"min {lo} must be smaller than max {hi}")
            else:
                lo, hi = (doc.limit(v, key) for v in vnode.value)
                if not _below(lo, hi):
                    raise doc.error(vnode, key, f"min {lo} must be smaller than max {hi}")
            limits[jname] = (lo, hi)
    final = dict(zip(ctx.names(), ctx.gens(), strict=True))
    drawing = _drawing(doc, top["drawing"][1], ctx,
                       {v: final[v] for v in joints + pose if v not in angles}, parameters,
                       {v: tuple(final[n] for n in angle_names(v)) for v in angles},
                       {p: final[n] for p, n in outside.items() if n in final},
                       {node: (k, final[c], final[s]) for node, (k, c, s) in offsets.items()
                        if c in final and s in final}) \
        if "drawing" in top else ()
    length = _clearance_length(doc, top["clearance"][1]) if "clearance" in top else None
    return RobotSpec(path, name, description, joints, pose, parameters, ctx,
                     tuple(constraints), tuple(constraint_lines), limits, lines,
                     angles=angles, radicals=used, drawing=drawing, clearance_length=length)


def _below(lo, hi) -> bool:
    """lo < hi for rational or :class:`RealLimit` values, proven (by balls at rising
    precision for a real one; equal reals are never proven below each other)."""
    if isinstance(lo, Fraction) and isinstance(hi, Fraction):
        return lo < hi
    from flint import arb, fmpq

    from singcheck.algebra.intervals import working_precision

    def ball(v):  # (a RealLimit, an angle's LinearInPi, a Fraction)
        return v.ball() if hasattr(v, "ball") else arb(fmpq(v.numerator, v.denominator))

    for bits in (64, 256, 1024):
        with working_precision(bits):
            if ball(lo) < ball(hi):
                return True
            if ball(lo) >= ball(hi):
                return False
    return False


def _clearance_length(doc: _Doc, node) -> Fraction:
    """The ``clearance`` key: ``{length: L}``, L > 0 exact (the length that turns a pose
    angle's column of A into a length, for the clearance κ)."""
    items = doc.mapping(node, "clearance")
    for key, (knode, _) in items.items():
        if key != "length":
            raise doc.error(knode, f"clearance.{key}", "unknown key (clearance has: length)")
    if "length" not in items:
        raise doc.error(node, "clearance", "expected {length: L}")
    length = doc.number(items["length"][1], "clearance.length")
    if not length > 0:
        raise doc.error(items["length"][1], "clearance.length", "must be positive")
    return length


def _drawing(doc: _Doc, node, ctx, variables, parameters,
             angles=None, opaque=None, offsets=None) -> tuple[DrawingBody, ...]:
    """The ``drawing`` key: ``body: [item, ...]`` where an item is a point ``[e, e(, e)]``
    or a chain of segments ``[[e, e(, e)], [e, e(, e)], ...]`` (two points: one segment),
    every ``e`` a polynomial in the joints, pose and parameters; one dimension, 2 or 3,
    for every point of the drawing."""
    bodies = []
    shape: dict[str, object] = {}  # the first point's dimension and where it is
    count = 0

    def point(pnode, key):
        nonlocal count
        if not kind(pnode) == "sequence" or not 2 <= len(pnode.value) <= 3 or \
                not all(kind(v) == "scalar" for v in pnode.value):
            raise doc.error(pnode, key, "expected a point: a list of 2 or 3 coordinates, "
                                        "e.g. [x, y, z]")
        if "dim" not in shape:
            shape.update(dim=len(pnode.value), line=_line(pnode))
        elif shape["dim"] != len(pnode.value):
            raise doc.error(pnode, key, f"a {len(pnode.value)}-D point in a "
                                        f"{shape['dim']}-D drawing (line {shape['line']})")
        count += 1
        if count > MAX_DRAWING_POINTS:
            raise doc.error(pnode, key, f"more than {MAX_DRAWING_POINTS} points")
        return tuple(doc.expression(
            v, f"{key}[{i}]", lambda n: compile_polynomial(n, ctx, variables, parameters,
                                                          angles, opaque, offsets))
            for i, v in enumerate(pnode.value))

    for bname, (knode, bnode) in doc.mapping(node, "drawing").items():
        key = f"drawing.{bname}"
        if not _IDENTIFIER.match(bname):
            raise doc.error(knode, key, f"{bname!r} is not a valid body name")
        if not kind(bnode) == "sequence" or not bnode.value:
            raise doc.error(bnode, key, "expected a non-empty list of segments "
                                        "[[x1, y1], [x2, y2]] or points [x, y]")
        chains, points = [], []
        for i, item in enumerate(bnode.value):
            ikey = f"{key}[{i}]"
            if not kind(item) == "sequence" or not item.value:
                raise doc.error(item, ikey, "expected a segment [[x1, y1], [x2, y2]] or a "
                                            "point [x, y]")
            if all(kind(v) == "scalar" for v in item.value):
                points.append(point(item, ikey))
            elif len(item.value) < 2:
                raise doc.error(item, ikey, "a segment needs two end points")
            else:
                chains.append(tuple(point(p, f"{ikey}[{j}]")
                                    for j, p in enumerate(item.value)))
        bodies.append(DrawingBody(bname, tuple(chains), tuple(points), _line(knode)))
    if not bodies:
        raise doc.error(node, "drawing", "names no body")
    return tuple(bodies)


def load_robot(path: str | os.PathLike) -> RobotSpec:
    return parse_robot(_read(path), os.fspath(path))


# ---------------------------------------------------------------------------------
# trajectories


def trajectory_parameter(doc: _Doc, top, robot: RobotSpec) -> str:
    pnode = top["parameter"][1]
    parameter = doc.text(pnode, "parameter")
    if not _IDENTIFIER.match(parameter) or parameter in RESERVED:
        raise doc.error(pnode, "parameter", f"{parameter!r} is not a valid name")
    if parameter in robot.pose or parameter in robot.joints or parameter in robot.parameters:
        raise doc.error(pnode, "parameter",
                        f"{parameter!r} is already a name of robot {robot.name}")
    return parameter


def parse_trajectory(text: str, path: str, robot: RobotSpec) -> TrajectorySpec:
    return _trajectory(_compose(text, path), path, robot)


def _trajectory(root, path: str, robot: RobotSpec) -> TrajectorySpec:
    """A trajectory document, with its optional ``mode`` (a working mode's label, checked
    against the robot when the path is certified)."""
    from dataclasses import replace

    spec = _trajectory_body(root, path, robot)
    top = _Doc(path).keys(root, TRAJECTORY_KEYS, "trajectory")
    if "mode" in top:
        label = _Doc(path).text(top["mode"][1], "mode")
        if not label or set(label) - set("+-o"):
            raise _Doc(path).error(top["mode"][1], "mode", f"{label!r} is not a working "
                                   "mode label (one of +, -, o per leg, e.g. +-+)")
        spec = replace(spec, mode=label)
    return spec


def _trajectory_body(root, path: str, robot: RobotSpec) -> TrajectorySpec:
    doc = _Doc(path)
    top = doc.keys(root, TRAJECTORY_KEYS, "trajectory")
    lines = {k: _line(knode) for k, (knode, _) in top.items()}
    name = doc.text(top["name"][1], "name")
    parameter = trajectory_parameter(doc, top, robot)
    if "segments" in top or "waypoints" in top or "interpolation" in top:
        return multi_piece(doc, root, top, name, parameter, robot, lines)
    for k in ("range", "pose"):
        if k not in top:
            raise doc.error(root, k, "missing required key in a trajectory spec (or give "
                                     "segments or waypoints)")
    rnode = top["range"][1]
    rng = time_range(doc, rnode, "range")
    nodes = pose_nodes(doc, top["pose"][1], "pose", robot, top["pose"][0])
    rng, coords, scale, offsets = trajectory_piece(doc, rng, rnode, nodes, "pose", parameter,
                                                   robot)
    return TrajectorySpec(path, name, parameter, rng, coords, lines, offsets, scale)


def load_trajectory(path: str | os.PathLike, robot: RobotSpec,
                    interpolation: str | None = None) -> TrajectorySpec:
    """A trajectory spec: YAML, or a CSV table of poses (``*.csv``) interpolated
    ``interpolation`` (linear or cubic; default cubic)."""
    p = os.fspath(path)
    if p.lower().endswith(".csv"):
        return parse_csv(_read(path), p, robot, interpolation or "cubic")
    return parse_trajectory(_read(path), p, robot)


def parse_trajectories(text: str, path: str, robot: RobotSpec) -> Iterator[TrajectorySpec]:
    """Each YAML document of ``text`` (separated by ``---``) as one trajectory; errors
    name the file, the line in it and, past the first, the document."""
    import io

    for document in _documents(io.BytesIO(text.encode()), path):
        yield document.parse(robot)


@dataclass(frozen=True)
class Document:
    """One trajectory of a run's input, read but not parsed yet (a worker parses it): a
    YAML document cut out of its file, or a CSV file's table.  ``error``: what was found
    wrong while reading it (not YAML, too big, a name already used in the run)."""

    path: str  # as messages name it (<stdin> for standard input)
    number: int  # its rank among its file's documents (1: the first)
    line: int  # the line of the file where its text starts
    text: str
    name: str | None = None  # its name key, when the YAML could be read
    name_line: int | None = None
    csv: CsvFormat | str | None = None  # a CSV table: how to read it (or its interpolation)
    error: SpecError | None = None
    #: its node tree when it was composed where it is parsed (a worker), so that it is
    #: not composed twice
    node: object = field(default=None, compare=False, repr=False)

    @property
    def label(self) -> str:
        """Its name, else where it starts (FILE:LINE)."""
        return self.name or f"{self.path}:{self.line}"

    def parse(self, robot: RobotSpec) -> TrajectorySpec:
        """The trajectory spec; :class:`SpecError` naming the file, the line in it and,
        past a file's first document, the document's number."""
        if self.error is not None:
            raise self.error
        if self.csv is not None:
            return parse_csv(self.text, self.path, robot, self.csv, self.name)
        try:
            node = self.node if self.node is not None else \
                _compose(self.text, self.path, self.line)
            return _trajectory(node, self.path, robot)
        except SpecError as e:
            if _looks_like_csv(self.text):
                e = SpecError(f"{e.message} (is it a CSV table of poses? name it *.csv or "
                              "run with --csv)", path=e.path, line=e.line, key=e.key)
            raise self.located(e) from None

    def located(self, e: SpecError) -> SpecError:
        if self.number == 1:
            return e
        return SpecError(f"{e.message} (document {self.number})", path=e.path, line=e.line,
                         key=e.key)


@dataclass(frozen=True)
class Span:
    """One YAML document of a batch's input as the parent of the batch sees it: where its
    bytes are, and its name read by a quick scan of its lines, not by YAML (a top-level
    ``name:`` line with a plain word, :func:`read_documents` with ``spans``).  The worker
    that certifies it reads it (:meth:`document`): from ``data``, or from ``source`` by
    its byte range (a regular file), and composes it, once."""

    path: str  # as messages name it (<stdin> for standard input)
    number: int
    line: int
    name: str
    name_line: int
    source: str | None  # a regular file to read the byte range from, else ``data``
    offset: int
    length: int
    data: bytes | None = None

    @property
    def label(self) -> str:
        return self.name

    def head(self) -> Document:
        """A :class:`Document` that names it (path, number, lines), without its text."""
        return Document(self.path, self.number, self.line, "", self.name, self.name_line)

    def loaded(self) -> Span:
        """This span with its bytes in ``data`` (to send it where ``source`` is not)."""
        return self if self.data is not None else replace(self, data=self._read())

    def _read(self) -> bytes:
        with open(self.source, "rb") as f:
            data = os.pread(f.fileno(), self.length, self.offset)
        if len(data) != self.length:
            raise OSError(f"{self.path} changed while the batch read it")
        return data

    def document(self, limit: int = MAX_BYTES) -> Document:
        """The document, composed (its node kept for its parsing); the error of one that
        cannot be read, or whose name is not the one the quick scan read."""
        head = self.head()
        try:
            data = self.data if self.data is not None else self._read()
        except OSError as e:
            return replace(head, error=SpecError(f"cannot read the file: {e.strerror or e}",
                                                 path=self.path, line=self.line))
        document = _document(self.path, self.number, self.line, data, limit, keep_node=True)
        if document is None or (document.error is None and (
                document.name, document.name_line) != (self.name, self.name_line)):
            return replace(head, error=head.located(SpecError(
                f"line {self.name_line} reads as the name {self.name!r}, but it is not the "
                "document's top-level name key (a line starting with 'name:' inside a "
                "multi-line value): indent it, or put the name key first",
                path=self.path, line=self.name_line, key="name")))
        return document


def _looks_like_csv(text: str) -> bool:
    """A header line of comma-separated names (t,x,y,z) and no YAML key on it."""
    first = next((line for line in text.splitlines() if line.strip()
                  and not line.lstrip().startswith("#")), "")
    return "," in first and ":" not in first and \
        all(_IDENTIFIER.match(c.strip()) for c in first.split(","))


def _is_marker(line: bytes, marker: bytes) -> bool:
    """A YAML document marker (``---`` or ``...`` at the start of a line, alone or
    followed by a blank): it always ends a document, even inside a scalar."""
    return line.startswith(marker) and (len(line) == 3 or line[3:4] in b" \t\r\n")


def _chunks(stream, limit: int) -> Iterator[tuple[int, bytes | None]]:
    """The documents of a YAML stream as (first line, bytes), read a line at a time: a
    document ends where the next ``---`` starts or at ``...``; comments and directives
    before a ``---`` go with its document.  A document over ``limit`` bytes is (line,
    None), skipped without being held."""
    for start, _, data, _ in _cuts(stream, limit):
        yield start, data


#: a top-level ``name:`` line whose value is a plain word (what a quick scan can read
#: without YAML: :func:`scan_documents`)
_NAME_LINE = re.compile(rb"name:[ \t]+([A-Za-z0-9_][A-Za-z0-9_.+-]*)[ \t]*(?:#.*)?\r?\n?\Z")


def _cuts(stream, limit: int) -> Iterator[tuple[int, int, bytes | None, list]]:
    """:func:`_chunks` with, for each document, its byte offset in the stream and the
    lines (number, line) that start with ``name:``; the marker line of a document that
    starts with ``---`` is its first."""
    lines: list[bytes] = []
    names: list[tuple[int, bytes]] = []
    size, start, number, content, too_big = 0, 1, 0, False, False
    offset = position = 0
    while True:
        line = stream.readline(limit + 1)
        if not line:
            break
        number += 1
        start_marker = _is_marker(line, b"---")
        if start_marker and content:
            yield start, offset, None if too_big else b"".join(lines), names
            lines, names, size, start, content, too_big = [], [], 0, number, False, False
            offset = position
        position += len(line)
        if line.startswith(b"name:"):
            names.append((number, line))
        if not too_big:
            size += len(line)
            too_big = size > limit
            if too_big:
                lines = []
            else:
                lines.append(line)
        stripped = line.strip()
        if start_marker or (stripped and not stripped.startswith(b"#")
                            and not line.startswith(b"%")):
            content = True
        if _is_marker(line, b"..."):
            if content:
                yield start, offset, None if too_big else b"".join(lines), names
            lines, names, size, start, content, too_big = [], [], 0, number + 1, False, False
            offset = position
    if content:
        yield start, offset, None if too_big else b"".join(lines), names


def _documents(stream, path: str, limit: int = MAX_BYTES) -> Iterator[Document]:
    """The non-empty YAML documents of a binary stream, one at a time, each composed
    once to read its name (the spec itself is parsed later, by :meth:`Document.parse`);
    a document that cannot be read is a :class:`Document` with its ``error``."""
    number = 0
    try:
        for first, data in _chunks(stream, limit):
            document = _document(path, number + 1, first, data, limit)
            if document is not None:  # None: an empty document (comments, a stray ---)
                number += 1
                yield document
    except OSError as e:
        yield Document(path, number + 1, 1, "", error=SpecError(
            f"cannot read the file: {e.strerror or e}", path=path))
        return
    if number == 0:
        yield Document(path, 1, 1, "", error=SpecError("the file is empty", path=path,
                                                        line=1))


def _spans(stream, path: str, source: str | None,
           limit: int = MAX_BYTES) -> Iterator[Document | Span]:
    """:func:`_documents`, but a document with one ``name: WORD`` line (and nothing after
    its ``---``) is a :class:`Span`, not composed: its bytes (``source`` None) or its
    byte range in the file ``source``."""
    number = 0
    try:
        for first, offset, data, names in _cuts(stream, limit):
            match = _NAME_LINE.match(names[0][1]) if data is not None and \
                len(names) == 1 else None
            if match and _bare_marker(data):
                number += 1
                yield Span(path, number, first, match.group(1).decode(), names[0][0], source,
                           offset, len(data), None if source else data)
                continue
            document = _document(path, number + 1, first, data, limit)
            if document is not None:
                number += 1
                yield document
    except OSError as e:
        yield Document(path, number + 1, 1, "", error=SpecError(
            f"cannot read the file: {e.strerror or e}", path=path))
        return
    if number == 0:
        yield Document(path, 1, 1, "", error=SpecError("the file is empty", path=path,
                                                        line=1))


def _bare_marker(data: bytes) -> bool:
    """No node on a document's ``---`` line (``--- |`` would make the rest a scalar)."""
    for line in data.split(b"\n", 20):
        if _is_marker(line + b"\n", b"---"):
            rest = line[3:].strip()
            return not rest or rest.startswith(b"#")
        if line.strip() and not line.lstrip().startswith(b"#") and \
                not line.startswith(b"%"):
            return True  # content before any marker: no --- line
    return False


def _document(path: str, number: int, first: int, data: bytes | None,
              limit: int = MAX_BYTES, keep_node: bool = False) -> Document | None:
    """One document of a stream, ``number`` of its file, its text starting at line
    ``first`` (``data`` None: it was over ``limit`` bytes), composed to read its name
    (the node kept in the document with ``keep_node``, for its parsing); None when it
    is empty.  One that cannot be read has its ``error``."""
    document = Document(path, number, first, "")
    if data is None:
        return replace(document, error=document.located(SpecError(
            f"the document is larger than {limit} bytes", path=path, line=first)))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = first + data[: e.start].count(b"\n")
        return replace(document, error=document.located(SpecError(
            "the file is not UTF-8 text", path=path, line=line)))
    try:
        node = _compose(text, path, first, empty_ok=True)
    except SpecError as e:
        return replace(document, text=text, error=document.located(e))
    if node is None:
        return None
    return replace(document, text=text, node=node if keep_node else None, **_name(node))


def _name(node) -> dict:
    """A trajectory document's name and its line, when its top is a mapping with one."""
    if kind(node) == "mapping":
        for k, v in node.value:
            if kind(k) == "scalar" and k.value == "name" and \
                    kind(v) == "scalar" and str(v.value).strip():
                return {"name": str(v.value).strip(), "name_line": _line(k)}
    return {}


def read_documents(paths: Iterable[str | os.PathLike], interpolation: str | None = None,
                   *, csv: CsvFormat | None = None, all_csv: bool = False,
                   spans: bool = False) -> Iterator[Document | Span]:
    """Every trajectory of the files, lazily, as :class:`Document` (a YAML file, or
    ``-``, standard input, holds one or more documents; a CSV file one table), read one
    at a time: memory does not grow with the number of trajectories but for their
    names, which must be unique in a run (a repeated one is that document's error).
    A file that cannot be opened, or ``-`` given twice, is refused here, at once.
    ``csv``: how CSV tables are read (``*.csv`` files; with ``all_csv``, every input,
    standard input too).  With ``spans``, a YAML document whose name a quick scan of its
    lines reads (a ``name: WORD`` line, once) is a :class:`Span`, not composed here:
    the worker that certifies it composes it (the parent of a batch only cuts the
    stream into documents and keeps the names)."""
    paths = [os.fspath(p) for p in paths]
    if paths.count(STDIN) > 1:
        raise SpecError("standard input (-) is given twice", path=STDIN)
    for path in paths:
        if path != STDIN:
            try:
                with open(path, "rb"):
                    pass
            except OSError as e:
                raise SpecError(f"cannot read the file: {e.strerror or e}", path=path) from None
    return _unique(_all_documents(paths, interpolation, csv, all_csv, spans))


def _all_documents(paths: list[str], interpolation: str | None,
                   table: CsvFormat | None = None, all_csv: bool = False,
                   spans: bool = False) -> Iterator[Document | Span]:
    for path in paths:
        if all_csv or path.lower().endswith(".csv"):
            stdin = path == STDIN
            document = Document(STDIN_NAME if stdin else path, 1, 1, "",
                                name="stdin" if stdin else csv_name(path),
                                csv=table or CsvFormat(interpolation or "cubic"))
            try:
                yield replace(document, text=_read(path))
            except SpecError as e:
                yield replace(document, error=e)
            continue
        if path == STDIN:
            yield from (_spans(sys.stdin.buffer, STDIN_NAME, None) if spans else
                        _documents(sys.stdin.buffer, STDIN_NAME))
            continue
        try:
            stream = open(path, "rb")
        except OSError as e:
            yield Document(path, 1, 1, "", error=SpecError(
                f"cannot read the file: {e.strerror or e}", path=path))
            continue
        with stream:
            if not spans:
                yield from _documents(stream, path)
                continue
            import stat

            regular = stat.S_ISREG(os.fstat(stream.fileno()).st_mode)
            yield from _spans(stream, path, path if regular else None)


def _unique(documents: Iterator[Document]) -> Iterator[Document]:
    """Names unique in a run: each name with where it was first seen (:class:`_Names`:
    the first :data:`NAMES_IN_MEMORY` in memory, the others on disk, so that the memory
    of a long batch does not grow with its number of trajectories)."""
    names = _Names()
    try:
        for document in documents:
            name = document.name
            if getattr(document, "error", None) is None and name is not None:
                used = names.claim(name, document.path, document.name_line)
                if used is not None:
                    if isinstance(document, Span):
                        document = document.head()
                    path, line = used
                    document = replace(document, error=document.located(SpecError(
                        f"trajectory name {name!r} is already used by {path}:{line or '?'} "
                        "(names must be unique in a run)", path=document.path,
                        line=document.name_line, key="name")))
            yield document
    finally:
        names.close()


#: the names of a run kept in memory (about 170 bytes each); past them, the names go to
#: a private temporary SQLite database on disk (:class:`_Names`)
NAMES_IN_MEMORY = 1024


class _Names:
    """The trajectory names a run has used, each with where it was first seen (path,
    line): the first ``in_memory`` in a dict, the others in a private temporary SQLite
    database (a file deleted when it is closed, its page cache bounded to
    :data:`_NAMES_CACHE_KIB`), so that a batch of 100,000 paths holds no more of them in
    memory than one of 1,000 (issue 32).  Where the database cannot be made or written
    (no temporary directory, a full disk), the names stay in the dict, as before."""

    def __init__(self, in_memory: int | None = None) -> None:
        self.kept: dict[str, tuple[str, int | None]] = {}
        self.in_memory = NAMES_IN_MEMORY if in_memory is None else in_memory
        self.db = None  # the database, once the dict is full
        self.spill = True  # False once the database failed: the dict keeps them all
        self.path_ids: dict[str, int] = {}  # the files of the run, numbered for the db
        self.paths: list[str] = []

    def __len__(self) -> int:
        """The names kept in memory."""
        return len(self.kept)

    def claim(self, name: str, path: str, line: int | None) -> tuple[str, int | None] | None:
        """Where ``name`` was first used in the run; None when it was not (it is now,
        at ``path``:``line``)."""
        used = self.kept.get(name)
        if used is not None:
            return used
        if self.spill and len(self.kept) >= self.in_memory:
            import sqlite3

            try:
                return self._claim_on_disk(name, path, line)
            except sqlite3.Error:  # the names come back to memory: none is lost
                self._back_to_memory()
                used = self.kept.get(name)
                if used is not None:
                    return used
        self.kept[name] = (path, line)
        return None

    def _claim_on_disk(self, name: str, path: str, line: int | None):
        db = self.db or self._open()
        path_id = self.path_ids.get(path)
        if path_id is None:
            path_id = self.path_ids[path] = len(self.paths)
            self.paths.append(path)
        before = db.total_changes
        db.execute("INSERT OR IGNORE INTO names VALUES (?, ?, ?)", (name, path_id, line))
        if db.total_changes != before:
            return None
        used_id, used_line = db.execute("SELECT path, line FROM names WHERE name = ?",
                                        (name,)).fetchone()
        return self.paths[used_id], used_line

    def _open(self):
        import sqlite3

        # "": a private database in a temporary file, deleted when it is closed; one
        # transaction that is never committed (no journal, no sync: nothing to recover)
        db = sqlite3.connect("", isolation_level=None, check_same_thread=False)
        try:
            for pragma in ("journal_mode = OFF", "synchronous = OFF",
                           f"cache_size = -{_NAMES_CACHE_KIB}"):
                db.execute(f"PRAGMA {pragma}")
            db.execute("CREATE TABLE names (name TEXT PRIMARY KEY, path INTEGER, "
                       "line INTEGER) WITHOUT ROWID")
            db.execute("BEGIN")
        except sqlite3.Error:
            db.close()
            raise
        self.db = db
        return db

    def _back_to_memory(self) -> None:
        """The database failed: what it holds back in the dict, never to spill again."""
        import sqlite3

        self.spill = False
        if self.db is None:
            return
        try:
            for name, path_id, line in self.db.execute("SELECT name, path, line FROM names"):
                self.kept.setdefault(name, (self.paths[path_id], line))
        except sqlite3.Error:  # unreadable too: the names in it are no longer checked
            pass
        self.close()

    def close(self) -> None:
        if self.db is not None:
            self.db.close()
            self.db = None


#: the page cache of :class:`_Names`'s database, in KiB
_NAMES_CACHE_KIB = 1024


def load_trajectories(paths: Iterable[str | os.PathLike], robot: RobotSpec,
                      interpolation: str | None = None) -> list[TrajectorySpec]:
    """Every trajectory of the files: a YAML file (or ``-``, standard input, once) holds
    one or more documents, a CSV file one path; names must be unique across them all.
    The first bad one raises :class:`SpecError`.  (:func:`read_documents` reads them
    one at a time instead.)"""
    return [document.parse(robot) for document in read_documents(paths, interpolation)]
