"""Parameters and joint limits outside the exact field (issue 27): ``l: 2*cos(1/10)``,
``rho3: [-cos(1), 4]``.  Each answer is checked against an oracle written here from the
geometry — the Orthoglide's inverse kinematics ρᵢ = Xᵢ ± √(l² − …) and det A at 50
digits with mpmath — never against singcheck's own output."""

from __future__ import annotations

import json
from itertools import product
from pathlib import Path

import mpmath as mp
import pytest

from singcheck.api import check, load_robot, load_trajectory
from singcheck.errors import SpecError
from tests.conftest import ROBOTS, TRAJECTORIES
from tests.test_cli import singcheck

ORTHO = (ROBOTS / "orthoglide.yaml").read_text()
LIMITS = (0, 4)  # the Orthoglide's joint limits (every joint), as the spec writes them


def _robot(tmp_path: Path, l_text: str = "2", rho3: str = "[0, 4]",
           name: str = "ortho") -> str:
    text = ORTHO.replace("parameters: {l: 2}", f"parameters: {{l: {l_text}}}")
    text = text.replace("rho3: [0, 4]", f"rho3: {rho3}")
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return str(path)


# --- the oracle: the Orthoglide's geometry at 50 digits ---------------------------------

def _heart(which: str):
    """The pose of trajectories/heart1.yaml or heart2.yaml at t (written out here)."""
    if which == "heart1":
        k, a, b, c, d = mp.mpf(8) / 7, mp.mpf(13) / 14, mp.mpf(5) / 14, mp.mpf(1) / 10, \
            mp.mpf(1) / 14
    else:
        k, a, b, c, d = mp.mpf(4) / 5, mp.mpf(13) / 20, mp.mpf(1) / 4, mp.mpf(1) / 20, \
            mp.mpf(1) / 20

    def pose(t):
        return (k * mp.sin(t) ** 3,
                a * mp.cos(t) - b * mp.cos(2 * t) - c * mp.cos(3 * t) - d * mp.cos(4 * t),
                mp.mpf(1))

    return pose


def _joints(L, X, signs):
    """ρᵢ = Xᵢ + σᵢ·√(L² − Σ_{j≠i} X_j²) (leg i: (Xᵢ − ρᵢ)² + Σ_{j≠i} X_j² = L²), or None
    where a leg has no real branch."""
    out = []
    for i, s in enumerate(signs):
        d = L * L - sum(X[j] ** 2 for j in range(3) if j != i)
        if d <= 0:
            return None
        out.append(X[i] + s * mp.sqrt(d))
    return out


def _det(L, X, signs):
    """det A / 8 of the Orthoglide in a mode: A's row i is ∂Fᵢ/∂X / 2, with Xᵢ − ρᵢ in
    column i."""
    rho = _joints(L, X, signs)
    rows = [[X[j] - (rho[i] if i == j else 0) for j in range(3)] for i in range(3)]
    return mp.det(mp.matrix(rows))


MODES = list(product((1, -1), repeat=3))


def _label(signs) -> str:
    return "".join("+" if s > 0 else "-" for s in signs)


def _feasible_modes(L, pose, limits, n=1500):
    """The modes whose joints are real and strictly inside their limits at every point of
    a grid over [-π, π] (with a margin the grid cannot hide: none of them comes near)."""
    ts = [-mp.pi + 2 * mp.pi * i / n for i in range(n + 1)]
    out = []
    for signs in MODES:
        ok = True
        for t in ts:
            rho = _joints(L, pose(t), signs)
            if rho is None or not all(lo < r < hi for r, (lo, hi) in zip(rho, limits,
                                                                       strict=True)):
                ok = False
                break
        if ok:
            out.append(_label(signs))
    return out


def _roots(f, lo, hi, n=4000):
    """Every sign change of f on a grid over [lo, hi], refined by mpmath.findroot."""
    ts = [lo + (hi - lo) * i / n for i in range(n + 1)]
    values = [f(t) for t in ts]
    out = []
    points = list(zip(ts, values, strict=True))
    for (a, fa), (b, fb) in zip(points, points[1:], strict=False):
        if mp.sign(fa) * mp.sign(fb) < 0:
            out.append(mp.findroot(f, (a, b), solver="anderson"))
    return out, min(abs(v) for v in values)


L_COS = "2*cos(1/10)"


