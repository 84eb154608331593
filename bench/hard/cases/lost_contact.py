"""Contact smaller than the mesh: Hertz's sphere and cylinder on coarse uniform meshes, where a
discrete constraint can miss the contact altogether (zero force, the body passed through the
obstacle) or see only part of it. Every row measures how much of the obstacle's approach its
penetration undoes; a row that undoes more than a tenth gets the verdict ``contact
unresolved`` rather than a plain ``accurate`` (``bench.measure.contact``, docs/theory.md,
section 19.1)."""

from __future__ import annotations

from bench.hard.registry import hard_case
from bench.hard.verdicts import solve_both
from formulations.cells import family_of
from formulations.registry import FORMULATIONS
from scenes import get_scene

# (scene, order, uniform levels): hertz-3d's contact radius 0.14 against h = 0.5, 0.25 (P1:
# 972, 6 936 DOFs; P2: 6 936), the 2D cylinder's half-width 0.1 against h = 0.25 (P2: 1 056)
LEVELS = (("hertz-3d", 1, (0, 1)), ("hertz-3d", 2, (0,)), ("hertz", 2, (0,)))


@hard_case("lost-contact", "Hertz's sphere (3D, P1 and P2) and cylinder (2D, P2) on meshes "
                           "coarser than the contact zone: a constraint that does not see the "
                           "contact is 'contact unresolved', never accurate",
           meta={"seconds": 15})  # measured on 2 cores
def lost_contact() -> list[dict]:
    records = []
    for name, order, levels in LEVELS:
        scene = get_scene(name)
        for level in levels:
            mesh = scene.mesh.refined(level) if level else scene.mesh
            for formulation in FORMULATIONS.names():
                if FORMULATIONS.why_not(formulation, scene=scene,
                                        family=family_of(mesh)) is not None:
                    continue
                rows, _ = solve_both("lost-contact", scene, formulation, mesh,
                                             variant=f"P{order}", level=level, order=order)
                predicted = scene.predict_contact
                for row in rows:
                    force = row["contact_force"]
                    row["finding"] = (f"force {force:.3g}" + (
                        f" (Hertz at it: a = {predicted(force).half_width:.3g})"
                        if predicted is not None and force > 0 else "")
                        + f", penetration {row['penetration_share']:.0%} of the approach")
                records += rows
    return records
