"""Verification gates: run small sequences, compute rates, effectivity and the Hertz comparison,
and check them against ``bench/expected.toml`` (one place for every expected value).

``python -m bench verify`` prints the pass/fail table; ``tests/bench/test_gates.py`` asserts it.
"""

from __future__ import annotations

import fnmatch
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from bench.errors import contact_zone
from bench.hard import run_hard
from bench.hard_verdicts import check_expected, write_hard
from bench.loop import LoopConfig, run_sequence
from bench.matrix import run_matrix
from bench.rates import KEYS, rates_table
from bench.store import ResultStore
from scenes import get_scene
from scenes.hertz import hertz_prediction

EXPECTED = Path(__file__).with_name("expected.toml")


def load_expected(path: str | Path = EXPECTED) -> dict:
    with open(path, "rb") as handle:
        return tomllib.load(handle)


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


def run_gate_matrices(expected: dict, out: str | Path, on_level=None) -> pd.DataFrame:
    """The result rows of every scene's gate run (stored in ``out``)."""
    store = ResultStore(out, overwrite=True)
    for run in expected["run"]:
        run_matrix([run["scene"]], run["formulations"], [run["solver"]], run["estimators"],
                   run["strategies"], store, LoopConfig(max_dofs=run["max_dofs"]),
                   on_level=on_level, reference_dofs=run.get("reference_dofs"))
    return store.run_table()


def hertz_table(expected: dict) -> pd.DataFrame:
    """Computed against closed-form Hertz half-width and peak pressure per formulation."""
    run = expected["hertz"]
    scene = get_scene("hertz")
    rows = []
    for formulation in run["formulations"]:
        *_, result = run_sequence(scene, formulation, run["solver"], "residual",
                                  LoopConfig(strategy="adaptive", max_dofs=run["max_dofs"]))
        sol = result.solution
        force = sol.contact_force()
        hertz = hertz_prediction(scene, force)
        start, end = contact_zone(sol)
        s = np.linspace(-4 * hertz["half_width"], 4 * hertz["half_width"], 8001)
        rows.append({"formulation": formulation, "ndofs": result.row.ndofs,
                     "contact_force": force, "half_width": 0.5 * (end - start),
                     "hertz_half_width": hertz["half_width"],
                     "peak_pressure": float(sol.pressure_at(s).max()),
                     "hertz_peak_pressure": hertz["peak_pressure"], "e_star": hertz["e_star"]})
    table = pd.DataFrame(rows)
    table["half_width_error"] = table["half_width"] / table["hertz_half_width"] - 1
    table["peak_pressure_error"] = table["peak_pressure"] / table["hertz_peak_pressure"] - 1
    return table


def _matches(row: pd.Series, gate: dict) -> bool:
    return all(fnmatch.fnmatch(str(row[k]), str(gate.get(k, "*"))) for k in KEYS if k in row)


def judge(expected: dict, rates: pd.DataFrame, hertz: pd.DataFrame) -> list[Verdict]:
    verdicts = []
    for gate in expected["gate"]:
        low, high = gate.get("min", -np.inf), gate.get("max", np.inf)
        source = gate["source"]
        table = hertz if gate["quantity"] in hertz.columns else rates
        selected = [row for _, row in table.iterrows() if _matches(row, gate)]
        if not selected:
            verdicts.append(Verdict(gate["name"], "(no rows)", np.nan, low, high, False, source))
        for row in selected:
            value = float(row[gate["quantity"]])
            label = "/".join(str(row[k]) for k in KEYS if k in row)
            verdicts.append(Verdict(gate["name"], label, value, low, high,
                                    bool(low <= value <= high), source))
    return verdicts


def hard_verdicts(expected: dict, hard: pd.DataFrame) -> list[Verdict]:
    """The hard cases' verdicts (bench.hard) against their [[hard]] entries."""
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
           on_level=None, hard: bool = True) -> tuple[list[Verdict], pd.DataFrame, pd.DataFrame]:
    """Every gate; with ``hard`` also the hard cases' verdicts (written to out/hard.csv)."""
    expected = load_expected(expected_path)
    rows = run_gate_matrices(expected, out, on_level)
    rates = rates_table(rows)
    hertz = hertz_table(expected)
    rates.to_csv(Path(out) / "rates.csv", index=False)
    hertz.to_csv(Path(out) / "hertz.csv", index=False)
    verdicts = judge(expected, rates, hertz)
    if hard:
        table = run_hard()
        write_hard(table, out)
        verdicts += hard_verdicts(expected, table)
    return verdicts, rates, hertz


def verdict_table(verdicts: list[Verdict]) -> str:
    frame = pd.DataFrame([{"gate": v.gate, "combination": v.combination,
                           "value": f"{v.value:.4g}",
                           "allowed": v.expected or f"[{v.low:g}, {v.high:g}]",
                           "verdict": "pass" if v.passed else "FAIL"} for v in verdicts])
    return frame.to_markdown(index=False)
