"""The ``singcheck`` command group: parse options, call :mod:`singcheck.api`, render.

stdout carries the result (a table, or JSON with ``--format json``); stderr carries
progress, notes and errors.  Library errors become exit codes in
:func:`singcheck.cli.exitcodes.exit_codes` and :func:`main`, nowhere else.
"""

from __future__ import annotations

import os
import sys

import click

from singcheck.cli.exitcodes import ExitCode, exit_codes, fail
from singcheck.collector import fewer_collections
from singcheck.errors import SpecError, UnsupportedRobotError
from singcheck.report.progress import Progress
from singcheck.version import __version__

RUN_EPILOG = """\b
Examples:
  singcheck run robots/orthoglide.yaml trajectories/heart1.yaml
  singcheck run robots/orthoglide.yaml trajectories/*.yaml --format json > report.json
  cat paths/*.yaml | singcheck run robots/orthoglide.yaml - --format jsonl
  singcheck run robots/orthoglide.yaml paths.yaml --format junit -o report.xml
  singcheck run robots/orthoglide.yaml paths.yaml --scheduler tcp://10.0.0.5:8786
  singcheck run robots/orthoglide.yaml - --csv --columns t=time,x=X_mm,y=Y_mm,z=Z_mm \\
    --scale x=1/1000,y=1/1000,z=1/1000 < log.csv

\b
Working modes (+++, +-, ooo, ...): one character per leg, in the order of the joints:
  +  the branch with +√D: ρ = (-b + √D)/(2a) for a leg quadratic in its joint ρ;
     for a revolute joint θ, the branch with +√Δ in (cos θ, sin θ) (one elbow posture)
  -  the other branch: -√D (the other elbow posture)
  o  the only branch of a leg linear in its joint (ρ = -c/b): nothing to choose
A mode is feasible when each of its branches stays real, apart from the other branch
and inside the joint limits along the whole path.  A robot runs in one mode: --mode
LABEL (or mode: LABEL in a trajectory document, quoted: mode: "-+") makes the verdict,
exit status, table and JSON about that mode alone; --start-joints th1=pi/2,th2=0.3
picks the one mode whose joints at the start are within 1e-6 of those values (for an
angle, of (cos, sin): about 1e-6 rad); none or several is an error (exit 2).

\b
Clearance (--clearance, --min-clearance D): κ(t), the smallest singular value of the
leg-normalised Jacobian D^(-1/2)·A (A = ∂F/∂X, each leg's row scaled to length 1), is
0 exactly at a parallel singularity and 1 where the legs' rows are orthonormal; a pose
angle's column is divided by the robot's clearance: {length: L} (default 1).  Each
considered mode gets its certified minimum over the path and where, within
1e-6·max(κ, 1e-3) (ball arithmetic, branch-and-bound over t).  With --min-clearance D a
nonsingular path whose κ is proven below D is near-singular (exit 1).

\b
Exit status:
  0  every trajectory is proven singularity-free
  1  some trajectory is singular, infeasible or near-singular (--min-clearance)
  2  bad command line or bad spec file
  3  some trajectory could not be decided (unknown), none singular
  4  an elimination backend is missing or failed
  70 internal error
  130 interrupted (Ctrl-C, SIGTERM, SIGHUP)
A batch exits with its worst outcome (0 < 3 < 1 < 2 < 4 < 70): a trajectory's own
failure (time limit: unknown; bad document past the first 100, backend or internal
error: error) is its result, never the end of the batch.
"""


class _Commands(click.Group):
    """singcheck's command group: ``workspace`` and ``jointspace`` (cli/spaces.py, with
    the region machinery they need) are loaded only when named or listed, so that
    ``run`` starts without them."""

    _LAZY = ("workspace", "jointspace")

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*super().list_commands(ctx), *self._LAZY})

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name in self._LAZY and name not in self.commands:
            _register_space_commands()
        return super().get_command(ctx, name)


@click.group(cls=_Commands,
             context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="singcheck")
def cli() -> None:
    """Prove whether a parallel robot's trajectory is free of parallel singularities.

    singcheck follows Jha, Chablat, Rouillier & Moroz (IDETC 2015): the robot
    F(ρ, X) = 0 is projected onto its workspace (ξ(X), eliminating the joints), the
    trajectory X = φ(t) is substituted, and every real root of μ(t) = ξ(φ(t)) is
    isolated in a certified interval.  Each candidate is then classified per working
    mode (inverse-kinematics branch) as a real singularity or a spurious one.

    Answers are proven with exact arithmetic and rigorous ball arithmetic, or reported
    as "unknown" with the reason; nothing is decided by sampling.
    """


@cli.command(epilog=RUN_EPILOG)
@click.argument("robot", type=click.Path(dir_okay=False))
@click.argument("trajectories", nargs=-1, required=True, type=click.Path(dir_okay=False,
                                                                        allow_dash=True))
@click.option("--backend",
              type=click.Choice(["auto", "singular", "macaulay2", "sympy", "flint"]),
              default="auto", envvar="SINGCHECK_BACKEND", show_default=True, show_envvar=True,
              help="Elimination engine for the robot's projection; auto picks Singular, else "
                   "Macaulay2, else SymPy, and hands a request the CAS does not finish in "
                   "60 s to flint (see `singcheck backends`).")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True), default=600,
              show_default=True, help="Wall-clock limit in seconds for each CAS run.")
@click.option("--no-cache", is_flag=True,
              help="Neither read nor write the cache of elimination results and region "
                   "maps (see `singcheck cache`).")
@click.option("--tolerance", type=click.FloatRange(min=0, min_open=True), default=1e-9,
              show_default=True, help="Width of the certified enclosure of each root in t.")
@click.option("--format", "fmt", type=click.Choice(["table", "json", "jsonl", "junit"]),
              default="table", show_default=True,
              help="table for people; json for programs (its JSON Schema: singcheck schema "
                   "report); jsonl: one JSON object per trajectory, with time_s, written as "
                   "each one finishes; junit: JUnit XML for CI test reports.")
@click.option("-o", "--output", type=click.Path(dir_okay=False, writable=True),
              help="Write the result to this file (atomically: nothing if interrupted) "
                   "instead of stdout.")
@click.option("-j", "--jobs", type=click.IntRange(min=1), default=os.cpu_count() or 1,
              show_default="number of cores",
              help="Processes certifying trajectories in parallel (used for more than 4).")
@click.option("--time-limit", type=click.FloatRange(min=0, min_open=True),
              default=300, show_default=True,
              help="Seconds allowed to each trajectory (its certification and its region "
                   "statement); past it the trajectory is unknown: time limit.")
@click.option("--no-regions", is_flag=True,
              help="Skip the workspace-region statement (where the path lies among the "
                   "regions of the workspace): faster batches.")
@click.option("--regions", "wait_regions", is_flag=True,
              help="Wait for the workspace-region statement however long it takes (within "
                   "--time-limit); by default it gets 2 s beside the verdict and is left "
                   "out, with the reason, past them.")
@click.option("--scheduler", metavar="ADDRESS", envvar="SINGCHECK_SCHEDULER",
              show_envvar=True,
              help="Run the batch on this dask.distributed scheduler (e.g. "
                   "tcp://10.0.0.5:8786): one task per trajectory; needs "
                   "pip install 'singcheck[dask]'.")
@click.option("--plot", "plot_dir", type=click.Path(file_okay=False),
              help="Also write the figures (see `singcheck plot`) to this directory.")
@click.option("--interpolation", type=click.Choice(["linear", "cubic"]), default="cubic",
              show_default=True,
              help="How a CSV table of poses (TRAJECTORY ending in .csv, or any with --csv) "
                   "is joined: straight lines, or the natural cubic spline through its rows.")
@click.option("--csv", "as_csv", is_flag=True,
              help="Read every TRAJECTORY, - (standard input) included, as a CSV table of "
                   "poses, whatever its name.")
@click.option("--columns", metavar="VAR=COLUMN,...",
              help="CSV column map: read each pose variable (or the parameter) from the "
                   "column with that header, e.g. t=time,x=X_mm,y=Y_mm; columns it does not "
                   "name are ignored.")
@click.option("--scale", metavar="VAR=FACTOR,...",
              help="Multiply a CSV column by an exact factor, e.g. x=1/1000,y=1/1000 for "
                   "millimetres (or 0.001).")
@click.option("--engine", type=click.Choice(["auto", "exact", "interval"]), default="auto",
              show_default=True,
              help="auto: the interval engine (det A enclosed along each feasible mode) "
                   "first, the exact engine (μ and its certified roots) to corroborate it "
                   "(within 5 s) or to decide what the intervals leave, the intervals alone "
                   "on a path the exact engine refuses; exact: the exact engine, held "
                   "against the intervals, and such a path refused; interval: the interval "
                   "engine alone (a tangency stays unknown).")
@click.option("--certificate", "certificate_dir", type=click.Path(file_okay=False),
              help="Write DIR/<trajectory>.cert.json for each trajectory: the claim and a "
                   "proof that `singcheck verify` re-checks without a CAS.")
@click.option("--mode", "mode", metavar="LABEL",
              help="The robot's working mode (e.g. +-+, see below): the verdict, exit status, "
                   "table and JSON are about it alone; overrides a document's mode key.")
@click.option("--start-joints", metavar="NAME=VALUE,...",
              help="Pick the working mode whose joints at each path's start are within 1e-6 "
                   "of these exact values (angles in radians, pi allowed; for an angle the "
                   "distance of (cos, sin)); no match or several is an error.")
@click.option("--clearance", "want_clearance", is_flag=True,
              help="Also certify each considered mode's minimum clearance κ over the path "
                   "(see below).")
@click.option("--min-clearance", type=click.FloatRange(min=0, min_open=True), metavar="D",
              help="A nonsingular path whose clearance κ in a considered mode is proven "
                   "below D is near-singular (exit 1); implies --clearance.")
@click.option("-q", "--quiet", is_flag=True, help="No progress notes on stderr.")
@click.option("-v", "--verbose", is_flag=True,
              help="Show root enclosures and the proof used for every mode and candidate.")
