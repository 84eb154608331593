"""``equilibrated-local``: the guaranteed bound with Korn constants from the geometry
(docs/theory.md, 13.4, "Local Korn constants")."""

import numpy as np
import pytest
from skfem import MeshTri

from bench.measure.discretisation_error import element_energy_errors
from bench.sequence.loop import LoopConfig, run_sequence
from estimators import get_estimator, guaranteed_estimators
from estimators.guaranteed.jump_equilibration import (
    _least_tau,
    _skew_means,
    _split_load,
    rough_elements,
    sub_triangles,
)
from estimators.guaranteed.rt_reference import ReferenceRT, element_matrices, scalar_values
from estimators.guaranteed.weighted_stress import energy_blocks, stress_weight
from formulations import get_formulation, solve
from formulations.elasticity import ELEMENTS
from scenes import get_scene

LAME = (0.5769, 0.3846)  # E = 1, nu = 0.3


@pytest.mark.parametrize("order", [1, pytest.param(3, marks=pytest.mark.slow)])  # P3: ~12 s
@pytest.mark.parametrize("formulation, options", [("mixed", {}), ("vi", {}),
                                                  ("nitsche", {"theta": 1.0})])
def test_bound_is_above_the_exact_error(formulation, options, order):
    """Against free-boundary's exact error on two meshes, and within 2x of ``equilibrated``
    on the same solution (measured 1.0 .. 1.5: the oscillation's K_T costs most at P3)."""
    scene = get_scene("free-boundary")
    for level in (1, 2):
        sol = solve(get_formulation(formulation)(scene, scene.mesh.refined(level),
                                                 order=order, **options), "active-set")
        estimate = get_estimator("equilibrated-local")(scene, sol)
        error = float(np.sqrt(element_energy_errors(scene, sol).sum()))
        assert estimate.guaranteed and estimate.estimator == "equilibrated-local"
        assert estimate.eta >= error * (1 - 1e-6)  # the exact error's quadrature (~1e-8)
        assert estimate.eta <= 2.0 * get_estimator("equilibrated")(scene, sol).eta


def test_both_bounds_serve_target_error():
    assert guaranteed_estimators() == ["equilibrated", "equilibrated-local"]


def test_the_parts_sum_to_eta_0():
    scene = get_scene("paper")
    rows = [r.row for r in run_sequence(scene, "vi", "active-set", "equilibrated-local",
                                        LoopConfig(strategy="uniform", max_dofs=600))]
    for row in rows:
        parts = (row.eta_symmetric, row.eta_skew, row.eta_oscillation, row.eta_load)
        assert min(parts) >= 0
        assert sum(parts) == pytest.approx(row.eta_0, rel=1e-12)  # one sum, reordered


def _jumping(x):
    return np.array([np.where(x[0] > 0.3, 1.0 + x[1], -x[0]), np.where(x[0] > 0.3, x[1], 2.0)])


@pytest.mark.parametrize("k", [1, 2])
def test_taus_skew_part_has_zero_mean_on_every_rough_element(k):
    """With the mean constraints the divergence still matches r_2 and int_T s(tau) = 0 on
    each rough element (relative 1e-10 of the elements' int |s(tau)|: a direct solve)."""
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    rough = rough_elements(mesh, _jumping, k)
    sub, parent = sub_triangles(mesh, rough, _jumping, k)
    r_2, _ = _split_load(mesh, rough, sub, parent, _jumping, k)
    rt = ReferenceRT.build(sub, k, 2 * k + 2)
    X, W = rt.quadrature
    _, divergence = element_matrices(sub, k, X, W, scalar_values(ELEMENTS[k](), X))
    blocks = energy_blocks(sub, k, X, W, stress_weight(LAME, 3.0))
    means = (_skew_means(sub, rt, parent, rough.size), parent)
    tau, defect = _least_tau(sub, rt, blocks, divergence, r_2, means)
    assert defect < 1e-10
    values = rt.values(tau)
    s = 0.5 * (values[0, 1] - values[1, 0]) * rt.dx
    per_element = np.bincount(parent, s.sum(axis=1), rough.size)
    size = np.bincount(parent, np.abs(s).sum(axis=1), rough.size)
    assert np.abs(per_element).max() <= 1e-10 * size.max()
    assert np.abs(means[0] @ tau.ravel()).max() <= 1e-10 * size.max()  # the same, by M
