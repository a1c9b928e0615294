"""Batches on a Dask cluster: ``singcheck run … --scheduler ADDRESS``.

The robot's projection is computed once, here, and shipped to every worker
(``Client.scatter(…, broadcast=True)``); each trajectory is one task, which calls the
public API (:func:`singcheck.api.check_safely`, i.e. :func:`singcheck.check` with the
batch's failure handling); results come back as they finish.  The transport, the
scheduling and the worker processes are dask.distributed's (``pip install
'singcheck[dask]'``): singcheck adds no protocol of its own.  python-flint's polynomials
cross the wire through :mod:`singcheck.algebra.pickling`.
"""

from __future__ import annotations

import uuid
from collections.abc import Iterator
from dataclasses import replace

from singcheck.api import (
    DEFAULT_TIME_LIMIT,
    DEFAULT_TOLERANCE,
    Notify,
    Robot,
    _quiet,
    check_safely,
    prepare_regions,
)
from singcheck.errors import BackendError, SpecError
from singcheck.spec.files import TrajectorySpec

CONNECT_TIMEOUT = 30  # seconds to reach the scheduler


def _client(address: str):
    try:
        from distributed import Client
    except ImportError:
        raise SpecError("--scheduler needs dask.distributed: pip install "
                        "'singcheck[dask]'") from None
    try:
        return Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as e:
        raise BackendError(f"cannot reach the Dask scheduler at {address}: {e}") from None


def _remote_check(robot: Robot, trajectory: TrajectorySpec, options: dict,
                  region_cache: bool) -> dict:
    """One task, on a worker: the public API on the shipped robot."""
    if region_cache and robot.region_cache is None:
        from singcheck.spaces.region_map import RegionMapCache

        robot.region_cache = RegionMapCache()  # the worker's own cache directory
    return check_safely(robot, trajectory, **options)


def check_on_cluster(address: str, robot: Robot, trajectories: list[TrajectorySpec], *,
                     tolerance: float = DEFAULT_TOLERANCE, regions: bool = True,
                     time_limit: float | None = DEFAULT_TIME_LIMIT, ordered: bool = True,
                     notify: Notify = _quiet) -> Iterator[dict]:
    """:func:`singcheck.api.check_batch` on the dask.distributed scheduler at
    ``address``: yields each trajectory's JSON object in input order, or
    (``ordered=False``) as the tasks finish.  Stopping the iteration (Ctrl-C) cancels
    the tasks still queued."""
    from singcheck.algebra.pickling import register

    register()
    client = _client(address)
    try:
        notify(f"dask scheduler {address}: {len(client.scheduler_info()['workers'])} "
               "worker(s)")
        options = dict(tolerance=tolerance, regions=regions, time_limit=time_limit)
        if regions and not prepare_regions(
                robot, trajectories, time_limit, notify):
            options["regions"] = False
        shipped = client.scatter(replace(robot, region_cache=None), broadcast=True)
        window = max(64, 16 * len(client.scheduler_info()["workers"]))
        yield from _results(client, _Submitter(client, shipped, trajectories, options,
                                               robot.region_cache is not None, window),
                            trajectories, ordered)
    finally:
        client.close()  # the tasks still queued or running are cancelled with it


class _Submitter:
    """Submits the tasks a window at a time (``window`` in flight), so that neither this
    process nor the scheduler holds a task per trajectory of a long batch at once."""

    def __init__(self, client, shipped, trajectories, options, region_cache: bool,
                 window: int) -> None:
        from distributed import as_completed

        self.client, self.shipped, self.options = client, shipped, options
        self.region_cache = region_cache
        self.pending = iter(enumerate(trajectories))
        self.batch = uuid.uuid4().hex[:12]
        self.index: dict[str, int] = {}
        self.completed = as_completed(loop=client.loop)
        for _ in range(window):
            self.next()

    def next(self) -> None:
        """Submit the next trajectory's task, if any is left."""
        for i, spec in self.pending:
            future = self.client.submit(_remote_check, self.shipped, spec, self.options,
                                        self.region_cache, key=f"singcheck-{self.batch}-{i}",
                                        pure=False)
            self.index[future.key] = i
            self.completed.add(future)
            return


def _results(client, tasks: _Submitter, trajectories, ordered: bool) -> Iterator[dict]:
    from singcheck.report.trajectory import error_json

    done: dict[int, dict] = {}
    next_out = 0
    for future in tasks.completed:
        i = tasks.index.pop(future.key)
        try:
            doc = future.result()
        except Exception as e:  # the task was lost (a worker died) or could not run
            doc = error_json(trajectories[i], "internal",
                             f"the Dask task failed: {type(e).__name__}: {e}")
        future.release()
        tasks.next()
        if not ordered:
            yield doc
            continue
        done[i] = doc
        while next_out in done:
            yield done.pop(next_out)
            next_out += 1
