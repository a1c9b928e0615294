"""File writes: readers see the old file or the whole new one, never a part; and a
user's ``-o`` target that is not a regular file is written to, never replaced."""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

from singcheck.errors import SpecError


def write_atomically(path: str | os.PathLike, text: str, *, make_parents: bool = False) -> None:
    """Write ``text`` to a temporary file beside ``path``, then rename it into place.

    On any failure (or Ctrl-C) the temporary file is removed and ``path`` is untouched.
    Used for cache entries and the CAS version memo (``make_parents``: create missing
    directories), and by :func:`write_output` for regular files, so concurrent runs and
    interrupted ones never leave half a file.  Whatever ``path`` was (a FIFO or a symlink
    planted in a cache, say), it is replaced by a regular file.
    """
    target = Path(path)
    if make_parents:
        target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(tmp, _mode_for(target))
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_output(path: str | os.PathLike, text: str) -> None:
    """Write a result to the user's ``-o`` target.

    A regular file (or a new one) is written atomically; a symlink is followed and its
    target written (the link stays a link); anything else that exists — a character
    device such as ``/dev/null`` or ``/dev/stdout``, a FIFO, a socket — is opened and
    written in place, as a shell redirection would, never replaced.  A missing parent
    directory is an error, not created.  Every failure (``/dev/full``: no space left) is
    a :class:`~singcheck.errors.SpecError` naming the file and the reason.
    """
    name = os.fspath(path)
    try:
        real = os.path.realpath(name)
        try:
            mode = os.stat(real).st_mode
        except FileNotFoundError:
            mode = None
        if mode is not None and not stat.S_ISREG(mode):
            if stat.S_ISDIR(mode):
                raise IsADirectoryError(21, "Is a directory")
            with open(real, "w", encoding="utf-8") as f:
                f.write(text)
            return
        parent = os.path.dirname(real) or "."
        if not os.path.isdir(parent):
            raise FileNotFoundError(2, f"the directory {parent} does not exist")
        write_atomically(real, text)
    except OSError as e:
        raise SpecError(f"cannot write the output: {e.strerror or e}", path=name) from None


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