def run(robot, trajectories, backend, timeout, no_cache, tolerance, fmt, output, jobs,
        time_limit, no_regions, wait_regions, scheduler, plot_dir, interpolation, as_csv,
        columns, scale, engine, certificate_dir, mode, start_joints, want_clearance,
        min_clearance, quiet,
        verbose) -> None:  # engine: which certifies (--backend eliminates)
    """Certify each TRAJECTORY of ROBOT (YAML spec files; - reads standard input; a
    trajectory may also be a CSV table of poses).  A YAML file may hold several
    trajectories as documents separated by ---; their names must be unique in a run.
    They are read one at a time as the batch goes, so memory stays flat: a bad one
    among the first 100 stops the run at once, a later one is that trajectory's error.

    For every trajectory it prints the candidate singular times (certified
    enclosures of the roots of μ(t)), the pose and joints there, which working
    modes are singular, whether each candidate is real or spurious for the feasible
    mode(s), the working modes with their feasibility, and the verdict:
    singularity-free, singular, infeasible or unknown.

    It also places the path in the workspace: the certified times where it crosses
    the serial-singularity, ξ and joint-limit surfaces, the number of IK solutions
    inside the limits between them, the region holding the whole path when it stays in
    one (its decomposition is computed once and cached), and the certified time at which
    a path leaves the workspace.

    A batch never stops for one trajectory: a trajectory that runs past --time-limit is
    unknown, one whose check fails is an error with the reason, and the others
    complete.  On Ctrl-C, SIGTERM or SIGHUP the jsonl lines already written stay valid
    and -o writes nothing.
    """
    if plot_dir:
        require_extra("plot")
    progress = Progress(quiet)
    table = csv_format(interpolation, columns, scale)
    selection = {"mode": mode, "start_joints": _start_joints(start_joints),
                 "clearance": want_clearance, "min_clearance": min_clearance}
    with exit_codes():
        code = _run(robot, trajectories, backend, timeout, no_cache, tolerance, fmt, output,
                    verbose, progress, jobs, plot_dir, interpolation, time_limit=time_limit,
                    regions=False if no_regions else "wait" if wait_regions else True,
                    scheduler=scheduler, table=table,
                    all_csv=as_csv, certify_with=engine, certificate_dir=certificate_dir,
                    selection=selection)
    sys.exit(int(code))


#: a trajectory's outcome as an exit status, and how bad each is (a batch exits with
#: the worst of its trajectories; USAGE: a document that is no valid trajectory)
_SEVERITY = [ExitCode.SINGULARITY_FREE, ExitCode.UNKNOWN, ExitCode.SINGULAR,
             ExitCode.USAGE, ExitCode.BACKEND, ExitCode.INTERNAL]


def _outcome(doc: dict) -> ExitCode:
    verdict = doc["verdict"]
    if verdict in ("singular", "infeasible", "near-singular"):
        return ExitCode.SINGULAR
    if verdict == "singularity-free":
        return ExitCode.SINGULARITY_FREE
    if verdict == "error":
        return {"backend": ExitCode.BACKEND, "worker-died": ExitCode.BACKEND,
                "spec": ExitCode.USAGE}.get(doc["error"]["kind"], ExitCode.INTERNAL)
    return ExitCode.UNKNOWN


def _worst(codes) -> ExitCode:
    return max(codes, key=_SEVERITY.index, default=ExitCode.SINGULARITY_FREE)


def csv_format(interpolation: str, columns: str | None, scale: str | None):
    """The --columns and --scale options as a :class:`~singcheck.spec.paths.CsvFormat`
    for the CSV tables of a run (None when neither is given); a malformed one is a usage
    error (exit 2)."""
    from singcheck.spec.paths import CsvFormat

    if not (columns or scale):
        return None
    mapped = _pairs(columns, "--columns", lambda text: text)
    return CsvFormat(interpolation, tuple(mapped), tuple(_pairs(scale, "--scale", _factor)))


def _pairs(text: str | None, option: str, value) -> list[tuple[str, object]]:
    out: dict[str, object] = {}
    for item in (text or "").split(","):
        name, eq, rest = item.partition("=")
        name, rest = name.strip(), rest.strip()
        if not item.strip():
            continue
        if not eq or not name or not rest:
            raise click.BadParameter(f"expected NAME=VALUE, got {item.strip()!r}",
                                     param_hint=option)
        if name in out:
            raise click.BadParameter(f"{name} is given twice", param_hint=option)
        try:
            out[name] = value(rest)
        except ValueError as e:
            raise click.BadParameter(f"{name}: {e}", param_hint=option) from None
    return list(out.items())


def _start_joints(text: str | None) -> dict | None:
    """--start-joints as {joint: exact value a + b·π}; a malformed one is exit 2."""
    if not text:
        return None
    return dict(_pairs(text, "--start-joints", _angle_or_number))


def _angle_or_number(text: str):
    from singcheck.spec.grammar import ExprError, compile_constant, parse

    try:
        return compile_constant(parse(text))
    except ExprError as e:
        raise ValueError(f"{e} in {text!r} (give an exact number, e.g. 1/2, 0.25 or "
                         "2*pi/3)") from None


def _factor(text: str):
    """An exact, non-zero rational factor (singcheck's grammar: 1/1000, 0.001, 1e-3)."""
    from singcheck.spec.grammar import ExprError, compile_constant, parse

    try:
        value = compile_constant(parse(text))
    except ExprError as e:
        raise ValueError(f"{e} in {text!r}") from None
    if value.pi_coefficient or not value.rational:
        raise ValueError(f"{text!r} is not a non-zero rational number (a CSV stays "
                         "rational: give angles in radians)")
    return value.rational