@pytest.fixture(scope="module")
def cos_robot(tmp_path_factory):
    return load_robot(_robot(tmp_path_factory.mktemp("robot"), L_COS), backend="flint",
                      cache=False)


@pytest.mark.parametrize("which", ["heart1", "heart2"])
def test_a_transcendental_leg_length_is_certified_by_the_interval_engine(cos_robot, which):
    """l = 2·cos(1/10) ≈ 1.990: the oracle finds the feasible mode and the sign changes
    of its det A; singcheck must be singular exactly there (each oracle root inside a
    reported interval, one per root) or free where there are none."""
    mp.mp.dps = 50
    L = 2 * mp.cos(mp.mpf(1) / 10)
    pose = _heart(which)
    feasible = _feasible_modes(L, pose, [LIMITS] * 3)
    assert feasible == ["+++"]
    roots, smallest = _roots(lambda t: _det(L, pose(t), (1, 1, 1)), -mp.pi, mp.pi)

    report = check(cos_robot, load_trajectory(str(TRAJECTORIES / f"{which}.yaml"),
                                              cos_robot), regions=False).certificate
    assert [m.label for m in report.modes if m.feasible] == feasible
    singular = [c for c in report.candidates if c.singular_modes]
    if which == "heart1":
        assert len(roots) == 2 and report.verdict == "singular"
        assert len(singular) == len(roots)
        for c, root in zip(sorted(singular, key=lambda c: float(c.t.mid())), roots,
                           strict=True):
            assert c.singular_modes == ["+++"]
            lo, hi = float(c.t.lower()), float(c.t.upper())
            assert lo - 1e-12 <= float(root) <= hi + 1e-12, (root, lo, hi)
            assert hi - lo < 1e-5
        # l = 2 puts them elsewhere (0.9778, 1.5119): the answer did read the parameter
        assert all(abs(float(r) - 0.9778) > 5e-3 and abs(float(r) - 1.5119) > 5e-3
                   for r in roots)
    else:
        assert roots == [] and smallest > mp.mpf("0.01")
        assert report.verdict == "singularity-free" and singular == []
    check_ = report.corroboration.to_json()
    assert check_["engine"] == "interval" and check_["status"] == "exact engine not run"
    assert "outside the exact field" in check_["detail"]


def test_the_json_report_names_the_interval_engine_and_the_missing_projection(tmp_path):
    robot = _robot(tmp_path, L_COS)
    out = singcheck("run", robot, str(TRAJECTORIES / "heart1.yaml"), "--format", "json",
                    "-q")
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["backend"] == "none" and doc["singularity_surface_degree"] is None
    assert doc["elimination_method"].startswith("not computed: the parameter l = 2*cos(1/10)")
    (traj,) = doc["trajectories"]
    assert traj["verdict"] == "singular" and "workspace" not in traj
    assert traj["corroboration"]["engine"] == "interval"
    proofs = {m["proof"] for c in traj["candidates"] for m in c["modes"]}
    assert proofs == {"sign change of det A along the mode (ball arithmetic)"}
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((Path(__file__).parent.parent / "singcheck" / "schemas" /
                         "report.schema.json").read_text())
    assert list(jsonschema.Draft202012Validator(schema).iter_errors(doc)) == []


@pytest.mark.parametrize("text", ["pi/2 + 1", "sqrt(1 + sqrt(2))", "cos(1)^(-1) + 1/2"])
def test_other_finite_reals_are_accepted_and_enclosed(tmp_path, text):
    """π outside sin/cos, nested square roots, a negative power: each is a finite real;
    the constraint's constant is the value's ball (checked against mpmath)."""
    from singcheck.algebra.radicals import radical_balls

    mp.mp.dps = 50
    expected = {"pi/2 + 1": mp.pi / 2 + 1, "sqrt(1 + sqrt(2))": mp.sqrt(1 + mp.sqrt(2)),
                "cos(1)^(-1) + 1/2": 1 / mp.cos(1) + mp.mpf(1) / 2}[text]
    robot = load_robot(_robot(tmp_path, text), backend="flint", cache=False)
    (ball,) = radical_balls(robot.spec.context).values()
    assert ball.rad() < 1e-15 and abs(float(ball.mid()) - float(expected)) < 1e-14
    report = check(robot, load_trajectory(str(TRAJECTORIES / "helix.yaml"), robot),
                   regions=False)
    assert report.verdict in ("singularity-free", "singular", "infeasible")


