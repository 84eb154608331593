"""Equilibrated stress reconstruction on vertex patches (docs/theory.md, section 13.2).

For the auxiliary problem (4) of the seed paper with Neumann data t (q on Gamma_N, -lambda* n on
Gamma_C), each row of the reconstructed stress sigma* is a Raviart-Thomas field RT_k of the
degree k of the displacements (``estimators.raviart_thomas``: normal traces P_k per facet,
divergence P_k per element), built as sigma* = sum_a sigma_a over the mesh vertices a, with
sigma_a on the patch omega_a of a:

    minimise ||sigma_a - psi_a sigma_h||_{0, omega_a}   (row by row, Frobenius)
    subject to  div sigma_a = Pi_k (sigma_h grad psi_a - psi_a f)   on every element,
                sigma_a n = 0                   on the facets of the patch opposite to a,
                sigma_a n = Pi_k (psi_a t)      on the facets at a on Gamma_N and Gamma_C,

(Braess-Schoeberl; Ern-Vohralik), psi_a the hat function of a and Pi_k the L2 projection onto
P_k per element or facet. Off Gamma_D the constraints are solvable exactly when the patch data
balance (the translations psi_a e_i are test functions of the discrete problem); the row of one
constant multiplier is then redundant and dropped. The sum satisfies div sigma* + Pi_k f = 0 and
sigma* n = Pi_k t on Gamma_N and Gamma_C. The patches are small dense saddle-point systems, solved
in batches of equal size (no loop over patches).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import ElementTriP1, FacetBasis

from estimators.patch_data import Interior
from estimators.patches import (
    FIXED,
    FREE,
    ZERO,
    PairMatrices,
    index_type,
    layout,
    solve_patches,
)
from estimators.raviart_thomas import ElementTriRTk
from estimators.rt_reference import ReferenceRT

# local facets of scikit-fem's triangles: 0 = (v0, v1), 1 = (v1, v2), 2 = (v0, v2); the k + 1
# RT_k DOFs of local facet f are (k + 1) f .. (k + 1) f + k, the interior ones follow.
_OPPOSITE_FACET = np.array([1, 2, 0])


@dataclass(frozen=True, eq=False)
class Reconstruction:
    """sigma* row by row as RT DOF vectors on ``basis`` (an ``estimators.rt_reference.
    ReferenceRT``; shape (2, basis.N)), the element values
    of sigma* (2, 2, n_elements, n_points) at the quadrature points of ``basis``, and how far
    the patch data were from balance (max over patches, relative to the largest patch datum)."""

    basis: ReferenceRT
    dofs: np.ndarray
    values: np.ndarray
    imbalance: float


@dataclass(frozen=True)
class BoundaryData:
    """Neumann data t on boundary ``facets``: ``traction(x)`` gives t (2, n_f, nq) at the points
    x (2, n_f, nq) of those facets (in that order)."""

    facets: np.ndarray
    traction: object


@dataclass(frozen=True, eq=False)
class Flux:
    """Pi_k (psi_a t) on boundary facets for both facet vertices a: the prescribed RT_k DOF
    values (n_f, 2 vertices, 2 rows, k + 1 facet DOFs), the integrals of psi_a t (n_f, 2, 2),
    the vertices (2, n_f), the elements (n_f,) and their local facet (n_f,)."""

    values: np.ndarray
    integrals: np.ndarray
    ends: np.ndarray
    elements: np.ndarray
    local: np.ndarray


def boundary_flux(interior: Interior, part: BoundaryData) -> Flux:
    """The ``Flux`` of ``part`` at the RT degree and quadrature of ``interior``."""
    mesh, k, facets = interior.rt.mesh, interior.k, part.facets
    # no DOF locations: mapping them would cost a pass over every element of the mesh
    fb = FacetBasis(mesh, ElementTriRTk(k), facets=facets, intorder=interior.intorder,
                    disable_doflocs=True)
    hats = FacetBasis(mesh, ElementTriP1(), facets=facets, quadrature=fb.quadrature,
                      disable_doflocs=True)
    local = _local_facet(mesh, facets, fb.tind)
    rows = np.arange(facets.size)
    normal_trace = np.array([np.einsum("ifp,ifp->fp", np.asarray(b[0]), fb.normals)
                             for b in fb.basis])            # (8, n_f, nq)
    own = (k + 1) * local[None, :] + np.arange(k + 1)[:, None]         # (k + 1, n_f)
    trace = normal_trace[own, rows[None, :]]                           # (k + 1, n_f, nq)
    gram = np.einsum("jfp,lfp,fp->fjl", trace, trace, fb.dx)
    x = np.asarray(fb.global_coordinates())
    t = part.traction(x)
    ends = mesh.facets[:, facets]
    vertex_local = (mesh.t[:, fb.tind][None, :, :] == ends[:, None, :]).argmax(axis=1)
    psi = np.array([np.asarray(b[0]) for b in hats.basis])[vertex_local, rows[None, :]]
    moments = np.einsum("vfp,rfp,jfp,fp->fvrj", psi, t, trace, fb.dx)
    values = np.linalg.solve(gram[:, None, None], moments[..., None])[..., 0]
    return Flux(values=values, integrals=np.einsum("vfp,rfp,fp->fvr", psi, t, fb.dx),
                ends=ends, elements=fb.tind, local=local)


def _local_facet(mesh, facets: np.ndarray, elements: np.ndarray) -> np.ndarray:
    return (mesh.t2f[:, elements] == facets[None, :]).argmax(axis=0)


def boundary_fluxes(interior: Interior, boundary: list[BoundaryData]) -> list[Flux]:
    """The ``Flux`` of every part with facets."""
    return [boundary_flux(interior, part) for part in boundary if part.facets.size]


def boundary_balance(n_vertices: int, fluxes: list[Flux]) -> np.ndarray:
    """int psi_a t (n_vertices, 2) over the boundary."""
    balance = np.zeros((n_vertices, 2))
    for flux in fluxes:
        for v in (0, 1):
            np.add.at(balance, flux.ends[v], flux.integrals[:, v])
    return balance


def reconstruct(interior: Interior, fluxes: list[Flux],
                clamped: np.ndarray) -> Reconstruction:
    """sigma* of the module docstring for the boundary data ``fluxes``; ``clamped``
    (n_vertices,) marks the vertices on Gamma_D (their patches have no balance condition)."""
    rt, k = interior.rt, interior.k
    mesh = rt.mesh
    n_el, n_v = mesh.t.shape[1], mesh.p.shape[1]
    patch = mesh.t.T.ravel()                     # pair p = 3 e + i
    element = np.repeat(np.arange(n_el), 3)
    dofs = rt.element_dofs.T[element]
    n_rt, n_dg = interior.rhs.shape[-1], interior.data.shape[-1]
    facet_of_dof = np.concatenate([np.repeat(np.arange(3), k + 1), np.full(k * (k + 1), -1)])
    status = np.full((patch.size, n_rt), FREE, dtype=np.int8)
    status[facet_of_dof[None, :] == _OPPOSITE_FACET[np.tile(np.arange(3), n_el)][:, None]] = ZERO
    fixed = np.zeros((patch.size, n_rt, 2))
    for flux in fluxes:
        for v in (0, 1):
            p = 3 * flux.elements + (mesh.t[:, flux.elements]
                                     == flux.ends[v][None, :]).argmax(axis=0)
            for j in range(k + 1):
                status[p, (k + 1) * flux.local + j] = FIXED
                fixed[p, (k + 1) * flux.local + j] = flux.values[:, v, :, j]
    balance = boundary_balance(n_v, fluxes)
    pairs = PairMatrices(mass=interior.class_mass, divergence=interior.class_divergence,
                         element_class=interior.classes.of,
                         rhs=interior.rhs.reshape(-1, 2, n_rt).transpose(0, 2, 1),
                         data=interior.data.reshape(-1, 2, n_dg).transpose(0, 2, 1), fixed=fixed)
    lay = layout(patch, dofs, status, facet_holders(mesh, rt.element_dofs, k), n_v)
    free_values = solve_patches(lay, pairs, clamped)
    sigma = np.zeros((2, rt.N))
    for r in (0, 1):
        np.add.at(sigma[r], lay.key_dof, free_values[:, r])
        np.add.at(sigma[r], dofs[status == FIXED], fixed[..., r][status == FIXED])
    values = rt.values(sigma)
    gap = (interior.total - balance)[~clamped]
    scale = np.abs(interior.total).max() + np.abs(balance).max() + np.finfo(float).tiny
    return Reconstruction(basis=rt, dofs=sigma, values=values,
                          imbalance=float(np.abs(gap).max(initial=0.0) / scale))


def facet_holders(mesh, element_dofs: np.ndarray, k: int) -> np.ndarray:
    """For every (pair p = 3 e + i, RT slot j) the flat index p' n_rt + j' of the entry that
    represents the same unknown of patch mesh.t[i, e]: for a DOF on a facet, the entry of the
    facet's first element e' (scikit-fem's f2t[0]), which holds the same vertex at its corner
    i' and the same global DOF at the same position along the facet (the facet's DOFs are
    numbered by facet); interior DOFs represent themselves. Entries of a facet opposite the
    pair's vertex are never read (ZERO) and hold some index."""
    n_rt, n_el = element_dofs.shape
    holder = np.arange(3 * n_el * n_rt, dtype=index_type(3 * n_el * n_rt)).reshape(3 * n_el, n_rt)
    elements = np.arange(n_el)
    for f in range(3):
        facet = mesh.t2f[f]
        moved = np.flatnonzero(mesh.f2t[0, facet] != elements)
        first = mesh.f2t[0, facet[moved]]
        f0 = (mesh.t2f[:, first] == facet[moved][None, :]).argmax(axis=0)
        for corner in range(3):
            i0 = (mesh.t[:, first] == mesh.t[corner, moved][None, :]).argmax(axis=0)
            for i in range(k + 1):
                holder[3 * moved + corner, (k + 1) * f + i] = ((3 * first + i0) * n_rt
                                                               + (k + 1) * f0 + i)
    return holder
