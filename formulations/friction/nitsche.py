"""Friction in Nitsche's method, theta = 1 (Chouly's formulation; docs/theory.md, 17.2).

With the tangent t, sigma_nt = t . sigma n and the slip w of the obstacle, the tangential
Nitsche traction P_t(u) = sigma_nt(u) - gamma (u_t - w) is projected onto the friction disc:
sigma_t,h = [P_t(u_h)]_s, s the Tresca bound or mu lambda_h (Coulomb); in 3D P_t is a vector
of the two tangents' components and [.]_s its projection onto the disc of radius s. The discrete
equation adds to the frictionless one (formulations.methods.nitsche)

    - theta/gamma (sigma_nt(u_h), sigma_nt(v))_C + 1/gamma ([P_t(u_h)]_s, theta sigma_nt(v)
      - gamma v_t)_C,

consistent: the exact solution has [P_t(u)]_s = sigma_t. For theta = 1 it is the optimality
condition of the frictionless functional plus -1/(2 gamma) ||sigma_nt||^2 + 1/gamma int
H_s(P_t), H_s Huber's function (H_s' = [.]_s): with lengths q = -[P_n]_- / gamma and r the
slacks, the QP of ``formulations.friction.slack`` with K - S'(W/gamma)S - S_t'(W/gamma)S_t,
normal rows N - S/gamma, tangential rows U_t - S_t/gamma and weights gamma W. Coulomb is the
fixed point s = mu lambda_h on it. Other theta have no such functional and are refused with
friction.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.base import ContactQP, FrictionState
from formulations.cells.evaluation import evaluate_on_trace
from formulations.friction.nodal import interleaved, slide_components
from formulations.friction.slack import (
    contact_tangents,
    shear_vectors,
    slack_friction_qp,
    tangential_rows,
)
from formulations.friction.state import friction_state
from formulations.semismooth import SemismoothSystem


def shear_stress_rows(elasticity, trace, t: np.ndarray) -> sparse.csr_matrix:
    """u -> sigma_nt(u_h) at the points ``t`` of every contact facet, over the free DOFs (in
    3D both tangents per point, point-major)."""
    nq = t.shape[-1]
    at = evaluate_on_trace(elasticity.basis, trace, t)
    normal = np.repeat(trace.normal, nq, axis=1)
    return elasticity.restrict(interleaved([
        at.stress_matrix(normal, np.repeat(tangent, nq, axis=1), elasticity.lame)
        for tangent in contact_tangents(trace)]))


def nitsche_friction_qp(scene, system: SemismoothSystem, elasticity, trace,
                        t: np.ndarray) -> ContactQP:
    """The theta = 1 QP of the module docstring."""
    shear = shear_stress_rows(elasticity, trace, t)
    block = shear.shape[0] // system.gamma.size
    inverse = sparse.diags(1.0 / system.gamma)
    scaled = sparse.diags(system.weight / system.gamma)
    K = (system.K - system.S.T @ scaled @ system.S
         - shear.T @ sparse.diags(np.repeat(system.weight / system.gamma, block)) @ shear)
    return slack_friction_qp(scene, K.tocsr(), system.F, system.N - inverse @ system.S,
                             tangential_rows(elasticity, trace, t)
                             - sparse.diags(np.repeat(1.0 / system.gamma, block)) @ shear,
                             system.gap, system.weight * system.gamma, system.weight,
                             trace.points(t), contact_tangents(trace),
                             near_null=elasticity.rigid_modes)


def shear_parts(scene, elasticity, trace, gamma_facet: np.ndarray, u_free: np.ndarray,
                pressure):
    """At local coordinates t of every contact facet, sigma_nt(u_h) and sigma_t,h = [P_t(u_h)]_s
    along each tangent of ``contact_tangents`` (each (n_facets, nt, d - 1); in 3D P_t is
    projected onto the disc of radius s as a vector)."""
    u, law = elasticity.expand(u_free), scene.friction
    tangents = contact_tangents(trace)
    # w . t_k per facet (0 if the obstacle does not slide)
    slides = ([np.zeros(trace.size)] * len(tangents) if not law.slide else
              list(slide_components(law.slide, tangents).reshape(trace.size, -1).T))

    def parts(tt):
        tt = np.asarray(tt, dtype=float)
        nq = tt.shape[-1]
        at = evaluate_on_trace(elasticity.basis, trace, tt)
        normal = np.repeat(trace.normal, nq, axis=1)
        stress = np.stack([(at.stress_matrix(normal, np.repeat(tangent, nq, axis=1),
                                             elasticity.lame) @ u).reshape(trace.size, nq)
                           for tangent in tangents], axis=-1)
        argument = stress - np.stack([
            np.repeat(gamma_facet, nq).reshape(trace.size, nq)
            * ((at.matrix(np.repeat(tangent, nq, axis=1)) @ u).reshape(trace.size, nq)
               - slide[:, None]) for tangent, slide in zip(tangents, slides, strict=True)],
            axis=-1)                                          # (facet, point, tangent)
        bound = (law.coefficient * pressure(tt) if law.kind == "coulomb"
                 else law.slip_bound_at(trace.points(tt)).reshape(trace.size, nq))
        size = np.linalg.norm(argument, axis=-1)
        projected = argument * (np.minimum(size, bound) / np.where(size > 0, size, 1.0))[
            ..., None]
        return stress, projected

    return parts


def shear_function(scene, elasticity, trace, gamma_facet: np.ndarray, u_free: np.ndarray,
                   pressure):
    """sigma_t,h(t) = [P_t(u_h)]_s at local coordinates t of every contact facet (in 3D the
    vector P_t projected onto the disc of radius s)."""
    parts = shear_parts(scene, elasticity, trace, gamma_facet, u_free, pressure)
    tangents = contact_tangents(trace)

    def shear(tt):
        projected = parts(tt)[1]
        return trace.shear(projected, tangents)

    return shear


def shear_residual(scene, elasticity, trace, gamma_facet: np.ndarray, u_free: np.ndarray,
                   pressure):
    """sum_k (sigma_nt_k(u_h) - sigma_t,h . t_k) t_k (d, n_facets, nt) at local coordinates t
    of every contact facet: the tangential part of Nitsche's traction residual."""
    parts = shear_parts(scene, elasticity, trace, gamma_facet, u_free, pressure)

    def residual(tt):
        stress, projected = parts(tt)
        return shear_vectors(stress - projected, contact_tangents(trace))

    return residual


def nitsche_friction_state(scene, qp: ContactQP, answer, elasticity, trace, t: np.ndarray,
                           row_length: np.ndarray, gamma_facet: np.ndarray,
                           pressure) -> FrictionState:
    """The points' states from the QP's multipliers (``formulations.friction.state``; a
    multiplier is w_q |e| times a traction) and sigma_t,h = [P_t(u_h)]_s along the facets."""
    ns = row_length.size
    tangential = (np.full(qp.friction.block * ns, np.nan) if answer.tangential is None
                  else answer.tangential)
    return friction_state(qp.friction, answer.u, answer.multipliers[:ns], tangential,
                          1.0 / row_length, trace.row_coordinates(t),
                          shear_function(scene, elasticity, trace, gamma_facet,
                                         answer.u[:elasticity.free.size], pressure))
