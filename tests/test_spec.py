"""Spec files: exact parsing, and one located line for every kind of bad input."""

from __future__ import annotations

from fractions import Fraction

import mpmath
import pytest
from flint import arb, fmpq

from singcheck.algebra.trig import LinearInPi, evaluate_trig
from singcheck.errors import SpecError
from singcheck.spec.files import load_robot, load_trajectory, parse_robot, parse_trajectory
from singcheck.spec.grammar import (
    ExprError,
    compile_constant,
    compile_trajectory_coordinate,
    parse,
)
from tests.conftest import ROBOTS, TRAJECTORIES

ROBOT = """\
name: r
joints: [p, q]
pose: [x, y]
parameters: {l: 2}
constraints:
  - (x - p)^2 + y^2 - l^2
  - x^2 + (y - q)^2 - l^2
joint_limits: {p: [0, 4]}
"""

TRAJ = """\
name: c
parameter: t
range: [-pi, pi]
pose:
  x: cos(t)
  y: sin(t)
"""


@pytest.fixture(scope="module")
def robot():
    return parse_robot(ROBOT, "r.yaml")


def test_numbers_are_exact():
    assert compile_constant(parse("0.1")) == LinearInPi(Fraction(1, 10))
    assert compile_constant(parse("1e-3")) == LinearInPi(Fraction(1, 1000))
    assert compile_constant(parse("2/3 - 1/6")) == LinearInPi(Fraction(1, 2))
    assert compile_constant(parse("-pi/2")) == LinearInPi(Fraction(0), Fraction(-1, 2))


def test_precedence_power_binds_tighter_than_unary_minus():
    assert compile_constant(parse("-2^2")) == LinearInPi(Fraction(-4))
    assert compile_constant(parse("2^3^2")) == LinearInPi(Fraction(512))
    assert compile_constant(parse("2**3*2")) == LinearInPi(Fraction(16))
    assert compile_constant(parse("1 - 2 - 3")) == LinearInPi(Fraction(-4))
    assert compile_constant(parse("12/2/3")) == LinearInPi(Fraction(2))


@pytest.mark.parametrize("text", [
    "8/7*sin(t)^3",
    "13/14*cos(t) - 5/14*cos(2*t) - 1/10*cos(3*t) - 1/14*cos(4*t)",
    "sin(-3*t)*cos(t*5) + t^2/7",
    "(2*t)^2 - sin((2*t))",
])
def test_trig_expansion_agrees_with_direct_evaluation(text):
    import mpmath

    poly = compile_trajectory_coordinate(parse(text), "t", {})
    env = {"sin": mpmath.sin, "cos": mpmath.cos}
    for q in (Fraction(1, 3), Fraction(-7, 5), Fraction(22, 7)):
        mpmath.mp.dps = 40
        direct = eval(text.replace("^", "**"), env, {"t": mpmath.mpf(q.numerator) / q.denominator})
        ball = evaluate_trig(poly, arb(fmpq(q.numerator, q.denominator)))
        assert abs(float(ball.mid()) - float(direct)) < 1e-12


def test_the_orthoglide_spec(orthoglide):
    spec = orthoglide.spec
    assert spec.joints == ("rho1", "rho2", "rho3") and spec.pose == ("x", "y", "z")
    r1, r2, r3, x, y, z = spec.context.gens()
    assert spec.constraints[0] == (x - r1) ** 2 + y**2 + z**2 - 4
    assert spec.joint_limits["rho3"] == (0, 4)
    assert spec.constraint_lines == (9, 10, 11)  # below the modeline and the comment


def test_heart1_range_is_exactly_minus_pi_to_pi(orthoglide):
    traj = load_trajectory(TRAJECTORIES / "heart1.yaml", orthoglide.spec)
    assert traj.range.start == LinearInPi(Fraction(0), Fraction(-1))
    assert traj.range.end == LinearInPi(Fraction(0), Fraction(1))
    assert str(traj.pose["z"]) == "1"


