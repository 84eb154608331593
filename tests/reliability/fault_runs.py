"""Commands of ``python -m bench`` started cheaply enough to kill hundreds of them: each is
forked from a server process that has imported the package once (multiprocessing's
forkserver), runs in a session of its own (so that a signal reaches its Dask workers too, as
Ctrl-C in a terminal does) and writes its output to files."""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

PRELOAD = ["bench.cli", "bench.matrix.run", "bench.matrix.distributed"]


def _command(argv: list[str], stdout: str, stderr: str) -> None:
    os.setsid()
    for fd, path in ((1, stdout), (2, stderr)):
        handle = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(handle, fd)
        os.close(handle)
    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, signal.SIG_DFL)  # as in a new process; main() sets its own
    try:
        from bench.cli import main

        status = main(argv)
    except BaseException:  # noqa: BLE001 - what escapes main is what the test looks for
        traceback.print_exc()
        status = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


@dataclass
class Command:
    process: multiprocessing.Process
    stdout: Path
    stderr: Path
    started: float

    def signal(self, number: int) -> None:
        try:
            os.killpg(self.process.pid, number)
        except ProcessLookupError:  # not yet its own session, or already ended
            try:
                os.kill(self.process.pid, number)
            except ProcessLookupError:
                pass

    def wait(self, timeout: float = 300.0) -> int:
        """The exit status: the command's own, or -N if signal N ended it; returns once no
        process of its group (its Dask workers) runs any more, as the next command would
        find it."""
        self.process.join(timeout)
        if self.process.exitcode is None:
            self.signal(signal.SIGKILL)
            self.process.join()
            raise AssertionError(f"the command did not end within {timeout} s")
        deadline = time.monotonic() + 30.0
        while group_runs(self.process.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        return self.process.exitcode

    def output(self) -> tuple[str, str]:
        return self.stdout.read_text(), self.stderr.read_text()


def group_runs(group: int) -> bool:
    """Whether a process of process group ``group`` runs (zombies do not)."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue  # ended while we looked
        if int(fields[2]) == group and fields[0] not in ("Z", "X"):
            return True
    return False


_context = None


def start(argv: list[str], folder: Path) -> Command:
    """``python -m bench ARGV`` forked from the server, its output in ``folder``."""
    global _context
    if _context is None:
        _context = multiprocessing.get_context("forkserver")
        _context.set_forkserver_preload(PRELOAD)
    stdout, stderr = folder / "stdout.txt", folder / "stderr.txt"
    process = _context.Process(target=_command, args=(argv, str(stdout), str(stderr)))
    process.start()
    return Command(process, stdout, stderr, time.monotonic())
