"""Progress for people, on stderr: notes, a spinner, a bar for batches (rich).

Silent with ``--quiet``; plain lines when stderr is not a terminal (CI logs).
"""

from __future__ import annotations

import sys


class Progress:
    """Progress notes on stderr (silent with --quiet).

    rich is imported only when stderr is a terminal: plain lines need nothing but
    ``sys.stderr``, so a run piped into a file or a CI log starts faster.
    """

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self._console = None

    @property
    def console(self):
        if self._console is None:
            from rich.console import Console

            self._console = Console(stderr=True, highlight=False, soft_wrap=True)
        return self._console

    def _terminal(self) -> bool:
        return sys.stderr.isatty() and self.console.is_terminal

    def note(self, message: str) -> None:
        if self.quiet:
            return
        if self._terminal():
            from rich.markup import escape

            self.console.print(f"[dim]singcheck:[/dim] {escape(message)}")
        else:
            sys.stderr.write(f"singcheck: {message}\n")
            sys.stderr.flush()

    def bar(self, total: int | None):
        """A context giving ``advance(name, verdict)``: a bar on a terminal, else notes
        (``total`` None: not known, a stream being read)."""
        from contextlib import contextmanager

        @contextmanager
        def plain():
            done = [0]
            step = max(1, total // 10) if total else 1000
            of = f"/{total}" if total else ""

            def advance(name: str, verdict: str) -> None:
                done[0] += 1
                if total and total <= 20:
                    self.note(f"[{done[0]}/{total}] {name}: {verdict}")
                elif done[0] % step == 0 or done[0] == total:
                    self.note(f"certified {done[0]}{of} trajectories")

            yield advance

        @contextmanager
        def rich_bar():
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeRemainingColumn,
            )

            with Progress(TextColumn("certifying"), BarColumn(), MofNCompleteColumn(),
                          TimeRemainingColumn(), console=self.console, transient=True) as bar:
                task = bar.add_task("certify", total=total)
                done = [0]

                def advance(name: str, verdict: str) -> None:
                    done[0] += 1
                    bar.advance(task)

                yield advance
            self.note(f"certified {done[0]} trajectories")

        if self.quiet:
            @contextmanager
            def silent():
                yield lambda name, verdict: None
            return silent()
        return rich_bar() if (total is None or total > 1) and self._terminal() else plain()

    def status(self, message: str):
        from contextlib import nullcontext

        if self.quiet or not self._terminal():
            self.note(message)
            return nullcontext()
        return self.console.status(message)
