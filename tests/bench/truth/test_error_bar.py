"""The error-bar model on synthetic sequences where its assumptions hold exactly, and the
cross-check's arithmetic."""

from types import SimpleNamespace

import numpy as np
import pytest

from bench.truth import crosscheck
from bench.truth.crosscheck import ENERGY_AGREEMENT, cross_check
from bench.truth.error_bar import MAX_RATE, MIN_RATE, error_bar, fitted_rate


def orthogonal_sequence(rate, ndofs):
    """Errors C N^-rate of nested Galerkin levels: d_k^2 = e_(k-1)^2 - e_k^2 exactly."""
    errors = 3.0 * np.asarray(ndofs, float) ** -rate
    return errors, np.sqrt(errors[:-1] ** 2 - errors[1:] ** 2)


@pytest.mark.parametrize("rate", [0.5, 1.0, 1.5])
def test_error_bar_is_exact_when_its_assumptions_hold(rate):
    ndofs = [100, 180, 300, 520, 900, 1500]  # irregular ratios, as adaptive sequences give
    errors, differences = orthogonal_sequence(rate, ndofs)
    bar = error_bar(ndofs, list(differences))
    # d decays at the rate of e only asymptotically: the fit over unequal ratios is close
    assert bar.rate == pytest.approx(rate, rel=0.05)
    assert bar.estimated_error == pytest.approx(errors[-1], rel=0.05)


def test_rate_is_clipped_and_defaults_to_one_half():
    # (DOFs of the levels the differences belong to, the differences)
    assert fitted_rate([100], [1.0]) == 0.5
    assert fitted_rate([100, 1000], [1.0, 1e-9]) == MAX_RATE
    assert fitted_rate([100, 1000], [1.0, 1.0]) == MIN_RATE


def test_error_bar_needs_one_difference_per_level_after_the_first():
    with pytest.raises(ValueError, match="differences"):
        error_bar([10, 20, 40], [1.0])
    with pytest.raises(ValueError, match="differences"):
        error_bar([10], [])


def test_cross_check_compares_relative_energy_and_force(monkeypatch):
    # two stand-in references whose fields coincide: only the scalar comparisons matter here
    monkeypatch.setattr(crosscheck, "energy_difference", lambda first, second, lame: 0.0)
    field = SimpleNamespace()
    a = SimpleNamespace(energy=400.0, contact_force=5000.0, field=field, lame=(1.0, 1.0),
                        norm=28.0, recipe="p3", ndofs=10)
    b = SimpleNamespace(energy=400.0 * (1 + 0.5 * ENERGY_AGREEMENT), contact_force=5000.001,
                        field=field, lame=(1.0, 1.0), norm=28.0, recipe="p2", ndofs=20)
    check = cross_check(a, b)
    assert check.energy_difference == pytest.approx(0.5 * ENERGY_AGREEMENT, rel=1e-6)
    assert check.force_difference == pytest.approx(2e-7, rel=1e-3)
    assert check.passed and check.recipe == "p2" and check.ndofs == 20
    b.contact_force = 5000.1  # 2e-5: above FORCE_AGREEMENT
    assert not cross_check(a, b).passed
