"""The mixed method on a 3D contact surface (docs/theory.md, 19.2 and 19.3): with P1
multipliers on the surface one level coarser it sees Hertz's contact where vi does and carries
the same force, on uniform and adaptive meshes."""

import pytest

from bench.measure.contact import contact_resolution
from bench.sequence.loop import LoopConfig, run_sequence
from formulations import get_formulation, solve
from scenes import get_scene


def force_against_vi(scene, mesh, order: int) -> tuple[float, float, object]:
    mixed = solve(get_formulation("mixed")(scene, mesh, order=order), "active-set")
    vi = solve(get_formulation("vi")(scene, mesh, order=order), "active-set")
    return mixed.contact_force(), vi.contact_force(), mixed


@pytest.mark.slow  # 52 272 P1 DOFs, twice
def test_uniform_p1_carries_vis_force_from_5e4_dofs():
    # hertz-3d, uniform level 2: measured 4.937 against vi's 4.961 (-0.5 %); star patches gave
    # 2.34 and the coarse P0 triangles 5.04 (+1.5 %). The force is right, the zone is not yet:
    # the coarse hats (support radius 0.25) are wider than the contact disc (0.14) and u_h
    # goes through the obstacle between them by 36 % of the approach (measured), which the
    # row's status says
    scene = get_scene("hertz-3d")
    mixed, vi, solution = force_against_vi(scene, scene.mesh.refined(2), 1)
    assert mixed == pytest.approx(vi, rel=0.02)
    assert "36%" in contact_resolution(scene, solution).unresolved


@pytest.mark.slow  # an adaptive sequence to 6.5e4 DOFs and one vi solve
@pytest.mark.parametrize("order", [1, 2])
def test_adaptive_mixed_carries_vis_force_on_the_same_mesh(order):
    # measured: P1 at 55 245 DOFs 4.4630 against 4.4616 (+0.03 %), within 1.5 % from 4 320
    # DOFs; P2 (P1 multipliers on the trace mesh) at 61 374 DOFs 4.4033 against 4.4093
    # (-0.14 %), within 0.4 % from 18 864 DOFs
    scene = get_scene("hertz-3d")
    *_, last = run_sequence(scene, "mixed", "active-set", "residual",
                            LoopConfig(strategy="adaptive", order=order, max_dofs=65000,
                                       diagnostics=False))
    assert last.row.ndofs > 50000 and last.row.status == "ok"
    vi = solve(get_formulation("vi")(scene, last.solution.elasticity.mesh, order=order),
               "active-set")
    assert last.solution.contact_force() == pytest.approx(vi.contact_force(), rel=0.02)


def test_the_coarse_multipliers_see_the_contact_the_stars_missed():
    # hertz-3d at 6 936 P1 DOFs (h = 0.25, contact radius 0.14): both miss it (force 0); at
    # the next level the coarse hats carry 4.94 where the stars carried 2.34 (slow test above).
    # Here, on paper-3d at 13 872 DOFs: the stars leave 17 % of the approach undone, the coarse
    # hats 9.87 % (measured; deterministic to round-off, far below the 0.13 % margin)
    scene = get_scene("paper-3d")
    mesh = scene.mesh.refined(2)
    hats = solve(get_formulation("mixed")(scene, mesh), "active-set")
    stars = solve(get_formulation("mixed")(scene, mesh, multiplier_mesh="star"), "active-set")
    assert contact_resolution(scene, stars).unresolved
    assert not contact_resolution(scene, hats).unresolved
