"""Every way a command can be asked to end (docs/reliability.md, "Signals"): SIGINT (Ctrl-C),
SIGTERM (``kill``, ``timeout``, batch schedulers) and SIGHUP (a closed terminal) all raise
``Ended`` in the main thread, a ``KeyboardInterrupt``, so that the one path that keeps finished
rows and puts back what an ``--overwrite`` run set aside runs for each; a second signal while
that path runs is ignored, so it cannot be cut short. The command then prints one line and
exits with 128 + the signal's number."""

from __future__ import annotations

import signal
from contextlib import contextmanager

ENDING = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Ended(KeyboardInterrupt):
    """The process was asked to end by ``signal_number``."""

    def __init__(self, signal_number: int):
        super().__init__(signal.Signals(signal_number).name)
        self.signal_number = signal_number


def _raise_ended(number, frame) -> None:
    for each in ENDING:  # the cleanup that follows runs to its end
        signal.signal(each, signal.SIG_IGN)
    raise Ended(number)


@contextmanager
def ending_signals():
    """Within the block, SIGINT, SIGTERM and SIGHUP raise ``Ended``; the handlers before it
    come back after it."""
    saved = {number: signal.signal(number, _raise_ended) for number in ENDING}
    try:
        yield
    finally:
        for number, handler in saved.items():
            signal.signal(number, handler)


def exit_status(error: KeyboardInterrupt) -> int:
    """128 + the number of the signal that ended the command (SIGINT for a plain
    KeyboardInterrupt)."""
    return 128 + getattr(error, "signal_number", signal.SIGINT)


def ended_line(error: KeyboardInterrupt, out) -> str:
    """The one line a command ended by a signal prints."""
    name = signal.Signals(getattr(error, "signal_number", signal.SIGINT)).name
    return (f"interrupted: every finished row is kept in {out} (results.parquet, results.csv);"
            f" ended by {name}")
