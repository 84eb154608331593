"""Scene data: what a Signorini problem is (docs/theory.md, sections 1 and 2).

A scene is declarative: geometry and initial mesh, which boundary part is which, the material,
the loads, the linearised gap g and a coordinate along Gamma_C. It validates itself on
construction so that a bad problem is refused before any solve.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from skfem import Mesh, MeshTri

from scenes.checks import PointFunction, SceneError, is_integer, is_number  # noqa: F401
from scenes.friction import NO_FRICTION, FrictionLaw

# the corners of the reference triangle and its centroid, as (2, 4) local coordinates: where a
# 3D scene's gap is checked on every contact facet
TRIANGLE_CHECK_POINTS = np.array([[0.0, 1.0, 0.0, 1 / 3], [0.0, 0.0, 1.0, 1 / 3]])


def simplex_points(corners: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of facets with corner points ``corners`` (d, k, n) (k = 2: segments, k = 3:
    triangles) at local coordinates t: (nq,) along a segment, (2, nq) in the reference triangle
    (x = a + t_0 (b - a) + t_1 (c - a)); shape (d, n, nq)."""
    t = np.asarray(t, dtype=float)
    a = corners[:, 0][:, :, None]
    if corners.shape[1] == 2:
        return a + (corners[:, 1][:, :, None] - a) * t.reshape(1, 1, -1)
    return (a + (corners[:, 1][:, :, None] - a) * t[0][None, None, :]
            + (corners[:, 2][:, :, None] - a) * t[1][None, None, :])


def simplex_measures(corners: np.ndarray) -> np.ndarray:
    """Lengths of segments or areas of triangles with corner points ``corners`` (d, k, n)."""
    if corners.shape[1] == 2:
        return np.linalg.norm(corners[:, 1] - corners[:, 0], axis=0)
    return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                         corners[:, 2] - corners[:, 0], axis=0), axis=0)


def _check(condition: bool, parameter: str, value, allowed: str) -> None:
    if not condition:
        raise SceneError(f"{parameter}={value!r} is not {allowed}")


@dataclass(frozen=True)
class Material:
    """Isotropic linear elastic material (docs/theory.md, section 1).

    ``plane`` is ``"stress"`` or ``"strain"``; the Lame parameters follow from it.
    """

    young_modulus: float
    poisson_ratio: float
    plane: str = "stress"

    def __post_init__(self):
        E, nu = self.young_modulus, self.poisson_ratio
        _check(is_number(E) and np.isfinite(E) and E > 0,
               "young_modulus", E, "a finite number > 0")
        _check(is_number(nu) and np.isfinite(nu) and nu > -1,
               "poisson_ratio", nu, "> -1")
        _check(nu < 0.5, "poisson_ratio", nu, "< 0.5")
        _check(self.plane in ("stress", "strain"), "plane", self.plane,
               "one of 'stress', 'strain'")

    @property
    def lame(self) -> tuple[float, float]:
        """(lambda, mu); lambda is lambda* = E nu / (1 - nu^2) in plane stress."""
        E, nu = float(self.young_modulus), float(self.poisson_ratio)
        mu = E / (2.0 * (1.0 + nu))
        if self.plane == "stress":
            return E * nu / (1.0 - nu**2), mu
        return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu


@dataclass(frozen=True, eq=False)
class ExactSolution:
    """A scene's known solution: u (``displacement(x)``, shape (2, ...)), its gradient
    (``gradient(x)``, shape (2, 2, ...), grad[i, j] = du_i/dx_j), the contact pressure as a function
    of the contact coordinate, and the contact-zone end points (contact coordinates); with
    friction also the shear traction and the stick zone."""

    displacement: PointFunction
    gradient: PointFunction
    pressure: Callable[[np.ndarray], np.ndarray]
    contact_zone: tuple[float, float]
    source: str = ""
    # with friction: the shear traction sigma_t along Gamma_C (a function of the contact
    # coordinate, t = n turned by +90 degrees) and the stick zone's end points
    shear: Callable[[np.ndarray], np.ndarray] | None = None
    stick_zone: tuple[float, float] | None = None


