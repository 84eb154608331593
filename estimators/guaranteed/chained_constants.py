"""Trace and Friedrichs constants chained over the triangles of a mesh of the domain
(docs/theory.md, section 13.4, "Trace and Friedrichs constants with a proof").

On each triangle T, v = w_T + r_T with r_T the rigid motion with v's mean and mean rotation
on T (rotation about T's centroid), so that, with a_T = ||grad w_T||_T,

* a_T^2 <= K_T ||eps(v)||_T^2 (Kim's bound, ``estimators.guaranteed.local_korn.element_korn``);
* ||w_T||_T <= P_T a_T, P_T = h_T / pi (Payne and Weinberger, T convex);
* ||w_T||_F^2 <= tau_(T,F)^2 a_T^2 on a side F, tau^2 = (|F| / |T|) (P_T^2 + h_T P_T): from
  int_F phi^2 = |F| / (2 |T|) int_T (2 phi^2 + (x - p) . grad phi^2), p the vertex opposite F.

v is continuous and 0 on Gamma_D, so r_T - r_T' = w_T' - w_T on an interior side and r_T =
-w_T on a clamped one: the rigid motions' jump form J(r) = sum_F ||r_T - r_T'||_F^2 + sum_D
||r_T||_F^2 is at most sum_T c_T a_T^2, c_T = 2 sum_(F interior) tau^2 + sum_(F on Gamma_D)
tau^2. With g_O^2 and g_C^2 the largest eigenvalues of sum_T ||r_T||_T^2 and sum_C ||r_T||_F^2
against J (a matrix pencil over 3 rigid motions per triangle, its entries exact integrals
of quadratics) and s = 2 mu + 2 min(lambda, 0) (a(v, v) >= s ||eps(v)||^2):

    C_F <= ((max_T P_T^2 K_T)^(1/2) + g_O (max_T c_T K_T)^(1/2)) / s^(1/2),
    C_T <= ((max_T w_T K_T)^(1/2) + g_C (max_T c_T K_T)^(1/2)) / s^(1/2),

w_T the sum of tau^2 over T's sides on Gamma_C. No convexity of the domain is needed.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.linalg import eigh
from scipy.sparse.linalg import eigsh

from estimators.averaging import element_areas
from estimators.guaranteed.local_korn import element_korn

DENSE_UNKNOWNS = 3000  # rigid motions (3 per triangle) up to which the pencil is solved densely
OPPOSITE = np.array([2, 0, 1])  # the vertex opposite each side of skfem's t2f order
_SIMPSON = np.array([1.0, 4.0, 1.0]) / 6.0


def rigid_at(x: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Translations and the rotation about ``centre`` (2, m) at points x (2, m, q): (3, 2, m, q)."""
    one, zero = np.ones(x.shape[1:]), np.zeros(x.shape[1:])
    return np.array([[one, zero], [zero, one],
                     [centre[1][:, None] - x[1], x[0] - centre[0][:, None]]])


def strain_floor(lame: tuple[float, float]) -> float:
    """s with a(v, v) >= s ||eps(v)||^2 in 2D: 2 mu + 2 min(lambda, 0) ((tr e)^2 <= 2 |e|^2)."""
    lam, mu = lame
    return 2 * mu + 2 * min(lam, 0.0)


def side_lengths(mesh) -> np.ndarray:
    """The lengths (3, n_el) of the sides opposite each vertex."""
    x = mesh.p[:, mesh.t]
    return np.array([np.linalg.norm(x[:, (i + 1) % 3] - x[:, (i + 2) % 3], axis=0)
                     for i in range(3)])


def element_factors(mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P_T = h_T / pi, K_T and tau^2 (3, n_el) per side in the mesh's t2f order (module
    docstring)."""
    sides = side_lengths(mesh)                                   # opposite vertex i
    h = sides.max(axis=0)
    poincare = h / np.pi
    tau2 = (sides / element_areas(mesh) * (poincare**2 + h * poincare))[OPPOSITE]
    return poincare, element_korn(mesh), tau2


def side_rule(mesh, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Simpson's rule on ``facets``: points (2, m, 3) and weights (m, 3), exact for cubics."""
    a, b = mesh.p[:, mesh.facets[0, facets]], mesh.p[:, mesh.facets[1, facets]]
    points = np.stack([a, 0.5 * (a + b), b], axis=-1)
    return points, np.linalg.norm(b - a, axis=0)[:, None] * _SIMPSON


