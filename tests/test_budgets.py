"""Every stage has a budget (issue 16): a costly step is refused up front (exit 2, one
line) or stops at the time limit within a bounded overrun (exit 3, ``unknown: time
limit``) — composing ξ with a path, eliminating along a path, and the workspace and
joint-space decompositions."""

from __future__ import annotations

import re
import time

import pytest

from singcheck import api
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_hardening import (  # noqa: F401
    BIG_CONSTANT,
    cache_env,
    run_cli,
    trajectory,
)

STACKED = ROBOTS / "stacked-orthoglide.yaml"
#: each coordinate a cube: ξ (57,855 terms) composed with it took 4 s of CPU in one
#: uninterruptible FLINT call, and overran a 2 s time limit by 6-10 s
CUBES = {"x1": "(sin(t)+cos(t)+t)^3", "y1": "(sin(t)-cos(t)+t/2)^3",
         "z1": "(sin(t)+2*cos(t)-t)^3", "x2": "(sin(t)+cos(t)+3*t)^3",
         "y2": "(3*sin(t)+cos(t)+t)^3", "z2": "(sin(t)+cos(t)+t/7)^3"}


@pytest.fixture(scope="module")
def stacked():
    return api.load_robot(STACKED, backend="flint", cache=False)


def assert_stops(machine, spec_file: str, limit: float, within: float) -> None:
    """The check ends ``unknown: time limit`` having used less than ``within`` seconds of
    CPU (a run that went on past its checkpoints would use the whole computation's CPU;
    CPU time, unlike the wall clock, does not grow when other processes load the
    machine, which made this flaky), and within four times that of wall clock.  The
    exact engine alone: these are its stages (``auto`` may answer by intervals first)."""
    spec = api.load_trajectory(spec_file, machine)
    start, cpu = time.monotonic(), time.process_time()
    report = api.check(machine, spec, time_limit=limit, regions=False, engine="exact")
    elapsed, used = time.monotonic() - start, time.process_time() - cpu
    assert report.verdict == "unknown" and "time limit" in report.reason
    assert used < within, used
    assert elapsed < 4 * within, elapsed


# -- composing ξ with the path ------------------------------------------------------------


def _coordinates(*texts):
    from singcheck.spec.grammar import compile_trajectory_coordinate, parse

    return tuple(compile_trajectory_coordinate(parse(text), "t", {}) for text in texts)


@pytest.mark.parametrize("piece_work, piece_pairs", [(1, 1), (2_000, 50), (10**5, 10**3)])
def test_composition_in_pieces_is_the_one_call_composition(orthoglide_projection, monkeypatch,
                                                           piece_work, piece_pairs):
    """Horner's scheme with every intermediate reduced gives exactly FLINT's one-call
    composition, reduced modulo s² + c² - 1 (and it reaches the checkpoint)."""
    from singcheck.algebra import composition
    from singcheck.algebra.trig import TRIG, reduce_trig
    from singcheck.certify.path import compose_pose

    calls = []
    monkeypatch.setattr(composition, "PIECE_WORK", piece_work)
    monkeypatch.setattr(composition, "PIECE_PAIRS", piece_pairs)
    monkeypatch.setattr(composition, "checkpoint", lambda: calls.append(1))
    xi = orthoglide_projection.singularity_surface
    phi = _coordinates("(sin(t) + cos(t) + t)^3", "t^2 - 3/7*sin(2*t)", "1 + cos(t)/5")
    expected = reduce_trig(xi.compose(*phi, ctx=TRIG))
    assert compose_pose(xi, phi, ("x", "y", "z")) == expected
    assert len(calls) > 10


def test_a_costly_composition_stops_at_the_time_limit(stacked, tmp_path, cache_env):  # noqa: F811
    """The stacked Orthoglide with cubes: stopped within the limit and a bounded overrun
    (before: one FLINT call ran 6-10 s past a 2 s limit)."""
    assert_stops(stacked, trajectory(tmp_path, CUBES), limit=2, within=4)


