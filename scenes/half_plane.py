"""Coupled partial slip of a rigid cylinder on an elastic half-plane: an independent,
semi-analytic reference for the `hertz` scene with Coulomb friction (docs/theory.md, 19.4).

Plane strain, the half-plane's surface tractions p (pressure, compressive) and q (shear on the
body, along +x), and its surface displacements (Johnson, Contact Mechanics, 1985, eq. 2.25,
with A = 2 (1 - nu^2) / E and Dundurs' beta = (1 - 2 nu) / (2 (1 - nu)) of an elastic body on a
rigid one; u_z into the body):

    u_z(x) = beta A / 2 int q(s) sign(x - s) ds - A / pi int p(s) ln|x - s| ds + C_z,
    u_x(x) = -beta A / 2 int p(s) sign(x - s) ds - A / pi int q(s) ln|x - s| ds + C_x.

The rigid parabola g(x) = x^2 / (2 R) - delta presses with the force P and drags the surface
along +x with the force Q, in one step from the unloaded state, as the finite element scene
does (its slip is u_t minus the obstacle's whole slide): u_z - delta + x^2 / (2 R) >= 0,
p >= 0 and their product 0; in the stick zone u_x = omega (the indenter's rigid slide, which
the half-plane fixes only up to a constant, hence Q is given instead), elsewhere in contact
q = -mu p sign(u_x - omega). With ``history`` the same loads are reached in steps, the slip of
each step measured from the last (press, then shear: the incremental problem).

Discretisation: p and q piecewise constant on N equal cells of [-L, L], the displacements
collocated at the cells' midpoints with the kernels integrated exactly over each cell, and the
complementarity solved by a primal-dual active-set iteration on the dense (2N + 2) system. The
ends of the contact and stick zones are where p^2 and (mu p - |q|)^2, which vanish like the
distance to the end, extrapolate linearly to zero from the last two cells inside.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenes.base import SceneError, StickPrediction

MAX_ITERATIONS = 200  # active-set steps per load step (measured: 4 to 12)
TANGENTIAL_WEIGHT = 0.1  # the stick test's slip weight, relative to the contact's: with equal
# weights the iteration cycles between stick and slip cells (measured at N = 800, nu = 0.49)
EXTENT = 1.4  # the cells cover [-EXTENT b, EXTENT b], b Hertz's half-width at P


@dataclass(frozen=True)
class HalfPlaneContact:
    """The discrete answer: cell midpoints ``x``, ``pressure`` and ``shear`` per cell, which
    cells ``stick``, the ``contact_zone`` and ``stick_zone`` ends, and the active-set
    ``iterations`` of the last load step."""

    x: np.ndarray
    pressure: np.ndarray
    shear: np.ndarray
    stick: np.ndarray
    contact_zone: tuple[float, float]
    stick_zone: tuple[float, float]
    iterations: int

    def shear_at(self, s: np.ndarray) -> np.ndarray:
        """q at points ``s`` (linear between the cell midpoints, 0 outside the cells)."""
        return np.interp(s, self.x, self.shear, left=0.0, right=0.0)


def kernels(edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(L, S): L_ij = (1/pi) int_cell_j ln|x_i - s| ds and S_ij = (1/2) int_cell_j
    sign(x_i - s) ds at the midpoints x_i of the cells between ``edges``."""
    x = 0.5 * (edges[:-1] + edges[1:])

    def antiderivative(t):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(t == 0, 0.0, t * np.log(np.abs(t)) - t)

    d_left, d_right = x[:, None] - edges[None, :-1], x[:, None] - edges[None, 1:]
    L = (antiderivative(d_left) - antiderivative(d_right)) / np.pi
    S = 0.5 * (np.abs(d_left) - np.abs(d_right))  # int sign(x - s) ds = |x - a| - |x - b|
    return L, S


def zone_end(x: np.ndarray, inside: np.ndarray, margin: np.ndarray, side: int) -> float:
    """The end of the zone ``inside`` on ``side`` (-1 left, +1 right): where margin^2,
    linear near the end, extrapolates to zero from the two outermost cells inside."""
    cells = np.flatnonzero(inside)
    if cells.size < 2:
        return float(x[cells[0]]) if cells.size else float("nan")
    i, j = (cells[0], cells[1]) if side < 0 else (cells[-1], cells[-2])
    m_i, m_j = margin[i] ** 2, margin[j] ** 2
    if m_j == m_i:
        return float(x[i])
    return float(x[i] + (x[i] - x[j]) * m_i / (m_j - m_i))


