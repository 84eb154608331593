"""Verification gates: run the sequences of ``expected.toml``, compute rates, effectivity and
the closed-form comparison, and check every gate (and the hard cases' verdicts) against it.

``python -m bench verify`` prints the pass/fail table; tests/bench/verify asserts it.
"""

from __future__ import annotations

import fnmatch
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from bench.hard import check_expected, run_hard, write_hard
from bench.matrix import RunConfig, run
from bench.matrix.config_files import run_fields
from bench.matrix.goals import goal_table
from bench.matrix.rates import rates_table
from bench.sequence.rows import KEYS
from bench.verify.closed_form import closed_form_table
from bench.verify.expected import EXPECTED, load_expected
from bench.verify.partial_slip import partial_slip_table
from bench.verify.truth_checks import error_bar_table, truth_table


@dataclass(frozen=True)
class Verdict:
    gate: str
    combination: str
    value: float
    low: float
    high: float
    passed: bool
    source: str
    expected: str = ""  # a verdict gate's expected verdict (instead of a [low, high] band)


def run_gate_matrices(expected: dict, out: str | Path, on_level=None,
                      workers: int = 0) -> pd.DataFrame:
    """The result rows of every ``[[run]]`` of expected.toml (stored together in ``out``);
    ``workers`` > 0 runs each on a local Dask cluster of that many processes."""
    tables = []
    for k, entry in enumerate(expected["run"]):  # run-file keys (bench.matrix.config_files)
        fields = run_fields(entry, f"{EXPECTED.name} [[run]] {k + 1}")
        config = RunConfig(**fields, out=str(out), overwrite=k == 0, workers=workers,
                           command="python -m bench verify")
        tables.append(run(config, on_level=on_level).table)
    return pd.concat(tables, ignore_index=True)


MATCHED = [*KEYS, "dim"]  # a gate's keys that select rows (glob patterns; dim: 2 or 3)


def _matches(row: pd.Series, gate: dict) -> bool:
    return all(fnmatch.fnmatch(str(row[k]), str(gate.get(k, "*"))) for k in MATCHED
               if k in row)


def gate_names(expected: dict, quick: bool = False) -> list[str]:
    """The gates checked: all, or without those marked ``full`` (the reduced run)."""
    return sorted({g["name"] for g in expected["gate"] if not (quick and g.get("full"))})


def gate_passes(row: pd.Series, quantity: str, low: float, high: float) -> bool:
    """A value in [low, high]; a slope with a 95 % interval (``quantity_low``,
    ``quantity_high``: the rates table) passes where its interval meets [low, high], the
    report's reading of the same slope (docs/report.md, "Slopes and their intervals")."""
    value = float(row[quantity])
    if f"{quantity}_low" in row and np.isfinite(row[f"{quantity}_low"]):
        return bool(np.isfinite(value) and row[f"{quantity}_low"] <= high
                    and row[f"{quantity}_high"] >= low)
    return bool(low <= value <= high)


def check_gates(expected: dict, tables: list[pd.DataFrame], quick: bool = False,
                only_present: bool = False) -> list[Verdict]:
    """Every gate against the first of ``tables`` with a column of its quantity
    (``only_present``: only the gates whose quantity one of ``tables`` has)."""
    verdicts = []
    for gate in expected["gate"]:
        if quick and gate.get("full"):
            continue
        if only_present and not any(gate["quantity"] in t.columns for t in tables):
            continue
        low, high = gate.get("min", -np.inf), gate.get("max", np.inf)
        source = gate["source"]
        table = next((t for t in tables if gate["quantity"] in t.columns), tables[0])
        selected = [row for _, row in table.iterrows() if _matches(row, gate)]
        if not selected:
            verdicts.append(Verdict(gate["name"], "(no rows)", np.nan, low, high, False, source))
        for row in selected:
            value = float(row[gate["quantity"]])
            label = row["label"] if "label" in row else "/".join(
                str(row[k]) for k in KEYS if k in row and str(row[k]))
            verdicts.append(Verdict(gate["name"], label, value, low, high,
                                    gate_passes(row, gate["quantity"], low, high), source))
    return verdicts


