"""Calibration data for ``polynomials.may_be_slow``: every ``until_deadline`` call, timed.

    python bench/calibrate_slow.py OUT.jsonl SOURCE [COUNT] [SEED] [TIME_LIMIT]

Runs robots × paths in-process (SOURCE: ``bundled`` robots × trajectories and
bench/user_inputs.py's paths, ``crashes`` (tests/data/crashes), ``random`` or
``random:K`` (harmonics and degrees K times higher), ``fuzz`` or ``fuzz:K``
(tests/test_fuzz.py-like coordinates), ``synthetic`` (random sparse polynomials, every
call forked)) with
``forked.until_deadline`` replaced by a recorder: for each call on one polynomial it
writes a JSON line with the operation (``what``), the polynomial's terms, largest
degree in one variable, total degree, number of variables, coefficient bits
(``polynomials._height_bits``) and the CPU seconds of the call itself.  A call the
current ``may_be_slow`` flags runs in a forked child (``run_forked``) capped at
``CAP_S`` seconds, so that a call of minutes cannot hang the calibration; one past the
cap is recorded as ``cpu_s: null, capped: true``.  Not part of the product.
"""

from __future__ import annotations

import json
import random
import re
import sys
import time
import traceback
from fractions import Fraction
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CAP_S = 20.0
OUT = None
CASE = {"id": ""}


def _features(p) -> dict:
    from singcheck.algebra.polynomials import _height_bits, may_be_slow

    degrees = p.degrees()
    return {"terms": len(p), "deg": int(max(degrees, default=0)),
            "tdeg": int(p.total_degree()) if len(p) else 0, "nvars": sum(d > 0 for d in degrees),
            "bits": int(_height_bits(p)), "slow_now": may_be_slow(p)}


def _timed(fn, keep: bool = True):
    def run(argument):
        start = time.process_time()
        value = fn(argument)
        return time.process_time() - start, value if keep else None
    return run


def recorder(fn, argument, what, costly):
    from flint import fmpq_mpoly

    from singcheck.budget import TimeLimitExceeded
    from singcheck.elimination.cas.forked import run_forked

    if not isinstance(argument, fmpq_mpoly):
        return fn(argument)  # products (a pair), inverses in a number field: not ours
    row = {"case": CASE["id"], "what": what, **_features(argument)}
    if row["slow_now"] or CASE.get("fork"):
        wall = time.perf_counter()
        try:
            cpu, value = run_forked(_timed(fn, not CASE.get("fork")), argument, CAP_S, what)
            row.update(cpu_s=cpu, where="forked")
        except TimeLimitExceeded:
            row.update(cpu_s=None, capped=True, where="forked")
            OUT.write(json.dumps(row) + "\n")
            OUT.flush()
            raise
        row["fork_wall_s"] = time.perf_counter() - wall
    else:
        cpu, value = _timed(fn)(argument)
        row.update(cpu_s=cpu, where="here")
    OUT.write(json.dumps(row) + "\n")
    OUT.flush()
    return value


def install() -> None:
    from singcheck.elimination.cas import forked

    forked.until_deadline = recorder


def path(rng: str, **pose: str) -> str:
    return (f"name: p\nparameter: t\nrange: {rng}\npose:\n" +
            "".join(f"  {k}: {v}\n" for k, v in pose.items()))


def q(rng: random.Random, lo: int, hi: int, den: int = 100) -> str:
    return str(Fraction(rng.randint(lo, hi), den))


def harmonics(rng: random.Random, centre: str, amp: int, k: int) -> str:
    terms = [centre]
    for j in range(1, k + 1):
        f = rng.choice(["cos", "sin"])
        terms.append(f"({q(rng, -amp, amp)})*{f}({j}*t)" if j > 1 else
                     f"({q(rng, -amp, amp)})*{f}(t)")
    return " + ".join(terms)


def poly(rng: random.Random, centre: str, amp: int, k: int) -> str:
    return " + ".join([centre] + [f"({q(rng, -amp, amp)})*t^{j}" for j in range(1, k + 1)])


