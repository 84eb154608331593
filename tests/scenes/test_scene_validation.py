import numpy as np
import pytest
from skfem import MeshTri

from scenes import Material, Scene, SceneError, get_scene, scene_names

GRID = np.linspace(-1, 1, 5)


def make(**changes):
    base = dict(name="t", description="t", mesh=MeshTri.init_tensor(GRID, GRID),
                material=Material(1.0, 0.3), is_dirichlet=lambda x: np.abs(x[1] - 1) < 1e-9,
                is_contact=lambda x: np.abs(x[1] + 1) < 1e-9,
                gap=lambda x: 0.1 + 0 * x[0], contact_coordinate=lambda x: x[0])
    base.update(changes)
    return Scene(**base)


@pytest.mark.parametrize("E, nu, plane, message", [
    (0.0, 0.3, "stress", "young_modulus=0.0 is not a finite number > 0"),
    (-70000.0, 0.3, "stress", "young_modulus=-70000.0 is not a finite number > 0"),
    (float("nan"), 0.3, "stress", "young_modulus=nan is not a finite number > 0"),
    (1.0, 0.5, "stress", "poisson_ratio=0.5 is not < 0.5"),
    (1.0, 0.7, "strain", "poisson_ratio=0.7 is not < 0.5"),
    (1.0, -1.0, "stress", "poisson_ratio=-1.0 is not > -1"),
    (1.0, 0.3, "membrane", "plane='membrane' is not one of 'stress', 'strain'"),
])
def test_material_rejects_bad_values(E, nu, plane, message):
    with pytest.raises(SceneError) as error:
        Material(E, nu, plane)
    assert str(error.value) == message


def test_scene_rejects_empty_contact_boundary():
    with pytest.raises(SceneError, match="contact boundary='empty' is not non-empty"):
        make(is_contact=lambda x: np.zeros(x.shape[1], bool))


def test_scene_rejects_missing_clamp():
    with pytest.raises(SceneError, match="dirichlet boundary='of measure 0' is not of positive"):
        make(is_dirichlet=lambda x: np.zeros(x.shape[1], bool))


def test_scene_rejects_non_finite_gap():
    with pytest.raises(SceneError, match=r"gap='nan at x=\[.*\]' is not finite"):
        make(gap=lambda x: np.where(x[0] > 0.5, np.nan, 0.1))


def test_scene_rejects_overlapping_parts():
    with pytest.raises(SceneError, match="disjoint from the contact boundary"):
        make(is_dirichlet=lambda x: np.abs(x[1] + 1) < 1e-9)


def test_paper_scene_matches_design():
    scene = get_scene("paper")
    assert "paper" in scene_names()
    assert scene.material.young_modulus == 70000.0 and scene.material.poisson_ratio == 0.33
    assert scene.material.plane == "stress"
    # plane stress: lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu)) (docs/theory.md, section 1)
    lam, mu = scene.material.lame
    assert lam == pytest.approx(70000 * 0.33 / (1 - 0.33**2), rel=1e-14)
    assert mu == pytest.approx(70000 / 2.66, rel=1e-14)
    # g(x) = 0.85 - sqrt(1 - x^2): negative (obstacle pushes up by 0.15) at x = 0
    assert scene.gap(np.array([[0.0, 1.0], [-1.0, -1.0]])) == pytest.approx([-0.15, 0.85])
    mid = scene.mesh.p[:, scene.mesh.facets[:, scene.contact_facets()]].mean(axis=1)
    assert np.allclose(mid[1], -1.0) and scene.facet_lengths(scene.contact_facets()).sum() == 2.0
    assert scene.facet_lengths(scene.dirichlet_facets()).sum() == 2.0


def test_unknown_scene_lists_valid_ones():
    with pytest.raises(KeyError) as error:
        get_scene("hertzz")
    listed = str(error.value).split("valid scenes: ", 1)[1].rstrip("'\"").split(", ")
    # every built-in scene (and any a scene file registered earlier in this process), sorted
    builtin = ["corner", "free-boundary", "full-contact", "graded", "grazing", "hertz",
               "incompressible", "no-contact", "paper", "thin", "traction", "wedge"]
    assert set(builtin) <= set(listed) and listed == sorted(listed) == scene_names()


def test_paper_rejects_bad_divisions():
    with pytest.raises(SceneError, match="initial_divisions=1 is not an integer >= 2"):
        get_scene("paper", initial_divisions=1)
