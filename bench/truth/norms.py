"""||u|| = a(u, u)^(1/2) of a scene's solution, the scale of relative errors: from the exact
solution where the scene has one, else from the overkill reference's summary (truth.json)."""

from __future__ import annotations

import numpy as np
from skfem import Basis

from bench.measure.discretisation_error import energy_density
from formulations.cells import family_of
from scenes import get_scene

# uniform refinements of the scene's mesh for ||u|| of an exact solution, and the order of the
# quadrature rule on them (the highest scikit-fem has on tetrahedra is 8), per dimension
NORM_REFINEMENTS = {2: 5, 3: 2}
NORM_RULE_ORDER = {2: 10, 3: 8}


def exact_energy_norm(scene_name: str) -> float | None:
    """||u|| of a scene's exact solution (None without one), integrated with a rule of order
    NORM_RULE_ORDER on its mesh refined NORM_REFINEMENTS times."""
    try:
        scene = get_scene(scene_name)
    except KeyError:
        return None
    if scene.exact is None:
        return None
    dim = scene.mesh.dim()
    mesh = scene.mesh.refined(NORM_REFINEMENTS[dim])
    basis = Basis(mesh, family_of(mesh).elements[1](), intorder=NORM_RULE_ORDER[dim])
    grad = scene.exact.gradient(np.asarray(basis.global_coordinates()))
    return float(np.sqrt((energy_density(grad, *scene.material.lame) * basis.dx).sum()))


def scene_norm(scene_name: str, truth: dict) -> float | None:
    """||u|| for relative errors: the reference's ``energy_norm`` in ``truth`` (truth.json)
    when errors were measured against a reference, the exact solution's otherwise; None when
    there is no truth."""
    entry = truth.get(scene_name, {})
    if entry.get("kind") == "reference":
        return entry.get("energy_norm")
    return exact_energy_norm(scene_name)
