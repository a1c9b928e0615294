"""Batches on a Dask cluster: ``singcheck run … --scheduler ADDRESS``.

The robot's projection is computed once, here, and shipped to every worker
(``Client.scatter(…, broadcast=True)``); each task holds a few trajectories (CHUNK) and
calls the public API for each (:func:`singcheck.api.check_item`, i.e.
:func:`singcheck.check` with the batch's failure handling; a document read but not
parsed is parsed on the worker); results come back as the tasks finish, a bounded
number of tasks in flight.  The transport, the scheduling and the worker processes are
dask.distributed's (``pip install 'singcheck[dask]'``): singcheck adds no protocol of
its own.  python-flint's polynomials cross the wire through
:mod:`singcheck.algebra.pickling`.
"""

from __future__ import annotations

import uuid
from collections.abc import Iterable, Iterator
from dataclasses import replace

from singcheck.api import (
    DEFAULT_TIME_LIMIT,
    DEFAULT_TOLERANCE,
    LOOKAHEAD,
    Formatted,
    Notify,
    Robot,
    _head,
    _quiet,
    _TaskSizes,
    check_item,
    formatted,
    shared_regions,
)
from singcheck.errors import BackendError, SpecError
from singcheck.spec.files import Document, Span, TrajectorySpec

CONNECT_TIMEOUT = 30  # seconds to reach the scheduler


def check_address(address: str) -> None:
    """Refuse (:class:`SpecError`, before any work) a ``--scheduler`` address that
    dask.distributed cannot read: a scheme it does not know, no host, no port or a port
    out of range.  Given one, ``Client`` raised from inside its constructor, printed a
    ``Client.__del__`` traceback and stalled a minute on its way out."""
    try:
        _import_distributed()
        from distributed.comm.addressing import get_address_host_port, parse_address
        from distributed.comm.registry import get_backend
    except ImportError:
        raise SpecError("--scheduler needs dask.distributed: pip install "
                        "'singcheck[dask]'") from None
    try:
        scheme, _ = parse_address(address)
        get_backend(scheme)
        host, port = get_address_host_port(address)
        if not host or not 0 < port < 65536:
            raise ValueError(f"no host, or no port in 1-65535, in {address!r}")
    except (ValueError, TypeError) as e:
        raise SpecError(f"--scheduler {address}: not a scheduler address ({e}); e.g. "
                        "tcp://10.0.0.5:8786") from None


#: modules dask.distributed uses when they are there and does without otherwise (NumPy to
#: allocate receive buffers, Jinja2 for notebook reprs); a batch needs neither
OPTIONAL_IMPORTS = ("numpy", "jinja2")


def _import_distributed() -> None:
    """``import distributed`` without :data:`OPTIONAL_IMPORTS` (those not imported
    already): they are 30% of its import time (0.26 s on 2 cores), which the batch's
    command waits for before the cluster's workers get their first task.  The modules
    stay importable afterwards.  Raises ImportError when dask.distributed is missing."""
    import sys

    if "distributed" in sys.modules:
        return
    held = [name for name in OPTIONAL_IMPORTS if name not in sys.modules]
    for name in held:
        sys.modules[name] = None  # import raises ImportError: the fallback is taken
    try:
        import distributed  # noqa: F401
    finally:
        for name in held:
            if sys.modules.get(name, False) is None:
                del sys.modules[name]


def _client(address: str):
    check_address(address)
    from distributed import Client

    try:
        return Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as e:
        raise BackendError(f"cannot reach the Dask scheduler at {address}: {e}") from None


def _remote_check(robot: Robot, chunk: list, options: dict, region_cache: bool,
                  line=None) -> list[dict | Formatted]:
    """One task, on a worker: the public API on the shipped robot, for a few
    trajectories (specs, or documents read and parsed here) in turn; each result
    formatted here by ``line`` when the batch has one."""
    if region_cache and robot.region_cache is None:
        from singcheck.spaces.region_map import RegionMapCache

        robot.region_cache = RegionMapCache()  # the worker's own cache directory
    return [formatted(check_item(robot, item, **options), line) for item in chunk]


#: the periodic diagnostics of a worker, of its nanny and of the scheduler that a batch
#: pauses while it runs (restored when it ends): the statistical profiler (every 10 ms,
#: it stops the task's thread to read its stack), the event loop's tick measure (20 ms)
#: and the system monitor (500 ms).  Each wakes the process's event loop, which takes the
#: GIL from the task; on 2 cores with 2 workers these cost the cluster about 10% of its
#: throughput against ``--jobs 2`` (docs/speed.md).  None of them guards anything.
DIAGNOSTICS = ("profile", "profile-cycle", "tick", "ticks", "monitor")
#: periodic guards slowed (not stopped) during a batch, to this many ms: the memory
#: monitor (spill, pause, restart past the memory limit) polls every 100 ms by default;
#: every second still catches a runaway worker long before its memory is spent
SLOWED = {"memory_monitor": 1000}