@pytest.mark.parametrize("l_text", ["2", L_COS])
@pytest.mark.parametrize("lower, feasible", [("-cos(1)", False), ("-3*cos(1)", True)])
def test_a_transcendental_joint_limit_decides_a_mode(tmp_path, l_text, lower, feasible):
    """rho3 ≥ -cos(1) ≈ -0.5403: mode ++- starts at ρ3 ≈ -0.54 below it (infeasible);
    rho3 ≥ -3·cos(1) ≈ -1.62: ρ3 = 1 − √(l² − x² − y²) ≥ 1 − l > -1.62 all along, and
    below 4 (feasible).  The oracle computes the joints itself."""
    mp.mp.dps = 50
    L = 2 * mp.cos(mp.mpf(1) / 10) if l_text == L_COS else mp.mpf(2)
    bound = -mp.cos(1) * (3 if feasible else 1)
    pose = _heart("heart1")
    rho3 = _joints(L, pose(-mp.pi), (1, 1, -1))[2]
    assert (rho3 > bound) is feasible and abs(rho3 - bound) > mp.mpf("0.002")
    oracle = _feasible_modes(L, pose, [LIMITS, LIMITS, (bound, 4)], n=600)
    assert ("++-" in oracle) is feasible and "+++" in oracle

    robot = load_robot(_robot(tmp_path, l_text, f"[{lower}, 4]"), backend="flint",
                       cache=False)
    report = check(robot, load_trajectory(str(TRAJECTORIES / "heart1.yaml"), robot),
                   regions=False).certificate
    modes = {m.label: m for m in report.modes}
    assert sorted(label for label, m in modes.items() if m.feasible) == sorted(oracle)
    if not feasible:
        assert f"rho3 is outside [{lower}, 4] from the start" in modes["++-"].reason
    assert report.verdict == "singular"  # +++ crosses its singularity either way


BAD = [
    ("sqrt(1 - 2*cos(1/10))", "parameters.l", "sqrt of a negative number is not real"),
    ("1/(cos(1)^2 + sin(1)^2 - 1)", "parameters.l", "not proven non-zero"),
    ("1/(cos(1) - cos(1))", "parameters.l", "division by zero"),  # a − a: exactly 0
    ("1/(3 - 3)", "parameters.l", "division by zero"),
    ("(sin(1/2) - sin(1/2))^(-1)", "parameters.l", "a negative power of zero"),
    ("(cos(1)*sin(1) - sin(1)*cos(1))^(-1)", "parameters.l", "not proven non-zero"),
    ("cos(1)^(1/2)", "parameters.l", "exponents must be integers"),
    ("exp(1)", "parameters.l", "unknown function 'exp'"),
]


@pytest.mark.parametrize("text, key, phrase", BAD, ids=[b[2] for b in BAD])
def test_values_that_are_not_finite_reals_are_refused_with_file_and_line(tmp_path, text,
                                                                         key, phrase):
    robot = _robot(tmp_path, text)
    with pytest.raises(SpecError) as err:
        load_robot(robot, backend="flint", cache=False)
    assert err.value.line == 7 and err.value.key == key and phrase in err.value.message
    out = singcheck("run", robot, str(TRAJECTORIES / "heart1.yaml"), "-q")
    assert out.returncode == 2 and f"{robot}:7: {key}:" in out.stderr
    assert phrase in out.stderr and "Traceback" not in out.stderr


@pytest.mark.parametrize("text", ["2 + sqrt(cos(1) - cos(1))", "2 + sqrt(1 - 1)",
                                  "sqrt(4 + sin(1/3) - sin(1/3))"])
def test_a_difference_of_the_same_constant_is_exactly_zero(tmp_path, text):
    """a − a is 0 wherever a is defined, though its ball is not [0, 0]; the square root
    of an exact 0 is 0 (both were refused: "not proven positive").  l = 2 then, and
    heart 1's singular times are the oracle's for l = 2."""
    mp.mp.dps = 50
    pose = _heart("heart1")
    roots, _ = _roots(lambda t: _det(mp.mpf(2), pose(t), (1, 1, 1)), -mp.pi, mp.pi)
    robot = load_robot(_robot(tmp_path, text), backend="flint", cache=False)
    report = check(robot, load_trajectory(str(TRAJECTORIES / "heart1.yaml"), robot),
                   regions=False).certificate
    singular = sorted((c for c in report.candidates if c.status == "real"),
                      key=lambda c: float(c.t.mid()))
    assert report.verdict == "singular" and len(singular) == len(roots) == 2
    for c, root in zip(singular, roots, strict=True):
        assert float(c.t.lower()) - 1e-12 <= float(root) <= float(c.t.upper()) + 1e-12


