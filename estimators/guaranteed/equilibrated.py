"""``equilibrated``: a guaranteed upper bound of the energy error from an equilibrated stress
and Theorem 1 of the seed paper with every constant computed (docs/theory.md, section 13).

    A   = ||C^{-1/2}(sym sigma* - sigma_h)|| + C_K ||skw sigma*|| + C_G osc + C_F ||rho||
        >= ||u_0 - u_h||,
    D   = ||d|| >= ||(g - u_hn)_-||'_{1/2},     N = C_T ||lambda*_-||_{0,Gamma_C},
    B   = (lambda*_+, g - u_hn - d . n)_{Gamma_C},
    eta = (a + sqrt(a^2 + 4 b)) / 2,  a = A + D + N,  b = A D + B,

with u_0 the solution of the auxiliary problem (4) with contact traction lambda*, sigma* its
equilibrated stress and rho the load that balances the patches u_h does not balance exactly
(``estimators.guaranteed.equilibration``), d an extension of (g - u_hn)_- (``estimators.contact_
extension``; of two, the one with the smaller eta), osc the data oscillation (Payne-
Weinberger's 1/pi and a trace constant derived in 13.3; where f jumps inside elements, most of
it equilibrated on sub-triangles, ``estimators.guaranteed.jump_equilibration``), C_G = (1/(2 mu) +
C_K^2)^(1/2), and
C_K, C_T, C_F the domain constants (``estimators.guaranteed.constants``). eta_0 reports A,
eta_geometric D and eta_complementarity sqrt(B).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np

from estimators.averaging import compliance_energy
from estimators.base import BoundTerms, Estimate, register_estimator
from estimators.guaranteed.auxiliary_traction import contact_traction
from estimators.guaranteed.bounded_shear import auxiliary_shear, l2_excess_term
from estimators.guaranteed.consistency_stress import consistency_stress, with_consistency
from estimators.guaranteed.constants import domain_constants
from estimators.guaranteed.equilibration import (
    BoundaryData,
    boundary_balance,
    boundary_fluxes,
    reconstruct,
)
from estimators.guaranteed.guaranteed_contact import (
    ContactBound,
    ContactBounds,
    traction_at,
)
from estimators.guaranteed.guaranteed_friction import friction_bound, raw_shear, shear_at
from estimators.guaranteed.jump_equilibration import jump_oscillation
from estimators.guaranteed.oscillation import oscillation
from estimators.guaranteed.patch_data import interior_data, rebalanced
from estimators.guaranteed.symmetrisation import symmetrised
from estimators.residual.triangles import stress_at, stress_tensor
from formulations import DiscreteSolution
from formulations.cells.evaluation import gradients_at_reference
from formulations.elasticity import stress_from_gradient

# The bound needs the patch data to balance (docs/theory.md, 13.2); past this relative
# imbalance (round-off is ~1e-12) the stress is not equilibrated and no bound is claimed.
BALANCE_TOLERANCE = 1e-8


class NotEquilibrated(RuntimeError):
    """The discrete solution does not balance the auxiliary problem's hat functions."""


def tresca_only_for(name: str):
    """The ``applies`` check of estimator ``name``: Coulomb is refused (not a minimisation: no
    bound, docs/theory.md 17.5)."""
    def check(scene=None, **context) -> str | None:
        if scene is not None and scene.friction.kind == "coulomb":
            return (f"estimator '{name}' bounds the error under Tresca friction only "
                    f"(the scene's law is {scene.friction.label}: Coulomb's is not a "
                    "minimisation)")
        return None
    return check


tresca_only = tresca_only_for("equilibrated")


@dataclass(frozen=True)
class DualNorms:
    """What replaces C_T times a norm in N and N_t (``estimators.guaranteed.equilibrated_local``):
    the trace constant, and N and N_t themselves where they are bounded otherwise (None: C_T
    ||lambda*_-|| and C_Tt ||(|sigma*_t| - s)_+||)."""

    trace: float
    negative_traction: float | None = None
    excess_shear: float | None = None
    # C_Tt, the bound of ||v_t||_{Gamma_C} in N_t (None: ``trace`` bounds the whole trace
    # ||v||_{Gamma_C}, as the proved constants do; the computed C_T bounds only v . n)
    tangential_trace: float | None = None


