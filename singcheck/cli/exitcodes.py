"""The one exit-status enum of the command line (documented in docs/outputs.md), and the one
place where library errors become exit codes."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from enum import IntEnum

import click

from singcheck.errors import BackendError, SingcheckError, SpecError


class ExitCode(IntEnum):
    SINGULARITY_FREE = 0  #: every trajectory is proven singularity-free
    SINGULAR = 1  #: some trajectory is singular or infeasible
    USAGE = 2  #: bad command line or bad spec file
    UNKNOWN = 3  #: some trajectory could not be decided (and none is singular)
    BACKEND = 4  #: an elimination backend is missing or failed
    INTERNAL = 70  #: a bug in singcheck (reported in one line; SINGCHECK_DEBUG=1 for details)
    INTERRUPTED = 130  #: Ctrl-C


@contextmanager
def exit_codes() -> Iterator[None]:
    """The one place where library errors become exit codes (and Ctrl-C becomes 130)."""
    try:
        yield
    except KeyboardInterrupt:
        fail("interrupted", ExitCode.INTERRUPTED)
    except SpecError as e:
        fail(str(e), ExitCode.USAGE)
    except BackendError as e:
        fail(str(e), ExitCode.BACKEND)
    except SingcheckError as e:
        fail(str(e), ExitCode.UNKNOWN)


def fail(message: str, code: ExitCode) -> None:
    """One line on stderr, then exit with ``code``."""
    click.echo(f"singcheck: error: {message}", err=True)
    sys.exit(int(code))
