"""Errors of P1 solutions measured against a P3 reference on a non-nested adaptive mesh agree
with their exact errors (free-boundary has an exact solution)."""

import numpy as np
import pytest

from bench.measure.discretisation_error import exact_errors
from bench.truth import cache
from formulations import get_formulation, solve
from scenes import get_scene


def measured_and_exact(refinements: int, reference_dofs: int, tmp_path, monkeypatch):
    monkeypatch.setenv("SIGNORINI_BENCH_CACHE", str(tmp_path))
    scene = get_scene("free-boundary")
    reference = cache.load_or_build(scene, reference_dofs)
    sol = solve(get_formulation("mixed")(scene, scene.mesh.refined(refinements)), "active-set")
    assert sol.status == "ok", sol.reason
    return reference, reference.errors(sol), exact_errors(scene, sol)


@pytest.mark.slow  # ~11 s: a P3 reference of its own
def test_p1_error_against_a_p3_reference_is_its_exact_error(tmp_path, monkeypatch):
    # 33 024 uniform P1 DOFs against a ~40 000-DOF adaptive P3 reference: the reference's own
    # error (about 3e-6) is below 5 % of the judged error (about 2e-4), so the measured value
    # must be the exact one within 1 % plus the reference's error
    ref, measured, exact = measured_and_exact(5, 40000, tmp_path, monkeypatch)
    allowed = 0.01 * exact.energy_error + ref.estimated_error
    assert abs(measured.energy_error - exact.energy_error) <= allowed
    assert measured.pressure_error == pytest.approx(exact.pressure_error, rel=0.02)
    assert ref.estimated_error < 0.05 * exact.energy_error  # not too coarse to judge it


@pytest.mark.long
def test_a_two_million_dof_solution_is_measured_to_one_percent(tmp_path, monkeypatch):
    # the scale target: P1 at 2 099 200 DOFs against a 90 000-DOF P3 reference
    ref, measured, exact = measured_and_exact(8, 100000, tmp_path, monkeypatch)
    assert measured.energy_error == pytest.approx(exact.energy_error, rel=0.01)
    assert measured.pressure_error == pytest.approx(exact.pressure_error, rel=0.01)
    assert np.isfinite(ref.estimated_error)