def _pause_diagnostics(dask_worker) -> None:
    """On a worker or its nanny (``Client.run`` passes either as ``dask_worker``, on its
    event loop): pause :data:`DIAGNOSTICS` and slow :data:`SLOWED` for a batch; nested
    batches (two clients at once) count, and the last one to end restores them
    (:func:`_resume_diagnostics`)."""
    server = dask_worker
    depth = getattr(server, "_singcheck_batches", 0)
    server._singcheck_batches = depth + 1
    if depth:
        return
    saved = {}
    for name in DIAGNOSTICS:
        pc = server.periodic_callbacks.get(name)
        if pc is not None and pc.is_running():
            pc.stop()
            saved[name] = None
    for name, ms in SLOWED.items():
        pc = server.periodic_callbacks.get(name)
        if pc is not None and pc.callback_time < ms:
            saved[name] = pc.callback_time
            pc.callback_time = ms
    server._singcheck_saved = saved
    _fewer_collections(+1)


def _fewer_collections(step: int) -> None:
    """While any server of this process (worker or nanny: a LocalCluster's nannies
    share the client's process) is in a batch, the cyclic garbage collector is tuned as
    the command line tunes itself and its ``--jobs`` workers
    (:func:`singcheck.collector.fewer_collections`); the last one to leave restores it.
    ``step``: +1 entering, -1 leaving."""
    import gc

    from singcheck.collector import fewer_collections

    held = _GC["held"] + step
    _GC["held"] = max(held, 0)
    if step > 0 and held == 1:
        _GC["before"] = fewer_collections()
    elif step < 0 and held == 0 and _GC["before"] is not None:
        gc.set_threshold(*_GC["before"])
        _GC["before"] = None


#: this process's servers in a batch, and the collector's thresholds to restore after
_GC: dict = {"held": 0, "before": None}


def _resume_diagnostics(dask_worker) -> None:
    """Undo :func:`_pause_diagnostics` once the last batch on this worker or nanny
    has ended."""
    server = dask_worker
    depth = getattr(server, "_singcheck_batches", 0) - 1
    server._singcheck_batches = max(depth, 0)
    if depth > 0:
        return
    from time import time

    _fewer_collections(-1)
    saved = getattr(server, "_singcheck_saved", {})
    if "tick" in saved and hasattr(server, "_last_tick"):
        # the pause is not the event loop being unresponsive: measure from now on
        server._last_tick = server._last_tick_cycle = time()
        server._last_tick_counter = getattr(server, "_tick_counter", 0)
    for name, old in saved.items():
        pc = server.periodic_callbacks.get(name)
        if pc is None:
            continue
        if old is None:
            pc.start()
        else:
            pc.callback_time = old
    server._singcheck_saved = {}


def _on_workers(client, function) -> None:
    """Run ``function`` on every worker, every nanny and the scheduler; a cluster that
    refuses (``Client.run`` disabled, a worker gone) only keeps its diagnostics running."""
    for nanny in (False, True):
        try:
            client.run(function, nanny=nanny, on_error="ignore")
        except Exception:  # noqa: BLE001 - an optimisation, never the batch's failure
            pass
    try:
        client.run_on_scheduler(_on_scheduler, function)
    except Exception:  # noqa: BLE001 - as above
        pass


def _on_scheduler(function, dask_scheduler=None) -> None:
    """``function`` (:func:`_pause_diagnostics` or :func:`_resume_diagnostics`) on the
    scheduler: its tick measure (every 20 ms) and system monitor (500 ms) wake its event
    loop on a core the workers need."""
    function(dask_scheduler)


#: trajectories per task at most, and the seconds a task should take: on a 2-worker
#: cluster a task costs about 14 ms of CPU beyond its trajectories' own (a heart: about
#: 4 ms), so tasks start at FIRST_CHUNK and grow to what takes TASK_SECONDS at the pace
#: seen (:class:`singcheck.api._TaskSizes`; 2,000 hearts on 2 cores: 128 a task ran 5%
#: faster than 64); a short batch goes in at least TASKS_PER_WORKER tasks per thread
CHUNK = 128
FIRST_CHUNK = 16
TASK_SECONDS = 0.5
TASKS_PER_WORKER = 4


