"""Data passed between formulations, solvers and estimators (docs/theory.md, section 3).

* ``ContactQP``: the discrete problem min 1/2 u'Ku - F'u s.t. Bu <= G over the free DOFs.
* ``QPSolution``: what a solver returns (arrays plus the solver's own status and its
  ``SolverDiagnostics``).
* ``DiscreteSolution``: u_h and lambda_h on Gamma_C with residuals computed from the arrays,
  the same object for every formulation so that estimators never branch on its name.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from formulations.cells.evaluation import normal_trace_matrix
from formulations.contact.boundary import ContactBoundary
from formulations.elasticity import Elasticity

STATUS_OK, STATUS_INACCURATE, STATUS_FAILED = "ok", "inaccurate", "failed"
STATUS_SKIPPED = "skipped"


@dataclass(frozen=True, eq=False)
class FrictionRows:
    """Friction on the constraint nodes of a ``ContactQP`` (docs/theory.md, 17.2): the objective
    gains sum_i b_i |T_i u - w_i| with T_i the ``block`` (d - 1) tangential rows of node i (row
    i of B is its normal row), w_i the obstacle's tangential displacement (``shift``, 0 if
    None) and b_i the slip bound, a force: the given ``bound`` (Tresca), or ``coefficient``
    times the node's normal reaction (Coulomb: a fixed point on the bound)."""

    T: sparse.csr_matrix
    bound: np.ndarray
    coefficient: float = 0.0
    block: int = 1
    shift: np.ndarray | None = None  # the obstacle's tangential displacement per row of T

    def slip(self, u: np.ndarray) -> np.ndarray:
        """T u minus the obstacle's own tangential displacement: the slip per row of T."""
        return self.T @ u if self.shift is None else self.T @ u - self.shift

    @property
    def coulomb(self) -> bool:
        return self.coefficient > 0

    def bounds(self, normal_reactions: np.ndarray | None) -> np.ndarray:
        """b_i: the Tresca bound, or mu (lambda_n,i)^+ for Coulomb (the first rows of B are
        the friction points' normal rows; a slack QP's further rows are not)."""
        if not self.coulomb:
            return self.bound
        normal = np.asarray(normal_reactions, dtype=float)[:self.bound.size]  # the points' rows
        return self.coefficient * np.maximum(normal, 0.0)

    def with_bound(self, bound: np.ndarray) -> FrictionRows:
        """The Tresca problem with slip bound ``bound`` (a Coulomb fixed point's step)."""
        return FrictionRows(T=self.T, bound=np.asarray(bound, dtype=float), block=self.block,
                            shift=self.shift)

    def node_norms(self, values: np.ndarray) -> np.ndarray:
        """|v_i| per node of a tangential vector (block entries per node, node-major)."""
        return np.linalg.norm(np.reshape(values, (-1, self.block)), axis=1)


FRICTION_STATES = ("separated", "stick", "slip")


@dataclass(frozen=True, eq=False)
class ConsistencyTerm:
    """A term of the discrete equation beyond a(u_h, v) - L(v) and the contact tractions
    lambda_h, sigma_t,h: the equation holds with - (q, sigma(v) n)_{Gamma_C} added, q (d,
    n_facets, nq) a vector at the local coordinates ``points`` of every contact facet and
    ``weights`` (n_facets * nq) the quadrature weights times the facets' measures, the rule the
    formulation integrates with (Nitsche's theta/gamma times the traction residual,
    docs/theory.md 12.1 and 13.2, "Balance")."""

    points: np.ndarray
    weights: np.ndarray
    vector: np.ndarray


@dataclass(frozen=True, eq=False)
class FrictionState:
    """The friction law's answer at the points where a formulation poses it (the nodes of
    Gamma_C for vi; docs/theory.md, 17.2): their contact coordinate, tangential reaction (a
    force), shear traction sigma_t, tangential displacement (the slip), bound (a force) and
    state (``FRICTION_STATES``), all computed from the returned arrays; ``traction(t)``: the
    discrete shear traction sigma_t,h at local coordinates t of every contact facet, as
    ``DiscreteSolution.pressure`` gives lambda_h (t = n turned by +90 degrees)."""

    coordinate: np.ndarray
    tangential_reactions: np.ndarray
    shear: np.ndarray
    slip: np.ndarray
    bound: np.ndarray
    state: np.ndarray
    traction: Callable[[np.ndarray], np.ndarray]
    bound_traction: np.ndarray  # the bound as a stress (s(x_i), or mu lambda_h(x_i))

    def zone(self, state: str) -> tuple[float, float]:
        """The end points of the points in ``state`` along a 2D Gamma_C, in 3D the zone's
        extent along the first contact coordinate (NaN, NaN if there are none)."""
        first = self.coordinate if self.coordinate.ndim == 1 else self.coordinate[0]
        where = first[self.state == state]
        if where.size == 0:
            return float("nan"), float("nan")
        return float(where.min()), float(where.max())


