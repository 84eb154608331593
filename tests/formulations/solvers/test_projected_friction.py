"""Friction on the iterative back-end (formulations.solvers.projected_friction): the same
answer as the condensed route on a factorisation, for every formulation, Tresca and Coulomb,
2D and 3D, found by the plain iteration (no safeguard) and without forming C K^-1 C'."""

import numpy as np
import pytest

from conftest import energy_difference
from formulations import get_formulation
from formulations.discretisation import solve
from formulations.solvers import backends
from formulations.solvers.projected_friction import FrictionSets, next_sets
from scenes import get_scene

pytestmark = pytest.mark.skipif("amg" not in backends.available_backends(),
                                reason="pyamg is not installed")
DIRECT = "pardiso" if "pardiso" in backends.available_backends() else "splu"
# what the back-end promises for frictionless contact (tests/formulations/solvers/test_amg.py):
# CG to a relative residual of 1e-10, slip directions settled to 1e-10; measured 8e-12 .. 1.6e-10
ENERGY_AGREEMENT = 1e-8


@pytest.mark.parametrize("scene,parameters,refine,order,formulation", [
    ("stick-slip", {}, 3, 1, "vi"), ("stick-slip", {}, 3, 1, "mixed"),
    ("stick-slip", {}, 2, 2, "vi"),  # a node with |lambda_t| = b and no slip (both laws hold)
    ("stick-slip", {}, 2, 2, "penalty"),
    ("paper", {"friction": "coulomb", "mu": 0.3}, 2, 1, "nitsche"),
    ("stick-slip-3d", {}, 1, 1, "vi"), ("stick-slip-3d", {}, 1, 1, "nitsche"),
    ("stick-slip-3d", {}, 1, 1, "mixed"),  # patches out of contact that stick
    ("paper-3d", {"friction": "coulomb", "mu": 0.3}, 1, 1, "vi")])
def test_the_frictional_solve_agrees_with_the_condensed_one(scene, parameters, refine, order,
                                                           formulation):
    scene = get_scene(scene, **parameters)
    discretisation = get_formulation(formulation)(scene, scene.mesh.refined(refine),
                                                  order=order)
    direct = solve(discretisation, "active-set", backend=DIRECT)
    iterative = solve(discretisation, "active-set", backend="amg")
    assert iterative.status == direct.status == "ok", iterative.reason
    assert iterative.diagnostics.safeguard == ""  # the plain iteration found it
    assert iterative.backend == "amg"
    assert iterative.diagnostics.krylov_iterations
    assert energy_difference(discretisation, iterative, direct) < ENERGY_AGREEMENT


def test_a_slipping_node_whose_slip_reverses_sticks_first():
    """One node, bound 1, slipping along +e1 with the force at its bound: a slip of -1e-3
    along e1 (it reverses) sends it to stick, not to slip along -e1 (the small coupling c
    that keeps the 3D iteration from flipping directions), and the normal row stays."""
    from scipy import sparse

    from formulations.base import ContactQP, FrictionRows

    T = sparse.csr_matrix(np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
    qp = ContactQP(K=sparse.identity(3, format="csr"), F=np.zeros(3),
                   B=sparse.csr_matrix(np.array([[1.0, 0.0, 0.0]])), G=np.zeros(1),
                   row_scale=np.ones(1), objective_scale=1.0,
                   friction=FrictionRows(T=T, bound=np.ones(1), block=2))
    sets = FrictionSets(np.ones(1, dtype=bool), np.zeros(1, dtype=bool),
                        np.array([[1.0, 0.0]]))
    u = np.array([0.0, -1e-3, 0.0])
    new, changed, _ = next_sets(qp, sets, u, np.ones(1), np.array([1.0, 0.0]),
                                np.full(1, 1e-2))
    assert new.stick.all() and new.normal.all() and changed == 1
