"""Singular exponents of elastic corners against published values and closed forms."""

import numpy as np
import pytest

from scenes import get_scene
from scenes.corners import (
    Corner,
    corner_exponents,
    kolosov,
    predicted_rate,
    singularities,
)


def test_traction_free_re_entrant_corner_matches_szabo_babuska():
    # L-shaped domain, 270 degrees, both sides free: 0.544483736782 and 0.908529189846
    # (Szabo & Babuska, Finite Element Analysis, 1991); independent of the material
    exponents = corner_exponents(Corner((0, 0), 1.5 * np.pi, ("free", "free")), 1.8, upper=1.2)
    assert exponents[:2] == pytest.approx([0.544483736782, 0.908529189846], abs=1e-9)


def test_crack_tip_has_the_double_exponent_one_half():
    # a traction-free crack (360 degrees): modes I and II both r^(1/2) (Williams, 1957)
    exponents = corner_exponents(Corner((0, 0), 2 * np.pi, ("free", "free")), 1.8, upper=1.2)
    assert exponents[0] == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("angle", [np.pi / 2, 0.75 * np.pi, 1.5 * np.pi])
@pytest.mark.parametrize("kappa", [1.8, 2.0075])
def test_clamped_free_exponents_solve_williams_equation(angle, kappa):
    # Williams (1952) for one clamped and one free side:
    # 4 kappa sin^2(lambda w) = (1 + kappa)^2 - 4 lambda^2 sin^2(w); at w = pi it gives the
    # known complex 1/2 +- i ln(kappa) / (2 pi). The determinant here is built independently.
    exponents = corner_exponents(Corner((0, 0), angle, ("clamped", "free")), kappa, upper=2.5)
    assert exponents
    for lam in exponents:
        residual = 4 * kappa * np.sin(lam * angle) ** 2 - (1 + kappa) ** 2 \
            + 4 * lam**2 * np.sin(angle) ** 2
        assert abs(residual) < 1e-8, (lam, residual)


def test_right_angle_clamped_free_in_plane_strain():
    # nu = 0.3, plane strain (kappa = 1.8): lambda = 0.7112 (Williams' equation above)
    exponents = corner_exponents(Corner((0, 0), np.pi / 2, ("clamped", "free")),
                                 kolosov(0.3, "strain"))
    assert exponents[0] == pytest.approx(0.711173, abs=1e-6)


def test_stress_free_fields_are_left_out():
    # a free right angle has only rigid motions below 1 (lambda = 1: rotation, no stress)
    exponents = corner_exponents(Corner((0, 0), np.pi / 2, ("free", "free")), 1.8, upper=1.5)
    assert all(x > 1.0 + 1e-6 for x in exponents)


def test_paper_scene_prediction():
    # plane stress, nu = 0.33: kappa = 2.67 / 1.33; the clamped top corners limit P1 to
    # N^(-lambda/2) under uniform refinement
    found = singularities(get_scene("paper"))
    assert found[0].exponent == pytest.approx(0.74606, abs=1e-5)
    assert predicted_rate([s.exponent for s in found], 1) == pytest.approx(-0.37303, abs=1e-5)
    assert predicted_rate([1.5], 3) == -0.75


def test_bad_corner_is_refused():
    with pytest.raises(ValueError, match="sides"):
        Corner((0, 0), 1.0, ("clamped", "sliding"))
    with pytest.raises(ValueError, match="angle"):
        Corner((0, 0), 7.0, ("free", "free"))
