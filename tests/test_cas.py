"""CAS backends in three stages: compiled scripts (golden), recorded output (parsed
offline), and live runs of Singular and Macaulay2 (marked; CI must run them)."""

from __future__ import annotations

import os
import random
import time
from pathlib import Path

import pytest
from flint import fmpq, fmpq_mpoly_ctx

from singcheck.algebra.polynomials import squarefree_part
from singcheck.elimination.cas.polytext import (
    PolynomialSyntaxError,
    format_polynomial,
    from_terms,
    parse_polynomial,
)
from singcheck.elimination.cas.process import BackendTimeout, run_program
from singcheck.elimination.cas.scripts import macaulay2_script, parse_result, singular_script
from singcheck.elimination.requests import EliminationRequest
from singcheck.errors import BackendError
from singcheck.model.robot import determinant

HERE = Path(__file__).parent
DATA = HERE / "data" / "cas"
GOLDEN = HERE / "golden"

CTX = fmpq_mpoly_ctx.get(("rho1", "rho2", "rho3", "x", "y", "z"), "lex")
r1, r2, r3, x, y, z = CTX.gens()
F = ((x - r1) ** 2 + y**2 + z**2 - 4, x**2 + (y - r2) ** 2 + z**2 - 4,
     x**2 + y**2 + (z - r3) ** 2 - 4)
DET_A = determinant(tuple(tuple(f.derivative(v) for v in "xyz") for f in F))
XI = EliminationRequest("singularity_surface", CTX, (*F, DET_A), ("rho1", "rho2", "rho3"))
POSE = fmpq_mpoly_ctx.get(("x", "y", "z"), "lex")
px, py, pz = POSE.gens()
SPHERE = px**2 + py**2 + pz**2 - 4


# -- compile -------------------------------------------------------------------------

@pytest.mark.parametrize("compile_, golden", [
    (singular_script, "orthoglide_xi.sing"),
    (macaulay2_script, "orthoglide_xi.m2"),
])
def test_generated_scripts_match_the_golden_files(compile_, golden):
    script = compile_(XI, "LIBRARY")
    assert script == (GOLDEN / golden).read_text()


def test_scripts_never_contain_floats_or_user_names():
    script = singular_script(XI, "LIBRARY")
    assert "rho" not in script and "." not in script.replace("LIBRARY", "")


# -- parse -----------------------------------------------------------------------------

def _recorded(name: str) -> str:
    return (DATA / name).read_text()


@pytest.mark.parametrize("cas, name", [("Singular", "singular_orthoglide_xi.out"),
                                       ("M2", "macaulay2_orthoglide_xi.out")])
def test_recorded_output_parses_to_the_papers_degree_18_surface(cas, name):
    (xi,) = parse_result(cas, _recorded(name), "", XI)
    assert xi.total_degree() == 18
    degrees = sorted((f.total_degree(), m) for f, m in xi.factor()[1])
    assert degrees == [(2, 2), (14, 1)]
    assert any(f == SPHERE for f, _ in xi.factor()[1])


GOOD = _recorded("singular_orthoglide_xi.out")
ERROR_OUTPUTS = {
    "error line": ("   ? `foo(1)` is undefined\n   ? error occurred in or before x.sing line 3\n"
                   + GOOD, "reported an error"),
    "no output": ("", "0 'begin' markers"),
    "truncated": (GOOD.split("@@singcheck-end")[0], "0 'end' markers"),
    "repeated marker": (GOOD + GOOD, "2 'begin' markers"),
    "count mismatch": (GOOD.replace("singularity_surface 1", "singularity_surface 2"),
                       "announced 2 polynomials but printed 1"),
    "garbage polynomial": (GOOD.replace("v4^10", "v4^^10", 1), "unreadable polynomial"),
    "unknown variable": (GOOD.replace("v4^10", "v9^10", 1), "unknown variable v9"),
    "joint left in": (GOOD.replace("v4^10", "v1^10", 1), "still involves an eliminated"),
    "stray text": ("// ** redefining i\n" + GOOD, "printed something unexpected"),
    "M2 error": ("t.m2:10:1:(3):[5]: error: no method for adjacent objects\n",
                 "reported an error"),
}


@pytest.mark.parametrize("case", sorted(ERROR_OUTPUTS))
def test_bad_output_is_a_backend_failure_quoting_it(case):
    stdout, phrase = ERROR_OUTPUTS[case]
    with pytest.raises(BackendError) as err:
        parse_result("Singular", stdout, "", XI)
    assert phrase in str(err.value)
    assert len(str(err.value)) < 400 and "\n" not in str(err.value)


