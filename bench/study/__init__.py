"""The rate study: uniform and adaptive sequences to a million DOFs and beyond, against sharp
references, with the predictions from the scenes' singular exponents (docs/theory.md,
section 10)."""

from bench.study.run import QUICK, StudyConfig, run_study

__all__ = ["QUICK", "StudyConfig", "run_study"]
