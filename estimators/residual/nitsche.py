"""``nitsche-residual``: the residual estimator of Chouly, Fabre, Hild, Pousin and Renard for
Nitsche's method (IMA J. Numer. Anal. 38 (2018); docs/theory.md, section 12.4).

Per element T, in the suite's energy units (1/E, section 4) and hp weights h/p:

    eta_T^2 = (1/E) ( h_T^2 ||f + div sigma(u_h)||_T^2 + sum_e h_e R_e^2 ),

with R_e the half stress jump on interior edges, ||sigma_n(u_h) - q|| on Gamma_N and, on
Gamma_C, ||sigma_nt(u_h)|| + ||sigma_nn(u_h) - [P_gamma(u_h)]_-|| = ||sigma_nn(u_h) + lambda_h||
(lambda_h = -[P_gamma(u_h)]_- is Nitsche's pressure). These are the terms of the residual
estimator's eta_0; what differs is that the eq. (8) contact terms are not added: Nitsche's
method is consistent, and its reliability proof (under a saturation assumption) needs only the
Nitsche residual on Gamma_C. It applies to a formulation that declares the trait
``nitsche-contact`` (``nitsche``; a plugin may too).
"""

from __future__ import annotations

import numpy as np

from estimators.base import Estimate, register_estimator
from estimators.residual.triangles import volume_terms
from formulations import DiscreteSolution
from formulations.registry import formulation_traits


def nitsche_only(scene=None, formulation: str = "", **_) -> str | None:
    """A formulation qualifies by declaring the trait ``nitsche-contact`` (docs/plugins.md,
    "Traits"), not by its name."""
    if "nitsche-contact" in formulation_traits(formulation):
        return None
    return (f"nitsche-residual estimates Nitsche's method only (its contact term is the "
            f"Nitsche residual sigma_nn(u_h) - [P_gamma(u_h)]_-), not {formulation!r}, which "
            "does not declare the trait nitsche-contact")


@register_estimator("nitsche-residual", "Chouly-Fabre-Hild-Pousin-Renard residual estimator "
                                        "for nitsche: eta_0 with the Nitsche contact residual, "
                                        "no eq. (8) terms", applies=nitsche_only)
def estimate(scene, solution: DiscreteSolution) -> Estimate:
    return nitsche_estimate(volume_terms(scene, solution))


def nitsche_estimate(local: np.ndarray) -> Estimate:
    """The estimate from the residual estimator's squared volume indicators (module
    docstring): no eq. (8) contact terms."""
    eta = float(np.sqrt(local.sum()))
    return Estimate(estimator="nitsche-residual", eta=eta, eta_0=eta, eta_geometric=0.0,
                    eta_complementarity=0.0, indicators=local)
