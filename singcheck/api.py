"""singcheck's public Python API: load a robot once, then check trajectories against it.

The command line is one client of these functions; nothing here prints (long steps
report through an optional ``notify(message)`` callback) and nothing here knows about
exit codes.  ::

    import singcheck
    robot = singcheck.load_robot("robots/orthoglide.yaml", backend="auto")
    traj = singcheck.load_trajectory("trajectories/heart1.yaml", robot)
    report = singcheck.check(robot, traj)
    report.verdict          # "singular"
    report.to_dict()        # the JSON schema's trajectory object

:func:`load_robot` builds the polynomial model and computes the projection once (through
the elimination cache); :func:`check` reuses it, so checking more trajectories against the
same :class:`Robot` runs no CAS and reads no cache entry.
"""

from __future__ import annotations

import signal
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from singcheck.budget import TimeLimitExceeded, deadline, remaining
from singcheck.certify.classification import Candidate, TrajectoryReport
from singcheck.certify.path import PathModel
from singcheck.certify.pieces import certify_trajectory
from singcheck.certify.working_modes import WorkingMode
from singcheck.elimination.projection import MAX_SURFACE_TERMS, RobotProjection, project_robot
from singcheck.model.robot import RobotModel, build_model
from singcheck.spec.files import Document, RobotSpec, Span, TrajectorySpec
from singcheck.spec.files import load_robot as read_robot_spec
from singcheck.spec.files import load_trajectory as read_trajectory_spec

Notify = Callable[[str], None]

DEFAULT_TOLERANCE = 1e-9


def _quiet(message: str) -> None:
    """The default ``notify``: say nothing."""


def elimination_engine(backend: str = "auto", timeout: float = 600.0, cache: bool = True,
                       notify: Notify = _quiet):
    """The chosen elimination backend (named through ``notify`` when picked by ``auto``),
    behind the on-disk cache unless ``cache`` is false."""
    from singcheck.elimination.cache import CachedBackend, EliminationCache
    from singcheck.elimination.cas import get_backend

    engine = get_backend(backend, timeout=timeout)
    if backend == "auto":
        notify(f"backend: {engine.name} {engine.version()} (auto)")
    return CachedBackend(engine, EliminationCache()) if cache else engine


@dataclass
class Robot:
    """A robot spec with its exact model and its projection onto the workspace (ξ(X), the
    workspace boundary and the joint-limit surfaces), computed once."""

    spec: RobotSpec
    model: RobotModel
    projection: RobotProjection
    region_cache: Any = None  # where region maps persist between runs (None: this process)

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def backend(self) -> str:
        return self.projection.backend

    def __repr__(self) -> str:  # short: the model's polynomials run to kilobytes
        return (f"<Robot {self.name}: joints {', '.join(self.spec.joints)}; pose "
                f"{', '.join(self.spec.pose)}; {_surface_summary(self.projection)}>")

    @property
    def singularity_surface(self):
        """ξ(X), squarefree, exact (an ``fmpq_mpoly`` in the pose variables); None when it
        was too big to expand (``projection.not_expanded`` says why)."""
        return self.projection.singularity_surface


def _surface_summary(projection) -> str:
    if not projection.expanded:
        return "ξ(X) not expanded"
    return (f"ξ(X) of degree {projection.singularity_surface.total_degree()} "
            f"({projection.backend})")


def robot_from_spec(spec: RobotSpec, backend: str = "auto", *, timeout: float = 600.0,
                    cache: bool = True, notify: Notify = _quiet, engine=None,
                    max_surface_terms: int = MAX_SURFACE_TERMS) -> Robot:
    """A :class:`Robot` from an already-read spec (``engine``: a ready backend, else one is
    built from ``backend``, ``timeout`` and ``cache``).  ξ(X) is not expanded when its
    bound exceeds ``max_surface_terms`` (0: never; each path then eliminates along itself)."""
    model = build_model(spec)
    engine = engine or elimination_engine(backend, timeout, cache, notify)
    projection = project_robot(model, engine, max_surface_terms)
    region_cache = None
    if cache:
        from singcheck.spaces.region_map import RegionMapCache

        region_cache = RegionMapCache()
    return Robot(spec, model, projection, region_cache)


