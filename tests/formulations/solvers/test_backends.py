"""Sparse back-ends: the Schur-complement route gives the same B K^-1 B' and K^-1 b as a dense
computation, on every available back-end."""

import numpy as np
import pytest
from scipy import sparse

from formulations import get_formulation
from formulations.solvers import backends
from scenes import get_scene


@pytest.fixture(scope="module")
def qp():
    scene = get_scene("paper")
    return get_formulation("mixed")(scene, scene.mesh.refined(2)).qp


CONDENSING = [b for b in backends.available_backends() if backends.condenses(b)]


@pytest.mark.skipif(not CONDENSING, reason="no condensing back-end installed")
@pytest.mark.parametrize("backend", CONDENSING)
def test_condensed_operator_and_solve_match_dense_linear_algebra(qp, backend):
    factor = backends.factorise_condensed(qp.K, np.unique(qp.B.indices), backend)
    K, B = qp.K.toarray(), qp.B.toarray()
    S = B @ np.linalg.solve(K, B.T)
    # both sides are O(1e-5) x cond(K) ~ 1e3 round-off apart
    assert factor.condensed(qp.B) == pytest.approx(S, rel=1e-9, abs=1e-9 * np.abs(S).max())
    x = factor.solve(qp.F)
    assert x == pytest.approx(np.linalg.solve(K, qp.F), rel=1e-9, abs=1e-9 * np.abs(x).max())
    X = factor.solve(np.column_stack([qp.F, 2 * qp.F]))  # several right-hand sides at once
    assert X[:, 1] == pytest.approx(2 * x, rel=1e-12, abs=1e-12 * np.abs(x).max())


@pytest.mark.parametrize("backend", CONDENSING)
def test_a_matrix_that_is_not_positive_definite_is_refused(backend):
    K = sparse.csc_matrix(np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
    with pytest.raises(Exception, match="(?i)positive definite|not positive|pivot"):
        backends.factorise_condensed(K, np.array([2]), backend)


@pytest.mark.parametrize("backend", CONDENSING)
def test_a_schur_block_too_large_for_the_memory_is_refused_before_the_backend(backend,
                                                                               monkeypatch):
    # 1000 contact DOFs need 3 x 8 MB; with 1 MiB "available" the back-end is never called
    monkeypatch.setattr(backends.os, "sysconf", lambda name: 256 if "PAGES" in name else 4096)
    K = sparse.identity(2000, format="csc")
    with pytest.raises(backends.FactorisationError,
                       match=r"dense Schur block of 1000 contact DOFs needs 0.0 GiB"):
        backends.factorise_condensed(K, np.arange(1000), backend)


@pytest.mark.parametrize("backend", backends.available_backends())
def test_plain_factorisation_solves(qp, backend):
    b = qp.F - qp.B.T @ np.ones(qp.m)
    x = backends.factorise(qp.K, backend)(b)
    assert x == pytest.approx(np.linalg.solve(qp.K.toarray(), b), rel=1e-9,
                              abs=1e-9 * np.abs(x).max())


def test_splu_gives_no_condensed_factor():
    K = sparse.csc_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    with pytest.raises(backends.BackendError, match="backend='splu' gives no cheap Schur"):
        backends.factorise_condensed(K, np.array([0, 1]), "splu")


def test_unknown_backend_is_refused_with_the_choices():
    with pytest.raises(backends.BackendError, match=r"backend='mumps' is not one of "
                                                     r"pardiso, cholmod, splu"):
        backends.check_backend("mumps")


def test_default_backend_is_available():
    assert backends.default_backend() in backends.available_backends()
