"""The balancing correction delta of the auxiliary contact traction lambda* (docs/theory.md,
13.3): its moments, and with facet weights the least weighted norm among linear functions per
facet."""

import numpy as np
import pytest

import estimators.guaranteed.auxiliary_traction as auxiliary
from estimators import get_estimator
from estimators.guaranteed.contact_extension import vertex_normals
from estimators.guaranteed.equilibrated import equilibrate
from estimators.guaranteed.guaranteed_contact import FacetPolynomial, balanced_traction
from formulations import get_formulation, solve
from formulations.contact.reference_facets import gauss_legendre
from scenes import get_scene


@pytest.fixture(scope="module")
def hertz_vi_p2():
    scene = get_scene("hertz")
    solution = solve(get_formulation("vi")(scene, scene.mesh, order=2), "active-set")
    clamped = equilibrate(scene, solution)[5]
    return scene, solution, clamped


def _correction(trace, defect, clamped, weight):
    zero = FacetPolynomial(np.zeros((trace.size, 1)))
    return balanced_traction(trace, zero, defect, clamped, weight=weight).delta   # (2, n_f)


def _moments(trace, delta):
    """int delta psi_a over Gamma_C per mesh vertex, by 3-point Gauss per facet (exact for
    the quadratic integrands)."""
    t, w = gauss_legendre(3)
    values = delta[0][:, None] * (1 - t) + delta[1][:, None] * t
    n_v = trace.mesh.p.shape[1]
    return sum(np.bincount(v, trace.length * (values * hat * w).sum(axis=1), minlength=n_v)
               for v, hat in zip(trace.vertices, (1 - t, t), strict=True))


@pytest.mark.parametrize("weighted", [False, True])
def test_the_correction_has_the_moments_it_balances(hertz_vi_p2, weighted):
    """int delta psi_a = -defect_a . nu_a on every contact vertex off Gamma_D, for a random
    defect, with and without random facet weights in [1, 1e3] (relative 1e-12: one sparse
    solve of a well-conditioned mass matrix)."""
    _, solution, clamped = hertz_vi_p2
    trace = solution.trace
    rng = np.random.default_rng(3)
    defect = rng.standard_normal((trace.mesh.p.shape[1], 2))
    weight = 10 ** rng.uniform(0, 3, trace.size) if weighted else None
    moments = _moments(trace, _correction(trace, defect, clamped, weight))
    on = np.unique(np.concatenate(trace.vertices))
    on = on[~clamped[on]]
    wanted = -(defect[on] * vertex_normals(trace)[:, on].T).sum(axis=1)
    assert np.linalg.norm(moments[on] - wanted) <= 1e-12 * np.linalg.norm(wanted)


def test_the_weighted_correction_is_the_least_weighted_norm(hertz_vi_p2):
    """Against the KKT system of min sum_e omega_e ||delta||_e^2 over every linear function
    per facet (2 values per facet, discontinuous) with those moments, assembled and solved
    densely (relative 1e-10); with omega = 1 the minimiser is continuous, the P1 delta."""
    _, solution, clamped = hertz_vi_p2
    trace = solution.trace
    rng = np.random.default_rng(5)
    defect = rng.standard_normal((trace.mesh.p.shape[1], 2))
    weight = 10 ** rng.uniform(0, 3, trace.size)
    on = np.unique(np.concatenate(trace.vertices))
    on = on[~clamped[on]]
    n = 2 * trace.size                      # unknowns: delta at (start, end) of every facet
    Q = np.zeros((n, n))
    C = np.zeros((on.size, n))
    local = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6   # int of the facet's linear hats' products
    for e in range(trace.size):
        idx = [e, trace.size + e]
        Q[np.ix_(idx, idx)] = weight[e] * trace.length[e] * local
        for side in (0, 1):
            row = np.searchsorted(on, trace.vertices[side][e])
            if row < on.size and on[row] == trace.vertices[side][e]:
                C[row, idx] += trace.length[e] * local[side]
    rhs = -(defect[on] * vertex_normals(trace)[:, on].T).sum(axis=1)
    kkt = np.block([[2 * Q, C.T], [C, np.zeros((on.size, on.size))]])
    expected = np.linalg.solve(kkt, np.concatenate([np.zeros(n), rhs]))[:n]
    got = _correction(trace, defect, clamped, weight).ravel()
    assert np.linalg.norm(got - expected) <= 1e-10 * np.linalg.norm(expected)
    continuous = _correction(trace, defect, clamped, None)
    start, end = trace.vertices
    for v in on:  # one value per vertex, whichever facet holds it
        values = np.concatenate([continuous[0][start == v], continuous[1][end == v]])
        assert np.ptp(values) <= 1e-12 * np.abs(continuous).max()


def test_gap_weights_lower_the_bound_on_a_coarse_contact_zone(hertz_vi_p2, monkeypatch):
    """hertz, vi, P2, 1122 DOFs (1 .. 3 active nodes): the continuous correction spreads the
    reactions over facets far from the contact zone, where u_h leaves a gap of 0.1 .. 0.3, and
    B pays lambda*_+ times it. The weighted correction keeps off them: measured eta 0.1757 ->
    0.1321 and sqrt(B) 0.117 -> 0.059; asked: eta at least 15 % lower, sqrt(B) at least 30 %."""
    scene, solution, _ = hertz_vi_p2
    weighted = get_estimator("equilibrated")(scene, solution)
    monkeypatch.setattr(auxiliary, "gap_weights", lambda scene, solution: [None])
    plain = get_estimator("equilibrated")(scene, solution)
    assert weighted.eta <= 0.85 * plain.eta
    assert weighted.eta_complementarity <= 0.7 * plain.eta_complementarity


def test_a_weighted_correction_needs_a_margin_to_be_taken():
    """Candidates pressure by pressure, four weights each, None first: a weighted one is taken
    only if its contact terms are below (1 - WEIGHTED_MARGIN) of the best unweighted one's."""
    margin = auxiliary.WEIGHTED_MARGIN
    terms = np.array([1.0, 0.95, 2.0, 2.0, 0.9, 2.0, 2.0, 2.0])
    assert auxiliary._chosen(terms, 4) == 4             # the best unweighted: 0.9 (pressure 2)
    terms[6] = 0.9 * (1 - margin) * 0.999
    assert auxiliary._chosen(terms, 4) == 6
    terms[6] = 0.9 * (1 - margin) * 1.001
    assert auxiliary._chosen(terms, 4) == 4
