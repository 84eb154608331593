"""The extension d of the guaranteed bound relaxed off Gamma_C (docs/theory.md, section 13.3).

The one-layer fields of ``estimators.guaranteed.contact_extension`` drop to zero across the elements
at Gamma_C, so their energy carries a factor 1/h that the penetration they extend need not have.
Any d in H^1_D with the same trace on Gamma_C gives the same complementarity term B and the same
constraint d . n <= w, so the one kept here is the field of least energy among the continuous
P2 fields with that trace (quadratic per contact facet: the one-layer field's, vertex values
and facet bubble) that vanish on Gamma_D and outside a strip of LAYERS layers of elements at
Gamma_C: a small linear elasticity problem on the strip. The one-layer field is one of them,
so D can only drop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import splu
from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm
from skfem.helpers import ddot, sym_grad
from skfem.helpers import trace as matrix_trace
from skfem.models.elasticity import linear_elasticity

from estimators.guaranteed.contact_extension import Extension

# elements within this many vertex layers of Gamma_C: on `paper`, mixed, P1, 2178 DOFs, D of
# the fitted field 1.534 (one-layer), 1.344, 1.061, 0.981, 0.949, 0.923 for 1, 2, 3, 4, 6
LAYERS = 4


@dataclass(frozen=True, eq=False)
class StripExtension:
    """d with the trace of ``surface`` on Gamma_C and a(d, d) per element ``energies`` (with
    the Lame parameters it was relaxed with)."""

    surface: Extension
    energies: np.ndarray

    def along(self, trace, direction: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self.surface.along(trace, direction, t)

    def energy(self, trace, lame: tuple[float, float]) -> np.ndarray:
        return self.energies


def strip_elements(mesh, vertices: np.ndarray, layers: int) -> np.ndarray:
    """The elements with a vertex within ``layers`` - 1 vertex layers of ``vertices``."""
    near = np.zeros(mesh.p.shape[1], dtype=bool)
    near[vertices] = True
    for _ in range(layers - 1):
        near[mesh.t[:, near[mesh.t].any(axis=0)].ravel()] = True
    return np.flatnonzero(near[mesh.t].any(axis=0))


def strip_basis(trace, layers: int = LAYERS) -> tuple[Basis, np.ndarray, np.ndarray]:
    """Vector P2 on the strip of ``strip_elements`` at Gamma_C as a mesh of its own, with the
    mesh vertices it uses and its elements (indices into the mesh's)."""
    mesh = trace.mesh
    elements = strip_elements(mesh, np.unique(np.concatenate(trace.vertices)), layers)
    used, local_t = np.unique(mesh.t[:, elements], return_inverse=True)
    strip = MeshTri(np.ascontiguousarray(mesh.p[:, used]), local_t.reshape(3, -1))
    return Basis(strip, ElementVector(ElementTriP2())), used, elements


def relaxed(fields: tuple[Extension, ...], trace, lame: tuple[float, float],
            clamped_facets: np.ndarray, layers: int = LAYERS) -> tuple[StripExtension, ...]:
    """The least-energy P2 field of the module docstring for each one-layer field of
    ``fields`` (one factorisation for all: the strip and its fixed DOFs are theirs in common);
    ``clamped_facets`` the facets of Gamma_D."""
    mesh = trace.mesh
    zero = np.zeros(mesh.t.shape[1])
    moving = [i for i, d in enumerate(fields) if np.any(d.nodal) or np.any(d.bubble)]
    energies = [zero] * len(fields)
    if moving:
        basis, used, elements = strip_basis(trace, layers)
        fixed = _fixed_dofs(basis, trace, mesh, used, clamped_facets)
        free = np.setdiff1d(np.arange(basis.N), fixed)
        x = np.array([_surface_values(fields[i], trace, basis, used) for i in moving]).T
        K = asm(linear_elasticity(*lame), basis)
        if free.size:
            x[free] = splu(K[free][:, free].tocsc()).solve(-(K[free][:, fixed] @ x[fixed]))
        for column, i in enumerate(moving):
            energies[i] = zero.copy()
            energies[i][elements] = _element_energies(basis, x[:, column], lame)
    return tuple(StripExtension(d, e) for d, e in zip(fields, energies, strict=True))


def _element_energies(basis, x: np.ndarray, lame: tuple[float, float]) -> np.ndarray:
    lam, mu = lame
    eps = sym_grad(basis.interpolate(x))
    density = 2 * mu * ddot(eps, eps) + lam * matrix_trace(eps) ** 2
    return (density * basis.dx).sum(axis=1)


def _keys(pairs: np.ndarray, n: int) -> np.ndarray:
    pairs = np.sort(pairs, axis=0)
    return pairs[0].astype(np.int64) * n + pairs[1]


def _strip_facets(strip_facets: np.ndarray, used: np.ndarray, wanted: np.ndarray, mesh
                  ) -> np.ndarray:
    """The strip's facets (indices into ``strip_facets``, local vertex pairs) that are the
    mesh facets ``wanted``."""
    n = mesh.p.shape[1]
    return np.flatnonzero(np.isin(_keys(used[strip_facets], n),
                                  _keys(mesh.facets[:, wanted], n)))


def _fixed_dofs(basis, trace, mesh, used, clamped_facets) -> np.ndarray:
    """Every DOF on Gamma_C (the trace), on Gamma_D and on the strip's inner boundary (0)."""
    strip = basis.mesh
    boundary = strip.boundary_facets()
    outer = _strip_facets(strip.facets[:, boundary], used, mesh.boundary_facets(), mesh)
    inner = np.setdiff1d(boundary, boundary[outer])
    contact = _strip_facets(strip.facets, used, trace.facets, mesh)
    clamped = _strip_facets(strip.facets, used, clamped_facets, mesh)
    return np.unique(np.concatenate([basis.get_dofs(f).flatten()
                                     for f in (inner, contact, clamped)]))


def _surface_values(d: Extension, trace, basis, used: np.ndarray) -> np.ndarray:
    """The P2 DOF values of the one-layer field on Gamma_C (zero elsewhere): vertex values,
    and at facet midpoints their mean plus the bubble (4 t (1 - t) = 1 there)."""
    x = np.zeros(basis.N)
    strip, mesh = basis.mesh, trace.mesh
    local = np.full(mesh.p.shape[1], -1)
    local[used] = np.arange(used.size)
    on = np.unique(np.concatenate(trace.vertices))
    for c in (0, 1):
        x[basis.nodal_dofs[c, local[on]]] = d.nodal[c, on]
    facets = _strip_facets(strip.facets, used, trace.facets, mesh)
    order = np.argsort(_keys(mesh.facets[:, trace.facets], mesh.p.shape[1]))
    mine = order[np.searchsorted(_keys(mesh.facets[:, trace.facets], mesh.p.shape[1])[order],
                                 _keys(used[strip.facets[:, facets]], mesh.p.shape[1]))]
    middle = 0.5 * (d.nodal[:, mesh.facets[0, trace.facets[mine]]]
                    + d.nodal[:, mesh.facets[1, trace.facets[mine]]])
    middle += d.bubble[mine] * trace.normal[:, mine]
    for c in (0, 1):
        x[basis.facet_dofs[c, facets]] = middle[c]
    return x
