"""What a run prints as it goes (bench.cli.progress): at most PROGRESS_LINES lines for a whole
matrix when not on a terminal, none with quiet, a bar on a terminal."""

import io
from types import SimpleNamespace

from bench.cli.progress import PROGRESS_LINES, Progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_long_matrix_prints_at_most_ten_lines_off_a_terminal():
    stream = io.StringIO()
    live = Progress(224, stream=stream, what="matrix")
    for _ in range(224):
        live.sequence(SimpleNamespace(scene="paper"))
    live.close()
    lines = stream.getvalue().splitlines()
    assert len(lines) <= PROGRESS_LINES and lines[-1].startswith("[matrix] 224 of 224 done")


def test_quiet_prints_nothing_and_a_terminal_gets_a_bar():
    stream = io.StringIO()
    live = Progress(5, stream=stream, quiet=True)
    for _ in range(5):
        live.sequence(SimpleNamespace(scene="paper"))
    assert stream.getvalue() == ""
    terminal = Terminal()
    bar = Progress(5, stream=terminal, what="matrix")
    bar.sequence(SimpleNamespace(scene="hertz"))
    bar.close()
    assert "matrix: 1/5" in terminal.getvalue() and "hertz" in terminal.getvalue()
