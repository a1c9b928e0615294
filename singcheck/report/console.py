"""Rich renderings captured as text: what the CLI writes to stdout or to ``-o FILE``."""

from __future__ import annotations

from collections.abc import Callable
from io import StringIO


def captured(draw: Callable, interactive: bool, width: int) -> str:
    """Run ``draw(console)`` on a rich console writing into a string: with colours and
    the terminal's width when ``interactive``, else plain text ``width`` columns wide."""
    from rich.console import Console

    buffer = StringIO()
    console = Console(file=buffer, force_terminal=interactive,
                      width=None if interactive else width, highlight=False)
    draw(console)
    return buffer.getvalue()