def test_a_composition_beyond_the_work_bound_is_refused_up_front(stacked, tmp_path):
    """Coefficients of hundreds of digits: μ would have few terms but huge coefficients;
    refused (a spec error: one line, exit 2) with the estimate and the bound, at once."""
    from singcheck.algebra.composition import MAX_COMPOSE_WORK
    from singcheck.errors import SpecError

    big = "(12345678901234567890123456789/98765432109876543210987654321)"
    pose = {v: f"{big}^{k}*(sin(t) + cos(t) + t)^3"
            for v, k in zip(stacked.model.pose, (20, 19, 18, 17, 16, 15), strict=True)}
    spec = api.load_trajectory(trajectory(tmp_path, pose), stacked)
    start = time.monotonic()
    with pytest.raises(SpecError) as refused:  # the exact engine's refusal (auto: intervals)
        api.check(stacked, spec, time_limit=60, regions=False, engine="exact")
    assert time.monotonic() - start < 2
    message = str(refused.value)
    assert "too costly" in message and "\n" not in message
    assert f"at most {MAX_COMPOSE_WORK:.3g}" in message
    estimate = float(re.search(r"would cost ([0-9.e+]+)", message).group(1))
    assert estimate > MAX_COMPOSE_WORK


# -- workspace and joint space ------------------------------------------------------------


@pytest.mark.parametrize("space, robot, limit", [("workspace", "orthoglide", "1"),
                                                 ("jointspace", "big-constant", "0.3")])
def test_space_analyses_stop_at_the_time_limit_and_write_nothing(
        tmp_path, monkeypatch, capsys, cache_env, space, robot, limit):  # noqa: F811
    """The Orthoglide's 3-D workspace takes seconds without a limit, the big-constant
    joint space about 0.9 s since the exact plane adjacency got faster; with a smaller
    --time-limit they end with exit 3, one line naming the limit, and no -o file."""
    if robot == "big-constant":
        path = tmp_path / "big.yaml"
        path.write_text(BIG_CONSTANT)
    else:
        path = ROBOTS / f"{robot}.yaml"
    target = tmp_path / "out.json"
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, space, str(path), "--backend", "flint",
                             "-q", "--time-limit", limit, "--format", "json", "-o", str(target))
    elapsed = time.monotonic() - start
    assert code == 3, err
    assert err.count("\n") == 1 and f"unknown: time limit ({limit} s)" in err, err
    assert not target.exists() and out == ""
    assert elapsed < 4, elapsed


def test_space_commands_state_their_time_limit():
    from click.testing import CliRunner

    from singcheck.cli.spaces import jointspace, workspace

    for command in (workspace, jointspace):
        result = CliRunner().invoke(command, ["--help"])
        assert result.exit_code == 0
        text = " ".join(result.output.split())
        option = text[text.index("--time-limit FLOAT"):text.index("--format [")]
        assert "past it the command ends with exit 3" in option
        assert option.endswith("[default: 300; x>0] ")


# -- eliminating the joints along a path --------------------------------------------------

ROTARY = ROBOTS / "rotary-delta.yaml"  # revolute legs and √3: ξ(X) is not expanded


@pytest.fixture(scope="module")
def rotary():
    machine = api.load_robot(ROTARY, backend="flint", cache=False)
    assert not machine.projection.expanded
    return machine


def test_a_hostile_path_wise_elimination_is_refused_up_front(rotary, tmp_path):
    """High harmonics mixed with t: the bound on the norm chain's intermediates is over
    its limit, so the path is refused at once (it ran 25 s to over 100 s before)."""
    from singcheck.errors import SpecError

    pose = {"x": "cos(6*t)/2", "y": "sin(5*t)/2", "z": "-2 + t/10"}
    spec = api.load_trajectory(trajectory(tmp_path, pose), rotary)
    start = time.monotonic()
    with pytest.raises(SpecError) as refused:  # the exact engine's refusal (auto: intervals)
        api.check(rotary, spec, time_limit=60, regions=False, engine="exact")
    assert time.monotonic() - start < 2
    message = str(refused.value)
    assert "too costly" in message and "eliminating the joints along the path" in message


