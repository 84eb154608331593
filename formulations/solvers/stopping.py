"""When the contact solvers stop: the registered stopping rules and the error components of an
iterate they stop on (docs/theory.md, section 18).

An iterate (u, lambda) of a QP leaves two residuals. The algebraic one, r_alg = F - K u -
B' lambda (what the inexact linear solve left), is a load the guaranteed bound carries as
C_F ||rho|| (13.2); ``LoadNorm`` bounds that term from r alone:

    eta_alg = C_F (sum_a |(H r)_a|^2 / m_a)^(1/2),   (H r)_(a,i) = <r, psi_a e_i>,
    m_a = int psi_a,

an upper bound of C_F ||rho|| for rho = sum_a (H r)_a / m_a psi_a because the consistent P1
mass matrix is below the lumped one. The linearisation (complementarity) residual is the sign
the iteration has not yet got right: the penetration (B u - G)_+ and the negative multipliers
lambda_-. eta_lin = ||w||_K + C_F ||rho(B' lambda_-)|| with w = B' (B B')^-1 (B u - G)_+ the
smallest lift of the penetration (the bound's D pays for it) and B' lambda_- the force the
negative multipliers exert (its N pays for it, measured here as a load).

``fixed``: the tolerances of the solvers (the judge). ``adaptive``: a Krylov solve stops when
eta_alg <= gamma_alg (eta_disc + eta_lin), the active-set (Newton) iteration when eta_lin <=
gamma_lin eta_disc, with eta_disc the level's expected discretisation estimate (``Stopping``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from formulations.base import STATUS_INACCURATE, STATUS_OK, IterateComponents
from scenes.registry import Registry

STOPPING_RULES = Registry("stopping rule")
FIXED, ADAPTIVE = "fixed", "adaptive"
STOPPING_RULES.register(FIXED, "the solvers' own tolerances: relative residual 1e-10 on "
                               "amg, the active set iterated until it settles")(FIXED)
STOPPING_RULES.register(ADAPTIVE, "stop the Krylov solve when eta_alg <= gamma_alg (eta_disc "
                                  "+ eta_lin) and the active-set or Newton iteration when "
                                  "eta_lin <= gamma_lin eta_disc")(ADAPTIVE)
GAMMA_ALG = 0.1  # the default fractions (docs/theory.md, 18.3)
GAMMA_LIN = 0.1


def check_stopping(name: str) -> str:
    if name not in STOPPING_RULES.names():
        raise ValueError(f"stopping={name!r} is not one of "
                         f"{', '.join(STOPPING_RULES.names())}")
    return name


def check_gamma(name: str, value) -> float:
    if not (isinstance(value, (int, float)) and 0.0 < value < 1.0):
        raise ValueError(f"{name}={value!r} is not a number in (0, 1)")
    return float(value)


@dataclass(frozen=True, eq=False)
class LoadNorm:
    """r -> eta_alg of the module docstring. ``hats``: H over the QP's unknowns (columns past
    its width, a slack form's slacks, carry no hat); ``weights``: m_a per row of H;
    ``friedrichs``: C_F of the domain (``estimators.guaranteed.constants``)."""

    hats: sparse.csr_matrix
    weights: np.ndarray
    friedrichs: float

    def __call__(self, r: np.ndarray) -> float:
        tested = self.hats @ np.asarray(r)[:self.hats.shape[1]]
        return float(self.friedrichs * np.sqrt((tested * tested / self.weights).sum()))


@dataclass(frozen=True, eq=False)
class Stopping:
    """A stopping rule for one solve: ``rule`` (a name of STOPPING_RULES), the load norm of
    its unknowns (None: no components, the rule is ``fixed``), the level's expected
    discretisation estimate (NaN: none yet, the rule is ``fixed``) and the fractions."""

    rule: str = FIXED
    load_norm: LoadNorm | None = None
    expected_disc: float = float("nan")
    gamma_alg: float = GAMMA_ALG
    gamma_lin: float = GAMMA_LIN

    @property
    def adaptive(self) -> bool:
        return (self.rule == ADAPTIVE and self.load_norm is not None
                and bool(np.isfinite(self.expected_disc)))

    def algebraic(self, r: np.ndarray) -> float:
        return self.load_norm(r) if self.load_norm is not None else float("nan")

    def krylov_done(self, r: np.ndarray, eta_lin: float) -> bool:
        """Whether a Krylov solve whose residual is ``r`` may stop (adaptive only)."""
        return self.adaptive and self.algebraic(r) <= self.gamma_alg * (
            self.expected_disc + (eta_lin if np.isfinite(eta_lin) else 0.0))

    def newton_done(self, eta_lin: float) -> bool:
        """Whether the active-set (Newton) iteration may stop at an iterate with ``eta_lin``."""
        return self.adaptive and eta_lin <= self.gamma_lin * self.expected_disc


FIXED_STOPPING = Stopping()


@dataclass(frozen=True)
class _Diagonal:
    inverse: np.ndarray

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.inverse * b


@dataclass(frozen=True, eq=False)
class QPLinearisation:
    """eta_lin of a QP's iterates (module docstring): one factorisation of B B' per QP."""

    K: sparse.csr_matrix
    B: sparse.csr_matrix
    G: np.ndarray

    @functools.cached_property
    def gram(self):
        """A solve with B B'; where B B' is singular (dependent rows, e.g. a slack form's
        rows on points no DOF reaches) its diagonal instead: then w is a lift only up to
        the rows' overlap, which an estimate may live with."""
        if not self.B.shape[0]:
            return None
        gram = sparse.csc_matrix(self.B @ self.B.T)
        try:
            return splu(gram)
        except RuntimeError:
            diagonal = gram.diagonal()
            inverse = np.divide(1.0, diagonal, out=np.zeros_like(diagonal),
                                where=diagonal > 0)
            return _Diagonal(inverse)

    def __call__(self, u: np.ndarray, lam: np.ndarray, load_norm: LoadNorm) -> float:
        return self.measure(self.B @ u - self.G, lam, load_norm)

    def measure(self, excess: np.ndarray, lam: np.ndarray, load_norm: LoadNorm) -> float:
        """eta_lin from B u - G (``excess``) and the raw multipliers."""
        penetration = np.maximum(excess, 0.0)
        lift = 0.0
        if penetration.any() and self.gram is not None:
            w = self.B.T @ self.gram.solve(penetration)
            lift = float(np.sqrt(max(w @ (self.K @ w), 0.0)))
        negative = np.maximum(-np.asarray(lam), 0.0)
        force = load_norm(self.B.T @ negative) if negative.any() else 0.0
        return lift + force


