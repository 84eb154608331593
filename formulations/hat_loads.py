"""The residual of an iterate tested with the vertex hats: ``load_norm`` builds the
``LoadNorm`` that measures a residual vector as the guaranteed bound's load (docs/theory.md,
18.1; ``formulations.solvers.stopping``)."""

from __future__ import annotations

import numpy as np
from scipy import sparse

from formulations.elasticity import Elasticity
from formulations.solvers.stopping import LoadNorm


def simplex_mesh(elasticity: Elasticity) -> bool:
    """Whether the hats are those of a conforming simplicial mesh (triangles, tetrahedra)."""
    mesh = elasticity.mesh
    return elasticity.constraint is None and mesh.t.shape[0] == mesh.dim() + 1


def hat_rows(elasticity: Elasticity) -> sparse.csr_matrix:
    """H with (H r)_(a,i) = <r, psi_a e_i> for r over the unknowns: row d a + i holds the
    values of the P1 hat psi_a at the Lagrange nodes of component i (its barycentric
    coordinate there, read off the reference nodes of every element)."""
    basis, mesh = elasticity.basis, elasticity.mesh
    d = mesh.dim()
    local = basis.elem.doflocs                                   # (n_local, d) reference
    bary = np.column_stack([1.0 - local.sum(axis=1), local])     # (n_local, d + 1)
    component = np.arange(local.shape[0]) % d                    # u^1, u^2, ... interleaved
    dofs = basis.element_dofs                                    # (n_local, n_el)
    rows = d * mesh.t[:, None, :] + component[None, :, None]     # (d + 1, n_local, n_el)
    cols = np.broadcast_to(dofs[None], rows.shape)
    vals = np.broadcast_to(bary.T[:, :, None], rows.shape)
    keep = vals > 0
    keys, first = np.unique(rows[keep].astype(np.int64) * basis.N + cols[keep],
                            return_index=True)
    H = sparse.csr_matrix((vals[keep][first], (keys // basis.N, keys % basis.N)),
                          shape=(d * mesh.p.shape[1], basis.N))
    return H[:, elasticity.free].tocsr()


def load_norm(elasticity: Elasticity, friedrichs: float) -> LoadNorm | None:
    """The load norm of the elasticity's unknowns with the domain's C_F; None where the hats
    are not those of a conforming simplicial mesh (hanging nodes: no bound to measure in)."""
    if not simplex_mesh(elasticity):
        return None
    mesh = elasticity.mesh
    H = hat_rows(elasticity)
    d, corners = mesh.dim(), mesh.t.shape[0]
    volume = np.abs(elasticity.basis.mapping.detDF(np.zeros((d, 1)))).ravel() / np.prod(
        np.arange(1, d + 1))
    weights = np.bincount(mesh.t.ravel(), np.tile(volume / corners, corners),
                          minlength=mesh.p.shape[1])
    # a hat is a test function where its vertex's DOF is an unknown (off Gamma_D)
    unknown = np.zeros(elasticity.basis.N, dtype=bool)
    unknown[elasticity.free] = True
    rows = np.flatnonzero(unknown[elasticity.basis.nodal_dofs.T.ravel()])
    return LoadNorm(H[rows], np.repeat(weights, d)[rows], float(friedrichs))
