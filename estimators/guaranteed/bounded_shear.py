"""A bounded auxiliary shear traction sigma*_t for the guaranteed bound under Tresca friction
(docs/theory.md, 17.5).

The bound charges the excess of sigma*_t over the slip bound s with the tangential trace
constant, N_t = C_Tt ||(|sigma*_t| - s)_+||. The projection of sigma_t,h plus its P1 correction
(``guaranteed_friction.balanced_shear``) exceeds s where the discrete shear does (the mixed
method's multiplier between the nodes where it is bounded, the penalty's projection) and where
the correction adds to it (vi's). This one is a polynomial of degree k on each contact facet
whose Bernstein coefficients x_j lie in [-s(t_j), s(t_j)], t_j = j / k the Greville points
(so |sigma*_t| <= s wherever s is concave along the facet), and whose moments against the hat
functions along the vertex tangents are what u_h leaves unbalanced after lambda*, as far as
such a shear has them: a box-constrained least-squares problem on Gamma_C,

    min_{|x_j| <= s(t_j)} ||M^(-1/2) (G x - R)||^2 + EPSILON^2 ||sigma*_t||^2_{0,Gamma_C},

M the P1 mass matrix of Gamma_C, so that the first term is the squared L2 norm of the P1
correction that balances what x leaves (as for lambda_h), and with it the bound of the excess
it adds. The estimate takes this shear only where it gives the smaller friction terms.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg

from estimators.guaranteed.guaranteed_contact import (
    ContactTraction,
    balanced_traction,
    contact_mass,
    traction_balance,
)
from estimators.guaranteed.guaranteed_friction import (
    QUADRATURE,
    balanced_shear,
    friction_bound,
    raw_shear,
    shear_excess,
    vertex_tangents,
)
from estimators.guaranteed.nonnegative_traction import EPSILON, bernstein_polynomial, hat_moments
from formulations.base import STATUS_OK
from formulations.contact.reference_facets import gauss_legendre
from formulations.friction.slack import contact_tangent
from formulations.solvers.box import box_bvls


def coefficient_bounds(scene, trace, k: int) -> np.ndarray:
    """The slip bound at the Greville points j / k of each contact facet, (n_f, k + 1)."""
    t = np.linspace(0.0, 1.0, k + 1)
    return scene.friction.slip_bound_at(trace.points(t)).reshape(trace.size, t.size)


def bounded_shear(scene, solution, defect: np.ndarray, clamped: np.ndarray,
                  balance) -> ContactTraction | None:
    """sigma*_t of the module docstring for the tangential imbalance ``defect`` (n_vertices, 2)
    that u_h leaves after lambda*; ``balance(pressure)`` the per-vertex moments of the shear
    traction ``pressure`` t. None if the box problem fails."""
    trace, k = solution.trace, solution.elasticity.order
    on = np.unique(np.concatenate(trace.vertices))
    on = on[~clamped[on]]
    tangents = vertex_tangents(trace)
    R = (defect[on] * tangents[:, on].T).sum(axis=1)
    # ||M^-1/2 (G x - R)|| is the L2 norm of the P1 correction that balances what x leaves
    factor = linalg.cholesky(contact_mass(trace)[on][:, on].toarray(), lower=True)
    A = linalg.solve_triangular(factor, hat_moments(trace, k)[on].toarray(), lower=True)
    target = linalg.solve_triangular(factor, R, lower=True)
    # ||sum_j x_j B_j||^2 <= sum_j x_j^2 |e| / (k + 1) (Bernstein: a partition of unity)
    weights = EPSILON * np.repeat(np.sqrt(trace.length / (k + 1)), k + 1)
    upper = coefficient_bounds(scene, trace, k).ravel()
    result = box_bvls(A.T @ A + np.diag(weights**2), A.T @ target, -upper, upper)
    if result.status != STATUS_OK:
        return None
    shear = bernstein_polynomial(result.lam.reshape(trace.size, k + 1))
    return balanced_traction(trace, shear, defect - balance(shear), clamped, orientation=1.0,
                             directions=tangents)


def l2_excess_term(trace, trace_constant: float):
    """N_t as C_T ||g||_{0,Gamma_C} for the excess g at Gauss points with weights w."""
    def term(excess: np.ndarray, w: np.ndarray) -> float:
        return trace_constant * float(np.sqrt(trace.integrate(excess**2, w).sum()))
    return term


def auxiliary_shear(scene, solution, interior, left: np.ndarray, clamped: np.ndarray,
                    bounds, excess_term) -> ContactTraction:
    """sigma*_t (docs/theory.md, 17.5) for the imbalance ``left`` (n_vertices, 2) that u_h
    leaves after lambda*: of the corrected projection of sigma_t,h (``balanced_shear``) and the
    bounded shear above, the one with the smaller friction terms N_t + sqrt(B_t), N_t =
    ``excess_term(g, w)`` for the excess g at the Gauss points, B_t the smallest over the
    extensions of the contact terms ``bounds`` (B_t sees only their traces); no patch problem
    is solved for either."""
    def balance(pressure):
        return traction_balance(interior, solution.trace, pressure,
                                contact_tangent(solution.trace))

    raw = raw_shear(solution).pressure
    candidates = [balanced_shear(solution, left - balance(raw), clamped),
                  bounded_shear(scene, solution, left, clamped, balance)]
    t, w = gauss_legendre(QUADRATURE)

    def terms(shear):
        slack = min(friction_bound(scene, solution, shear, bound.field).complementarity
                    for bound in bounds.marking)
        excess = shear_excess(scene, solution, shear, t)[2]
        return excess_term(excess, w) + np.sqrt(max(slack, 0.0))

    return min((shear for shear in candidates if shear is not None), key=terms)
