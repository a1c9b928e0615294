"""Singular and Macaulay2 as subprocesses: compile → run → parse, then re-check.

Each backend is the same three stages with different pure pieces (the script from
:mod:`singcheck.cas.scripts`, the argv below) and one shared funnel
(:func:`singcheck.cas.process.run_program`).  The generated script is written to a
temporary directory that is removed afterwards; no user init file is read
(``Singular -q -t --no-rc``, ``M2 --script``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cache

from singcheck.elimination.cas.scripts import macaulay2_script, parse_result, singular_script
from singcheck.elimination.requests import (
    EliminationRequest,
    EliminationResult,
    prismatic_chain,
    slow_backend_refusal,
)
from singcheck.errors import BackendError

# (the subprocess machinery, tempfile and importlib.resources are imported where a CAS
# actually runs: a warm run answers from the cache and never needs them)

DEFAULT_TIMEOUT = 600.0


def library_path(filename: str) -> str:
    """Absolute path of a file of ``backends/`` (installed as ``singcheck.cas_library``):
    beside the package's ``__init__.py`` when it is a directory on disk (importlib's
    resource readers only when it is not, e.g. in a zip)."""
    import singcheck.cas_library as library

    if library.__file__:
        path = os.path.join(os.path.dirname(library.__file__), filename)
        if os.path.isfile(path):
            return path
    from importlib import resources

    return str(resources.files("singcheck.cas_library").joinpath(filename))


def _passagemath_singular() -> str | None:
    """The ``Singular`` binary shipped by PyPI's passagemath-singular, if installed."""
    import glob
    import sys
    import sysconfig

    roots = {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]}
    roots.update(p for p in sys.path if p.endswith("site-packages"))
    for root in roots:
        for path in glob.glob(os.path.join(root, "sage_wheels", "bin", "Singular")):
            if os.access(path, os.X_OK):
                return path
    return None


def _on_path(program: str) -> str | None:
    """The first executable file called ``program`` in a directory of PATH, as
    ``shutil.which`` finds it on POSIX (without importing shutil, and with it bz2 and
    lzma, into every warm run)."""
    for directory in os.get_exec_path():
        path = os.path.join(directory or os.curdir, program)
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return None


@dataclass(frozen=True)
class ExternalCAS:
    name: str  # backend name on the command line
    program: str  # executable looked up on PATH
    tested_versions: str
    install_hint: str

    def find(self) -> str | None:
        found = _on_path(self.program)
        if found is None and self.name == "singular":
            found = _passagemath_singular()
        return found

    def argv(self, executable: str, script_path: str) -> list[str]:
        if self.name == "singular":
            return [executable, "-q", "-t", "--no-rc", script_path]
        return [executable, "--script", script_path]

    def version_argv(self, executable: str) -> list[str]:
        return [executable, "--version"]

    def script(self, request: EliminationRequest) -> str:
        if self.name == "singular":
            return singular_script(request, library_path("singcheck.lib"))
        return macaulay2_script(request, library_path("singcheck.m2"))


SINGULAR = ExternalCAS(
    "singular", "Singular", "4.3.1 (Debian bookworm)",
    "install it with `apt-get install singular` (Debian/Ubuntu), or without root with "
    "`pip install passagemath-singular` (ships a Singular binary)")
MACAULAY2 = ExternalCAS(
    "macaulay2", "M2", "1.21 (Debian bookworm)",
    "install it with `apt-get install macaulay2` (Debian/Ubuntu)")


def _binary_identity(executable: str) -> str:
    real = os.path.realpath(executable)
    st = os.stat(real)
    return f"{real}:{st.st_size}:{st.st_mtime_ns}"


@cache
def cas_version(cas: ExternalCAS, executable: str) -> str:
    """The CAS version, remembered on disk per binary (path, size, mtime) so that a
    warm run starts no CAS process at all."""
    import json

    from singcheck.elimination.cache import cache_dir, read_bounded

    memo = cache_dir() / "versions.json"
    ident = _binary_identity(executable)
    try:
        known = json.loads(read_bounded(memo, 2**20).decode("utf-8"))
        if isinstance(known.get(ident), str):
            return known[ident]
    except (OSError, ValueError, AttributeError, RecursionError):
        known = {}
    version = _ask_version(cas, executable)
    try:
        from singcheck.atomic import write_atomically

        write_atomically(memo, json.dumps({**(known if isinstance(known, dict) else {}),
                                           ident: version}), make_parents=True)
    except OSError:
        pass
    return version