def load_robot(path: str, backend: str = "auto", *, timeout: float = 600.0,
               cache: bool = True, notify: Notify = _quiet,
               max_surface_terms: int = MAX_SURFACE_TERMS) -> Robot:
    """Read a robot spec (YAML) and project it: the elimination runs here, once (or comes
    from the cache); raises :class:`~singcheck.errors.SpecError` for a bad file and
    :class:`~singcheck.errors.BackendError` when the backend is missing or fails."""
    return robot_from_spec(read_robot_spec(path), backend, timeout=timeout, cache=cache,
                           notify=notify, max_surface_terms=max_surface_terms)


def load_trajectory(path: str, robot: Robot, interpolation: str | None = None) -> TrajectorySpec:
    """Read a trajectory spec (YAML, or a CSV table of poses interpolated
    ``interpolation``: linear or cubic, the default) for ``robot``: its pose variables
    are checked."""
    return read_trajectory_spec(path, robot.spec, interpolation)


def load_trajectories(paths, robot: Robot, interpolation: str | None = None
                      ) -> list[TrajectorySpec]:
    """Every trajectory of the files (``-``: standard input): a YAML file may hold several
    documents, one trajectory each; names must be unique across them all (else
    :class:`~singcheck.errors.SpecError`, naming the file, line and document)."""
    from singcheck.spec.files import load_trajectories as read_trajectories

    return read_trajectories(paths, robot.spec, interpolation)


@dataclass
class Report:
    """The certified answer for one trajectory: a verdict with its proofs."""

    trajectory: TrajectorySpec
    certificate: TrajectoryReport | None  # None when the time limit stopped it first
    workspace: Any = None  # the path against the workspace's regions (or None)
    time_limited: str | None = None  # why the work stopped early, if it did
    extra: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.trajectory.name

    def __repr__(self) -> str:  # short: the certificate holds the whole path model
        return f"<Report {self.name}: {self.verdict}: {self.reason}>"

    @property
    def verdict(self) -> str:
        """singularity-free, singular, infeasible or unknown."""
        return self.certificate.verdict if self.certificate else "unknown"

    @property
    def reason(self) -> str:
        if self.certificate is None:
            return self.time_limited.removeprefix("unknown: ")  # the verdict says unknown
        return self.certificate.reason

    @property
    def candidates(self) -> list[Candidate]:
        """Certified roots of μ(t), each classified per working mode."""
        return self.certificate.candidates if self.certificate else []

    @property
    def working_modes(self) -> list[WorkingMode]:
        return self.certificate.modes if self.certificate else []

    @property
    def path(self) -> PathModel | None:
        return self.certificate.path if self.certificate else None

    def to_dict(self) -> dict[str, Any]:
        """The JSON report's trajectory object (``singcheck schema report``)."""
        from singcheck.report.trajectory import (
            time_limited_json,
            trajectory_json,
            workspace_json,
        )

        if self.certificate is None:
            return time_limited_json(self.trajectory, self.reason)
        doc = trajectory_json(self.certificate)
        if self.workspace is not None:
            doc["workspace"] = workspace_json(self.workspace)
            exit_time = doc["workspace"]["exit_time_interval"]
            if doc["verdict"] == "infeasible" and exit_time:
                lo, hi = exit_time
                doc["reason"] += f"; the path leaves the workspace at t ∈ [{lo:.9g}, {hi:.9g}]"
        elif self.time_limited:
            doc["reason"] += f" ({self.time_limited})"
        doc.update(self.extra)  # the chosen mode, the clearance (when asked for)
        return doc


def check(robot: Robot, trajectory: TrajectorySpec, *, tolerance: float = DEFAULT_TOLERANCE,
          regions: bool | str = True, time_limit: float | None = None,
          notify: Notify = _quiet, engine: str = "auto", mode: str | None = None,
          start_joints: dict | None = None, clearance: bool = False,
          min_clearance: float | None = None) -> Report:
    """Certify one trajectory of ``robot``: candidate singular times, their classification
    per working mode, the verdict, and (``regions``) where the path lies in the workspace.

    ``time_limit`` (seconds) bounds the whole certification; past it the report's verdict
    is ``unknown`` with the reason (the region statement alone past it is left out, with
    the reason).  The region statement has its own budget of :data:`REGION_BUDGET`
    seconds (``regions="wait"``: none), past which it is left out and the reason says
    so: it never holds the verdict back.  Prints nothing; ``notify`` hears of long steps.
    ``engine``: ``auto`` (both engines: the exact one where it can run, always held
    against the interval one; the interval engine alone on a path the exact one
    refuses), ``exact`` (refuse such a path) or ``interval`` (the interval engine alone).

    ``mode`` (a working mode's label, else the trajectory's own ``mode``) or
    ``start_joints`` (joint name → exact value at the path's start, which picks the one
    mode matching them: :func:`singcheck.certify.modes.mode_at_start`) makes the verdict
    about that mode alone.  ``clearance`` adds each considered mode's certified minimum
    of κ (:mod:`singcheck.certify.clearance`); ``min_clearance`` (implies it) makes a
    nonsingular path whose κ is proven below it ``near-singular``.  A label the robot
    lacks, or start joints matching no mode or several, raise
    :class:`~singcheck.errors.SpecError`.
    """
    from singcheck.certify import modes as working
    from singcheck.elimination.projection import transcendental_limits

    label = mode or trajectory.mode
    chosen_by = "--mode" if mode else "document" if label else None
    if label:
        working.check_label(robot.model, label, trajectory.path,
                            None if mode else "mode")
    with deadline(time_limit):
        try:
            certificate = certify_trajectory(robot.projection, trajectory, tolerance, engine)
        except TimeLimitExceeded as e:
            return Report(trajectory, None, time_limited=str(e))
        full = certificate
        extra: dict = {}
        try:
            if start_joints and not label:
                label, chosen_by = working.mode_at_start(certificate, start_joints), \
                    "--start-joints"
            if label:
                certificate = working.restrict(certificate, label)
                extra["mode"] = {"label": label, "chosen_by": chosen_by}
                if chosen_by == "--start-joints":
                    extra["mode"]["start_tolerance"] = working.START_TOLERANCE
            if clearance or min_clearance is not None:
                extra.update(_clearance(robot, certificate, min_clearance))
        except TimeLimitExceeded as e:
            return Report(trajectory, certificate, time_limited=f"{e} while certifying the "
                          "clearance", extra=extra)
        if not regions or any(r.path.exact_refused for r in full.pieces or [full]) or \
                transcendental_limits(robot.projection.model):
            return Report(trajectory, certificate, extra=extra)  # no region statement
        from singcheck.spaces.path_regions import path_in_workspace, pieces_in_workspace

        budget = None if regions == "wait" else region_budget()
        left = remaining()
        own = budget is not None and (left is None or left > budget)
        try:
            with deadline(budget):
                if not _with_mu(full):
                    return Report(trajectory, certificate, extra=extra)
                mu_roots = [c.t for c in full.candidates] if full.mu_roots_complete else None
                if full.pieces:
                    where = pieces_in_workspace(full, tolerance, robot.region_cache, notify)
                else:
                    where = path_in_workspace(full.path, tolerance, mu_roots=mu_roots,
                                              region_cache=robot.region_cache, notify=notify)
        except TimeLimitExceeded as e:
            why = (f"workspace region not computed: its own budget of {budget:g} s ran out "
                   "(--regions waits for it)") if own else f"{e} while naming the workspace region"
            return Report(trajectory, certificate, time_limited=why, extra=extra)
        return Report(trajectory, certificate, where, extra=extra)


