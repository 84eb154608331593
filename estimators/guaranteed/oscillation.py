"""The data oscillation of the guaranteed bound (docs/theory.md, section 13.2,
"Oscillation"): per element, what sigma* does not balance of the load and of the Neumann and
contact tractions, bounded with Payne-Weinberger's h/pi and the facet constant C_e."""

from __future__ import annotations

import numpy as np
from skfem import Basis, ElementDG, FacetBasis

from estimators.guaranteed.equilibration import BoundaryData
from estimators.guaranteed.jump_equilibration import JumpOscillation
from estimators.guaranteed.jump_flux import FluxOscillation
from estimators.guaranteed.patch_data import scalar_lagrange
from formulations.cells.p1_stiffness import barycentric_gradients
from formulations.elasticity import element_diameters
from scenes.base import simplex_measures


def oscillation(scene, rt: Basis, boundary: list[BoundaryData],
                *jumps: JumpOscillation | FluxOscillation | None) -> np.ndarray:
    """Per element, (h_T / pi) ||f - Pi_k f||_T + sum_e C_e ||t - Pi_k t||_e over its facets
    with Neumann data, C_e^2 = |e| h_T^2 / |T| (1/pi^2 + 2/(d pi)) in d dimensions
    (docs/theory.md, 13.2); on the elements of each of ``jumps`` its own term of f instead
    (13.2, "Where f jumps": ``JumpOscillation`` or ``FluxOscillation``; None: none)."""
    mesh, k, d = rt.mesh, rt.elem.k, rt.mesh.dim()
    out = np.zeros(mesh.t.shape[1])
    if scene.body_force is not None:
        rest = np.ones(mesh.t.shape[1], dtype=bool)   # the elements no part covers
        for jump in jumps:
            if jump is not None:
                out[jump.elements], rest[jump.elements] = np.sqrt(jump.osc_squares), False
        rest = np.flatnonzero(rest)
        if rest.size:
            dg = Basis(mesh, ElementDG(scalar_lagrange(k, d)), quadrature=rt.quadrature,
                       elements=rest)
            f = scene.body_force(np.asarray(dg.global_coordinates()))
            out[rest] = element_diameters(mesh)[rest] / np.pi * np.sqrt(projection_error(dg, f))
    for part in boundary:
        if part.facets.size == 0:
            continue
        fb = FacetBasis(mesh, scalar_lagrange(k, d), facets=part.facets, intorder=8,
                        disable_doflocs=True)   # a pass over every element saved
        t = part.traction(np.asarray(fb.global_coordinates()))
        err = projection_error(fb, t)
        measure = simplex_measures(mesh.p[:, mesh.facets[:, part.facets]])
        element = fb.tind
        c_e = np.sqrt(measure * element_diameters(mesh)[element] ** 2
                      / barycentric_gradients(mesh)[1][element] * (1 / np.pi**2 + 2 / (d * np.pi)))
        out += np.bincount(element, c_e * np.sqrt(err), mesh.t.shape[1])
    return out


def projection_error(basis, values: np.ndarray) -> np.ndarray:
    """||v - Pi v||^2 per element or facet of ``basis`` for v (d, n, nq), Pi the L2 projection
    onto the span of the basis's local functions (on a facet the P_k functions of the triangle
    span P_k(e) with repetitions: the pseudo-inverse of their Gram matrix)."""
    phi = np.array([np.asarray(b[0]) for b in basis.basis])           # (m, n, nq)
    gram = np.einsum("jnp,lnp,np->njl", phi, phi, basis.dx)
    moments = np.einsum("jnp,rnp,np->nrj", phi, values, basis.dx)
    coef = np.einsum("njl,nrl->nrj", np.linalg.pinv(gram, rcond=1e-10), moments)
    projected = np.einsum("nrj,jnp->rnp", coef, phi)
    return (((values - projected) ** 2).sum(axis=0) * basis.dx).sum(axis=1)
