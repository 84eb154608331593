"""The hard cases (docs/theory.md, section 8): problems where a formulation or a solver may
break, each solved by every solver, with a verdict per row and the numbers behind it.
``python -m bench hard`` runs them."""

from bench.hard.registry import (
    hard_case,
    hard_case_descriptions,
    hard_case_names,
    hard_scene_names,
)
from bench.hard.run import run_hard
from bench.hard.tables import check_expected, hard_display, hard_markdown, write_hard
from bench.hard.verdicts import LOSS_TOLERANCE, PRESSURE_TOLERANCE

__all__ = ["LOSS_TOLERANCE", "PRESSURE_TOLERANCE", "check_expected", "hard_case",
           "hard_case_descriptions", "hard_case_names", "hard_display", "hard_markdown",
           "hard_scene_names", "run_hard", "write_hard"]