def test_a_limit_that_is_not_real_is_refused(tmp_path):
    robot = _robot(tmp_path, rho3="[0, sqrt(cos(2))]")
    out = singcheck("run", robot, str(TRAJECTORIES / "heart1.yaml"), "-q")
    assert out.returncode == 2 and f"{robot}:12: joint_limits.rho3:" in out.stderr
    assert "not real" in out.stderr


def test_the_exact_engine_refuses_such_a_robot_and_auto_answers(tmp_path):
    robot = _robot(tmp_path, L_COS)
    heart = str(TRAJECTORIES / "heart2.yaml")
    out = singcheck("run", robot, heart, "--engine", "exact", "-q")
    assert out.returncode == 2, out.stderr
    line = [x for x in out.stderr.splitlines() if "error" in x]
    assert len(line) == 1 and f"{robot}:7: parameters:" in line[0]
    assert "--engine exact cannot certify this robot" in line[0]
    assert "l = 2*cos(1/10)" in line[0] and "outside the exact field" in line[0]
    for engine in ("auto", "interval"):
        out = singcheck("run", robot, heart, "--engine", engine, "-q")
        assert out.returncode == 0, out.stderr  # free (the oracle above says so)
    for command in (["workspace", robot], ["project", robot]):
        out = singcheck(*command, "-q") if command[0] == "workspace" else singcheck(*command)
        assert out.returncode == 2 and f"{robot}:7: parameters:" in out.stderr
        assert "Traceback" not in out.stderr


def test_the_exact_field_keeps_the_exact_path(tmp_path):
    """l = 2 (the bundled spec) and a limit 2*sqrt(2) stay in the field: the projection
    is computed and the exact engine decides (its proof is the elimination's)."""
    robot = _robot(tmp_path, "4/2", "[0, 2*sqrt(2) + 1]")
    out = singcheck("run", robot, str(TRAJECTORIES / "heart1.yaml"), "--format", "json",
                    "--backend", "flint", "--no-regions", "-q")
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["singularity_surface_degree"] == 16
    assert not doc["elimination_method"].startswith("not computed")
    (traj,) = doc["trajectories"]
    assert traj["root_isolation"] == "tangent half-angle"  # μ's roots, isolated exactly
    assert "elimination" in {m["proof"] for c in traj["candidates"] for m in c["modes"]}
    assert traj["corroboration"]["status"] == "confirmed"
    spec = load_robot(robot, backend="flint", cache=False).spec
    assert spec.context.names() == ("rho1", "rho2", "rho3", "x", "y", "z")


# --- a revolute robot, a path naming the parameter, an undecided graze -----------------

def _assert_matches(report, truth, name: str) -> None:
    """singcheck's verdict, its one feasible mode and its singular times (each inside its
    reported ball) are the oracle's ``truth``; a path named *cross* is singular."""
    assert report.verdict == truth.verdict == ("singular" if "cross" in name
                                               else "singularity-free")
    feasible = [m for m in report.working_modes if m.feasible]
    assert len(feasible) == len(truth.feasible) == 1
    times = sorted(feasible[0].singular_times, key=lambda c: float(c.t.mid()))
    assert len(times) == len(truth.singular_times)
    for c, t in zip(times, truth.singular_times, strict=True):
        assert float(c.t.lower()) - 1e-12 <= float(t) <= float(c.t.upper()) + 1e-12


