"""The one file of expectations, ``expected.toml``: the gate runs, the gates, the claimed
slopes the report compares with, the closed-form comparison and the hard cases' verdicts. A
``[[run]]`` that names no formulations or estimators runs every registered one."""

from __future__ import annotations

import tomllib
from pathlib import Path

from estimators import estimator_names
from formulations import formulation_names

EXPECTED = Path(__file__).with_name("expected.toml")


class ExpectedError(ValueError):
    """The file of expected values cannot be read."""


def load_expected(path: str | Path = EXPECTED) -> dict:
    """The gates, claims and hard verdicts of ``path``; ExpectedError, naming the file and
    what to do, when it is missing or damaged."""
    try:
        with open(path, "rb") as handle:
            expected = tomllib.load(handle)
    except (OSError, ValueError) as error:  # TOMLDecodeError is a ValueError
        raise ExpectedError(f"the expected values {path} cannot be read "
                            f"({type(error).__name__}: {error}); reinstall the package "
                            "(pip install --force-reinstall .) or restore the file") from None
    for run in [*expected.get("run", []), *expected.get("closed_form", []),
                expected.get("partial_slip", {})]:
        # a table that names none runs every registered one (one name or a list)
        if "formulation" not in run:
            run.setdefault("formulations", formulation_names())
        if "estimator" not in run:
            run.setdefault("estimators", estimator_names())
    return expected


def claims(expected: dict | None = None) -> dict[tuple[str, str, int], tuple[float, str]]:
    """(scene, strategy, order) -> (claimed slope of log(error) against log(ndofs), its
    source); a claim without an order is for P1."""
    expected = load_expected() if expected is None else expected
    return {(c["scene"], c["strategy"], int(c.get("order", 1))): (float(c["slope"]),
                                                                   c["source"])
            for c in expected.get("claim", [])}