@dataclass(frozen=True, eq=False)
class ContactQP:
    """min 1/2 u'Ku - F'u  s.t.  B u <= G, over the free DOFs.

    ``row_scale`` (> 0, one per constraint) and ``objective_scale`` (> 0) are the natural units
    of the rows of B (a length) and of K (Young's modulus); solvers divide by them so that the
    scaled problem is O(1), and multiply the multipliers back.
    """

    K: sparse.csr_matrix
    F: np.ndarray
    B: sparse.csr_matrix
    G: np.ndarray
    row_scale: np.ndarray
    objective_scale: float
    # K's rigid-body modes (``Elasticity.rigid_modes``): the near-null space of the ``amg``
    # back-end (None: none known; the back-end is then slower, not wrong)
    near_null: np.ndarray | None = None
    # Tresca or Coulomb friction on the nodes of B (None: frictionless)
    friction: FrictionRows | None = None

    @property
    def n(self) -> int:
        return int(self.F.size)

    @property
    def m(self) -> int:
        return int(self.G.size)

    @property
    def gap_scale(self) -> float:
        """The largest mean gap max_i |G_i| / row_scale_i (a length; 0 if every gap is 0)."""
        return float(np.abs(self.G / self.row_scale).max(initial=0.0))


def slack_qp(K: sparse.spmatrix, F: np.ndarray, P: sparse.spmatrix, gap: np.ndarray,
             D: np.ndarray, objective_scale: float) -> ContactQP:
    """min 1/2 u'Ku - F'u + 1/2 s'Ds  s.t.  P u - s <= g, -s <= 0: a squared positive part
    (x)_+^2 = min {s^2 : s >= x, s >= 0} per row of P, with one slack s each (the penalty, and
    the convex form of Nitsche's method; docs/theory.md, sections 3 and 12.2)."""
    ns = gap.size
    eye = sparse.identity(ns, format="csr")
    return ContactQP(K=sparse.block_diag([K, sparse.diags(D)], format="csr"),
                     F=np.concatenate([F, np.zeros(ns)]),
                     B=sparse.bmat([[P, -eye], [None, -eye]], format="csr"),
                     G=np.concatenate([gap, np.zeros(ns)]), row_scale=np.ones(2 * ns),
                     objective_scale=objective_scale)


def slack_warm_start(pressing: np.ndarray) -> np.ndarray:
    """A warm start for ``slack_qp``: row q of P u - s <= g active where the point presses,
    else its s_q >= 0."""
    pressing = np.asarray(pressing, dtype=bool)
    return np.concatenate([pressing, ~pressing]).astype(float)


@dataclass(frozen=True, eq=False)
class SolverDiagnostics:
    """What a solver reports about its own run (``formulations.solvers.active_set``); the
    defaults are what a solver that reports nothing (the reference) gets."""

    active_set_changes: tuple[int, ...] = ()  # constraints entering or leaving, per iteration
    cycled: bool = False  # the plain active-set iteration repeated a set
    safeguard: str = ""  # what answered instead of the plain iteration ("" if nothing did)
    condition_estimate: float = float("nan")  # of the last linear system, solver's scaling
    condensed: np.ndarray | None = None  # B K^-1 B' when the solver formed it (pardiso, cholmod)
    phases: tuple[tuple[str, float], ...] = ()  # (phase, seconds) of the solve, in order
    krylov_iterations: tuple[int, ...] = ()  # per linear solve, on an iterative back-end
    # the adaptive stopping rule ended the iteration before the fixed tolerances would have
    # (formulations.solvers.stopping)
    stopped_early: bool = False
    # the last linear step's algebraic residual (an iterative back-end's Newton steps on a
    # system; None where the step was solved directly)
    algebraic_residual: np.ndarray | None = None
    # the final sets of a box-constrained solve (solvers.box: -1 at the lower bound, 0 free, 1
    # at the upper; normal rows, then tangential), the next Coulomb step's start
    sets: np.ndarray | None = None