def friction_terms(friction, duals: DualNorms) -> dict[str, float]:
    """The friction parts of ``BoundTerms``: N_t and sqrt(B_t^+) (0 without friction)."""
    if friction is None:
        return {}
    excess = duals.excess_shear
    if excess is None:
        excess = (duals.trace if duals.tangential_trace is None
                  else duals.tangential_trace) * friction.excess
    return {"excess_shear": excess,
            "friction_complementarity": float(np.sqrt(max(friction.complementarity, 0.0)))}


@register_estimator("equilibrated", "guaranteed upper bound: equilibrated RT stress on vertex "
                                    "patches, symmetrised by the curl of a stream function "
                                    "(Prager-Synge), plus Theorem 1's contact terms, "
                                    "every constant computed; Tresca friction's terms too",
                    guaranteed=True, applies=tresca_only, friction=(2, 3))
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    rec, interior, load, bounds, boundary, _, shear = equilibrate(scene, solution)
    lam, mu = solution.elasticity.lame
    constants = domain_constants(scene)
    compliance = compliance_squares(rec, interior, (lam, mu))
    skew = ((rec.values[0, 1] - rec.values[1, 0]) ** 2 / 2 * rec.basis.dx).sum(axis=1)
    jump = jump_oscillation(rec.basis.mesh, scene.body_force, rec.basis.elem.k, (lam, mu),
                            constants.korn, level_set=scene.load_jump,
                            stress_gap=stress_gap(rec, solution))
    osc = oscillation(scene, rec.basis, boundary, jump)
    if jump is not None:  # where f jumps: sigma* - tau on the rough elements (13.2)
        if jump.divergence_defect > BALANCE_TOLERANCE:
            raise NotEquilibrated(f"div tau misses r_2 by {jump.divergence_defect:.1e} "
                                  f"(relative) > {BALANCE_TOLERANCE:g}: no bound")
        compliance[jump.elements], skew[jump.elements] = jump.symmetric, jump.skew
    parts, volume = volume_parts(compliance, skew, osc, load.squares, constants, mu)
    return smallest(scene, solution, parts, volume, bounds, friction_of(scene, solution, shear),
                    "equilibrated")


def volume_parts(compliance: np.ndarray, skew: np.ndarray, osc: np.ndarray,
                 load_squares: np.ndarray, constants, mu: float) -> tuple[dict, np.ndarray]:
    """The parts of A (``BoundTerms``' volume fields) and A_T^2 per element from the squares
    per element of ||C^{-1/2}(sym sigma* - sigma_h)||, ||skw sigma*|| and ||rho||, and osc_T
    (docs/theory.md, 13.2): A = S + C_K K + C_G osc + C_F ||rho||, C_G^2 = 1/(2 mu) + C_K^2."""
    grad_constant = np.sqrt(1 / (2 * mu) + constants.korn**2)
    volume = (np.sqrt(compliance) + constants.korn * np.sqrt(skew) + grad_constant * osc
              + constants.friedrichs * np.sqrt(load_squares)) ** 2
    parts = dict(symmetric=np.sqrt(compliance.sum()), skew=constants.korn * np.sqrt(skew.sum()),
                 oscillation=grad_constant * np.sqrt((osc**2).sum()),
                 load=constants.friedrichs * np.sqrt(load_squares.sum()))
    return parts, volume


def stress_gap(rec, solution: DiscreteSolution, stress=stress_at):
    """sigma* - sigma_h (d, d, n, nq) at points x (d, n, nq) of the elements ``cells``, as a
    function ``gap(x, cells, reference=None)`` (``estimators.guaranteed.jump_equilibration``,
    ``stress_gap``; ``reference`` as in ``ReferenceRT.values_at``), sigma_h from
    ``stress(solution, x (d, m), cells (m,))``."""
    def gap(x: np.ndarray, cells: np.ndarray, reference: np.ndarray | None = None
            ) -> np.ndarray:
        d = x.shape[0]
        sigma_h = stress(solution, x.reshape(d, -1), np.repeat(cells, x.shape[2]))
        return (rec.basis.values_at(rec.dofs, x, cells, reference)
                - sigma_h.reshape(d, d, *x.shape[1:]))

    return gap