def _run(robot, trajectories, backend_name, timeout, no_cache, tolerance, fmt, output, verbose,
         progress, jobs, plot_dir=None, interpolation="cubic", *, time_limit=300.0,
         regions=True, scheduler=None, table=None, all_csv=False, certify_with="auto",
         certificate_dir=None, selection=None):
    from contextlib import closing
    from itertools import chain, islice

    from singcheck import api
    from singcheck.spec.files import load_robot, read_documents

    if scheduler:
        from singcheck.cluster import check_address

        try:  # a malformed address: exit 2 now, not after the work
            check_address(scheduler)
        except SpecError as e:
            fail(e.message, ExitCode.USAGE)
    spec = load_robot(robot)
    # past the first documents, the workers read and compose each document (spans): this
    # process only cuts the input into documents and keeps their names (not with
    # --certificate or --plot, which need every document's text here)
    documents = read_documents(trajectories, interpolation, csv=table, all_csv=all_csv,
                               spans=not certificate_dir and not plot_dir)
    # the first documents (all of a small batch) are parsed here, before any work: a bad
    # one stops the run at once (exit 2, one line); past them, the documents are parsed
    # by the workers, and a bad one is that trajectory's result
    texts: dict = {}
    robot_text = ""  # a robot read from standard input: its certificates say "no spec"
    if certificate_dir:
        documents = _texts_kept(documents, texts)
        if robot != "-":
            with open(robot, encoding="utf-8") as f:
                robot_text = f.read()
    # (each within its trajectory's time limit: parsing is the first stage of its check)
    first = [api.parse_within(document, spec, time_limit)
             for document in islice(documents, api.LOOKAHEAD)]
    total = len(first) if len(first) < api.LOOKAHEAD else None  # None: not known yet
    items = chain(first, documents)
    kept: list = []
    if plot_dir:
        items = _keeping(items, kept)
    selection = {k: v for k, v in (selection or {}).items() if v}
    _check_selection(spec, selection)
    engine = api.elimination_engine(backend_name, timeout, not no_cache, progress.note)
    with progress.status(f"projecting {spec.name} onto its workspace ({engine.name})"):
        machine = api.robot_from_spec(spec, cache=not no_cache, engine=engine)
    if selection.get("mode"):  # the labels need the model's legs
        from singcheck.certify.modes import check_label

        try:
            check_label(machine.model, selection["mode"])
        except SpecError as e:
            raise click.BadParameter(e.message, param_hint="--mode") from None
    if certify_with == "exact":  # a robot with parameters outside the exact field:
        # refused before any path (exit 2, the spec's parameters line, why)
        from singcheck.elimination.projection import refuse_elimination

        refuse_elimination(machine.model, "--engine exact cannot certify this robot")
    projection = machine.projection
    if projection.expanded:
        degree = projection.singularity_surface.total_degree()
        progress.note(f"singularity surface ξ(X): degree {degree} ({projection.method})")
    else:
        progress.note(f"singularity surface: not expanded: {projection.not_expanded}")
    options = dict(tolerance=tolerance, regions=regions, time_limit=time_limit,
                   ordered=fmt != "jsonl", notify=progress.note, engine=certify_with,
                   **selection)
    if fmt == "jsonl" and not certificate_dir:  # each line written by the worker that
        # checked its trajectory (a certificate needs the whole object here)
        from singcheck.report.trajectory import JsonLine, robot_json

        options["line"] = JsonLine(robot_json(projection))
    if scheduler:
        from singcheck.cluster import check_on_cluster

        batch = check_on_cluster(scheduler, machine, items, **options)
    else:
        batch = api.check_batch(machine, items, jobs=jobs, **options)
    code = ExitCode.SINGULARITY_FREE
    used: set = set()  # certificate file names written
    with _sink(fmt, output, projection) as sink, progress.bar(total) as advance, \
            closing(batch) as docs:
        for doc in docs:
            sink.add(doc)
            if certificate_dir:
                _certify(certificate_dir, robot_text, texts, doc, used, progress)
            code = _worst([code, _outcome(doc)])
            advance(doc["name"], doc["verdict"])
        sink.finish(code, tolerance, verbose)
    if plot_dir:
        certificates = _certificates(machine, _parsed(kept, spec), time_limit, tolerance)
        gate = selection.get("min_clearance")
        _plot_all(certificates, plot_dir, progress,
                  _clearances(certificates, bool(selection.get("clearance")), gate), gate)
    return code


def _texts_kept(documents, texts: dict):
    """``documents``, each one's text kept in ``texts`` under its name (for
    --certificate: a certificate holds the spec texts as read)."""
    for document in documents:
        texts[document.name] = document.text
        yield document


def _certify(directory, robot_text: str, texts: dict, doc: dict, used: set, progress) -> None:
    """Write one trajectory's certificate (``--certificate``)."""
    from singcheck.certify.certificate import build_certificate, write_certificate

    try:
        cert = build_certificate(robot_text, texts.pop(doc["name"], ""), doc)
        target = write_certificate(directory, cert, used)
    except (OSError, ArithmeticError, ValueError, RecursionError) as e:  # the run stands
        print(f"singcheck: warning: certificate of {doc['name']} not written: {e}",
              file=sys.stderr)
        return
    progress.note(f"certificate: {target}" + (
        f" (not re-checkable: {cert['not_recheckable']})" if cert["proof"] is None else
        f" ({cert['incomplete']})" if "incomplete" in cert else ""))


def _check_selection(spec, selection: dict) -> None:
    """--start-joints checked against the robot before any work (exit 2, one line): joints
    it has, and not with --mode (whose label is checked once the model is built)."""
    for name in selection.get("start_joints") or {}:
        if name not in spec.joints:
            raise click.BadParameter(f"{name!r} is not a joint of {spec.name} (joints: "
                                     f"{', '.join(spec.joints)})", param_hint="--start-joints")
    if selection.get("mode") and selection.get("start_joints"):
        raise click.BadParameter("give --mode or --start-joints, not both",
                                 param_hint="--start-joints")


