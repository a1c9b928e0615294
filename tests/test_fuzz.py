"""Property-based fuzzing of robot and trajectory specs (hypothesis).

Three kinds of hostile specs, all grown from the bundled ones: *structure* (a trajectory
built key by key, keys dropped, added or nested), *grammar* (expressions generated from
singcheck's grammar, hostile literals, deep nesting, large multiples and exponents) and
*bytes* (the bundled files with bytes flipped, inserted, deleted or repeated), and
*paths of pieces* (segments, waypoints linear or cubic, CSV tables) on every bundled
robot class, pose angles in radians or degrees (``30 deg``).  The
property: every case ends with an exit status 0–3 (free, singular, bad spec, unknown)
within its time budget, never with another exception (what the command line reports as
exit 70) — the spec is untrusted input, and the README's "Security model" says what
each stage may cost.

The cases run in-process through the API and the command line's own exit-code mapping
(fast); :func:`test_fuzzed_specs_through_the_command_line` runs a sample through the real
``singcheck`` process and checks there is no traceback on stderr.

``SINGCHECK_FUZZ_EXAMPLES=N`` scales the number of cases (the CI default keeps the run
near a minute); ``SINGCHECK_FUZZ_REPORT=FILE`` writes the counts of exit statuses as it
goes (``SINGCHECK_FUZZ_REGIONS=0`` leaves out the region statement, for speed;
``SINGCHECK_FUZZ_BUDGET=S`` sets each case's time limit, 2 s by default;
``SINGCHECK_FUZZ_SHARED=1`` judges an overrun by CPU time as well, see SHARED), and
with ``SINGCHECK_FUZZ_KEEP_GOING=1`` (a long campaign) a failing case is
appended to ``FILE.failures`` (JSON lines: the two specs and the error) instead of
stopping the run.
"""

from __future__ import annotations

import atexit
import functools
import json
import os
import subprocess
import sys
import time
from collections import Counter
from fractions import Fraction
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")  # the `test` extra installs it
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tests.conftest import ROBOTS, ROOT, TRAJECTORIES  # noqa: E402

EXAMPLES = int(os.environ.get("SINGCHECK_FUZZ_EXAMPLES", "30"))
#: seconds of certification per case (api.check's time_limit); SINGCHECK_FUZZ_BUDGET: a
#  campaign may ask for less, so that more cases run in its time
BUDGET = float(os.environ.get("SINGCHECK_FUZZ_BUDGET", "2"))
#: what a check may run past it (SINGCHECK_FUZZ_SLACK: a campaign asks for 1 s): one
#   step no checkpoint can cut (a piece of a composition, a product or resultant within
#   the path-wise bound, a FLINT root isolation), with room for a loaded machine;
#   composing the stacked Orthoglide's ξ once took 5-12 s in one call, now cut into
#   pieces (tests/test_budgets.py)
SLACK = float(os.environ.get("SINGCHECK_FUZZ_SLACK", "8"))
#: SINGCHECK_FUZZ_SHARED=1 (a campaign on a machine shared with other work, under nice):
#  a case past BUDGET + SLACK of wall clock is a failure only if it also used that much
#  CPU (its own and its reaped forks'); a run starved of CPU by the scheduler is counted
#  and written to FILE.overruns instead, to be replayed on a quiet machine
SHARED = os.environ.get("SINGCHECK_FUZZ_SHARED") == "1"
REGIONS = os.environ.get("SINGCHECK_FUZZ_REGIONS", "1") != "0"  # the region statement too
ROBOT_BUDGET = 60.0  # reading and projecting a (mutated) robot, memoised per text
ROBOT_FILES = sorted(ROBOTS.glob("*.yaml"))
TRAJECTORY_FILES = sorted(TRAJECTORIES.glob("*.yaml"))
COUNTS: Counter = Counter()


def _report() -> None:
    target = os.environ.get("SINGCHECK_FUZZ_REPORT")
    if target and COUNTS:
        Path(target).write_text(json.dumps(dict(sorted(COUNTS.items())), indent=1) + "\n")


atexit.register(_report)