def compliance_squares(rec, interior, lame: tuple[float, float]) -> np.ndarray:
    """||C^{-1/2}(sym sigma* - sigma_h)||_T^2 per element."""
    diff = rec.values - interior.sigma_h
    sym = np.array([diff[0, 0], diff[1, 1], 0.5 * (diff[0, 1] + diff[1, 0])])
    return (compliance_energy(sym, *lame) * rec.basis.dx).sum(axis=1)


def friction_of(scene, solution, shear):
    """The friction terms of sigma*_t = ``shear`` on segments as a function of the extension
    d (``guaranteed_friction.friction_bound``; None without friction)."""
    return None if shear is None else functools.partial(friction_bound, scene, solution, shear)


def smallest(scene, solution, parts: dict, volume: np.ndarray, bounds: ContactBounds, friction,
             name: str, duals: DualNorms | None = None) -> Estimate:
    """Every extension d gives a bound (13.3): the smallest over the relaxed fields, as
    estimator ``name``, ``friction(d)`` the friction terms (17.5; None without friction)
    (``duals``: by default the computed C_T and C_Tt of 13.4 times the norms), with
    the indicators of the smallest over the one-layer fields, scaled to sum to eta^2: the
    relaxed fields' energy spreads over the strip's layers, away from the elements where the
    penetration is (13.3, "Marking")."""
    if duals is None:
        constants = domain_constants(scene)
        duals = DualNorms(trace=constants.trace, tangential_trace=constants.tangential_trace)

    def best(options):
        return min((_combined(parts, volume, bound, friction, name, duals)
                    for bound in options), key=lambda est: est.eta)

    steering, sharp = best(bounds.marking), best(bounds.sharp)
    scale = sharp.eta**2 / steering.indicators.sum() if steering.indicators.sum() > 0 else 0.0
    return replace(sharp, indicators=steering.indicators * scale)


def _combined(parts: dict, volume: np.ndarray, bound, friction_terms_of, name: str,
              duals: DualNorms) -> Estimate:
    """eta of 13.1 from the parts of A (``BoundTerms``' volume fields), the contact terms of
    one extension (``bound``) and, under friction, those of sigma*_t (17.5)."""
    friction = None if friction_terms_of is None else friction_terms_of(bound.field)
    negative_traction = duals.negative_traction
    if negative_traction is None:
        negative_traction = duals.trace * bound.negative
    terms = BoundTerms(**parts, negative_traction=negative_traction,
                       **friction_terms(friction, duals))
    A = terms.symmetric + terms.skew + terms.oscillation + terms.load
    a = A + bound.extension + terms.negative_traction + terms.excess_shear
    # b only grows when rounded up to 0: e^2 <= a e + b stays true (docs/theory.md, 17.5)
    b = max(A * bound.extension + bound.complementarity
            + (friction.complementarity if friction else 0.0), 0.0)
    eta = 0.5 * (a + np.sqrt(a * a + 4 * b))
    local = marking_shares(eta, A, volume, terms, bound, friction)
    return Estimate(estimator=name, eta=float(eta), eta_0=float(A),
                    eta_geometric=bound.extension,
                    eta_complementarity=float(np.sqrt(bound.complementarity)), indicators=local,
                    guaranteed=True, bound=terms)


def marking_shares(eta: float, A: float, volume: np.ndarray, terms: BoundTerms,
                   bound: ContactBound, friction) -> np.ndarray:
    """eta^2 per element for marking. With a and b as in 13.1, eta^2 = a eta + b splits into
    A eta + D (eta + A) + N eta + B (+ N_t eta + B_t under friction); each part is spread over
    the elements like its own square (``volume`` ~ A_T^2, a(d, d)_T, ||lambda*_-||^2 and the
    slack of B on the element's contact facets), so a term weighs in marking as in eta."""
    parts = [(A * eta, volume), (bound.extension * (eta + A), bound.energy),
             (terms.negative_traction * eta, bound.negative_squares),
             (bound.complementarity, bound.slack)]
    if friction is not None:
        parts.append((terms.excess_shear * eta + max(friction.complementarity, 0.0),
                      friction.per_element))
    local = sum(total * spread / spread.sum() for total, spread in parts if spread.sum() > 0)
    return np.zeros_like(volume) + local


