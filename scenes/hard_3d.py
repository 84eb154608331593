"""Hard scenes in 3D (tags ``hard`` and ``3d``; docs/theory.md, sections 8 and 14.5): a thin
plate, a nearly incompressible block and grazing contact, each a box clamped on top with
Gamma_C its bottom face (outer normal (0, 0, -1)), so that g is the gap along n = (0, 0, -1).
Like the 2D hard scenes they are left out of the comparison matrix and run as hard cases, at
fewer uniform refinements (``bench.hard.cases.scenes.hard_level``)."""

from __future__ import annotations

import numpy as np

from scenes.base import Material, Scene
from scenes.budget import tensor_mesh
from scenes.paper_3d import ball_gap
from scenes.registry import register_scene

_TOL = 1e-10


def _box(name, description, gap, *, width=2.0, height=2.0, n=4, nz=4, poisson_ratio=0.3,
         young_modulus=70000.0, body_force=None, parameters=None) -> Scene:
    xs = np.linspace(-width / 2, width / 2, n + 1)
    zs = np.linspace(-height / 2, height / 2, nz + 1)
    return Scene(name=name, description=description, mesh=tensor_mesh(xs, xs, zs),
                 material=Material(young_modulus, poisson_ratio, "strain"),
                 is_dirichlet=lambda x: np.abs(x[2] - height / 2) < _TOL,
                 is_contact=lambda x: np.abs(x[2] + height / 2) < _TOL,
                 gap=gap, contact_coordinate=lambda x: np.asarray(x)[:2],
                 body_force=body_force, parameters=parameters or {}, tags=("hard", "3d"))


@register_scene("thin-3d", "hard: a 50:1 plate pressed by a paraboloid (thin body, flat "
                           "elements)",
                tags=("hard", "3d"), dim=3)
def thin_3d() -> Scene:
    return _box("thin-3d", "plate (-1,1)^2 x (-0.02,0.02), g = r^2 - 0.01",
                lambda x: x[0] ** 2 + x[1] ** 2 - 0.01, height=0.04, n=8, nz=1)


@register_scene("incompressible-3d", "hard: paper-3d's ball on a nearly incompressible body "
                                     "(nu = 0.4999; P1 locking)",
                tags=("hard", "3d"), dim=3)
def incompressible_3d(poisson_ratio: float = 0.4999) -> Scene:
    return _box("incompressible-3d", f"paper-3d geometry, nu = {poisson_ratio}", ball_gap,
                poisson_ratio=poisson_ratio, parameters={"poisson_ratio": poisson_ratio})


@register_scene("grazing-3d", "hard: a block hanging under its weight (nu = 0) just touching a "
                              "flat obstacle: u_n = g and p = 0 on all of Gamma_C",
                tags=("hard", "3d"), dim=3)
def grazing_3d(density: float = 1000.0) -> Scene:
    """The 2D ``grazing`` scene's one-dimensional solution holds in 3D too (nu = 0,
    traction-free sides): sigma_zz = rho (z + 1), u_z = rho ((z + 1)^2 - 4) / (2 E), the bottom
    moves down by 2 rho / E, and the obstacle is put exactly there."""
    rho, E = float(density), 70000.0
    return _box("grazing-3d", f"hanging block, nu = 0, flat obstacle at g = 2 rho / E, "
                f"rho = {rho:g}", lambda x: np.full(x.shape[1:], 2.0 * rho / E),
                poisson_ratio=0.0, young_modulus=E,
                body_force=lambda x: np.array([0.0 * x[0], 0.0 * x[0], -rho + 0.0 * x[0]]),
                parameters={"density": rho})
