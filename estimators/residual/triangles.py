"""``residual``: the paper's eta of (8) with the residual eta_0 of its section 5 (on
tetrahedra: ``estimators.residual.tetrahedra``).

eta_0^2 = sum_T ( (h_T/p)^2 R_{0,T}^2 + sum_{e in E_T} (h_e/p) R_{0,e}^2 ),
R_{0,T} = ||f + div sigma(u_h)||_{0,T},
R_{0,e} = 1/2 ||[sigma_n(u_h)]||_e (interior), ||sigma_n(u_h) - q||_e (Gamma_N),
          ||sigma_nn(u_h) + lambda_h||_e + ||sigma_nt(u_h) - sigma_t,h||_e (Gamma_C), 0 on
          Gamma_D, with sigma_t,h the discrete shear traction with friction (0 without).
For P1, sigma(u_h) is constant per element, so div sigma(u_h) = 0 and the jumps are constant
along each edge. h_T is the element diameter, h_e the edge length, p the polynomial order (the
hp weights of Melenk and Wohlmuth; docs/theory.md, section 9).

Units: the residuals are stresses, so sum h^2 R^2 scales like E ||u - u_h||^2. We report
eta_0^2 = (1/E) sum_T (...) so that eta_0 is in energy-norm units and the effectivity index does
not depend on Young's modulus; for E = 1 this is exactly the paper's formula (its "<~" hides
material constants, so rates and marking are unaffected by the weight).
"""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementTetP0, ElementTriP0

from estimators.base import Estimate, combine, register_estimator
from estimators.contact_terms import contact_terms
from formulations import DiscreteSolution
from formulations.cells.evaluation import gradients_at, gradients_at_reference
from formulations.contact.edges import outer_normals
from formulations.contact.reference_facets import gauss_legendre
from formulations.elasticity import ELEMENTS, element_diameters, stress_from_gradient

EDGE_QUADRATURE_POINTS = 4  # Neumann and contact edges: q and lambda_h are not polynomials


def stress_tensor(stress: np.ndarray) -> np.ndarray:
    """(s11, s22, s12, ...) as the symmetric 2 x 2 tensor (2, 2, ...)."""
    s11, s22, s12 = stress
    return np.array([[s11, s12], [s12, s22]])