@pytest.mark.parametrize("name, pose", [
    ("five-bar-cross", lambda t: [mp.mpf(0), 3 - 2 * t]),
    ("five-bar-free", lambda t: [-1 + 2 * t, mp.mpf(5) / 2]),
])
def test_a_revolute_robot_with_a_real_link_length(tmp_path, name, pose):
    """l1 = 2·cos(1/20): the oracle's feasible modes and singular times (IK in closed
    form, det A at 50 digits, bisection) are the interval engine's."""
    from tests import robot_oracles as oracles

    mp.mp.dps = 50
    l1 = 2 * mp.cos(mp.mpf(1) / 20)
    path = oracles.Path(name, lambda: oracles.five_bar(l1), 0, 1, pose, None)
    truth = oracles.solve(path)
    robot_file = tmp_path / "five-bar.yaml"
    robot_file.write_text((ROBOTS / "five-bar.yaml").read_text().replace(
        "l1: 2,", "l1: 2*cos(1/20),"))
    robot = load_robot(str(robot_file), backend="flint", cache=False)
    assert "l1" in str(robot.spec.context.names())  # an opaque constant of the ring
    report = check(robot, load_trajectory(str(TRAJECTORIES / f"{name}.yaml"), robot),
                   regions=False)
    _assert_matches(report, truth, name)
    if truth.singular_times:  # l1 = 2 crosses at (3 - √3)/2 ≈ 0.634: this one elsewhere
        assert abs(float(truth.singular_times[0]) - 0.6339746) > 1e-3


def test_a_path_may_name_a_real_parameter(tmp_path, cos_robot):
    """x = l·cos t/4, y = l·sin t/4 + 1/2, z = 1 (l = 2·cos(1/10)): the oracle's det A
    along +++ keeps one sign; singcheck proves the path free (a path kept as trees)."""
    mp.mp.dps = 50
    L = 2 * mp.cos(mp.mpf(1) / 10)

    def pose(t):
        return L * mp.cos(t) / 4, L * mp.sin(t) / 4 + mp.mpf(1) / 2, mp.mpf(1)

    roots, smallest = _roots(lambda t: _det(L, pose(t), (1, 1, 1)), 0, 2 * mp.pi, 800)
    assert roots == [] and smallest > mp.mpf("0.1")
    doc = tmp_path / "circle.yaml"
    doc.write_text("name: circle\nparameter: t\nrange: [0, 2*pi]\n"
                   "pose: {x: l*cos(t)/4, y: l*sin(t)/4 + 1/2, z: 1}\n")
    report = check(cos_robot, load_trajectory(str(doc), cos_robot), regions=False)
    assert report.verdict == "singularity-free", report.reason


def test_a_graze_is_proven_at_a_simple_time_and_unknown_elsewhere(tmp_path):
    """The biglide (det A = 4y(q − p), q − p ≠ 0) with a leg of length 2·cos(1/10): on
    y = t² det A touches 0 at t = 0 without changing sign, which balls cannot prove, but
    y = 0 exactly there (a factor of det A in the pose alone): `singular` at t = 0,
    proven.  On y = (t − √2/2)² the touch is at an irrational time: `unknown`, the
    window holding √2/2 and its bound, and why the exact engine did not run."""
    text = (ROBOTS / "biglide.yaml").read_text().replace(
        "constraints:", "parameters: {a: 2*cos(1/10)}\nconstraints:").replace(
        "(x - p)^2 + y^2 - 4", "(x - p)^2 + y^2 - a^2")
    (tmp_path / "biglide.yaml").write_text(text)
    robot = load_robot(str(tmp_path / "biglide.yaml"), backend="flint", cache=False)
    report = check(robot, load_trajectory(str(TRAJECTORIES / "biglide-graze.yaml"), robot),
                   regions=False)
    assert report.verdict == "singular" and report.reason.endswith("at t = 0 (exactly)")
    (c,) = report.certificate.candidates
    assert float(c.t.lower()) <= 0 <= float(c.t.upper())
    (tmp_path / "graze.yaml").write_text("name: graze\nparameter: t\nrange: [0, 1]\n"
                                         "pose: {x: t/2, y: (t - sqrt(2)/2)^2}\n")
    report = check(robot, load_trajectory(str(tmp_path / "graze.yaml"), robot),
                   regions=False)
    assert report.verdict == "unknown"
    assert "|det A| ≤" in report.reason and "outside the exact field" in report.reason
    windows = report.certificate.undecided
    root = 2 ** 0.5 / 2
    assert windows and all(float(t.lower()) <= root <= float(t.upper()) for t, _ in windows)


