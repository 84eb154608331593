"""The mixed method with h/H = 1, 1/2, 1/4: its discrete inf-sup constant and multiplier
oscillation under refinement (docs/theory.md, section 8)."""

from __future__ import annotations

import matplotlib.ticker
import pandas as pd
from matplotlib.figure import Figure

from bench.hard.registry import case_figure, hard_case
from bench.hard.verdicts import solve_both
from bench.measure.slope import fit_slope
from formulations.solvers.registry import FAST_SOLVER
from scenes import get_scene


@hard_case("mixed-h/H", "mixed method with h/H = 1, 1/2, 1/4 on the paper scene: discrete "
                        "inf-sup constant and multiplier oscillation under refinement")
def mixed_ratio() -> list[dict]:
    scene, records = get_scene("paper"), []
    for ratio in (1.0, 0.5, 0.25):
        for level in (2, 3, 4):
            rows, _ = solve_both("mixed-h/H", scene, "mixed", scene.mesh.refined(level),
                                 variant=f"h/H={ratio:g}", level=level, inf_sup=True,
                                 h_over_H=ratio)
            records += rows
    frame = pd.DataFrame(records)
    for ratio in (1.0, 0.5, 0.25):
        part = frame[(frame["variant"] == f"h/H={ratio:g}") & (frame["solver"] == FAST_SOLVER)]
        # h ~ ndofs^(-1/2): the slope of log beta against log h
        slope = -2 * fit_slope(part["ndofs"], part["inf_sup"]).slope
        text = (f"beta_h {part['inf_sup'].iloc[0]:.3g} -> {part['inf_sup'].iloc[-1]:.3g} "
                f"(~ h^{slope:.2f}); oscillation {part['pressure_oscillation'].iloc[-1]:.2f}")
        for record in records:
            if record["variant"] == f"h/H={ratio:g}":
                record["finding"] = text
    return records


def inf_sup_plot(rows: pd.DataFrame, title: str, log_beta: bool = True):
    """beta_h against ndofs per variant of the fast solver's rows (None without any); a linear
    beta axis where some variant's beta_h is 0."""
    fast = rows[rows["solver"] == FAST_SOLVER]
    if fast.empty:
        return None
    fig = Figure(figsize=(5.5, 4))
    ax = fig.subplots()
    for variant, group in fast.groupby("variant", sort=False):
        (ax.loglog if log_beta else ax.semilogx)(group["ndofs"], group["inf_sup"], marker="o",
                                                 label=variant)
    ax.set(xlabel="ndofs", title=title)
    if log_beta:
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    else:
        ax.set(ylabel="beta_h", ylim=(-0.05, None))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


@case_figure("mixed-h/H", "The mixed method's discrete inf-sup constant beta_h against ndofs for "
                          "h/H = 1, 1/2, 1/4: bounded below only for h/H <= 1/2.")
def inf_sup_figure(rows: pd.DataFrame):
    return inf_sup_plot(rows, "mixed: discrete inf-sup constant beta_h")