def test_a_polynomial_of_many_thousand_terms_parses_exactly_and_fast():
    rng = random.Random(7)
    ctx = fmpq_mpoly_ctx.get(tuple(f"a{i}" for i in range(6)), "lex")
    # CAS output: large integer coefficients over a common denominator
    terms = {tuple(rng.randrange(12) for _ in range(6)): fmpq(rng.randrange(-10**30, 10**30), 7)
             for _ in range(20000)}
    p = from_terms(ctx, terms)
    text = format_polynomial(p)
    assert len(p) > 15000
    start = time.perf_counter()
    assert parse_polynomial(text, ctx) == p
    # generous: a linear parse takes well under a second here; a quadratic one minutes
    assert time.perf_counter() - start < 30


@pytest.mark.parametrize("text", ["v1+", "2*", "v1^", "(1/2*v1", "3/0*v1", "v1 v2", "x1",
                                  "1.5*v1", "", "v1v2", "1/2/3", "--1", "v1^2^3",
                                  "v0", "v4", "+", "2*-v1"])
def test_malformed_polynomials_are_refused(text):
    with pytest.raises(PolynomialSyntaxError):
        parse_polynomial(text, POSE)


def test_the_quick_reader_of_plain_text_agrees_with_the_general_one(monkeypatch):
    """Cache entries are read by a one-regex-per-term reader; whatever it accepts must
    read exactly as the token-by-token parser reads it (random strings of the tokens),
    and it must read back every polynomial format_polynomial writes."""
    from singcheck.elimination.cas import polytext

    rng = random.Random(3)
    x, y, z = POSE.gens()
    for _ in range(300):
        p = sum((fmpq(rng.randrange(-10**20, 10**20), rng.randrange(1, 10**12)) *
                 x**rng.randrange(4) * y**rng.randrange(4) * z**rng.randrange(4)
                 for _ in range(rng.randrange(6))), POSE.from_dict({}))
        assert polytext._parse_plain(format_polynomial(p), POSE) == p
    pieces = ["v1", "v2", "v3", "v4", "^", "^2", "*", "+", "-", "/", "0", "1", "12", "*v1"]
    accepted = 0
    for _ in range(20000):
        text = "".join(rng.choice(pieces) for _ in range(rng.randrange(1, 8)))
        quick = polytext._parse_plain(text, POSE)
        if quick is None:
            continue
        accepted += 1
        with monkeypatch.context() as m:
            m.setattr(polytext, "_parse_plain", lambda text, ctx: None)
            assert parse_polynomial(text, POSE) == quick, text
    assert accepted > 500


# -- run: the process funnel -----------------------------------------------------------

def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie still answers kill(0); read its state
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except FileNotFoundError:
        return False


def test_timeout_kills_the_whole_process_group(tmp_path):
    pids = tmp_path / "pids"
    script = f"sleep 300 & echo $! > {pids}; echo $$ >> {pids}; wait"
    start = time.monotonic()
    with pytest.raises(BackendTimeout):
        run_program(["sh", "-c", script], timeout=1)
    assert time.monotonic() - start < 10
    time.sleep(0.2)
    for pid in map(int, pids.read_text().split()):
        assert not _alive(pid), f"process {pid} survived the timeout"


def test_a_missing_program_is_a_backend_error():
    with pytest.raises(BackendError, match="could not start"):
        run_program(["/nonexistent/Singular"], timeout=5)


# -- live ------------------------------------------------------------------------------

def _backend(name: str):
    from singcheck.elimination.cas import _external, get_backend

    if _external(name).find() is None:
        message = f"{name} is not installed: `make setup` installs it"
        if os.environ.get("CI"):
            pytest.fail(message + " (CI must run every backend test)")
        pytest.skip("LOUD SKIP: " + message)
    return get_backend(name)


@pytest.mark.parametrize("name", ["singular", "macaulay2"])
def test_live_elimination_is_the_papers_surface(name):
    backend = _backend(name)
    (xi,) = backend.eliminate(XI).polynomials
    assert xi.total_degree() == 18
    from singcheck.elimination.cas import get_backend

    (norm,) = get_backend("sympy").eliminate(XI).polynomials
    assert squarefree_part(xi) == squarefree_part(norm)


@pytest.mark.parametrize("name", ["singular", "macaulay2"])
def test_live_errors_are_backend_failures(name, monkeypatch):
    backend = _backend(name)
    monkeypatch.setattr(backend, "script", lambda request: "this is not a script(;\n")
    with pytest.raises(BackendError):
        backend.eliminate(XI)