FUZZ = settings(max_examples=EXAMPLES, deadline=None, database=None, derandomize=False,
                suppress_health_check=list(HealthCheck), print_blob=True)


# -- running one case --------------------------------------------------------------------


@pytest.fixture(scope="module", autouse=True)
def private_cache(tmp_path_factory):
    """One cache for the whole run: robots that differ only in bytes that do not matter
    (a comment, a space) share their projection and region maps, as on disk for users."""
    directory = tmp_path_factory.mktemp("fuzz-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SINGCHECK_CACHE_DIR", str(directory / "cache"))
        mp.setenv("XDG_CONFIG_HOME", str(directory / "config"))
        yield



_ROBOTS: dict = {}


def _robot(text: str, path: str):
    """The robot (projection with the in-process FLINT backend), memoised by its text."""
    from singcheck import api
    from singcheck.budget import deadline
    from singcheck.spec.files import parse_robot

    if text not in _ROBOTS:
        if len(_ROBOTS) > 64:
            _ROBOTS.clear()
        try:
            with deadline(BUDGET * 2):
                _ROBOTS[text] = ("ok", api.robot_from_spec(parse_robot(text, path),
                                                           backend="flint", cache=True))
        except Exception as e:  # replayed below, inside the exit-code mapping
            _ROBOTS[text] = ("error", e)
    kind, value = _ROBOTS[text]
    if kind == "error":
        raise value
    return value


def outcome(robot_text: str, trajectory_text: str, csv: str | None = None) -> int:
    """The exit status ``singcheck run`` gives for this robot and trajectory (``csv``: a
    CSV table, interpolated linear or cubic), computed in-process: any exception the CLI
    would report as an internal error propagates (or, in a campaign, is recorded)."""
    try:
        return _outcome(robot_text, trajectory_text, csv)
    except Exception as e:
        if not os.environ.get("SINGCHECK_FUZZ_KEEP_GOING"):
            raise
        import traceback

        COUNTS["failures"] += 1
        where = traceback.extract_tb(e.__traceback__)[-1]
        _record("failures", {"error": f"{type(e).__name__}: {str(e)[:500]}",
                             "at": f"{where.filename}:{where.lineno}"},
                robot_text, trajectory_text, csv)
        return -1


def _record(kind: str, what: dict, robot_text: str, trajectory_text: str,
            csv: str | None) -> None:
    """One JSON line in ``SINGCHECK_FUZZ_REPORT.kind``: ``what``, the specs."""
    with open(os.environ["SINGCHECK_FUZZ_REPORT"] + "." + kind, "a") as f:
        f.write(json.dumps({**what, "robot": robot_text, "trajectory": trajectory_text,
                            "csv": csv}) + "\n")


def _exit_message(e: SystemExit) -> str:
    """What the error behind an exit said (exit 4's backend failure, exit 70's bug), for
    the campaign's failure record: the exception ``exit_codes`` turned into the exit."""
    cause = e.__context__ or e.__cause__
    return f"{type(cause).__name__}: {cause}"[:500] if cause is not None else ""