def test_a_batch_on_two_workers_reads_the_real_parameter(tmp_path):
    """The opaque constant's function travels to each worker with the robot's ring
    (algebra/pickling): six paths on two workers (a batch of at most four runs in the
    command's own process), each verdict the one the oracle tests above prove (heart 1
    singular, heart 2 free), every line naming the interval engine.  With the default
    region statement: such a batch once ended at its start, an internal error (the
    shared region maps were prepared for a robot that has no ξ to decompose)."""
    robot = _robot(tmp_path, L_COS)
    paths = [str(TRAJECTORIES / f"{n}.yaml") for n in ("heart1", "heart2") * 3]
    copies = []
    for i, p in enumerate(paths):  # (names must be unique in a batch)
        text = Path(p).read_text().replace("name: heart", f"name: h{i}-heart")
        copies.append(tmp_path / f"p{i}.yaml")
        copies[-1].write_text(text)
    out = singcheck("run", robot, *map(str, copies), "--format", "jsonl", "--jobs", "2",
                    "-q")
    assert out.returncode == 1, out.stderr
    lines = {d["name"]: d for d in map(json.loads, out.stdout.splitlines())}
    assert {k: d["verdict"] for k, d in lines.items()} == {
        f"h{i}-heart{1 + i % 2}": "singular" if i % 2 == 0 else "singularity-free"
        for i in range(6)}
    assert all(d["corroboration"]["engine"] == "interval" for d in lines.values())


def _rpr_oracle(a):
    """The 3-RPR (bases (0,0), (5,0), (1,4)) with its second platform point at angle a
    from the x axis, (cos a, sin a), instead of (1, 0): written from the geometry, F_i =
    |P + R(φ)bᵢ − Aᵢ|² − rᵢ², det A from the gradients in (x, y, φ)."""
    from tests import robot_oracles as oracles

    bases = ((0, 0), (5, 0), (1, 4))
    platform = ((mp.mpf(0), mp.mpf(0)), (mp.cos(a), mp.sin(a)), (mp.mpf(0), mp.mpf(1)))

    def parts(i, X):
        c, s = mp.cos(X[2]), mp.sin(X[2])
        bx, by = platform[i]
        rb = (c * bx - s * by, s * bx + c * by)
        drb = (-s * bx - c * by, c * bx - s * by)  # d(R b)/dφ
        return (X[0] + rb[0] - bases[i][0], X[1] + rb[1] - bases[i][1]), drb

    def abc(i):
        def f(X):  # -r² + |u|² = 0
            u, _ = parts(i, X)
            return -1, 0, u[0] ** 2 + u[1] ** 2

        return f

    def det_A(q, X):
        rows = []
        for i in range(3):
            u, drb = parts(i, X)
            rows.append([u[0], u[1], u[0] * drb[0] + u[1] * drb[1]])
        return oracles.det(rows)

    legs = tuple(oracles.quadratic_leg(f"r{i + 1}", abc(i), mp.mpf(1) / 2, 5)
                 for i in range(3))
    return oracles.Oracle("3-rpr", ("x", "y", "phi"), legs, det_A)


@pytest.mark.parametrize("name, pose", [
    ("3-rpr-cross", lambda t: [2 + mp.cos(t), 2 + mp.sin(t), t]),
    ("3-rpr-free", lambda t: [3 - mp.cos(t), mp.mpf(1) / 2 + mp.sin(t), t]),
])
def test_an_angle_plus_a_real_offset_in_a_constraint(tmp_path, name, pose):
    """cos(phi + a), sin(phi + a) with a = 1/3 rad (not a multiple of π/12): cos a and
    sin a are opaque constants and the call is expanded around them; the verdict and
    singular times are the oracle's (the offset moves the crossing from 0.119)."""
    from tests import robot_oracles as oracles

    mp.mp.dps = 50
    path = oracles.Path(name, lambda: _rpr_oracle(mp.mpf(1) / 3), 0, 1, pose, None)
    truth = oracles.solve(path)
    text = (ROBOTS / "3-rpr.yaml").read_text().replace(
        "(x + cos(phi) - 5)^2 + (y + sin(phi))^2", "(x + cos(phi + a) - 5)^2 + "
        "(y + sin(phi + a))^2").replace("constraints:", "parameters: {a: 1/3}\nconstraints:")
    (tmp_path / "rpr.yaml").write_text(text)
    robot = load_robot(str(tmp_path / "rpr.yaml"), backend="flint", cache=False)
    assert "K[[cos(1/3)]]" in robot.spec.context.names()
    report = check(robot, load_trajectory(str(TRAJECTORIES / f"{name}.yaml"), robot),
                   regions=False)
    _assert_matches(report, truth, name)
    for t in truth.singular_times:
        assert abs(float(t) - 0.119047) > 1e-2


