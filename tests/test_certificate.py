"""Certificates (docs/certificate.md): written by ``run --certificate``, re-checked by
``singcheck.verify`` with flint, sympy and mpmath unimportable; tampering is caught; the
claimed singular times are checked against det A computed independently (mpmath, 50
digits, the Orthoglide's closed-form legs)."""

from __future__ import annotations

import ast
import copy
import json
import subprocess
import sys
import time
from fractions import Fraction

import mpmath
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from singcheck.verify import check, main
from singcheck.verify.numbers import ONE, Iv, cos, sin
from tests.conftest import ROBOTS, ROOT, TRAJECTORIES
from tests.test_cli import singcheck

ORTHO = str(ROBOTS / "orthoglide.yaml")
BLOCKER = """\
import sys
class _Blocker:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('flint', 'sympy', 'mpmath', 'numpy'):
            raise ImportError('blocked for the test: ' + name)
sys.meta_path.insert(0, _Blocker())
"""


@pytest.fixture(scope="module")
def certs(tmp_path_factory):
    """Certificates of heart1 and the helix, written by the command line."""
    folder = tmp_path_factory.mktemp("certs")
    out = singcheck("run", ORTHO, str(TRAJECTORIES / "heart1.yaml"),
                    str(TRAJECTORIES / "helix.yaml"), "--no-regions", "-q", "-j", "1",
                    "--format", "json", "--certificate", str(folder))
    assert out.returncode == 1, out.stderr  # heart1 is singular
    return {name: json.loads((folder / f"{name}.cert.json").read_text())
            for name in ("heart1", "helix")}


def verify_subprocess(tmp_path, cert, blocked: bool = True) -> subprocess.CompletedProcess:
    path = tmp_path / "c.cert.json"
    path.write_text(json.dumps(cert) if isinstance(cert, dict) else cert)
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text(BLOCKER if blocked else "")
    env = {"PYTHONPATH": f"{site}:{ROOT}", "PATH": "/usr/bin:/bin"}
    return subprocess.run([sys.executable, "-m", "singcheck.verify", str(path)],
                          capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120)


def failures(cert: dict) -> list[str]:
    try:
        return check(cert)[0]
    except ValueError as e:  # malformed: exit 2
        return [f"unreadable: {e}"]


@pytest.mark.parametrize("name", ["heart1", "helix"])
def test_verify_passes_with_the_cas_libraries_unimportable(certs, name, tmp_path):
    size = len(json.dumps(certs[name]))
    assert size < 1_000_000
    start = time.perf_counter()
    out = verify_subprocess(tmp_path, certs[name])
    seconds = time.perf_counter() - start
    assert out.returncode == 0, out.stdout + out.stderr
    assert f"proven: {name}: " in out.stdout
    assert seconds < 2.0, seconds