def stress_at(solution: DiscreteSolution, x: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """sigma(u_h) (2, 2, n) at points x (2, n) of elements ``cells``."""
    grad = gradients_at(solution.elasticity.basis, solution.u, x, cells)
    return stress_tensor(stress_from_gradient(grad, *solution.elasticity.lame))


def stress_divergence(solution: DiscreteSolution, basis: Basis) -> np.ndarray:
    """div sigma(u_h) (2, n_elements, n_points) at the quadrature points of ``basis``: grad u_h
    is written exactly in the discontinuous P_(p-1) space (its values at that element's nodes)
    and differentiated there, through each element's inverse Jacobian."""
    elasticity = solution.elasticity
    scalar = ELEMENTS[elasticity.order - 1]()  # sigma(u_h) is in its discontinuous space
    grad = gradients_at_reference(elasticity.basis, solution.u, scalar.doflocs.T)
    sigma = stress_tensor(stress_from_gradient(grad, *elasticity.lame))  # (2, 2, nE, nk)
    inverse = elasticity.basis.mapping.invA  # (2, 2, nE): affine triangles
    X = basis.quadrature[0]
    div = np.zeros((2, elasticity.mesh.t.shape[1], X.shape[1]))
    for k in range(sigma.shape[3]):
        _, reference = scalar.lbasis(X, k)  # (2, nq)
        gradient = np.einsum("rde,rq->deq", inverse, reference)  # of node k's function
        for i in (0, 1):
            div[i] += (sigma[i, :, :, k][:, :, None] * gradient).sum(axis=0)
    return div


def element_residual(scene, solution: DiscreteSolution, divergence=None) -> np.ndarray:
    """(h_T / p)^2 ||f + div sigma(u_h)||_T^2 per triangle or tetrahedron (div sigma(u_h) = 0
    for P1); ``divergence(solution, basis)`` gives div sigma(u_h) at the basis's points
    (default: ``stress_divergence``, on triangles)."""
    elasticity = solution.elasticity
    mesh, order = elasticity.mesh, elasticity.order
    if scene.body_force is None and order == 1:
        return np.zeros(mesh.t.shape[1])
    # scikit-fem's default rule for P_p; a scalar P0 basis carries it (dx and the points)
    # without the vector basis functions nothing here reads
    d = mesh.dim()
    basis = Basis(mesh, ElementTriP0() if d == 2 else ElementTetP0(), intorder=2 * order)
    residual = np.zeros((d,) + basis.dx.shape)
    if scene.body_force is not None:
        residual += scene.body_force(np.asarray(basis.global_coordinates()))
    if order > 1:
        residual += (divergence or stress_divergence)(solution, basis)
    norm2 = ((residual**2).sum(axis=0) * basis.dx).sum(axis=1)
    return (element_diameters(mesh) / order) ** 2 * norm2


def edge_points(mesh, facets: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points at local coordinates t of mesh facets, shape (2, n_facets * len(t))."""
    a, b = mesh.p[:, mesh.facets[0, facets]], mesh.p[:, mesh.facets[1, facets]]
    return (a[:, :, None] + (b - a)[:, :, None] * t[None, None, :]).reshape(2, -1)


def interior_jumps(solution: DiscreteSolution) -> np.ndarray:
    """(h_e / p) (1/2 ||[sigma_n]||_e)^2 added to both elements of every interior edge, with
    p Gauss points per edge (exact: the jump has degree p - 1)."""
    mesh, order = solution.elasticity.mesh, solution.elasticity.order
    n_elements = mesh.t.shape[1]
    interior = np.flatnonzero(mesh.f2t[1] >= 0)
    t1, t2 = mesh.f2t[:, interior]
    h, n = outer_normals(mesh, *mesh.facets[:, interior], t1)  # sign irrelevant for the jump
    t, w = gauss_legendre(order)
    x = edge_points(mesh, interior, t)
    jump = (stress_at(solution, x, np.repeat(t1, t.size))
            - stress_at(solution, x, np.repeat(t2, t.size)))
    jn = np.einsum("ijn,jn->in", jump, np.repeat(n, t.size, axis=1))
    norm2 = ((jn**2).sum(axis=0).reshape(-1, t.size) * w).sum(axis=1) * h
    share = h / order * 0.25 * norm2
    return np.bincount(t1, share, n_elements) + np.bincount(t2, share, n_elements)


def edge_residuals(scene, solution: DiscreteSolution) -> np.ndarray:
    """sum_{e in E_T} (h_e / p) R_{0,e}^2 per element."""
    mesh, order = solution.elasticity.mesh, solution.elasticity.order
    n_elements = mesh.t.shape[1]
    out = interior_jumps(solution)
    t, w = gauss_legendre(EDGE_QUADRATURE_POINTS)
    nq = t.size
    neumann = scene.neumann_facets(mesh)
    if neumann.size:
        element = mesh.f2t[0, neumann]
        h, n = outer_normals(mesh, *mesh.facets[:, neumann], element)
        sigma = stress_at(solution, edge_points(mesh, neumann, t), np.repeat(element, nq))
        sn = np.einsum("ijn,jn->in", sigma, np.repeat(n, nq, axis=1)).reshape(2, -1, nq)
        if scene.traction is not None:
            sn = sn - scene.traction(scene.facet_points(neumann, t, mesh))
        norm2 = ((sn**2).sum(axis=0) * w).sum(axis=1) * h
        out += np.bincount(element, h / order * norm2, n_elements)

    trace = solution.trace
    normal = np.repeat(trace.normal, nq, axis=1)
    sigma = stress_at(solution, trace.points(t).reshape(2, -1), np.repeat(trace.element, nq))
    sn = np.einsum("ijn,jn->in", sigma, normal)
    snn = np.einsum("in,in->n", sn, normal)
    # sigma_nt(u_h) - sigma_t,h along t = n turned by +90 degrees (sigma_t,h = 0 frictionless)
    snt = np.einsum("in,in->n", sn, np.array([-normal[1], normal[0]])).reshape(-1, nq)
    if solution.friction is not None:
        snt = snt - solution.friction.traction(t)
    normal_part = np.sqrt(trace.integrate((snn.reshape(-1, nq) + solution.pressure(t)) ** 2, w))
    r_e = normal_part + np.sqrt(trace.integrate(snt**2, w))
    out += np.bincount(trace.element, trace.length / order * r_e**2, n_elements)
    return out


@register_estimator("residual", "residual eta_0 (seed paper, section 5) plus the geometric and "
                                "complementarity contact terms of eq. (8); with friction the "
                                "shear residual and the friction complementarity",
                    friction=(2, 3))
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    return combine("residual", volume_terms(scene, solution), contact_terms(scene, solution))


def volume_terms(scene, solution: DiscreteSolution) -> np.ndarray:
    """eta_0^2 per triangle: element and edge residuals, over E (tetrahedra:
    ``estimators.residual.tetrahedra``)."""
    young = float(scene.material.young_modulus)
    return (element_residual(scene, solution) + edge_residuals(scene, solution)) / young