def waypoints(rng: random.Random, centres: dict, amp: int, n: int, kind: str) -> str:
    rows = []
    for i in range(n):
        cells = ", ".join(f"{v}: {float(Fraction(c)) + rng.randint(-amp, amp) / 100:.3f}"
                          for v, c in centres.items())
        rows.append(f"  - {{t: {i}, {cells}}}")
    return f"name: w\nparameter: t\ninterpolation: {kind}\nwaypoints:\n" + "\n".join(rows) + "\n"


DELTA, ORTHO = "robots/rotary-delta.yaml", "robots/orthoglide.yaml"
GS, RUS = "robots/gough-stewart.yaml", "tests/data/robots/6-rus.yaml"
STACKED, LDELTA = "robots/stacked-orthoglide.yaml", "robots/linear-delta.yaml"
RRR = "tests/data/robots/3-rrr.yaml"


FUZZ_TERMS = ["sin(t)", "cos(t)", "sin(2*t)", "cos(3*t)", "sin(t)^3", "t", "t^2", "1"]
FUZZ_ROBOTS = {DELTA: ["x", "y", "z"], ORTHO: ["x", "y", "z"], LDELTA: ["x", "y", "z"],
               STACKED: ["x1", "y1", "z1", "x2", "y2", "z2"], RRR: ["x", "y", "phi"],
               "robots/3-prr.yaml": ["x", "y", "phi"], "robots/3-rpr.yaml": ["x", "y", "phi"],
               "robots/five-bar.yaml": ["x", "y"], "robots/biglide.yaml": ["x", "y"]}


def fuzz_coordinate(rng: random.Random, scale: int) -> str:
    """As tests/test_fuzz.py's path_coordinates: a few c·sin(kt), c·cos(kt), c·tⁿ."""
    terms = []
    for _ in range(rng.randint(1, 3 + scale)):
        c = rng.choice(["1", "-1", "1/2", "3/7", "2", "-5/14", "0.1"])
        terms.append(f"{c}*{rng.choice(FUZZ_TERMS)}")
    return " + ".join(terms)


def fuzz_cases(rng: random.Random, count: int, scale: int = 1):
    """Fuzz-like paths (sines mixed with powers of t: μ's norm over sin t) on every robot."""
    for i in range(count):
        robot = rng.choice(sorted(FUZZ_ROBOTS))
        pose = {v: fuzz_coordinate(rng, scale) for v in FUZZ_ROBOTS[robot]}
        rng_text = rng.choice(["[-pi, pi]", "[0, 1]", "[-1, 2]", "[0, 10]"])
        yield f"fuzz-{scale}-{i}", robot, path(rng_text, **pose)


