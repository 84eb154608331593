"""The study's slopes on synthetic sequences with known rates, and the reduced study end to
end."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from bench.study import QUICK, StudyConfig, run_study
from bench.study.analysis import fitted_slope, local_slopes, nearly_half_range, two_term_fit


def synthetic(rates, strategy="uniform", n0=100.0, levels=6):
    """A table of one sequence whose error, eta and pressure error decay like N^rate."""
    ndofs = n0 * 4.0 ** np.arange(levels)
    return pd.DataFrame({
        "scene": "paper", "formulation": "mixed", "solver": "active-set",
        "estimator": "residual", "strategy": strategy, "order": 1, "scene_parameters": "",
        "formulation_options": "", "status": "ok", "level": np.arange(levels), "ndofs": ndofs,
        "energy_error": 2.0 * ndofs ** rates[0], "eta": 5.0 * ndofs ** rates[1],
        "pressure_error": ndofs ** rates[2], "effectivity_index": 2.5,
        "reference_too_coarse": False})


def test_local_slopes_recover_exact_power_laws():
    slopes = local_slopes(synthetic((-0.37, -0.4, -0.25)))
    assert len(slopes) == 5
    assert np.allclose(slopes["error_slope"], -0.37)
    assert np.allclose(slopes["eta_slope"], -0.4)
    assert np.allclose(slopes["pressure_slope"], -0.25)


def test_fitted_slope_and_its_standard_error():
    # exact power law: no spread; with noise of known size the standard error is close to
    # sigma / sqrt(sum (x - mean)^2), the textbook formula
    n = 100.0 * 4.0 ** np.arange(6)
    slope, error = fitted_slope(n, 3.0 * n ** -0.5)
    assert slope == pytest.approx(-0.5) and error == pytest.approx(0.0, abs=1e-12)
    rng = np.random.default_rng(1)
    slopes = [fitted_slope(n, n ** -0.5 * np.exp(rng.normal(0, 0.05, n.size)))[0]
              for _ in range(400)]
    x = np.log(n[-4:])
    assert np.std(slopes) == pytest.approx(0.05 / np.sqrt(((x - x.mean()) ** 2).sum()),
                                           rel=0.15)
    assert np.isnan(fitted_slope(n[:2], n[:2] ** -0.5)[1])  # two points: no spread


def test_nearly_half_range_finds_where_the_local_slope_is_minus_a_quarter():
    table = synthetic((-0.25, -0.25, -0.25))
    late = table["ndofs"] > 3000
    table.loc[late, "energy_error"] = table.loc[late, "energy_error"].iloc[0] * (
        table.loc[late, "ndofs"] / table.loc[late, "ndofs"].iloc[0]) ** -0.37
    found = nearly_half_range(local_slopes(table)).iloc[0]
    assert (found["holds_from"], found["holds_to"]) == (100, 6400)
    assert found["last_local_slope"] == pytest.approx(-0.37)


@pytest.mark.slow  # about a minute: the study end to end on its reduced grid
def test_the_reduced_study_reports_every_sequence(tmp_path):
    config = dataclasses.replace(QUICK, out=str(tmp_path / "s"), report=str(tmp_path / "r"))
    table, report, verdicts = run_study(config)
    assert verdicts == []  # the study's gates judge the full budgets only
    text = report.read_text()
    assert "## Predictions" in text and "0.7461" in text  # the paper scene's corner exponent
    assert not table["reference_too_coarse"].astype(bool).any()
    asymptotic = pd.read_csv(tmp_path / "r" / "asymptotic.csv")
    run = table[table["status"] != "skipped"]  # combinations a registration declares impossible
    assert len(asymptotic) == run.groupby(["formulation", "estimator", "strategy"]).ngroups
    assert (tmp_path / "r" / "figures" / "paper-slopes.png").exists()
    again, _, _ = run_study(config)  # resumable: every sequence reused, the same rows
    assert len(again) == len(table)


def test_two_term_fit_recovers_the_singular_share_and_crossover():
    # e^2 = A/N + B N^-lambda exactly: the share at the last level and the N of equal parts
    # are known in closed form
    A, B, lam = 4.0, 0.02, 0.75
    n = 100.0 * 4.0 ** np.arange(8)
    errors = np.sqrt(A / n + B * n ** -lam)
    share, crossover, slope_there = two_term_fit(n, errors, lam)
    assert share == pytest.approx(B * n[-1] ** -lam / errors[-1] ** 2, rel=1e-8)
    assert crossover == pytest.approx((A / B) ** (1 / (1 - lam)), rel=1e-8)
    assert slope_there == pytest.approx(-(1 + lam) / 4)
    assert np.isnan(two_term_fit(n, n ** -0.5, 1.2)[0])  # lambda >= p: no singular part


@pytest.mark.long
def test_the_full_study_passes_its_gates(tmp_path):
    # about an hour on 2 cores (README, "The rate study"); every [[study_gate]] must pass
    config = dataclasses.replace(StudyConfig(), out=str(tmp_path / "s"),
                                 report=str(tmp_path / "r"))
    _, _, verdicts = run_study(config)
    failed = [f"{v.gate} {v.combination}: {v.value:.4g}" for v in verdicts if not v.passed]
    assert verdicts and not failed, "; ".join(failed)