@pytest.mark.parametrize("lower, feasible", [("2*cos(1)", True), ("2*cos(1/5)", False)])
def test_a_real_angle_limit(tmp_path, lower, feasible):
    """th1 ≥ 2·cos(1) ≈ 1.081 keeps the 5-bar's mode +- on five-bar-cross (its th1
    stays in [1.908, 2.095], the oracle says); th1 ≥ 2·cos(1/5) ≈ 1.960 cuts it at the
    start (no mode is left).
    The robot's parameters stay exact: the exact engine still runs, the limit is
    compared by balls."""
    from tests import robot_oracles as oracles

    mp.mp.dps = 50
    lo1 = 2 * mp.cos(1 if feasible else mp.mpf(1) / 5)
    path = oracles.Path("five-bar-cross", lambda: oracles.five_bar(mp.mpf(2), lo1), 0, 1,
                        lambda t: [mp.mpf(0), 3 - 2 * t], None)
    truth = oracles.solve(path)
    (tmp_path / "fb.yaml").write_text((ROBOTS / "five-bar.yaml").read_text().replace(
        "th1: [pi/3, pi]", f"th1: [{lower}, pi]"))
    robot = load_robot(str(tmp_path / "fb.yaml"), backend="flint", cache=False)
    assert robot.projection.expanded  # ξ computed: the parameters are exact
    report = check(robot, load_trajectory(str(TRAJECTORIES / "five-bar-cross.yaml"), robot),
                   regions=False)
    assert report.verdict == truth.verdict == ("singular" if feasible else "infeasible")
    assert len([m for m in report.working_modes if m.feasible]) == len(truth.feasible)


@pytest.mark.parametrize(("parameters", "length_squared", "L"), [
    # sqrt of a real parameter inside a constraint (it was refused: "define it as a
    # parameter (m: sqrt(l))"): l = 2·cos(1/10) written through a = l²
    ("{a: 4*cos(1/10)^2}", "sqrt(a)^2", lambda: 2 * mp.cos(mp.mpf(1) / 10)),
    # square roots of constants outside the rationals: √(8 + 4√3)·√(8 − 4√3) = √16 = 4
    ("{}", "sqrt(8 + 4*sqrt(3))*sqrt(8 - 4*sqrt(3))", lambda: mp.mpf(2)),
])
def test_a_square_root_of_a_real_constant_in_a_constraint(tmp_path, parameters,
                                                          length_squared, L):
    """Each sqrt of a constant the exact field does not hold is an opaque constant of its
    own (proven a finite real on balls), so only the interval engine runs; heart 1's
    singular times are the oracle's for that leg length."""
    mp.mp.dps = 50
    text = ORTHO.replace("parameters: {l: 2}", f"parameters: {parameters}").replace(
        "l^2", length_squared)
    assert text.count(length_squared) == 3
    (tmp_path / "robot.yaml").write_text(text)
    pose = _heart("heart1")
    roots, _ = _roots(lambda t: _det(L(), pose(t), (1, 1, 1)), -mp.pi, mp.pi)
    assert len(roots) == 2 and _feasible_modes(L(), pose, [LIMITS] * 3) == ["+++"]
    out = singcheck("run", str(tmp_path / "robot.yaml"), str(TRAJECTORIES / "heart1.yaml"),
                    "--format", "json", "-q")
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["elimination_method"].startswith("not computed: the constant")
    (traj,) = doc["trajectories"]
    assert [m["label"] for m in traj["working_modes"] if m["feasible"]] == ["+++"]
    spans = [c["t_interval"] for c in traj["candidates"]]
    assert len(spans) == 2
    for (lo, hi), root in zip(spans, roots, strict=True):
        assert lo - 1e-12 <= float(root) <= hi + 1e-12 and hi - lo < 1e-5


