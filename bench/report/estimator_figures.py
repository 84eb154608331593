"""The figure that compares estimators across every scene: which is sharp, which is safe."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from estimators import estimator_names

ESTIMATOR_CAPTION = ("Effectivity eta / ||u - u_h|| of every level with a sharp enough truth, "
                     "per estimator, over all scenes, formulations, orders and strategies "
                     "(box: quartiles, whiskers: range). Below the line the estimator "
                     "under-estimates the error.")


def estimator_effectivity(judged: pd.DataFrame) -> Figure | None:
    """Every judged level's effectivity per estimator (one column each, jittered points over
    a box of the quartiles), log scale, with the line eta = error."""
    if judged.empty:
        return None
    names = [n for n in estimator_names() if n in set(judged["estimator"])]
    fig = Figure(figsize=(8, 3.5))
    ax = fig.subplots()
    values = [judged.loc[judged["estimator"] == n, "effectivity_index"].to_numpy()
              for n in names]
    ax.boxplot(values, showfliers=False, whis=(0, 100))
    rng = np.random.default_rng(0)  # fixed jitter: the same picture from the same rows
    for k, v in enumerate(values, start=1):
        ax.plot(k + rng.uniform(-0.2, 0.2, v.size), v, ".", markersize=2, alpha=0.5)
    ax.set_xticks(range(1, len(names) + 1), names)
    ax.axhline(1.0, color="k", linewidth=0.8)
    ax.set_yscale("log")
    ax.set_ylabel("eta / ||u - u_h||")
    ax.grid(True, which="both", axis="y", alpha=0.3)
    fig.tight_layout()
    return fig