BAD_ROBOTS = [
    # (text, line, key, phrase)
    (ROBOT.replace("(x - p)^2", "(x - w)^2"), 6, "constraints[0]", "undeclared name 'w'"),
    (ROBOT.replace("(x - p)^2", "sin(x*p)"), 6, "constraints[0]", "integer combination"),
    # (sin(x + 1), cos(x + pi/5): an angle plus a real offset, accepted since issue 27)
    (ROBOT.replace("(x - p)^2", "sin(x/2 + 1)"), 6, "constraints[0]", "integer combination"),
    (ROBOT.replace("(x - p)^2", "cos(p) + p"), 6, "constraints[0]", "is an angle"),
    (ROBOT.replace("(x - p)^2", "sqrt(x)"), 6, "constraints[0]", "sqrt takes a constant"),
    (ROBOT.replace("(x - p)^2", "sqrt(-2)"), 6, "constraints[0]", "not real"),
    (ROBOT.replace("{l: 2}", "{l: sqrt(-1)}"), 4, "parameters.l", "not real"),
    # (pi*sqrt(2) and pi are finite reals: accepted, as opaque constants, since issue 27)
    (ROBOT.replace("{l: 2}", "{l: sqrt(1 - 2*cos(1/10))}"), 4, "parameters.l", "not real"),
    (ROBOT.replace("{l: 2}", "{l: 1/(cos(1)^2 + sin(1)^2 - 1)}"), 4, "parameters.l",
     "not proven non-zero"),
    (ROBOT.replace("{l: 2}", "{l: 1/(cos(1) - cos(1))}"), 4, "parameters.l",
     "division by zero"),  # a − a: exactly 0
    (ROBOT.replace("{l: 2}", "{l: 1/(2 - 2)}"), 4, "parameters.l", "division by zero"),
    (ROBOT.replace("{l: 2}", "{l: (sin(1)*cos(1) - cos(1)*sin(1))^(-1)}"), 4,
     "parameters.l", "negative power of a value not proven"),
    (ROBOT.replace("{l: 2}", "{l: cos(1)^(1/2)}"), 4, "parameters.l", "must be integers"),
    (ROBOT.replace("{l: 2}", "{l: tan(1)}"), 4, "parameters.l", "unknown function 'tan'"),
    (ROBOT.replace("{p: [0, 4]}", "{p: [0, sqrt(cos(2))]}"), 8, "joint_limits.p", "not real"),
    (ROBOT.replace("{l: 2}", "{l: 2, a: cos(1)}").replace("(x - p)^2", "cos(a*x)"), 6,
     "constraints[0]", "not an exact algebraic number"),
    (ROBOT.replace("(x - p)^2", "(x - p)/y"), 6, "constraints[0]", "division by a non-constant"),
    (ROBOT.replace("(x - p)^2", "(x - p)^-2"), 6, "constraints[0]", "non-negative integers"),
    (ROBOT.replace("(x - p)^2", "(x - p)^(1/2)"), 6, "constraints[0]", "non-negative integers"),
    (ROBOT.replace("(x - p)^2", "(x - p)^1000"), 6, "constraints[0]", "larger than 64"),
    (ROBOT.replace("(x - p)^2", "2(x - p)"), 6, "constraints[0]", "missing operator"),
    (ROBOT.replace("(x - p)^2", "((x - p)^2"), 6, "constraints[0]", "expected ')'"),
    (ROBOT.replace("(x - p)^2", "pi*x"), 6, "constraints[0]", "pi is not allowed"),
    (ROBOT.replace("  - x^2 + (y - q)^2 - l^2\n", ""), 5, "constraints", "must be square"),
    (ROBOT.replace("name: r\n", ""), 1, "name", "missing required key"),
    (ROBOT + "colour: red\n", 9, "colour", "unknown key"),
    (ROBOT + "name: again\n", 9, None, "duplicate key 'name'"),
    (ROBOT.replace("{p: [0, 4]}", "{p: [4, 0]}"), 8, "joint_limits.p", "must be smaller"),
    (ROBOT.replace("{p: [0, 4]}", "{w: [0, 4]}"), 8, "joint_limits.w", "is not a joint"),
    (ROBOT.replace("{p: [0, 4]}", "{p: [pi, 3]}"), 8, "joint_limits.p", "min pi must be smaller"),
    (ROBOT.replace("{p: [0, 4]}", "{p: [0, x]}"), 8, "joint_limits.p", "not allowed here"),
    (ROBOT.replace("{l: 2}", "{l: two}"), 4, "parameters.l", "'two' is not allowed"),
    (ROBOT.replace("pose: [x, y]", "pose: [x, p]"), 3, "pose", "both a joint and a pose"),
    (ROBOT.replace("joints: [p, q]", "joints: [p, pi]"), 2, "joints[1]", "reserved"),
    (ROBOT.split("constraints:")[0] + "constraints: 3\n", 5, "constraints", "non-empty list"),
    (ROBOT.replace("  - (x - p)^2 + y^2 - l^2", "  - {a: 1}"), 6, "constraints[0]",
     "single value"),
    (ROBOT.replace("  - (x - p)^2 + y^2 - l^2", "  - x - x"), 6, "constraints[0]",
     "identically zero"),
    ("name: [unclosed\n", 2, None, "not valid YAML"),
    ("", 1, None, "the file is empty"),
    ("!!python/object/apply:os.system ['echo hacked']\n", 1, None, "not allowed"),
    ("name: !!python/name:os.system x\n", 1, None, "not allowed"),
    ("- just\n- a list\n", 1, None, "expected a mapping"),
    (ROBOT + "drawing: 3\n", 9, "drawing", "expected a mapping"),
    (ROBOT + "drawing: {}\n", 9, "drawing", "names no body"),
    (ROBOT + "drawing:\n  legs: []\n", 10, "drawing.legs", "non-empty list"),
    (ROBOT + "drawing:\n  legs:\n    - [[p, 0], [x, w]]\n", 11, "drawing.legs[0][1][1]",
     "undeclared name 'w'"),
    (ROBOT + "drawing:\n  legs:\n    - [[p, 0], [x, y/x]]\n", 11, "drawing.legs[0][1][1]",
     "division by a non-constant"),
    (ROBOT + "drawing:\n  legs:\n    - [[p, 0], [x, y]]\n    - [[q, 0, 0], [x, y, 0]]\n",
     12, "drawing.legs[1][0]", "3-D point in a 2-D drawing (line 11)"),
    (ROBOT + "drawing:\n  dots: [[x]]\n", 10, "drawing.dots[0]", "2 or 3 coordinates"),
    (ROBOT + "drawing:\n  dots: [[x, y, 0, 1]]\n", 10, "drawing.dots[0]",
     "2 or 3 coordinates"),
    (ROBOT + "drawing:\n  legs: [[[p, 0]]]\n", 10, "drawing.legs[0]", "two end points"),
    (ROBOT + "drawing:\n  legs: [[[p, 0], x]]\n", 10, "drawing.legs[0][1]",
     "expected a point"),
    (ROBOT + "drawing:\n  legs: 3\n", 10, "drawing.legs", "non-empty list"),
    (ROBOT + "drawing:\n  dots: [[pi, 0]]\n", 10, "drawing.dots[0][0]", "pi is not allowed"),
]


