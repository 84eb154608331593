"""The command line, ``python -m bench COMMAND``: arguments in ``parser``, commands in
``commands``."""

from bench.cli.commands import main

__all__ = ["main"]
