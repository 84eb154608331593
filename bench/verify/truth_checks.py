"""The truth's own gates (docs/theory.md, section 6.3): how sharp each reference says it is,
whether two independent recipes agree, and whether the error-bar model tells the truth where it
can be checked, on a scene with an exact solution, in every order.

``[truth]`` of expected.toml says which scenes, budgets and orders; its ``quick`` table is the
reduced version the default tests run (the cross-check's gates are then left out).
"""

from __future__ import annotations

import pandas as pd

from bench.measure.discretisation_error import exact_errors
from bench.truth import truth_for
from bench.truth.error_bar import error_bar
from bench.truth.references import Recipe, reference_levels
from scenes import get_scene


def settings(section: dict, quick: bool) -> dict:
    """The ``[truth]`` settings, overridden by its ``quick`` table when ``quick``."""
    merged = {k: v for k, v in section.items() if k != "quick"}
    if quick:
        merged.update(section.get("quick", {}))
    return merged


def truth_table(section: dict, quick: bool = False) -> pd.DataFrame:
    """One row per reference scene: its size, relative error bar and (with ``crosscheck``)
    the agreement with the second recipe."""
    config = settings(section, quick)
    rows = []
    for name in config["scenes"]:
        truth = truth_for(get_scene(name), config["reference_dofs"],
                          crosscheck=config.get("crosscheck", False))
        ref = truth.reference
        row = {"scene": name, "label": f"{name}/{ref.recipe}/{ref.ndofs}", "ndofs": ref.ndofs,
               "relative_estimated_error": ref.estimated_error / ref.norm,
               "build_seconds": ref.build_seconds}
        if truth.crosscheck is not None:
            check = truth.crosscheck
            row.update(crosscheck=check.recipe, crosscheck_ndofs=check.ndofs,
                       energy_difference=check.energy_difference,
                       force_difference=check.force_difference,
                       energy_norm_difference=check.energy_norm_difference)
        rows.append(row)
    return pd.DataFrame(rows)


def error_bar_table(section: dict, quick: bool = False) -> pd.DataFrame:
    """Estimated against true error on every level of at least ``min_dofs`` DOFs of the
    reference recipe run on a scene with an exact solution, in each order."""
    config = section["error_bar"]
    max_dofs = settings(section, quick).get("error_bar_max_dofs", config["max_dofs"])
    scene = get_scene(config["scene"])
    rows = []
    for order in config["orders"]:
        ndofs, differences = [], []
        recipe = Recipe(f"mixed-p{order}", "mixed", order)
        for row, sol, difference in reference_levels(scene, max_dofs, recipe):
            n = row.ndofs
            ndofs.append(n)
            if difference is None:
                continue
            differences.append(difference)
            if n < config["min_dofs"]:
                continue
            bar = error_bar(ndofs, differences)
            true = exact_errors(scene, sol).energy_error
            rows.append({"scene": scene.name, "order": order, "ndofs": n,
                         "label": f"{scene.name}/P{order}/{n}", "estimated_error":
                         bar.estimated_error, "true_error": true,
                         "error_bar_ratio": bar.estimated_error / true, "fitted_rate": bar.rate})
    return pd.DataFrame(rows)