def equilibrate(scene, solution: DiscreteSolution, symmetrise=None,
                trace_constant: float | None = None, excess_term=None):
    """sigma* (a ``Reconstruction``, symmetrised by ``estimators.guaranteed.symmetrisation``, or by
    ``symmetrise(rec, interior, prescribed, lame)`` if given), the patch data, rho,
    the contact terms of lambda* (``ContactBounds``, lambda* chosen with
    ``trace_constant``, by default the computed C_T), the Neumann data of the auxiliary
    problem, the clamped vertices and sigma*_t (None without friction; chosen with
    ``excess_term``, by default C_Tt ||g||, ``estimators.guaranteed.bounded_shear``)
    (docs/theory.md, 13.2, 13.3 and 17.5)."""
    elasticity = solution.elasticity
    mesh, order = elasticity.mesh, elasticity.order
    lam, mu = elasticity.lame

    def stress(basis):
        grad = gradients_at_reference(elasticity.basis, solution.u, basis.quadrature[0])
        return stress_tensor(stress_from_gradient(grad, lam, mu))

    clamped = np.zeros(mesh.p.shape[1], dtype=bool)
    clamped[mesh.facets[:, scene.dirichlet_facets(mesh)].ravel()] = True
    interior = with_consistency(  # Nitsche's consistency term in the data (13.2)
        interior_data(mesh, stress, scene.body_force, order, max(4, 2 * order + 2)),
        consistency_stress(solution))
    trace = solution.trace
    n_v = mesh.p.shape[1]
    neumann = BoundaryData(scene.neumann_facets(mesh), scene.traction or (lambda x: 0.0 * x))
    neumann_flux = boundary_fluxes(interior, [neumann])
    reaction = interior.total - boundary_balance(n_v, neumann_flux)
    shear = None
    sheared = [] if solution.friction is None else [
        BoundaryData(trace.facets, lambda x: shear_at(trace, raw_shear(solution), x))]
    lam_star, bounds = contact_traction(  # the normal balance net of sigma_t,h's own
        scene, solution, interior,
        reaction - boundary_balance(n_v, boundary_fluxes(interior, sheared)), clamped,
        trace_constant)
    normal = BoundaryData(trace.facets, lambda x: traction_at(trace, lam_star, x))
    contact = normal
    if sheared:  # sigma*_t balances what is left along the tangents (17.5)
        left = reaction - boundary_balance(n_v, boundary_fluxes(interior, [normal]))
        if excess_term is None:
            excess_term = l2_excess_term(trace, domain_constants(scene).tangential_trace
                                         if trace_constant is None else trace_constant)
        shear = auxiliary_shear(scene, solution, interior, left, clamped, bounds,
                                excess_term)
        contact = BoundaryData(trace.facets, lambda x: traction_at(trace, lam_star, x)
                               + shear_at(trace, shear, x))
    fluxes = neumann_flux + boundary_fluxes(interior, [contact])
    interior, load = rebalanced(interior, interior.total - boundary_balance(n_v, fluxes),
                                clamped)
    rec = reconstruct(interior, fluxes, clamped)
    if rec.imbalance > BALANCE_TOLERANCE:
        raise NotEquilibrated(f"the patch data do not balance (relative imbalance "
                              f"{rec.imbalance:.1e} > {BALANCE_TOLERANCE:g}): no bound")
    prescribed = np.concatenate([part.facets for part in (neumann, contact)])
    if symmetrise is not None:
        return (symmetrise(rec, interior, prescribed, (lam, mu)), interior, load, bounds,
                [neumann, contact], clamped, shear)
    rec = symmetrised(rec, interior, prescribed, (lam, mu), domain_constants(scene).korn)
    return rec, interior, load, bounds, [neumann, contact], clamped, shear
