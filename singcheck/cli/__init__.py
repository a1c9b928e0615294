"""The command line (stage 9, the top): click commands only.

Each command parses its options, calls :mod:`singcheck.api` (and the stage packages for
``project`` and the space commands), renders through :mod:`singcheck.report`, and maps
errors to exit codes (:mod:`singcheck.cli.exitcodes`).  The only importer of click.
May import every stage.
"""

from singcheck.cli.commands import cli, main

__all__ = ["cli", "main"]