@pytest.mark.parametrize("text, line, key, phrase", BAD_ROBOTS,
                         ids=[p for *_, p in BAD_ROBOTS])
def test_bad_robot_specs_get_one_located_line(text, line, key, phrase):
    with pytest.raises(SpecError) as err:
        parse_robot(text, "bad.yaml")
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith(f"bad.yaml:{line}:"), message
    if key:
        assert f" {key}:" in message, message
    assert phrase in message, message


def test_drawing_bodies_are_exact_polynomials_in_joints_pose_and_parameters():
    spec = parse_robot(ROBOT + """\
drawing:
  rail: [[[-l, 0], [2*l, 0]]]
  legs:
    - [[p, 0], [x, y]]
    - [[0, q], [x, y], [x + 1/10, y]]
  platform: [[x, y], [x/2, 0.5*y]]
""", "r.yaml")
    assert [b.name for b in spec.drawing] == ["rail", "legs", "platform"]
    assert [b.line for b in spec.drawing] == [10, 11, 14]
    assert spec.drawing_dimension == 2
    p, q, x, y = spec.context.gens()
    rail, legs, platform = spec.drawing
    assert rail.chains == (((-2, 0), (4, 0)),) and not rail.points
    assert legs.chains[0] == ((p, 0 * x), (x, y))
    assert legs.chains[1][2] == (x + fmpq(1, 10), y)  # 0.1 is exactly 1/10
    assert platform.points == ((x, y), (x / 2, y / 2)) and not platform.chains
    assert parse_robot(ROBOT, "r.yaml").drawing == ()
    assert parse_robot(ROBOT, "r.yaml").drawing_dimension is None