def random_cases(rng: random.Random, count: int, scale: int = 1):
    """(id, robot, trajectory text): paths on the robots with path-wise elimination and
    high-degree paths on the others; ``scale`` raises harmonics and degrees."""
    for i in range(count):
        kind = rng.choice(["delta-h", "delta-h", "delta-p", "delta-w", "gs-h", "gs-w",
                           "rus-h", "rus-p", "ortho-h", "ortho-w", "stacked-h",
                           "ldelta-h", "rrr-h"])
        k = rng.randint(1, 3) * scale
        if kind == "delta-h":
            text = path("[-pi, pi]", x=harmonics(rng, "0", 40, k), y=harmonics(rng, "0", 40, k),
                        z=harmonics(rng, "-2", 20, rng.randint(0, k)))
        elif kind == "delta-p":
            text = path("[0, 1]", x=poly(rng, q(rng, -50, 50), 60, k),
                        y=poly(rng, q(rng, -50, 50), 60, k), z=poly(rng, "-2", 30, k))
        elif kind == "delta-w":
            text = waypoints(rng, {"x": "0", "y": "0", "z": "-2"}, 50, 2 + k, "cubic")
        elif kind == "gs-h":
            text = path("[0, 2]", x=harmonics(rng, "0", 25, k), y=harmonics(rng, "0", 25, k),
                        z=harmonics(rng, "2", 20, rng.randint(0, k)),
                        psi=rng.choice(["0", "t", "t/2", f"{q(rng, -50, 50)}*sin(t)"]),
                        theta="0", phi="0")
        elif kind == "gs-w":
            text = waypoints(rng, {"x": "0", "y": "0", "z": "2", "psi": "0", "theta": "0",
                                   "phi": "0"}, 20, 2 + k, rng.choice(["linear", "cubic"]))
        elif kind == "rus-h":
            text = path("[-pi, pi]", x=harmonics(rng, "0", 25, k), y=harmonics(rng, "0", 25, k),
                        z=harmonics(rng, "-2", 20, rng.randint(0, k)),
                        psi="0", theta="0", phi="0")
        elif kind == "rus-p":
            text = path("[0, 1]", x=poly(rng, "0", 30, k), y=poly(rng, "0", 30, k),
                        z=poly(rng, "-2", 20, k), psi="0", theta="0", phi="0")
        elif kind == "ortho-h":
            text = path("[-pi, pi]", x=harmonics(rng, "1/2", 50, 2 * k),
                        y=harmonics(rng, "1/2", 50, 2 * k), z=harmonics(rng, "1", 20, k))
        elif kind == "ortho-w":
            text = waypoints(rng, {"x": "1/2", "y": "1/2", "z": "1"}, 40, 3 + 2 * k, "cubic")
        elif kind == "stacked-h":
            text = path("[-pi, pi]", **{f"{v}{j}": harmonics(rng, c, 30, k) for j in (1, 2)
                                        for v, c in (("x", "1/2"), ("y", "1/2"), ("z", "1"))})
        elif kind == "ldelta-h":
            text = path("[-pi, pi]", x=harmonics(rng, "0", 40, k),
                        y=harmonics(rng, "0", 40, k), z=harmonics(rng, "-2", 20, k))
        else:
            text = path("[-pi, pi]", x=harmonics(rng, "0", 20, k), y=harmonics(rng, "0", 20, k),
                        phi=f"{q(rng, -30, 30)}*sin(t)" if rng.random() < 0.5 else "0")
        robot = {"delta": DELTA, "gs": GS, "rus": RUS, "ortho": ORTHO, "stacked": STACKED,
                 "ldelta": LDELTA, "rrr": RRR}[kind.split("-")[0]]
        yield f"{kind}-{scale}-{i}", robot, text


def bundled_cases():
    import yaml

    sys.path.insert(0, str(ROOT))
    from user_inputs import INPUTS

    robots = sorted((ROOT / "robots").glob("*.yaml"))
    trajs = sorted((ROOT / "trajectories").glob("*.yaml"))
    for r in robots:
        pose = set(yaml.safe_load(r.read_text())["pose"])
        for t in trajs:
            doc = yaml.safe_load(t.read_text())
            if set((doc.get("pose") or {}).keys()) == pose:
                yield f"{r.stem}:{t.stem}", str(r.relative_to(ROOT)), t.read_text()
    for what, robot, traj, edit in INPUTS:
        if edit is None and "\n" in traj:
            yield f"user:{what}", robot, traj


def crash_cases():
    """tests/data/crashes/*.yaml: the inputs that once ran long in one uninterruptible call."""
    for f in sorted((ROOT / "tests" / "data" / "crashes").glob("*.yaml")):
        text = f.read_text()
        robot = re.search(r"^# robot: (\S+)", text, re.M)
        if robot:
            yield f"crash:{f.stem}", f"robots/{robot.group(1)}.yaml", text


def random_poly(rng: random.Random, ctx, degree: int, terms: int, bits: int):
    """``terms`` random monomials of degree at most ``degree`` in each variable, random
    integer coefficients of ``bits`` bits."""
    n = ctx.nvars()
    terms = min(terms, (degree + 1) ** n)
    d = {}
    while len(d) < terms:
        d[tuple(rng.randint(0, degree) for _ in range(n))] = rng.randint(1, 1 << bits) * \
            rng.choice([-1, 1])
    return ctx.from_dict(d)


