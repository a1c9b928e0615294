"""The guard between singcheck and a CAS: it dies with singcheck, and takes the CAS and
every descendant of the CAS with it, even when singcheck is SIGKILLed.

:func:`singcheck.elimination.cas.process.run_program` does not start the CAS itself but
this file, as a fresh interpreter (``python -I -S guard.py PARENT LIMIT SCRATCH --
argv…``: standard library only, a few milliseconds).  The guard

* asks the kernel for ``SIGTERM`` when its parent thread exits (``PR_SET_PDEATHSIG``;
  the thread of singcheck that starts it is the one that waits for it), and checks that
  its parent is still the one it was started by, so a parent that died before that
  request is noticed too;
* is a *child subreaper* (``PR_SET_CHILD_SUBREAPER``): a descendant of the CAS whose
  parent dies, including one that called ``setsid`` to leave the process group, is
  re-parented to the guard instead of to init;
* forks the CAS, which asks for ``SIGKILL`` when the guard dies
  (``PR_SET_PDEATHSIG``; so even a SIGKILLed guard leaves no CAS behind) and runs under
  an address-space bound (``RLIMIT_AS``, ``LIMIT`` bytes, 0 for none) before ``exec``;
* on ``SIGTERM`` (its parent died) kills every process of its group, then, round by
  round, every child it has (the re-parented descendants), reaps them, removes the
  CAS's scratch directory ``SCRATCH`` (its parent, killed, could not; "" for none) and
  exits 143.

When the CAS ends normally the guard exits with the same status (a CAS killed by a
signal: the guard kills itself with that signal, without a core file), and whatever the
CAS left behind is re-parented to singcheck, which kills its group and its strays as
before.  Linux only; elsewhere the ``prctl`` calls fail and the guard is a plain
``exec`` wrapper.  Also importable: :func:`children` and :func:`reap_children` serve
run_program's own clean-up.
"""

from __future__ import annotations

import functools
import os
import signal
import sys

#: this file, run as a script by run_program
SCRIPT = os.path.abspath(__file__)
PR_SET_PDEATHSIG = 1
PR_SET_CHILD_SUBREAPER = 36
#: the exit status and first bytes on stderr of a guard whose CAS could not be started
EXEC_FAILED = 127
EXEC_FAILED_MARK = "singcheck-guard: could not start "


def prctl(option: int, value: int) -> bool:
    """``prctl(option, value)`` through libc; False where it is not available."""
    try:
        return _libc().prctl(option, value, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


@functools.cache
def _libc():
    """The C library through ctypes, loaded once: a forked child that loaded it itself
    spent about 6 ms importing ctypes, most of a short stoppable call's cost."""
    import ctypes

    return ctypes.CDLL(None, use_errno=True)


def ready_to_fork() -> None:
    """Load here, before a fork, what :func:`die_with_parent` needs in the child."""
    try:
        _libc()
    except OSError:
        pass


def _processes():
    """(pid, state, parent pid, process group) of every process, from /proc (nothing
    where there is no /proc)."""
    try:
        entries = os.listdir("/proc")
    except OSError:
        return
    for name in entries:
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat[stat.rfind(b")") + 2:].split()
        if len(fields) > 2:
            yield int(name), fields[0], int(fields[1]), int(fields[2])


def children() -> set[int]:
    """The pids whose parent is this process."""
    me = os.getpid()
    return {pid for pid, _, parent, _ in _processes() if parent == me}


def _group_members(group: int) -> set[int]:
    """The live processes (not zombies) of process group ``group``, other than us."""
    me = os.getpid()
    return {pid for pid, state, _, pgrp in _processes()
            if pgrp == group and state != b"Z" and pid != me}


def die_with_parent(parent: int, signum: int = signal.SIGKILL) -> None:
    """In a freshly forked child: ask for ``signum`` when the parent's forking thread
    exits (``PR_SET_PDEATHSIG``), exit at once if ``parent`` is already gone (it died
    before the request), and take the default action for SIGINT, SIGTERM and SIGHUP
    again (the parent's handlers are the parent's)."""
    prctl(PR_SET_PDEATHSIG, signum)
    if os.getppid() != parent:
        os._exit(1)
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)


def reap_children(keep, rounds: int = 100) -> None:
    """Kill (SIGKILL, with their groups) and reap our children for which ``keep(pid)`` is
    false, round after round: each round's deaths re-parent the next generation of
    descendants to us when we are their subreaper."""
    for _ in range(rounds):
        strays = [pid for pid in children() if not keep(pid)]
        if not strays:
            return
        for pid in strays:
            for kill in (os.killpg, os.kill):
                try:
                    kill(pid, signal.SIGKILL)
                except OSError:
                    pass
        for pid in strays:
            try:
                os.waitpid(pid, 0)
            except OSError:
                pass


class _ParentDied(Exception):
    pass


def _stop(signum, frame):
    raise _ParentDied


def _kill_everything() -> None:
    """Kill our group (but us) and every descendant re-parented to us."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    group = os.getpgid(0)
    for _ in range(100):
        members = _group_members(group)
        if not members:
            break
        for pid in members:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        reap_children(lambda pid: False, rounds=1)
    reap_children(lambda pid: False)


def _exec_cas(argv: list[str], limit: int, guard: int) -> None:
    """In the forked child: die with the guard, bound the address space, exec."""
    try:
        die_with_parent(guard)
        if limit > 0:
            import resource

            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        os.execvp(argv[0], argv)
    except BaseException as e:  # exec failed: say why on stderr, for run_program
        reason = getattr(e, "strerror", None) or str(e)
        os.write(2, f"{EXEC_FAILED_MARK}{argv[0]}: {reason}\n".encode(errors="replace"))
    os._exit(EXEC_FAILED)


def _remove_scratch(path: str) -> None:
    """Remove the CAS's scratch directory (only one of singcheck's: ``singcheck-*``)."""
    if path and os.path.basename(os.path.normpath(path)).startswith("singcheck-"):
        import shutil

        shutil.rmtree(path, ignore_errors=True)


def main(args: list[str]) -> int:
    parent, limit, scratch, sep, *argv = args
    if sep != "--" or not argv:
        print("usage: guard.py PARENT LIMIT SCRATCH -- argv...", file=sys.stderr)
        return 2
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, _stop)
    try:
        prctl(PR_SET_CHILD_SUBREAPER, 1)
        prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        if os.getppid() != int(parent):  # the parent died before the request
            raise _ParentDied
        import resource

        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        guard = os.getpid()
        cas = os.fork()
        if cas == 0:
            _exec_cas(argv, int(limit), guard)
        while True:  # reap re-parented orphans as they come, until the CAS ends
            pid, status = os.waitpid(-1, 0)
            if pid == cas:
                break
    except _ParentDied:
        _kill_everything()
        _remove_scratch(scratch)
        return 143
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        signal.signal(sig, signal.SIG_DFL)
        os.kill(os.getpid(), sig)
    return os.waitstatus_to_exitcode(status)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
