"""Equilibrated stress reconstruction on vertex patches (docs/theory.md, section 13.2).

For the auxiliary problem (4) of the seed paper with Neumann data t (q on Gamma_N, -lambda* n on
Gamma_C), each row of the reconstructed stress sigma* is a Raviart-Thomas field RT_k of the
degree k of the displacements (``estimators.guaranteed.raviart_thomas``: normal traces P_k per
facet, divergence P_k per element), built as sigma* = sum_a sigma_a over the mesh vertices a, with
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

from dataclasses import dataclass, replace

import numpy as np
from skfem import FacetBasis

from estimators.guaranteed.patch_condensation import condensed
from estimators.guaranteed.patch_data import Interior, vertex_totals
from estimators.guaranteed.patches import (
    FIXED,
    FREE,
    ZERO,
    PairMatrices,
    index_type,
    layout,
    moved_prescribed,
    solve_patches,
)
from estimators.guaranteed.rt_reference import (
    HATS,
    OPPOSITE_FACET,
    ReferenceRT,
    facet_dof_count,
    rt_element,
)

# the m RT_k DOFs of local facet f (m = facet_dof_count) are m f .. m f + m - 1, the interior
# ones follow.


@dataclass(frozen=True, eq=False)
class Reconstruction:
    """sigma* row by row as RT DOF vectors on ``basis`` (an ``estimators.guaranteed.rt_reference.
    ReferenceRT``; shape (d, basis.N)), the element values
    of sigma* (d, d, n_elements, n_points) at the quadrature points of ``basis``, and how far
    the patch data were from balance (max over patches, relative to the largest patch datum)."""

    basis: ReferenceRT
    dofs: np.ndarray
    values: np.ndarray
    imbalance: float


@dataclass(frozen=True)
class BoundaryData:
    """Neumann data t on boundary ``facets``: ``traction(x)`` gives t (d, n_f, nq) at the points
    x (d, n_f, nq) of those facets (in that order)."""

    facets: np.ndarray
    traction: object


@dataclass(frozen=True, eq=False)
class Flux:
    """Pi_k (psi_a t) on boundary facets for every facet vertex a: the prescribed RT_k DOF
    values (n_f, d vertices, d rows, m facet DOFs), the integrals of psi_a t (n_f, d, d), the
    vertices (d, n_f), the elements (n_f,) and their local facet (n_f,)."""

    values: np.ndarray
    integrals: np.ndarray
    ends: np.ndarray
    elements: np.ndarray
    local: np.ndarray


def boundary_flux(interior: Interior, part: BoundaryData) -> Flux:
    """The ``Flux`` of ``part`` at the RT degree and quadrature of ``interior``."""
    mesh, k, facets, d = interior.rt.mesh, interior.k, part.facets, interior.rt.mesh.dim()
    # no DOF locations: mapping them would cost a pass over every element of the mesh
    fb = FacetBasis(mesh, rt_element(k, d), facets=facets, intorder=interior.intorder,
                    disable_doflocs=True)
    hats = FacetBasis(mesh, HATS[d](), facets=facets, quadrature=fb.quadrature,
                      disable_doflocs=True)
    local = _local_facet(mesh, facets, fb.tind)
    rows = np.arange(facets.size)
    normal_trace = np.array([np.einsum("ifp,ifp->fp", np.asarray(b[0]), fb.normals)
                             for b in fb.basis])            # (n_rt, n_f, nq)
    m = facet_dof_count(k, d)
    own = m * local[None, :] + np.arange(m)[:, None]                   # (m, n_f)
    trace = normal_trace[own, rows[None, :]]                           # (m, n_f, nq)
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


def boundary_balance(n_vertices: int, fluxes: list[Flux], dim: int = 2) -> np.ndarray:
    """int psi_a t (n_vertices, dim) over the boundary."""
    balance = np.zeros((n_vertices, dim))
    for flux in fluxes:
        for v in range(flux.ends.shape[0]):
            np.add.at(balance, flux.ends[v], flux.integrals[:, v])
    return balance


def reconstruct(interior: Interior, fluxes: list[Flux], clamped: np.ndarray,
                condense: bool = False) -> Reconstruction:
    """sigma* of the module docstring for the boundary data ``fluxes``; ``clamped``
    (n_vertices,) marks the vertices on Gamma_D (their patches have no balance condition).
    With ``condense`` the element-interior unknowns are eliminated first
    (``estimators.guaranteed.patch_condensation``; the same sigma* to round-off): what the
    tetrahedral bound asks, where it took the patch problems of a 52 634-tetrahedron `hertz-3d` mesh
    from 22 s to 6.5 s; on triangles, whose patch systems repeat and share one factorisation per
    class, it took `paper`'s 5e5-DOF level from 5.2 s to 7.0 s."""
    rt, k = interior.rt, interior.k
    mesh = rt.mesh
    (corners, n_el), n_v, d = mesh.t.shape, mesh.p.shape[1], mesh.dim()
    patch = mesh.t.T.ravel()                     # pair p = (d + 1) e + i
    dofs = rt.element_dofs.T[np.repeat(np.arange(n_el), corners)]
    status, fixed = pair_status(interior, fluxes)
    pairs = PairMatrices(mass=interior.class_mass, divergence=interior.class_divergence,
                         element_class=interior.classes.of,
                         rhs=interior.rhs.reshape(-1, d, dofs.shape[1]).transpose(0, 2, 1),
                         data=interior.data.reshape(-1, d, interior.data.shape[-1]).transpose(
                             0, 2, 1), fixed=fixed, corners=corners)
    rhs, data = moved_prescribed(status, pairs)
    pairs = replace(pairs, rhs=rhs, data=data)
    holder = facet_holders(mesh, rt.element_dofs, k)
    sigma = np.zeros((d, rt.N))
    if condense:
        n_s = corners * facet_dof_count(k, d)
        reduced, elimination = condensed(pairs, interior.classes, dofs.shape[1] - n_s)
        lay = layout(patch, dofs[:, :n_s], status[:, :n_s],
                     (holder // dofs.shape[1] * n_s + holder % dofs.shape[1])[:, :n_s], n_v)
        free_values = solve_patches(lay, reduced, clamped)
        skeleton = np.where((lay.status == FREE)[..., None],
                            free_values[lay.first[patch][:, None] + lay.local], 0.0)
        inside = elimination.interior(skeleton)[:, : dofs.shape[1] - n_s]
        for r in range(d):
            sigma[r] += np.bincount(dofs[:, n_s:].ravel(), inside[..., r].ravel(),
                                    minlength=rt.N)
    else:
        lay = layout(patch, dofs, status, holder, n_v)
        free_values = solve_patches(lay, pairs, clamped)
    for r in range(d):
        np.add.at(sigma[r], lay.key_dof, free_values[:, r])
        np.add.at(sigma[r], dofs[status == FIXED], fixed[..., r][status == FIXED])
    balance = boundary_balance(n_v, fluxes, d)
    total = vertex_totals(mesh, interior.data)  # from the data the patches solved with
    gap = (total - balance)[~clamped]
    scale = np.abs(total).max() + np.abs(balance).max() + np.finfo(float).tiny
    return Reconstruction(basis=rt, dofs=sigma, values=rt.values(sigma),
                          imbalance=float(np.abs(gap).max(initial=0.0) / scale))


def pair_status(interior: Interior, fluxes: list[Flux]) -> tuple[np.ndarray, np.ndarray]:
    """Per pair and RT slot its status (ZERO on the facet opposite the pair's vertex, FIXED
    where ``fluxes`` prescribe it, else FREE) and the prescribed values (P, n_rt, d)."""
    mesh, k = interior.rt.mesh, interior.k
    (corners, n_el), d = mesh.t.shape, mesh.dim()
    n_rt, m = interior.rhs.shape[-1], facet_dof_count(k, d)
    facet_of_dof = np.concatenate([np.repeat(np.arange(corners), m),
                                   np.full(n_rt - corners * m, -1)])
    status = np.full((corners * n_el, n_rt), FREE, dtype=np.int8)
    status[facet_of_dof[None, :]
           == OPPOSITE_FACET[d][np.tile(np.arange(corners), n_el)][:, None]] = ZERO
    fixed = np.zeros((corners * n_el, n_rt, d))
    for flux in fluxes:
        for v in range(d):
            p = corners * flux.elements + (mesh.t[:, flux.elements]
                                           == flux.ends[v][None, :]).argmax(axis=0)
            for j in range(m):
                status[p, m * flux.local + j] = FIXED
                fixed[p, m * flux.local + j] = flux.values[:, v, :, j]
    return status, fixed


def facet_holders(mesh, element_dofs: np.ndarray, k: int) -> np.ndarray:
    """For every (pair p = (d + 1) e + i, RT slot j) the flat index p' n_rt + j' of the entry that
    represents the same unknown of patch mesh.t[i, e]: for a DOF on a facet, the entry of the
    facet's first element e' (scikit-fem's f2t[0]), which holds the same vertex at its corner
    i' and the same global DOF at the same position along the facet (the facet's DOFs are
    numbered by facet); interior DOFs represent themselves. Entries of a facet opposite the
    pair's vertex are never read (ZERO) and hold some index."""
    n_rt, n_el = element_dofs.shape
    c, m = mesh.t.shape[0], facet_dof_count(k, mesh.dim())     # corners, DOFs per facet
    holder = np.arange(c * n_el * n_rt, dtype=index_type(c * n_el * n_rt)).reshape(c * n_el, n_rt)
    elements = np.arange(n_el)
    for f in range(c):
        facet = mesh.t2f[f]
        moved = np.flatnonzero(mesh.f2t[0, facet] != elements)
        first = mesh.f2t[0, facet[moved]]
        f0 = (mesh.t2f[:, first] == facet[moved][None, :]).argmax(axis=0)
        for corner in range(c):
            i0 = (mesh.t[:, first] == mesh.t[corner, moved][None, :]).argmax(axis=0)
            for i in range(m):
                holder[c * moved + corner, m * f + i] = (c * first + i0) * n_rt + m * f0 + i
    return holder
