"""The residual estimator's eta_0 on tetrahedra (docs/theory.md, section 14.1): the terms of
``estimators.residual.triangles`` with triangular faces for edges,

    eta_0^2 = (1/E) sum_T ( (h_T/p)^2 ||f + div sigma(u_h)||_T^2 + sum_{F in T} (h_F/p) R_F^2 ),

R_F = 1/2 ||[sigma_n(u_h)]||_F inside, ||sigma_n(u_h) - q||_F on Gamma_N and
||sigma_nn(u_h) + lambda_h||_F + ||sigma_nt(u_h) - sigma_t,h||_F on Gamma_C (sigma_t,h = 0
without friction); h_F is the face's diameter.
For P1 and P2 on affine tetrahedra sigma(u_h) is of degree p - 1, so div sigma(u_h) is 0 (P1)
or constant per element (P2, ``stress_divergence_3d``); the element residual itself is
``estimators.residual.triangles.element_residual``, the same in both dimensions. Registered as the
tetrahedral variants of ``residual`` and ``nitsche-residual``.
"""

from __future__ import annotations

import numpy as np
from skfem import ElementTetP1

from estimators.base import Estimate, combine, register_cell_variant
from estimators.contact_terms import contact_terms
from estimators.residual.nitsche import nitsche_estimate
from estimators.residual.triangles import element_residual
from formulations import DiscreteSolution
from formulations.cells.evaluation import gradients_at, gradients_at_reference
from formulations.contact.reference_facets import triangle_rule
from formulations.contact.triangles import outer_triangle_normals
from formulations.elasticity import stress_tensor_from_gradient
from scenes.base import simplex_measures, simplex_points

BOUNDARY_DEGREE = 6  # Neumann and contact faces: q and lambda_h are not polynomials
# interior faces per block: at 5.5e5 P1 DOFs (6.4e6 faces) all at once took the level's peak
# from 2.2 GiB (the amg contact solve) to 3.9 GiB
FACE_CHUNK = 500_000