def _keeping(items, kept: list):
    """``items``, each also appended to ``kept`` (for --plot, after the batch)."""
    for item in items:
        kept.append(item)
        yield item


def _parsed(items: list, robot_spec) -> list:
    """The trajectory specs among ``items`` (documents parsed; a bad one left out: the
    batch has reported it)."""
    from singcheck.api import spec_of
    from singcheck.errors import SpecError
    from singcheck.spec.files import Document

    specs = []
    for item in map(spec_of, items):
        try:
            specs.append(item.parse(robot_spec) if isinstance(item, Document) else item)
        except SpecError:
            pass
    return [spec for spec in specs if spec is not None]  # None: its time limit


class _Sink:
    """Where results go: kept for the end (table, json, junit), or streamed (jsonl)."""

    def __init__(self, fmt: str, out, projection) -> None:
        from singcheck.report.trajectory import JsonLine, robot_json

        self.fmt, self.out, self.projection = fmt, out, projection
        self.line = JsonLine(robot_json(projection))
        self.results: list[dict] = []

    def add(self, doc) -> None:
        """One result: a trajectory object, or a :class:`singcheck.api.Formatted` whose
        jsonl line a worker wrote."""
        if self.fmt == "jsonl":
            line = doc.line if hasattr(doc, "line") else self.line(doc)
        else:
            seconds = doc.pop("time_s", None)  # JUnit's time
            if self.fmt == "junit":
                doc["time_s"] = seconds
            self.results.append(doc)
            return
        with _signals_held():  # a line is written whole, or not at all
            self.out.write(line)
            self.out.flush()

    def finish(self, code: ExitCode, tolerance: float, verbose: bool) -> None:
        if self.fmt != "jsonl":
            self.out.write(_render(self.projection, self.results, tolerance, self.fmt,
                                   verbose, code, to_file=self.out is not sys.stdout))


def _sink(fmt: str, output, projection):
    """A :class:`_Sink` on stdout, or on ``output``: a regular file written atomically (it
    appears when the batch is done, and not at all when it is interrupted), a device or
    FIFO written in place (:func:`singcheck.atomic.output_file`)."""
    from contextlib import contextmanager

    @contextmanager
    def opened():
        if not output:
            yield _Sink(fmt, sys.stdout, projection)
            return
        from singcheck.atomic import output_file

        with output_file(output) as f:
            yield _Sink(fmt, f, projection)

    return opened()


def _signals_held():
    """Hold Ctrl-C, SIGTERM and SIGHUP for the duration of the block (they are delivered
    just after it), so that a streamed line is never cut in half
    (:func:`singcheck.api.held_signals`)."""
    from singcheck.api import held_signals

    return held_signals()


def _render(projection, results, tolerance, fmt, verbose, code, to_file: bool) -> str:
    from singcheck.report import trajectory as rep

    if fmt == "json":
        return rep.to_json(rep.document(projection, results, tolerance, int(code)))
    if fmt == "junit":
        from singcheck.report.junit import junit_xml

        doc = rep.document(projection, [], tolerance, int(code))
        return junit_xml(doc.pop("robot"), results,
                         {k: v for k, v in doc.items() if k != "trajectories"})
    from singcheck.report.console import captured

    robot = rep.robot_json(projection)
    return captured(lambda console: rep.render_tables(console, robot, results, verbose),
                    interactive=sys.stdout.isatty() and not to_file, width=140)


@cli.command(epilog="""\b
Examples:
  singcheck project robots/orthoglide.yaml
  singcheck project robots/orthoglide.yaml trajectories/heart1.yaml --latex
""")
@click.argument("robot", type=click.Path(dir_okay=False))
@click.argument("trajectory", required=False, type=click.Path(dir_okay=False))
@click.option("--backend", type=click.Choice(["auto", "singular", "macaulay2", "sympy", "flint"]),
              default="auto", envvar="SINGCHECK_BACKEND", show_default=True)
@click.option("--latex", "as_latex", is_flag=True, help="LaTeX (an align* environment).")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True)
@click.option("--no-epsilon", is_flag=True,
              help="Skip ε(ρ) (a Gröbner elimination of the pose, slow for large robots).")
@click.option("--segment", type=click.IntRange(min=1),
              help="For a TRAJECTORY of several pieces (segments, waypoints, CSV): the piece "
                   "whose formulas to print (1 = the first), in its own time.")
