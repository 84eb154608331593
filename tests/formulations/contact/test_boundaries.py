"""The contact boundary's kinds (edges, triangles, quadrilateral faces) answer the same questions
from their own reference facet: quadrature that integrates what it says, Lagrange bases that
are one at their own nodes, measures that add up to Gamma_C's area, located points found again,
lumped masses that sum to the area, and outer normals."""

import numpy as np
import pytest

from formulations.cells import family_for
from formulations.contact import contact_trace
from formulations.contact.boundary import CONTACT_BOUNDARIES
from scenes import get_scene

# a kind, the cell axis and scene that give it, and Gamma_C's measure there
KINDS = {"edges": ("tri", "paper", 2.0), "triangles": ("tri", "paper-3d", 4.0),
         "quadrilaterals": ("quad", "paper-3d", 4.0)}


def boundary(kind: str):
    cell, name, _ = KINDS[kind]
    scene = get_scene(name)
    family = family_for(cell, scene.dim)
    mesh = family.refinement(family.starting_mesh(scene)).refined
    return scene, contact_trace(scene, mesh)


def test_every_registered_kind_is_tested():
    assert set(CONTACT_BOUNDARIES.names()) == set(KINDS)


@pytest.mark.parametrize("kind", KINDS)
def test_the_measures_add_up_and_the_rules_integrate_exactly(kind):
    scene, trace = boundary(kind)
    assert trace.name == kind
    # Gamma_C is the bottom side of a square of side 2, or of a cube's 2 x 2 face: round-off
    assert trace.measure.sum() == pytest.approx(KINDS[kind][2], rel=1e-12)
    t, w = trace.rule(4)
    assert trace.integrate(np.ones((trace.size, w.size)), w).sum() == pytest.approx(
        KINDS[kind][2], rel=1e-12)
    # a quadratic in the first contact coordinate: exact with a degree-4 rule (to round-off)
    s = trace.coordinates_at(t)
    first = s if s.ndim == 2 else s[0]
    exact = {2: 2 / 3, 3: 4 / 3}[trace.dim]  # int s^2 over [-1, 1] (x [-1, 1])
    assert trace.integrate(first**2, w).sum() == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("kind", KINDS)
def test_lagrange_bases_are_one_at_their_own_nodes(kind):
    _, trace = boundary(kind)
    for order in (1, 2):
        nodes = trace.lagrange_points(order)
        values = trace.lagrange_basis(order)(nodes)
        assert np.allclose(values, np.eye(values.shape[0]), atol=1e-12)


@pytest.mark.parametrize("kind", KINDS)
def test_located_points_are_found_again_and_the_pressure_there_is_exact(kind):
    _, trace = boundary(kind)
    t = trace.rule(3)[0]  # points inside the facets: each belongs to one facet only
    s = trace.row_coordinates(t)
    # a pressure linear in the local coordinates of every facet: pressure_at reproduces it
    weights = np.arange(1.0, trace.size + 1.0)

    def pressure(tt):
        tt = np.asarray(tt, dtype=float)
        first = tt if tt.ndim == 1 else tt[0]
        return weights[:, None] * (1.0 + first[None, :])

    # linear interpolation between samples (edges), the P2/Q2 interpolant (surfaces): exact
    assert np.allclose(trace.pressure_at(pressure, s), pressure(t).ravel(), rtol=1e-9)


@pytest.mark.parametrize("kind, order", [(kind, 1) for kind in KINDS]
                         + [("edges", 2), ("quadrilaterals", 2)])
def test_nodal_masses_sum_to_the_area_and_normals_point_out(kind, order):
    """Lumped masses are positive where they are the basis functions' integrals (P1, 2D P2,
    Q1, Q2: Simpson's 1/36, 4/36, 16/36); the P2 triangles' fit their own (see
    formulations.contact.surface_nodes)."""
    scene, trace = boundary(kind)
    nodes = trace.nodes(order)
    assert nodes.weight.sum() == pytest.approx(KINDS[kind][2], rel=1e-12)
    assert np.all(nodes.weight > 0)
    assert nodes.points.shape[1] == nodes.weight.size == np.unique(nodes.facet_rows).size
    # each facet's rows are its Lagrange points, in their order
    at = trace.points(trace.lagrange_points(order))  # (d, n_facets, k)
    assert np.allclose(nodes.points[:, nodes.facet_rows], at, atol=1e-12)
    # Gamma_C is the bottom: the outer normal is -e_y in 2D, -e_z in 3D
    down = -np.eye(trace.dim)[:, -1][:, None]
    assert np.allclose(trace.normal, down, atol=1e-12)
    assert np.allclose(nodes.normal, down, atol=1e-12)
