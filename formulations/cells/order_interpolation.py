"""Nodal interpolation between two vector Lagrange spaces on one mesh (docs/theory.md, 20.3):
the operator that takes the DOFs of a field of ``source`` to the DOFs of its interpolant in
``target``, for every order and cell family alike. A target DOF is a point value of one
component, so row i is the source's basis functions evaluated at the target's DOF location i in
one element that holds it (a continuous field has one value there). From order p to p + 1 it is
the exact embedding; from p + 1 to p the Lagrange interpolant i_h that filters a dual-weighted
residual.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from skfem import Basis

from formulations.cells.evaluation import drop_roundoff, evaluate_at


def dof_cells(basis: Basis) -> np.ndarray:
    """One element holding each DOF of ``basis`` (the last one that lists it)."""
    cells = np.empty(basis.N, dtype=np.int64)
    elements = np.broadcast_to(np.arange(basis.nelems), basis.element_dofs.shape)
    cells[basis.element_dofs.ravel()] = elements.ravel()
    return cells


def interpolation_matrix(source: Basis, target: Basis) -> sparse.csr_matrix:
    """I (target.N x source.N): I u is the target DOF vector of the nodal interpolant of the
    source field u. Both bases are vector Lagrange bases on the same mesh (scikit-fem's
    component-interleaved DOFs: local DOF k is component k mod d)."""
    if source.mesh is not target.mesh and source.mesh.t.shape != target.mesh.t.shape:
        raise ValueError("source and target bases are not on the same mesh")
    d = source.mesh.dim()
    cells = dof_cells(target)
    # the component of each target DOF: its local index in its element, mod d
    local = np.empty(target.N, dtype=np.int64)
    positions = np.broadcast_to(np.arange(target.element_dofs.shape[0])[:, None],
                                target.element_dofs.shape)
    local[target.element_dofs.ravel()] = positions.ravel()
    direction = np.eye(d)[:, local % d]
    evaluation = evaluate_at(source, target.doflocs, cells)
    return drop_roundoff(evaluation.matrix(direction))
