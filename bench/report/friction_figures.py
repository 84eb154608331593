"""The friction figures of a scene with friction: the shear traction along Gamma_C, its bound
and where each point sticks, slips or is separated (2D), or a map of the states over Gamma_C
(3D) (docs/theory.md, 17)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from bench.report.figures import colour
from formulations.base import FRICTION_STATES

STATE_COLOURS = {"separated": "0.7", "stick": "tab:blue", "slip": "tab:red"}
ZOOM = 1.4  # the 3D maps show the points in contact and this many times their reach


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


def state_maps(artifacts: dict, zones=None):
    """Where each friction point sticks, slips or is separated over the contact coordinates
    (x, y) per formulation (3D: adaptive, last level, first estimator), marker size growing with
    |sigma_t,h| / bound; ``zones`` (stick radius, contact radius) draws the exact circles.
    None without 3D friction data."""
    chosen = {}
    for key, data in sorted(artifacts.items()):
        if key[2] == "adaptive" and "friction_shear_size" in data:
            chosen.setdefault(key[0], data)
    if not chosen:
        return None
    cols = min(3, len(chosen))
    rows = -(-len(chosen) // cols)
    fig = Figure(figsize=(4 * cols + 1, 4 * rows))
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[len(chosen):]:
        ax.set_axis_off()
    for ax, (formulation, data) in zip(axes, chosen.items(), strict=False):
        x, y = np.asarray(data["friction_coordinate"])
        bound = np.asarray(data["friction_bound"])
        ratio = np.asarray(data["friction_shear_size"]) / np.where(bound > 0, bound, 1.0)
        for code, state in enumerate(FRICTION_STATES):
            where = data["friction_state"] == code
            ax.scatter(x[where], y[where], s=2 + 10 * np.clip(ratio[where], 0, 1),
                       color=STATE_COLOURS[state], label=state)
        for radius in zones or ():
            ax.add_patch(Circle((0.0, 0.0), radius, fill=False, linestyle="--", color="k",
                                linewidth=0.8))
        touching = data["friction_state"] != FRICTION_STATES.index("separated")
        if touching.any():  # a zoom on the points in contact (and the exact zones)
            reach = max(np.hypot(x[touching], y[touching]).max(), *(zones or (0.0,)))
            ax.set_xlim(-ZOOM * reach, ZOOM * reach)
            ax.set_ylim(-ZOOM * reach, ZOOM * reach)
        ax.set_title(f"{formulation}: {int(data['ndofs'])} DOFs", fontsize=9)
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    return fig
