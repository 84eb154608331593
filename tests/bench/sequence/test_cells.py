"""The refinement loop on quadrilaterals: every formulation runs on the hierarchy's leaves
(hanging nodes included), the rows say which cells they ran on, and Q1/Q2 converge at the
rates the theory gives against free-boundary's exact solution (docs/theory.md, section 15)."""

import numpy as np
import pytest

from bench.matrix.task import why_skipped
from bench.measure.contact import SOLVED_STATUSES as SOLVED
from bench.measure.slope import fit_slope
from bench.sequence.loop import LoopConfig, run_sequence
from bench.truth import truth_for
from formulations import formulation_names
from scenes import get_scene


def levels(scene, formulation, config, estimator="residual"):
    return list(run_sequence(scene, formulation, "active-set", estimator, config,
                             truth=truth_for(scene, None)))


@pytest.mark.parametrize("formulation", formulation_names())
def test_every_formulation_runs_adaptively_on_quadrilaterals_with_hanging_nodes(formulation):
    scene = get_scene("free-boundary")
    results = levels(scene, formulation, LoopConfig(cell="quad", max_dofs=1500))
    assert len(results) >= 4 and all(r.row.status in SOLVED for r in results)
    assert {r.row.cell for r in results} == {"quad"}
    hanging = results[-1].solution.elasticity.mesh.hierarchy.hanging()[0].size
    assert hanging > 0  # the adaptive meshes are irregular
    # the exact solution's error falls (the residual estimator steers the refinement)
    errors = [r.row.energy_error for r in results]
    assert errors[-1] < 0.6 * errors[0]


@pytest.mark.parametrize("strategy, order, max_dofs, rate", [
    ("adaptive", 1, 15000, -0.5), ("uniform", 1, 40000, -0.5), ("adaptive", 2, 20000, -1.0)])
def test_q1_and_q2_converge_at_the_rates_of_theory_on_free_boundary(strategy, order, max_dofs,
                                                                    rate):
    results = levels(get_scene("free-boundary"), "vi",
                     LoopConfig(strategy=strategy, order=order, cell="quad", max_dofs=max_dofs))
    ndofs = np.array([r.row.ndofs for r in results][-4:])
    errors = np.array([r.row.energy_error for r in results][-4:])
    slope = fit_slope(ndofs, errors).slope
    # the gate of docs/theory.md, section 15: within 0.05 of the rate over the last four
    # levels (measured -0.51, -0.47, -1.02)
    assert abs(slope - rate) <= 0.05


def test_an_estimator_not_built_on_quadrilaterals_is_skipped_with_its_reason():
    scene = get_scene("paper")
    assert why_skipped(scene, "mixed", "active-set", "residual", cell="quad") is None
    assert why_skipped(scene, "mixed", "active-set", "averaging", cell="quad") is None
    assert "not built on quadrilaterals" in why_skipped(scene, "mixed", "active-set",
                                                        "equilibrated", cell="quad")
    assert "order 3 on quadrilaterals" in why_skipped(scene, "vi", "active-set", "residual",
                                                      order=3, cell="quad")


def test_the_inf_sup_constant_levels_off_on_quadrilaterals_for_h_over_H_one_half():
    """The seed's condition h/H <= 1/2 on the hierarchy's own coarser level: the discrete
    inf-sup constant levels off (measured 0.629, 0.607, 0.602 from 544 to 8320 DOFs); with the
    multiplier on the leaves' own edges (h/H = 1) it halves with h (0.108, 0.053, 0.027)."""
    scene = get_scene("paper")

    def constants(h_over_H):
        return [r.row.inf_sup for r in run_sequence(
            scene, "mixed", "active-set", "residual",
            LoopConfig(strategy="uniform", cell="quad", max_dofs=9000),
            formulation_options={"h_over_H": h_over_H})][-3:]

    stable, unstable = constants(0.5), constants(1.0)
    assert min(stable) > 0.5 and max(stable) / min(stable) < 1.1  # levelled off
    assert all(0.4 < b / a < 0.6  # halves with h
               for a, b in zip(unstable[:-1], unstable[1:], strict=True))