@pytest.mark.parametrize("path", sorted(ROBOTS.glob("*.yaml")), ids=lambda p: p.stem)
def test_every_bundled_robot_has_a_drawing_of_its_dimension(path):
    spec = load_robot(path)
    assert spec.drawing, f"{path.name} has no drawing key"
    # planar robots with an orientation (3-RPR: x, y, phi) are drawn in the plane
    positions = [v for v in spec.pose if v not in spec.angles]
    assert spec.drawing_dimension == (3 if len(positions) >= 3 else 2)
    # the drawing moves with every pose coordinate (a leg of variable length, 3-RPR or
    # Gough-Stewart, is drawn from the pose alone; sliders and cranks use their joint)
    used = {v for body in spec.drawing for chain in body.chains for point in chain
            for c in point for v, d in zip(spec.context.names(), c.degrees(), strict=True)
            if d > 0}  # a zero polynomial has degrees -1
    for name in spec.pose:  # an angle through its cos or sin
        assert used & set(spec.variables(name)), name


BAD_TRAJECTORIES = [
    (TRAJ.replace("[-pi, pi]", "[pi, pi]"), 3, "range", "empty range"),
    (TRAJ.replace("[-pi, pi]", "[1, -1]"), 3, "range", "empty range"),
    (TRAJ.replace("[-pi, pi]", "[0, pi^2]"), 3, "range[1]", "powers of pi"),
    (TRAJ.replace("[-pi, pi]", "[0]"), 3, "range", "expected [start, end]"),
    (TRAJ.replace("cos(t)", "sqrt(t)"), 5, "pose.x", "'sqrt(t)' is not defined at t = -pi"),
    (TRAJ.replace("cos(t)", "tan(t)"), 5, "pose.x", "unknown function 'tan'"),
    (TRAJ.replace("cos(t)", "cos(s)"), 5, "pose.x", "integer multiple of t"),
    (TRAJ.replace("cos(t)", "u"), 5, "pose.x", "undeclared name 'u'"),
    (TRAJ.replace("  y: sin(t)\n", ""), 4, "pose", "missing coordinate(s) y"),
    (TRAJ + "  z: 1\n", 7, "pose.z", "not a pose variable"),
    (TRAJ.replace("parameter: t", "parameter: x"), 2, "parameter", "already a name"),
    (TRAJ.replace("name: c\n", ""), 1, "name", "missing required key"),
    (TRAJ + "speed: 2\n", 7, "speed", "unknown key"),
]


@pytest.mark.parametrize("text, line, key, phrase", BAD_TRAJECTORIES,
                         ids=[p for *_, p in BAD_TRAJECTORIES])
def test_bad_trajectory_specs_get_one_located_line(robot, text, line, key, phrase):
    with pytest.raises(SpecError) as err:
        parse_trajectory(text, "t.yaml", robot)
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith(f"t.yaml:{line}:"), message
    assert f" {key}:" in message, message
    assert phrase in message, message


@pytest.mark.parametrize("x", ["cos(t + 1)", "cos(t/2)", "cos(100000*t)"])
def test_a_pose_that_is_no_trig_polynomial_is_kept_as_an_expression(robot, x):
    """Not a polynomial in t, sin t, cos t over Q: accepted as an expression path (the
    interval engine's alone), the exact engine's refusal naming the coordinate."""
    traj = parse_trajectory(TRAJ.replace("cos(t)", x), "t.yaml", robot)
    assert f"x = {x}" in traj.not_algebraic
    assert "y = " not in traj.not_algebraic  # sin(t) alone is exact
    assert parse_trajectory(TRAJ, "t.yaml", robot).not_algebraic == ""


