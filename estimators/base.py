"""The estimate of one discrete solution (docs/theory.md, section 4)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from formulations.cells import family_of
from formulations.registry import friction_dims, frictionless_only
from scenes.registry import Registry


@dataclass(frozen=True)
class BoundTerms:
    """The parts of a guaranteed bound's A and N (docs/theory.md, 13.1), each in energy-norm
    units, so that a user sees which one dominates: ``symmetric`` the compliance norm of
    sym sigma* - sigma_h, ``skew`` C_K ||skw sigma*||, ``oscillation`` C_G osc, ``load``
    C_F ||rho||, ``negative_traction`` C_T ||lambda*_-||; with Tresca friction
    ``excess_shear`` C_Tt ||(|sigma*_t| - s)_+|| and ``friction_complementarity`` sqrt(B_t^+)
    (docs/theory.md, 17.5; 0 without friction)."""

    symmetric: float
    skew: float
    oscillation: float
    load: float
    negative_traction: float
    excess_shear: float = 0.0
    friction_complementarity: float = 0.0

    def columns(self) -> dict[str, float]:
        """As result columns: eta_symmetric, eta_skew, ..."""
        return {f"eta_{name}": float(value) for name, value in vars(self).items()}


@dataclass(frozen=True, eq=False)
class Estimate:
    """Global estimate and per-element indicators.

    eta^2 = eta_0^2 + eta_geometric^2 + eta_complementarity^2 (the paper's (8)), where
    eta_geometric = ||(g - u_hn)_-||_{1/2,Gamma_C} and
    eta_complementarity = |(lambda_h, (g - u_hn)_-)_{0,Gamma_C}|^{1/2}.
    ``indicators`` are squared element contributions; they sum to eta^2.
    """

    estimator: str
    eta: float
    eta_0: float
    eta_geometric: float
    eta_complementarity: float
    indicators: np.ndarray
    guaranteed: bool = False  # eta is an upper bound of ||u - u_h|| with no unknown constant
    bound: BoundTerms | None = None  # a guaranteed bound's parts


def combine(estimator: str, volume: np.ndarray, contact) -> Estimate:
    """The estimate from squared per-element volume indicators (eta_0^2 = their sum) and the
    shared contact terms (``estimators.contact_terms``): eta^2 = eta_0^2 + geometric +
    complementarity, as in the paper's (8)."""
    eta_0 = float(np.sqrt(volume.sum()))
    return Estimate(estimator=estimator,
                    eta=float(np.sqrt(eta_0**2 + contact.geometric + contact.complementarity)),
                    eta_0=eta_0, eta_geometric=float(np.sqrt(contact.geometric)),
                    eta_complementarity=float(np.sqrt(contact.complementarity)),
                    indicators=volume + contact.per_element)


ESTIMATORS = Registry("estimator")
# "estimator@family" -> the estimate function of an estimator on other cells
ESTIMATOR_VARIANTS = Registry("estimator variant")
SIMPLICES = ("tri", "tet")  # the cell families (formulations.cells) most estimators are built on


def register_estimator(name: str, description: str, applies=None, guaranteed: bool = False,
                       families: tuple[str, ...] = SIMPLICES,
                       friction: bool | tuple[int, ...] = False):
    """Register ``estimate(scene, solution) -> Estimate`` under ``name``; ``guaranteed``: its
    eta is an upper bound of the energy error with every constant computed (what
    ``--target-error`` needs); ``families``: the cell families it runs on (others can add
    their own ``register_cell_variant``); ``friction``: whether it has the friction terms
    (True: in 2D; or the dimensions, e.g. (2, 3)), else a scene with friction is refused with
    that reason."""
    dims = friction_dims(friction)
    check = frictionless_only("estimator", name, applies, dims)
    return ESTIMATORS.register(name, description, check,
                               meta={"guaranteed": bool(guaranteed),
                                     "families": tuple(families), "friction": bool(dims),
                                     "friction_dims": dims})


def register_cell_variant(name: str, family: str):
    """Register ``estimate(scene, solution)`` as estimator ``name`` on the cells of
    ``family`` (a family name of ``formulations.cells``): one module, one registration."""
    return ESTIMATOR_VARIANTS.register(f"{name}@{family}", f"{name} on {family} cells")


def estimator_on(name: str, family: str):
    """The estimate function of ``name`` on ``family``'s cells."""
    variant = f"{name}@{family}"
    if variant in ESTIMATOR_VARIANTS.names():
        return ESTIMATOR_VARIANTS.get(variant)
    return ESTIMATORS.get(name)


def why_not_on(name: str, family) -> str | None:
    """Why estimator ``name`` does not run on ``family``'s cells (a ``CellFamily``), or
    None."""
    if (family.name in ESTIMATORS.meta(name, "families", SIMPLICES)
            or f"{name}@{family.name}" in ESTIMATOR_VARIANTS.names()):
        return None
    return f"{name} is not built on {family.shape}"


def guaranteed_estimators() -> list[str]:
    return [n for n in ESTIMATORS.names() if ESTIMATORS.meta(n, "guaranteed", False)]


def get_estimator(name: str):
    """The estimate function of ``name``: where ``register_cell_variant`` gave it variants,
    one that runs the variant of the solution mesh's cell family (``estimator_on``)."""
    default = ESTIMATORS.get(name)          # a KeyError naming the estimators if unknown
    if not any(v.startswith(f"{name}@") for v in ESTIMATOR_VARIANTS.names()):
        return default

    def estimate(scene, solution):
        return estimator_on(name, family_of(solution.elasticity.mesh).name)(scene, solution)

    estimate.__doc__ = default.__doc__
    return estimate


estimator_names = ESTIMATORS.names
estimator_descriptions = ESTIMATORS.descriptions