@dataclass(frozen=True)
class IterateComponents:
    """The iteration's part of the error of a returned iterate (docs/theory.md, 18.1):
    eta_alg (the algebraic residual) and eta_lin (the linearisation residual) as loads of the
    guaranteed bound, NaN where they were not measured; the stopping rule that ended it."""

    eta_alg: float = float("nan")
    eta_lin: float = float("nan")
    rule: str = "fixed"
    stopped_early: bool = False


@dataclass(frozen=True, eq=False)
class QPSolution:
    """A solver's answer: primal u (free DOFs), multipliers of Bu <= G, and its own report."""

    u: np.ndarray | None
    multipliers: np.ndarray | None
    status: str
    reason: str
    iterations: int
    solve_time: float
    solver: str
    backend: str = ""
    diagnostics: SolverDiagnostics = field(default_factory=SolverDiagnostics)
    # the tangential reactions lambda_t of a frictional QP (FrictionRows), one per row of T
    tangential: np.ndarray | None = None


@dataclass(frozen=True)
class Residuals:
    """KKT residuals computed from the returned arrays (see ``formulations.kkt``)."""

    violation: float
    dual_violation: float
    complementarity: float
    stationarity: float


@dataclass(frozen=True, eq=False)
class DiscreteSolution:
    """u_h and the discrete contact pressure lambda_h >= 0 on Gamma_C.

    ``pressure(t)`` returns lambda_h at local coordinates t in [0, 1] of every contact facet of
    ``trace`` (shape (n_facets, len(t))). ``multiplier_breaks`` are the end points (in the scene's
    contact coordinate) of the pieces lambda_h is defined on.
    """

    formulation: str
    solver: str
    elasticity: Elasticity
    trace: ContactBoundary  # a kind of formulations.contact (edges, triangles, quadrilaterals)
    u: np.ndarray
    pressure: Callable[[np.ndarray], np.ndarray]
    multiplier_breaks: np.ndarray
    residuals: Residuals
    status: str
    reason: str
    iterations: int
    solve_time: float
    active_constraints: int
    max_h_over_H: float = float("nan")
    backend: str = ""
    # the QP multipliers (clipped at 0) and the formulation's own arrays (a frozen dataclass
    # of the formulation module, e.g. ``formulations.methods.mixed.MixedDetails``)
    multipliers: np.ndarray | None = None
    details: object | None = None
    # relative disagreement of the formulation's pressure with its QP multipliers, where the
    # formulation can check it (penalty); 0 where lambda_h is the multiplier itself
    pressure_mismatch: float = 0.0
    diagnostics: SolverDiagnostics = field(default_factory=SolverDiagnostics)
    friction: FrictionState | None = None  # with a friction law
    consistency: ConsistencyTerm | None = None  # Nitsche (theta != 0)
    components: IterateComponents = field(default_factory=IterateComponents)

    @property
    def ok(self) -> bool:
        return self.status == STATUS_OK

    @property
    def energy(self) -> float:
        return self.elasticity.energy(self.u)

    def normal_displacement(self, t: np.ndarray) -> np.ndarray:
        """u_h . n at local coordinates t in [0, 1] of every contact facet, for any order;
        shape (n_facets, len(t))."""
        t = np.asarray(t, dtype=float)
        values = normal_trace_matrix(self.elasticity.basis, self.trace, t) @ self.u
        return values.reshape(self.trace.size, t.shape[-1])

    def pressure_at(self, s: np.ndarray, samples: int = 17) -> np.ndarray:
        """lambda_h at contact coordinates ``s`` (a number along a 2D Gamma_C, (2, m) on a 3D
        one), located in its facet (the contact boundary's ``pressure_at``)."""
        return self.trace.pressure_at(self.pressure, s, samples)

    def contact_force(self, quadrature_points: int = 4) -> float:
        """The integral of lambda_h over Gamma_C (``quadrature_points`` Gauss points per
        facet in 2D, a rule of the same degree 2 n - 1 on triangles)."""
        t, w = self.trace.rule(2 * quadrature_points - 1)
        return float(self.trace.integrate(self.pressure(t), w).sum())
