"""File writes: readers see the old file or the whole new one, never a part; and a
user's ``-o`` target that is not a regular file is written to, never replaced."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TextIO

from singcheck.errors import SpecError


def write_atomically(path: str | os.PathLike, text: str, *, make_parents: bool = False) -> None:
    """Write ``text`` to a temporary file beside ``path``, then rename it into place.

    On any failure (or Ctrl-C) the temporary file is removed and ``path`` is untouched.
    Used for cache entries and the CAS version memo (``make_parents``: create missing
    directories), so concurrent runs and interrupted ones never leave half a file.
    Whatever ``path`` was (a FIFO or a symlink planted in a cache, say), it is replaced
    by a regular file.
    """
    with atomic_file(path, make_parents=make_parents) as f:
        f.write(text)


@contextmanager
def atomic_file(path: str | os.PathLike, *, make_parents: bool = False) -> Iterator[TextIO]:
    """A text file to write bit by bit (a stream of results) that appears at ``path``
    whole when the block ends, and not at all if it raises (or Ctrl-C stops it)."""
    import tempfile  # (with shutil, random, bz2, lzma: only when a file is written)

    target = Path(path)
    if make_parents:
        target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            yield f
        os.chmod(tmp, _mode_for(target))
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


class _Output:
    """The user's output file: a write error becomes a one-line SpecError naming it."""

    def __init__(self, f: TextIO, name: str) -> None:
        self._f, self.name = f, name

    def write(self, text: str) -> int:
        with _reported(self.name):
            return self._f.write(text)

    def flush(self) -> None:
        with _reported(self.name):
            self._f.flush()


@contextmanager
def _reported(name: str) -> Iterator[None]:
    try:
        yield
    except OSError as e:
        raise SpecError(f"cannot write the output: {e.strerror or e}", path=name) from None


@contextmanager
def output_file(path: str | os.PathLike) -> Iterator[_Output]:
    """The user's ``-o`` target, to write bit by bit.

    A regular file (or a new one) is written atomically: it appears whole when the block
    ends, not at all if it raises.  A symlink is followed and its target written (the
    link stays a link).  Anything else that exists — a character device such as
    ``/dev/null`` or ``/dev/stdout``, a FIFO, a socket — is opened and written in place,
    as a shell redirection would, never replaced (a FIFO that no process opens for
    reading within :data:`FIFO_WAIT` seconds is an error).  A missing parent directory is an
    error, not created.  Every failure (``/dev/full``: no space left) is a
    :class:`~singcheck.errors.SpecError` naming the file and the reason (exit 2).
    """
    name = os.fspath(path)
    with _reported(name):
        real = os.path.realpath(name)
        try:
            mode = os.stat(real).st_mode
        except FileNotFoundError:
            mode = None
        if mode is not None and stat.S_ISDIR(mode):
            raise IsADirectoryError(21, "Is a directory")
        in_place = mode is not None and not stat.S_ISREG(mode)
        parent = os.path.dirname(real) or "."
        if not in_place and not os.path.isdir(parent):
            raise FileNotFoundError(2, f"the directory {parent} does not exist")
        opened = _open_in_place(real) if in_place else atomic_file(real)
    with _reported(name), opened as f:
        yield _Output(f, name)


#: how long ``-o FIFO`` waits for a process to open the FIFO for reading (seconds)
FIFO_WAIT = 10.0


def _open_in_place(path: str) -> TextIO:
    """A device, FIFO or socket opened for writing without blocking on the open: a FIFO
    that no process reads is retried for :data:`FIFO_WAIT` seconds, then an error
    (a plain ``open`` waited for a reader for ever).  Writes then block as usual."""
    import errno
    import fcntl
    import time

    end = time.monotonic() + FIFO_WAIT
    while True:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
            break
        except OSError as e:
            if e.errno != errno.ENXIO:
                raise
            if time.monotonic() >= end:
                raise OSError(errno.ENXIO, f"no process reads this FIFO (waited "
                                           f"{FIFO_WAIT:g} s for one)") from None
            time.sleep(0.05)
    fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) & ~os.O_NONBLOCK)
    return open(fd, "w", encoding="utf-8")


def write_output(path: str | os.PathLike, text: str) -> None:
    """Write a whole result to the user's ``-o`` target (see :func:`output_file`)."""
    with output_file(path) as f:
        f.write(text)


#: the longest file-name stem made from input, in bytes of UTF-8: room for what follows
#: it (``-jointspace.png``, a counter) under the usual limit of 255 bytes a name
MAX_STEM_BYTES = 160


def safe_file_name(text: str, taken: set[str] | None = None) -> str:
    """``text`` (a name from a spec: input) as a file-name stem that stays inside the
    directory it is joined to: letters and digits (any script), ``.``, ``_``, ``-``,
    ``+``, ``=`` are kept, ``/`` becomes ``_``, parentheses become ``-`` (tan(phi/2) ->
    tan-phi_2), anything else (NUL, a space, a control character) ``_``; leading dots
    are dropped (no ``..``, no hidden file), and a stem longer than
    :data:`MAX_STEM_BYTES` is cut, with a hash of the whole text so that long names
    stay apart.  With ``taken`` (the stems already used in one directory by this run), a
    stem already there gets ``-2``, ``-3``, … and the one returned is added to it, so two
    names that map to the same stem never write the same file.

    >>> safe_file_name("../escape"), safe_file_name("/etc/passwd"), safe_file_name("..")
    ('_escape', '_etc_passwd', '_')
    >>> taken = set()
    >>> safe_file_name("a/b", taken), safe_file_name("a_b", taken)
    ('a_b', 'a_b-2')
    """
    import hashlib

    out = str(text).replace("/", "_").replace("(", "-").replace(")", "")
    out = "".join(c if c.isalnum() or c in "._-+=" else "_" for c in out).lstrip(".") or "_"
    if len(out.encode("utf-8")) > MAX_STEM_BYTES:
        digest = hashlib.sha256(str(text).encode("utf-8", "surrogatepass")).hexdigest()[:12]
        cut = out.encode("utf-8")[:MAX_STEM_BYTES - 13].decode("utf-8", "ignore")
        out = f"{cut}-{digest}"
    if taken is None:
        return out
    stem, n = out, 1
    while stem.casefold() in taken:
        n += 1
        stem = f"{out}-{n}"
    taken.add(stem.casefold())
    return stem


def _mode_for(target: Path) -> int:
    """Keep an existing file's mode; give a new one the usual 0666 less the umask
    (mkstemp creates 0600)."""
    try:
        st = target.stat()
        if stat.S_ISREG(st.st_mode):
            return st.st_mode & 0o777
    except OSError:
        pass
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask
