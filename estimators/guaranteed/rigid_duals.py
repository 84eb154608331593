"""Dual norms of a load, of a negative contact traction and of Tresca friction's excess shear
on H^1_D, chained over the triangles of the mesh (docs/theory.md, section 13.4, "Localised dual
norms").

For v in H^1_D split on each triangle as in ``estimators.guaranteed.chained_constants``
(v = w_T + r_T, a_T = ||grad w_T||_T <= K_T^(1/2) ||eps(v)||_T), a functional
l(v) = (rho, v) + (lambda, v . n) splits into l(w) + l(r). The first part is local:

    (rho, w_T)_T <= ||rho||_T P_T a_T,    (lambda, w_T . n)_F <= ||lambda||_F tau_(T,F) a_T.

The second is a linear form on the rigid motions, l(r) = m . r, bounded by the weighted jump
form J_w(r) = sum_F omega_F ||r_T - r_T'||_F^2 + sum_(Gamma_D) omega_F ||r_T||_F^2 with
omega_F = 1 / (2 max(tau^2 K) of its two sides) inside and 1 / (tau^2 K_T) on Gamma_D: each
side's term is then at most ||eps(v)||^2 of its triangles, a triangle has three sides, so
J_w(r) <= 3 ||eps(v)||^2 and m . r <= (m . J_w^-1 m)^(1/2) 3^(1/2) ||eps(v)||. With
a(v, v) >= s ||eps(v)||^2:

    l(v) <= ((sum_T (local_T)^2 K_T)^(1/2) + (3 m . J_w^-1 m)^(1/2)) ||v|| / s^(1/2).

Where rho and lambda are rough on the scale of the mesh (as Nitsche's unbalanced patches and
a negative traction on a coarse contact zone are), this is far below the global C_F ||rho|| and
C_T ||lambda||: one sparse factorisation of 3 unknowns per triangle pays for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.guaranteed.chained_constants import (
    element_factors,
    jump_form,
    rigid_at,
    strain_floor,
    triangle_rule,
)
from formulations.friction.slack import contact_tangent
from formulations.solvers.backends import factorise


@dataclass(frozen=True, eq=False)
class RigidChain:
    """The data of the module docstring on one mesh."""

    mesh: object
    centres: np.ndarray   # (2, n_el) the triangles' centroids
    poincare: np.ndarray  # P_T = h_T / pi
    korn: np.ndarray      # K_T
    tau2: np.ndarray      # (3, n_el) tau^2 per side, in the mesh's t2f order
    solve: object         # J_w^-1, by the default direct back-end
    stiffness: float      # s

    @staticmethod
    def of(scene, mesh, lame: tuple[float, float]) -> RigidChain:
        poincare, korn, tau2 = element_factors(mesh)
        worst = np.zeros(mesh.facets.shape[1])
        np.maximum.at(worst, mesh.t2f.ravel(), (tau2 * korn).ravel())
        centres = mesh.p[:, mesh.t].mean(axis=1)
        J = jump_form(mesh, centres, 0.5 / worst, 1.0 / worst, scene.dirichlet_facets(mesh))
        return RigidChain(mesh, centres, poincare, korn, tau2, factorise(J.tocsc()),
                          strain_floor(lame))

    def bound(self, local: np.ndarray, moments: np.ndarray) -> float:
        """sup l(v) / ||v|| for l with the local parts ``local`` (n_el,) (||rho||_T P_T +
        sum_F ||lambda||_F tau_F) and the rigid moments ``moments`` (n_el, 3)."""
        m = moments.ravel()
        rigid = np.sqrt(3.0 * max(float(m @ self.solve(m)), 0.0))
        return float((np.sqrt((local**2 * self.korn).sum()) + rigid) / np.sqrt(self.stiffness))

    def load(self, rho) -> float:
        """The bound for the balancing load ``rho``
        (``estimators.guaranteed.patch_data.BalancingLoad``: a continuous P1 field and its
        squared norms per element)."""
        local = rho.nodal[self.mesh.t]                                   # (3, n_el, 2)
        points, weights = triangle_rule(self.mesh)                       # edge midpoints
        values = np.stack([0.5 * (local[i] + local[(i + 1) % 3]) for i in range(3)], axis=-1)
        moments = np.einsum("idnq,ndq,nq->ni", rigid_at(points, self.centres), values, weights)
        return self.bound(np.sqrt(rho.squares) * self.poincare, moments)

    def facet_local(self, trace, values: np.ndarray, w: np.ndarray) -> np.ndarray:
        """sum_F ||g||_F tau_(T,F) per triangle for g given at the points of weights w of
        each contact facet of ``trace``, ``values`` (n_facets, nq)."""
        owner = trace.element
        side = np.argmax(self.mesh.t2f[:, owner] == trace.facets, axis=0)
        norms = np.sqrt(trace.integrate(values**2, w))
        return np.bincount(owner, norms * np.sqrt(self.tau2[side, owner]), self.mesh.t.shape[1])

    def traction(self, trace, values: np.ndarray, t: np.ndarray, w: np.ndarray) -> float:
        """The bound for a normal traction on Gamma_C given at the points t (weights w) of
        each contact facet of ``trace``: ``values`` (n_facets, nq)."""
        n_el, owner = self.mesh.t.shape[1], trace.element
        r = rigid_at(trace.points(t), self.centres[:, owner])            # (3, 2, n_f, nq)
        along = np.einsum("idfq,df->ifq", r, trace.normal)
        per_facet = (along * (values * w)[None]).sum(axis=-1) * trace.length   # (3, n_f)
        moments = np.stack([np.bincount(owner, per_facet[i], n_el) for i in range(3)], axis=1)
        return self.bound(self.facet_local(trace, values, w), moments)

    def absolute_tangential(self, trace, values: np.ndarray, w: np.ndarray) -> float:
        """The bound for v -> int_(Gamma_C) g |v . t| with g >= 0 given as in ``traction``
        and t the facets' tangents (the excess shear of Tresca friction, docs/theory.md
        17.5). The functional is not linear, but the rigid part of v . t is constant on a
        straight facet, m_F . r_T, so sum_F G_F |m_F . r_T| (G_F = int_F g) is at most
        sum_F G_F (m_F . J_w^-1 m_F)^(1/2) J_w(r)^(1/2): one solve per facet where g > 0."""
        owner, n_rigid = trace.element, 3 * self.mesh.t.shape[1]
        weights = trace.integrate(values, w)
        live = np.flatnonzero(weights > 0)
        middle = trace.points(np.array([0.5]))[:, live, 0]
        r = rigid_at(middle[:, :, None], self.centres[:, owner[live]])[..., 0]   # (3, 2, k)
        tangent = contact_tangent(trace)[:, live]
        m = np.einsum("idk,dk->ki", r, tangent)                          # (k, 3)
        rigid = 0.0
        # 32 right-hand sides at a time: 3 n_el x 32 doubles, 77 MB at 1e5 triangles
        for start in range(0, live.size, 32):
            chunk = np.arange(start, min(start + 32, live.size))
            rhs = np.zeros((n_rigid, chunk.size))
            rows = 3 * owner[live[chunk]][:, None] + np.arange(3)
            rhs[rows, np.arange(chunk.size)[:, None]] = m[chunk]
            dual = np.maximum((rhs * self.solve(rhs)).sum(axis=0), 0.0)
            rigid += float(weights[live[chunk]] @ np.sqrt(3.0 * dual))
        local = self.facet_local(trace, values, w)
        return float((np.sqrt((local**2 * self.korn).sum()) + rigid) / np.sqrt(self.stiffness))