def project(robot, trajectory, backend, as_latex, fmt, no_epsilon, segment) -> None:
    """Print the robot's formulas: det A, det B, ξ(X), ε(ρ), the workspace boundary and
    joint-limit surfaces; with a TRAJECTORY, φ(t) and every joint's parametrisation
    ρ(t) = P(t) ± √Q(t)/k (the paper's form, in s = sin t and c = cos t)."""
    with exit_codes():
        from singcheck import api
        from singcheck.certify.path import build_path
        from singcheck.elimination.projection import joint_space_singularities
        from singcheck.report.formulas import render
        from singcheck.spec.files import load_robot, load_trajectory
        from singcheck.spec.real_constants import exact_engine_refusal

        spec = load_robot(robot)
        if exact_engine_refusal(spec):  # nothing over Q to eliminate or write out
            raise UnsupportedRobotError(
                f"its formulas (ξ, ε, the workspace boundary) are not computed: "
                f"{exact_engine_refusal(spec)}", path=spec.path,
                line=spec.lines.get("parameters"), key="parameters")
        traj = load_trajectory(trajectory, spec) if trajectory else None
        if traj is not None and (traj.segments or segment):
            count = len(traj.pieces)
            if segment is None or segment > count:
                raise SpecError(f"the trajectory has {count} piece(s): choose one with "
                                f"--segment N (1 to {count})", path=traj.path)
            traj = traj.pieces[segment - 1]
        if traj is not None and (traj.time_scale is not None or traj.time_offset):
            own = (f"tau = {traj.time_scale}*pi*{traj.parameter}" if traj.time_scale
                   is not None else f"u = {traj.parameter} - {traj.time_offset}")
            click.echo(f"note: t in these formulas is the piece's own time, {own}", err=True)
        engine = api.elimination_engine(backend, cache=False)
        machine = api.robot_from_spec(spec, cache=False, engine=engine)
        epsilon = None if no_epsilon or not machine.projection.expanded else \
            joint_space_singularities(machine.model, engine)
        path = build_path(machine.projection, traj) if traj else None
        click.echo(render(machine.projection, epsilon, path, "json" if fmt == "json" else
                          "latex" if as_latex else "text"), nl=False)


def _certificates(machine, specs, time_limit: float, tolerance: float = 1e-9) -> list:
    """Each trajectory's certificate within ``time_limit`` seconds; one that runs past it
    is left out (no figure), noted on stderr, and makes the command end with exit 3."""
    from singcheck import api

    out = []
    for spec in specs:
        report = api.check(machine, spec, tolerance=tolerance, regions=False,
                           time_limit=time_limit)
        if report.certificate is None:
            click.echo(f"singcheck: {spec.name}: {report.verdict}: {report.reason} "
                       "(--time-limit): no figure", err=True)
        else:
            out.append(report.certificate)
    return out


def _clearances(certificates, want: bool, gate: float | None) -> list | None:
    """Each certificate's certified clearance per feasible mode (None: not asked)."""
    if not want and gate is None:
        return None
    from singcheck.certify.modes import clearances

    out = []
    for certificate in certificates:
        spec = certificate.path.projection.model.spec
        length = spec.clearance_length if spec.clearance_length is not None else 1
        out.append(clearances(certificate, length))
    return out


def _plot_all(certificates, out_dir: str, progress, clearance: list | None = None,
              gate: float | None = None) -> list:
    try:
        from singcheck.report.plots import write_figures
    except ImportError as e:
        raise SpecError(f"plotting needs matplotlib, scikit-image and numpy ({e.name} is "
                        "missing): pip install 'singcheck[plot]'") from None
    written: list = []
    taken: set[str] = set()  # two names with one safe file name must not overwrite
    for i, certificate in enumerate(certificates):
        written += write_figures(certificate, out_dir,
                                 clearance=None if clearance is None else clearance[i],
                                 gate=gate, taken=taken)
    progress.note(f"wrote {len(written)} figure files to {out_dir}")
    return written


def _plot_html(certificates, out_dir: str, plotly_js: str = "inline",
               clearance: list | None = None, gate: float | None = None):
    try:
        import plotly  # noqa: F401

        from singcheck.report.plots import write_html
    except ImportError as e:
        raise SpecError(f"--format html needs plotly and numpy ({e.name} is missing): "
                        "pip install 'singcheck[html]'") from None
    return write_html(certificates, os.path.join(out_dir, "singcheck.html"), plotly_js,
                      clearance, gate)


@cli.command(epilog="""\b
Examples:
  singcheck plot robots/orthoglide.yaml trajectories/heart1.yaml --out figures/
  singcheck plot robots/orthoglide.yaml --regions workspace --slice z=1 --out figures/
  singcheck plot robots/skew-biglide.yaml --regions workspace --out figures/
""")
@click.argument("robot", type=click.Path(dir_okay=False))
@click.argument("trajectories", nargs=-1, type=click.Path(dir_okay=False))
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False),
              help="Directory for the PNG and SVG files (created if needed).")
@click.option("--backend", type=click.Choice(["auto", "singular", "macaulay2", "sympy", "flint"]),
              default="auto", envvar="SINGCHECK_BACKEND", show_default=True)
@click.option("--format", "fmt", type=click.Choice(["files", "html"]), default="files",
              show_default=True, help="files: PNG and SVG per figure; html: one "
              "self-contained interactive page (needs singcheck[html]).")
@click.option("--plotly", "plotly_js", type=click.Choice(["inline", "cdn"]), default="inline",
              show_default=True, help="For --format html: inline plotly's JavaScript (a "
              "page that works offline, several MB) or load it from plotly's CDN (a much "
              "smaller page that needs the network).")
@click.option("--regions", "spaces", multiple=True,
              type=click.Choice(["workspace", "jointspace"]),
              help="Also draw the regions of that space coloured by their number of "
              "solutions (a plane: a planar robot, or --slice on a spatial one).")
@click.option("--slice", "slices", multiple=True, metavar="AXIS=VALUE",
              help="For --regions: fix an axis to an exact rational (repeatable); a pose "
              "axis slices the workspace, a joint the joint space.")
@click.option("--time-limit", type=click.FloatRange(min=0, min_open=True), default=300,
              show_default=True,
              help="Seconds allowed to each trajectory's certification and to each region "
              "analysis; past it that figure is not drawn and the command ends with exit "
              "3, unknown: time limit.")