def check_on_cluster(address: str, robot: Robot,
                     trajectories: Iterable[TrajectorySpec | Document], *,
                     tolerance: float = DEFAULT_TOLERANCE, regions: bool = True,
                     time_limit: float | None = DEFAULT_TIME_LIMIT, ordered: bool = True,
                     notify: Notify = _quiet, engine: str = "auto", line=None,
                     **selection) -> Iterator[dict | Formatted]:
    """:func:`singcheck.api.check_batch` on the dask.distributed scheduler at
    ``address``: yields each trajectory's JSON object in input order, or
    (``ordered=False``) as the tasks finish.  ``trajectories`` is read lazily, a bounded
    number of tasks ahead.  Stopping the iteration (Ctrl-C) cancels the tasks still
    queued.  ``line``: as for :func:`~singcheck.api.check_batch`, the workers write each
    result's line; a :class:`~singcheck.spec.files.Span` travels with its bytes (a
    cluster's workers need not see this machine's files)."""
    from itertools import chain, islice

    from singcheck.algebra.pickling import register

    register()
    client = _client(address)
    quiet = False
    try:
        workers = client.scheduler_info()["workers"]
        threads = sum(w.get("nthreads", 1) for w in workers.values())
        notify(f"dask scheduler {address}: {len(workers)} worker(s)")
        options = dict(tolerance=tolerance, regions=regions, time_limit=time_limit,
                       engine=engine, **selection)
        items = iter(trajectories)
        head = list(islice(items, LOOKAHEAD))
        shared_regions(robot, head, options, notify)
        # hash=False: a random key, not a token of the robot (tokenizing pickled it all
        # once more, about 0.3 s of every run on 2 cores)
        shipped = client.scatter(replace(robot, region_cache=None), broadcast=True,
                                 hash=False)
        _on_workers(client, _pause_diagnostics)
        quiet = True
        window = max(8, TASKS_PER_WORKER * threads)  # tasks in flight
        first = FIRST_CHUNK if len(head) == LOOKAHEAD else \
            max(1, min(FIRST_CHUNK, -(-len(head) // window)))
        sizes = _TaskSizes(threads, first, CHUNK, TASK_SECONDS, TAIL)
        yield from _results(_Submitter(client, shipped, chain(head, items), options,
                                       robot.region_cache is not None, window, sizes, line),
                            ordered)
    finally:
        if quiet:
            _on_workers(client, _resume_diagnostics)
        client.close()  # the tasks still queued or running are cancelled with it


#: the fewest trajectories a task of a batch's end holds
TAIL = 4


class _Submitter:
    """Submits the tasks a window at a time (``window`` in flight), so that neither this
    process nor the scheduler holds a task per trajectory of a long batch at once.

    Each task is ``sizes.take(items)`` (:class:`singcheck.api._TaskSizes`: small at
    first, then what takes about TASK_SECONDS at the pace seen), read two tasks ahead,
    so that once the input has ended the last trajectories go in smaller and
    smaller tasks (a share of what is left per worker thread, at least TAIL), and the
    batch does not end with one worker on a whole task while the others wait."""

    def __init__(self, client, shipped, items: Iterator, options, region_cache: bool,
                 window: int, sizes: _TaskSizes, line=None) -> None:
        from distributed import as_completed

        self.client, self.shipped, self.options, self.line = client, shipped, options, line
        self.region_cache = region_cache
        self.items, self.sizes = items, sizes
        self.read = 0
        self.batch = uuid.uuid4().hex[:12]
        self.chunks: dict[str, tuple[int, list]] = {}  # key -> (first index, trajectories)
        self.completed = as_completed(loop=client.loop)
        for _ in range(window):
            self.next()

    def next(self) -> None:
        """Submit the next few trajectories as one task, if any is left."""
        chunk = self.sizes.take(self.items)
        if not chunk:
            return
        chunk = [item.loaded() if isinstance(item, Span) else item for item in chunk]
        future = self.client.submit(_remote_check, self.shipped, chunk, self.options,
                                    self.region_cache, self.line,
                                    key=f"singcheck-{self.batch}-{self.read}", pure=False)
        self.chunks[future.key] = (self.read, chunk)
        self.read += len(chunk)
        self.completed.add(future)


def _results(tasks: _Submitter, ordered: bool) -> Iterator[dict]:
    from singcheck.report.trajectory import error_json

    done: dict[int, dict] = {}
    next_out = 0
    for future in tasks.completed:
        first, chunk = tasks.chunks.pop(future.key)
        tasks.sizes.finished(len(chunk))
        try:
            docs = future.result()
        except Exception as e:  # the task was lost (a worker died) or could not run
            # Dask re-runs a task whose worker died; KilledWorker means it killed every
            # worker it was given (out of memory, most likely): like a path that kills
            # its --jobs worker twice, that is the paths' own error, not a bug
            kind = "worker-died" if type(e).__name__ == "KilledWorker" else "internal"
            docs = [formatted(error_json(_head(item), kind,
                                         f"the Dask task failed: {type(e).__name__}: {e}"),
                              tasks.line)
                    for item in chunk]
        future.release()
        tasks.next()
        if not ordered:
            yield from docs
            continue
        done.update(enumerate(docs, first))
        while next_out in done:
            yield done.pop(next_out)
            next_out += 1
