"""``point-displacement``: the vertical displacement at the centre of the body (the last
component: the one along the obstacle's push in every built-in scene), averaged with a smooth
bump k = (1 - r^2)^2 / (1, (1 - r^2)^2) of radius 1/16 of the body's smallest extent
(docs/theory.md, 20.1): j(u) = (k e_d, u). A point value is no functional in H^1 (its dual
solution, a Green's function, is not in H^1); the bump's mean is."""

from __future__ import annotations

import numpy as np

from estimators.quantities.base import Quantity, box_rule, register_quantity

RADIUS = 1 / 16  # of the body's smallest extent


def kernel_of(centre: np.ndarray, radius: float):
    """x (d, ...) -> k(x) e_d (d, ...), the bump's density along the last axis."""
    d = centre.size
    norm = np.pi * radius**2 / 3 if d == 2 else 32 * np.pi * radius**3 / 105

    def kernel(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        r2 = sum((x[i] - centre[i]) ** 2 for i in range(d)) / radius**2
        out = np.zeros(x.shape)
        out[d - 1] = np.clip(1 - r2, 0, None) ** 2 / norm
        return out

    return kernel


def bump_rule(centre: np.ndarray, radius: float):
    """A composite Gauss rule on the bump's box: points (d, n), weights (n,)."""
    box = np.column_stack([centre - radius, centre + radius])
    return box_rule(box, panels=24 if centre.size == 2 else 8)


def reference_value(reference, centre: np.ndarray, radius: float, kernel) -> float:
    """j of an overkill reference: its displacement at the bump rule's points."""
    from formulations.cells.evaluation import evaluate_at
    from formulations.elasticity import dof_basis

    x, w = bump_rule(centre, radius)
    basis = dof_basis(reference.mesh, reference.order)
    cells = reference.mesh.element_finder()(*x)
    direction = np.zeros_like(x)
    direction[-1] = 1.0
    values = evaluate_at(basis, x, cells).matrix(direction) @ reference.u
    return float(np.sum(w * kernel(x)[-1] * values))


@register_quantity("point-displacement", "the vertical displacement at the body's centre "
                                         "(a smooth bump's mean)")
def point_displacement(scene) -> Quantity:
    from formulations.cells import family_of

    low, high = scene.mesh.p.min(axis=1), scene.mesh.p.max(axis=1)
    centre, radius = (low + high) / 2, RADIUS * float((high - low).min())
    kernel = kernel_of(centre, radius)

    def evaluate(solution) -> float:
        elasticity = solution.elasticity
        load = family_of(elasticity.mesh).body_load(kernel, elasticity.basis, elasticity.order)
        return float(load @ solution.u)

    exact = None
    if scene.exact is not None:
        x, w = bump_rule(centre, radius)
        exact = float(np.sum(w * kernel(x)[-1] * scene.exact.displacement(x)[-1]))
    return Quantity(name="point-displacement", evaluate=evaluate, exact=exact, kernel=kernel,
                    unit="length",
                    from_reference=lambda ref: reference_value(ref, centre, radius, kernel))
