"""The goal table: per sequence with a quantity of interest, how its error fell and how well
the goal estimate judged it (docs/report.md, "Quantities of interest"; docs/theory.md 20.5).

One row per sequence (``KEYS``) whose rows carry a goal: the DOFs at which the quantity's
relative error first reached TARGET (and stayed below 2 TARGET on every later level), the
effectivity's range and the levels with the wrong sign from JUDGED_FROM DOFs on (a level where
the signed error crossed zero is judged by how far its estimate misses instead), and for a
goal-driven sequence the energy-driven one's DOFs to the same target beside its own (the
ratio is what goal-driven refinement saves).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from bench.measure.contact import SOLVED_STATUSES
from bench.sequence.goal import GOAL_STRATEGY
from bench.sequence.rows import KEYS, with_labels

TARGET = 1e-4  # relative error of the quantity the DOF counts are taken at
# DOFs: the effectivity is judged on the levels from here on, and again from twice that (a
# sequence whose contact set settles late: docs/theory.md 20.5)
JUDGED_FROM = 1000
PAIRED = [k for k in KEYS if k != "strategy"]  # a goal-driven sequence's energy-driven twin


def dofs_to(frame: pd.DataFrame, target: float = TARGET) -> float:
    """The DOFs of the first level whose relative error is at most ``target`` and whose later
    levels all stay below 2 ``target`` (a sign change of the error can pass through 0 on the
    way: one lucky level is not reaching it); NaN if none."""
    error = frame["qoi_relative_error"].to_numpy(dtype=float)
    ndofs = frame["ndofs"].to_numpy(dtype=float)
    for k in range(error.size):
        if error[k] <= target and np.all(error[k:] <= 2 * target):
            return float(ndofs[k])
    return math.nan


CROSSING = 0.1  # a level whose error is below this share of both neighbours' crossed zero
MISS = 0.25  # a crossing's estimate may miss its error by this share of the neighbours' errors


def zero_crossings(frame: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Per level: whether its signed error passed through zero between its neighbours (|e|
    below CROSSING times both neighbours' |e|: its effectivity is a ratio of two round-offs of
    the same small number and says nothing), and whether its estimate then misses e by more
    than MISS times the smaller neighbour's |e| (the same test in absolute terms)."""
    error = frame["qoi_error"].abs().to_numpy(dtype=float)
    miss = (frame["qoi_estimate"] - frame["qoi_error"]).abs().to_numpy(dtype=float)
    crossing, missed = np.zeros(error.size, dtype=bool), np.zeros(error.size, dtype=bool)
    if error.size >= 3:
        neighbours = np.minimum(error[:-2], error[2:])
        crossing[1:-1] = error[1:-1] < CROSSING * neighbours
        missed[1:-1] = crossing[1:-1] & (miss[1:-1] > MISS * neighbours)
    return crossing, missed


def effectivity_range(frame: pd.DataFrame, from_dofs: int) -> tuple[float, float, int, int,
                                                                    int]:
    """(min, max) of the effectivity on the levels from ``from_dofs`` DOFs whose contact is
    resolved (status ok), zero crossings left out; their number; how many of them have the
    wrong sign; how many crossings the estimate missed (``zero_crossings``)."""
    crossing, missed = zero_crossings(frame)
    judged = ((frame["ndofs"] >= from_dofs) & (frame["status"] == "ok")
              & frame["qoi_effectivity"].notna()).to_numpy()
    plain = frame[judged & ~crossing]
    missed_crossings = int((judged & missed).sum())
    if not len(plain):
        return math.nan, math.nan, 0, 0, missed_crossings
    return (float(plain["qoi_effectivity"].min()), float(plain["qoi_effectivity"].max()),
            len(plain), int((~plain["qoi_sign_right"].astype(bool)).sum()), missed_crossings)


def interval_columns(frame: pd.DataFrame) -> dict:
    """The guaranteed intervals of a sequence (rows with ``qoi_guaranteed``): how many levels
    have one, how many miss the true value (the gate: none), and the last one's half-width
    relative to the true value."""
    if "qoi_guaranteed" not in frame:
        return {"interval_levels": 0, "interval_misses": 0, "interval_half_width": math.nan}
    held = frame[frame["qoi_guaranteed"].fillna(False).astype(bool)
                 & frame["qoi_true"].notna()]
    if not len(held):
        return {"interval_levels": 0, "interval_misses": 0, "interval_half_width": math.nan}
    last = held.iloc[-1]
    return {"interval_levels": len(held),
            "interval_misses": int((~held["qoi_interval_holds"].astype(bool)).sum()),
            "interval_half_width": float((last["qoi_upper"] - last["qoi_lower"]) / 2
                                         / abs(last["qoi_true"]))}


def sequence_row(frame: pd.DataFrame) -> dict:
    """The goal columns of one sequence's solved levels (sorted by level)."""
    low, high, judged, wrong, missed = effectivity_range(frame, JUDGED_FROM)
    later = effectivity_range(frame, 2 * JUDGED_FROM)
    last = frame.iloc[-1]
    return {"levels": len(frame), "ndofs": int(last["ndofs"]), "qoi": float(last["qoi"]),
            "qoi_relative_error": float(last["qoi_relative_error"]),
            "dofs_to_target": dofs_to(frame), "qoi_effectivity_min": low,
            "qoi_effectivity_max": high, "qoi_judged_levels": judged, "qoi_wrong_sign": wrong,
            "qoi_crossings_missed": missed,
            "qoi_effectivity_min_from_2000": later[0],
            "qoi_effectivity_max_from_2000": later[1],
            "qoi_wrong_sign_from_2000": later[3],
            "qoi_crossings_missed_from_2000": later[4],
            **interval_columns(frame), "t_goal": float(frame["t_goal"].sum())}


def goal_table(table: pd.DataFrame) -> pd.DataFrame:
    """One row per sequence with a goal (empty without any), with ``energy_dofs_to_target``
    and ``dofs_ratio`` (energy-driven over goal-driven DOFs to TARGET) on the goal-driven
    ones."""
    table = with_labels(table)
    if "qoi_relative_error" not in table or not (table["goal"] != "").any():
        return pd.DataFrame()
    solved = table[(table["goal"] != "") & table["status"].isin(SOLVED_STATUSES)
                   & (table["level"] >= 0)]
    rows = [{**dict(zip(KEYS, key, strict=True)), "dim": int(group["dim"].iloc[0]),
             **sequence_row(group.sort_values("level"))}
            for key, group in solved.groupby(KEYS, sort=True, dropna=False)]
    out = pd.DataFrame(rows)
    if out.empty:
        return out
    energy = out[out["strategy"] == "adaptive"].set_index(PAIRED)["dofs_to_target"]
    twin = out.set_index(PAIRED).index.map(lambda k: energy.get(k, math.nan))
    out["energy_dofs_to_target"] = np.where(out["strategy"] == GOAL_STRATEGY, twin, math.nan)
    out["dofs_ratio"] = out["energy_dofs_to_target"] / out["dofs_to_target"]
    return out
