"""Friction in Nitsche's method, theta = 1 (Chouly's formulation; docs/theory.md, 17.2).

With the tangent t, sigma_nt = t . sigma n and the slip w of the obstacle, the tangential
Nitsche traction P_t(u) = sigma_nt(u) - gamma (u_t - w) is projected onto the friction disc:
sigma_t,h = [P_t(u_h)]_s, s the Tresca bound or mu lambda_h (Coulomb). The discrete equation
adds to the frictionless one (formulations.nitsche)

    - theta/gamma (sigma_nt(u_h), sigma_nt(v))_C + 1/gamma ([P_t(u_h)]_s, theta sigma_nt(v)
      - gamma v_t)_C,

consistent: the exact solution has [P_t(u)]_s = sigma_t. For theta = 1 it is the optimality
condition of the frictionless functional plus -1/(2 gamma) ||sigma_nt||^2 + 1/gamma int
H_s(P_t), H_s Huber's function (H_s' = [.]_s): with lengths q = -[P_n]_- / gamma and r the
slacks, the QP of ``formulations.slack_friction`` with K - S'(W/gamma)S - S_t'(W/gamma)S_t,
normal rows N - S/gamma, tangential rows U_t - S_t/gamma and weights gamma W. Coulomb is the
fixed point s = mu lambda_h on it. Other theta have no such functional and are refused with
friction.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.base import ContactQP, FrictionState
from formulations.evaluation import evaluate_on_trace
from formulations.friction_state import friction_state
from formulations.semismooth import SemismoothSystem
from formulations.slack_friction import contact_tangent, slack_friction_qp, tangential_rows


def shear_stress_rows(elasticity, trace, t: np.ndarray) -> sparse.csr_matrix:
    """u -> sigma_nt(u_h) at the points ``t`` of every contact facet, over the free DOFs."""
    nq = t.shape[-1]
    at = evaluate_on_trace(elasticity.basis, trace, t)
    return elasticity.restrict(at.stress_matrix(np.repeat(trace.normal, nq, axis=1),
                                                np.repeat(contact_tangent(trace), nq, axis=1),
                                                elasticity.lame))


def nitsche_friction_qp(scene, system: SemismoothSystem, elasticity, trace,
                        t: np.ndarray) -> ContactQP:
    """The theta = 1 QP of the module docstring."""
    shear = shear_stress_rows(elasticity, trace, t)
    inverse = sparse.diags(1.0 / system.gamma)
    scaled = sparse.diags(system.weight / system.gamma)
    K = system.K - system.S.T @ scaled @ system.S - shear.T @ scaled @ shear
    return slack_friction_qp(scene, K.tocsr(), system.F, system.N - inverse @ system.S,
                             tangential_rows(elasticity, trace, t) - inverse @ shear,
                             system.gap, system.weight * system.gamma, system.weight,
                             trace.points(t))


def shear_function(scene, elasticity, trace, gamma_facet: np.ndarray, u_free: np.ndarray,
                   pressure):
    """sigma_t,h(t) = [P_t(u_h)]_s at local coordinates t of every contact facet."""
    u, law = elasticity.expand(u_free), scene.friction

    def shear(tt):
        tt = np.asarray(tt, dtype=float)
        nq = tt.shape[-1]
        at = evaluate_on_trace(elasticity.basis, trace, tt)
        normal = np.repeat(trace.normal, nq, axis=1)
        tangent = np.repeat(contact_tangent(trace), nq, axis=1)
        sigma = at.stress_matrix(normal, tangent, elasticity.lame) @ u
        u_t = at.matrix(tangent) @ u
        argument = (sigma - np.repeat(gamma_facet, nq) * (u_t - law.slide)).reshape(
            trace.size, nq)
        bound = (law.coefficient * pressure(tt) if law.kind == "coulomb"
                 else law.slip_bound_at(trace.points(tt)).reshape(trace.size, nq))
        return np.clip(argument, -bound, bound)

    return shear



def nitsche_friction_state(scene, qp: ContactQP, answer, elasticity, trace, t: np.ndarray,
                           row_length: np.ndarray, gamma_facet: np.ndarray,
                           pressure) -> FrictionState:
    """The points' states from the QP's multipliers (``formulations.friction_state``; a
    multiplier is w_q |e| times a traction) and sigma_t,h = [P_t(u_h)]_s along the facets."""
    ns = row_length.size
    tangential = np.full(ns, np.nan) if answer.tangential is None else answer.tangential
    return friction_state(qp.friction, answer.u, answer.multipliers[:ns], tangential,
                          1.0 / row_length, trace.row_coordinates(t),
                          shear_function(scene, elasticity, trace, gamma_facet,
                                         answer.u[:elasticity.free.size], pressure))