@dataclass(frozen=True)
class ContactPrediction:
    """A closed-form contact pressure of elliptic shape at a given contact force (Hertz's):
    p(s) = p0 sqrt(1 - ((s - centre) / b)^2)_+ with half-width b and peak p0."""

    half_width: float
    peak_pressure: float
    centre: float = 0.0
    label: str = ""

    def pressure(self, s: np.ndarray) -> np.ndarray:
        if not self.half_width > 0:  # no contact force: no pressure anywhere
            return np.zeros(np.shape(s))
        r = (np.asarray(s, dtype=float) - self.centre) / self.half_width
        return self.peak_pressure * np.sqrt(np.clip(1.0 - r**2, 0.0, None))


@dataclass(frozen=True)
class StickPrediction:
    """A closed-form partial-slip answer (Cattaneo-Mindlin's) at given normal and tangential
    forces: the stick zone's half-width, and the shear traction q(s) of the slip and stick zones
    (Hertz's half-width and peak pressure beside them)."""

    stick_half_width: float
    half_width: float
    peak_pressure: float
    coefficient: float
    direction: float = 1.0  # the sign of the shear traction (along t)
    centre: float = 0.0
    label: str = ""

    def shear(self, s: np.ndarray) -> np.ndarray:
        """mu p0 (sqrt(1 - x^2/b^2)_+ - (c/b) sqrt(1 - x^2/c^2)_+), x = s - centre (Johnson,
        Contact Mechanics, 7.1)."""
        x = np.asarray(s, dtype=float) - self.centre
        b, c = self.half_width, self.stick_half_width
        outer = np.sqrt(np.clip(1.0 - (x / b) ** 2, 0.0, None))
        inner = (c / b) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None)) if c > 0 else 0.0
        return self.direction * self.coefficient * self.peak_pressure * (outer - inner)


