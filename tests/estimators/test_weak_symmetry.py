"""Weak symmetry of the equilibrated stress (estimators.weak_symmetry)."""

import numpy as np
import pytest
from skfem.assembly import Dofs

from estimators.equilibrated import equilibrate
from estimators.patch_data import SCALARS
from estimators.symmetrisation import curl_values
from estimators.weak_symmetry import constraint_matrix, skew_moments, weakly_symmetrised
from formulations import get_formulation, solve
from scenes import get_scene


@pytest.mark.parametrize("k", [1, 2])
def test_the_constraint_matrix_is_the_skew_moment_of_the_curl(k):
    """B phi against (s(curl phi), psi_z) computed from curl phi's values: two assembly
    paths, one operator (round-off)."""
    scene = get_scene("paper")
    solution = solve(get_formulation("vi")(scene, scene.mesh.refined(1), order=k),
                     "active-set")
    rt = equilibrate(scene, solution)[0].basis
    n = Dofs(rt.mesh, SCALARS[k + 1]()).N
    phi = np.random.default_rng(k).standard_normal((2, n))
    direct = skew_moments(rt, curl_values(rt, phi))
    assert np.abs(constraint_matrix(rt) @ phi.ravel() - direct).max() <= (
        1e-12 * np.abs(direct).max())


@pytest.mark.parametrize("scene_name, k", [("paper", 1), ("hertz", 2), ("free-boundary", 3)])
def test_the_skew_part_is_orthogonal_to_every_hat_and_the_tractions_stay(scene_name, k):
    """After the constrained correction: (s(sigma), psi_z) = 0 for every vertex (relative
    1e-10: one sparse factorisation's round-off), and the RT DOFs on the facets where sigma n
    is prescribed are those of the equilibrated stress (curl phi's normal trace vanishes
    there)."""
    scene = get_scene(scene_name)
    solution = solve(get_formulation("mixed")(scene, scene.mesh.refined(2), order=k),
                     "active-set")
    captured = {}

    def weak(rec, interior, prescribed, lame):
        captured.update(before=rec, prescribed=prescribed)
        out, captured["defect"] = weakly_symmetrised(rec, interior, prescribed, lame, 1.0)
        return out

    after = equilibrate(scene, solution, weak)[0]
    before = captured["before"]
    moments = skew_moments(after.basis, after.values)
    scale = np.abs(skew_moments(before.basis, before.values)).max()
    assert np.abs(moments).max() <= 1e-10 * scale
    assert captured["defect"] <= 1e-10
    facet_dofs = Dofs(after.basis.mesh, after.basis.elem).get_facet_dofs(
        captured["prescribed"]).all()
    change = after.dofs[:, facet_dofs] - before.dofs[:, facet_dofs]
    assert np.abs(change).max() <= 1e-9 * np.abs(before.dofs).max()  # round-off
