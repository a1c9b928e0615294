"""Domain errors. The library raises these; only ``cli.py`` turns them into exit codes."""

from __future__ import annotations


class SingcheckError(Exception):
    """Base class of every error singcheck reports to a user."""


class SpecError(SingcheckError):
    """A robot or trajectory spec is unreadable or wrong.

    ``str()`` is one line: ``FILE:LINE: KEY: what is wrong``.
    """

    def __init__(self, message: str, *, path: str | None = None, line: int | None = None,
                 key: str | None = None) -> None:
        self.message = message
        self.path = path
        self.line = line
        self.key = key
        super().__init__(str(self))

    def __reduce__(self):  # keep the location when crossing a process boundary
        return (_rebuild_spec_error, (type(self), self.message, self.path, self.line, self.key))

    def __str__(self) -> str:
        where = self.path or "<spec>"
        if self.line is not None:
            where += f":{self.line}"
        key = f" {self.key}:" if self.key else ""
        return f"{where}:{key} {self.message}"


class UnsupportedRobotError(SpecError):
    """The robot is valid but outside the class of robots singcheck can certify."""


class BackendError(SingcheckError):
    """An elimination backend is missing, failed, or returned something unexpected."""


def _rebuild_spec_error(cls, message, path, line, key):
    return cls(message, path=path, line=line, key=key)