def qp_components(qp, answer, stopping: Stopping) -> IterateComponents:
    """The components of a QP solver's ``answer`` (u, raw multipliers) under ``stopping``;
    under friction the tangential reactions are part of the balance."""
    early = answer.diagnostics.stopped_early
    if stopping.load_norm is None or answer.u is None or answer.multipliers is None:
        return IterateComponents(rule=stopping.rule, stopped_early=early)
    u, lam = answer.u, answer.multipliers
    r = qp.F - qp.K @ u - qp.B.T @ lam
    if qp.friction is not None and answer.tangential is not None:
        r = r - qp.friction.T.T @ answer.tangential
    eta_lin = QPLinearisation(qp.K, qp.B, qp.G)(u, lam, stopping.load_norm)
    return IterateComponents(stopping.algebraic(r), eta_lin, stopping.rule, early)


def system_components(system, answer, stopping: Stopping) -> IterateComponents:
    """The components of a semismooth system's iterate: its nonlinear residual R(u) split
    into the last linear step's algebraic residual and the rest (the linearisation's)."""
    early = answer.diagnostics.stopped_early
    if stopping.load_norm is None or answer.u is None:
        return IterateComponents(rule=stopping.rule, stopped_early=early)
    residual = system.residual(answer.u)
    algebraic = answer.diagnostics.algebraic_residual
    if algebraic is None:
        algebraic = np.zeros_like(residual)
    return IterateComponents(stopping.algebraic(algebraic),
                             stopping.algebraic(residual - algebraic), stopping.rule, early)


# the rule's criteria are met on the solver's own residual (the projected one, before the
# zero-to-accuracy multipliers are set to zero); recomputed from the returned arrays they may
# differ by that much, not by a factor: past it the iterate is not what the rule promised
CHECK_SLACK = 1.1


def stopped_status(answer, components: IterateComponents, stopping: Stopping, status: str,
                   reason: str) -> tuple[str, str]:
    """(status, reason) of an iterate the adaptive rule ended early: its KKT residuals are
    the discretisation's order by design, so it is ``ok`` when its measured components meet
    the rule, and ``inaccurate`` (saying which criterion failed) when they do not."""
    if not components.stopped_early or answer.status != STATUS_OK or not stopping.adaptive:
        return status, reason
    eta_alg, eta_lin, expected = components.eta_alg, components.eta_lin, stopping.expected_disc
    measured = f"eta_alg={eta_alg:.3g}, eta_lin={eta_lin:.3g}, expected eta_disc={expected:.3g}"
    if not (eta_alg <= CHECK_SLACK * stopping.gamma_alg * (expected + eta_lin)
            and eta_lin <= CHECK_SLACK * stopping.gamma_lin * expected):
        return STATUS_INACCURATE, f"the adaptive stopping rule is not met: {measured}"
    return STATUS_OK, "; ".join(filter(None, (reason and f"KKT {reason}",
                                              f"stopped by the adaptive rule: {measured}")))
