"""Hard scenes (tag ``hard``): cases where a formulation or a solver may break
(docs/theory.md, section 8).

Each is a rectangle clamped on top with Gamma_C its bottom edge (outer normal (0, -1)), so the
gap is g(x) along n = (0, -1): negative g means the obstacle pushes the body up. They are left
out of the default comparison (``python -m bench compare``) and exercised by tests/scenes.
"""

from __future__ import annotations

import numpy as np

from scenes.base import Material, Scene
from scenes.budget import tensor_mesh
from scenes.paper import paper_gap
from scenes.registry import register_scene

_TOL = 1e-10


def _block(name, description, gap, *, width=2.0, height=2.0, nx=4, ny=4, poisson_ratio=0.3,
           plane="stress", young_modulus=70000.0, body_force=None, traction=None, ys=None,
           is_dirichlet=None, parameters=None) -> Scene:
    xs = np.linspace(-width / 2, width / 2, nx + 1)
    ys = np.linspace(-height / 2, height / 2, ny + 1) if ys is None else ys
    return Scene(name=name, description=description, mesh=tensor_mesh(xs, ys),
                 material=Material(young_modulus, poisson_ratio, plane),
                 is_dirichlet=is_dirichlet or (lambda x: np.abs(x[1] - height / 2) < _TOL),
                 is_contact=lambda x: np.abs(x[1] + height / 2) < _TOL,
                 gap=gap, contact_coordinate=lambda x: x[0], body_force=body_force,
                 traction=traction, parameters=parameters or {}, tags=("hard",))


@register_scene("no-contact", "hard: a body pulled down by its weight, the obstacle 1.0 away "
                              "(nothing touches)",
                tags=("hard",), dim=2)
def no_contact() -> Scene:
    return _block("no-contact", "gap 1.0, body force (0, -1000)",
                  lambda x: np.full(x.shape[1:], 1.0),
                  body_force=lambda x: np.array([0.0 * x[0], -1000.0 + 0.0 * x[0]]))


@register_scene("full-contact", "hard: a flat obstacle pushes the whole of Gamma_C up by 0.01",
                tags=("hard",), dim=2)
def full_contact() -> Scene:
    return _block("full-contact", "flat obstacle, g = -0.01 on all of Gamma_C",
                  lambda x: np.full(x.shape[1:], -0.01))


@register_scene("incompressible", "hard: the paper's obstacle on a nearly incompressible body "
                                  "(plane strain, nu = 0.4999; P1 locking)",
                tags=("hard",), dim=2)
def incompressible(poisson_ratio: float = 0.4999) -> Scene:
    return _block("incompressible", f"paper geometry, plane strain, nu = {poisson_ratio}",
                  paper_gap,
                  poisson_ratio=poisson_ratio, plane="strain",
                  parameters={"poisson_ratio": poisson_ratio})


@register_scene("wedge", "hard: an obstacle with a kink, g = 0.5 |x| - 0.05",
                tags=("hard",), dim=2)
def wedge() -> Scene:
    return _block("wedge", "wedge obstacle g = 0.5|x| - 0.05", lambda x: 0.5 * np.abs(x[0]) - 0.05)


@register_scene("thin", "hard: a 50:1 strip pressed by a parabola (thin body, long elements)",
                tags=("hard",), dim=2)
def thin() -> Scene:
    return _block("thin", "strip (-1,1) x (-0.02,0.02), g = x^2 - 0.001",
                  lambda x: x[0] ** 2 - 0.001, height=0.04, nx=50, ny=1)


@register_scene("grazing", "hard: a block hanging under its weight (nu = 0) just touching a flat "
                           "obstacle: u_n = g and p = 0 on all of Gamma_C (no strict "
                           "complementarity)",
                tags=("hard",), dim=2)
def grazing(density: float = 1000.0) -> Scene:
    """With nu = 0 and traction-free sides the hanging block is one-dimensional:
    sigma_yy = rho (y + 1), u_y = rho ((y + 1)^2 - 4) / (2E), so the bottom moves down by
    u_n = 2 rho / E. The obstacle is put exactly there: g = 2 rho / E, the body rests on it
    with zero pressure everywhere -- every contact constraint is degenerate (tight, with a zero
    multiplier). P1 is not exact for the quadratic u_y, so the discrete body presses with a
    small residual force of order h^2, which the solvers must get right with every constraint
    nearly degenerate."""
    rho, E = float(density), 70000.0
    return _block("grazing", f"hanging block, nu = 0, flat obstacle at g = 2 rho / E, "
                  f"rho = {rho:g}", lambda x: np.full(x.shape[1:], 2.0 * rho / E),
                  poisson_ratio=0.0, young_modulus=E,
                  body_force=lambda x: np.array([0.0 * x[0], -rho + 0.0 * x[0]]),
                  parameters={"density": rho})


@register_scene("traction", "hard: load-driven contact: a cantilever (clamped left side) "
                            "pressed by a traction on its top onto a flat obstacle 0.002 below",
                tags=("hard",), dim=2)
def traction(pressure: float = 400.0) -> Scene:
    """No obstacle penetrates the initial configuration (g = 0.002 > 0): contact is made by
    the load alone, near the free end, and the contact zone ends at the corner (1, -1)."""
    q = float(pressure)
    return _block("traction", f"cantilever, top traction (0, -{q:g}), flat obstacle g = 0.002",
                  lambda x: np.full(x.shape[1:], 0.002),
                  traction=lambda x: np.array([0.0 * x[0],
                                               np.where(x[1] > 1.0 - _TOL, -q, 0.0)]),
                  is_dirichlet=lambda x: np.abs(x[0] + 1.0) < _TOL,
                  parameters={"pressure": q})


@register_scene("corner", "hard: a tilted flat obstacle pushes the left end up; the contact "
                          "zone ends at the corner (-1, -1) of the domain",
                tags=("hard",), dim=2)
def corner() -> Scene:
    return _block("corner", "tilted flat obstacle g = 0.02 (x + 0.2)",
                  lambda x: 0.02 * (x[0] + 0.2))


@register_scene("graded", "hard: the paper's obstacle on a strongly graded initial mesh "
                          "(geometric layers towards Gamma_C, aspect ratios up to ~130)",
                tags=("hard",), dim=2)
def graded(ratio: float = 0.5, layers: int = 9) -> Scene:
    """y-spacing shrinks by ``ratio`` towards the contact edge: with the defaults the bottom
    layer is 2 ratio^(layers-1) / sum_k ratio^k = 0.0039 thin against elements 0.5 wide
    (aspect ratio 128)."""
    widths = ratio ** np.arange(layers)  # bottom layer last
    ys = 1.0 - 2.0 * np.concatenate([[0.0], np.cumsum(widths)]) / widths.sum()
    return _block("graded", f"paper gap, {layers} geometric layers, ratio {ratio:g}",
                  paper_gap,
                  ys=np.sort(ys), poisson_ratio=0.33,
                  parameters={"ratio": ratio, "layers": layers})
