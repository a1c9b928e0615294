"""The memory bound of every elimination: ``SINGCHECK_MEMORY_LIMIT``.

Each CAS process (:mod:`.guard` sets ``RLIMIT_AS`` before ``exec``) and each forked
child of an in-process backend (:mod:`.isolated`) runs under an address-space bound, so
that a Gröbner basis or a resultant that blows up ends with an allocation failure,
reported in one line (exit 4), instead of waking the kernel's OOM killer.
"""

from __future__ import annotations

import os

from singcheck.errors import SpecError


def default_memory_limit() -> int:
    """Half the machine's memory, at least 2 GiB (Macaulay2 alone reserves about 1 GiB
    of address space to start)."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        total = 0
    return max(2 * 2**30, total // 2)


_UNITS = {"": 2**20, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


def inherited_limit() -> int:
    """The hard address-space bound singcheck itself runs under (``ulimit -v``), in bytes;
    0 for none.  No process of ours can raise it: every bound we set stays under it."""
    try:
        import resource

        _, hard = resource.getrlimit(resource.RLIMIT_AS)
    except (ImportError, OSError, ValueError):
        return 0
    return 0 if hard == resource.RLIM_INFINITY or hard <= 0 else hard


def under_inherited(bound: int) -> int:
    """``bound`` (bytes, 0: none), lowered to :func:`inherited_limit` when that is lower:
    ``setrlimit`` refuses to raise a hard limit ("not allowed to raise maximum limit"),
    which left Singular unable to start under ``ulimit -v``."""
    inherited = inherited_limit()
    return min(bound, inherited) if inherited and bound else bound or inherited


def memory_limit() -> int:
    """The bound on each CAS process's address space, in bytes (0: none): the
    environment's ``SINGCHECK_MEMORY_LIMIT`` (``4G``, ``512M``, a number of MiB, or
    ``none``), else :func:`default_memory_limit`; never above the hard limit singcheck
    runs under (:func:`under_inherited`)."""
    return under_inherited(_requested_limit())


def raise_hint(limit: int) -> str:
    """What to do when a CAS needs more than ``limit`` bytes."""
    if limit and limit == inherited_limit():
        return ("raise the address-space limit singcheck runs under (ulimit -v) if the "
                "robot needs more")
    return "raise SINGCHECK_MEMORY_LIMIT (or set it to none) if the robot needs more"


def _requested_limit() -> int:
    text = os.environ.get("SINGCHECK_MEMORY_LIMIT", "").strip().upper().removesuffix("B")
    text = text.removesuffix("I")  # 4GiB, 4GB and 4G alike
    if not text:
        return default_memory_limit()
    if text in ("NONE", "0"):
        return 0
    number, unit = (text[:-1], text[-1]) if text[-1] in _UNITS else (text, "")
    if not number.isdigit() or len(number) > 12 or int(number) == 0:
        raise SpecError(f"SINGCHECK_MEMORY_LIMIT={os.environ['SINGCHECK_MEMORY_LIMIT']!r}: "
                        "expected a size such as 4G or 512M (a number alone is MiB), or "
                        "none")
    return int(number) * _UNITS[unit]


def bound_text(limit: int) -> str:
    """The bound ``limit``, for a message (naming ``ulimit -v`` when it is that one)."""
    inherited = " (ulimit -v)" if limit == inherited_limit() else ""
    return f"the bound of {describe_limit(limit)}{inherited}"


def describe_limit(limit: int) -> str:
    return f"{limit / 2**30:g} GiB" if limit % 2**30 == 0 else f"{limit // 2**20} MiB"
