"""The residual estimator's eta_0 on a hexahedral hierarchy with hanging nodes (docs/theory.md,
section 15.4): the terms of ``estimators.residual.tetrahedra`` with quadrilateral faces,

    eta_0^2 = (1/E) sum_T ( (h_T/p)^2 ||f + div sigma(u_h)||_T^2 + sum_{F in T} (h_F/p) R_F^2 ),

where a face split by finer neighbours is measured on each of its quarters, the fine cell
against the coarse one across (as the quadrilateral variant measures both halves of an edge).
The element residual is the quadrilateral variant's (``element_residuals``, in 3D), the
contact faces the tetrahedral one's (``contact_residuals``: any 3D contact boundary), and the
stress comes from the exact gradient polynomials of ``formulations.cells.quad_evaluation``.
Registered as the hexahedral variants of ``residual`` and ``nitsche-residual``.
"""

from __future__ import annotations

import numpy as np

from estimators.base import Estimate, combine, register_cell_variant
from estimators.contact_terms import contact_terms
from estimators.residual.nitsche import nitsche_estimate
from estimators.residual.quadrilaterals import QuadStress, element_residuals
from estimators.residual.tetrahedra import contact_residuals
from formulations.cells.tensor_stiffness import tensor_rule
from formulations.contact.quadrilaterals import bilinear
from formulations.contact.surfaces import outward
from scenes.hex_hierarchy import FACES

BOUNDARY_POINTS = 4  # Gauss points per side on Neumann faces: q is not a polynomial


def cyclic_facets(mesh) -> np.ndarray:
    """Every facet's corners (4, n_facets) in cyclic order (scikit-fem sorts them)."""
    corners = np.empty((4, mesh.facets.shape[1]), dtype=np.int64)
    corners[:, mesh.t2f.ravel()] = mesh.t[np.array(FACES)].transpose(1, 0, 2).reshape(4, -1)
    return corners


def face_geometry(mesh, corners: np.ndarray, points: int):
    """Points (3, n, nq), weights (nq,), areas, unit normals (3, n) and diameters of
    parallelogram faces with cyclic ``corners`` (4, n), on the points^2 Gauss rule."""
    c = mesh.p[:, corners]  # (3, 4, n)
    t, w = tensor_rule(points, 2)
    cross = np.cross(c[:, 1] - c[:, 0], c[:, 3] - c[:, 0], axis=0)
    area = np.linalg.norm(cross, axis=0)
    diameter = np.maximum(np.linalg.norm(c[:, 2] - c[:, 0], axis=0),
                          np.linalg.norm(c[:, 3] - c[:, 1], axis=0))
    return bilinear(c, t), w, area, cross / area, diameter


def face_pieces(mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every interior face piece: the facet and the cells on either side. The conforming
    interior faces, and each quarter of a split face (its fine cell, the coarse cell across:
    the quarter holds the split face's centre)."""
    interior = np.flatnonzero(mesh.f2t[1] >= 0)
    facets, first, second = interior, mesh.f2t[0, interior], mesh.f2t[1, interior]
    hierarchy = mesh.hierarchy
    node, corners = hierarchy.hanging_faces()
    if node.size:
        used, _ = hierarchy.leaf_vertices()
        split = np.full(mesh.p.shape[1], -1)
        split[np.searchsorted(used, node)] = np.arange(node.size)
        one_sided = np.flatnonzero(mesh.f2t[1] < 0)
        which = split[mesh.facets[:, one_sided]].max(axis=0)  # the split face it quarters
        quarters = one_sided[which >= 0]
        coarse = mesh.f2t[0, mesh.facet_with(corners)][which[which >= 0]]
        facets = np.concatenate([facets, quarters])
        first = np.concatenate([first, mesh.f2t[0, quarters]])
        second = np.concatenate([second, coarse])
    return facets, first, second


def face_residuals(scene, solution, stress: QuadStress) -> np.ndarray:
    """sum_{F in T} (h_F / p) R_F^2 per cell: the jumps on every interior face piece, then
    Neumann and contact faces."""
    mesh, order = solution.elasticity.mesh, solution.elasticity.order
    n_cells, corners = mesh.t.shape[1], cyclic_facets(mesh)
    facets, first, second = face_pieces(mesh)
    x, w, area, normal, h = face_geometry(mesh, corners[:, facets], order + 1)
    nq = w.size
    x = x.reshape(3, -1)
    jump = stress.sigma(x, np.repeat(first, nq)) - stress.sigma(x, np.repeat(second, nq))
    jn = np.einsum("ijn,jn->in", jump, np.repeat(normal, nq, axis=1))
    share = h / order * 0.25 * ((jn**2).sum(axis=0).reshape(-1, nq) * w).sum(axis=1) * area
    out = np.bincount(first, share, n_cells) + np.bincount(second, share, n_cells)
    neumann = scene.neumann_facets(mesh)
    if neumann.size:
        cells = mesh.f2t[0, neumann]
        x, w, area, normal, h = face_geometry(mesh, corners[:, neumann], BOUNDARY_POINTS)
        normal = outward(mesh, normal, mesh.p[:, corners[:, neumann]], cells)
        nq = w.size
        sn = np.einsum("ijn,jn->in", stress.sigma(x.reshape(3, -1), np.repeat(cells, nq)),
                       np.repeat(normal, nq, axis=1)).reshape(3, -1, nq)
        if scene.traction is not None:
            sn = sn - scene.traction(x)
        out += np.bincount(cells, h / order * ((sn**2).sum(axis=0) * w).sum(axis=1) * area,
                           n_cells)
    return out + contact_residuals(solution, stress.sigma)


def hex_volume_terms(scene, solution) -> np.ndarray:
    """eta_0^2 per cell (the module docstring's terms, over E)."""
    stress = QuadStress(solution)
    return (element_residuals(scene, solution, stress)
            + face_residuals(scene, solution, stress)) / float(scene.material.young_modulus)


@register_cell_variant("residual", "hex")
def hex_residual_estimate(scene, solution) -> Estimate:
    return combine("residual", hex_volume_terms(scene, solution), contact_terms(scene, solution))


@register_cell_variant("nitsche-residual", "hex")
def hex_nitsche_residual_estimate(scene, solution) -> Estimate:
    return nitsche_estimate(hex_volume_terms(scene, solution))