def hard_verdicts(expected: dict, hard: pd.DataFrame) -> list[Verdict]:
    """The hard cases' verdicts (``bench.hard``) against their [[hard]] entries."""
    out = []
    for check, (_, row) in zip(check_expected(hard, expected.get("hard", [])), hard.iterrows(),
                               strict=True):
        label = "/".join(str(check[k]) for k in ("formulation", "solver", "variant")
                         if str(check[k]) not in ("", "nan"))
        out.append(Verdict(f"hard case {check['case']}", label, float(row.get("loss", np.nan)),
                           np.nan, np.nan, check["passed"],
                           f"got {check['verdict']}; {check['source']}", check["expected"]))
    return out


def verify(out: str | Path = "results-verify", expected_path: str | Path = EXPECTED,
           on_level=None, hard: bool = True, quick: bool = False, workers: int = 0,
           ) -> tuple[list[Verdict], pd.DataFrame, pd.DataFrame]:
    """Every gate; with ``hard`` also the hard cases' verdicts (written to out/hard.csv);
    ``quick``: the reduced truth checks of ``[truth.quick]`` and no ``full`` gates. Returns
    the verdicts, the rates table and the closed-form comparison (``workers``: as in
    ``run_gate_matrices``; the results do not depend on it)."""
    expected = load_expected(expected_path)
    rows = run_gate_matrices(expected, out, on_level, workers)
    rates, goals = rates_table(rows), goal_table(rows)
    closed_form = closed_form_table(expected["closed_form"])
    partial_slip = partial_slip_table(expected["partial_slip"])
    truth = truth_table(expected["truth"], quick)
    bars = error_bar_table(expected["truth"], quick)
    for name, table in (("rates", rates), ("goals", goals), ("closed-form", closed_form),
                        ("partial-slip", partial_slip), ("truth", truth), ("error-bar", bars)):
        table.to_csv(Path(out) / f"{name}.csv", index=False)
    verdicts = check_gates(expected, [rates, goals, closed_form, partial_slip, truth, bars],
                           quick)
    if hard:
        table = run_hard()
        write_hard(table, out)
        verdicts += hard_verdicts(expected, table)
    verdict_frame(verdicts).to_csv(Path(out) / "verdicts.csv", index=False)
    return verdicts, rates, closed_form


def verdict_frame(verdicts: list[Verdict]) -> pd.DataFrame:
    """The verdicts as a table (``verdicts.csv``: what ``bench history`` records)."""
    return pd.DataFrame([{"gate": v.gate, "combination": v.combination, "value": v.value,
                          "low": v.low, "high": v.high, "passed": v.passed}
                         for v in verdicts], columns=["gate", "combination", "value", "low",
                                                      "high", "passed"])


def verdict_table(verdicts: list[Verdict]) -> str:
    frame = pd.DataFrame([{"gate": v.gate, "combination": v.combination,
                           "value": f"{v.value:.4g}",
                           "allowed": v.expected or f"[{v.low:g}, {v.high:g}]",
                           "verdict": "pass" if v.passed else "FAIL"} for v in verdicts])
    return frame.to_markdown(index=False)


def verify_truth(out: str | Path, expected_path: str | Path = EXPECTED, quick: bool = False,
                 ) -> list[Verdict]:
    """The truth's gates alone (the references, their cross-check and the error-bar model of
    ``[truth]``), without the sequences: what ``verify`` adds over ``verify(quick=True)``
    (tables written to ``out``)."""
    expected = load_expected(expected_path)
    truth = truth_table(expected["truth"], quick)
    bars = error_bar_table(expected["truth"], quick)
    for name, table in (("truth", truth), ("error-bar", bars)):
        table.to_csv(Path(out) / f"{name}.csv", index=False)
    return check_gates(expected, [truth, bars], quick, only_present=True)