def check_loads(P: float, Q: float, mu: float, poisson_ratio: float) -> None:
    if not P > 0:
        raise SceneError(f"P={P!r} is not a positive force")
    if not (mu > 0 and abs(Q) < mu * P):
        raise SceneError(f"Q={Q!r} is not below mu P = {mu * P!r} (partial slip needs "
                         f"|Q| < mu P with mu > 0)")
    if not 0.0 <= poisson_ratio <= 0.5:
        raise SceneError(f"poisson_ratio={poisson_ratio!r} is not in [0, 0.5]")


@dataclass(frozen=True)
class HalfPlane:
    """The discrete half-plane: cell ``edges`` and midpoints ``x``, the kernels ``L`` and ``S``
    (``kernels``), the compliance ``A`` and Dundurs' ``beta``."""

    edges: np.ndarray
    x: np.ndarray
    L: np.ndarray
    S: np.ndarray
    A: float
    beta: float

    @classmethod
    def of(cls, young_modulus: float, poisson_ratio: float, half_length: float, cells: int):
        edges = np.linspace(-half_length, half_length, int(cells) + 1)
        L, S = kernels(edges)
        return cls(edges, 0.5 * (edges[:-1] + edges[1:]), L, S,
                   2 * (1 - poisson_ratio**2) / young_modulus,
                   (1 - 2 * poisson_ratio) / (2 * (1 - poisson_ratio)))

    def displacements(self, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(u_z, u_x) at the midpoints, without their constants."""
        A, b = self.A, self.beta
        return A * (b * self.S @ q - self.L @ p), A * (-b * self.S @ p - self.L @ q)


@dataclass(frozen=True)
class ActiveSets:
    """Cells in ``contact``, which of them ``stick``, and the sign of q on the slipping ones."""

    contact: np.ndarray
    stick: np.ndarray
    sign: np.ndarray

    def same(self, other: ActiveSets) -> bool:
        return all(np.array_equal(a, b) for a, b in zip(
            (self.contact, self.stick, self.sign), (other.contact, other.stick, other.sign),
            strict=True))


def step_system(plane: HalfPlane, sets: ActiveSets, radius: float, mu: float, P: float,
                Q: float, held: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The linear system of one active-set step in z = (p, q, delta, omega) (module
    docstring); ``held``: the slip u_x - omega each stuck cell keeps from the last step."""
    n, A, beta, h = plane.x.size, plane.A, plane.beta, plane.edges[1] - plane.edges[0]
    M, rhs = np.zeros((2 * n + 2, 2 * n + 2)), np.zeros(2 * n + 2)
    c, st = sets.contact, sets.contact & sets.stick
    slip = sets.contact & ~sets.stick
    M[:n][c, :n], M[:n][c, n:2 * n], M[:n][c, 2 * n] = -A * plane.L[c], A * beta * plane.S[c], -1
    rhs[:n][c] = -plane.x[c] ** 2 / (2 * radius)
    M[np.flatnonzero(~c), np.flatnonzero(~c)] = 1.0  # p = 0 off the contact
    rows = n + np.flatnonzero(st)
    M[rows, :n], M[rows, n:2 * n], M[rows, 2 * n + 1] = (-A * beta * plane.S[st],
                                                         -A * plane.L[st], -1)
    rhs[rows] = held[st]
    k = np.flatnonzero(slip)
    M[n + k, n + k], M[n + k, k] = 1.0, -mu * sets.sign[k]  # q = sign mu p
    M[n + np.flatnonzero(~c), n + np.flatnonzero(~c)] = 1.0  # q = 0 off the contact
    M[2 * n, :n], M[2 * n + 1, n:2 * n] = h, h
    rhs[2 * n], rhs[2 * n + 1] = P, Q
    return M, rhs


def load_step(plane: HalfPlane, sets: ActiveSets, radius: float, mu: float, P: float,
              Q: float, held: np.ndarray):
    """Solve one load step by the primal-dual active-set iteration: (p, q, slip u_x - omega,
    sets, iterations)."""
    n = plane.x.size
    r = 1.0 / (plane.A * (plane.edges[1] - plane.edges[0]))  # pressure per displacement
    for iteration in range(1, MAX_ITERATIONS + 1):
        M, rhs = step_system(plane, sets, radius, mu, P, Q, held)
        try:
            z = np.linalg.solve(M, rhs)
        except np.linalg.LinAlgError:  # no stuck cell yet: omega is free, any value will do
            z = np.linalg.lstsq(M, rhs, rcond=None)[0]
        p, q, delta, omega = z[:n], z[n:2 * n], z[2 * n], z[2 * n + 1]
        u_z, u_x = plane.displacements(p, q)
        gap, slip = u_z - delta + plane.x**2 / (2 * radius), u_x - omega
        normal = p - r * gap
        trial = q - TANGENTIAL_WEIGHT * r * (slip - held)
        contact = normal > 0
        new = ActiveSets(contact, contact & (np.abs(trial) < mu * normal),
                         np.where(contact, np.sign(trial), 0.0))
        if new.same(sets):
            return p, q, slip, sets, iteration
        sets = new
    raise SceneError(f"the half-plane's active-set iteration did not settle in "
                     f"{MAX_ITERATIONS} steps (P={P!r}, Q={Q!r}, mu={mu!r})")


def coupled_partial_slip(young_modulus: float, poisson_ratio: float, radius: float, mu: float,
                         P: float, Q: float, cells: int = 800,
                         history: int = 0) -> HalfPlaneContact:
    """The rigid cylinder of radius R on the half-plane at the forces P and Q (per unit
    thickness), in one step (``history`` 0, as the finite element scene) or pressed in
    ``history`` steps and then sheared in as many (module docstring)."""
    check_loads(P, Q, mu, poisson_ratio)
    e_star = young_modulus / (1 - poisson_ratio**2)
    b = float(np.sqrt(4 * P * radius / (np.pi * e_star)))  # Hertz's half-width
    plane = HalfPlane.of(young_modulus, poisson_ratio, EXTENT * b, cells)
    contact = np.abs(plane.x) < b
    c = b * np.sqrt(1 - abs(Q) / (mu * P))  # Cattaneo-Mindlin's stick zone to start from
    sets = ActiveSets(contact, np.abs(plane.x) < c, np.where(contact, np.sign(Q) or 1.0, 0.0))
    steps = [(P, Q)] if not history else (
        [(P * k / history, 0.0) for k in range(1, history + 1)]
        + [(P, Q * k / history) for k in range(1, history + 1)])
    held = np.zeros(plane.x.size)
    for P_k, Q_k in steps:
        p, q, slip, sets, iterations = load_step(plane, sets, radius, mu, P_k, Q_k, held)
        held = np.where(sets.contact, slip, 0.0)  # a cell sticks at where it last was
    stick = sets.contact & sets.stick
    margin = mu * p - np.abs(q)
    zone = tuple(zone_end(plane.x, stick, margin, side) for side in (-1, 1))
    contact_zone = tuple(zone_end(plane.x, sets.contact, np.maximum(p, 0), side)
                         for side in (-1, 1))
    return HalfPlaneContact(plane.x, p, q, stick, contact_zone, zone, iterations)


@dataclass(frozen=True, eq=False)
class CoupledStickPrediction(StickPrediction):
    """``StickPrediction`` from the half-plane's coupled answer ``reference`` (solved along
    +x and mirrored for an obstacle sliding along -x): the stick zone's half-width and centre,
    the contact zone's half-width, and the shear traction interpolated between the cells."""

    reference: HalfPlaneContact | None = None

    def shear(self, s: np.ndarray) -> np.ndarray:
        d = self.direction or 1.0
        return d * self.reference.shear_at(d * np.asarray(s, dtype=float))


def coupled_partial_slip_prediction(mu: float, slide: float, cells: int = 800):
    """(material, R, P, Q) -> ``CoupledStickPrediction`` of the one-step problem at the
    forces P and |Q| (module docstring)."""
    direction = float(np.sign(slide)) or 1.0

    def predict(material, radius: float, P: float, Q: float) -> CoupledStickPrediction:
        answer = coupled_partial_slip(material.young_modulus, material.poisson_ratio, radius,
                                      mu, P, abs(Q), cells=cells)
        (a1, a2), (c1, c2) = answer.contact_zone, answer.stick_zone
        c = 0.5 * (c2 - c1)
        return CoupledStickPrediction(
            c, 0.5 * (a2 - a1), float(answer.pressure.max()), mu, direction=direction,
            centre=direction * 0.5 * (c1 + c2), reference=answer,
            label=f"coupled half-plane, c = {c:.4g}, shift = {direction * 0.5 * (c1 + c2):.3g}")
    return predict
