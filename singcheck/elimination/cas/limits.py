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


def memory_limit() -> int:
    """The bound on each CAS process's address space, in bytes (0: none): the
    environment's ``SINGCHECK_MEMORY_LIMIT`` (``4G``, ``512M``, a number of MiB, or
    ``none``), else :func:`default_memory_limit`."""
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


def describe_limit(limit: int) -> str:
    return f"{limit / 2**30:g} GiB" if limit % 2**30 == 0 else f"{limit // 2**20} MiB"
