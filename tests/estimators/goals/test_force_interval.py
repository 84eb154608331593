"""The contact force's guaranteed interval: it holds the exact force for every formulation
(free-boundary's closed form), its centre is the discrete force where the formulation's
equation holds with its own pressure (psi_h is a test function of the discrete space), and a
Gamma_C with a clamped node is refused with the reason."""

import numpy as np
import pytest
from skfem import MeshTri

import estimators.quantities as Q
from estimators.base import get_estimator
from estimators.goals.force_interval import force_interval, why_no_interval
from formulations import get_formulation, solve
from scenes import Material, Scene, get_scene

SCENE = get_scene("free-boundary", align_jump=1)
EXACT = Q.get_quantity("contact-force", SCENE).exact


@pytest.fixture(scope="module", params=["mixed", "vi", "penalty", "nitsche"])
def solved(request):
    mesh = SCENE.mesh.refined(2)
    return request.param, solve(get_formulation(request.param)(SCENE, mesh, order=1),
                                "active-set")


def test_the_interval_holds_the_exact_force(solved):
    _, solution = solved
    eta = get_estimator("equilibrated")(SCENE, solution).eta
    interval = force_interval(solution, eta)
    assert interval.lower <= EXACT <= interval.upper
    # the width is eta ||psi||, psi the least-energy unit push of Gamma_C
    assert interval.half_width == pytest.approx(eta * interval.psi_norm, rel=1e-14)


def test_the_centre_is_the_discrete_force_of_the_mixed_and_nodal_methods(solved):
    name, solution = solved
    if name not in ("mixed", "vi"):
        pytest.skip("the penalty's and Nitsche's equations hold with other tractions")
    centre = force_interval(solution, 0.0).centre
    # one linear solve's round-off relative to the force
    assert centre == pytest.approx(solution.contact_force(), rel=1e-9)


def test_a_clamped_node_on_gamma_c_is_refused():
    scene = Scene(name="corner", description="clamped left side meets Gamma_C",
                  mesh=MeshTri.init_symmetric().refined(2),
                  material=Material(1.0, 0.3, "strain"),
                  is_dirichlet=lambda x: np.abs(x[0]) < 1e-10,
                  is_contact=lambda x: np.abs(x[1]) < 1e-10,
                  gap=lambda x: 0.0 * x[0] - 0.01, contact_coordinate=lambda x: x[0])
    solution = solve(get_formulation("vi")(scene, scene.mesh, order=1), "active-set")
    assert "clamped or hanging" in why_no_interval(solution)
    with pytest.raises(ValueError, match="no guaranteed force interval"):
        force_interval(solution, 1.0)