def _ask_version(cas: ExternalCAS, executable: str) -> str:
    from singcheck.elimination.cas.process import run_program

    run = run_program(cas.version_argv(executable), timeout=60)
    text = (run.stdout or run.stderr).strip().splitlines()
    if not text:
        raise BackendError(f"{cas.program} --version printed nothing")
    first = text[0]
    if cas.name == "singular" and "version" in first:
        return first.split("version", 1)[1].split("(")[0].strip()
    return first.strip()


def out_of_memory(run) -> str:
    """How a failed :class:`~singcheck.elimination.cas.process.ProgramRun` met its
    address-space bound ("" when it did not seem to): its last 4 KiB of output says an
    allocation failed (Singular: "error: no more memory"; Macaulay2: "out of memory";
    C++ and GMP allocators alike), or it died of SIGABRT or SIGKILL, the ways
    allocators, garbage collectors (and the kernel's OOM killer) end it."""
    import re
    import signal

    tail = run.stdout[-4096:] + "\n" + run.stderr[-4096:]
    if re.search(r"no more memory|out of memory|cannot allocate memory|bad_alloc|"
                 r"memory exhausted|unable to allocate", tail, re.IGNORECASE):
        return "ran out of memory"
    if run.returncode in (-signal.SIGABRT, -signal.SIGKILL):
        return (f"died of {signal.Signals(-run.returncode).name} (most likely out of "
                "memory)")
    return ""


class ExternalBackend:
    """An elimination backend that runs a CAS program once per request."""

    def __init__(self, cas: ExternalCAS, executable: str | None = None,
                 timeout: float = DEFAULT_TIMEOUT) -> None:
        self.cas = cas
        self.name = cas.name
        found = executable or cas.find()
        if found is None:
            raise BackendError(f"backend {cas.name}: {cas.program} was not found; "
                               f"{cas.install_hint}")
        self.executable = found
        self.timeout = timeout

    def version(self) -> str:
        return cas_version(self.cas, self.executable)

    def script(self, request: EliminationRequest) -> str:
        return self.cas.script(request)

    def cache_identity(self, request: EliminationRequest) -> str:
        """What determines the result: the script and the library it loads."""
        library = "singcheck.lib" if self.name == "singular" else "singcheck.m2"
        with open(library_path(library), encoding="utf-8") as f:
            return self.script(request) + "\n" + f.read()

    def eliminate(self, request: EliminationRequest) -> EliminationResult:
        import tempfile

        from singcheck.elimination.cas.limits import bound_text, inherited_limit, raise_hint
        from singcheck.elimination.cas.process import run_program

        if self.name == "macaulay2":
            refusal = slow_backend_refusal(request, "macaulay2")
            if refusal:
                raise BackendError(refusal)
        script = self.script(request)
        with tempfile.TemporaryDirectory(prefix="singcheck-") as tmp:
            suffix = "sing" if self.name == "singular" else "m2"
            path = os.path.join(tmp, f"{request.label}.{suffix}")
            with open(path, "w", encoding="utf-8") as f:
                f.write(script)
            run = run_program(self.cas.argv(self.executable, path), self.timeout, cwd=tmp,
                              scratch=tmp)
        if run.returncode != 0 and run.memory_limit:
            memory = out_of_memory(run)
            if memory:
                raise BackendError(
                    f"{self.cas.program} {memory} under {bound_text(run.memory_limit)} "
                    f"per CAS process; {raise_hint(run.memory_limit)}")
            if run.memory_limit == inherited_limit():  # it may not even start under it
                raise BackendError(
                    f"{self.cas.program} exited with status {run.returncode} under "
                    f"{bound_text(run.memory_limit)}; {raise_hint(run.memory_limit)}")
        polys = parse_result(self.cas.program, run.stdout, run.stderr, request)
        if run.returncode != 0:
            raise BackendError(f"{self.cas.program} exited with status {run.returncode}")
        how = "resultant chain" if self.name == "singular" and prismatic_chain(request) \
            else "eliminate"
        return EliminationResult(request, polys, f"{self.cas.program} {how}", self.name)
