"""Quantities of interest: every registered one builds on the exact scenes, and the exact
values agree with integrals done by hand (polynomial antiderivatives, independent of the
composite rule the code uses)."""

import numpy as np
import pytest
from numpy.polynomial import polynomial as P

import estimators.quantities as Q
from scenes.registry import get_scene

FREE = get_scene("free-boundary")
P0 = 0.01 * (FREE.material.lame[0] + 2 * FREE.material.lame[1])  # push * (lambda + 2 mu)
A = 0.4  # the scene's half_width


def pressure_polynomial() -> np.ndarray:
    """P0 (1 - x^2/a^2)^2 as polynomial coefficients in x."""
    return P0 * P.polypow([1.0, 0.0, -1.0 / A**2], 2)


def integral(coefficients, low: float, high: float) -> float:
    antiderivative = P.polyint(coefficients)
    return float(P.polyval(high, antiderivative) - P.polyval(low, antiderivative))


@pytest.mark.parametrize("name", Q.quantity_names())
def test_every_quantity_builds_and_has_an_exact_value_on_free_boundary(name):
    quantity = Q.get_quantity(name, FREE)
    assert quantity.name == name and np.isfinite(quantity.exact)


def test_the_exact_contact_force_is_the_pressure_integral():
    expected = integral(pressure_polynomial(), -A, A)  # P0 a 16/15
    # the zone's C^1 end inside a panel costs the composite rule about 1e-9 relative
    assert Q.get_quantity("contact-force", FREE).exact == pytest.approx(expected, rel=1e-8)
    assert expected == pytest.approx(P0 * A * 16 / 15, rel=1e-12)


def test_the_exact_mean_pressure_is_the_trapezoid_mean():
    # plateau |x| <= 1/8, ramps to 0 at |x| = 3/16 (Gamma_C is (-1, 1))
    p = pressure_polynomial()
    ramp = P.polymul(p, [3.0, -16.0])  # (3/16 - x) / (1/16) = 3 - 16 x on (1/8, 3/16)
    total = 2 * (integral(p, 0, 1 / 8) + integral(ramp, 1 / 8, 3 / 16))
    expected = total / (2 / 8 + 1 / 16)
    # the weight's kinks lie on panel edges; the zone's end lies outside the part
    assert Q.get_quantity("mean-pressure", FREE).exact == pytest.approx(expected, rel=1e-9)


def test_the_exact_3d_contact_force_is_the_paraboloid_volume():
    scene = get_scene("free-boundary-3d")
    lam, mu = scene.material.lame
    p0 = 0.01 * (lam + 2 * mu)
    # int over the disc r < a of p0 (1 - r^2/a^2)^2 = p0 pi a^2 / 3; the 3D composite rule's
    # error at the zone's C^1 edge is below 1e-6 relative
    assert Q.get_quantity("contact-force", scene).exact == pytest.approx(
        p0 * np.pi * A**2 / 3, rel=1e-6)


def test_a_scene_without_a_predicted_peak_is_refused_with_the_reason():
    with pytest.raises(ValueError, match="goal='peak-pressure' on scene 'paper': .*no peak"):
        Q.get_quantity("peak-pressure", get_scene("paper"))


def test_an_unknown_quantity_names_the_known_ones():
    with pytest.raises(KeyError, match="contact-force"):
        Q.get_quantity("stress", FREE)


def test_the_contact_zone_has_no_dual_problem():
    assert "no dual problem" in Q.get_quantity("contact-zone", FREE).why_no_dual