def stress_at(solution: DiscreteSolution, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """sigma(u_h) (3, 3, n) at points x (3, n) of elements ``cells``."""
    grad = gradients_at(solution.elasticity.basis, solution.u, x, cells)
    return stress_tensor_from_gradient(grad, *solution.elasticity.lame)


def stress_divergence_3d(solution: DiscreteSolution, n_points: int) -> np.ndarray:
    """div sigma(u_h) (3, n_elements, n_points) of P2 on tetrahedra: sigma(u_h) is linear, so
    its values at the vertices, differentiated, give the constant divergence."""
    elasticity = solution.elasticity
    vertices = ElementTetP1()
    grad = gradients_at_reference(elasticity.basis, solution.u, vertices.doflocs.T)
    sigma = stress_tensor_from_gradient(grad, *elasticity.lame)  # (3, 3, nE, 4)
    inverse = elasticity.basis.mapping.invA  # (3, 3, nE)
    div = np.zeros((3, inverse.shape[2]))
    for k in range(4):
        _, reference = vertices.lbasis(vertices.doflocs.T[:, :1], k)
        gradient = np.einsum("rde,r->de", inverse, reference[:, 0])  # (3, nE)
        div += np.einsum("ije,je->ie", sigma[:, :, :, k], gradient)
    return np.repeat(div[:, :, None], n_points, axis=2)


def face_data(mesh, facets: np.ndarray, degree: int):
    """Points (3, n * nq), weights w (nq,), areas, diameters and corner points of faces."""
    corners = mesh.p[:, mesh.facets[:, facets]]
    t, w = triangle_rule(degree)
    diameter = np.max([np.linalg.norm(corners[:, i] - corners[:, (i + 1) % 3], axis=0)
                       for i in range(3)], axis=0)
    return simplex_points(corners, t).reshape(3, -1), w, simplex_measures(corners), diameter, \
        corners


def interior_jumps_3d(solution: DiscreteSolution) -> np.ndarray:
    """(h_F / p) (1/2 ||[sigma_n]||_F)^2 added to both tetrahedra of every interior face, in
    blocks of FACE_CHUNK faces (the stresses of all faces at once set a 3D level's peak)."""
    mesh = solution.elasticity.mesh
    interior = np.flatnonzero(mesh.f2t[1] >= 0)
    out = np.zeros(mesh.t.shape[1])
    for start in range(0, interior.size, FACE_CHUNK):
        block = interior[start:start + FACE_CHUNK]
        t1, t2 = mesh.f2t[:, block]
        share = face_jumps(solution, block, t1, t2)
        out += np.bincount(t1, share, out.size) + np.bincount(t2, share, out.size)
    return out


def face_jumps(solution: DiscreteSolution, faces: np.ndarray, t1: np.ndarray,
               t2: np.ndarray) -> np.ndarray:
    """(h_F / p) (1/2 ||[sigma_n]||_F)^2 of the interior ``faces`` between t1 and t2."""
    order = solution.elasticity.order
    x, w, area, h, corners = face_data(solution.elasticity.mesh, faces, 2 * (order - 1))
    nq = w.size
    n = np.repeat(outer_triangle_normals(solution.elasticity.mesh, corners, t1), nq, axis=1)
    jump = stress_at(solution, x, np.repeat(t1, nq)) - stress_at(solution, x, np.repeat(t2, nq))
    jn = np.einsum("ijn,jn->in", jump, n)
    norm2 = ((jn**2).sum(axis=0).reshape(-1, nq) * w).sum(axis=1) * area
    return h / order * 0.25 * norm2


def face_residuals_3d(scene, solution: DiscreteSolution) -> np.ndarray:
    """sum_{F in T} (h_F / p) R_F^2 per tetrahedron."""
    mesh, order = solution.elasticity.mesh, solution.elasticity.order
    n_elements = mesh.t.shape[1]
    out = interior_jumps_3d(solution)
    neumann = scene.neumann_facets(mesh)
    if neumann.size:
        element = mesh.f2t[0, neumann]
        x, w, area, h, corners = face_data(mesh, neumann, BOUNDARY_DEGREE)
        nq = w.size
        n = np.repeat(outer_triangle_normals(mesh, corners, element), nq, axis=1)
        sn = np.einsum("ijn,jn->in", stress_at(solution, x, np.repeat(element, nq)), n)
        if scene.traction is not None:
            sn = sn - scene.traction(x)
        norm2 = ((sn**2).sum(axis=0).reshape(-1, nq) * w).sum(axis=1) * area
        out += np.bincount(element, h / order * norm2, n_elements)
    return out + contact_residuals(solution, lambda x, cells: stress_at(solution, x, cells))


def contact_residuals(solution: DiscreteSolution, sigma_at) -> np.ndarray:
    """(h_F / p) R_F^2 per cell on the contact faces of any 3D contact boundary, with
    ``sigma_at(x, cells)`` the stress of u_h at points of given cells."""
    trace, order = solution.trace, solution.elasticity.order
    t, w = trace.rule(BOUNDARY_DEGREE)
    nq = w.size
    normal = np.repeat(trace.normal, nq, axis=1)
    sigma = sigma_at(trace.points(t).reshape(3, -1), np.repeat(trace.element, nq))
    sn = np.einsum("ijn,jn->in", sigma, normal)
    snn = np.einsum("in,in->n", sn, normal)
    shear = sn - snn * normal
    if solution.friction is not None:  # sigma_nt(u_h) - sigma_t,h (docs/theory.md, 17.5)
        shear = shear - solution.friction.traction(t).reshape(3, -1)
    snt2 = (shear**2).sum(axis=0).reshape(-1, nq)
    normal_part = np.sqrt(trace.integrate((snn.reshape(-1, nq) + solution.pressure(t)) ** 2, w))
    r_f = normal_part + np.sqrt(trace.integrate(snt2, w))
    return np.bincount(trace.element, trace.diameter / order * r_f**2,
                       solution.elasticity.mesh.t.shape[1])


def volume_terms_3d(scene, solution: DiscreteSolution) -> np.ndarray:
    """eta_0^2 per tetrahedron: element and face residuals, over E."""
    def divergence(solution, basis):
        return stress_divergence_3d(solution, basis.dx.shape[1])

    return (element_residual(scene, solution, divergence)
            + face_residuals_3d(scene, solution)) / float(scene.material.young_modulus)


@register_cell_variant("residual", "tet")
def residual_estimate_3d(scene, solution: DiscreteSolution) -> Estimate:
    return combine("residual", volume_terms_3d(scene, solution), contact_terms(scene, solution))


@register_cell_variant("nitsche-residual", "tet")
def nitsche_residual_estimate_3d(scene, solution: DiscreteSolution) -> Estimate:
    return nitsche_estimate(volume_terms_3d(scene, solution))
