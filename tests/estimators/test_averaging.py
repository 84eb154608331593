"""The averaging (Zienkiewicz-Zhu) estimator."""

import numpy as np
import pytest
from skfem import Basis, ElementTriP1, Functional

from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.sequence.loop import LoopConfig, run_sequence
from estimators import get_estimator
from estimators.averaging import (
    averaged_stress,
    averaging_indicators,
    compliance_energy,
)
from formulations import get_formulation, solve
from formulations.elasticity import stress_from_gradient
from scenes import get_scene

estimate = get_estimator("averaging")


def test_compliance_energy_is_sigma_colon_epsilon():
    # sigma : C^-1 sigma = sigma : eps for sigma = C eps, for any strain and both planes
    rng = np.random.default_rng(0)
    for lam, mu in ((0.0, 500.0), (20000.0, 26000.0), (1e6, 1.0)):
        grad = rng.normal(size=(2, 2, 50))
        sigma = stress_from_gradient(grad, lam, mu)
        eps = np.array([grad[0, 0], grad[1, 1], 0.5 * (grad[0, 1] + grad[1, 0])])
        sigma_eps = sigma[0] * eps[0] + sigma[1] * eps[1] + 2 * sigma[2] * eps[2]
        assert compliance_energy(sigma, lam, mu) == pytest.approx(sigma_eps, rel=1e-9)


@pytest.mark.parametrize("formulation", ["mixed", "vi"])
def test_zero_when_the_stress_is_globally_constant(compression_scene, formulation):
    # the exact solution is linear, P1 reproduces it, so sigma_h is one constant that nodal
    # averaging reproduces: eta_A vanishes to round-off (stress E delta / 2 = 5)
    mesh = compression_scene.mesh.refined(2)
    sol = solve(get_formulation(formulation)(compression_scene, mesh), "active-set")
    est = estimate(compression_scene, sol)
    energy_norm = np.sqrt(sol.u @ sol.elasticity.K @ sol.u)
    assert est.eta_0 < 1e-10 * energy_norm
    assert est.eta_geometric < 1e-10 * energy_norm
    # the complementarity term is the square root of lambda x (round-off penetration): with
    # p = 5 on |Gamma_C| = 2 and a penetration of 100 ulps of max|u| it is ~1e-8 relative
    # (measured 4.1e-9 absolute for vi: 1.3e-8 relative, against 3.2e-9 allowed before)
    roundoff = 100 * np.finfo(float).eps * np.abs(sol.u).max()
    assert est.eta_complementarity <= np.sqrt(5.0 * 2.0 * roundoff)


def test_positive_on_the_paper_scene_and_indicators_sum_to_eta_squared():
    scene = get_scene("paper")
    sol = solve(get_formulation("mixed")(scene, scene.mesh.refined(3)), "active-set")
    est = estimate(scene, sol)
    assert est.eta_0 > 0 and (est.indicators >= 0).all()  # exact: sums of squares
    assert est.indicators.sum() == pytest.approx(est.eta**2, rel=1e-12)


def test_midpoint_rule_is_exact_against_a_high_order_quadrature():
    # an independent integration: A sigma_h as a P1 field in scikit-fem, 4th-order quadrature
    scene = get_scene("paper")
    mesh = scene.mesh.refined(2)
    sol = solve(get_formulation("vi")(scene, mesh), "active-set")
    lam, mu = sol.elasticity.lame
    stress = sol.elasticity.element_stress(sol.u)
    basis = Basis(mesh, ElementTriP1(), intorder=4)
    vertex = averaged_stress(sol, basis)
    fields = [basis.interpolate(vertex[k]) for k in range(3)]

    @Functional
    def density(w):
        diff = np.array([stress[k][:, None] - w[f"s{k}"] for k in range(3)])
        return compliance_energy(diff, lam, mu)

    brute = density.elemental(basis, s0=fields[0], s1=fields[1], s2=fields[2])
    assert averaging_indicators(sol) == pytest.approx(brute, rel=1e-10, abs=1e-14)


def test_indicators_drive_an_adaptive_run():
    config = LoopConfig(strategy="adaptive", max_dofs=3000)
    rows = [r.row for r in run_sequence(get_scene("paper"), "mixed", "active-set", "averaging",
                                        config)]
    assert all(r.status in SOLVED for r in rows) and len(rows) >= 6
    assert rows[-1].eta < 0.5 * rows[2].eta  # level 2 is the first with contact
    assert rows[-1].h_min < rows[-1].h_max / 8  # graded, not uniform
