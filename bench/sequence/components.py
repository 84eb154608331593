"""The error components of a level's iterate and the stopping rule of its solve
(docs/theory.md, section 18): eta_disc, eta_lin, eta_alg, eta_total, and the columns that count
the work (newton_steps, krylov_iterations)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from estimators.base import ESTIMATORS
from estimators.guaranteed.constants import domain_constants
from formulations.cells import DEFAULT_CELL
from formulations.hat_loads import load_norm, simplex_mesh
from formulations.solvers.stopping import ADAPTIVE, Stopping, check_gamma, check_stopping


def check_stopping_settings(stopping: str, gamma_alg, gamma_lin) -> None:
    """A registered rule and fractions in (0, 1), or ValueError naming the bad one."""
    check_stopping(stopping)
    check_gamma("gamma_alg", gamma_alg)
    check_gamma("gamma_lin", gamma_lin)


def check_stopping_cell(stopping: str, cell: str) -> None:
    """The adaptive rule measures with the hats of a conforming simplicial mesh."""
    if stopping == ADAPTIVE and cell != DEFAULT_CELL:
        raise ValueError(f"stopping='adaptive' is measured on triangles and tetrahedra only "
                         f"(cell={cell!r}: the hats of a mesh with hanging nodes are not "
                         f"those of the bound); use cell='{DEFAULT_CELL}' or stopping='fixed'")


@dataclass(frozen=True)
class Previous:
    """What the next level's stopping rule predicts from: a level's eta_disc and unknowns."""

    eta_disc: float
    ndofs: int


def measured(estimator: str, rule: str) -> bool:
    """Whether a level's components are measured: under the adaptive rule, or with a
    guaranteed estimator (whose domain constants are computed anyway)."""
    return rule == ADAPTIVE or bool(ESTIMATORS.meta(estimator, "guaranteed", False))


def expected_disc(previous: Previous | None, ndofs: int, order: int, dim: int) -> float:
    """The level's expected eta_disc: the previous level's scaled by (N_prev / N)^(p / d),
    the optimal rate (the smallest value a converging sequence can reach, so the rule errs
    towards solving more); NaN on the first level."""
    if previous is None or not math.isfinite(previous.eta_disc) or ndofs <= 0:
        return float("nan")
    return previous.eta_disc * (previous.ndofs / ndofs) ** (order / dim)


def level_stopping(scene, disc, config, estimator: str, previous: Previous | None) -> Stopping:
    """The stopping rule of a level's solve (``config``: a ``LoopConfig``)."""
    rule = config.stopping
    if not measured(estimator, rule) or not simplex_mesh(disc.elasticity):
        return Stopping(rule=rule, gamma_alg=config.gamma_alg, gamma_lin=config.gamma_lin)
    norm = load_norm(disc.elasticity, domain_constants(scene).friedrichs)
    return Stopping(rule=rule, load_norm=norm,
                    expected_disc=expected_disc(previous, disc.ndofs, config.order, scene.dim),
                    gamma_alg=config.gamma_alg, gamma_lin=config.gamma_lin)


def without_algebraic_load(estimate, eta_alg: float) -> float:
    """A guaranteed bound's eta with its load term C_F ||rho|| less the algebraic part
    ``eta_alg`` (13.1: eta^2 = a eta + b, a = A + D + N, b = A D + B; A less delta gives
    a - delta and b - delta D)."""
    eta, D = estimate.eta, estimate.eta_geometric
    delta = min(estimate.bound.load, eta_alg) if math.isfinite(eta_alg) else 0.0
    a = estimate.eta_0 + D + estimate.bound.negative_traction + estimate.bound.excess_shear
    b = eta * eta - a * eta
    a, b = a - delta, max(b - delta * D, 0.0)
    return 0.5 * (a + math.sqrt(a * a + 4.0 * b))


def component_columns(solution, estimate) -> dict:
    """eta_disc, eta_lin, eta_alg, eta_total and the work of a solved level (docs/columns.md).
    With a guaranteed bound, eta_total is that bound on the returned iterate (every residual
    in it) and eta_disc the same bound without the algebraic load; else eta_disc is the
    estimate and eta_total adds eta_lin and eta_alg (up to the estimator's constant)."""
    parts = solution.components
    eta_alg, eta_lin = parts.eta_alg, parts.eta_lin
    if estimate is not None and estimate.guaranteed and estimate.bound is not None:
        eta_total, eta_disc = estimate.eta, without_algebraic_load(estimate, eta_alg)
    elif estimate is not None:
        eta_disc = estimate.eta
        eta_total = eta_disc + sum(x for x in (eta_alg, eta_lin) if math.isfinite(x))
    else:
        eta_disc = eta_total = float("nan")
    return dict(eta_disc=eta_disc, eta_lin=eta_lin, eta_alg=eta_alg, eta_total=eta_total,
                stopped_early=parts.stopped_early,
                newton_steps=solution.iterations,
                krylov_iterations=int(sum(solution.diagnostics.krylov_iterations)))