@pytest.mark.parametrize(("constraint", "message"), [
    ("sqrt(l - 3)", "constraints[0]: sqrt(l - 3): sqrt of a negative number is not real"),
    ("sqrt(x)", "constraints[0]: sqrt takes a constant (e.g. sqrt(3), sqrt(3/4), sqrt(l) of "
                "a parameter l), not a joint or pose variable"),
])
def test_a_square_root_that_is_not_a_real_constant_is_refused(tmp_path, constraint, message):
    text = ORTHO.replace("parameters: {l: 2}", "parameters: {l: 2*cos(1/10)}").replace(
        "+ z^2 - l^2\n  - x^2", f"+ z^2 - {constraint}\n  - x^2", 1)
    (tmp_path / "robot.yaml").write_text(text)
    out = singcheck("run", str(tmp_path / "robot.yaml"), str(TRAJECTORIES / "heart1.yaml"))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.strip().splitlines()[-1].startswith(
        f"singcheck: error: {tmp_path / 'robot.yaml'}:9: {message}")


def test_unparse_writes_what_the_grammar_reads():
    """The text of a constant (an opaque constant's name, sqrt(...)) read back is the same
    real: 3,000 random expressions with -, ^, /, sqrt, cos, pi, evaluated at 40 digits
    from both trees by an evaluator written here."""
    import random
    from fractions import Fraction

    from singcheck.spec.grammar import parse, unparse

    mp.mp.dps = 40
    env = {"a": mp.mpf("1.3"), "b": mp.mpf("0.7"), "pi": mp.pi}

    def value(n):
        if n.kind == "num":
            return mp.mpf(Fraction(n.value).numerator) / Fraction(n.value).denominator
        if n.kind == "name":
            return env[n.value]
        if n.kind == "neg":
            return -value(n.args[0])
        if n.kind == "call":
            return getattr(mp, n.value)(value(n.args[0]))
        a, b = (value(x) for x in n.args)
        return {"add": lambda: a + b, "sub": lambda: a - b, "mul": lambda: a * b,
                "div": lambda: a / b, "pow": lambda: a ** b}[n.kind]()

    rng = random.Random(7)

    def text(depth):
        if depth == 0 or rng.random() < 0.2:
            return rng.choice(["a", "b", "2", "1/3", "0.5", "pi", "-a", "-2"])
        op = rng.choice(["+", "-", "*", "/", "^", "neg", "sqrt", "cos"])
        if op == "neg":
            return f"-({text(depth - 1)})"
        if op in ("sqrt", "cos"):
            return f"{op}({text(depth - 1)})"
        if op == "^":
            return f"({text(depth - 1)})^{rng.choice(['2', '3', '-1'])}"
        return f"({text(depth - 1)}) {op} ({text(depth - 1)})"

    checked = 0
    for _ in range(3000):
        tree = parse(text(5))
        try:
            want = value(tree)
        except (ZeroDivisionError, ValueError):
            continue
        got = value(parse(unparse(tree)))
        assert abs(got - want) <= mp.mpf(10) ** -30 * (1 + abs(want)), unparse(tree)
        checked += 1
    assert checked > 2500


def test_sin_and_cos_of_a_constant_inside_a_constraint(tmp_path):
    """`4*cos(1/100)^2` written in the biglide's constraint instead of a parameter (it
    was refused: "the argument of sin/cos must be an integer combination of angles"):
    cos(1/100) is an opaque constant like a real parameter.  det A = 4·y·(q − p) with
    q − p ≠ 0, so on biglide-double-cross (y = t² − 10⁻⁸) the singular times are ±10⁻⁴
    in every feasible mode (the oracle: the zeros of y, by hand)."""
    text = (ROBOTS / "biglide.yaml").read_text().replace(
        "(x - p)^2 + y^2 - 4", "(x - p)^2 + y^2 - 4*cos(1/100)^2")
    (tmp_path / "biglide.yaml").write_text(text)
    out = singcheck("run", str(tmp_path / "biglide.yaml"),
                    str(TRAJECTORIES / "biglide-double-cross.yaml"), "--format", "json", "-q")
    assert out.returncode == 1, out.stderr
    doc = json.loads(out.stdout)
    assert doc["elimination_method"].startswith("not computed: the constant")
    (traj,) = doc["trajectories"]
    feasible = [m for m in traj["working_modes"] if m["feasible"]]
    assert feasible and traj["verdict"] == "singular"
    for m in feasible:
        assert len(m["singular_times"]) == 2
        assert all(abs(abs(t) - 1e-4) < 1e-9 for t in m["singular_times"])