def test_a_costly_path_wise_elimination_stops_at_the_time_limit(rotary, tmp_path):
    """cos 12t, sin 11t: within the bound, about 1.4 s of CPU here of norms before μ's
    degree is refused; a 0.2 s limit stops it at a checkpoint inside the chain (0.21 s
    of CPU here), not after it: at most 0.6 s of CPU.  The longest step between two
    checkpoints is now one squarefree factorization (0.19 s here); before, one square of
    the last revolute norm (0.25 s here) and a squarefree split ran with no checkpoint
    between them, and CI stopped at 0.64 s."""
    pose = {"x": "cos(12*t)/2", "y": "sin(11*t)/2", "z": "-2"}
    assert_stops(rotary, trajectory(tmp_path, pose), limit=0.2, within=0.6)


@pytest.mark.parametrize("limit, code, verdict", [
    ("0.2", 3, "verdict unknown: time limit (0.2 s) reached"),
    ("60", 2, "verdict error: "),
])
def test_a_path_stopped_before_its_roots_claims_no_candidate_list(
        monkeypatch, capsys, tmp_path, cache_env, limit, code, verdict):  # noqa: F811
    """Stopped by its time limit (exit 3) or refused as too costly (exit 2) before μ's
    roots were isolated, the console report says that nothing is certified: not that μ
    has no real root, no isolation method, no empty working-mode table, and the verdict
    once."""
    pose = {"x": "cos(12*t)/2", "y": "sin(11*t)/2", "z": "-2"}
    status, out, _ = run_cli(monkeypatch, capsys, "run", str(ROTARY), trajectory(tmp_path, pose),
                             "--backend", "flint", "--time-limit", limit, "--engine", "exact")
    assert status == code
    assert "not certified: the check ended before the real roots of μ(t) were isolated" in out
    assert verdict in out and "error: error" not in out and "unknown: unknown" not in out
    assert "no candidate" not in out and "roots by" not in out and "working modes" not in out


@pytest.mark.parametrize("reduce", ["identity", "circle"])
def test_a_product_in_slices_is_the_product_and_stops_between_slices(monkeypatch, reduce):
    """Random dense polynomials in (a, s, c): the sliced product (as the path-wise
    revolute norms and the composition take it) equals x·y (or its remainder modulo
    s² + c² - 1, computed here by FLINT's own division) for slices of every size, with a
    checkpoint before each slice."""
    import random

    from flint import fmpq_mpoly_ctx

    from singcheck.algebra import composition

    ctx = fmpq_mpoly_ctx.get(("a", "s", "c"), "lex")
    rng = random.Random(7)
    x, y = (ctx.from_dict({(i, j, k): rng.randrange(-99, 100) for i in range(4)
                           for j in range(3) for k in range(3)}) for _ in range(2))
    a, s, c = ctx.gens()
    circle = s * s + c * c - 1
    red = (lambda p: p) if reduce == "identity" else (lambda p: divmod(p, circle)[1])
    expected = red(x * y)
    for pairs in (1, 7, len(x), 5 * len(x), len(x) * len(y)):
        assert composition.multiply_in_pieces(x, y, red, pairs) == expected, pairs
    calls = []
    monkeypatch.setattr(composition, "checkpoint", lambda: calls.append(1))
    composition.multiply_in_pieces(x, y, red, 2 * len(x))
    assert len(calls) == 1 + (len(y) + 1) // 2  # one before the product, one per slice


@pytest.mark.parametrize("robot, pose", [
    ("orthoglide", ("8/7*sin(t)^3", "13/14*cos(t) - 5/14*cos(2*t)", "1 + t/3")),
    ("orthoglide", ("t^2 - sin(t)", "cos(3*t)", "t")),
    ("skew-biglide", ("2*cos(t) + t/2", "sin(2*t)")),
])
def test_the_path_wise_size_bound_bounds_mu(robot, pose):
    """The a-priori degrees hold for μ computed both ways: eliminated along the path,
    and ξ(φ(t)) composed from the expanded ξ."""
    from singcheck.algebra.trig import TRIG
    from singcheck.certify.path import compose_pose, eliminate_along_path, pathwise_size_bound

    machine = api.load_robot(ROBOTS / f"{robot}.yaml", backend="flint", cache=False)
    phi = _coordinates(*pose)
    deg_t, deg_sc, _ = pathwise_size_bound(machine.model, phi)
    for mu in (eliminate_along_path(machine.model, phi),
               compose_pose(machine.singularity_surface, phi, machine.model.pose)):
        assert mu.context() is TRIG
        assert mu.degrees()[0] <= deg_t and mu.degrees()[1] + mu.degrees()[2] <= deg_sc