@click.option("--clearance", "want_clearance", is_flag=True,
              help="Also draw κ(t), the clearance of each feasible mode, with its certified "
              "minimum (see `singcheck run --help`).")
@click.option("--min-clearance", type=click.FloatRange(min=0, min_open=True), metavar="D",
              help="Draw the gate line κ = D on the clearance figure (implies --clearance).")
@click.option("-q", "--quiet", is_flag=True, help="No progress notes on stderr.")
def plot(robot, trajectories, out_dir, backend, fmt, plotly_js, spaces, slices, time_limit,
         want_clearance, min_clearance, quiet) -> None:
    """Draw the paper's figures for each TRAJECTORY of ROBOT: μ(t) with its certified
    roots, det A along the feasible modes, the path with ξ(X) = 0 in the workspace,
    and the working modes in joint space with the joint-limit box (PNG and SVG); when
    the robot spec has a drawing, the robot at the start and at each proven singular
    time (and, with --format html, animated along the path).
    With --regions, draw a plane of the workspace or joint space: each region filled by
    its exact number of solutions and labelled, the discriminant variety's curves."""
    require_extra("html" if fmt == "html" else "plot")
    progress = Progress(quiet)
    with exit_codes():
        if not trajectories and not spaces:
            raise click.UsageError("give at least one TRAJECTORY, or --regions SPACE")
        complete = True
        for space, own in _slices_by_space(robot, spaces, slices).items():
            paths = _plot_regions(space, robot, own, backend, out_dir, progress, time_limit)
            complete &= paths is not None
            for path in paths or []:
                click.echo(str(path))
        if trajectories:
            from singcheck import api
            from singcheck.budget import TimeLimitExceeded, deadline
            from singcheck.spec.files import load_trajectory

            machine = api.load_robot(robot, backend, notify=progress.note)
            specs = []
            for path in trajectories:  # reading one is bounded by its time limit too
                try:
                    with deadline(time_limit), api.hard_time_limit(time_limit):
                        specs.append(load_trajectory(path, machine.spec))
                except TimeLimitExceeded as e:
                    click.echo(f"singcheck: {path}: unknown: {e} (while reading it; "
                               "--time-limit): no figure", err=True)
                    complete = False
            certificates = _certificates(machine, specs, time_limit)
            complete &= len(certificates) == len(specs)
            kappa = _clearances(certificates, want_clearance, min_clearance)
            if fmt == "html":
                click.echo(str(_plot_html(certificates, out_dir, plotly_js, kappa,
                                          min_clearance)))
            else:
                for path in _plot_all(certificates, out_dir, progress, kappa, min_clearance):
                    click.echo(str(path))
    if not complete:
        sys.exit(int(ExitCode.UNKNOWN))


#: The optional extras: the modules each needs, and the package that provides each.
EXTRAS = {"plot": ("numpy", "matplotlib", "skimage"), "html": ("numpy", "plotly")}
_PACKAGES = {"skimage": "scikit-image"}


def require_extra(extra: str) -> None:
    """Stop up front (exit 2, one line naming the extra to install) when an optional
    dependency is missing, before any work is done."""
    import importlib.util

    missing = []
    for module in EXTRAS[extra]:
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            missing.append(_PACKAGES.get(module, module))
    if missing:
        fail(f"this needs the optional extra '{extra}' ({', '.join(missing)} "
             f"{'is' if len(missing) == 1 else 'are'} not installed): "
             f"pip install 'singcheck[{extra}]'", ExitCode.USAGE)


def _slices_by_space(robot, spaces, slices) -> dict[str, list[str]]:
    """Each --slice goes to the spaces having its axis (pose axes: the workspace; joints:
    the joint space); a slice that fits none of the requested spaces is an error."""
    from singcheck.cli.spaces import parse_slice
    from singcheck.model.robot import build_model
    from singcheck.spec.files import load_robot

    if not spaces:
        return {}
    model = build_model(load_robot(robot))
    from singcheck.spaces.chart import Chart

    axes = {"workspace": Chart.of(model.pose, model.angles).axes,
            "jointspace": Chart.of(model.joints, model.angles).axes}
    out: dict[str, list[str]] = {space: [] for space in dict.fromkeys(spaces)}
    for text in slices:
        axis, _ = parse_slice(text)
        owners = [space for space in out if axis in axes[space]]
        if not owners:
            names = ", ".join(a for space in out for a in axes[space])
            raise click.BadParameter(f"{axis} is not an axis of the requested space(s) "
                                     f"({names})", param_hint="--slice")
        for space in owners:
            out[space].append(text)
    return out


def _plot_regions(space, robot, slices, backend, out_dir, progress,
                  time_limit: float) -> list | None:
    """The region figure of ``space`` (its paths), or None (noted on stderr) when the
    analysis runs past ``time_limit`` seconds."""
    from singcheck.budget import TimeLimitExceeded
    from singcheck.cli.spaces import compute
    from singcheck.spaces.analysis import SliceError

    try:
        from singcheck.report.region_plots import write_region_figure
    except ImportError as e:  # pragma: no cover - the plot extra is missing
        raise SpecError(f"plotting needs matplotlib and numpy ({e.name} is missing): "
                        "pip install 'singcheck[plot]'") from None
    try:
        analysis, _ = compute(space, robot, slices, "auto", False, backend, 600, False,
                              progress, time_limit)
    except SliceError as e:
        raise click.BadParameter(str(e), param_hint="--slice") from None
    except TimeLimitExceeded as e:
        click.echo(f"singcheck: unknown: {e} (the {space} regions; --time-limit): no "
                   "figure", err=True)
        return None
    if len(analysis.axes) != 2:
        raise click.BadParameter(f"the {space} has {len(analysis.axes)} free axes; fix all "
                                 "but two with --slice", param_hint="--slice")
    return write_region_figure(analysis, out_dir)


