"""The mixed method's multiplier spaces on tetrahedra: the macro-element condition of the star
patches checked on the patches themselves, the inf-sup constant of the stable and the unstable
choices, and clear errors for options that do not exist in 3D (docs/theory.md, sections 14.7
and 19.2)."""

import re
from dataclasses import replace

import numpy as np
import pytest

from formulations import get_formulation, solve
from formulations.contact import contact_trace
from formulations.contact.patches import free_normal_vertices, patch_sizes, patches
from formulations.contact.reference_facets import triangle_rule
from formulations.diagnostics import inf_sup_constant
from formulations.elasticity import assemble_elasticity
from scenes import get_scene


def graded_mesh(scene, steps: int = 2):
    """The scene's mesh refined ``steps`` times at the tetrahedra nearest the contact centre:
    an adaptive-looking mesh whose contact triangles differ in size."""
    mesh = scene.mesh.refined()
    for _ in range(steps):
        centre = mesh.p[:, mesh.t].mean(axis=1)
        mesh = mesh.refined(np.flatnonzero(np.linalg.norm(centre - np.array(
            [[0.0], [0.0], [-1.0]]), axis=0) < 0.6))
    return mesh


def star_patches_of(scene, mesh):
    elasticity = assemble_elasticity(scene, mesh, 1)
    surface = contact_trace(scene, mesh)
    admissible = free_normal_vertices(surface, elasticity.basis.nodal_dofs, elasticity.free)
    return surface, admissible, patches(surface, "star", admissible)


@pytest.mark.parametrize("graded", [False, True])
def test_every_star_patch_holds_the_whole_star_of_a_free_vertex(graded):
    # the macro-element condition, checked from the patches alone: some vertex with a free
    # normal displacement has all of its contact triangles inside the patch
    scene = get_scene("paper-3d")
    mesh = graded_mesh(scene) if graded else scene.mesh.refined(2)
    surface, admissible, patch = star_patches_of(scene, mesh)
    assert patch.shape == (surface.size,) and patch.min() == 0
    assert np.array_equal(np.unique(patch), np.arange(patch.max() + 1))  # no empty patch
    corners = surface.vertices
    for p in range(patch.max() + 1):
        inside = patch == p
        holds_star = [admissible[v] and np.all(inside[(corners == v).any(axis=0)])
                      for v in np.unique(corners[:, inside])]
        assert any(holds_star), f"patch {p} holds no whole star"
    if graded:  # the contact triangles do differ in size there
        assert surface.measure.max() > 3.5 * surface.measure.min()


def test_patch_sizes_and_the_triangle_patches():
    scene = get_scene("paper-3d")
    surface, admissible, patch = star_patches_of(scene, scene.mesh.refined(2))
    area, H = patch_sizes(surface, patch)
    # the patches tile Gamma_C, the bottom face (-1, 1)^2 of area 4
    assert area.sum() == pytest.approx(4.0, rel=1e-12)
    assert np.allclose(H**2, area)
    # a star of at least four equal triangles: h / H = (|T| / |P|)^(1/2) <= 1/2 wherever a
    # triangle joined no other patch; measured 0.41 at most on this mesh
    assert np.sqrt(surface.measure / area[patch]).max() <= 0.5
    assert np.array_equal(patches(surface, "triangle", admissible), np.arange(surface.size))


@pytest.mark.parametrize("order", [1, 2])
def test_B_integrates_normal_displacement_and_G_a_linear_gap_exactly(order):
    # on a graded mesh: B u = int_P u . n over each patch for a field of degree p, and
    # G_P = int_P g = |T| g(centroid) summed over its triangles for a linear g (round-off)
    scene = replace(get_scene("paper-3d"), gap=lambda x: 0.3 * x[0] - 0.2 * x[1] + 0.05)
    disc = get_formulation("mixed")(scene, graded_mesh(scene, steps=1), order=order,
                                    multiplier_mesh="star")
    surface, patch = disc.trace, star_patches_of(scene, disc.elasticity.mesh)[2]
    x = disc.elasticity.basis.doflocs  # (3, N): every DOF's location
    u = np.where(np.arange(x.shape[1]) % 3 == 2, x[0] ** order + 0.5 * x[1] - 0.1, 7.0)
    # exact: n = (0, 0, -1) on the bottom face, so u . n = -(x^p + y / 2 - 1 / 10); the
    # tangential components (7) must not count
    t, w = triangle_rule(4)
    points = surface.points(t)
    exact = -np.bincount(patch, weights=((points[0] ** order + 0.5 * points[1] - 0.1)
                                         * w).sum(axis=1) * surface.measure)
    assert disc.qp.B @ u[disc.elasticity.free] == pytest.approx(exact, rel=1e-12, abs=1e-14)
    centroid = surface.points(np.array([[1 / 3], [1 / 3]]))[:, :, 0]
    expected_G = np.bincount(patch, weights=surface.measure * scene.gap(centroid))
    assert disc.qp.G == pytest.approx(expected_G, rel=1e-12, abs=1e-14)


