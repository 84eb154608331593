"""Nitsche's consistency term carried by an element stress tau into the patch data
(docs/theory.md, 13.2, "Balance"; ``estimators.guaranteed.consistency_stress``)."""

from dataclasses import replace

import numpy as np
import pytest

from estimators import get_estimator
from estimators.guaranteed.consistency_stress import consistency_stress
from estimators.guaranteed.equilibrated import equilibrate
from estimators.guaranteed.equilibrated_3d import equilibrate as equilibrate_3d
from formulations import get_formulation, solve
from scenes import get_scene

CASES = [  # scene, refinements, order, theta
    ("paper", 2, 1, 1.0), ("paper", 2, 2, -1.0), ("stick-slip", 2, 1, 1.0),
    ("paper-3d", 0, 1, 1.0),
    pytest.param("hertz-3d", 1, 1, 1.0, marks=pytest.mark.slow)]  # ~30 s


def load_norm(scene, solution) -> float:
    """||rho||: the load that balances what the patch data of u_h leave."""
    if scene.mesh.dim() == 3:
        return float(np.sqrt(equilibrate_3d(scene, solution)[2].squares.sum()))
    return float(np.sqrt(equilibrate(scene, solution)[2].squares.sum()))


@pytest.mark.parametrize("name, refinements, order, theta", CASES)
def test_tau_balances_the_patches_that_nitsches_equation_leaves(name, refinements, order,
                                                                  theta):
    # the patch data of u_h, from the formulation's own solved equation: with tau they
    # balance every hat function, so rho is round-off (~1e-11 of the bound measured); the
    # same solution without its consistency term leaves a rho of 1e-3 .. 0.1 of the bound
    scene = get_scene(name)
    solution = solve(get_formulation("nitsche")(scene, scene.mesh.refined(refinements),
                                                order=order, theta=theta), "active-set")
    eta = get_estimator("equilibrated")(scene, solution).eta
    assert solution.consistency is not None
    assert load_norm(scene, solution) <= 1e-8 * eta
    assert load_norm(scene, replace(solution, consistency=None)) >= 1e-4 * eta


def test_tau_lives_on_the_elements_at_the_contact_boundary_and_is_symmetric():
    scene = get_scene("paper")
    solution = solve(get_formulation("nitsche")(scene, scene.mesh.refined(2)), "active-set")
    tau = consistency_stress(solution)
    assert tau.shape == (2, 2, solution.elasticity.mesh.t.shape[1])
    at_contact = np.zeros(tau.shape[-1], dtype=bool)
    at_contact[solution.trace.element] = True
    assert np.abs(tau[..., ~at_contact]).max() == 0.0  # nothing written there
    assert np.abs(tau[..., at_contact]).max() > 0.0
    np.testing.assert_array_equal(tau, tau.transpose(1, 0, 2))  # C sym(q x n), exactly


def test_the_incomplete_variant_has_no_consistency_term():
    # theta = 0: (12.1) has no theta/gamma term, and its patches balance without tau
    scene = get_scene("paper")
    solution = solve(get_formulation("nitsche")(scene, scene.mesh.refined(2), theta=0.0),
                     "active-set")
    assert solution.consistency is None and consistency_stress(solution) is None
    eta = get_estimator("equilibrated")(scene, solution).eta
    assert load_norm(scene, solution) <= 1e-8 * eta
