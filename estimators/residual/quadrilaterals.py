"""The seed's residual estimator on a quadrilateral hierarchy with hanging nodes: the terms of
``estimators.residual.triangles`` (the paper's (8) with eta_0 of its section 5) for Q1 and Q2
solutions on the quadrilateral family's meshes (docs/theory.md, section 15).

eta_0^2 = (1/E) sum_T ( (h_T/p)^2 ||f + div sigma(u_h)||_T^2 + sum_{e in E_T} (h_e/p) R_e^2 ).
An edge with a hanging node is measured on each of its halves, the fine cell against the
coarse one across it: R_e = 1/2 ||[sigma_n(u_h)]||_e on interior edges and halves,
||sigma_n(u_h) - q||_e on Gamma_N, ||sigma_nn(u_h) + lambda_h||_e + ||sigma_nt(u_h)||_e on
Gamma_C. The contact terms, E ||w||_0 ||w||_1 and |(lambda_h, w)| with w = (g - u_hn)_-, are
``estimators.contact_terms``'s, as on every cell.
The stress is evaluated from the exact gradient polynomials of
``formulations.cells.quad_evaluation``.
"""

from __future__ import annotations

import numpy as np

from estimators.base import Estimate, register_cell_variant
from estimators.contact_terms import contact_terms
from estimators.residual.nitsche import nitsche_estimate
from formulations.cells.quad_evaluation import QuadGradient
from formulations.cells.quad_load import affine_maps, volumes
from formulations.cells.tensor_stiffness import tensor_rule
from formulations.contact.reference_facets import gauss_legendre
from formulations.elasticity import element_diameters, stress_tensor_from_gradient
from scenes.quad_hierarchy import edge_keys

EDGE_POINTS = 4  # Gauss points on Neumann and contact edges: q and lambda_h are not polynomials


