"""The rate study's numbers (docs/theory.md, section 10): local slopes between consecutive
levels, fitted asymptotic slopes with their standard errors, the predictions from the scenes'
singular exponents, and where the seed paper's "nearly O(h^1/2)" holds.

Slopes are of log(y) against log(N): -1/4 is O(h^1/2), -1/2 is O(h).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from bench.measure.slope import fit_slope
from bench.sequence.rows import KEYS, with_labels
from formulations import STATUS_OK
from scenes import get_scene
from scenes.corners import predicted_rate, singularities

FIT_LEVELS = 4  # the asymptotic slope: least squares over the last levels
QUANTITIES = {"error": "energy_error", "eta": "eta", "pressure": "pressure_error"}
NEARLY = 0.05  # "nearly O(h^1/2)": a local error slope within this of -1/4
EFFECTIVITY_FROM = 1000  # effectivity statistics from this many DOFs (coarser: no contact yet)
# the columns that tell the sequences apart in the tables
SHOWN = ["scene", "formulation", "formulation_options", "estimator", "strategy", "order", "cell"]


def _ok(table: pd.DataFrame) -> pd.DataFrame:
    return with_labels(table[(table["status"] == STATUS_OK) & (table["level"] >= 0)])


def local_slopes(table: pd.DataFrame) -> pd.DataFrame:
    """One row per pair of consecutive levels of every sequence: the slopes between them."""
    rows = []
    for key, group in _ok(table).groupby(KEYS, sort=True, dropna=False):
        group = group.sort_values("ndofs")
        for (_, a), (_, b) in zip(group.iloc[:-1].iterrows(), group.iloc[1:].iterrows(),
                                  strict=True):
            row = {**dict(zip(KEYS, key, strict=True)), "ndofs_from": int(a["ndofs"]),
                   "ndofs_to": int(b["ndofs"])}
            step = np.log(b["ndofs"]) - np.log(a["ndofs"])
            for name, column in QUANTITIES.items():
                ok = a[column] > 0 and b[column] > 0
                row[f"{name}_slope"] = (np.log(b[column] / a[column]) / step if ok
                                        else float("nan"))
            rows.append(row)
    return pd.DataFrame(rows)


def fitted_slope(ndofs, values, levels: int = FIT_LEVELS) -> tuple[float, float]:
    """The least-squares slope over the last ``levels`` positive values and its standard error
    (NaN with fewer than 3 points: a line through two points has no spread)."""
    ndofs, values = np.asarray(ndofs, float), np.asarray(values, float)
    keep = values > 0
    fit = fit_slope(ndofs[keep][-levels:], values[keep][-levels:])  # the suite's one fit
    return fit.slope, fit.stderr if np.isfinite(fit.stderr) else float("nan")


def predictions(scenes, orders=(1,)) -> pd.DataFrame:
    """Per scene and order: its smallest singular exponent, where, and the predicted slopes
    (h is N^(-1/d) in d dimensions)."""
    rows = []
    for name in scenes:
        scene = get_scene(name)
        found = singularities(scene)
        for order in orders:
            rows.append({"scene": name, "order": order, "exponent": found[0].exponent,
                         "where": found[0].where,
                         "predicted_uniform": predicted_rate([s.exponent for s in found],
                                                             order, scene.dim),
                         "predicted_adaptive": -order / scene.dim})
    return pd.DataFrame(rows)


def asymptotic_table(table: pd.DataFrame, levels: int = FIT_LEVELS) -> pd.DataFrame:
    """Per sequence: the fitted slopes (and standard errors) of error, eta and pressure error
    over the last levels, the prediction beside them, and the effectivity on every level."""
    ok = _ok(table)
    scenes, orders = sorted(ok["scene"].unique()), sorted(ok["order"].unique())
    predicted = predictions(scenes, orders).set_index(["scene", "order"])
    rows = []
    for key, group in ok.groupby(KEYS, sort=True, dropna=False):
        group = group.sort_values("ndofs")
        row = {**dict(zip(KEYS, key, strict=True)), "levels": len(group),
               "ndofs_first": int(group["ndofs"].iloc[0]),
               "ndofs_last": int(group["ndofs"].iloc[-1])}
        for name, column in QUANTITIES.items():
            row[f"{name}_slope"], row[f"{name}_slope_se"] = fitted_slope(
                group["ndofs"], group[column], levels)
        expected = predicted.loc[(row["scene"], row["order"])]
        row["predicted"] = float(expected[f"predicted_{row['strategy']}"])
        if row["strategy"] == "uniform":
            row["singular_share"], row["crossover_ndofs"], _ = two_term_fit(
                group["ndofs"], group["energy_error"], float(expected["exponent"]),
                int(row["order"]))
        effectivity = group.loc[group["ndofs"] >= EFFECTIVITY_FROM, "effectivity_index"]
        row.update(effectivity_min=float(effectivity.min()),
                   effectivity_max=float(effectivity.max()),
                   too_coarse_rows=int(group["reference_too_coarse"].astype(bool).sum()))
        rows.append(row)
    return pd.DataFrame(rows)


def two_term_fit(ndofs, errors, exponent: float, order: int = 1,
                 levels: int = FIT_LEVELS) -> tuple[float, float, float]:
    """Fit e^2 = A N^-p + B N^-lambda (the smooth part and the singular part of the squared
    error under uniform refinement, lambda < p) to the last ``levels`` errors by linear least
    squares. Returns the singular part's share B N^-lambda / e^2 at the last level, the N at
    which both parts are equal, (A / B)^(1 / (p - lambda)), and the local slope the model
    predicts there. NaN when the fit has no positive B or too few levels."""
    n, e = np.asarray(ndofs, float)[-levels:], np.asarray(errors, float)[-levels:]
    if n.size < 3 or not exponent < order:
        return float("nan"), float("nan"), float("nan")
    basis = np.column_stack([n ** -float(order), n ** -exponent]) / e[:, None] ** 2
    (A, B), *_ = np.linalg.lstsq(basis, np.ones(n.size), rcond=None)  # relative residuals
    if not (A > 0 and B > 0):
        return float("nan"), float("nan"), float("nan")
    share = B * n[-1] ** -exponent / (A * n[-1] ** -float(order) + B * n[-1] ** -exponent)
    crossover = (A / B) ** (1.0 / (order - exponent))
    return float(share), float(crossover), float(-(order + exponent) / 4.0)


def nearly_half_range(slopes: pd.DataFrame, target: float = -0.25) -> pd.DataFrame:
    """Per uniform sequence: the DOF range over which the local error slopes are within NEARLY
    of ``target`` (-1/4: "nearly O(h^1/2)"), the range of the local slopes and the last one."""
    rows = []
    uniform = slopes[slopes["strategy"] == "uniform"]
    for key, group in uniform.groupby(SHOWN, sort=True):
        inside = (group["error_slope"] - target).abs() <= NEARLY
        rows.append({**dict(zip(SHOWN, key, strict=True)),
                     "holds_from": int(group.loc[inside, "ndofs_from"].min()) if inside.any()
                     else None,
                     "holds_to": int(group.loc[inside, "ndofs_to"].max()) if inside.any()
                     else None,
                     "local_slope_min": float(group["error_slope"].min()),
                     "local_slope_max": float(group["error_slope"].max()),
                     "last_local_slope": float(group["error_slope"].iloc[-1]),
                     "last_pair": f"{group['ndofs_from'].iloc[-1]}-{group['ndofs_to'].iloc[-1]}"})
    return pd.DataFrame(rows)
