"""Overkill references on tetrahedra: recipes, the error bar against an exact error, the cache
and the pressure between samples."""

import numpy as np
import pytest
from skfem import Basis, MeshTet

from bench.measure.discretisation_error import energy_density, exact_errors
from bench.truth import cache
from bench.truth.crosscheck import cross_check
from bench.truth.references import recipes_for
from formulations import get_formulation, solve
from formulations.elasticity import vector_element
from scenes import get_scene

BUDGET = 45000  # measured: the rate fit leaves its clipping floor from here (30 912 DOFs)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path_factory.mktemp("cache")))
        scene = get_scene("free-boundary-3d")
        yield scene, cache.load_or_build(scene, BUDGET)


def test_tetrahedral_scenes_get_p2_recipes():
    assert recipes_for(get_scene("paper-3d")) == ("vi-p2", "nitsche-p2")
    assert recipes_for(get_scene("paper")) == ("mixed-p3", "mixed-p2")


@pytest.mark.slow  # the 45 000-DOF reference: about 40 s to build, once per module
def test_the_error_bar_is_of_the_size_of_the_true_error(reference):
    scene, ref = reference
    assert isinstance(ref.mesh, MeshTet) and ref.recipe == "vi-p2" and ref.order == 2
    basis = Basis(ref.mesh, vector_element(2, 3), intorder=8)
    diff = scene.exact.gradient(np.asarray(basis.global_coordinates())) - \
        basis.interpolate(ref.u).grad
    true_error = np.sqrt((energy_density(diff, *ref.lame) * basis.dx).sum())
    # the 2D standard (tests/bench/measure): a model, right within a factor 2; measured 0.62
    # here, 0.71 at 46 122 DOFs (at 18 624 DOFs the fitted rate sits on its floor 1/4 and the
    # bar is 2.2 x the true error: safe, but outside the band)
    assert 0.5 < ref.estimated_error / true_error < 2.0, (ref.estimated_error, true_error)


@pytest.mark.slow  # the 45 000-DOF reference: about 40 s to build, once per module
def test_a_cached_reference_loads_as_it_was_built(reference):
    scene, ref = reference
    again = cache.load_or_build(scene, BUDGET)
    assert isinstance(again.mesh, MeshTet) and np.array_equal(again.u, ref.u)
    assert again.pressure_s.shape == ref.pressure_s.shape and again.zone == ref.zone


@pytest.mark.slow  # the 45 000-DOF reference: about 40 s to build, once per module
def test_reference_errors_agree_with_exact_errors(reference):
    scene, ref = reference
    sol = solve(get_formulation("vi")(scene, scene.mesh.refined(1)), "active-set")
    exact, measured = exact_errors(scene, sol), ref.errors(sol)
    # the triangle inequality bounds the energy difference by the reference's own error
    # (estimated; a factor 2 for the model, as above)
    assert abs(measured.energy_error - exact.energy_error) <= 2 * ref.estimated_error
    # the pressure, within a factor 2: the reference's own pressure error is not negligible
    # at this budget (measured 1.44e-3 exact against 1.48e-3 via the reference here, and
    # 4.1e-4 against 5.4e-4 at refined(2))
    assert measured.pressure_error == pytest.approx(exact.pressure_error, rel=1.0)


@pytest.mark.slow  # the 45 000-DOF reference: about 40 s to build, once per module
def test_the_pressure_is_interpolated_over_the_contact_plane(reference):
    scene, ref = reference
    x = np.array([[0.0, 0.1, 0.3, 0.9], [0.0, 0.2, 0.1, 0.0]])
    values = ref.pressure(x)
    exact = scene.exact.pressure(x)
    # inside the zone (r < 0.4) within 15 % of the exact peak: -sigma_nn of a 3e4-DOF
    # adaptive P2 solution, measured 12 % high at the centre, 0.04 % and 6 % of the local
    # value at the other two points; outside the zone exactly 0 (lambda_h is 0 there)
    assert np.abs(values - exact).max() < 0.15 * exact.max()
    assert values[-1] == 0.0


@pytest.mark.slow  # builds a second 45 000-DOF P2 reference (Nitsche's): about 20 s
def test_the_two_recipes_differ_by_no_more_than_their_own_errors(reference):
    scene, ref = reference
    other = cache.load_or_build(scene, BUDGET, recipes_for(scene)[1])
    check = cross_check(ref, other)
    # ||u_1 - u_2|| <= e_1 + e_2 (triangle inequality), each estimate within a factor 2 of
    # its true error (test above), hence the factor 2
    assert check.energy_norm_difference * ref.norm <= \
        2 * (ref.estimated_error + other.estimated_error)
    assert check.recipe == "nitsche-p2" and not check.passed  # 1e-7 in energy: P3's standard
