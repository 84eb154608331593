"""Meshes shared by the estimator tests."""

import numpy as np
import pytest
from skfem import MeshTri


@pytest.fixture
def skewed_mesh() -> MeshTri:
    """A locally refined, sheared mesh: every orientation and shape of element occurs."""
    mesh = MeshTri.init_symmetric().refined(2)
    mesh = mesh.refined(np.arange(5))
    p = mesh.p.copy()
    p[0] += 0.3 * p[1] ** 2
    return MeshTri(p, mesh.t)