@cli.command()
@click.option("--format", "fmt", type=click.Choice(["table", "json"]), default="table",
              show_default=True)
def backends(fmt) -> None:
    """List the elimination backends: found or not, path, version, tested versions."""
    from singcheck.elimination.cas import describe_backends

    infos = describe_backends()
    if fmt == "json":
        import json

        click.echo(json.dumps([info.__dict__ for info in infos], indent=2))
        return
    for info in infos:
        state = "found" if info.found else "missing"
        click.echo(f"{info.name:10} {state:8} {info.version or '-':10} {info.path or '-'}")
        click.echo(f"{'':10} tested with {info.tested}" + (f"; {info.note}" if info.note else ""))


@cli.group()
def cache() -> None:
    """The on-disk cache of elimination results (SINGCHECK_CACHE_DIR moves it)."""


@cache.command("info")
def cache_info() -> None:
    """Where the cache is, and how many entries and bytes it holds."""
    from singcheck.elimination.cache import EliminationCache

    c = EliminationCache()
    entries = c.entries()
    size = sum(p.stat().st_size for p in entries)
    click.echo(f"directory: {c.directory}\nentries:   {len(entries)}\nbytes:     {size}")


@cache.command("clear")
def cache_clear() -> None:
    """Delete every cached elimination result."""
    from singcheck.elimination.cache import EliminationCache

    click.echo(f"removed {EliminationCache().clear()} entries")


@cli.command(epilog="""\b
Examples:
  singcheck schema robot > robot.schema.json
  singcheck schema report | check-jsonschema --schemafile /dev/stdin report.json
""")
@click.argument("name", type=click.Choice(["robot", "trajectory", "report", "certificate"]))
def schema(name) -> None:
    """Print the JSON Schema (Draft 2020-12) of a robot spec, a trajectory document or
    the JSON report (each jsonl line: the report's $defs/jsonl_line).  Editors with the
    YAML language server check a spec whose first line is
    # yaml-language-server: $schema=PATH/TO/robot.schema.json"""
    from singcheck.schemas import schema_text

    click.echo(schema_text(name), nl=False)


@cli.command(epilog="""\b
Examples:
  singcheck run robots/orthoglide.yaml trajectories/heart1.yaml --certificate certs
  singcheck verify certs/heart1.cert.json
""")
@click.argument("certificates", nargs=-1, required=True, type=click.Path(dir_okay=False))
def verify(certificates) -> None:
    """Re-check CERTIFICATES (written by run --certificate) without a CAS: exit 0 when
    every claim is proven, 1 with one line per failed or not re-checked step, 2 for an
    unreadable file.  The same as python -m singcheck.verify (docs/certificate.md)."""
    from singcheck.verify import main as verify_main

    sys.exit(verify_main(list(certificates)))


def _register_space_commands() -> None:
    from singcheck.cli.spaces import jointspace, workspace

    cli.add_command(workspace)
    cli.add_command(jointspace)


def _interrupt_on_signals() -> None:
    """SIGTERM and SIGHUP stop singcheck the way Ctrl-C does (exit 130, the streamed
    results kept, no partial -o file).  In this process only: forked workers reset
    them (:func:`singcheck.api._worker_signals`)."""
    import signal

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, interrupt)


def _exit_quickly(code) -> None:
    """End the process now with ``code``, skipping the interpreter's teardown (freeing
    every module and object: several milliseconds of a warm run), when that teardown
    has nothing else to do: no atexit handler registered (coverage, temporary
    directories' finalizers, dask, …), no thread or process pool left.  Standard output
    and error are flushed first; if that fails (a closed pipe), the ordinary exit
    handles it.  Otherwise it returns and the ordinary exit follows."""
    import atexit

    threading = sys.modules.get("threading")
    if not isinstance(code, int) or getattr(atexit, "_ncallbacks", lambda: 1)() or \
            (threading is not None and threading.active_count() > 1) or \
            "concurrent.futures" in sys.modules or "multiprocessing" in sys.modules:
        return
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        return
    os._exit(code)


def main() -> None:
    """Console-script entry point: never lets a traceback reach the user."""
    fewer_collections()  # (the forked --jobs workers inherit it)
    _interrupt_on_signals()
    try:
        cli.main(standalone_mode=False)
        _exit_quickly(0)
    except click.exceptions.Abort:
        fail("interrupted", ExitCode.INTERRUPTED)
    except click.ClickException as e:
        e.show()
        sys.exit(int(ExitCode.USAGE))
    except KeyboardInterrupt:
        fail("interrupted", ExitCode.INTERRUPTED)
    except SystemExit as e:
        _exit_quickly(e.code)
        raise
    except Exception as e:  # a bug: say so in one line, keep the traceback for --debug users
        if os.environ.get("SINGCHECK_DEBUG"):
            raise
        fail(f"internal error: {type(e).__name__}: {e} (set SINGCHECK_DEBUG=1 for the "
              "traceback, and please report it)", ExitCode.INTERNAL)
