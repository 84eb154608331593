"""Static condensation of the element-interior unknowns of the vertex-patch problems
(docs/theory.md, section 14.5).

On an element, the RT_k DOFs inside it (I) and the multipliers of its divergence constraint
against the P_k DG functions q_1 .. q_(n-1) (L) couple to nothing outside it: the patch's other
elements see only the facet DOFs (S) and the constraint against the constant 1 = sum_l q_l
(the DG basis is nodal, a partition of unity, so this row is the sum of the rows). That row is
zero on I (int_T div phi = int_dT phi . n = 0 for an interior phi), and

    K = [M_II  B_LI'; B_LI  0]

is invertible: div maps the interior functions onto the mean-free P_k, and no combination of
q_1 .. q_(n-1) is constant. Eliminating E = (I, L) element by element leaves each patch a
system in S and one multiplier per element (on tetrahedra at k = 1: 12 facet DOFs and 1
multiplier per element instead of 15 and 4), with the element matrix M_SS - A_ES' K^-1 A_ES,
A_ES = [M_IS; B_LS], and the right-hand side b_S - A_ES' K^-1 b_E; then x_E = K^-1 (b_E -
A_ES x_S) element by element.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.guaranteed.patch_classes import Classes
from estimators.guaranteed.patches import PairMatrices


@dataclass(frozen=True, eq=False)
class Elimination:
    """Per class of elements: ``inverse`` K^-1 (n_classes, n_e, n_e) and ``coupling`` A_ES
    (n_classes, n_e, n_s); per pair, ``local`` b_E (P, n_e, d); ``classes`` the element
    classes and ``corners`` the pairs per element (pair p belongs to element p // corners)."""

    inverse: np.ndarray
    coupling: np.ndarray
    local: np.ndarray
    classes: Classes
    corners: int

    def solved(self, right: np.ndarray) -> np.ndarray:
        """K^-1 right for ``right`` (P, n_e, d)."""
        return per_element(self.classes, self.inverse, right, self.corners)

    def interior(self, skeleton: np.ndarray) -> np.ndarray:
        """x_E (P, n_e, d) of every pair from its facet unknowns x_S (P, n_s, d), zero where
        not FREE (prescribed values are already in b_E)."""
        coupled = per_element(self.classes, self.coupling, skeleton, self.corners)
        return self.solved(self.local - coupled)


def per_element(classes: Classes, matrices: np.ndarray, right: np.ndarray,
                corners: int) -> np.ndarray:
    """matrices[class of the pair's element] @ right[pair] for ``matrices`` (n_classes, m,
    n) and ``right`` (P, n, d): the pairs of an element are the columns of one product per
    element, or per class where classes repeat (``Classes.products``)."""
    n_pairs, n, d = right.shape
    by_element = right.reshape(-1, corners, n, d).transpose(0, 2, 1, 3)
    flat = by_element.reshape(-1, n, corners * d)[classes.order]
    out = np.empty((flat.shape[0], matrices.shape[1], corners * d))
    out[classes.order] = classes.products(matrices, flat)
    return out.reshape(-1, matrices.shape[1], corners, d).transpose(0, 2, 1, 3).reshape(
        n_pairs, matrices.shape[1], d)


def condensed(pairs: PairMatrices, classes: Classes,
              n_interior: int) -> tuple[PairMatrices, Elimination]:
    """The patch data of the facet DOFs (the first n_rt - ``n_interior`` slots) and the
    constant multipliers, and the elimination that recovers the rest; ``pairs`` with the
    prescribed values already moved to the right
    (``estimators.guaranteed.patches.moved_prescribed``)."""
    n_rt, n_s = pairs.mass.shape[1], pairs.mass.shape[1] - n_interior
    M, B, rhs, data = pairs.mass, pairs.divergence, pairs.rhs, pairs.data
    interior = slice(n_s, n_rt)
    constant = B.sum(axis=1, keepdims=True)
    constant[:, :, interior] = 0.0          # int_T div phi_I = 0: round-off removed
    K = np.block([[M[:, interior, interior], B[:, 1:, interior].transpose(0, 2, 1)],
                  [B[:, 1:, interior], np.zeros((M.shape[0],) + (B.shape[1] - 1,) * 2)]])
    coupling = np.concatenate([M[:, interior, :n_s], B[:, 1:, :n_s]], axis=1)
    inverse = np.linalg.inv(K)
    schur = M[:, :n_s, :n_s] - coupling.transpose(0, 2, 1) @ inverse @ coupling
    elimination = Elimination(inverse=inverse, coupling=coupling,
                              local=np.concatenate([rhs[:, interior], data[:, 1:]], axis=1),
                              classes=classes, corners=pairs.corners)
    solved = elimination.solved(elimination.local)
    reduced_rhs = rhs[:, :n_s] - per_element(classes, coupling.transpose(0, 2, 1), solved,
                                             pairs.corners)
    reduced = PairMatrices(mass=0.5 * (schur + schur.transpose(0, 2, 1)), divergence=constant[
        :, :, :n_s], element_class=pairs.element_class, rhs=reduced_rhs,
        data=data.sum(axis=1, keepdims=True), fixed=pairs.fixed[:, :n_s], corners=pairs.corners)
    return reduced, elimination