def _clearance(robot: Robot, certificate: TrajectoryReport, threshold: float | None) -> dict:
    """The clearance keys of the report (and the gate applied to ``certificate``'s
    verdict, in place)."""
    from fractions import Fraction

    from singcheck.certify import modes as working
    from singcheck.certify.clearance import REL_TOL

    given = robot.spec.clearance_length
    length = given if given is not None else Fraction(1)
    found = working.clearances(certificate, length)
    if threshold is not None:
        certificate.verdict, certificate.reason = working.gate(certificate, found, threshold)
    return {"clearance": {label: c.to_json() for label, c in found.items()},
            "clearance_settings": {"angle_length": str(length),
                                   "angle_length_default": given is None,
                                   "tolerance": f"hi - lo <= {REL_TOL:g}*max(min, 1e-3)",
                                   "min_clearance": threshold}}


def _with_mu(certificate) -> bool:
    """μ along every piece of a certified path, for the region statement (the interval
    engine may have decided without it); False when the exact engine refuses a piece."""
    from singcheck.certify.path import with_mu

    for report in certificate.pieces or [certificate]:
        report.path = with_mu(report.path)
        if report.path.mu is None:
            return False
    return True


#: seconds the region statement may take beside a verdict (``regions="wait"``: no budget
#: of its own, only the trajectory's time limit): it never holds the verdict back
REGION_BUDGET = 2.0


def region_budget() -> float:
    """:data:`REGION_BUDGET`, or the environment's ``SINGCHECK_REGION_BUDGET`` (seconds, a
    positive number; anything else is ignored)."""
    import math
    import os

    try:
        value = float(os.environ.get("SINGCHECK_REGION_BUDGET", ""))
    except ValueError:
        return REGION_BUDGET
    return value if value > 0 and math.isfinite(value) else REGION_BUDGET


#: the default per-trajectory time limit of a batch (seconds): generous, but finite
DEFAULT_TIME_LIMIT = 300.0


def check_safely(robot: Robot, trajectory: TrajectorySpec, *, spent: float = 0.0,
                 **options) -> dict[str, Any]:
    """:func:`check` as one trajectory of a batch: its JSON trajectory object (with
    ``time_s``, the seconds it took), whatever happens.  A failure of this trajectory
    alone (a backend failure, a bug, the time limit) becomes its result — verdict
    ``unknown`` past the time limit, ``error`` with the reason otherwise — so that the
    other trajectories of the batch still complete.  ``spent``: the seconds its parsing
    took, which count against its time limit (and its ``time_s``).
    Ctrl-C (KeyboardInterrupt) still stops the batch."""
    import time

    from singcheck.errors import BackendError, SpecError
    from singcheck.report.trajectory import error_json, time_limited_json

    start = time.perf_counter() - spent
    try:
        with deadline(options.get("time_limit"), spent), \
                hard_time_limit(options.get("time_limit"), spent):
            doc = check(robot, trajectory, **options).to_dict()
    except TimeLimitExceeded as e:
        doc = time_limited_json(trajectory, str(e))
    except BackendError as e:
        doc = error_json(trajectory, "backend", str(e))
    except SpecError as e:  # refused up front (a path too costly to certify)
        doc = error_json(trajectory, "spec", str(e))
    except Exception as e:  # a bug, confined to this trajectory
        doc = error_json(trajectory, "internal", f"{type(e).__name__}: {e}")
    doc["time_s"] = round(time.perf_counter() - start, 6)
    return doc


@contextmanager
def hard_time_limit(seconds: float | None, spent: float = 0.0):
    """A backstop behind the cooperative :func:`~singcheck.budget.checkpoint`: in a
    process's main thread, a timer raises :class:`TimeLimitExceeded` a little after the
    limit (10 % and a second; ``spent`` of it gone already), should some loop not reach
    a checkpoint in time."""
    import signal
    import threading

    if (seconds is None or not hasattr(signal, "setitimer")
            or threading.current_thread() is not threading.main_thread()):
        yield
        return

    def expire(signum, frame):
        raise TimeLimitExceeded(f"time limit ({seconds:g} s) reached")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, max(seconds * 1.1 + 1 - spent, 1e-3))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


# state inherited by forked workers (set just before the pool starts)
_WORKER: dict = {}