def test_plot_stops_at_the_time_limit_and_draws_nothing_for_that_figure(
        tmp_path, monkeypatch, capsys, cache_env):  # noqa: F811
    """plot bounds its region analysis as the space commands do (the big-constant joint
    space takes about 0.9 s without a limit): exit 3, one line naming the limit, no figure."""
    path = tmp_path / "big.yaml"
    path.write_text(BIG_CONSTANT)
    out_dir = tmp_path / "figures"
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "plot", str(path), "--regions",
                             "jointspace", "--out", str(out_dir), "--backend", "flint",
                             "-q", "--time-limit", "0.3")
    elapsed = time.monotonic() - start
    assert code == 3, err
    assert "unknown: time limit (0.3 s)" in err and "no figure" in err, err
    assert out == "" and not list(out_dir.glob("*.png"))
    assert elapsed < 4, elapsed


def test_plot_states_its_time_limit():
    from click.testing import CliRunner

    from singcheck.cli.commands import plot

    text = CliRunner().invoke(plot, ["--help"], terminal_width=100).output
    assert "--time-limit" in text and "exit 3" in text


@pytest.mark.parametrize("plain", [True, False])
def test_reading_a_large_polynomial_stops_at_the_time_limit(plain):
    """A cached ξ of many terms is read by a Python loop: it checks the deadline, so an
    expired limit stops it (both readers: the cache's own form and the general one)."""
    from flint import fmpq_mpoly_ctx

    from singcheck.budget import TimeLimitExceeded, deadline
    from singcheck.elimination.cas.polytext import CHECK_EVERY, parse_polynomial

    ctx = fmpq_mpoly_ctx.get(("x", "y"), "lex")
    sep = "+" if plain else " + "
    text = sep.join(f"{k}*v1^{k}*v2" for k in range(1, 3 * CHECK_EVERY))
    assert parse_polynomial(text, ctx).coeffs()[-1] == 1  # reads whole without a limit
    with deadline(1e-9):
        time.sleep(1e-3)
        with pytest.raises(TimeLimitExceeded):
            parse_polynomial(text, ctx)


def test_a_six_axis_workspace_is_decomposed_once_sliced_to_three(tmp_path, monkeypatch,
                                                                 capsys, cache_env):  # noqa: F811
    """The stacked Orthoglide's 6-D workspace is refused up front (one line, exit 2,
    naming --slice); with three axes sliced it is a 3-D decomposition like any other,
    bounded by --time-limit."""
    robot = str(ROBOTS / "stacked-orthoglide.yaml")
    code, out, err = run_cli(monkeypatch, capsys, "workspace", robot, "--backend", "flint",
                             "-q")
    assert code == 2 and "6 free axes" in err and "--slice" in err, err
    assert err.count("\n") == 1 and out == ""
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "workspace", robot, "--backend", "flint",
                             "-q", "--time-limit", "1", "--slice", "x2=0", "--slice", "y2=0",
                             "--slice", "z2=0")
    assert code == 3 and "unknown: time limit (1 s)" in err, err
    assert time.monotonic() - start < 15  # the projection (cached after) and the limit


