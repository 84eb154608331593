"""The weighted norm of RT_k stresses (estimators.guaranteed.weighted_stress)."""

import numpy as np
import pytest

from estimators.guaranteed.weighted_stress import stress_weight

LAME = (0.5769, 0.3846)  # E = 1, nu = 0.3


def test_the_stress_weight_is_the_compliance_plus_the_weighted_skew_part():
    tau = np.array([[0.3, -1.2], [0.7, 2.0]])
    lam, mu = LAME
    sym = np.array([tau[0, 0], tau[1, 1], 0.5 * (tau[0, 1] + tau[1, 0])])
    expected = (sym[0] ** 2 + sym[1] ** 2 + 2 * sym[2] ** 2
                - lam / (2 * (lam + mu)) * (sym[0] + sym[1]) ** 2) / (2 * mu)
    expected += 2.5**2 * (tau[0, 1] - tau[1, 0]) ** 2 / 2        # C_K^2 |skw tau|^2
    assert tau.ravel() @ stress_weight(LAME, 2.5) @ tau.ravel() == pytest.approx(expected,
                                                                                  rel=1e-14)
