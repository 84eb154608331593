"""``equilibrated`` on tetrahedra (docs/theory.md, section 14.5, "`equilibrated` on
tetrahedra"): the bound of 13.1 with the stress of 13.2 built on tetrahedral vertex patches.

sigma* has rows in RT_k on the tetrahedra (``estimators.guaranteed.raviart_thomas_tet``; the mesh
with each element's vertices sorted, which keeps its facets and their numbering), from the same
batched patch problems as on triangles (``estimators.guaranteed.equilibration``), with Neumann data
q and
-lambda* n on the contact triangles (``estimators.guaranteed.guaranteed_contact_3d``), made weakly
symmetric by the curl of a potential (``estimators.guaranteed.symmetrisation_3d``): A =
||C^{-1/2}(sym sigma* - sigma_h)|| + C_K ||skw sigma*|| + C_G osc + C_F ||rho||, with the constants
of ``estimators.guaranteed.constants`` on the 3D domain and the oscillation of
``estimators.guaranteed.oscillation``; the body force's part by RT_0 fluxes on sub-tetrahedra
(``estimators.guaranteed.jump_flux``; 13.2, "Where f jumps, element by element"), inside sigma*
where f jumps inside elements. Under Tresca friction sigma*_t beside lambda*
(``estimators.guaranteed.guaranteed_friction_3d``).
"""

from __future__ import annotations

import numpy as np

from estimators.averaging import compliance_energy
from estimators.base import Estimate, register_cell_variant
from estimators.guaranteed.consistency_stress import consistency_stress, with_consistency
from estimators.guaranteed.constants import domain_constants
from estimators.guaranteed.equilibrated import (
    BALANCE_TOLERANCE,
    NotEquilibrated,
    smallest,
    stress_gap,
    volume_parts,
)
from estimators.guaranteed.equilibration import (
    BoundaryData,
    boundary_balance,
    boundary_fluxes,
    reconstruct,
)
from estimators.guaranteed.guaranteed_contact import ContactBounds
from estimators.guaranteed.guaranteed_friction_3d import surface_tractions
from estimators.guaranteed.jump_flux import SMOOTH_LEVELS, flux_oscillation
from estimators.guaranteed.oscillation import oscillation
from estimators.guaranteed.patch_data import interior_data, rebalanced
from estimators.guaranteed.raviart_thomas_tet import sorted_tetrahedra
from estimators.guaranteed.symmetrisation_3d import symmetrised
from estimators.residual.tetrahedra import stress_at
from formulations import DiscreteSolution

# exact for the squares of RT_k and of sigma_h, with positive weights (scikit-fem's tetrahedron
# rules of degree 3, 4 and 8 have a negative one: a norm could come out negative)
INTORDER = {1: 5, 2: 6}


@register_cell_variant("equilibrated", "tet")
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    rec, interior, load, tractions, boundary = equilibrate(scene, solution)
    lam, mu = solution.elasticity.lame
    constants = domain_constants(scene)  # on the 3D domain (docs/theory.md, 13.4)
    diff = rec.values - interior.sigma_h
    sym = 0.5 * (diff + diff.transpose(1, 0, 2, 3))
    compliance = (compliance_energy(sym.reshape(9, *sym.shape[2:]), lam, mu)
                  * rec.basis.dx).sum(axis=1)
    skew = ((0.5 * (rec.values - rec.values.transpose(1, 0, 2, 3))) ** 2).sum(axis=(0, 1))
    skew = (skew * rec.basis.dx).sum(axis=1)
    osc = oscillation(scene, rec.basis, boundary,
                      *body_force_terms(scene, solution, rec, compliance, skew))
    parts, volume = volume_parts(compliance, skew, osc, load.squares, constants, mu)
    bounds = ContactBounds(marking=tractions.bounds, sharp=tractions.bounds)
    return smallest(scene, solution, parts, volume, bounds, tractions.friction(scene, solution),
                    "equilibrated")