def synthetic(rng: random.Random, count: int) -> None:
    """Products A·B² (a squarefree part, a factorization to find) and resultants of
    random sparse polynomials, sizes drawn up to where one call takes seconds."""
    from flint import fmpq_mpoly_ctx

    from singcheck.algebra.polynomials import squarefree_part

    for i in range(count):
        n = rng.choice([1, 2, 2, 3, 4, 5])
        ctx = fmpq_mpoly_ctx.get(tuple(f"v{j}" for j in range(n)), "lex")
        degree = rng.choice([2, 4, 8, 16, 32, 64, 128])
        terms = min(rng.choice([2, 5, 10, 20, 40, 80]), (degree + 1) ** n)
        bits = rng.choice([8, 30, 60, 200, 1000])
        a = random_poly(rng, ctx, degree, terms, bits)
        b = random_poly(rng, ctx, max(1, degree // 2), max(1, terms // 2), bits)
        c = random_poly(rng, ctx, max(1, degree // 2), max(1, terms // 2), bits)
        op = rng.choice(["squarefree", "factor", "resultant"])
        CASE["id"] = f"synthetic-{i}-{op}"
        try:
            if op == "squarefree":
                recorder(squarefree_part, a * b * b, "synthetic squarefree part", True)
            elif op == "factor":
                recorder(lambda p: p.factor(), a * b * c, "synthetic factorization", True)
            elif n > 1:  # with a small leg, as the norm chain's
                leg = random_poly(rng, ctx, 2, min(6, 3 ** n), 30)
                recorder(lambda p, leg=leg: p.resultant(leg, "v0"), a * b,
                         "synthetic resultant", True)
        except Exception as e:  # noqa: BLE001
            print(CASE["id"], type(e).__name__, str(e)[:100], flush=True)
        print(CASE["id"], flush=True)


def main() -> int:
    global OUT
    out, source = Path(sys.argv[1]), sys.argv[2]
    count = int(sys.argv[3]) if len(sys.argv) > 3 else 100
    seed = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    limit = float(sys.argv[5]) if len(sys.argv) > 5 else 30.0
    install()
    from singcheck import api
    from singcheck.spec.files import parse_robot, parse_trajectory

    rng = random.Random(seed)
    if source == "synthetic":
        OUT, CASE["fork"] = out.open("a"), True
        synthetic(rng, count)
        return 0
    if source == "bundled":
        cases = list(bundled_cases())
    elif source.startswith("fuzz"):
        cases = list(fuzz_cases(rng, count, int(source.partition(":")[2] or 1)))
    elif source == "crashes":
        cases = list(crash_cases())
    elif source == "random":
        cases = list(random_cases(rng, count))
    else:
        cases = list(random_cases(rng, count, scale=int(source.split(":")[1])))
    robots = {}
    OUT = out.open("a")
    for case, robot, text in cases:
        CASE["id"] = case
        start = time.perf_counter()
        try:
            if robot not in robots:
                robots[robot] = api.robot_from_spec(
                    parse_robot((ROOT / robot).read_text(), robot), backend="flint", cache=True)
            machine = robots[robot]
            spec = parse_trajectory(text, "p.yaml", machine.spec)
            report = api.check(machine, spec, time_limit=limit, regions=False)
            verdict = report.to_dict().get("verdict")
        except Exception as e:  # noqa: BLE001
            verdict = f"{type(e).__name__}: {str(e)[:100]}"
            if not isinstance(e, (ValueError, KeyError)):
                traceback.print_exc(limit=2)
        OUT.write(json.dumps({"case": case, "robot": robot, "trajectory": text,
                              "verdict": verdict,
                              "wall_s": time.perf_counter() - start}) + "\n")
        OUT.flush()
        print(f"{case}: {verdict} {time.perf_counter() - start:.2f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
