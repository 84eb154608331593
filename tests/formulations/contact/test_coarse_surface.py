"""The contact surface one level coarser (docs/theory.md, 19.2): on a uniformly refined mesh it
is the surface before the refinement, its hats are that surface's P1 hats and the mixed
method's rows integrate against them; on a bisection-refined mesh the hats still make a
non-negative partition of unity."""

from dataclasses import replace

import numpy as np
import pytest

from formulations import get_formulation
from formulations.contact import contact_trace
from formulations.contact.coarse_surface import coarse_hats, coarse_triangles, coarse_vertices
from formulations.contact.reference_facets import triangle_rule
from scenes import get_scene


def coarse_of(scene, mesh):
    surface = contact_trace(scene, mesh)
    coarse = coarse_vertices(surface.vertices, mesh.p.shape[1])
    return surface, coarse


@pytest.mark.parametrize("level", [1, 2])
def test_a_uniform_refinement_is_undone_exactly(level):
    scene = get_scene("hertz-3d")
    fine, before = scene.mesh.refined(level), scene.mesh.refined(level - 1)
    surface, coarse = coarse_of(scene, fine)
    # scikit-fem keeps the old vertices' numbers: the coarse vertices are the old surface's
    assert np.array_equal(np.flatnonzero(coarse), np.unique(contact_trace(scene, before)
                                                            .vertices))
    patch = coarse_triangles(surface.vertices, coarse)
    assert np.array_equal(np.bincount(patch), np.full(contact_trace(scene, before).size, 4))
    # each coarse triangle is the union of its four children: the same area
    area = np.bincount(patch, weights=surface.measure)
    assert np.sort(area) == pytest.approx(np.sort(contact_trace(scene, before).measure),
                                          rel=1e-12)


def test_the_hats_are_the_coarse_surfaces_p1_hats():
    # every vertex outside C is the midpoint of a coarse edge: its weights are 1/2, 1/2, and
    # psi_Z interpolates the coarse hat at every fine vertex (checked from the fine vertices'
    # positions: the coarse hat of Z is linear on the coarse triangles around it)
    scene = get_scene("hertz-3d")
    fine = scene.mesh.refined(1)
    surface, coarse = coarse_of(scene, fine)
    P = coarse_hats(surface.vertices, coarse)
    on = np.unique(surface.vertices)
    assert np.asarray(P.sum(axis=1)).ravel()[on] == pytest.approx(1.0, abs=1e-15)
    assert P.min() >= 0
    weights = np.sort(P[on[~coarse[on]]].toarray(), axis=1)[:, -2:]
    assert weights == pytest.approx(0.5, abs=1e-15)
    # the partition reproduces linear functions: sum_Z x_Z psi_Z(z) = x_z at every vertex
    xy = fine.p[:2]
    assert P[on] @ xy[:, np.flatnonzero(coarse)].T == pytest.approx(xy[:, on].T, abs=1e-14)


@pytest.mark.parametrize("order", [1, 2])
def test_the_rows_integrate_against_the_coarse_hats(order):
    # B u = int psi_Z u . n and G = int psi_Z g, computed independently on the coarse mesh,
    # whose hats are linear on its own triangles (integrands of degree p + 1 and 3: a rule of
    # degree 4 is exact; round-off only)
    scene = replace(get_scene("paper-3d"), gap=lambda x: 0.3 * x[0] ** 2 - 0.2 * x[1] + 0.05)
    fine, before = scene.mesh.refined(2), scene.mesh.refined(1)
    disc = get_formulation("mixed")(scene, fine, order=order, h_over_H=0.5, multiplier_degree=1)
    x = disc.elasticity.basis.doflocs
    u = np.where(np.arange(x.shape[1]) % 3 == 2, x[0] ** order + 0.5 * x[1] - 0.1, 7.0)
    coarse = contact_trace(scene, before)
    t, w = triangle_rule(4)
    points = coarse.points(t)  # (3, n, nq); n = (0, 0, -1): u . n = -(x^p + y / 2 - 1/10)
    u_n = -(points[0] ** order + 0.5 * points[1] - 0.1)
    gap = np.asarray(scene.gap(points))
    bary = np.array([1 - t[0] - t[1], t[0], t[1]])  # the coarse hats on each coarse triangle
    rows = np.unique(coarse.vertices)
    exact_B, exact_G = (np.zeros(rows.size) for _ in range(2))
    for k in range(3):
        at = np.searchsorted(rows, coarse.vertices[k])
        np.add.at(exact_B, at, (bary[k] * u_n * w).sum(axis=1) * coarse.measure)
        np.add.at(exact_G, at, (bary[k] * gap * w).sum(axis=1) * coarse.measure)
    assert disc.qp.B @ u[disc.elasticity.free] == pytest.approx(exact_B, rel=1e-12, abs=1e-14)
    assert disc.qp.G == pytest.approx(exact_G, rel=1e-12, abs=1e-14)  # a quadratic gap


def test_a_bisection_refined_surface_keeps_a_partition_of_unity():
    scene = get_scene("hertz-3d")
    mesh = scene.mesh.refined()
    for _ in range(2):
        centre = mesh.p[:, mesh.t].mean(axis=1)
        mesh = mesh.refined(np.flatnonzero(np.linalg.norm(centre - np.array(
            [[0.0], [0.0], [-2.0]]), axis=0) < 0.8))
    surface, coarse = coarse_of(scene, mesh)
    P = coarse_hats(surface.vertices, coarse)
    on = np.unique(surface.vertices)
    assert np.asarray(P.sum(axis=1)).ravel()[on] == pytest.approx(1.0, abs=1e-14)
    assert P.min() >= 0 and (np.diff(P.tocsr().indptr)[on] >= 1).all()
    # no two coarse vertices share a triangle, and every triangle lands in one patch
    assert (coarse[surface.vertices].sum(axis=0) <= 1).all()
    patch = coarse_triangles(surface.vertices, coarse)
    assert patch.min() == 0 and np.array_equal(np.unique(patch), np.arange(patch.max() + 1))
