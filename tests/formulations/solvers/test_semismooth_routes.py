"""The semismooth Newton's routes: past SPARSE_NEWTON_FROM contact points a symmetric Nitsche
system takes sparse steps on the direct back-end (no dense nq x nq block) and agrees with the
condensed route; a Jacobian the SPD factorisation refuses falls back to the condensed route."""

import numpy as np
import pytest

from formulations import get_formulation
from formulations.discretisation import solve
from formulations.solvers import backends, reused_factorisation
from formulations.solvers import semismooth_newton as newton_module
from scenes import get_scene

CONDENSING = [b for b in backends.available_backends() if backends.condenses(b)]
pytestmark = pytest.mark.skipif(not CONDENSING, reason="no condensing back-end installed")


@pytest.fixture(scope="module")
def nitsche_3d():
    scene = get_scene("hertz-3d")
    return get_formulation("nitsche")(scene, scene.mesh.refined(1))


def energy_difference(discretisation, a, b) -> float:
    K, e = discretisation.elasticity.K, a.u - b.u
    return float(np.sqrt(e @ (K @ e) / (b.u @ (K @ b.u))))


def test_the_route_depends_on_the_size_symmetry_and_back_end(nitsche_3d, monkeypatch):
    system, direct = nitsche_3d.system, CONDENSING[0]
    assert system.nq > newton_module.SPARSE_NEWTON_FROM  # 3D: many contact points already
    assert newton_module.newton_route(system, direct) == (False, direct)
    monkeypatch.setattr(newton_module, "SPARSE_NEWTON_FROM", system.nq)  # few: condensed
    assert newton_module.newton_route(system, direct) == (True, None)
    skew = get_formulation("nitsche")(get_scene("hertz-3d"),
                                      get_scene("hertz-3d").mesh.refined(1), theta=0.0)
    assert newton_module.newton_route(skew.system, direct) == (True, None)  # not SPD
    assert newton_module.newton_route(system, "splu") == (False, None)  # SuperLU steps


def test_sparse_steps_agree_with_the_condensed_route(nitsche_3d, monkeypatch):
    sparse = solve(nitsche_3d, "active-set", backend=CONDENSING[0])
    monkeypatch.setattr(newton_module, "SPARSE_NEWTON_FROM", nitsche_3d.system.nq)
    condensed = solve(nitsche_3d, "active-set", backend=CONDENSING[0])
    assert sparse.status == condensed.status == "ok"
    assert not any(phase == "condense" for phase, _ in sparse.diagnostics.phases)
    assert any(phase == "condense" for phase, _ in condensed.diagnostics.phases)
    # both solve the same piecewise linear equation exactly: round-off apart (cond(K) ~ 1e4)
    assert energy_difference(nitsche_3d, sparse, condensed) < 1e-10


def test_a_jacobian_refused_by_the_factorisation_falls_back_to_the_condensed_route(
        nitsche_3d, monkeypatch):
    def refusing(*args, **kwargs):
        raise backends.FactorisationError("zero pivot (K is not positive definite?)")
    monkeypatch.setattr(reused_factorisation, "factorise", refusing)
    answer = solve(nitsche_3d, "active-set", backend=CONDENSING[0])
    assert answer.status == "ok"
    assert any(phase == "condense" for phase, _ in answer.diagnostics.phases)