def body_force_terms(scene, solution: DiscreteSolution, rec, compliance: np.ndarray,
                     skew: np.ndarray) -> tuple:
    """The oscillation of f by RT_0 fluxes on sub-tetrahedra (``estimators.guaranteed.jump_flux``;
    13.2, "Where f jumps, element by element"): on the rough elements inside sigma* (their
    ``compliance`` and ``skew`` squares replaced by those of sigma* - tau), on the others
    apart; (None, None) without a body force."""
    mesh, k = rec.basis.mesh, rec.basis.elem.k
    jump = flux_oscillation(mesh, scene.body_force, k, gap=stress_gap(rec, solution, stress_at),
                            lame=solution.elasticity.lame)
    rough = np.zeros(0, dtype=np.int64) if jump is None else jump.elements
    smooth = flux_oscillation(mesh, scene.body_force, k, SMOOTH_LEVELS,
                              elements=np.setdiff1d(np.arange(mesh.t.shape[1]), rough))
    for part in (jump, smooth):
        if part is not None and part.divergence_defect > BALANCE_TOLERANCE:
            raise NotEquilibrated(f"the moments of f - Pi_k f miss zero by "
                                  f"{part.divergence_defect:.1e} (relative) > "
                                  f"{BALANCE_TOLERANCE:g}: no bound")
    if jump is not None:
        compliance[jump.elements], skew[jump.elements] = jump.symmetric, jump.skew
    return jump, smooth


def equilibrate(scene, solution: DiscreteSolution):
    """sigma* (a ``Reconstruction`` on the sorted mesh), the patch data, rho, the contact
    tractions (lambda*, its terms with every extension d, sigma*_t) and the Neumann data of the
    auxiliary problem (docs/theory.md, 13.2, 14.5, 17.5)."""
    elasticity = solution.elasticity
    mesh, order = sorted_tetrahedra(elasticity.mesh), elasticity.order
    if not np.array_equal(mesh.facets, elasticity.mesh.facets):
        raise NotEquilibrated("sorting the tetrahedra renumbered the facets: no bound")
    n_v = mesh.p.shape[1]

    def stress(rt):
        x = np.asarray(rt.global_coordinates())                         # (3, n_el, nq)
        cells = np.repeat(np.arange(x.shape[1]), x.shape[2])
        return stress_at(solution, x.reshape(3, -1), cells).reshape(3, 3, *x.shape[1:])

    clamped = np.zeros(n_v, dtype=bool)
    clamped[mesh.facets[:, scene.dirichlet_facets(mesh)].ravel()] = True
    interior = with_consistency(  # Nitsche's consistency term in the data (13.2)
        interior_data(mesh, stress, scene.body_force, order, INTORDER[order]),
        consistency_stress(solution))
    neumann = BoundaryData(scene.neumann_facets(mesh), scene.traction or (lambda x: 0.0 * x))
    neumann_flux = boundary_fluxes(interior, [neumann])
    reaction = interior.total - boundary_balance(n_v, neumann_flux, 3)
    constants = domain_constants(scene)
    tractions = surface_tractions(scene, solution, interior, reaction, clamped,
                                  constants.trace, constants.tangential_trace)
    fluxes = neumann_flux + boundary_fluxes(interior, [tractions.contact])
    interior, load = rebalanced(interior, interior.total - boundary_balance(n_v, fluxes, 3),
                                clamped)
    rec = reconstruct(interior, fluxes, clamped, condense=True)  # 14.5: few shapes repeat
    if rec.imbalance > BALANCE_TOLERANCE:
        raise NotEquilibrated(f"the patch data do not balance (relative imbalance "
                              f"{rec.imbalance:.1e} > {BALANCE_TOLERANCE:g}): no bound")
    prescribed = np.concatenate([neumann.facets, tractions.contact.facets])
    rec = symmetrised(rec, interior, prescribed, elasticity.lame, constants.korn)
    return rec, interior, load, tractions, [neumann, tractions.contact]
