"""vi's P2 pressure on a 3D contact surface from its nodal reactions
(formulations.contact.surface_nodes)."""

import numpy as np
import pytest

from formulations.contact.reference_facets import triangle_rule
from formulations.contact.surface_nodes import (
    BERNSTEIN_MOMENTS,
    lagrange_values,
    nodal_pressures,
    surface_nodes,
    surface_pressure,
)
from formulations.contact.triangles import ContactSurface
from scenes import get_scene


def _surface():
    scene = get_scene("free-boundary-3d")
    mesh = scene.mesh.refined(1)
    trace = ContactSurface.of(scene, mesh)
    return trace, surface_nodes(mesh, trace, 2)


def test_bernstein_moments_sum_to_the_bernstein_integrals():
    # sum_i phi_i = 1, so sum_i int phi_i B_j = int B_j = 1/6 of the area for P2
    assert BERNSTEIN_MOMENTS.sum(axis=0) == pytest.approx(np.full(6, 1 / 6), abs=1e-14)


def test_the_reactions_of_a_non_negative_quadratic_give_it_back():
    trace, nodes = _surface()
    x, y = nodes.points[0], nodes.points[1]
    coefficients = 1.0 + x**2 + 0.5 * y          # Bernstein coefficients, all > 0 here
    assert coefficients.min() > 0
    # its reactions r_i = int lambda phi_i, assembled independently with a quadrature rule
    t, w = triangle_rule(6)
    bary = np.array([1 - t[0] - t[1], t[0], t[1]])
    bernstein = np.array([bary[0] ** 2, bary[1] ** 2, bary[2] ** 2, 2 * bary[0] * bary[1],
                          2 * bary[1] * bary[2], 2 * bary[0] * bary[2]])
    lam = coefficients[nodes.facet_rows] @ bernstein                 # (n_facets, nq)
    lagrange = np.array([2 * b * (b - 0.5) for b in bary] + [4 * bary[0] * bary[1],
                                                              4 * bary[1] * bary[2],
                                                              4 * bary[0] * bary[2]])
    per_facet = np.einsum("fq,iq,q->fi", lam, lagrange, w) * trace.measure[:, None]
    reaction = np.bincount(nodes.facet_rows.ravel(), per_facet.ravel(), nodes.weight.size)
    values = nodal_pressures(trace, nodes, reaction)
    expected = lagrange_values(nodes.facet_rows, coefficients)
    # a feasible exact fit: only the 1e-4-weighted norm term moves it (relative ~1e-8)
    assert values == pytest.approx(expected, rel=1e-6)
    force = trace.integrate(surface_pressure(values[nodes.facet_rows], t), w).sum()
    assert force == pytest.approx(reaction.sum(), rel=1e-6)
