"""Patches that share their saddle-point system (docs/theory.md, 13.2, "Patch classes")."""

import numpy as np
import pytest
from skfem import MeshTri

from estimators.guaranteed import patch_classes, patch_data, patches, symmetrisation
from estimators.guaranteed.equilibrated import equilibrate
from estimators.guaranteed.patch_classes import element_classes
from estimators.guaranteed.rt_reference import ReferenceRT, element_matrices, scalar_values
from formulations import get_formulation, solve
from formulations.elasticity import ELEMENTS
from scenes import get_scene


def matrices(mesh, k=1):
    X, W = ReferenceRT.build(mesh, k, 2 * k + 2).quadrature
    return element_matrices(mesh, k, X, W, scalar_values(ELEMENTS[k](), X))


@pytest.mark.parametrize("k", [1, 2, 3])
def test_congruent_elements_share_a_class_and_others_do_not(k, skewed_mesh):
    """Classes from the geometry against the matrices themselves (``rt_reference``)."""
    uniform = MeshTri.init_symmetric().refined(3)
    mass, divergence = matrices(uniform, k)
    owner = element_classes(uniform, k)
    # red refinement of the four starting triangles: few shapes and facet orientations
    assert np.unique(owner).size <= 32
    assert np.abs(mass - mass[owner]).max() <= 1e-12 * np.abs(mass).max()
    assert np.array_equal(divergence, divergence[owner])   # orientation signs only
    mass, divergence = matrices(skewed_mesh, k)
    owner = element_classes(skewed_mesh, k)
    # the sheared mesh: an element shares a class only with an equal one (to round-off)
    assert np.abs(mass - mass[owner]).max() <= 1e-12 * np.abs(mass).max()
    assert np.unique(owner).size > mass.shape[0] // 2


def test_a_hash_collision_does_not_merge_different_systems(monkeypatch, skewed_mesh):
    mass, divergence = matrices(skewed_mesh)
    monkeypatch.setattr(patch_classes, "element_hash", lambda flat, scale: np.zeros(len(flat[0])))
    owner = element_classes(skewed_mesh, 1)
    assert np.abs(mass - mass[owner]).max() <= 1e-12 * np.abs(mass).max()
    keys = np.array([[1, 2, 3], [1, 2, 4], [1, 2, 3], [0, 0, 0]])
    monkeypatch.setattr(patch_classes, "key_hash", lambda k: np.zeros(k.shape[0]))
    assert patch_classes.patch_classes(keys).tolist() == [0, 1, 0, 3]


def locally_refined(scene, times):
    mesh = scene.mesh.refined(2)
    for _ in range(times):
        centre = mesh.p[:, mesh.t].mean(axis=1)
        mesh = mesh.refined(np.flatnonzero(centre[0] + centre[1] < centre.sum(axis=0).mean()))
    return mesh


def row_by_row(reconstruction, *_):
    """No symmetrising correction: the patch solves' own stress."""
    return reconstruction


@pytest.mark.parametrize("order", [1, 2])
def test_shared_systems_give_the_stress_of_one_solve_per_patch(monkeypatch, order):
    """The classes' inverses against one LU per patch (every element its own class): the same
    stress to round-off of the dense solves (seen 4e-15 at P1 and 6e-14 at P2, relative;
    bound 1e-11)."""
    scene = get_scene("paper")
    solution = solve(get_formulation("vi")(scene, locally_refined(scene, 3), order=order),
                     "active-set")
    monkeypatch.setattr(patches, "BATCH", 64)      # several chunks, several classes each
    owners, classify = [], patches.patch_owners
    monkeypatch.setattr(patches, "patch_owners",
                        lambda *a: owners.append(classify(*a)) or owners[-1])
    shared = equilibrate(scene, solution, symmetrise=row_by_row)[0].dofs
    # the classes repeat: most chunks take the inverses, not an LU per patch
    assert 8 * np.unique(owners[0]).size < owners[0].size
    monkeypatch.setattr(patch_data, "element_classes",
                        lambda mesh, k: np.arange(mesh.t.shape[1]))
    alone = equilibrate(scene, solution, symmetrise=row_by_row)[0].dofs
    assert np.abs(shared - alone).max() <= 1e-11 * np.abs(alone).max()


def test_patches_whose_hashes_collide_keep_their_own_systems(monkeypatch):
    """Every patch of equal size, element count and clamping grouped as one (as if all their
    hashes collided): the pair-by-pair check must split the groups again, so the stress is
    that of one solve per patch (bound as above)."""
    scene = get_scene("paper")
    solution = solve(get_formulation("vi")(scene, locally_refined(scene, 3)), "active-set")
    monkeypatch.setattr(patch_data, "element_classes", lambda mesh, k: np.arange(mesh.t.shape[1]))
    alone = equilibrate(scene, solution, symmetrise=row_by_row)[0].dofs
    monkeypatch.undo()
    monkeypatch.setattr(patches, "BATCH", 64)
    shared_hashes, owners = patch_classes.patch_classes, []

    def colliding(keys):
        owners.append(shared_hashes(keys[:, :3]))
        return owners[-1]

    monkeypatch.setattr(patch_classes, "patch_classes", colliding)
    merged = equilibrate(scene, solution, symmetrise=row_by_row)[0].dofs
    assert np.unique(owners[0]).size <= 10    # 199 distinct systems, grouped as 8
    assert np.abs(merged - alone).max() <= 1e-11 * np.abs(alone).max()


@pytest.mark.parametrize("refine", [3, 0])
def test_class_products_equal_the_element_products(refine):
    """One product per class (uniform mesh: few classes) and one per element (a coarse mesh,
    classes barely repeat) against the element matrices one by one (float64: round-off)."""
    mesh = MeshTri.init_symmetric().refined(refine)
    classes = patch_classes.Classes.of_owners(element_classes(mesh, 1))
    rng = np.random.default_rng(refine)
    per_class = rng.standard_normal((classes.first.size, 5, 5))
    local = rng.standard_normal((classes.of.size, 5))
    expected = np.einsum("eij,ej->ei", per_class[classes.of], local)
    got = classes.products(per_class, local[classes.order])
    assert np.abs(got - expected[classes.order]).max() <= 1e-13 * np.abs(expected).max()


def test_stream_matrices_of_a_class_are_its_elements_own(skewed_mesh):
    """``curl_classes`` groups elements whose stream matrices agree to round-off, and on a
    uniform mesh it finds few classes."""
    # red refinement: four shapes, each in a few local vertex orders (24 classes seen)
    for mesh, most in ((MeshTri.init_symmetric().refined(3), 32), (skewed_mesh, None)):
        rt = ReferenceRT.build(mesh, 1, 4)
        Q = symmetrisation.density(1.0, 1.0, 20.0)
        own = symmetrisation.element_system(rt, Q, np.zeros((2, 2) + rt.dx.shape))[0]
        classes = symmetrisation.curl_classes(mesh)
        assert np.abs(own[classes.first][classes.of] - own).max() <= 1e-12 * np.abs(own).max()
        if most:
            assert classes.first.size <= most
