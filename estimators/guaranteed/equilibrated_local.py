"""``equilibrated-local``: the bound of ``equilibrated`` with its three constants, discrete
eigenvalues computed from below, replaced by constants proved from the geometry
(docs/theory.md, section 13.4, "Local Korn constants" and "Trace and Friedrichs constants
with a proof").

* sigma* is weakly symmetric: its skew part is orthogonal to the continuous piecewise linear
  functions (``estimators.guaranteed.weak_symmetry``). Then, for v in H^1_D, with the vertex
  patches' constants K_z of ``estimators.guaranteed.local_korn`` and the hat functions psi_z,

      (skw sigma*, skw grad v) = sum_z (psi_z skw sigma*, skw grad v - c_z)
          <= sum_z ||psi_z^(1/2) skw sigma*|| (K_z - 1)^(1/2) ||eps(v)||_(omega_z)
          <= ((d + 1) / (2 mu) sum_z (K_z - 1) ||psi_z^(1/2) skw sigma*||^2)^(1/2) ||v||

  (every element lies in d + 1 patches; a(v, v) >= 2 mu ||eps(v)||^2 as lambda >= 0).
* The data oscillation is orthogonal to P_k, which holds the rigid motions, so on an element
  (f - Pi_k f, v)_T = (f - Pi_k f, v - r)_T with r the rigid motion that gives v - r zero
  mean and zero mean rotation: ||v - r||_T <= (h_T / pi) K_T^(1/2) ||eps(v)||_T, and the same
  factor (K_T / (2 mu))^(1/2) on the facet terms. The sub-triangles of an element f jumps in
  are similar to it (uniform refinement), so they share its K_T.
* Where f jumps, tau's skew part has zero mean on every such element and is charged with
  ((K_T - 1) / (2 mu))^(1/2) (``estimators.guaranteed.jump_equilibration``).

* C_T and C_F (the negative traction and the balancing load) are those of
  ``estimators.guaranteed.proved_constants``, from the domain's geometry: no constant is computed
  from below.
"""

from __future__ import annotations

import functools

import numpy as np
from skfem import Basis, ElementTriP1

from estimators.base import register_estimator
from estimators.guaranteed.bounded_shear import l2_excess_term
from estimators.guaranteed.equilibrated import (
    BALANCE_TOLERANCE,
    DualNorms,
    NotEquilibrated,
    compliance_squares,
    equilibrate,
    friction_of,
    smallest,
    tresca_only_for,
)
from estimators.guaranteed.guaranteed_contact import QUADRATURE
from estimators.guaranteed.guaranteed_friction import shear_excess
from estimators.guaranteed.jump_equilibration import jump_oscillation
from estimators.guaranteed.local_korn import element_korn, vertex_korn
from estimators.guaranteed.oscillation import oscillation
from estimators.guaranteed.proved_constants import proved_constants
from estimators.guaranteed.rigid_duals import RigidChain
from estimators.guaranteed.weak_symmetry import weakly_symmetrised
from formulations import DiscreteSolution
from formulations.contact.reference_facets import gauss_legendre

NAME = "equilibrated-local"


def skew_squares(rec, korn: np.ndarray, mu: float) -> np.ndarray:
    """(d + 1) / (2 mu) sum_z (K_z - 1) ||psi_z^(1/2) skw sigma*||_T^2 per element, with
    |skw sigma|^2 = (sigma_12 - sigma_21)^2 / 2 (Frobenius)."""
    rt, t = rec.basis, rec.basis.mesh.t
    hats = Basis(rt.mesh, ElementTriP1(), quadrature=rt.quadrature)
    density = (rec.values[0, 1] - rec.values[1, 0]) ** 2 / 2 * rt.dx        # (n_el, nq)
    weighted = sum((korn[t[i]] - 1)[:, None] * np.asarray(hats.basis[i][0]) * density
                   for i in range(3))
    return (t.shape[0]) / (2 * mu) * weighted.sum(axis=1)


@register_estimator(NAME, "equilibrated with every constant proved: local Korn constants "
                          "from the patches' angles (weakly symmetric stress) and trace and "
                          "Friedrichs constants from the domain's geometry",
                    guaranteed=True, applies=tresca_only_for(NAME), friction=True,
                    families=("tri",))  # the patch equilibration with proved constants: 2D
