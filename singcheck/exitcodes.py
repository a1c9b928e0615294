"""The one exit-status enum of the command line (documented in the README)."""

from enum import IntEnum


class ExitCode(IntEnum):
    SINGULARITY_FREE = 0  #: every trajectory is proven singularity-free
    SINGULAR = 1  #: some trajectory is singular or infeasible
    USAGE = 2  #: bad command line or bad spec file
    UNKNOWN = 3  #: some trajectory could not be decided (and none is singular)
    BACKEND = 4  #: an elimination backend is missing or failed
    INTERNAL = 70  #: a bug in singcheck (reported in one line; SINGCHECK_DEBUG=1 for details)
    INTERRUPTED = 130  #: Ctrl-C