def test_the_exact_zeros_at_multiples_of_pi_stop_at_the_time_limit():
    """Found by the campaign: over [6.912, 2^31] the branch-and-bound tests each of the
    683 million multiples of π for an exact zero, with no check of the time limit (a
    fuzz case ran 15 minutes past its 2 s). Over [0, 3·10^6] (a million multiples: 2.7 s
    past a 0.5 s deadline before, without noticing it) the deadline now stops it where
    every multiple is a zero (sin t), and a function that vanishes at none of them
    (decided once per parity of k: p(t, 0, ±1) ≢ 0) is done at once."""
    from fractions import Fraction

    from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange
    from singcheck.budget import TimeLimitExceeded, deadline
    from singcheck.roots.branch_bound import _exact_zeros

    t, s, c = TRIG.gens()
    interval = TimeRange(LinearInPi(Fraction(0), Fraction(0)),
                         LinearInPi(Fraction(3 * 10**6), Fraction(0)))
    start = time.monotonic()
    with deadline(0.5), pytest.raises(TimeLimitExceeded):
        _exact_zeros(s * (t + 1), interval)  # a zero at each of the million multiples
    assert time.monotonic() - start < 3
    start = time.monotonic()
    with deadline(0.5):  # never 0 at t = kπ (s = 0 there): nothing to find
        assert _exact_zeros(t / 10 + s + 2, interval) == []
    assert time.monotonic() - start < 0.1
    few = TimeRange(LinearInPi(Fraction(-7), Fraction(0)), LinearInPi(Fraction(10), Fraction(0)))
    assert [k for k, *_ in _exact_zeros(t * (c - 1), few)] == [-2, 0, 2]  # even k only
    assert [(k, m) for k, m, *_ in _exact_zeros(t * s, few)] == \
        [(-2, 1), (-1, 1), (0, 2), (1, 1), (2, 1), (3, 1)]


def test_a_costly_leg_is_refused_up_front_though_legs_compose_lazily(orthoglide_projection,
                                                                      monkeypatch):
    """Legs enclosed from the pose are composed along the path only on first use; the
    refusal of a composition beyond the work bound still comes when the path is built
    (one line, "too costly"), not in the middle of a proof.  With the bound at 0 (and
    μ composed as usual), every non-constant leg coefficient is over it."""
    import singcheck.certify.path as P
    from singcheck.errors import SpecError
    from singcheck.spec.files import load_trajectory

    spec = load_trajectory(ROBOTS.parent / "trajectories" / "heart1.yaml",
                           orthoglide_projection.model.spec)
    mu = P.build_path(orthoglide_projection, spec).mu  # with the real bound
    monkeypatch.setattr(P, "_compose_mu", lambda *args: mu)
    monkeypatch.setattr(P, "MAX_COMPOSE_WORK", 0)
    monkeypatch.setattr(P, "PIECE_WORK", 0)
    with pytest.raises(SpecError) as refused:
        P.build_path(orthoglide_projection, spec)
    message = str(refused.value)
    assert "too costly: a leg's constraint along the path" in message and "\n" not in message


def test_the_region_statement_never_holds_the_verdict(monkeypatch):
    """Past its own budget the region statement is left out, with the reason and how to
    ask for it; the verdict is the one certified (heart 1: singular).  With
    ``regions="wait"`` it is computed within the trajectory's time limit."""
    robot = api.load_robot(ROBOTS / "orthoglide.yaml", backend="flint", cache=False)
    traj = api.load_trajectory(TRAJECTORIES / "heart1.yaml", robot)
    monkeypatch.setenv("SINGCHECK_REGION_BUDGET", "0.000001")
    hurried = api.check(robot, traj, time_limit=120)
    assert hurried.verdict == "singular" and hurried.workspace is None
    assert "workspace region not computed: its own budget" in hurried.to_dict()["reason"]
    assert "--regions waits for it" in hurried.to_dict()["reason"]
    waited = api.check(robot, traj, time_limit=120, regions="wait")
    assert waited.verdict == "singular" and waited.workspace is not None


