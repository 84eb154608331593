"""A first comparison report, a pure function of a results table: Markdown + convergence plot.

Rates are least-squares slopes of log(eta) against log(ndofs) over the last levels; in 2D,
O(h^1/2) is slope -1/4 and O(h) is slope -1/2 (DESIGN.md section 4).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

KEYS = ["scene", "formulation", "solver", "estimator", "strategy"]
RATE_LEVELS = 4  # fit the slope over the last 4 levels (pre-asymptotic levels are left out)


def eta_rate(group: pd.DataFrame, levels: int = RATE_LEVELS) -> float:
    ok = group[(group["status"] == "ok") & (group["eta"] > 0)].tail(levels)
    if len(ok) < 2:
        return float("nan")
    return float(np.polyfit(np.log(ok["ndofs"]), np.log(ok["eta"]), 1)[0])


def latest_run(table: pd.DataFrame) -> pd.DataFrame:
    """Keep, per combination, the rows of the most recent run that produced it."""
    last = table.groupby(KEYS)["run_id"].transform("max")
    return table[table["run_id"] == last]


def write_report(table: pd.DataFrame, out: str | Path) -> Path:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    everything = latest_run(table)
    table = everything[everything["level"] >= 0].copy()
    figure, axes = plt.subplots(figsize=(6.5, 4.5))
    lines, summary = [], []
    for key, group in table.groupby(KEYS, sort=True):
        ok = group[group["status"] == "ok"]
        label = "/".join(map(str, key))
        axes.loglog(ok["ndofs"], ok["eta"], "o-" if key[-1] == "adaptive" else "s--",
                    label=label, markersize=3)
        last = group.iloc[-1]
        summary.append({**dict(zip(KEYS, key, strict=True)), "levels": len(group),
                        "ndofs": last["ndofs"], "energy": last["energy"],
                        "contact_force": last["contact_force"], "eta": last["eta"],
                        "eta_0": last["eta_0"], "eta_geometric": last["eta_geometric"],
                        "eta_complementarity": last["eta_complementarity"],
                        "eta_rate": eta_rate(group), "status": last["status"]})
        lines += [f"### {label}", "", group[["level", "ndofs", "energy", "contact_force",
                  "eta", "eta_0", "eta_geometric", "eta_complementarity", "iterations",
                  "t_solve", "status"]].to_markdown(index=False, floatfmt=".5g"), ""]
    n = np.array([1e2, 1e4])
    for slope, style in ((-0.25, ":"), (-0.5, "-.")):
        axes.loglog(n, 30 * (n / n[0]) ** slope, "k" + style, linewidth=0.8,
                    label=f"slope {slope} (O(h^{-2 * slope:g}))")
    axes.set_xlabel("ndofs")
    axes.set_ylabel("eta")
    axes.legend(fontsize=7)
    axes.grid(True, which="both", alpha=0.3)
    figure.tight_layout()
    figure.savefig(out / "convergence.png", dpi=120)
    plt.close(figure)
    head = table.iloc[0]
    text = ["# signorini-bench report", "",
            f"Commit `{head['commit']}`, {head['versions']}, machine: {head['machine']}.", "",
            "## Summary (last level of each combination)", "",
            f"`eta_rate` is the slope of log(eta) against log(ndofs) over the last "
            f"{RATE_LEVELS} levels: -1/4 is O(h^1/2), -1/2 is O(h).", "",
            pd.DataFrame(summary).to_markdown(index=False, floatfmt=".5g"), "",
            "## Convergence", "", "![eta against ndofs](convergence.png)", "",
            "## Levels", "", *lines]
    failures = everything[everything["status"] != "ok"]
    listed = failures[KEYS + ["level", "status", "reason"]]
    text += ["## Failed, inaccurate and skipped rows", "",
             listed.to_markdown(index=False) if len(listed) else "None.", ""]
    path = out / "README.md"
    path.write_text("\n".join(text))
    return path