@dataclass(frozen=True, eq=False)
class Scene:
    """A Signorini problem on a 2D or 3D body (docs/theory.md, sections 2 and 14).

    Boundary parts are given as predicates on facet midpoints; every boundary facet that is
    neither Dirichlet nor contact is a Neumann facet (traction ``traction``, zero if None).
    ``contact_coordinate`` maps points of Gamma_C to a monotone arclength-like coordinate,
    used to order the contact facets (the multiplier mesh of the mixed method lives on it); in
    3D (a tetrahedral mesh) it maps points of Gamma_C to two coordinates (2, ...) on it, and the
    material is the 3D one (``plane="strain"``: the same Lame parameters).
    """

    name: str
    description: str
    mesh: Mesh
    material: Material
    is_dirichlet: PointFunction
    is_contact: PointFunction
    gap: PointFunction
    contact_coordinate: PointFunction
    body_force: PointFunction | None = None
    traction: PointFunction | None = None
    parameters: dict = field(default_factory=dict)
    tags: tuple[str, ...] = ()
    exact: ExactSolution | None = None
    # a closed-form contact pressure for the computed contact force, where theory has one
    predict_contact: Callable[[float], ContactPrediction] | None = None
    # a closed-form stick zone and shear traction for the computed normal and tangential
    # forces (P, Q), where theory has one (Cattaneo-Mindlin on hertz with a sliding obstacle)
    predict_stick: Callable[[float, float], StickPrediction] | None = None
    # the corners where the solution may be singular (scenes.corners), for rate predictions
    corners: tuple = ()
    # the friction law on Gamma_C (scenes.friction; frictionless unless a scene says otherwise)
    friction: FrictionLaw = NO_FRICTION
    # where body_force jumps inside elements, a level set whose zero set is the jump line (f
    # smooth on each side): the guaranteed bounds cut their sub-triangles along it
    # (docs/theory.md, 13.2, "Where f jumps"); None: found by the load rule alone
    load_jump: PointFunction | None = None

    def __post_init__(self):
        _check(isinstance(self.material, Material), "material", self.material,
               "a scenes.Material")
        _check(self.dim == 2 or self.material.plane == "strain", "material.plane",
               self.material.plane, "'strain' in 3D (the 3D Lame parameters are plane strain's)")
        self.check_mesh()

    @property
    def dim(self) -> int:
        """2 for a triangle mesh, 3 for a tetrahedral one."""
        return int(self.mesh.dim())

    def check_mesh(self, mesh: Mesh | None = None, level: int | None = None) -> None:
        """The boundary parts and the gap checked on ``mesh`` (default: the initial mesh), as
        every refined mesh must be: refinement puts new facet midpoints under the predicates,
        which may then overlap or meet a non-finite gap. SceneError names the level."""
        where = "" if level is None else f" on the mesh of level {level}"
        dirichlet, contact = self.dirichlet_facets(mesh), self.contact_facets(mesh)
        _check(contact.size > 0, "contact boundary", "empty" + where,
               "non-empty (no boundary facet satisfies is_contact)")
        _check(self.facet_measures(dirichlet, mesh).sum() > 0, "dirichlet boundary",
               "of measure 0" + where, "of positive measure (rigid motion not prevented: the "
               "body must be clamped somewhere)")
        both = np.intersect1d(dirichlet, contact)
        _check(both.size == 0, "dirichlet boundary",
               f"overlapping the contact boundary{where} on {both.size} facets, the first "
               f"at x={self._facet_midpoints(both[:1], mesh).ravel().tolist()}"
               if both.size else "", "disjoint from the contact boundary")
        # the gap at a few points per contact facet, including the end points
        x = self.facet_points(contact, np.array([0.0, 0.5, 1.0]) if self.dim == 2
                              else TRIANGLE_CHECK_POINTS, mesh)
        g = np.asarray(self.gap(x), dtype=float)
        bad = ~np.isfinite(g)
        _check(not bad.any(), "gap", f"{g[bad].ravel()[0]} at x={x[:, bad][:, 0].tolist()}"
               f"{where}" if bad.any() else None, "finite on the contact boundary")

    # --- boundary parts -------------------------------------------------------------------
    def dirichlet_facets(self, mesh: Mesh | None = None) -> np.ndarray:
        return self._facets_of(self.is_dirichlet, mesh)

    def contact_facets(self, mesh: Mesh | None = None) -> np.ndarray:
        return self._facets_of(self.is_contact, mesh)

    def neumann_facets(self, mesh: Mesh | None = None) -> np.ndarray:
        mesh = self.mesh if mesh is None else mesh
        facets = mesh.boundary_facets()
        taken = np.union1d(self.dirichlet_facets(mesh), self.contact_facets(mesh))
        return np.setdiff1d(facets, taken)

    def _facets_of(self, predicate: PointFunction, mesh: Mesh | None) -> np.ndarray:
        mesh = self.mesh if mesh is None else mesh
        facets = mesh.boundary_facets()
        mid = mesh.p[:, mesh.facets[:, facets]].mean(axis=1)
        return facets[np.asarray(predicate(mid), dtype=bool)]

    def facet_lengths(self, facets: np.ndarray, mesh: MeshTri | None = None) -> np.ndarray:
        """Lengths of 2D facets (``facet_measures`` in any dimension)."""
        return self.facet_measures(facets, mesh)

    def facet_measures(self, facets: np.ndarray, mesh: Mesh | None = None) -> np.ndarray:
        """Lengths (2D) or areas (3D) of the given facets."""
        mesh = self.mesh if mesh is None else mesh
        return simplex_measures(mesh.p[:, mesh.facets[:, facets]])

    def facet_points(self, facets: np.ndarray, t: np.ndarray,
                     mesh: Mesh | None = None) -> np.ndarray:
        """Points at local coordinates t (``simplex_points``) on each facet: a + t (b - a) in
        2D; shape (d, n_facets, n_t)."""
        mesh = self.mesh if mesh is None else mesh
        return simplex_points(mesh.p[:, mesh.facets[:, facets]], t)

    def _facet_midpoints(self, facets: np.ndarray, mesh: Mesh | None) -> np.ndarray:
        mesh = self.mesh if mesh is None else mesh
        return mesh.p[:, mesh.facets[:, facets]].mean(axis=1)
