"""The report's verdict box (docs/report.md, "The verdict box"): per scene, the sharpest
estimator and how often it under-estimates, the guaranteed estimator's effectivity range with
the combination at each extreme, and the cheapest combinations to a relative energy-norm error
of 1e-2 and 1e-3, with times inside the run's measured timing noise shown as ties."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from bench.matrix.rates import judged_levels
from bench.sequence.rows import KEYS, phase_time
from estimators import guaranteed_estimators
from formulations import STATUS_OK

# relative energy-norm errors the box ranks the combinations to: MAIN_TARGET always, the others
# where some combination of some scene reaches them
RELATIVE_TARGETS = (1e-1, 1e-2, 1e-3)
MAIN_TARGET = 1e-2
EFFECTIVITY_FROM_DOFS = 1000  # coarse levels are pre-asymptotic for every estimator
# the phases a uniform sequence repeats identically for every estimator: their spread is noise
IDENTICAL_WORK = ["t_assemble", "t_solve", "t_refine"]
NOISE_QUANTILE = 0.9  # of the measured spreads: a tie unless the gap beats 9 in 10 of them
LONG_SECONDS = 0.1  # below, a time's noise is start-up costs (absolute), above relative
TIES_SHOWN = 2


def sig3(value: float) -> str:
    """Three significant figures, never an exponent in prose: 2120, 0.000341, 4.4."""
    return np.format_float_positional(float(value), precision=3, unique=False,
                                      fractional=False, trim="-")


def combination(row, estimator: bool = True) -> str:
    """'vi/active-set/residual/adaptive P1' (the cell named unless triangles)."""
    parts = [row["formulation"], row["solver"], *([row["estimator"]] if estimator else []),
             row["strategy"]]
    cell = str(row.get("cell", "tri"))
    return "/".join(map(str, parts)) + f" P{int(row['order'])}" + (
        "" if cell in ("tri", "nan") else f" {cell}")


@dataclass(frozen=True)
class TimingNoise:
    """Run-to-run noise of a cumulative time t, modelled as ``absolute + relative * t``: the
    NOISE_QUANTILE of the spreads of identical work, absolute over the levels shorter than
    LONG_SECONDS (start-up costs dominate there), relative over the longer ones."""

    absolute: float
    relative: float
    samples: int

    def band(self, seconds: float) -> float:
        return self.absolute + self.relative * seconds


def timing_noise(rows: pd.DataFrame) -> TimingNoise | None:
    """Measured from the run itself: at each level, the uniform sequences of one formulation,
    solver, order and cell assemble, solve and refine the same problems whatever their
    estimator, so the spread of their cumulative times of those phases is run-to-run noise.
    None when no level has two such sequences."""
    uniform = rows[(rows["strategy"] == "uniform") & (rows["status"] == STATUS_OK)]
    uniform = uniform.sort_values("level")
    work = uniform[IDENTICAL_WORK].fillna(0.0).sum(axis=1)
    cumulative = work.groupby([uniform[k] for k in KEYS], dropna=False).cumsum()
    same = [uniform[k] for k in KEYS if k != "estimator"] + [uniform["level"]]
    groups = cumulative.groupby(same, dropna=False).agg(["min", "max", "count"])
    groups = groups[groups["count"] > 1]
    if groups.empty:
        return None
    spread = groups["max"] - groups["min"]
    long = groups["min"] >= LONG_SECONDS

    def quantile(values: pd.Series) -> float:
        return float(np.quantile(values, NOISE_QUANTILE)) if len(values) else 0.0

    return TimingNoise(quantile(spread[~long]), quantile(spread[long] / groups["min"][long]),
                       len(groups))


def cheapest(group: pd.DataFrame, norm: float, target: float,
             noise: TimingNoise | None) -> dict:
    """The sequences whose relative error ``energy_error / norm`` first falls to ``target``,
    cheapest first (cumulative wall time of every phase up to that level), and how many of
    them tie with the cheapest (within the measured noise)."""
    usable = measured(group)
    reached = []
    for _, seq in usable.sort_values("level").groupby(KEYS, sort=True, dropna=False):
        seconds = phase_time(seq).cumsum().to_numpy()
        hit = np.flatnonzero(seq["energy_error"].to_numpy() / norm <= target)
        if hit.size:
            first = seq.iloc[hit[0]]
            reached.append({"combination": combination(first), "ndofs": int(first["ndofs"]),
                            "seconds": float(seconds[hit[0]])})
    reached.sort(key=lambda r: r["seconds"])
    ties = 0
    if reached:
        fastest = reached[0]["seconds"]
        limit = fastest + (noise.band(fastest) if noise else 0.0)
        ties = sum(r["seconds"] <= limit for r in reached[1:])
    smallest = usable.loc[usable["energy_error"].idxmin()] if len(usable) else None
    return {"target": target, "ranking": reached, "ties": ties,
            "compared": usable.groupby(KEYS, dropna=False).ngroups,
            "smallest": None if smallest is None else
            (float(smallest["energy_error"] / norm), combination(smallest),
             int(smallest["ndofs"]))}


def measured(group: pd.DataFrame) -> pd.DataFrame:
    """The solved levels with an error measured against a sharp enough truth."""
    return group[(group["status"] == STATUS_OK) & group["energy_error"].gt(0)
                 & ~group["reference_too_coarse"].fillna(False).astype(bool)]


def shown_targets(rows: pd.DataFrame, norms: dict) -> list[float]:
    """MAIN_TARGET, and every other of RELATIVE_TARGETS that some combination reaches."""
    smallest = [measured(group)["energy_error"].min() / norms[scene]
                for scene, group in rows.groupby("scene") if norms.get(scene)]
    best = min(smallest, default=float("inf"))
    return [t for t in RELATIVE_TARGETS if t == MAIN_TARGET or best <= t]


def cheapest_text(best: dict) -> str:
    """'vi/... P1 0.41 s (1180 DOFs), tied with mixed/... 0.43 s; 12 of 16 reach it'."""
    ranking = best["ranking"]
    if not ranking and best["smallest"] is not None:
        error, name, ndofs = best["smallest"]
        return (f"none of {best['compared']} reached it; smallest {sig3(error)} ({name}, "
                f"{ndofs} DOFs)")
    if not ranking:
        return "no error measured against a sharp enough truth"
    top = ranking[0]
    text = f"{top['combination']}: {sig3(top['seconds'])} s ({top['ndofs']} DOFs)"
    if best["ties"]:
        shown = ", ".join(f"{r['combination']} {sig3(r['seconds'])} s"
                          for r in ranking[1:1 + min(best["ties"], TIES_SHOWN)])
        more = best["ties"] - min(best["ties"], TIES_SHOWN)
        text += f", tied with {shown}" + (f" and {more} more" if more else "")
    return text + f"; {len(ranking)} of {best['compared']} reach it"


def late_judged(group: pd.DataFrame) -> pd.DataFrame:
    """The judged levels from EFFECTIVITY_FROM_DOFS DOFs (all judged levels where none is)."""
    judged = judged_levels(group)
    fine = judged[judged["ndofs"] >= EFFECTIVITY_FROM_DOFS]
    return fine if len(fine) else judged


def sharpest_text(group: pd.DataFrame) -> str:
    """The estimator whose effectivity stays closest to 1 (median |log eta/error|), its range,
    and on how many judged levels it fell below the error."""
    judged = late_judged(group)
    if judged.empty:
        return "no truth sharp enough to judge"
    distance = judged.groupby("estimator")["effectivity_index"].agg(
        lambda eff: float(np.median(np.abs(np.log(eff)))))
    name = str(distance.idxmin())
    eff = judged.loc[judged["estimator"] == name, "effectivity_index"]
    below = int((eff < 1).sum())
    return (f"{name}: {sig3(eff.min())}..{sig3(eff.max())}, below the error on {below} of "
            f"{len(eff)} levels ({100 * below / len(eff):.0f} %)")


def guaranteed_text(group: pd.DataFrame) -> str:
    """Each guaranteed estimator's effectivity range with the combination (and DOFs) at each
    end; a range reaching below 1 says so, since the bound then failed."""
    judged = late_judged(group)
    parts = []
    for name in guaranteed_estimators():
        eff = judged[judged["estimator"] == name]
        if eff.empty:
            continue
        low = eff.loc[eff["effectivity_index"].idxmin()]
        high = eff.loc[eff["effectivity_index"].idxmax()]
        parts.append(f"{name}: {sig3(low['effectivity_index'])} ({combination(low, False)}, "
                     f"{int(low['ndofs'])} DOFs) .. {sig3(high['effectivity_index'])} "
                     f"({combination(high, False)}, {int(high['ndofs'])} DOFs)"
                     + (" - BELOW 1: the bound failed" if low["effectivity_index"] < 1 else ""))
    return "; ".join(parts) or "none run"


def verdict_row(scene: str, group: pd.DataFrame, norm: float | None,
                noise: TimingNoise | None, targets=(MAIN_TARGET,)) -> dict:
    """One row of the verdict box."""
    row = {"scene": scene, "sharpest estimator (effectivity, under-estimation)":
           sharpest_text(group),
           f"guaranteed bound from {EFFECTIVITY_FROM_DOFS} DOFs": guaranteed_text(group)}
    for target in targets:
        row[f"cheapest to relative error {sig3(target)}"] = (
            cheapest_text(cheapest(group, norm, target, noise)) if norm
            else "no truth: errors not measured")
    return row


def noise_text(noise: TimingNoise | None) -> str:
    if noise is None:
        return "no timing noise measured (no two uniform sequences share their work): no ties"
    return (f"a time within {sig3(noise.absolute)} s + {sig3(100 * noise.relative)} % of the "
            f"cheapest ties with it (the run's own timing noise: the {NOISE_QUANTILE:.0%} "
            f"quantile of the spread of identical work over {noise.samples} levels)")
