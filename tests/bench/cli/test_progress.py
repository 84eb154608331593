"""The live progress line: counts, DOFs and times on a terminal; silent otherwise."""

import io
from types import SimpleNamespace

from bench.cli.progress import Progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_line_counts_sequences_and_dofs_on_a_terminal():
    stream, printed = Terminal(), []
    progress = Progress(3, stream)
    on_level = progress.level(printed.append)
    on_level(SimpleNamespace(row=SimpleNamespace(ndofs=544)))
    progress.sequence(None, "budget")
    on_level(SimpleNamespace(row=SimpleNamespace(ndofs=2112)))
    progress.close()
    text = stream.getvalue()
    assert "1/3 sequences done, 2 left, max 2112 DOFs" in text and "to go" in text
    assert len(printed) == 2 and text.endswith("\n")


def test_progress_is_quiet_when_not_a_terminal():
    stream = io.StringIO()
    progress = Progress(2, stream)
    progress.sequence(None, "budget")
    progress.close()
    assert stream.getvalue() == ""
