"""The history of the suite's figures across commits (docs/history.md): ``sources`` read a
command's results folder into figures, ``store`` keeps them in ``history/figures.csv``,
``moves`` says which moved beyond their noise since the last entry, ``page`` renders them."""

from bench.history.moves import Move, moves
from bench.history.page import write_page
from bench.history.sources import SOURCES, figures_of, register_source
from bench.history.store import HISTORY_FILE, Figure, append_figures, read_history

__all__ = ["HISTORY_FILE", "SOURCES", "Figure", "Move", "append_figures", "figures_of",
           "moves", "read_history", "register_source", "write_page"]