def test_unreadable_files(tmp_path):
    with pytest.raises(SpecError, match="cannot read the file"):
        load_robot(tmp_path / "missing.yaml")
    latin = tmp_path / "latin.yaml"
    latin.write_bytes(b"name: r\ndescription: caf\xe9\n")
    with pytest.raises(SpecError, match=r"latin.yaml:2: the file is not UTF-8"):
        load_robot(latin)
    with pytest.raises(SpecError, match="cannot read the file"):
        load_robot(tmp_path)


def test_expression_errors_carry_a_column():
    with pytest.raises(ExprError) as err:
        parse("x + * y")
    assert err.value.column == 5


def test_bundled_specs_all_load():
    from singcheck.model.robot import build_model

    for path in ROBOTS.glob("*.yaml"):
        build_model(load_robot(path))


BOMBS = [
    # nested aliases: a few lines that would expand to an enormous document
    ("a: &a [x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a]\n"
     "c: [*b, *b, *b, *b, *b, *b, *b, *b]\n", "aliases"),
    (ROBOT.replace("(x - p)^2", "(((x - p)^64)^64)^64"), "degree exceeds"),
    (ROBOT.replace("(x - p)^2", "(x + y + p + q + 1)^60"), "more than 100000 terms"),
    (ROBOT.replace("{l: 2}", "{l: ((9^64)^64)^64}"), "too large"),
]


@pytest.mark.parametrize("text, phrase", BOMBS, ids=[p for _, p in BOMBS])
def test_specs_cannot_blow_up_memory_or_time(text, phrase):
    import time

    start = time.monotonic()
    with pytest.raises(SpecError, match=phrase):
        parse_robot(text, "bomb.yaml")
    assert time.monotonic() - start < 5


# ---------------------------------------------------------------------------------
# angles (sin/cos of variables), exact square roots, pi

ANGLE_ROBOT = """\
name: angles
joints: [th, r]
pose: [x, phi]
parameters: {R: 3/2, s3: sqrt(3), h: s3/2*R, a: pi/6}
constraints:
  - x*cos(2*th) - h*sin(th + phi) + cos(phi - pi/6) + sqrt(12)
  - r^2 - (x - cos(phi + a))^2 - sin(3*phi)^2
joint_limits: {th: [-pi/2, pi], r: [0, 4]}
"""


def _mp_eval(text: str, values: dict) -> mpmath.mpf:
    """The test's own evaluation of a spec expression (trusted text, 50 digits)."""
    env = {"sin": mpmath.sin, "cos": mpmath.cos, "sqrt": mpmath.sqrt, "pi": mpmath.pi,
           **values}
    return eval(text.replace("^", "**"), {"__builtins__": {}}, env)  # noqa: S307


def test_angles_and_square_roots_compile_exactly():
    """Each constraint, compiled with angles as (cos, sin) and √3 as a variable, equals
    the expression evaluated directly at 50 digits, at random points."""
    import random

    from singcheck.algebra.intervals import evaluate, working_precision

    text = ANGLE_ROBOT
    spec = parse_robot(text, "angles.yaml")
    assert spec.angles == {"th", "phi"}
    assert spec.radicals == (3,)
    assert spec.context.names() == ("cos(th)", "sin(th)", "r", "x", "cos(phi)", "sin(phi)",
                                    "sqrt(3)")
    lo, hi = spec.joint_limits["th"]
    assert (lo, hi) == (LinearInPi(Fraction(0), Fraction(-1, 2)),
                        LinearInPi(Fraction(0), Fraction(1)))
    sources = [line.strip()[2:] for line in text.splitlines() if line.startswith("  - ")]
    rng = random.Random(7)
    mpmath.mp.dps = 50
    for _ in range(5):
        th, r, x, phi = (mpmath.mpf(rng.uniform(-3, 3)) for _ in range(4))
        values = {"th": th, "r": r, "x": x, "phi": phi, "s3": mpmath.sqrt(3),
                  "h": mpmath.sqrt(3) / 2 * mpmath.mpf(3) / 2, "a": mpmath.pi / 6}
        point = [mpmath.cos(th), mpmath.sin(th), r, x, mpmath.cos(phi), mpmath.sin(phi),
                 mpmath.sqrt(3)]
        for poly, source in zip(spec.constraints, sources, strict=True):
            expected = _mp_eval(source, values)
            with working_precision(200):
                got = evaluate(poly, [arb(mpmath.nstr(v, 60)) for v in point])
            assert abs(mpmath.mpf(got.mid().str(50, radius=False)) - expected) < 1e-40


