"""The cyclic garbage collector, tuned alike in every process that certifies paths: the
command line, its ``--jobs`` workers (forked: they inherit it) and a Dask batch's
workers (:mod:`singcheck.cluster` raises it for the batch and restores it after).

Start-up imports create tens of thousands of long-lived objects (modules, classes,
functions), and every full collection scans them again: a few milliseconds of a warm
run, about 2% of a heart path in a batch.  A larger first-generation threshold lets the
collector run less often; it still runs, so memory stays bounded in long batches."""

from __future__ import annotations

import gc

#: the first-generation threshold while paths are certified (Python's default: 700)
FIRST_THRESHOLD = 50_000


def fewer_collections() -> tuple[int, ...]:
    """Raise the first threshold to :data:`FIRST_THRESHOLD` (never lower it); the
    thresholds before, to restore."""
    before = gc.get_threshold()
    gc.set_threshold(max(before[0], FIRST_THRESHOLD), *before[1:])
    return before