def _worker_signals() -> None:
    """In a forked worker: Ctrl-C and a hangup reach the whole process group, but it is
    the parent that stops the batch (and then terminates the workers); SIGTERM ends a
    worker silently.  So no worker prints a KeyboardInterrupt traceback.  A worker dies
    with the parent's thread that forked it (the main thread: a fork-context pool starts
    every worker at once), even when the parent is SIGKILLed."""
    import signal

    from singcheck.elimination.cas.guard import die_with_parent

    die_with_parent(_WORKER["parent"])  # SIGTERM: the default action
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _HELD)  # held while it was forked


#: the signals held while workers are forked (:func:`held_signals`)
_HELD = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}


def _check_chunk(chunk: list) -> list[dict | Formatted]:
    """A worker's task: several trajectories (specs, or documents it reads and parses),
    in turn; each result formatted here when the batch has a ``line`` format."""
    robot, options, line = _WORKER["robot"], _WORKER["options"], _WORKER.get("line")
    return [formatted(check_item(robot, item, **options), line) for item in chunk]


@dataclass(frozen=True)
class Formatted:
    """One trajectory's result as the worker that checked it wrote it (a batch with a
    ``line`` format): the line, and the few keys that its reader counts (``name``,
    ``verdict`` and, for an error, ``error.kind``), so that the process that gathers a
    batch neither pickles whole reports back nor formats them."""

    summary: dict
    line: str

    def __getitem__(self, key: str):
        return self.summary[key]

    def __contains__(self, key: str) -> bool:
        return key in self.summary


def formatted(doc: dict, line: Callable[[dict], str] | None) -> dict | Formatted:
    """``doc`` as a :class:`Formatted` result by ``line`` (itself when ``line`` is None)."""
    if line is None:
        return doc
    summary = {"name": doc["name"], "verdict": doc["verdict"]}
    if "error" in doc:
        summary["error"] = {"kind": doc["error"]["kind"]}
    return Formatted(summary, line(doc))


@dataclass
class Parsed:
    """A document parsed within its time limit (:func:`parse_within`): the spec, or None
    when the limit stopped the parsing (``reason``), and the seconds it took — they
    count against the trajectory's time limit."""

    document: Document
    spec: TrajectorySpec | None
    seconds: float
    reason: str = ""


def parse_within(document: Document | Span, robot_spec: RobotSpec,
                 time_limit: float | None) -> Parsed:
    """Parse ``document`` as the first stage of its trajectory's check: under its time
    limit (a 5,000-row CSV's exact cubic spline is solved here).  A bad document raises
    :class:`~singcheck.errors.SpecError`."""
    import time

    if isinstance(document, Span):
        document = document.document()

    start = time.perf_counter()
    try:
        with deadline(time_limit), hard_time_limit(time_limit):
            spec = document.parse(robot_spec)
    except TimeLimitExceeded as e:
        return Parsed(document, None, time.perf_counter() - start, f"{e} (while reading it)")
    return Parsed(document, spec, time.perf_counter() - start)


def spec_of(item: TrajectorySpec | Document | Parsed) -> TrajectorySpec | Document | None:
    """The trajectory spec of a batch's item when it is parsed (None when its parsing ran
    out of time), else the document."""
    return item.spec if isinstance(item, Parsed) else item


def check_item(robot: Robot, item: TrajectorySpec | Document | Span | Parsed,
               **options) -> dict[str, Any]:
    """:func:`check_safely` of a trajectory spec, or of a :class:`Document` read but not
    parsed yet: it is parsed here, within the trajectory's time limit (past it: verdict
    ``unknown``), and one that is wrong is its own result (verdict ``error``,
    ``error.kind`` ``spec``, the located message) like any failure of one trajectory of
    a batch."""
    from singcheck.report.trajectory import error_json, time_limited_json

    if isinstance(item, Span):  # its bytes read and composed here
        item = item.document()
    if isinstance(item, Document):
        from singcheck.errors import SpecError

        try:
            item = parse_within(item, robot.spec, options.get("time_limit"))
        except SpecError as e:
            return {**error_json(item, "spec", str(e)), "time_s": 0.0}
    if isinstance(item, Parsed):
        if item.spec is None:
            return {**time_limited_json(item.document, f"unknown: {item.reason}"),
                    "time_s": round(item.seconds, 6)}
        return check_safely(robot, item.spec, spent=item.seconds, **options)
    return check_safely(robot, item, **options)