def test_an_angle_trajectory_keeps_its_pi_offset():
    spec = parse_robot(ANGLE_ROBOT, "angles.yaml")
    traj = parse_trajectory("name: a\nparameter: t\nrange: [0, 1]\npose:\n"
                            "  x: cos(t + pi/6)\n  phi: 2*t - pi/6\n", "a.yaml", spec)
    assert str(traj.pose["phi"]) == "2*t" and traj.angle_offsets == {"phi": Fraction(-1, 6)}
    assert traj.pose["x"].context().names() == ("t", "s", "c", "sqrt(3)")
    assert str(traj.pose["x"]) == "-1/2*s + 1/2*c*sqrt(3)"
    scaled = parse_trajectory("name: a\nparameter: t\nrange: [0, 1]\npose:\n"
                              "  x: 0\n  phi: pi*t\n", "a.yaml", spec)
    assert "phi = pi*t" in scaled.not_algebraic  # an expression path: intervals alone


@pytest.mark.parametrize("text, value", [
    ("sqrt(12)", "2*sqrt(3)"), ("sqrt(3/4)", "1/2*sqrt(3)"), ("1/(1 + sqrt(2))", "-1 + sqrt(2)"),
    ("sqrt(2)*sqrt(3) - sqrt(6)", "0"), ("(sqrt(3)/2)^2", "3/4"), ("2*sin(pi/3)", "sqrt(3)"),
    ("cos(pi/12)", "1/4*sqrt(2) + 1/4*sqrt(6)"), ("pi/6 + 1", "1 + 1/6*pi"),
])
def test_parameter_values_are_exact_algebraic_numbers(text, value):
    from singcheck.spec.grammar import compile_value

    assert str(compile_value(parse(text), {})) == value


# -- the quick reader of plain YAML --------------------------------------------------

def _node_tree(node):
    """A node as nested tuples: kind, scalar text, line of every node."""
    if node.id == "scalar":
        return ("scalar", node.value, node.start_mark.line)
    if node.id == "sequence":
        return ("sequence", node.start_mark.line, [_node_tree(c) for c in node.value])
    return ("mapping", node.start_mark.line,
            [(_node_tree(k), _node_tree(v)) for k, v in node.value])


def test_the_plain_yaml_reader_composes_what_pyyaml_composes():
    """Every text the quick reader accepts — the bundled specs and ~4,000 mutants of
    them (characters inserted, deleted, lines doubled) — composes to PyYAML's nodes:
    the same kinds, scalar texts and lines; what it declines is left to PyYAML."""
    import random
    from pathlib import Path

    import yaml

    from singcheck.spec import plainyaml

    loaders = [yaml.SafeLoader, *([yaml.CSafeLoader] if hasattr(yaml, "CSafeLoader") else [])]

    def reference(text):  # the pure-Python loader and libyaml's must both agree
        out = []
        for loader in loaders:
            try:
                out.append([_node_tree(d) for d in yaml.compose_all(text, Loader=loader)])
            except yaml.YAMLError:
                out.append("not YAML")
        return out[0] if all(o == out[0] for o in out) else "the loaders differ"

    root = Path(__file__).resolve().parent.parent
    texts = [p.read_text() for p in sorted((*ROBOTS.glob("*.yaml"),
                                            *TRAJECTORIES.glob("*.yaml"),
                                            *(root / "bench" / "paths").glob("*.yaml")))]
    accepted = 0
    for text in texts:
        mine = plainyaml.compose_all(text, 16)
        if mine is not None:
            accepted += 1
            assert [_node_tree(d) for d in mine] == reference(text)
    assert accepted >= len(texts) - 3  # nearly all: multi-line flow lists are declined
    rng = random.Random(5)
    pieces = [" ", "  ", "-", "- ", ":", ": ", "#", " #", "[", "]", "{", "}", ",", "\n",
              "\n  ", "x", "1", "---\n", "a: ", "2001-01-01", "<<", "=", "*", "?", "'", "\t",
              "!", "&", "|", ">", "%", "~", "..."]
    accepted = 0
    for _ in range(4000):
        text = rng.choice(texts)
        for _ in range(rng.randint(1, 3)):
            at = rng.randrange(len(text) + 1)
            if rng.random() < 0.45:
                text = text[:at] + rng.choice(pieces) + text[at:]
            elif rng.random() < 0.8:
                text = text[:at] + text[at + rng.randint(1, 4):]
            else:
                lines = text.split("\n")
                lines.insert(rng.randrange(len(lines) + 1), rng.choice(lines))
                text = "\n".join(lines)
        mine = plainyaml.compose_all(text, 16)
        if mine is not None:
            accepted += 1
            assert [_node_tree(d) for d in mine] == reference(text), text
    assert accepted > 1000