SPACES = {"coarse P1": {}, "star": dict(multiplier_mesh="star"),
          "triangle": dict(h_over_H=1.0, multiplier_degree=0)}


def test_coarse_hats_and_stars_are_inf_sup_stable_and_the_triangles_are_not():
    # beta_h on paper-3d, P1, uniform levels 0..2 (300, 1944, 13 872 DOFs): measured 0.517,
    # 0.521, 0.525 for P1 on the coarse surface (the default), 0.673, 0.404, 0.344 for star
    # patches (then 0.336 at 104 544) and 0 for P0 on the triangles, whose multipliers
    # outnumber the normal displacements (B' has a kernel: round-off only). The floors and
    # the last ratios leave room for round-off, not for a decay like h (a ratio of 1/2)
    scene = get_scene("paper-3d")
    beta = {name: [inf_sup_constant(get_formulation("mixed")(scene, scene.mesh.refined(level),
                                                             **options))
                   for level in range(3)] for name, options in SPACES.items()}
    assert min(beta["coarse P1"]) > 0.45 and beta["coarse P1"][2] > 0.95 * beta["coarse P1"][1]
    assert min(beta["star"]) > 0.25 and beta["star"][2] > 0.8 * beta["star"][1]
    assert max(beta["triangle"]) < 1e-6


def test_star_patches_and_coarse_hats_stay_stable_on_a_graded_mesh():
    # measured on this mesh (1.5e4 DOFs): stars 0.39 (the uniform level 2 has 0.344), P1 on
    # the coarse surface 0.577 (uniform: 0.525)
    scene = get_scene("paper-3d")
    mesh = graded_mesh(scene)
    assert inf_sup_constant(get_formulation("mixed")(scene, mesh, multiplier_mesh="star")) > 0.25
    assert inf_sup_constant(get_formulation("mixed")(scene, mesh)) > 0.4


def test_the_unstable_choice_still_gets_the_unique_displacement():
    # triangle patches: the condensed B K^-1 B' is singular (measured: the active-set iteration
    # meets a singular active block and hands the QP to the reference solver; whether round-off
    # lets a Cholesky factor through first is not asserted); u is unique, so the energies agree
    # (Clarabel's relative gap ~1e-8)
    scene = get_scene("paper-3d")
    disc = get_formulation("mixed")(scene, scene.mesh.refined(), h_over_H=1.0,
                                    multiplier_degree=0)
    fast, reference = solve(disc, "active-set"), solve(disc, "reference")
    assert fast.ok and reference.ok
    assert fast.energy == pytest.approx(reference.energy, rel=1e-7)


@pytest.mark.parametrize(("options", "allowed"), [
    (dict(h_over_H=0.25), "h_over_H=0.25 is not allowed on a 3D contact surface: 0.5 (the "
                          "surface one level coarser) or 1"),
    (dict(multiplier_degree=2), "multiplier_degree=2 is not allowed on a 3D contact surface: "
                                "0 or 1"),
    (dict(multiplier_degree=1, multiplier_mesh="star"), "multiplier_degree=1 is not allowed "
                                                        "on a 3D contact surface with "
                                                        "multiplier_mesh='star': 0"),
    (dict(multiplier_mesh="stars"), "multiplier_mesh='stars' is not one of coarse, star")])
def test_options_that_have_no_3d_meaning_are_refused(options, allowed):
    scene = get_scene("paper-3d")
    with pytest.raises(ValueError, match=re.escape(allowed)):
        get_formulation("mixed")(scene, scene.mesh, **options)


def test_a_2d_boundary_refuses_a_3d_multiplier_mesh():
    scene = get_scene("paper")
    with pytest.raises(ValueError, match=re.escape("multiplier_mesh='star' is not allowed on a "
                                                   "2D contact boundary: coarse")):
        get_formulation("mixed")(scene, scene.mesh, multiplier_mesh="star")
