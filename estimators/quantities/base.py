"""Quantities of interest J(u, lambda) = j(u) + (lambda, omega)_{Gamma_C} (docs/theory.md,
20.1): what an engineer asks of a contact solution besides its energy error. A quantity is a
registered unit (``register_quantity``): ``make(scene) -> Quantity``, one module each.

A quantity linear in (u, lambda) gives the dual problem of the goal-oriented estimators
(``estimators.goals``) its data: the load j (a body-force density ``kernel``) and the normal
displacement ``weight`` omega the dual solution takes on the contact set. A quantity that is
not (the contact zone's size) leaves both None and says why in ``why_no_dual``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from scenes.registry import Registry

QUANTITIES = Registry("quantity")
quantity_names = QUANTITIES.names
quantity_descriptions = QUANTITIES.descriptions
DEFAULT_QUANTITY = "contact-force"


def register_quantity(name: str, description: str, applies=None):
    """Register ``make(scene) -> Quantity`` under ``name``; ``applies(scene=...)`` says why a
    scene has no such quantity (optional)."""
    return QUANTITIES.register(name, description, applies)


@dataclass(frozen=True, eq=False)
class Quantity:
    """One quantity of interest on one scene. ``evaluate(solution)``: J(u_h, lambda_h);
    ``exact``: J(u, lambda) where the scene's closed form gives it (None otherwise);
    ``from_reference(reference)``: J of an overkill reference (``bench.truth``), None if it
    cannot be read from one. ``weight(x)`` (x (d, ...) on Gamma_C) and ``kernel(x)`` ((d, ...)
    -> (d, ...)) are omega and the density of j, None where J has no such part."""

    name: str
    evaluate: Callable[[object], float]
    exact: float | None = None
    from_reference: Callable[[object], float | None] | None = None
    weight: Callable[[np.ndarray], np.ndarray] | None = None
    kernel: Callable[[np.ndarray], np.ndarray] | None = None
    why_no_dual: str | None = None
    unit: str = ""
    # a guaranteed interval from a guaranteed energy bound exists (the contact force:
    # estimators.goals.force_interval)
    energy_interval: bool = False

    def true_value(self, truth) -> float | None:
        """J of ``truth`` (``bench.truth``: the exact solution, else its reference)."""
        if truth is None:
            return None
        if truth.kind == "exact":
            return self.exact
        reference = getattr(truth, "reference", None)
        if reference is None or self.from_reference is None:
            return None
        return self.from_reference(reference)


def get_quantity(name: str, scene) -> Quantity:
    """The quantity ``name`` on ``scene``: a KeyError naming the quantities if unknown, a
    ValueError with the reason if the scene has none."""
    make = QUANTITIES.get(name)
    why = QUANTITIES.why_not(name, scene=scene)
    if why:
        raise ValueError(f"goal={name!r} on scene {scene.name!r}: {why}")
    return make(scene)


def weighted_pressure(solution, weight, degree: int | None = None) -> float:
    """(lambda_h, omega)_{Gamma_C} by a rule of the trace's kink degree (lambda_h may break
    inside a facet)."""
    trace = solution.trace
    t, w = trace.rule(trace.kink_degree if degree is None else degree)
    values = solution.pressure(t) * contact_weight(solution, weight, t)
    return float(trace.integrate(values, w).sum())


def contact_weight(solution, weight, t: np.ndarray) -> np.ndarray:
    """omega at local coordinates t of every contact facet (n_facets, nq)."""
    trace = solution.trace
    x = trace.points(np.asarray(t, dtype=float))
    return np.asarray(weight(x.reshape(x.shape[0], -1)), dtype=float).reshape(trace.size, -1)


# the composite rule for integrals of closed-form pressures: 512 panels (128 per axis in 3D) put
# a panel edge on every kink of the quantities' weights (multiples of 1/64 and 3/32 of the
# extent from its centre)
PANELS, PANEL_POINTS = 512, 6


def contact_box(scene) -> np.ndarray:
    """The range of the contact coordinate over Gamma_C: (k, 2) rows (low, high), k = d - 1."""
    facets = scene.contact_facets()
    points = scene.mesh.p[:, np.unique(scene.mesh.facets[:, facets])]
    s = np.atleast_2d(np.asarray(scene.contact_coordinate(points), dtype=float))
    return np.column_stack([s.min(axis=1), s.max(axis=1)])


def box_rule(box: np.ndarray, panels: int = PANELS, points: int = PANEL_POINTS):
    """A composite Gauss rule on the box (k, 2): points (k, n), weights (n,)."""
    g, gw = np.polynomial.legendre.leggauss(points)
    axes, weights = [], []
    for low, high in box:
        edges = np.linspace(low, high, panels + 1)
        half = 0.5 * np.diff(edges)[:, None]
        axes.append(((edges[:-1, None] + edges[1:, None]) / 2 + half * g[None, :]).ravel())
        weights.append((half * gw[None, :]).ravel())
    grids = np.meshgrid(*axes, indexing="ij")
    w = np.prod(np.meshgrid(*weights, indexing="ij"), axis=0)
    return np.array([grid.ravel() for grid in grids]), w.ravel()


def exact_pressure_integral(scene, weight) -> float | None:
    """(p, omega)_{Gamma_C} of the scene's closed-form pressure p (None without one), omega a
    function of the contact coordinate s, on a composite Gauss rule over the coordinates' box:
    the coordinate is arclength (area in 3D) on every built-in scene with an exact solution,
    whose Gamma_C is flat. The pressure is smooth but at the zone's end (C^1 there on
    free-boundary): the rule's relative error is about 1e-9 in 2D (tests)."""
    if scene.exact is None:
        return None
    s, w = coordinate_rule(scene)
    return float(np.sum(w * scene.exact.pressure(s) * weight(s)))


def reference_pressure_integral(reference, scene, weight) -> float:
    """(lambda_ref, omega) of an overkill reference's sampled pressure, on the same rule."""
    s, w = coordinate_rule(scene)
    return float(np.sum(w * reference.pressure(s) * weight(s)))


def coordinate_rule(scene):
    """``box_rule`` on the contact coordinates' box, PANELS per axis of a line and a quarter
    of that per axis of a surface, the points shaped as the scene's contact coordinates ((n,)
    along a line, (k, n) on a surface)."""
    box = contact_box(scene)
    s, w = box_rule(box, PANELS >> 2 * (len(box) - 1))
    return (s.reshape(-1) if len(box) == 1 else s), w


def pressure_quantity(name: str, scene, omega, unit: str = "pressure") -> Quantity:
    """J = (lambda, omega) with omega a function of the contact coordinate s ((...) along a
    line, (k, ...) on a surface): its value on a solution, the exact and the reference's."""
    def weight(x):  # omega at points x of Gamma_C
        return omega(scene.contact_coordinate(x)).reshape(np.shape(x)[1:])

    def along(s):  # omega at the coordinate rule's points
        return omega(s).reshape(np.shape(s)[-1:])

    return Quantity(name=name, evaluate=lambda sol: weighted_pressure(sol, weight),
                    exact=exact_pressure_integral(scene, along), weight=weight, unit=unit,
                    from_reference=lambda ref: reference_pressure_integral(ref, scene, along))