def test_a_plain_spec_is_read_without_pyyaml():
    """The warm run's point: reading a bundled robot and trajectory imports no PyYAML."""
    import subprocess
    import sys

    code = ("import sys; from singcheck.spec.files import load_robot, load_trajectory; "
            f"r = load_robot({str(ROBOTS / 'orthoglide.yaml')!r}); "
            f"load_trajectory({str(TRAJECTORIES / 'heart1.yaml')!r}, r); "
            "print('yaml' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


# --- the parse's caches (a batch's paths share their numbers and sin/cos terms) ---


def test_a_shared_sin_cos_term_compiles_in_each_ring_on_its_own():
    """cos(t + π/6) needs √3: compiled in a ring with √3 it is (√3/2)c - s/2, exactly;
    the same term asked for in the plain trig ring afterwards must still be refused,
    not served from the other ring's compilation."""
    from flint import fmpq, fmpq_mpoly_ctx

    from singcheck.algebra.trig import TRIG
    from singcheck.spec.grammar import ExprError, compile_trajectory_coordinate, parse

    ring = fmpq_mpoly_ctx.get(("t", "s", "c", "sqrt(3)"), "lex")
    t, s, c, r3 = ring.gens()
    p = compile_trajectory_coordinate(parse("cos(t + pi/6)"), "t", {}, ring)
    assert p == r3 * c * fmpq(1, 2) - s * fmpq(1, 2)
    q = compile_trajectory_coordinate(parse("2 + cos(t + pi/6)"), "t", {}, ring)
    assert q == p + 2
    with pytest.raises(ExprError):
        compile_trajectory_coordinate(parse("cos(t + pi/6)"), "t", {}, TRIG)


def test_an_argument_of_the_same_shape_is_read_with_the_parameters_of_its_robot():
    """k*pi*t with k = 1/2, then with k = 1/3 (another parameters dict, then the same dict
    changed): each reading gives its own multiple of π·t, whatever was read before."""
    from fractions import Fraction

    from singcheck.spec.grammar import Constant, compile_value, parse, pi_multiples

    tree = parse("sin(k*pi*t)")
    half = {"k": compile_value(parse("1/2"), {})}
    third = {"k": compile_value(parse("1/3"), {})}
    assert isinstance(half["k"], Constant)
    assert pi_multiples(tree, "t", half) == [Fraction(1, 2)]
    assert pi_multiples(parse("1 + sin(k*pi*t)"), "t", third) == [Fraction(1, 3)]
    half["k"] = third["k"]  # the same dict, changed in place
    assert pi_multiples(tree, "t", half) == [Fraction(1, 3)]


def test_a_literal_read_again_is_the_same_exact_number():
    from fractions import Fraction

    from singcheck.spec.grammar import compile_constant, parse

    for _ in range(2):
        assert compile_constant(parse("0.1 + 0.1")).rational == Fraction(1, 5)
        assert compile_constant(parse("1e-3")).rational == Fraction(1, 1000)