def test_a_slow_call_in_a_fork_stops_at_the_deadline():
    """``until_deadline``: a call its caller thinks may be slow runs in a fork that the
    deadline kills (the worded ``time limit`` of a checkpoint, well under 1 s late); a
    cheap one, or one without a deadline, runs here."""
    from singcheck.budget import TimeLimitExceeded, deadline
    from singcheck.elimination.cas.forked import until_deadline

    start = time.monotonic()
    with deadline(0.3), pytest.raises(TimeLimitExceeded, match=r"time limit \(0.3 s\)"):
        until_deadline(time.sleep, 30, "a sleep", costly=True)
    assert time.monotonic() - start < 0.3 + 0.5
    here = []
    with deadline(5):
        assert until_deadline(lambda x: here.append(x) or 2 * x, 21, "cheap", False) == 42
    assert here == [21]  # ran in this process
    assert until_deadline(lambda x: here.append(x) or x, 1, "no deadline", True) == 1
    assert here == [21, 1]
    with deadline(5):  # a slow one comes back through the pipe, exceptions too
        assert until_deadline(lambda x: here.append(x) or x + 1, 1, "forked", True) == 2
        with pytest.raises(ZeroDivisionError):
            until_deadline(lambda x: 1 / x, 0, "forked", True)
    assert here == [21, 1]  # the forked call appended in the child only


@pytest.mark.parametrize("where", ["norm_chain", "through_norm"])
def test_the_norm_steps_on_large_polynomials_run_where_the_deadline_stops_them(
        monkeypatch, where):
    """Issue 31: the path-wise norm chain's squarefree parts (1.2 s on a rotary Delta
    cubic path) and the factorization of μ's norm over sin t (17.9 s on a stacked
    Orthoglide path) were single FLINT calls past a 2 s limit.  Each step on a
    polynomial that ``may_be_slow`` goes through ``until_deadline`` as costly, and the
    answers are those of the calls made here."""
    from flint import fmpq_mpoly_ctx

    from singcheck.algebra.polynomials import may_be_slow
    from singcheck.budget import deadline
    from singcheck.elimination.cas import forked
    from singcheck.elimination.requests import norm_chain

    calls = _spied_forks(monkeypatch)
    ring = fmpq_mpoly_ctx.get(("r", "t", "s", "c"), "lex")
    r, t, s, c = ring.gens()
    if where == "norm_chain":
        g = (r * t + s + c) ** 2 * (r - t) * ((t + s + 1) ** 40 + c * t ** 3)
        assert may_be_slow(g) and not may_be_slow(r - t)
        with deadline(60):
            fast = norm_chain(g, [("r", r * r - t * s - 1)])
        monkeypatch.setattr(forked, "until_deadline", lambda fn, a, w, c: fn(a))
        assert fast == norm_chain(g, [("r", r * r - t * s - 1)])
    else:
        from fractions import Fraction

        from singcheck.algebra.trig import TRIG, LinearInPi, TimeRange, reduce_trig
        from singcheck.roots.isolation import _through_norm

        t, s, c = TRIG.gens()
        p = reduce_trig(((t - s) ** 2 + c * t ** 5 - c) * ((t + 3) ** 60 - s * c * t ** 40))
        with deadline(60):
            _through_norm(p, TimeRange(LinearInPi(Fraction(0)),
                                         LinearInPi(Fraction(1))), 1e-9)
    assert any(costly for _, costly in calls), calls


def _dense_like(nvars: int, terms: int, degree: int, bits: int, seed: int = 1):
    """A random polynomial of ``terms`` terms, largest degree ``degree`` (one variable
    reaches it) and coefficients of ``bits`` bits: the shape of a norm chain's step,
    without its cost (nothing is factored here)."""
    import random

    from flint import fmpq_mpoly_ctx

    rng = random.Random(seed)
    ctx = fmpq_mpoly_ctx.get(tuple(f"v{i}" for i in range(nvars)), "lex")
    monomials = {(degree,) + (0,) * (nvars - 1)}
    while len(monomials) < terms:
        monomials.add(tuple(rng.randint(0, degree) for _ in range(nvars)))
    return ctx.from_dict({m: rng.getrandbits(bits) | 1 << (bits - 1) for m in monomials})