def prepare_regions(robot: Robot, trajectories: list[TrajectorySpec], time_limit: float | None,
                    notify: Notify = _quiet) -> bool:
    """Compute, once, the region maps that several trajectories share (before workers
    fork, or before a cluster gets the robot), within ``time_limit``.  False when that
    ran out of time: the batch then runs without the region statement."""
    from singcheck.spaces.path_regions import prepare_region_maps

    try:
        with deadline(time_limit), hard_time_limit(time_limit):
            prepare_region_maps(robot.projection, [t.pieces[0] for t in trajectories],
                                robot.region_cache, notify)
    except TimeLimitExceeded:
        notify(f"the workspace regions shared by the paths took more than {time_limit:g} s "
               "(--time-limit): the batch runs without the region statement")
        return False
    return True


#: the trajectories a batch reads before it starts: the shared region maps are prepared
#: from them, and a batch of at most 4 runs in this process
LOOKAHEAD = 100
#: trajectories per task of a batch's worker processes at first, and tasks in flight per
#: worker; then each task holds what takes about TASK_SECONDS at the pace seen so far, at
#: most MAX_CHUNK (:class:`_TaskSizes`)
CHUNK = 8
TASKS_PER_WORKER = 4
MAX_CHUNK = 64
TASK_SECONDS = 0.25


