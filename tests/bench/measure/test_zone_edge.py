"""The contact zone's edge by the square-root law (bench.measure.zone_edge)."""

from types import SimpleNamespace

import numpy as np
import pytest
from skfem import MeshTri

from bench.measure.contact import contact_zone
from bench.measure.zone_edge import square_root_zone
from formulations.contact import contact_trace
from formulations.contact.triangles import ContactSurface
from scenes import get_scene

HALF_WIDTH = 0.3


def _hertz_profile(s, a=HALF_WIDTH):
    return np.sqrt(np.clip(1 - np.sum(np.atleast_2d(s) ** 2, axis=0) / a**2, 0.0, None))


def _line_solution(nodal):
    """A 2D 'solution' whose lambda_h is the P1 interpolant of ``nodal(s)`` on hertz's
    Gamma_C."""
    scene = get_scene("hertz")
    trace = contact_trace(scene, scene.mesh.refined(3))
    s0, s1 = trace.coordinate

    def pressure(t):
        t = np.asarray(t, dtype=float)
        return (1 - t)[None, :] * nodal(s0)[:, None] + t[None, :] * nodal(s1)[:, None]

    return SimpleNamespace(trace=trace, elasticity=SimpleNamespace(order=1), pressure=pressure)


def test_the_edge_is_the_zero_of_the_secant_of_lambda_squared_in_2d():
    solution = _line_solution(lambda s: _hertz_profile(s))
    start, end = square_root_zone(solution)
    nodes = np.unique(solution.trace.coordinate)
    inside = nodes[np.abs(nodes) < HALF_WIDTH]
    # lambda^2 = 1 - x^2 / a^2 at the nodes: the secant through the last two pressed nodes
    # x_i, x_{i-1} vanishes at x_i + (a^2 - x_i^2) / (x_i + x_{i-1}) (algebra, not the code),
    # beyond a by (a - x_i)(a - x_{i-1}) / (x_i + x_{i-1}) (lambda^2 is concave), and the
    # zone is cut back to the support, which ends at the first unpressed node
    right, left = inside[-1], inside[-2]
    expected_end = min(right + (HALF_WIDTH**2 - right**2) / (right + left),
                       nodes[nodes > right][0])
    first, second = inside[0], inside[1]
    expected_start = max(first - (HALF_WIDTH**2 - first**2) / (-first - second),
                         nodes[nodes < first][-1])
    assert end == pytest.approx(expected_end, abs=1e-12)  # round-off only
    assert start == pytest.approx(expected_start, abs=1e-12)
    # the secant's end is nearer the true edge than the support's
    assert abs(end - HALF_WIDTH) < abs(contact_zone(solution)[1] - HALF_WIDTH)


def test_a_piecewise_constant_pressure_keeps_its_support():
    # lambda_h = 1 on the facets that meet |x| < a, 0 elsewhere: no gradient to extrapolate
    scene = get_scene("hertz")
    trace = contact_trace(scene, scene.mesh.refined(2))
    s0, s1 = trace.coordinate
    pressed = (np.abs(s0) < HALF_WIDTH) | (np.abs(s1) < HALF_WIDTH)
    solution = SimpleNamespace(
        trace=trace, elasticity=SimpleNamespace(order=1),
        pressure=lambda t: np.repeat(pressed.astype(float)[:, None], np.size(t), axis=1))
    assert square_root_zone(solution) == pytest.approx(contact_zone(solution), abs=1e-14)


def test_no_contact_gives_nan():
    solution = _line_solution(lambda s: 0.0 * s)
    assert np.isnan(square_root_zone(solution)).all()


def _disc_solution(divisions: int):
    """A 3D 'solution' on a uniform triangulation of (-1, 1)^2 as Gamma_C, lambda_h the P1
    interpolant of Hertz's profile with radius HALF_WIDTH."""
    mesh = MeshTri.init_tensor(*(np.linspace(-1, 1, divisions + 1),) * 2)
    corners = mesh.p[:, mesh.t]                                    # (2, 3, n)
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    area = 0.5 * np.abs(e1[0] * e2[1] - e1[1] * e2[0])
    n = mesh.t.shape[1]
    surface = ContactSurface(mesh=mesh, facets=np.arange(n), vertices=mesh.t,
                             normal=np.tile([[0.0], [0.0], [-1.0]], n), measure=area,
                             diameter=np.full(n, 2 * np.sqrt(2) / divisions),
                             coordinate=corners, element=np.arange(n))
    nodal = _hertz_profile(mesh.p)[mesh.t]                         # (3, n)

    def pressure(t):
        t = np.asarray(t, dtype=float)
        phi = np.array([1 - t[0] - t[1], t[0], t[1]])              # (3, nq)
        return np.einsum("kn,kq->nq", nodal, phi)

    return SimpleNamespace(trace=surface, elasticity=SimpleNamespace(order=1),
                           pressure=pressure)


def test_the_disc_radius_is_found_inside_the_overshooting_support():
    solution = _disc_solution(64)     # h = 1/32 against a = 0.3
    start, end = square_root_zone(solution)
    radius = 0.5 * (end - start)
    # a secant of lambda^2 = 1 - r^2/a^2 overshoots its zero by at most h^2 / a along each
    # edge (the 2D test's formula), 1.1 % of a here: allowed 1.5 %
    assert radius == pytest.approx(HALF_WIDTH, rel=0.015)
    # the support adds up to a triangle (h / a = 10 %) around the disc
    support = contact_zone(solution)
    assert 0.5 * (support[1] - support[0]) > 1.03 * HALF_WIDTH
    assert abs(0.5 * (start + end)) < 1e-3  # the centre: symmetric mesh and pressure