def estimate(scene, solution: DiscreteSolution):
    mesh = solution.elasticity.mesh
    lam, mu = solution.elasticity.lame
    vertex, element = vertex_korn(mesh), element_korn(mesh)
    # the skew weight of the minimisation, as C_K^2 is in ``equilibrated``'s. One number:
    # per element (its vertices' mean) it forces the skew part to vanish on flat elements
    # (K_z ~ 1e5 on `graded`) at a far larger symmetric part (uniform, vi, 4752 DOFs, with
    # the projected iterations then stopped at 1e-2: eta 476 against 41 with the median)
    weight = float(np.sqrt(mesh.t.shape[0] * np.median(vertex - 1) / (2 * mu)))

    def weak(rec, interior, prescribed, lame):
        symmetric, defect = weakly_symmetrised(rec, interior, prescribed, lame, weight)
        if defect > BALANCE_TOLERANCE:
            raise NotEquilibrated(f"the skew part misses orthogonality to P1 by {defect:.1e} "
                                  f"(relative) > {BALANCE_TOLERANCE:g}: no bound")
        return symmetric

    constants = proved_constants(scene)

    @functools.cache
    def chain() -> RigidChain:
        return RigidChain.of(scene, mesh, (lam, mu))

    def excess_term(excess, w):  # N_t as ``dual_terms`` will charge it
        plain = l2_excess_term(solution.trace, constants.trace)(excess, w)
        return min(plain, chain().absolute_tangential(solution.trace, excess, w))

    rec, interior, load, bounds, boundary, _, shear = equilibrate(
        scene, solution, weak, constants.trace, excess_term)
    compliance = compliance_squares(rec, interior, (lam, mu))
    skew = skew_squares(rec, vertex, mu)
    jump = jump_oscillation(mesh, scene.body_force, rec.basis.elem.k, (lam, mu), 0.0,
                            element_korn=element, level_set=scene.load_jump)
    osc = np.sqrt(element / (2 * mu)) * oscillation(scene, rec.basis, boundary, jump)
    tau_sym, tau_skew = np.zeros_like(osc), np.zeros_like(osc)
    if jump is not None:
        if jump.divergence_defect > BALANCE_TOLERANCE:
            raise NotEquilibrated(f"div tau misses r_2 by {jump.divergence_defect:.1e} "
                                  f"(relative) > {BALANCE_TOLERANCE:g}: no bound")
        tau_sym[jump.elements] = np.sqrt(jump.symmetric)
        tau_skew[jump.elements] = np.sqrt((element[jump.elements] - 1) / (2 * mu) * jump.skew)
    parts = dict(symmetric=np.sqrt(compliance.sum()), skew=np.sqrt(skew.sum()),
                 oscillation=(np.sqrt((osc**2).sum()) + np.sqrt((tau_sym**2).sum())
                              + np.sqrt((tau_skew**2).sum())))
    parts["load"], duals = dual_terms(scene, solution, constants, load, bounds.sharp[0], shear,
                                      sum(parts.values()), chain)
    spread = parts["load"] * np.sqrt(load.squares / max(load.squares.sum(), 1e-300))
    volume = (np.sqrt(compliance) + np.sqrt(skew) + osc + tau_sym + tau_skew + spread) ** 2
    return smallest(scene, solution, parts, volume, bounds,
                    friction_of(scene, solution, shear), NAME, duals)


def dual_terms(scene, solution, constants, load, bound, shear, rest: float, chain
               ) -> tuple[float, DualNorms]:
    """The load term, N and N_t (13.4, 17.5): C_F ||rho||, C_T ||lambda*_-|| and C_T
    ||(|sigma*_t| - s)_+||, or the chained dual norms of ``estimators.guaranteed.rigid_duals`` where
    smaller. Both bound the same functionals; the chain (``chain()``) costs a sparse
    factorisation, built only where the three weigh (above 1e-6 of the rest of A)."""
    load_term = constants.friedrichs * np.sqrt(load.squares.sum())
    negative = constants.trace * bound.negative
    t, w = gauss_legendre(QUADRATURE)
    excess = None if shear is None else shear_excess(scene, solution, shear, t)[2]
    excess_norm = 0.0 if excess is None else np.sqrt(solution.trace.integrate(excess**2, w).sum())
    if load_term + negative + constants.trace * excess_norm <= 1e-6 * rest:
        return load_term, DualNorms(constants.trace, negative)
    negative = min(negative, chain().traction(solution.trace, bound.negative_part, t, w))
    shear_term = None if excess is None else min(
        constants.trace * excess_norm, chain().absolute_tangential(solution.trace, excess, w))
    return min(load_term, chain().load(load)), DualNorms(constants.trace, negative, shear_term)