def triangle_rule(mesh) -> tuple[np.ndarray, np.ndarray]:
    """The edge-midpoint rule on the triangles: points (2, n, 3), weights (n, 3), exact for
    quadratics."""
    x = mesh.p[:, mesh.t]
    points = np.stack([0.5 * (x[:, i] + x[:, (i + 1) % 3]) for i in range(3)], axis=-1)
    return points, np.repeat(element_areas(mesh)[:, None] / 3, 3, axis=1)


def _sparse(blocks: np.ndarray, index: np.ndarray, n: int) -> sp.csr_matrix:
    """Sum of the local matrices ``blocks`` (m, k, k) at the unknowns ``index`` (m, k)."""
    k = index.shape[1]
    return sp.coo_matrix((blocks.ravel(), (np.repeat(index, k, axis=1).ravel(),
                                           np.tile(index, (1, k)).ravel())), shape=(n, n)).tocsr()


def _side_gram(mesh, facets: np.ndarray, centres: np.ndarray, jump: bool):
    """The Gram matrices of r_T (or of r_T - r_T' if ``jump``) on ``facets``, exactly:
    (blocks, unknowns)."""
    points, weights = side_rule(mesh, facets)
    owners = [mesh.f2t[0, facets]] + ([mesh.f2t[1, facets]] if jump else [])
    E = np.concatenate([sign * rigid_at(points, centres[:, t])
                        for sign, t in zip((1.0, -1.0), owners, strict=False)])
    index = np.hstack([3 * t[:, None] + np.arange(3) for t in owners])
    return np.einsum("idmq,jdmq,mq->mij", E, E, weights), index


def jump_form(mesh, centres: np.ndarray, interior: np.ndarray | float,
              clamped: np.ndarray | float, dirichlet: np.ndarray) -> sp.csr_matrix:
    """J(r) = sum_F omega_F ||r_T - r_T'||_F^2 + sum_(Gamma_D) omega_F ||r_T||_F^2 over the
    rigid motions about ``centres`` (3 per triangle), with the weights omega per mesh facet
    (``interior`` inside, ``clamped`` on the ``dirichlet`` facets)."""
    n = 3 * mesh.t.shape[1]
    inner = np.flatnonzero(mesh.f2t[1] >= 0)
    total = sp.csr_matrix((n, n))
    for facets, weight, jump in ((inner, interior, True), (dirichlet, clamped, False)):
        blocks, index = _side_gram(mesh, facets, centres, jump)
        total = total + _sparse(blocks * np.broadcast_to(weight, (mesh.facets.shape[1],))
                                [facets][:, None, None], index, n)
    return total


def _largest(A: sp.csr_matrix, B: sp.csr_matrix) -> float:
    """The largest eigenvalue of A x = g B x, B positive definite."""
    if A.shape[0] <= DENSE_UNKNOWNS:
        return float(eigh(A.toarray(), B.toarray(), eigvals_only=True).max())
    return float(eigsh(A.tocsc(), k=1, M=B.tocsc(), which="LA", return_eigenvectors=False)[0])


def chained_constants(scene, mesh) -> tuple[float, float]:
    """(C_T, C_F) of the module docstring on ``mesh``, a triangulation of the scene's domain."""
    n = mesh.t.shape[1]
    poincare, korn, tau2 = element_factors(mesh)
    on = np.zeros((3, mesh.facets.shape[1]), dtype=bool)
    on[0, mesh.f2t[1] >= 0] = True
    on[1, scene.dirichlet_facets(mesh)] = True
    on[2, scene.contact_facets(mesh)] = True
    interior, clamped, contact = on[:, mesh.t2f]
    chain = (tau2 * (2.0 * interior + clamped)).sum(axis=0) * korn
    touching = (tau2 * contact).sum(axis=0) * korn
    centres = mesh.p[:, mesh.t].mean(axis=1)
    J = jump_form(mesh, centres, 1.0, 1.0, np.flatnonzero(on[1]))
    contact_gram = _sparse(*_side_gram(mesh, np.flatnonzero(on[2]), centres, False), 3 * n)
    points, weights = triangle_rule(mesh)
    E = rigid_at(points, centres)
    mass = _sparse(np.einsum("idmq,jdmq,mq->mij", E, E, weights),
                   3 * np.arange(n)[:, None] + np.arange(3), 3 * n)
    s = strain_floor(scene.material.lame)
    g_domain, g_contact = _largest(mass, J), max(_largest(contact_gram, J), 0.0)
    friedrichs = (np.sqrt((poincare**2 * korn).max()) + np.sqrt(g_domain * chain.max()))
    trace = np.sqrt(touching.max()) + np.sqrt(g_contact * chain.max())
    return float(trace / np.sqrt(s)), float(friedrichs / np.sqrt(s))
