"""Two result folders side by side (``python -m bench diff``): per sequence, the largest
relative difference of the numbers a change must not move (energy, contact force, eta and the
errors) on the levels whose meshes agree, and where the meshes part (an adaptive mesh can
differ after a tie in marking is broken the other way)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bench.matrix.store import ResultsError, read_results
from bench.measure.contact import SOLVED_STATUSES

COMPARED = ("energy", "contact_force", "eta", "eta_0", "energy_error", "pressure_error",
            "effectivity_index")
MESH = ("ndofs", "n_elements")  # a level's mesh is taken to agree when both do
REQUIRED = ("sequence_key", "status", "level")
IDENTITY = ("scene", "formulation", "estimator", "strategy", "order")


def relative_difference(a: pd.Series, b: pd.Series) -> np.ndarray:
    """|a - b| / max(|a|, |b|), 0 where both are 0 or both NaN, inf where one is NaN."""
    a, b = a.to_numpy(float), b.to_numpy(float)
    scale = np.maximum(np.abs(a), np.abs(b))
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(scale > 0, np.abs(a - b) / scale, 0.0)
    out[np.isnan(a) != np.isnan(b)] = np.inf
    out[np.isnan(a) & np.isnan(b)] = 0.0
    return out


def sequence_difference(old: pd.DataFrame, new: pd.DataFrame) -> dict:
    """One sequence's rows before and after: levels compared, the first level whose mesh
    differs, and the largest relative difference before it (and the worst column)."""
    both = old.merge(new, on="level", suffixes=("_old", "_new"))
    same = np.ones(len(both), dtype=bool)
    for column in MESH:
        same &= (both[f"{column}_old"] == both[f"{column}_new"]).to_numpy()
    parted = np.flatnonzero(~same)
    agree = both.iloc[: parted[0]] if parted.size else both
    worst, worst_column = 0.0, ""
    for column in COMPARED:
        if f"{column}_old" not in agree or agree.empty:
            continue
        difference = relative_difference(agree[f"{column}_old"], agree[f"{column}_new"])
        if difference.size and difference.max() > worst:
            worst, worst_column = float(difference.max()), column
    return {"levels": len(both), "same_mesh_levels": len(agree),
            "mesh_differs_from_level": int(both["level"].iloc[parted[0]]) if parted.size else -1,
            "max_relative_difference": worst, "worst_column": worst_column}


def diff_results(old_folder, new_folder) -> pd.DataFrame:
    """``sequence_difference`` for every sequence (matched by ``sequence_key``) in both
    folders' ok rows; sequences in only one folder are listed with ``levels`` 0."""
    tables = []
    for folder in (old_folder, new_folder):
        table = read_results(folder)
        if table is None:
            raise ResultsError(f"results folder {str(folder)!r} has no results")
        missing = [c for c in (*REQUIRED, *IDENTITY, *MESH) if c not in table.columns]
        if missing:
            raise ResultsError(f"results folder {str(folder)!r} is of another schema: no "
                               f"column {', '.join(missing)}; rerun it with this version")
        tables.append(table[table["status"].isin(SOLVED_STATUSES) & (table["level"] >= 0)])
    old, new = tables
    rows = []
    for key in sorted(set(old["sequence_key"]) | set(new["sequence_key"])):
        a, b = old[old["sequence_key"] == key], new[new["sequence_key"] == key]
        first = (a if len(a) else b).iloc[0]
        row = {name: first[name] for name in IDENTITY}
        if len(a) and len(b):
            row.update(sequence_difference(a, b))
        else:
            row.update(levels=0, same_mesh_levels=0, mesh_differs_from_level=-1,
                       max_relative_difference=np.nan,
                       worst_column="only in " + ("old" if len(a) else "new"))
        rows.append(row)
    return pd.DataFrame(rows)