class _TaskSizes:
    """How many trajectories the next task of a batch holds.

    Each task costs the pool its pickling, two pipes and a few thread wake-ups, about
    1.5 ms of CPU beyond its trajectories' (a Dask task about 14 ms), much of it in this
    process, which shares the cores with the workers: 2,000 hearts (4 ms each) in tasks
    of 8 took 8.9 s of CPU on 2 cores, in tasks of 64 8.5 s.  So the first tasks hold
    ``first`` (CHUNK), and the next ones what takes about ``seconds`` (TASK_SECONDS) at
    the pace seen so far, at most ``most`` (MAX_CHUNK): hearts go 64 to a task, paths of
    a second one by one.  Once the input has ended, what is left is shared among the
    workers (a task holds at most a (2·workers)-th of it, at least ``least``), so that
    the batch does not end with one worker on a long task while the others wait."""

    def __init__(self, workers: int, first: int | None = None, most: int | None = None,
                 seconds: float | None = None, least: int = 1) -> None:
        from time import monotonic

        self.workers, self.clock, self.start, self.done = workers, monotonic, monotonic(), 0
        self.first = CHUNK if first is None else first
        self.most = max(self.first, MAX_CHUNK if most is None else most)
        self.seconds = TASK_SECONDS if seconds is None else seconds
        self.least = least
        self.ahead: deque = deque()  # read by :meth:`take`, not in a task yet
        self.ended = False  # the input has ended

    def finished(self, count: int) -> None:
        self.done += count

    def next(self, left: int | None = None) -> int:
        """The next task's size; ``left``: the trajectories still to send, once the
        input has ended (None before)."""
        size = self.first
        if self.done:
            per_path = (self.clock() - self.start) * self.workers / self.done
            size = max(1, min(self.most, int(self.seconds / max(per_path, 1e-6))))
        if left is not None:
            size = min(size, max(self.least, -(-left // (2 * self.workers))))
        return size

    def take(self, items: Iterator) -> list:
        """The next task's trajectories from ``items`` (empty once all are taken), read
        two tasks ahead to know, near the end, what is left."""
        from itertools import islice

        size = self.next()
        while not self.ended and len(self.ahead) < 2 * size:
            more = list(islice(items, 2 * size - len(self.ahead)))
            self.ahead.extend(more)
            self.ended = not more
        if self.ended:
            size = self.next(len(self.ahead))
        return [self.ahead.popleft() for _ in range(min(size, len(self.ahead)))]


def shared_regions(robot: Robot, head: list, options: dict, notify: Notify = _quiet) -> None:
    """Before a batch's workers start: the region maps that its first trajectories
    share, computed once (:func:`prepare_regions`); ``options["regions"]`` is turned off
    when that ran out of time."""
    from singcheck.elimination.projection import transcendental_limits
    from singcheck.spec.real_constants import exact_engine_refusal

    specs = [t for t in map(spec_of, head) if isinstance(t, TrajectorySpec)]
    if options["regions"] and (transcendental_limits(robot.projection.model) or
                               exact_engine_refusal(robot.projection.model.spec)):
        # no algebraic limit surfaces, or no robot over Q (a real parameter): no region
        # statement (a batch once ended here, an internal error, on such a robot)
        options["regions"] = False
    if options["regions"] and specs and not prepare_regions(
            robot, specs, options["time_limit"], notify):
        options["regions"] = False


def check_batch(robot: Robot, trajectories: Iterable[TrajectorySpec | Document], *,
                tolerance: float = DEFAULT_TOLERANCE, regions: bool = True,
                time_limit: float | None = DEFAULT_TIME_LIMIT, jobs: int = 1,
                ordered: bool = True, notify: Notify = _quiet,
                engine: str = "auto", line: Callable[[dict], str] | None = None,
                **selection) -> Iterator[dict | Formatted]:
    """Certify many trajectories, in ``jobs`` forked processes when there are more than 4;
    yields each one's JSON trajectory object as soon as it is known: in input order, or
    (``ordered=False``) in the order they finish.

    ``trajectories`` is read lazily, a bounded window ahead of the results (specs, or
    :class:`~singcheck.spec.files.Document` from :func:`singcheck.spec.files.read_documents`,
    which the workers parse), so memory does not grow with their number.  One
    trajectory's failure is its own result (:func:`check_item`); the tasks a dying
    worker process breaks are run again (:func:`_forked`), and only a trajectory whose
    worker dies twice is an ``error`` result.  ``time_limit`` bounds each
    trajectory (and the shared region maps, once).  ``selection``: :func:`check`'s
    ``mode``, ``start_joints``, ``clearance`` and ``min_clearance``, for each trajectory.

    ``line`` (a function of a trajectory object, e.g.
    :class:`~singcheck.report.trajectory.JsonLine`): each result is instead a
    :class:`Formatted`, the line written by the worker that checked it; with
    :class:`~singcheck.spec.files.Span` items (``read_documents(…, spans=True)``) this
    process then only cuts the input into documents and writes the lines."""
    from itertools import chain, islice

    options = dict(tolerance=tolerance, regions=regions, time_limit=time_limit,
                   notify=notify, engine=engine, **selection)
    items = iter(trajectories)
    head = list(islice(items, LOOKAHEAD))
    if jobs > 1 and len(head) > 4:
        shared_regions(robot, head, options, notify)
        yield from _forked(robot, chain(head, items), options, jobs, ordered, line)
        return
    for item in chain(head, items):
        yield formatted(check_item(robot, item, **options), line)


def _forked(robot, items: Iterator, options, jobs: int, ordered: bool,
            line: Callable[[dict], str] | None = None) -> Iterator[dict | Formatted]:
    """The batch in ``jobs`` forked workers, TASKS_PER_WORKER tasks per worker in flight
    (of CHUNK to MAX_CHUNK trajectories: :class:`_TaskSizes`): a finished task is
    replaced by the next one read (before its results are yielded), so at most that many
    trajectories (and two tasks' worth read ahead) are held here at once, whatever the
    length of the batch.

    A worker that dies (killed, out of memory) breaks the pool and every task in flight
    with it: each of those tasks is run again, alone in a new pool (no other task in
    flight, so that a second death is its own); if it dies again, its trajectories are
    run one by one, alone, and one whose worker dies then is that trajectory's
    ``error`` of kind ``worker-died`` (it killed its worker twice: the OOM killer, most
    likely; not a bug, so the command exits 4 for it, as for a backend past its memory
    bound, not 70).  The others' results are kept."""
    import multiprocessing
    import os
    from collections import deque
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    from singcheck.algebra.pickling import register
    from singcheck.elimination.cas.guard import ready_to_fork
    from singcheck.report.trajectory import error_json

    register()  # specs cross to the workers by pickle
    ready_to_fork()  # each worker's die_with_parent, loaded once here
    _WORKER.update(robot=robot, options=options, parent=os.getpid(), line=line)

    def start():
        return ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork"),
                                   initializer=_worker_signals)

    pool = start()
    in_flight: dict = {}  # future -> (index of its first trajectory, its trajectories)
    lost: deque = deque()  # (first index, trajectories) of tasks whose worker died
    read = 0
    sizes = _TaskSizes(jobs)

    def send(chunk: list):
        nonlocal pool
        if getattr(pool, "_broken", False):
            _stop(pool)
            pool = start()
        with held_signals():  # a worker forked here sets its own handlers first (J1)
            try:
                return pool.submit(_check_chunk, chunk)
            except BrokenProcessPool:  # broken since: the batch goes on in a new pool
                _stop(pool)
                pool = start()
                return pool.submit(_check_chunk, chunk)

    def submit() -> bool:
        nonlocal read
        chunk = sizes.take(items)
        if chunk:
            in_flight[send(chunk)] = (read, chunk)
            read += len(chunk)
        return bool(chunk)

    def alone(chunk: list) -> list[dict] | Exception:
        try:
            return send(chunk).result()
        except Exception as e:  # noqa: BLE001 - its worker died, or it could not run
            return e

    def rerun(first: int, chunk: list) -> list[tuple[int, dict]]:
        docs = alone(chunk) if len(chunk) > 1 else None
        if isinstance(docs, list):
            return list(enumerate(docs, first))
        out = []
        for index, item in enumerate(chunk, first):
            result = alone([item])
            if isinstance(result, Exception):
                reason = (f"its worker process died twice (killed, or out of memory): "
                          f"{type(result).__name__}: {result}")
                result = [formatted({**error_json(_head(item), "worker-died", reason),
                                     "time_s": 0.0}, line)]
            out.append((index, result[0]))
        return out

    try:
        while len(in_flight) < jobs * TASKS_PER_WORKER and submit():
            pass
        done_early: dict[int, dict] = {}
        next_out = 0
        while in_flight or lost:
            results: list[tuple[int, dict]] = []
            if in_flight:
                finished, _ = wait(list(in_flight), return_when=FIRST_COMPLETED)
                for future in finished:
                    first, chunk = in_flight.pop(future)  # a done future holds its results
                    sizes.finished(len(chunk))
                    try:
                        results += enumerate(future.result(), first)
                    except Exception:  # noqa: BLE001 - its worker died: run it again
                        lost.append((first, chunk))
            if lost and not in_flight:  # the tasks the death broke, one at a time
                results += rerun(*lost.popleft())
            while not lost and len(in_flight) < jobs * TASKS_PER_WORKER and submit():
                pass
            if not ordered:
                for _, doc in results:
                    yield doc
                continue
            done_early.update(results)
            while next_out in done_early:
                yield done_early.pop(next_out)
                next_out += 1
    finally:
        _WORKER.clear()
        _stop(pool)


def _head(item):
    """What names a batch's item in its result: the spec, else the document."""
    if isinstance(item, Span):
        return item.head()
    return item.document if isinstance(item, Parsed) and item.spec is None else \
        spec_of(item)


def held_signals():
    """Ctrl-C, SIGTERM and SIGHUP held in this thread for the duration of the block:
    a worker forked inside it starts with them held, and :func:`_worker_signals`
    releases them once its own handlers are set (one signalled while starting no
    longer prints 'Exception in initializer … KeyboardInterrupt'); this process gets
    them just after the block."""
    import signal
    from contextlib import contextmanager

    @contextmanager
    def block():
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)

    return block()


def _stop(pool) -> None:
    """End a worker pool now: its processes terminated, its queued tasks cancelled."""
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()
    pool.shutdown(wait=True, cancel_futures=True)