@pytest.mark.parametrize("name", ["singular", "macaulay2"])
def test_live_script_that_never_ends_is_killed(name, monkeypatch):
    backend = _backend(name)
    loop = "while (1) { }\n" if name == "singular" else "while true do 1;\n"
    monkeypatch.setattr(backend, "script", lambda request: loop)
    backend.timeout = 2
    start = time.monotonic()
    with pytest.raises(BackendTimeout):
        backend.eliminate(XI)
    assert time.monotonic() - start < 15


def test_live_singular_over_its_memory_bound_is_a_backend_error(monkeypatch):
    """A product that needs far more than 200 MiB: Singular's allocator fails under the
    bound (``error: no more memory``) instead of the kernel's OOM killer stepping in."""
    backend = _backend("singular")
    monkeypatch.setenv("SINGCHECK_MEMORY_LIMIT", "200M")
    monkeypatch.setattr(backend, "script", lambda request: (
        "ring r=0,(x,y,z,w,u,v),dp;\npoly p = (x+y+z+w+u+v+1)^60;\np = p*p;\n"))
    start = time.monotonic()
    with pytest.raises(BackendError, match="Singular ran out of memory under the bound of "
                                           "200 MiB"):
        backend.eliminate(XI)
    assert time.monotonic() - start < 60


def test_programs_run_from_two_threads_do_not_kill_each_other():
    """A call reaps its own strays only: another thread's program, started after it and
    still running when it ends, is not one of them."""
    import sys
    import threading

    results = {}

    def run(name: str, seconds: float) -> None:
        results[name] = run_program([sys.executable, "-c",
                                     f"import time; time.sleep({seconds}); print('{name}')"],
                                    timeout=120)

    first = threading.Thread(target=run, args=("first", 1.0))
    second = threading.Thread(target=run, args=("second", 3.0))
    first.start()
    time.sleep(0.3)
    second.start()
    first.join()
    second.join()
    assert [(results[k].returncode, results[k].stdout.strip()) for k in ("first", "second")] \
        == [(0, "first"), (0, "second")]


def test_live_singular_computes_a_pose_angle_robots_surface_by_its_resultant_chain():
    """The 3-PRR (pose x, y, φ; prismatic legs): Singular gets the resultant chain, not a
    Gröbner elimination (which did not finish in 10 minutes), and its ξ is the chain
    Res_r3(Res_r2(Res_r1(det A, F1), F2), F3) computed here with FLINT, squarefree, up to
    a constant."""
    from singcheck.elimination.projection import singularity_surface_request
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    backend = _backend("singular")
    request = singularity_surface_request(build_model(load_robot(
        HERE.parent / "robots" / "3-prr.yaml")))
    assert "sc_resultant_chain" in singular_script(request, "LIBRARY")
    assert "sc_eliminate" in singular_script(XI, "LIBRARY")  # no pose angle: Gröbner
    result = backend.eliminate(request)
    assert result.method == "Singular resultant chain"
    (xi,) = result.polynomials
    *legs, det_a = request.generators
    chain = det_a
    for leg, joint in zip(legs, ("r1", "r2", "r3"), strict=True):
        chain = chain.resultant(leg, joint)
    from singcheck.algebra.polynomials import restrict

    expected = restrict(squarefree_part(chain), request.kept_context())  # r's are gone
    assert expected.total_degree() == 32
    assert request.kept_context().names() == ("x", "y", "cos(phi)", "sin(phi)")
    got = squarefree_part(xi)
    assert got * expected.leading_coefficient() == expected * got.leading_coefficient()


@pytest.mark.parametrize("name", ["sympy", "macaulay2"])
def test_slow_backends_refuse_the_3prr_surface_up_front_naming_those_that_can(name):
    """SymPy and Macaulay2 each ran past 10 minutes on the 3-PRR's ξ (Gröbner elimination
    and resultants alike): they refuse it at once, in one line naming flint and singular,
    instead of running into --timeout."""
    from singcheck.elimination.cas import get_backend
    from singcheck.elimination.projection import singularity_surface_request
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    backend = _backend(name) if name == "macaulay2" else get_backend(name)
    request = singularity_surface_request(build_model(load_robot(
        HERE.parent / "robots" / "3-prr.yaml")))
    start = time.monotonic()
    with pytest.raises(BackendError) as error:
        backend.eliminate(request)
    assert time.monotonic() - start < 5
    message = str(error.value)
    assert "\n" not in message and "714,425 terms" in message
    assert message.endswith("use --backend flint or singular")
