"""The guaranteed bound with Tresca friction (docs/theory.md, 17.5): above stick-slip's exact
error for every formulation that models friction, its shear traction balanced, Coulomb
refused."""

import numpy as np
import pytest

from bench.measure.discretisation_error import element_energy_errors
from estimators import get_estimator
from estimators.base import ESTIMATORS
from estimators.guaranteed.constants import domain_constants
from estimators.guaranteed.equilibrated import equilibrate
from formulations import get_formulation, solve
from formulations.registry import FORMULATIONS
from scenes import get_scene

FRICTIONAL = [name for name in FORMULATIONS.names() if FORMULATIONS.meta(name, "friction")]


@pytest.mark.parametrize("order, level", [
    (1, 1),
    *(pytest.param(order, level, marks=pytest.mark.slow)  # P2, P3 patch problems: ~2-15 s
      for order, level in [(2, 1), (3, 1), (1, 2), (2, 2), (3, 2)])])
@pytest.mark.parametrize("formulation", FRICTIONAL)
def test_the_bound_is_above_the_exact_error_with_tresca_friction(formulation, order, level):
    scene = get_scene("stick-slip")
    solution = solve(get_formulation(formulation)(scene, scene.mesh.refined(level),
                                                  order=order), "active-set")
    estimate = get_estimator("equilibrated")(scene, solution)
    error = float(np.sqrt(element_energy_errors(scene, solution).sum()))
    # a bound, not an estimate: no tolerance beyond the exact error's quadrature (~1e-8)
    assert estimate.eta >= error * (1 - 1e-6), (level, estimate.eta, error)
    assert estimate.eta <= 20 * error  # and not a useless one (measured <= 7 here)
    parts = estimate.bound
    assert parts.excess_shear >= 0 and parts.friction_complementarity >= 0


# Nitsche's equations also test with sigma(v) n; that term is in the patch data
# (``estimators.guaranteed.consistency_stress``)
@pytest.mark.parametrize("formulation", FRICTIONAL)
def test_the_shear_traction_balances_the_contact_patches(formulation):
    # sigma*_t corrected along the tangents leaves no imbalance for the load term rho
    # (round-off), where sigma_t,h alone would leave the discrete tangential reaction's
    # difference from it
    scene = get_scene("stick-slip")
    solution = solve(get_formulation(formulation)(scene, scene.mesh.refined(2)),
                     "active-set")
    rec, _, load, *_, shear = equilibrate(scene, solution)
    assert shear is not None and np.abs(shear.delta).max() > 0
    assert rec.imbalance <= 1e-10
    assert np.sqrt(load.squares.sum()) <= 1e-10 * get_estimator("equilibrated")(scene, solution).eta


def test_coulomb_is_refused_by_the_bound_and_tresca_is_not():
    why = ESTIMATORS.why_not("equilibrated", scene=get_scene("stick-slip",
                                                             friction="coulomb"))
    assert why == ("estimator 'equilibrated' bounds the error under Tresca friction only (the "
                   "scene's law is coulomb(mu=0.3): Coulomb's is not a minimisation)")
    assert ESTIMATORS.why_not("equilibrated", scene=get_scene("stick-slip")) is None


def test_the_tangential_trace_constant_bounds_a_shear_that_the_normal_one_does_not():
    # v = ((1 - y) / 2, 0) vanishes on the clamped top of (-1, 1)^2 and slides the whole of
    # Gamma_C (y = -1) by 1: ||v_t||^2 = 2 there, eps_xy = -1/4 everywhere, a(v, v) = 2 mu
    # (2 / 16) 4 = mu; so C_Tt^2 >= 2 / mu (5.2 at E = 1, nu = 0.3), while C_T bounds v . n,
    # which is 0 here, and is smaller (C_T^2 = 1.8): N_t needs its own constant (17.5)
    scene = get_scene("stick-slip")
    constants = domain_constants(scene)
    ratio = 2 / scene.material.lame[1]
    assert constants.trace**2 < ratio <= constants.tangential_trace**2
    assert constants.coarse[3] <= constants.tangential_trace  # fine + (fine - coarse)
    assert domain_constants(get_scene("paper")).tangential_trace is None  # no friction