def _cpu() -> float:
    """CPU seconds of this process and its reaped children (the forks of a check)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


#: where each case's trajectory file is written (read back as the command line reads it)
CASE_DIR = Path(os.environ.get("SINGCHECK_FUZZ_DIR") or
                __import__("tempfile").mkdtemp(prefix="singcheck-fuzz-"))


def _outcome(robot_text: str, trajectory_text: str, csv: str | None = None) -> int:
    from singcheck import api
    from singcheck.budget import deadline
    from singcheck.cli.commands import _outcome as exit_of
    from singcheck.cli.commands import _worst
    from singcheck.cli.exitcodes import exit_codes
    from singcheck.report.trajectory import to_json, trajectory_json
    from singcheck.spec.files import read_documents

    start = time.monotonic()
    loaded = None
    code = None
    path = CASE_DIR / ("trajectory.csv" if csv else "trajectory.yaml")
    path.write_text(trajectory_text, encoding="utf-8")
    try:
        with exit_codes():
            machine = _robot(robot_text, "robot.yaml")
            loaded, cpu = time.monotonic(), _cpu()
            codes = []
            for document in read_documents([path], csv):  # as `singcheck run` reads it
                parsed = api.parse_within(document, machine.spec, BUDGET)  # bad: exit 2
                if parsed.spec is None:  # its time limit, while parsing
                    codes.append(3)
                    continue
                with deadline(BUDGET, parsed.seconds):  # parsing counts (as check_item)
                    report = api.check(machine, parsed.spec, time_limit=BUDGET,
                                       regions=REGIONS)
                doc = report.to_dict()
                to_json(doc)  # the report renders
                if report.certificate is not None:
                    trajectory_json(report.certificate)
                codes.append(exit_of(doc))
            code = int(_worst(codes))
    except SystemExit as e:
        code = int(e.code)
        why = _exit_message(e)
    else:
        why = ""
    end = time.monotonic()
    COUNTS[f"exit {code}"] += 1
    COUNTS["cases"] += 1
    if COUNTS["cases"] % 25 == 0:
        _report()
    assert code in (0, 1, 2, 3), f"{code}: {why}"
    if loaded is None:
        loaded, cpu = end, _cpu()
    past = int((end - loaded - BUDGET) * 1000)
    COUNTS["max ms past the limit"] = max(COUNTS["max ms past the limit"], past)
    assert loaded - start < ROBOT_BUDGET, f"robot: {loaded - start:.1f} s"
    used = _cpu() - cpu
    COUNTS["max ms of CPU past the limit"] = max(COUNTS["max ms of CPU past the limit"],
                                                 int((used - BUDGET) * 1000))
    if SHARED and end - loaded >= BUDGET + SLACK and used < BUDGET + SLACK:
        COUNTS["overruns of wall clock only"] += 1  # the scheduler's, not a checkpoint's
        _record("overruns", {"wall s": round(end - loaded, 2), "cpu s": round(used, 2)},
                robot_text, trajectory_text, csv)
        return code
    assert end - loaded < BUDGET + SLACK, \
        f"trajectory: {end - loaded:.1f} s ({used:.1f} s of CPU)"
    return code


# -- strategies ----------------------------------------------------------------------------

HOSTILE_LITERALS = ["0", "1", "0.5", "1e400", "1e-400", "1.0e+308", "9" * 200,
                    "0." + "0" * 90 + "1", "2147483648", "1e5000", "00012", "3.", ".5",
                    "1e999999999"]


@functools.cache
def numbers() -> st.SearchStrategy[str]:
    return st.one_of(st.integers(-1000, 1000).map(str),
                     st.tuples(st.integers(-99, 99), st.integers(1, 99)).map(
                         lambda q: f"{q[0]}/{q[1]}"),
                     st.decimals(-100, 100, places=3, allow_nan=False).map(str),
                     st.sampled_from(HOSTILE_LITERALS))


def expressions(names: list[str], parameter: str = "t") -> st.SearchStrategy[str]:
    """Expressions of singcheck's grammar over ``names`` (and some that are not); one
    strategy object per arguments (building a recursive strategy afresh for every draw
    was most of a structured case's generation time)."""
    return _expressions(tuple(names), parameter)


@functools.lru_cache(maxsize=256)
def _expressions(names: tuple[str, ...], parameter: str) -> st.SearchStrategy[str]:
    calls = st.tuples(st.sampled_from(["sin", "cos", "sqrt", "tan", "sin", "cos"]),
                      st.one_of(st.integers(-4, 4), st.integers(-300, 300))).map(
        lambda c: f"{c[0]}({c[1]}*{parameter})" if c[1] != 1 else f"{c[0]}({parameter})")
    usual = st.one_of(st.integers(-5, 5).map(str), st.sampled_from(["1/2", "3/7", "0.25"]),
                      st.sampled_from(list(names) or ["x"]), calls)
    atoms = st.one_of(usual, usual, usual, usual, numbers(),
                      st.sampled_from(["pi", "pi/2", "sqrt(2)", "x_unknown"]))

    def grow(inner):
        return st.one_of(
            st.tuples(inner, st.sampled_from(["+", "-", "*", "/"]), inner).map(
                lambda a: f"{a[0]} {a[1]} {a[2]}"),
            inner.map(lambda a: f"({a})"),
            inner.map(lambda a: f"-{a}"),
            st.tuples(inner, st.one_of(st.integers(0, 70).map(str),
                                       st.sampled_from(["1e5", "-1", "1/2", parameter]))).map(
                lambda a: f"({a[0]})^{a[1]}"),
            st.tuples(st.sampled_from(["sin", "cos"]), inner).map(lambda a: f"{a[0]}({a[1]})"),
        )

    plain = st.recursive(atoms, grow, max_leaves=8)
    deep = st.tuples(st.integers(1, 400), st.sampled_from(["(", "-", "sin(", "["])).map(
        lambda d: d[1] * d[0] + parameter + {"(": ")", "-": "", "sin(": ")", "[": "]"}[d[1]]
        * d[0])
    return st.one_of(plain, plain, plain, deep)


@functools.cache
def path_coordinates(parameter: str = "t") -> st.SearchStrategy[str]:
    """Coordinates like the bundled ones: a few terms c·sin(kt), c·cos(kt), c·tⁿ."""
    term = st.tuples(st.sampled_from(["1", "-1", "1/2", "3/7", "2", "-5/14", "0.1"]),
                     st.sampled_from([f"sin({parameter})", f"cos({parameter})",
                                      f"sin(2*{parameter})", f"cos(3*{parameter})",
                                      f"sin({parameter})^3", parameter, f"{parameter}^2",
                                      "1"])).map(lambda c: f"{c[0]}*{c[1]}")
    return st.lists(term, min_size=1, max_size=4).map(" + ".join)


def _yaml_scalar(text: str) -> str:
    return json.dumps(text, ensure_ascii=False)  # a JSON string is a YAML scalar


@functools.lru_cache(maxsize=256)
def _robot_pose(robot_text: str) -> list[str]:
    """The robot's pose variables (memoised: PyYAML's pure-Python loader took a quarter
    of a campaign's time on the same few texts)."""
    import yaml

    try:
        return [str(v) for v in yaml.load(robot_text, Loader=getattr(yaml, "CSafeLoader",
                                                                      yaml.SafeLoader))["pose"]]
    except Exception:
        return ["x", "y", "z"]


@st.composite
def structured_trajectories(draw, pose: list[str], angles: list[str] = ()) -> str:
    """A trajectory built key by key: generated coordinates and ranges, sometimes a key
    missing, an extra one, or a value of the wrong shape; a pose angle sometimes in
    degrees."""
    parameter = draw(st.sampled_from(["t"] * 12 + ["s", "x", "pi", "sin"]))
    names = [parameter]
    ends = st.one_of(st.sampled_from(["-pi", "pi", "0", "1", "-1", "2*pi", "-1000000",
                                      "1000000", "1e300", "pi/3", "-1/2", "0"]), numbers())
    doc = {"name": draw(st.sampled_from(["t1", "x", "", "a b", "path"])),
           "parameter": parameter,
           "range": f"[{draw(ends)}, {draw(ends)}]",
           "pose": {v: draw(st.one_of(path_coordinates(parameter),
                                      path_coordinates(parameter),
                                      expressions(names, parameter))) for v in pose}}
    for v in angles:  # an angle of the pose, sometimes in degrees
        if draw(st.integers(0, 2)) == 0:
            doc["pose"][v] = draw(st.one_of(
                st.sampled_from(DEGREES),
                st.tuples(path_coordinates(parameter), st.sampled_from(DEGREES)).map(
                    lambda a: f"{a[0]} + {a[1]}")))
    if draw(st.integers(0, 9)) == 0:
        doc.pop(draw(st.sampled_from(sorted(doc))))
    if draw(st.integers(0, 9)) == 0:
        doc["extra"] = "1"
    lines = []
    for key, value in doc.items():
        if key == "pose":
            lines.append("pose:")
            lines += [f"  {k}: {_yaml_scalar(v)}" for k, v in value.items()]
        elif key == "range":
            lines.append(f"range: {value}")
        else:
            lines.append(f"{key}: {_yaml_scalar(value)}")
    if draw(st.integers(0, 19)) == 0:
        lines.insert(draw(st.integers(0, len(lines))), "  " + "[" * draw(st.integers(1, 60)))
    return "\n".join(lines) + "\n"


def _robot_angles(robot_text: str, pose: list[str]) -> list[str]:
    """The pose variables that are angles (under a sin or cos in the robot's constraints:
    the 3-PRR's and 3-RPR's phi, the Gough-Stewart's psi, theta, phi)."""
    return [v for v in pose if f"cos({v})" in robot_text or f"sin({v})" in robot_text]


#: angles in degrees (`d deg` is d·π/180 exactly), some not multiples of π/12
DEGREES = ["0 deg", "30 deg", "-45 deg", "90 deg", "15 deg", "1.5 deg", "1/3 deg",
           "360 deg", "-720 deg", "7 deg"]


def _plain(text: str) -> str:
    """A number as a YAML flow value: as is when plain, else a quoted string."""
    import re

    return text if re.fullmatch(r"[-+]?[0-9./eE+]+", text) else _yaml_scalar(text)


@st.composite
def path_forms(draw, pose: list[str], angles: list[str] = ()) -> tuple[str, str | None]:
    """A path of pieces as people write them, with its ``csv`` interpolation (None: YAML):
    ``segments`` (straight lines through waypoints, so they join, or a generated
    coordinate that may jump), ``waypoints`` (linear or cubic) or a CSV table; numbers
    sometimes hostile, sometimes a time out of order, a cell missing or a stray one.
    The pose ``angles`` take degrees (``30 deg``) as often as radians, and one case in
    ten puts a degree on a length."""
    usual = st.sampled_from(["0", "1", "1/2", "-1/2", "3/4", "0.3", "2", "-1", "1/3",
                             "0.125", "5/7", "1.5", "0.61", "-0.2"])
    hostile = draw(st.integers(0, 5)) == 0  # one case in six: any number, hostile ones too
    value = st.one_of(usual, usual, usual, numbers()) if hostile else usual
    degrees = st.one_of(usual, st.sampled_from(DEGREES))
    stray_degree = draw(st.integers(0, 9)) == 0
    values = {v: degrees if v in angles or stray_degree else value for v in pose}
    n = draw(st.integers(2, 7))
    times = [Fraction(0)]
    for _ in range(n - 1):
        times.append(times[-1] + Fraction(draw(st.sampled_from(["1", "1/2", "2", "1/3",
                                                                 "0.25", "10", "1/1000"]))))
    times_text = [str(t) for t in times]
    if draw(st.integers(0, 19)) == 0:  # a time out of order
        i = draw(st.integers(0, n - 2))
        times_text[i], times_text[i + 1] = times_text[i + 1], times_text[i]
    if hostile and draw(st.booleans()):
        times_text[draw(st.integers(0, n - 1))] = draw(numbers())
    rows = [{v: draw(values[v]) for v in pose} for _ in range(n)]
    form = draw(st.sampled_from(["segments", "waypoints", "csv"]))
    if form == "csv":
        columns = list(pose)
        if draw(st.integers(0, 14)) == 0:
            columns.pop(draw(st.integers(0, len(columns) - 1)))
        lines = [",".join(["t", *columns])]
        for t, row in zip(times_text, rows, strict=True):
            cells = [t, *(row[v] for v in columns)]
            if draw(st.integers(0, 29)) == 0:
                cells.append(draw(value))
            lines.append(",".join(cells))
        return "\n".join(lines) + "\n", draw(st.sampled_from(["linear", "cubic"]))
    name = _yaml_scalar(draw(st.sampled_from(["p", "../p", "a/b", "p q", "δ"])))
    if form == "waypoints":
        lines = [f"name: {name}", "parameter: t",
                 f"interpolation: {draw(st.sampled_from(['linear', 'cubic']))}",
                 "waypoints:"]
        lines += ["  - {" + ", ".join([f"t: {_plain(t)}", *(f"{v}: {_plain(row[v])}"
                                                            for v in pose)]) + "}"
                  for t, row in zip(times_text, rows, strict=True)]
        return "\n".join(lines) + "\n", None
    lines = [f"name: {name}", "parameter: t", "segments:"]
    for i in range(n - 1):
        t0, t1 = times_text[i], times_text[i + 1]
        coordinates = {}
        for v in pose:
            y0, y1 = rows[i][v], rows[i + 1][v]
            coordinates[v] = (draw(path_coordinates()) if draw(st.integers(0, 9)) == 0 else
                              f"({y0}) + (({y1}) - ({y0}))*(t - ({t0}))/(({t1}) - ({t0}))")
        lines.append(f"  - range: [{_plain(t0)}, {_plain(t1)}]")
        lines.append("    pose: {" + ", ".join(f"{v}: {_yaml_scalar(c)}"
                                              for v, c in coordinates.items()) + "}")
    return "\n".join(lines) + "\n", None


@st.composite
def mutated_robots(draw) -> str:
    """A bundled robot, sometimes with a parameter, a limit or a constraint changed."""
    text = draw(st.sampled_from(ROBOT_FILES)).read_text()
    kind = draw(st.integers(0, 5))
    if kind == 0:  # a parameter or a number changed
        for old in ("l: 2", "l1: 2", "9/4", "[0, 4]", "[-4, 4]", "[-1, 4]"):
            if old in text:
                new = draw(st.sampled_from(["l: 0", "l: -1", "l: 10^100", "9/4000000",
                                            "[0, 1e100]", "[4, 4]", "[1/3, 1/2]",
                                            "(2147483648-364349)^8"]))
                return text.replace(old, new, 1)
    if kind == 1:  # a constraint replaced by a generated polynomial
        lines = text.splitlines()
        index = [i for i, line in enumerate(lines) if line.strip().startswith("- (")]
        if index:
            names = ["x", "y", "z", "rho1", "rho2", "rho3", "p", "q", "l", "l1", "l2"]
            lines[draw(st.sampled_from(index))] = \
                "  - " + _yaml_scalar(draw(expressions(names, "x")))
            return "\n".join(lines) + "\n"
    return text


@st.composite
def byte_mutations(draw, text: str) -> str:
    """A spec with bytes flipped, inserted, deleted or a slice repeated (decoded as
    UTF-8 with replacement, as a hostile file would be read)."""
    data = bytearray(text.encode())
    for _ in range(draw(st.integers(1, 6))):
        op = draw(st.integers(0, 3))
        if not data:
            break
        at = draw(st.integers(0, len(data) - 1))
        if op == 0:
            data[at] = draw(st.integers(0, 255))
        elif op == 1:
            data[at:at] = draw(st.sampled_from([b"[", b"(", b"-", b"^99", b"e999", b"*t",
                                                b"\n", b": ", b"&a ", b"*a", b"!!python",
                                                b"\t", b"9" * 50, b"\x00"]))
        elif op == 2:
            del data[at:at + draw(st.integers(1, 20))]
        else:
            end = min(len(data), at + draw(st.integers(1, 40)))
            data[at:at] = bytes(data[at:end]) * draw(st.integers(2, 30))
    return data.decode("utf-8", errors="replace")


# -- the properties -----------------------------------------------------------------------


@pytest.mark.slow
@FUZZ
@given(st.data())
def test_structured_and_grammar_trajectories_end_with_exit_0_to_3(data):
    robot_text = data.draw(mutated_robots())
    pose = _robot_pose(robot_text)
    trajectory_text = data.draw(structured_trajectories(pose, _robot_angles(robot_text, pose)))
    outcome(robot_text, trajectory_text)


@pytest.mark.slow
@FUZZ
@given(st.data())
def test_byte_mutated_specs_end_with_exit_0_to_3(data):
    # (the stacked Orthoglide's projection takes seconds: not once per mutated byte)
    robot_file = data.draw(st.sampled_from([p for p in ROBOT_FILES if "stacked" not in
                                            p.name]))
    robot_text = robot_file.read_text()
    fitting = [p for p in TRAJECTORY_FILES if (p.name.startswith("skew") ==
                                               robot_file.name.startswith("skew")
                                               and p.name.startswith("biglide") ==
                                               robot_file.name.startswith("biglide")
                                               and p.name.startswith("stacked") ==
                                               robot_file.name.startswith("stacked"))]
    trajectory_text = data.draw(st.sampled_from(fitting or TRAJECTORY_FILES)).read_text()
    if data.draw(st.booleans()):
        trajectory_text = data.draw(byte_mutations(trajectory_text))
    else:
        robot_text = data.draw(byte_mutations(robot_text))
    outcome(robot_text, trajectory_text)


@pytest.mark.slow
@FUZZ
@given(st.data())
def test_paths_of_pieces_end_with_exit_0_to_3(data):
    """Segments, waypoints and CSV tables on every bundled robot — planar and spatial,
    prismatic and revolute legs, a pose angle (3-PRR, 3-RPR), three (Gough-Stewart), the
    stacked Orthoglide (its projection read once per process) — angles in radians or
    degrees."""
    robot_file = data.draw(st.sampled_from(ROBOT_FILES))
    robot_text = robot_file.read_text()
    pose = _robot_pose(robot_text)
    text, csv = data.draw(path_forms(pose, _robot_angles(robot_text, pose)))
    outcome(robot_text, text, csv)


def test_the_fuzzed_path_forms_cover_every_robot_class_and_unit():
    """The properties above draw from every bundled robot and write each path form
    (segments, waypoints, CSV) with angles in degrees: kept so when robots are added."""
    from hypothesis import find

    classes = {"planar": "five-bar", "spatial": "orthoglide", "revolute": "rotary-delta",
               "one angle": "3-rpr", "three angles": "gough-stewart",
               "stacked": "stacked-orthoglide"}
    assert {p.stem for p in ROBOT_FILES} >= set(classes.values())
    assert _robot_angles((ROBOTS / "gough-stewart.yaml").read_text(),
                         ["x", "psi", "theta", "phi"]) == ["psi", "theta", "phi"]
    pose = ["x", "y", "phi"]
    for form in ("segments:", "waypoints:"):
        text, csv = find(path_forms(pose, ["phi"]),
                         lambda c, form=form: form in c[0] and " deg" in c[0])
        assert csv is None
    text, csv = find(path_forms(pose, ["phi"]), lambda c: c[1] is not None and " deg" in c[0])
    assert text.startswith("t,x,y,phi") or text.startswith("t,")


CLI_SAMPLE = [
    # (robot file, trajectory text): hostile shapes from each finding class
    ("orthoglide", "name: a\nparameter: t\nrange: [0, 1]\npose:\n  x: " + "(" * 300 + "t"
     + ")" * 300 + "\n  y: 0\n  z: 1\n"),
    ("orthoglide", "name: a\nparameter: t\nrange: [0, 1]\npose:\n  x: 1e999999999\n  y: 0\n"
     "  z: 1\n"),
    ("orthoglide", "name: a\nparameter: t\nrange: [0, 1]\npose: " + "[" * 1000 + "\n"),
    ("orthoglide", "name: a\nparameter: t\nrange: [-pi, pi]\npose:\n  x: 8/7*sin(t)^3\n"
     "  y: 13/14*cos(t) - 5/14*cos(2*t)\n  z: 1\n"),
    ("skew-biglide", "name: b\nparameter: t\nrange: [0, 1]\npose:\n  x: (t+1)^2\n  y: -t\n"),
]


@pytest.mark.slow
@pytest.mark.parametrize("robot, text", CLI_SAMPLE)
def test_fuzzed_specs_through_the_command_line(tmp_path, robot, text):
    spec = tmp_path / "t.yaml"
    spec.write_text(text)
    out = subprocess.run([sys.executable, "-m", "singcheck", "run", str(ROBOTS / f"{robot}.yaml"),
                          str(spec), "--backend", "flint", "--no-cache"], capture_output=True,
                         text=True, cwd=ROOT, timeout=120,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert out.returncode in (0, 1, 2, 3), out.stderr
    assert "Traceback" not in out.stderr
    if out.returncode == 2:
        assert out.stderr.count("\n") == 1
