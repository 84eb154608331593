"""The one file of expectations, ``expected.toml``: the gate runs, the gates, the claimed
slopes the report compares with, the closed-form comparison and the hard cases' verdicts. A
``[[run]]`` that names no formulations or estimators runs every registered one."""

from __future__ import annotations

import tomllib
from pathlib import Path

from estimators import estimator_names
from formulations import formulation_names

EXPECTED = Path(__file__).with_name("expected.toml")


def load_expected(path: str | Path = EXPECTED) -> dict:
    with open(path, "rb") as handle:
        expected = tomllib.load(handle)
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