class QuadStress:
    """sigma(u_h) and div sigma(u_h) of a quadrilateral solution at points of given cells."""

    def __init__(self, solution):
        elasticity = solution.elasticity
        self.field = QuadGradient.from_solution(elasticity.basis, solution.u, elasticity.order)
        self.lame = elasticity.lame

    def gradient(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        return self.field.at(x, cells)

    def sigma(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        return stress_tensor_from_gradient(self.gradient(x, cells), *self.lame)

    def divergence(self, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
        return self.divergence_of(self.field.derivatives_at(x, cells))

    def divergence_of(self, dgrad: np.ndarray) -> np.ndarray:
        """div sigma from d_k (grad u)_ij (d, d, d, ...)."""
        lam, mu = self.lame
        d = dgrad.shape[0]
        strain = 0.5 * (dgrad + np.swapaxes(dgrad, 0, 1))  # d_k eps_ij
        d_trace = sum(dgrad[k, k] for k in range(d))  # d_i tr(eps)
        return np.array([2 * mu * sum(strain[i, k, k] for k in range(d)) + lam * d_trace[i]
                         for i in range(d)])


def element_residuals(scene, solution, stress: QuadStress) -> np.ndarray:
    """(h_T/p)^2 ||f + div sigma(u_h)||_T^2 per cell, on the (p + 1)^d Gauss points of each
    parallelogram or parallelepiped x = v0 + A xi (dx = |det A| w)."""
    mesh, order = solution.elasticity.basis.mesh, solution.elasticity.order
    X, w = tensor_rule(order + 1, mesh.p.shape[0])
    origin, A = affine_maps(mesh)  # (d, nE), (d, d, nE)
    x = origin[:, :, None] + np.einsum("ikE,kq->iEq", A, X)  # (d, nE, nq)
    residual = stress.divergence_of(stress.field.derivatives_at_reference(X))
    if scene.body_force is not None:
        residual = residual + scene.body_force(x)
    norm2 = ((residual**2).sum(axis=0) * w).sum(axis=1) * volumes(A)
    return (element_diameters(mesh) / order) ** 2 * norm2


def edge_pairs(solution) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every interior edge piece: end points a, b (2, n) and the cells on either side. The
    conforming interior edges, and both halves of every edge with a hanging node (its fine
    cell, the coarse cell across)."""
    mesh = solution.elasticity.basis.mesh
    hierarchy = mesh.hierarchy
    interior = np.flatnonzero(mesh.f2t[1] >= 0)
    a, b = mesh.facets[:, interior]
    first, second = mesh.f2t[:, interior]
    used, _ = hierarchy.leaf_vertices()
    node, ends_a, ends_b = (np.searchsorted(used, v) for v in hierarchy.hanging())
    if node.size:
        keys = edge_keys(mesh.facets[0], mesh.facets[1])  # int64: no overflow past 46 341
        order = np.argsort(keys)

        def owner(u, v):  # the (only) cell of the leaf facet (u, v)
            return mesh.f2t[0, order[np.searchsorted(keys[order], edge_keys(u, v))]]

        coarse = owner(ends_a, ends_b)
        a = np.concatenate([a, ends_a, node])
        b = np.concatenate([b, node, ends_b])
        first = np.concatenate([first, owner(ends_a, node), owner(node, ends_b)])
        second = np.concatenate([second, coarse, coarse])
    return mesh.p[:, a], mesh.p[:, b], first, second


def jump_residuals(solution, stress: QuadStress) -> np.ndarray:
    """(h_e/p) (1/2 ||[sigma_n]||_e)^2 to both cells of every interior edge piece."""
    order = solution.elasticity.order
    n_cells = solution.elasticity.basis.mesh.t.shape[1]
    a, b, first, second = edge_pairs(solution)
    t, w = gauss_legendre(order + 1)  # the jump has degree p along an edge: exact
    x = (a[:, :, None] + (b - a)[:, :, None] * t).reshape(2, -1)
    h = np.linalg.norm(b - a, axis=0)
    n = np.repeat(np.array([(b - a)[1], -(b - a)[0]]) / h, t.size, axis=1)
    jump = (stress.sigma(x, np.repeat(first, t.size))
            - stress.sigma(x, np.repeat(second, t.size)))
    jn = np.einsum("ijn,jn->in", jump, n)
    norm2 = ((jn**2).sum(axis=0).reshape(-1, t.size) * w).sum(axis=1) * h
    share = h / order * 0.25 * norm2
    return np.bincount(first, share, n_cells) + np.bincount(second, share, n_cells)


def boundary_residuals(scene, solution, stress: QuadStress) -> np.ndarray:
    """(h_e/p) R_e^2 on the Neumann and the contact edges."""
    elasticity = solution.elasticity
    mesh, order, n_cells = elasticity.basis.mesh, elasticity.order, elasticity.basis.mesh.t.shape[1]
    out = np.zeros(n_cells)
    t, w = gauss_legendre(EDGE_POINTS)
    trace = solution.trace
    neumann = scene.neumann_facets(mesh)
    if neumann.size:
        cells = mesh.f2t[0, neumann]
        a, b = mesh.p[:, mesh.facets[0, neumann]], mesh.p[:, mesh.facets[1, neumann]]
        h = np.linalg.norm(b - a, axis=0)
        inward = mesh.p[:, mesh.t[:, cells]].mean(axis=1) - a
        n = np.array([(b - a)[1], -(b - a)[0]]) / h
        n *= np.where((n * inward).sum(axis=0) > 0, -1.0, 1.0)
        x = a[:, :, None] + (b - a)[:, :, None] * t
        sn = np.einsum("ijn,jn->in", stress.sigma(x.reshape(2, -1), np.repeat(cells, t.size)),
                       np.repeat(n, t.size, axis=1)).reshape(2, -1, t.size)
        if scene.traction is not None:
            sn = sn - scene.traction(x)
        out += np.bincount(cells, h / order * ((sn**2).sum(axis=0) * w).sum(axis=1) * h,
                           n_cells)
    if trace.size:
        x = trace.points(t).reshape(2, -1)
        normal = np.repeat(trace.normal, t.size, axis=1)
        sn = np.einsum("ijn,jn->in", stress.sigma(x, np.repeat(trace.element, t.size)), normal)
        snn = np.einsum("in,in->n", sn, normal).reshape(-1, t.size)
        snt2 = ((sn - snn.ravel() * normal) ** 2).sum(axis=0).reshape(-1, t.size)
        r_e = (np.sqrt((((snn + solution.pressure(t)) ** 2) * w).sum(axis=1) * trace.length)
               + np.sqrt((snt2 * w).sum(axis=1) * trace.length))
        out += np.bincount(trace.element, trace.length / order * r_e**2, n_cells)
    return out


def quad_volume_terms(scene, solution, stress: QuadStress | None = None) -> np.ndarray:
    """eta_0^2 per cell (the module docstring's terms, over E)."""
    stress = QuadStress(solution) if stress is None else stress
    return (element_residuals(scene, solution, stress) + jump_residuals(solution, stress)
            + boundary_residuals(scene, solution, stress)) / float(scene.material.young_modulus)


@register_cell_variant("nitsche-residual", "quad")
def nitsche_residual_estimate(scene, solution) -> Estimate:
    """``nitsche-residual`` on quadrilaterals: the same volume terms, no eq. (8) terms."""
    return nitsche_estimate(quad_volume_terms(scene, solution))


@register_cell_variant("residual", "quad")
def quad_residual_estimate(scene, solution) -> Estimate:
    """eta of the paper's (8) for a quadrilateral contact solution, per-cell indicators."""
    volume = quad_volume_terms(scene, solution)
    shared = contact_terms(scene, solution)  # the contact terms every estimator shares
    geometric, complementarity = shared.geometric, shared.complementarity
    eta_0 = float(np.sqrt(volume.sum()))
    return Estimate(estimator="residual", eta=float(np.sqrt(eta_0**2 + geometric
                                                            + complementarity)),
                    eta_0=eta_0, eta_geometric=float(np.sqrt(geometric)),
                    eta_complementarity=float(np.sqrt(complementarity)),
                    indicators=volume + shared.per_element)