def test_the_blocker_blocks(tmp_path):
    """The import blocker the tests rely on does stop flint and mpmath."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(BLOCKER)
    out = subprocess.run([sys.executable, "-c", "import mpmath"], capture_output=True,
                         text=True, env={"PYTHONPATH": str(site)}, timeout=60)
    assert out.returncode == 1 and "blocked for the test" in out.stderr


def test_the_checker_imports_nothing_of_singcheck_but_itself(certs, tmp_path):
    path = tmp_path / "h.cert.json"
    path.write_text(json.dumps(certs["helix"]))
    script = ("import sys; from singcheck.verify import main; rc = main([sys.argv[1]]); "
              "print(sorted(m for m in sys.modules if m.startswith('singcheck')))")
    out = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True,
                         text=True, env={"PYTHONPATH": str(ROOT)}, timeout=60)
    modules = ast.literal_eval(out.stdout.strip().splitlines()[-1])
    assert "singcheck.verify" in modules
    assert {m for m in modules if not m.startswith("singcheck.verify")} <= {
        "singcheck", "singcheck.version"}


def test_the_checker_is_short():
    """Short enough to review in an afternoon (the aim was 800 lines; with revolute legs,
    pose angles, segments, waypoints, exact roots, exact multiples of π and square roots
    in an exact pose it holds 1,400, docstrings included): this bound keeps it from
    growing unnoticed."""
    lines = sum(len(p.read_text().splitlines())
                for p in (ROOT / "singcheck" / "verify").glob("*.py"))
    assert lines <= 1400, lines


def _plain(value):
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return str(value)


@pytest.mark.parametrize("path", [*sorted(ROBOTS.glob("*.yaml")),
                                  *sorted(TRAJECTORIES.glob("*.yaml"))], ids=lambda p: p.name)
def test_the_checkers_yaml_reader_agrees_with_pyyaml(path):
    """PyYAML as the oracle: every bundled single-document spec reads the same (scalars
    as text); a spec outside the subset is refused, never misread."""
    import yaml

    from singcheck.verify.reader import Refused, parse_yaml

    text = path.read_text()
    documents = [d for d in yaml.safe_load_all(text) if d is not None]
    if len(documents) != 1:
        pytest.skip("several documents: certificates hold one")
    try:
        mine = parse_yaml(text)
    except Refused:
        return
    assert mine == _plain(documents[0])


# --- the claim against independent computations ------------------------------------

def _orthoglide_det(t, mode="+++", x=None, y=None, z=None):
    """det A of the Orthoglide (l = 2) along heart1 at time t, mpmath, from the legs'
    closed form ρ_i = X_i ± sqrt(4 - (other coordinates)²)."""
    x = 8 * mpmath.sin(t) ** 3 / 7 if x is None else x(t)
    y = (13 * mpmath.cos(t) / 14 - 5 * mpmath.cos(2 * t) / 14 - mpmath.cos(3 * t) / 10
         - mpmath.cos(4 * t) / 14) if y is None else y(t)
    z = mpmath.mpf(1) if z is None else z(t)
    s = [1 if ch == "+" else -1 for ch in mode]
    r1 = x + s[0] * mpmath.sqrt(4 - y ** 2 - z ** 2)
    r2 = y + s[1] * mpmath.sqrt(4 - x ** 2 - z ** 2)
    r3 = z + s[2] * mpmath.sqrt(4 - x ** 2 - y ** 2)
    return mpmath.det(mpmath.matrix([[x - r1, y, z], [x, y - r2, z], [x, y, z - r3]]))


def test_heart1_singular_times_hold_a_root_of_det_a(certs):
    mpmath.mp.dps = 50
    spans = certs["heart1"]["claim"]["singular_times"]["+++"]
    assert len(spans) == 2
    for lo, hi in spans:
        a, b = (mpmath.mpf(Fraction(v).numerator) / Fraction(v).denominator for v in (lo, hi))
        assert b - a < 1e-8
        assert _orthoglide_det(a) * _orthoglide_det(b) < 0
    # the paper's two real singularities of the prototype's mode (+++), near 0.978, 1.512
    assert [round(float(Fraction(lo)), 4) for lo, _ in spans] == [0.9778, 1.5119]


def test_helix_det_a_keeps_its_sign(certs):
    mpmath.mp.dps = 30
    c = certs["helix"]
    assert c["claim"]["verdict"] == "singularity-free"
    values = [_orthoglide_det(mpmath.mpf(k) / 10, "+++", mpmath.sin, mpmath.cos,
                              lambda t: t / 20) for k in range(201)]
    assert all(v > 0 for v in values) or all(v < 0 for v in values)
    sign = "+" if values[0] > 0 else "-"
    assert set(c["proof"]["signs"]["+++"]) == {sign}


@given(st.fractions(min_value=-30, max_value=30, max_denominator=10 ** 6),
       st.fractions(min_value=0, max_value=1, max_denominator=1000))
@settings(max_examples=200, deadline=None)
def test_sin_cos_enclose_mpmath(x, w):
    mpmath.mp.dps = 40
    t = Iv.q(x).hull(Iv.q(x + w / 100))
    for k in range(3):
        p = mpmath.mpf(x.numerator) / x.denominator + mpmath.mpf(w.numerator) / w.denominator \
            / 100 * k / 2
        for f, g in ((sin, mpmath.sin), (cos, mpmath.cos)):
            box = f(t)
            assert mpmath.mpf(box.lo) / ONE <= g(p) <= mpmath.mpf(box.hi) / ONE


# --- tampering ---------------------------------------------------------------------

def tampered(cert: dict, where: str, old: str, new: str) -> dict:
    out = copy.deepcopy(cert)
    assert old in out["claim"][where]
    out["claim"][where] = out["claim"][where].replace(old, new, 1)
    return out


@pytest.mark.parametrize("where, old, new", [
    ("robot_spec", "parameters: {l: 2}", "parameters: {l: 201/100}"),
    ("robot_spec", "rho1: [0, 4]", "rho1: [0, 2]"),
    ("trajectory_spec", "x: 8/7*sin(t)^3", "x: 9/7*sin(t)^3"),
    ("trajectory_spec", "5/14*cos(2*t)", "5/14*cos(2*t) + 1/1000"),
    ("trajectory_spec", "range: [-pi, pi]", "range: [-pi, 3/2]"),  # drops t ≈ 1.5119
    ("trajectory_spec", "range: [-pi, pi]", "range: [-pi, 4]"),
    ("trajectory_spec", "range: [-pi, pi]", "range: [-pi, 1]"),
])
def test_tampered_heart1_specs_fail(certs, where, old, new):
    assert failures(tampered(certs["heart1"], where, old, new))


def test_a_claim_still_true_of_edited_specs_still_passes(certs):
    """The checker judges the claim about the specs it holds, not their bytes: on
    [-π, 3] heart1 is still singular at the same two times, and the cover still fits."""
    assert failures(tampered(certs["heart1"], "trajectory_spec", "range: [-pi, pi]",
                             "range: [-pi, 3]")) == []


@pytest.mark.parametrize("where, old, new", [
    ("trajectory_spec", "x: sin(t)", "x: 2*sin(t)"),
    ("trajectory_spec", "range: [0, 20]", "range: [0, 21]"),
    ("robot_spec", "parameters: {l: 2}", "parameters: {l: 1}"),  # legs not real
    ("robot_spec", "rho3: [0, 4]", "rho3: [0, 1]"),  # rho3 = z + sqrt(3) > 1: infeasible
])
def test_tampered_helix_specs_fail(certs, where, old, new):
    assert failures(tampered(certs["helix"], where, old, new))


def test_tampered_claims_fail(certs):
    for name, verdict in (("heart1", "singularity-free"), ("heart1", "infeasible"),
                          ("helix", "singular")):
        c = copy.deepcopy(certs[name])
        c["claim"]["verdict"] = verdict
        assert any("verdict" in f for f in failures(c)), (name, verdict)
    c = copy.deepcopy(certs["heart1"])  # a singular time moved by 0.01
    lo, hi = (Fraction(v) + Fraction(1, 100) for v in c["claim"]["singular_times"]["+++"][0])
    c["claim"]["singular_times"]["+++"][0] = [str(lo), str(hi)]
    assert failures(c)
    c = copy.deepcopy(certs["heart1"])  # a singular time dropped
    c["claim"]["singular_times"]["+++"].pop()
    assert failures(c)
    c = copy.deepcopy(certs["heart1"])  # an infeasible mode said feasible
    c["claim"]["modes"]["-++"] = "feasible"
    c["proof"]["signs"]["-++"] = c["proof"]["signs"]["+++"]
    assert any("-++" in f for f in failures(c))
    c = copy.deepcopy(certs["helix"])  # the feasible mode said infeasible: no witness
    c["claim"]["modes"]["+++"] = "infeasible"
    del c["proof"]["signs"]["+++"]
    c["proof"]["infeasible"]["+++"] = {"t": "1", "leg": 0}
    assert failures(c)
    c = copy.deepcopy(certs["helix"])
    c["claim"]["trajectory"] = "heart1"
    assert failures(c)


@given(st.data())
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
def test_mutated_proofs_never_pass_wrongly(certs, data):
    """A flipped sign always fails; any other mutation of the proof either fails or
    leaves the (true) claim proven — never a crash."""
    name = data.draw(st.sampled_from(["heart1", "helix"]))
    c = copy.deepcopy(certs[name])
    proof = c["proof"]
    kind = data.draw(st.sampled_from(["flip", "cut", "drop", "witness"]))
    if kind == "flip":
        s = proof["signs"]["+++"]
        i = data.draw(st.sampled_from([k for k, ch in enumerate(s) if ch != "0"]))
        proof["signs"]["+++"] = s[:i] + ("-" if s[i] == "+" else "+") + s[i + 1:]
        assert failures(c)
        return
    if kind == "cut":
        i = data.draw(st.integers(0, len(proof["cuts"]) - 1))
        proof["cuts"][i] = str(data.draw(st.fractions(-25, 25, max_denominator=2 ** 20)))
    elif kind == "drop":
        i = data.draw(st.integers(0, len(proof["cuts"]) - 1))
        del proof["cuts"][i]
        proof["signs"] = {m: s[:i] + s[i + 1:] for m, s in proof["signs"].items()}
    else:
        mode = data.draw(st.sampled_from(sorted(proof["infeasible"])))
        proof["infeasible"][mode] = {"t": str(data.draw(st.fractions(-25, 25))),
                                     "leg": data.draw(st.integers(-1, 3))}
    fails = failures(c)
    assert all(not f.startswith("unreadable") for f in fails)


# --- unreadable files and odd specs ------------------------------------------------

@pytest.mark.parametrize("text", ["not json", "[]", '{"format": "singcheck-certificate"}',
                                  '{"format": "other", "version": 1}'])
def test_unreadable_files_exit_2(tmp_path, text):
    out = verify_subprocess(tmp_path, text)
    assert out.returncode == 2 and out.stdout.count("\n") == 1 and "unreadable" in out.stdout


@pytest.mark.parametrize("old, new", [
    ("parameters: {l: 2}", "parameters: {l: __import__('os').getpid()}"),
    ("parameters: {l: 2}", "parameters: !!python/object:os.system {l: 2}"),
    ("parameters: {l: 2}", "parameters: &a {l: 2}"),
    ("parameters: {l: 2}", "parameters: {l: 2x}"),
    ("parameters: {l: 2}", "parameters: {l: 2^100000}"),
    ("parameters: {l: 2}", "parameters:\t{l: 2}"),
    ("name: orthoglide", "name: orthoglide\nname: again"),
])
def test_odd_specs_are_refused_in_one_line(certs, tmp_path, old, new):
    out = verify_subprocess(tmp_path, tampered(certs["heart1"], "robot_spec", old, new))
    assert out.returncode == 2, out.stdout
    assert out.stdout.count("\n") == 1 and "Traceback" not in out.stderr


def test_constants_that_are_not_rational_are_not_recheckable(tmp_path):
    from singcheck.certify.certificate import build_certificate

    robot = (ROBOTS / "linear-delta.yaml").read_text()  # s3: sqrt(3)
    path = (TRAJECTORIES / "linear-delta-free.yaml").read_text()
    cert = build_certificate(robot, path, {"name": "linear-delta-free",
                                           "verdict": "singularity-free",
                                           "working_modes": [], "candidates": []})
    assert cert["proof"] is None and "not_recheckable" in cert
    out = verify_subprocess(tmp_path, cert)
    assert out.returncode == 1 and "not re-checkable" in out.stdout
    cert["proof"] = {"cuts": [], "signs": {}, "infeasible": {}}  # a forged proof
    assert failures(cert)


def test_certificate_file_names_are_safe(tmp_path):
    from singcheck.certify.certificate import write_certificate

    used: set = set()
    for name in ["../../evil", "a/b", "x\x00y", "..", "heart1", "heart1"]:
        target = write_certificate(tmp_path, {"claim": {"trajectory": name}}, used)
        assert target.parent == tmp_path and target.resolve().parent == tmp_path.resolve()
        assert "/" not in target.name and "\x00" not in target.name
        assert target.name.endswith(".cert.json") and not target.name.startswith(".")
    assert len(list(tmp_path.iterdir())) == 6


def test_certificates_validate_against_their_schema(certs):
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((ROOT / "singcheck" / "schemas" / "certificate.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    v = jsonschema.Draft202012Validator(schema)
    for cert in certs.values():
        assert [e.message for e in v.iter_errors(cert)] == []
    bad = copy.deepcopy(certs["helix"])
    bad["proof"]["cuts"][0] = "0.5"
    assert list(v.iter_errors(bad))


def test_the_verify_command_and_module_agree(certs, tmp_path):
    path = tmp_path / "h.cert.json"
    path.write_text(json.dumps(certs["helix"]))
    out = singcheck("verify", str(path))
    assert out.returncode == 0 and "proven: helix: singularity-free" in out.stdout
    assert main([str(path), str(tmp_path / "missing.json")]) == 2


@pytest.fixture(scope="module")
def graze(tmp_path_factory):
    folder = tmp_path_factory.mktemp("graze")
    out = singcheck("run", str(ROBOTS / "biglide.yaml"), str(TRAJECTORIES / "biglide-graze.yaml"),
                    "--no-regions", "-q", "--format", "json", "--certificate", str(folder))
    assert out.returncode == 1, out.stderr
    return json.loads((folder / "biglide-graze.cert.json").read_text())


def test_a_tangency_at_a_rational_time_is_proven_exactly(graze):
    """biglide-graze touches y = 0 at t = 0: det A = 4y(q − p) (by hand, from the two
    circles' Jacobian) vanishes there without changing sign; the checker proves det A = 0
    exactly at t = 0 in Q(√D₁, √D₂)."""
    assert failures(graze) == []
    for mode, spans in graze["claim"]["singular_times"].items():
        (lo, hi), = spans
        assert Fraction(lo) <= 0 <= Fraction(hi)
        assert graze["proof"]["exact_roots"][mode] == ["0"]
    c = copy.deepcopy(graze)  # the exact root moved off the tangency
    c["proof"]["exact_roots"]["++"] = ["1/2"]
    assert any("not re-checked: working mode ++" in f for f in failures(c))
    c = copy.deepcopy(graze)  # the path no longer touches y = 0
    c["claim"]["trajectory_spec"] = c["claim"]["trajectory_spec"].replace(
        "y: t^2", "y: t^2 + 1/10")
    assert failures(c)


@pytest.fixture(scope="module")
def five_bar(tmp_path_factory):
    folder = tmp_path_factory.mktemp("five-bar")
    out = singcheck("run", str(ROBOTS / "five-bar.yaml"), str(TRAJECTORIES / "five-bar-cross.yaml"),
                    str(TRAJECTORIES / "five-bar-free.yaml"), "--no-regions", "-q", "-j", "1",
                    "--format", "json", "--certificate", str(folder))
    assert out.returncode == 1, out.stderr
    return {n: json.loads((folder / f"{n}.cert.json").read_text())
            for n in ("five-bar-cross", "five-bar-free")}


def _five_bar_dets(t):
    """det A of the five-bar (d = 1, l1 = l2 = 2) on five-bar-cross (x = 0, y = 3 − 2t)
    at time t for each pair of IK solutions inside the joint limits, by mpmath: each
    θ solves |(x ± d, y) − 2(cos θ, sin θ)| = 2 (two circles meeting)."""
    x, y = mpmath.mpf(0), 3 - 2 * t
    legs = []
    for base, (lo, hi) in ((-1, (mpmath.pi / 3, mpmath.pi)), (1, (0, 2 * mpmath.pi / 3))):
        px, py = x - base, y  # the point seen from the leg's base
        r = mpmath.sqrt(px ** 2 + py ** 2)
        half = mpmath.acos(r / 4)  # the triangle (2, 2, r): angle at the base
        sols = [mpmath.atan2(py, px) + s * half for s in (1, -1)]
        legs.append([th for th in sols if lo <= th % (2 * mpmath.pi) <= hi])
    out = []
    for th1 in legs[0]:
        for th2 in legs[1]:
            out.append(mpmath.det(mpmath.matrix(
                [[2 * (x + 1 - 2 * mpmath.cos(th1)), 2 * (y - 2 * mpmath.sin(th1))],
                 [2 * (x - 1 - 2 * mpmath.cos(th2)), 2 * (y - 2 * mpmath.sin(th2))]])))
    return out


def test_five_bar_certificates_check_revolute_legs(five_bar):
    """Revolute legs: (cos θ, sin θ) enclosed from a·cos θ + b·sin θ + d = 0, the angle
    limits as arcs.  The claimed singular time holds a sign change of det A computed by
    mpmath (50 digits) for the pair of IK solutions inside the limits."""
    mpmath.mp.dps = 50
    assert failures(five_bar["five-bar-free"]) == []
    cross = five_bar["five-bar-cross"]
    assert failures(cross) == []
    (mode, spans), = cross["claim"]["singular_times"].items()
    (lo, hi), = spans
    a, b = (mpmath.mpf(Fraction(v).numerator) / Fraction(v).denominator for v in (lo, hi))
    before, after = _five_bar_dets(a), _five_bar_dets(b)
    assert len(before) == len(after) == 1 and before[0] * after[0] < 0
    c = tampered(cross, "robot_spec", "th2: [0, 2*pi/3]", "th2: [0, pi/3]")
    assert failures(c)


@pytest.mark.parametrize("old, new", [
    ("parameters: {l: 2}", "parameters: {l: ((2^64)^64)^64}"),  # a constant too large
    ("parameters: {l: 2}", "parameters: {l: 1/0}"),
])
def test_hostile_constants_are_refused_in_one_line(certs, tmp_path, old, new):
    out = verify_subprocess(tmp_path, tampered(certs["heart1"], "robot_spec", old, new))
    assert out.returncode == 2 and out.stdout.count("\n") == 1, out.stdout + out.stderr


def test_hostile_paths_are_refused_or_fail(certs, tmp_path):
    for old, new in (("range: [-pi, pi]", "range: [1/(pi - pi), pi]"),
                     ("z: 1", "z: ((((t + 2)^64)^64)^64)^64")):
        out = verify_subprocess(tmp_path, tampered(certs["heart1"], "trajectory_spec", old,
                                                   new))
        assert out.returncode in (1, 2) and "Traceback" not in out.stderr, out.stderr


def _three_prr_det(t, mode):
    """det A of the 3-PRR (legs of length 3) on 3-prr-cross at time t by mpmath: the legs'
    closed forms (branch '+' adds the square root), A = ∂F/∂(x, y, φ) by hand."""
    x, y, phi = 3 / mpmath.mpf(2) + mpmath.sin(t) / 2, 2 - mpmath.cos(t) / 2, t
    c, s = mpmath.cos(phi), mpmath.sin(phi)
    sg = [1 if ch == "+" else -1 for ch in mode]
    r1 = x + sg[0] * mpmath.sqrt(9 - y ** 2)
    r2 = y + s + sg[1] * mpmath.sqrt(9 - (x + c - 5) ** 2)
    r3 = x - s + sg[2] * mpmath.sqrt(9 - (y + c - 5) ** 2)
    u2, v2, u3, v3 = x + c - 5, y + s - r2, x - s - r3, y + c - 5
    return mpmath.det(mpmath.matrix([[2 * (x - r1), 2 * y, 0],
                                     [2 * u2, 2 * v2, -2 * u2 * s + 2 * v2 * c],
                                     [2 * u3, 2 * v3, -2 * u3 * c - 2 * v3 * s]]))


def test_pose_angles_are_rechecked(tmp_path):
    """The 3-PRR's pose angle φ enters through cos φ, sin φ (∂/∂φ by the chain rule); the
    claimed crossing holds a sign change of det A computed by mpmath."""
    mpmath.mp.dps = 50
    out = singcheck("run", str(ROBOTS / "3-prr.yaml"), str(TRAJECTORIES / "3-prr-cross.yaml"),
                    "--no-regions", "-q", "--format", "json", "--certificate", str(tmp_path))
    assert out.returncode == 1, out.stderr
    cert = json.loads((tmp_path / "3-prr-cross.cert.json").read_text())
    assert failures(cert) == []
    times = cert["claim"]["singular_times"]
    assert times
    for mode, spans in times.items():
        for lo, hi in spans:
            a, b = (mpmath.mpf(Fraction(v).numerator) / Fraction(v).denominator
                    for v in (lo, hi))
            assert _three_prr_det(a, mode) * _three_prr_det(b, mode) < 0
    assert failures(tampered(cert, "trajectory_spec", "phi: t", "phi: t/2"))


from tests.test_paths import SEGMENTS_YAML as SEGMENTS  # noqa: E402 (the docs' example)


def test_paths_of_segments_are_rechecked(tmp_path):
    """Segments joined at rational times: the cover cuts at each join, the pose is
    proven continuous there exactly; the claimed singular time holds a sign change of
    det A by mpmath (the line of its segment)."""
    mpmath.mp.dps = 50
    spec = tmp_path / "pp.yaml"
    spec.write_text(SEGMENTS)
    out = singcheck("run", ORTHO, str(spec), "--no-regions", "-q", "--format", "json",
                    "--certificate", str(tmp_path / "certs"))
    assert out.returncode == 1, out.stderr
    cert = json.loads((tmp_path / "certs" / "pick-and-place.cert.json").read_text())
    assert failures(cert) == []
    assert "1" in cert["proof"]["cuts"]
    spans = [s for m in cert["claim"]["singular_times"].values() for s in m]
    assert spans
    for lo, hi in cert["claim"]["singular_times"]["+++"]:
        a, b = (mpmath.mpf(Fraction(v).numerator) / Fraction(v).denominator for v in (lo, hi))
        line = (lambda t: mpmath.mpf(1) / 4 + 13 * t / 20, lambda t: 3 / mpmath.mpf(5) + t / 2,
                lambda t: mpmath.mpf(1)) if b < 1 else \
            (lambda t: 3 / mpmath.mpf(5) + 3 * t / 10, lambda t: 19 / mpmath.mpf(10) - 4 * t / 5,
             lambda t: mpmath.mpf(1))
        assert a > 1 or b < 1
        assert _orthoglide_det(a, "+++", *line) * _orthoglide_det(b, "+++", *line) < 0
    assert failures(tampered(cert, "trajectory_spec", "range: [1, 2]", "range: [1, 3]"))
    jump = tampered(cert, "trajectory_spec", "x: 3/5 + 3/10*t", "x: 3/5 + 3/10*t + 1/100")
    assert any("jumps" in f for f in failures(jump))


WAYPOINTS = """\
name: through-waypoints
parameter: t
interpolation: {kind}
waypoints:
  - {{t: 0, x: 1/4, y: 3/5, z: 1}}
  - {{t: 1, x: 9/10, y: 11/10, z: 1}}
  - {{t: 2, x: 6/5, y: 3/10, z: 1}}
"""


@pytest.mark.parametrize("kind", ["cubic", "linear"])
def test_paths_through_waypoints_are_rechecked(tmp_path, kind):
    """The checker builds the natural cubic spline (or the lines) itself, over Q; the
    claimed singular times hold a sign change of det A along SciPy's natural spline."""
    interpolate = pytest.importorskip("scipy.interpolate")
    spec = tmp_path / "wp.yaml"
    spec.write_text(WAYPOINTS.format(kind=kind))
    out = singcheck("run", ORTHO, str(spec), "--no-regions", "-q", "--format", "json",
                    "--certificate", str(tmp_path / "certs"))
    assert out.returncode == 1, out.stderr
    cert = json.loads((tmp_path / "certs" / "through-waypoints.cert.json").read_text())
    assert failures(cert) == []
    ts, xs, ys = [0, 1, 2], [0.25, 0.9, 1.2], [0.6, 1.1, 0.3]
    if kind == "cubic":
        fx, fy = (interpolate.CubicSpline(ts, v, bc_type="natural") for v in (xs, ys))
    else:
        np = pytest.importorskip("numpy")
        fx, fy = (lambda t, v=v: np.interp(t, ts, v) for v in (xs, ys))
    mpmath.mp.dps = 30
    spans = cert["claim"]["singular_times"]["+++"]
    assert spans
    for lo, hi in spans:
        d = [_orthoglide_det(float(Fraction(v)), "+++", lambda t: mpmath.mpf(float(fx(t))),
                             lambda t: mpmath.mpf(float(fy(t))), lambda t: mpmath.mpf(1))
             for v in (lo, hi)]
        assert d[0] * d[1] < 0
    assert failures(tampered(cert, "trajectory_spec", "x: 9/10", "x: 8/10"))


def _expressions():
    """Texts of rational expressions built from the grammar (numbers in every exact
    form, + - * / ^ **, parentheses, unary signs)."""
    number = st.sampled_from(["2", "0.1", "1e-3", "3/4", ".5", "17", "2.50", "1E2"])
    return st.recursive(number, lambda inner: st.one_of(
        st.tuples(inner, st.sampled_from([" + ", " - ", "*", " / "]), inner).map("".join),
        st.tuples(inner, st.sampled_from(["^", "**"]), st.sampled_from(["0", "1", "2", "3"]))
        .map(lambda p: f"({p[0]}){p[1]}{p[2]}"),
        inner.map(lambda e: f"-({e})"), inner.map(lambda e: f"+{e}")), max_leaves=12)


@given(_expressions())
@settings(max_examples=300, deadline=None)
def test_the_checkers_grammar_agrees_with_singcheck(text):
    """Two independent readers of the expression grammar give the same exact value
    (or both refuse: a division by zero)."""
    _agree(text)


@pytest.mark.parametrize("text", ["-2^2", "2^3^2", "2**-1", "2^1/2", "(1/3)^2*9", "2 3",
                                  "1/(2-2)", "2^65", "0.1e1", "1/2/3", "2x", "--1"])
def test_the_checkers_grammar_agrees_on_corner_cases(text):
    _agree(text)


def _agree(text: str) -> None:
    from singcheck.spec.grammar import ExprError, compile_constant, parse
    from singcheck.verify.reader import Refused, constant, parse_expr

    try:
        theirs = compile_constant(parse(text))
    except (ExprError, ZeroDivisionError):
        theirs = None
    try:
        mine = constant(parse_expr(text))
    except Refused:
        mine = None
    if theirs is None or mine is None:
        assert theirs is None and mine is None, (text, theirs, mine)
    else:
        assert theirs.pi_coefficient == 0 and theirs.rational == mine, text


def test_an_infeasible_path_is_proven_by_its_witnesses(tmp_path):
    """leaves-workspace (x = 3 sin t on [0, π/2]): every mode leaves the workspace or the
    limits; each witness is re-checked by mpmath from the legs' closed form."""
    mpmath.mp.dps = 30
    out = singcheck("run", ORTHO, str(TRAJECTORIES / "leaves-workspace.yaml"), "--no-regions",
                    "-q", "--format", "json", "--certificate", str(tmp_path))
    assert out.returncode == 1, out.stderr
    cert = json.loads((tmp_path / "leaves-workspace.cert.json").read_text())
    assert cert["claim"]["verdict"] == "infeasible" and failures(cert) == []
    for mode, w in cert["proof"]["infeasible"].items():
        t = mpmath.mpf(Fraction(w["t"]).numerator) / Fraction(w["t"]).denominator
        pose = [3 * mpmath.sin(t), mpmath.mpf(0), mpmath.mpf(1)]
        k = w["leg"]
        d = 4 - sum(v ** 2 for i, v in enumerate(pose) if i != k)
        if d >= 0:
            rho = pose[k] + (1 if mode[k] == "+" else -1) * mpmath.sqrt(d)
            assert not 0 <= rho <= 4, (mode, w)
    c = copy.deepcopy(cert)
    c["claim"]["modes"]["+++"] = "feasible"
    c["claim"]["verdict"] = "singularity-free"
    c["proof"]["signs"]["+++"] = "+" * (len(c["proof"]["cuts"]) + 1)
    assert failures(c)


def test_one_certificate_per_document_of_a_batch(tmp_path):
    """A file of two documents, two workers, jsonl: each trajectory gets its own
    certificate holding its own document's text."""
    spec = tmp_path / "two.yaml"
    spec.write_text((TRAJECTORIES / "heart2.yaml").read_text() + "---\n"
                    + (TRAJECTORIES / "helix.yaml").read_text())
    out = singcheck("run", ORTHO, str(spec), "--no-regions", "-q", "-j", "2", "--format",
                    "jsonl", "--certificate", str(tmp_path / "certs"))
    assert out.returncode == 0, out.stderr
    assert len(out.stdout.splitlines()) == 2
    names = sorted(p.name for p in (tmp_path / "certs").iterdir())
    assert names == ["heart2.cert.json", "helix.cert.json"]
    for name in ("heart2", "helix"):
        cert = json.loads((tmp_path / "certs" / f"{name}.cert.json").read_text())
        assert f"name: {name}\n" in cert["claim"]["trajectory_spec"]
        assert cert["claim"]["trajectory_spec"].count("name:") == 1
        assert main([str(tmp_path / "certs" / f"{name}.cert.json")]) == 0


def test_a_path_starting_and_ending_on_the_singularity_is_proven(tmp_path):
    """biglide, x = t, y = sin(2πt)/2 on [0, 1] (the interval engine alone: π·t): det A =
    4·y·(q − p) vanishes at t = 0, 1/2 and 1 in every mode.  The pieces touching an end
    cannot get a sign; the checker accepts them inside a claimed singular time reaching
    past that end whose exact root it proves itself (sin(2π·0) and sin(2π·1) evaluated in
    Q + Qπ).  Before, the certificate said `incomplete` and verify refused it."""
    mpmath.mp.dps = 50
    for t in (0, mpmath.mpf(1) / 2, 1):  # the oracle: y = 0 there, q − p = ±2 ± 3/2 ≠ 0
        assert abs(mpmath.sin(2 * mpmath.pi * t)) < mpmath.mpf(10) ** -45
    robot = tmp_path / "biglide.yaml"
    robot.write_text((ROBOTS / "biglide.yaml").read_text())
    traj = tmp_path / "p.yaml"
    traj.write_text("name: p\nparameter: t\nrange: [0, 1]\npose:\n  x: t\n"
                    "  y: sin(2*pi*t)/2\n")
    out = singcheck("run", str(robot), str(traj), "--no-regions", "-q", "--format", "json",
                    "--certificate", str(tmp_path))
    assert out.returncode == 1, out.stderr
    cert = json.loads((tmp_path / "p.cert.json").read_text())
    assert "incomplete" not in cert and failures(cert) == []
    for mode, roots in cert["proof"]["exact_roots"].items():
        assert roots == ["0", "1/2", "1"], mode
        first, *_, last = cert["claim"]["singular_times"][mode]
        assert Fraction(first[0]) <= 0 <= Fraction(first[1])
        assert Fraction(last[0]) <= 1 <= Fraction(last[1])
        assert cert["proof"]["signs"][mode][0] == cert["proof"]["signs"][mode][-1] == "0"
    c = copy.deepcopy(cert)  # the end's exact root taken away: the end run is unproven
    c["proof"]["exact_roots"]["++"] = ["1/2", "1"]
    assert any("working mode ++ singular in t ∈ [-" in f for f in failures(c))
    c = copy.deepcopy(cert)  # an exact root outside the range does not count
    c["claim"]["trajectory_spec"] = c["claim"]["trajectory_spec"].replace("[0, 1]",
                                                                         "[1/1000, 1]")
    assert failures(c)
    c = copy.deepcopy(cert)  # the first span no longer reaches the start
    c["claim"]["singular_times"]["--"][0][0] = "1/1000000000000"
    assert any("working mode --: det A not proven ≠ 0 on pieces 1 to" in f for f in failures(c))


@pytest.mark.parametrize("k", range(-13, 14))
def test_exact_sines_of_multiples_of_pi_agree_with_mpmath(k):
    """The checker's exact values of sin and cos at kπ/6 (a path's pose at a rational
    time, such as sin(2πt) at t = 1/12), against mpmath at 50 digits: rational where
    they are, refused (NotDecided) where not (√3/2)."""
    from singcheck.verify.checker import EXACT, value
    from singcheck.verify.numbers import NotDecided
    from singcheck.verify.reader import parse_expr

    mpmath.mp.dps = 50
    for fn, exact in (("sin", mpmath.sin), ("cos", mpmath.cos)):
        truth = exact(k * mpmath.pi / 6)
        rational = [q for q in (-1, Fraction(-1, 2), 0, Fraction(1, 2), 1)
                    if abs(truth - mpmath.mpf(q.numerator if isinstance(q, Fraction) else q)
                           / (q.denominator if isinstance(q, Fraction) else 1)) < 1e-40]
        for text in (f"{fn}({k}*pi*t/6)", f"{fn}(pi*t*{k}/6 + 1 - 1)"):
            try:
                got = value(parse_expr(text), {"t": Fraction(1)}, EXACT)
            except NotDecided:
                got = None
            assert got == (rational[0] if rational else None), (text, truth)


def test_surds_add_multiply_and_compare_exactly():
    """Square roots at an exact time: Σ c·√k with k squarefree, rational when it is."""
    from singcheck.verify.checker import EXACT, NotDecided, _Surd

    two, three = EXACT["sqrt"](Fraction(2)), EXACT["sqrt"](Fraction(3))
    assert isinstance(two, _Surd) and EXACT["sqrt"](Fraction(8)) == two * 2
    assert two * two == 2 and isinstance(two * two, Fraction)
    assert (two + three) ** 2 == 5 + 2 * EXACT["sqrt"](Fraction(6))
    assert two - two == 0 and (two + 1) * (two - 1) == 1
    assert EXACT["sqrt"](Fraction(9, 4)) == Fraction(3, 2)
    assert EXACT["sqrt"](Fraction(1, 2)) == two / 2
    for undecided in (lambda: 1 / two, lambda: EXACT["sin"](two),
                      lambda: EXACT["sqrt"](two), lambda: two ** -1,
                      lambda: EXACT["sqrt"](Fraction(-1))):
        with pytest.raises(NotDecided):
            undecided()


def test_a_pose_with_a_square_root_is_rechecked_at_its_exact_zeros(tmp_path):
    """The biglide (det A = 4y(q − p)) on x = √2·t/2, y = sin(2πt)/2 over [0, 2]: y = 0
    exactly at t = k/2 (the oracle), three crossings and two range ends, where the pose
    is (k/√2, 0); the ends hold no sign change, so the checker proves det A = 0 there
    exactly, with √2 in the legs' branches.  Claiming t = 1/4 singular fails."""
    path = tmp_path / "p.yaml"
    path.write_text("name: p\nparameter: t\nrange: [0, 2]\npose:\n  x: sqrt(2)*t/2\n"
                    "  y: sin(2*pi*t)/2\n")
    out = singcheck("run", str(ROBOTS / "biglide.yaml"), str(path), "--no-regions", "-q",
                    "--format", "json", "--certificate", str(tmp_path))
    assert out.returncode == 1, out.stderr
    cert = json.loads((tmp_path / "p.cert.json").read_text())
    assert failures(cert) == []
    for spans in cert["claim"]["singular_times"].values():
        centres = sorted((Fraction(lo) + Fraction(hi)) / 2 for lo, hi in spans)
        assert [round(2 * float(c)) for c in centres] == [0, 1, 2, 3, 4]
        assert all(abs(2 * c - round(2 * c)) < Fraction(1, 10**6) for c in centres)
    forged = copy.deepcopy(cert)
    for spans in forged["claim"]["singular_times"].values():
        spans.append(["1/4", "1/4"])
    assert failures(forged)
