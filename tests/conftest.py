"""Small scenes with answers known independently of the code under test."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import numpy as np
import pytest
from skfem import MeshTri

from bench.matrix.provenance import THREAD_VARIABLES
from scenes import Material, Scene

TOL = 1e-10


def pytest_configure(config):
    """Each test worker gets its share of the cores for BLAS, MKL and OpenMP (cores // workers)
    unless the caller set any thread count: two workers of two threads each on two cores ran
    the default tests in 345 s against 243 s with one thread each. The workers are started
    after this hook and inherit the variables before their libraries load."""
    workers = getattr(config.option, "numprocesses", None)
    if (os.environ.get("PYTEST_XDIST_WORKER") or not isinstance(workers, int) or workers < 2
            or any(name in os.environ for name in THREAD_VARIABLES)):
        return
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    os.environ.update({name: str(max(1, (cores or 1) // workers)) for name in THREAD_VARIABLES})


def energy_difference(discretisation, a, b) -> float:
    """||a.u - b.u||_K / ||b.u||_K: how far two solves of one discretisation differ."""
    K = discretisation.elasticity.K
    e = a.u - b.u
    return float(np.sqrt(e @ (K @ e) / (b.u @ (K @ b.u))))


def interruptible_bench(*args, cwd=None) -> subprocess.Popen:
    """``python -m bench ARGS`` as a child that Ctrl-C (SIGINT) reaches: a shell without job
    control starts background commands with SIGINT ignored, children inherit that, and Python
    then installs no KeyboardInterrupt handler, so the child is reset to the default first."""
    return subprocess.Popen([sys.executable, "-m", "bench", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=cwd,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def square_scene(gap, *, young_modulus=1000.0, poisson_ratio=0.0, divisions=4,
                 body_force=None, traction=None, name="test-square") -> Scene:
    """(-1,1)^2 clamped on top, contact on the bottom (outer normal (0,-1)), free sides."""
    grid = np.linspace(-1.0, 1.0, divisions + 1)
    return Scene(name=name, description="test square", mesh=MeshTri.init_tensor(grid, grid),
                 material=Material(young_modulus, poisson_ratio, "stress"),
                 is_dirichlet=lambda x: np.abs(x[1] - 1) < TOL,
                 is_contact=lambda x: np.abs(x[1] + 1) < TOL,
                 gap=gap, contact_coordinate=lambda x: x[0],
                 body_force=body_force, traction=traction)


@pytest.fixture
def skewed_mesh() -> MeshTri:
    """A locally refined, sheared mesh: every orientation and shape of element occurs."""
    mesh = MeshTri.init_symmetric().refined(2)
    mesh = mesh.refined(np.arange(5))
    p = mesh.p.copy()
    p[0] += 0.3 * p[1] ** 2
    return MeshTri(p, mesh.t)


@pytest.fixture
def compression_scene():
    """A rigid flat pushes the bottom up by delta = 0.01 (g = -delta), nu = 0.

    Exact solution: u = (0, delta (1 - y) / 2), sigma_yy = -E delta / 2, contact pressure
    p = E delta / 2 on all of Gamma_C. u is linear and p constant, so P1 x P0 reproduce them.
    """
    return square_scene(lambda x: np.full(x.shape[1:], -0.01), young_modulus=1000.0)


@pytest.fixture
def free_scene():
    """No contact: the obstacle is 1.0 away and a downward body force moves the body ~1e-3."""
    return square_scene(lambda x: np.full(x.shape[1:], 1.0), young_modulus=1000.0,
                        poisson_ratio=0.3,
                        body_force=lambda x: np.array([0.0 * x[0], -1.0 + 0.0 * x[0]]))


@pytest.fixture
def pushed_cube():
    """(-1,1)^3 clamped on top, pushed up by delta = 0.01 on the bottom, nu = 0:
    u = (0, 0, delta (1 - z) / 2), pressure E delta / 2 = 5 on all 4 of Gamma_C (force 20),
    energy 1/2 (E delta^2 / 4) |Omega| = 0.1; trilinear, so Q1 holds it."""
    from scenes.budget import tensor_mesh

    grid = np.linspace(-1.0, 1.0, 3)
    return Scene(name="pushed-cube", description="flat push", mesh=tensor_mesh(grid, grid, grid),
                 material=Material(1000.0, 0.0, "strain"),
                 is_dirichlet=lambda x: np.abs(x[2] - 1) < 1e-10,
                 is_contact=lambda x: np.abs(x[2] + 1) < 1e-10,
                 gap=lambda x: np.full(x.shape[1:], -0.01),
                 contact_coordinate=lambda x: np.asarray(x)[:2])


@pytest.fixture(scope="session")
def finished_run(tmp_path_factory):
    """A results folder of two finished sequences (free-boundary, vi and mixed, active set, up
    to 300 DOFs), made once; tests take copies (``results_copy``)."""
    from bench.cli import main

    out = tmp_path_factory.mktemp("finished") / "results"
    assert main(["run", "--scene", "free-boundary", "--formulation", "vi,mixed", "--solver",
                 "active-set", "--max-dofs", "300", "--out", str(out)]) == 0
    return out


@pytest.fixture
def results_copy(finished_run, tmp_path):
    """A private copy of ``finished_run``."""
    import shutil

    return shutil.copytree(finished_run, tmp_path / "results")


def folder_bytes(folder) -> dict:
    """Every file under ``folder`` (but its lock) by relative path, with its bytes."""
    from pathlib import Path

    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(Path(folder).rglob("*"))
            if p.is_file() and p.name != ".lock"}


# ---- linear elasticity on the unit cube, solved by scikit-fem alone (tetrahedral patch tests)

CUBE_LAME = (1.0, 1.0)
CUBE_STRAIN = np.array([[0.3, 0.1, -0.2], [0.05, -0.1, 0.2], [0.1, 0.3, 0.15]])  # u = G x


def cube_problem(n, order, body_force, traction):
    """P_order elasticity on the unit cube (x = 0 clamped at u = CUBE_STRAIN x, t on the other
    faces), solved by scikit-fem alone, on a mesh whose tetrahedra list their vertices in
    random order; the sorted mesh's patch data (``estimators.guaranteed.patch_data``), the boundary
    flux, the clamped vertices, the free faces and rho."""
    from skfem import (
        Basis,
        ElementTetP1,
        ElementTetP2,
        ElementVector,
        FacetBasis,
        LinearForm,
        MeshTet,
        asm,
        condense,
        solve,
    )
    from skfem.helpers import dot
    from skfem.models.elasticity import linear_elasticity

    from estimators.guaranteed.equilibrated_3d import INTORDER
    from estimators.guaranteed.equilibration import BoundaryData, boundary_balance, boundary_fluxes
    from estimators.guaranteed.patch_data import interior_data, rebalanced
    from estimators.guaranteed.raviart_thomas_tet import sorted_tetrahedra
    from formulations.cells.evaluation import gradients_at
    from formulations.elasticity import stress_tensor_from_gradient

    cube = MeshTet.init_tensor(*[np.linspace(0, 1, n + 1)] * 3)
    rng = np.random.default_rng(3)
    mesh = MeshTet(cube.p, np.ascontiguousarray(
        np.array([rng.permutation(c) for c in cube.t.T]).T))
    basis = Basis(mesh, ElementVector(ElementTetP1() if order == 1 else ElementTetP2()))

    def clamped_side(x):
        return x[0] < 1e-12

    def free_sides(m):
        return np.setdiff1d(m.boundary_facets(),
                            m.facets_satisfying(clamped_side, boundaries_only=True))

    @LinearForm
    def load(v, w):
        return dot(body_force(np.asarray(w.x)), v)

    @LinearForm
    def surface(v, w):
        return dot(traction(np.asarray(w.x)), v)

    F = asm(load, basis) + asm(surface, FacetBasis(mesh, basis.elem, facets=free_sides(mesh)))
    fixed = basis.get_dofs(mesh.facets_satisfying(clamped_side, boundaries_only=True)).all()
    exact = (CUBE_STRAIN @ basis.doflocs)[np.arange(basis.N) % 3, np.arange(basis.N)]
    u = solve(*condense(asm(linear_elasticity(*CUBE_LAME), basis), F, x=exact, D=fixed))

    def sigma_h(rt):
        x = np.asarray(rt.global_coordinates())
        cells = np.repeat(np.arange(mesh.t.shape[1]), x.shape[2])
        grad = gradients_at(basis, u, x.reshape(3, -1), cells)
        return stress_tensor_from_gradient(grad, *CUBE_LAME).reshape(3, 3, *x.shape[1:])

    sorted_mesh = sorted_tetrahedra(mesh)
    interior = interior_data(sorted_mesh, sigma_h, body_force, order, INTORDER[order])
    facets = free_sides(sorted_mesh)
    clamped = np.zeros(sorted_mesh.p.shape[1], dtype=bool)
    clamped[sorted_mesh.facets[:, sorted_mesh.facets_satisfying(
        clamped_side, boundaries_only=True)].ravel()] = True
    fluxes = boundary_fluxes(interior, [BoundaryData(facets, traction)])
    balance = boundary_balance(sorted_mesh.p.shape[1], fluxes, 3)
    interior, rho = rebalanced(interior, interior.total - balance, clamped)
    return interior, fluxes, clamped, facets, rho


def faces_normal(x):
    """The outer normal of the unit cube at points x (3, ...) on its faces."""
    n = np.zeros_like(x)
    for i in range(3):
        n[i][np.abs(x[i] - 1) < 1e-12] = 1.0
        n[i][np.abs(x[i]) < 1e-12] = -1.0
    return n