@pytest.mark.parametrize("nvars, terms, degree, bits, squarefree, slow", [
    # the shapes that took 0.1-0.4 s in one squarefree part (rotary Delta paths of
    # cubic waypoints, degree-6 polynomials, 4-6 harmonics; 1.2 s under load): forked
    (2, 3054, 156, 420, True, True),
    (4, 10585, 72, 180, True, True),
    (6, 8911, 10, 16, True, True),  # the smallest squarefree part over 50 ms (92 ms)
    # the rotary Delta circle's two squarefree parts (7 and 5 ms; a fork cost 20 and
    # 13 ms): in this process
    (5, 2326, 14, 39, True, False),
    (2, 377, 28, 108, True, False),
    # a factorization or resultant of the same size is not assumed as cheap
    (5, 2326, 14, 39, False, True),
    (2, 377, 28, 108, False, True),
    # a path written with 10^-91: thousand-digit coefficients make a small one costly
    (2, 377, 28, 3000, True, True),
])
def test_may_be_slow_flags_the_measured_slow_shapes(nvars, terms, degree, bits, squarefree,
                                                     slow):
    """``may_be_slow``'s calibration (bench/calibrate_slow.py): polynomials of the shapes
    measured, built at random (their calls are not run)."""
    from singcheck.algebra.polynomials import _height_bits, may_be_slow

    p = _dense_like(nvars, terms, degree, bits)
    assert len(p) == terms and max(p.degrees()) == degree and _height_bits(p) == bits
    assert may_be_slow(p, squarefree=squarefree) is slow


def test_the_rotary_delta_circle_runs_its_squarefree_parts_in_this_process(monkeypatch):
    """The free circle's norm chain forks no call (its two squarefree parts took 7 and 5
    ms here, a fork and its pickled result 20 and 13 ms); its verdict is unchanged."""

    calls = _spied_forks(monkeypatch)
    robot = api.load_robot(ROTARY, backend="flint", cache=False)
    spec = api.load_trajectory(TRAJECTORIES / "rotary-delta-free.yaml", robot)
    report = api.check(robot, spec, time_limit=300, regions=False)
    assert report.verdict == "singularity-free"
    assert any("squarefree part" in what for what, _ in calls)
    assert not any(costly for _, costly in calls), calls


@pytest.mark.slow
@pytest.mark.parametrize("limit", [0.3, 1.0, 2.0])
def test_a_costly_rotary_delta_path_stops_within_a_second_of_its_limit(rotary, tmp_path,
                                                                         limit):
    """Six harmonics: about 7.5 s of norm chain here (squarefree parts up to 52,000
    terms of degree 168, 0.2-0.4 s each, in forks; hundreds of smaller ones in this
    process) before μ's degree is refused.  Limits that cut it at different steps end
    it ``unknown: time limit`` within 1 s of wall clock past the limit: no step that
    ``may_be_slow`` let run here outlasts the deadline by more."""
    pose = {"x": "8/25*sin(t) + 6/25*cos(2*t) - 7/100*sin(3*t) - 13/50*sin(4*t)"
                 " + 11/100*cos(5*t) + cos(6*t)/50",
            "y": "3/20*sin(t) + 11/100*cos(2*t) - 17/100*cos(3*t) + 3/100*cos(4*t)"
                 " + sin(5*t)/5 - 39/100*cos(6*t)",
            "z": "-2 - 3/50*cos(t) - sin(2*t)/100"}
    spec = api.load_trajectory(trajectory(tmp_path, pose, "-pi, pi"), rotary)
    start = time.monotonic()
    report = api.check(rotary, spec, time_limit=limit, regions=False, engine="exact")
    elapsed = time.monotonic() - start
    assert report.verdict == "unknown" and "time limit" in report.reason
    assert elapsed < limit + 1, elapsed


def _spied_forks(monkeypatch) -> list[tuple[str, bool]]:
    """Every stoppable FLINT call from now on, as (what, costly), recorded as it runs."""
    from singcheck.elimination.cas import forked

    calls: list[tuple[str, bool]] = []
    real = forked.until_deadline

    def spy(fn, argument, what, costly):
        calls.append((what, costly))
        return real(fn, argument, what, costly)

    monkeypatch.setattr(forked, "until_deadline", spy)
    return calls
