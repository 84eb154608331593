"""The friction figure of a scene with friction: the shear traction along Gamma_C, its bound
and where each point sticks, slips or is separated (docs/theory.md, 17)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from bench.report.figures import colour
from formulations.base import FRICTION_STATES

STATE_COLOURS = {"separated": "0.7", "stick": "tab:blue", "slip": "tab:red"}


def shear_traction(artifacts: dict, reference_curve=None):
    """sigma_t,h and +-bound at the friction points per formulation (adaptive, first
    estimator), the states as a strip below; None without friction."""
    chosen = {}
    for key, data in sorted(artifacts.items()):
        if key[2] == "adaptive" and "friction_shear" in data and key[0] not in chosen:
            chosen[key[0]] = data
    if not chosen:
        return None
    fig = Figure(figsize=(8, 5))
    top, strip = fig.subplots(2, 1, sharex=True, height_ratios=(4, 1))
    for row, (formulation, data) in enumerate(chosen.items()):
        s = np.asarray(data["friction_coordinate"])
        order = np.argsort(s)
        top.plot(s[order], data["friction_shear"][order], color=colour(formulation),
                 linewidth=1, label=f"{formulation} sigma_t,h ({int(data['ndofs'])} DOFs)")
        for sign in (1, -1):
            top.plot(s[order], sign * data["friction_bound"][order], color=colour(formulation),
                     linewidth=0.6, linestyle=":")
        for code, state in enumerate(FRICTION_STATES):
            where = data["friction_state"] == code
            strip.scatter(s[where], np.full(where.sum(), row), s=6,
                          color=STATE_COLOURS[state],
                          label=state if row == 0 else None)
    if reference_curve is not None:
        s, values, label = reference_curve
        top.plot(s, values, "k--", linewidth=1, label=label)
    top.set_ylabel("shear traction sigma_t (dotted: +-bound)")
    top.legend(fontsize=7)
    top.grid(True, alpha=0.3)
    strip.set_yticks(range(len(chosen)), list(chosen))
    strip.set_xlabel("contact coordinate")
    strip.legend(fontsize=7, ncol=3, loc="upper right")
    fig.tight_layout()
    return fig
