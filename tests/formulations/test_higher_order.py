"""P2 and P3: exact quadratures for polynomial fields, every formulation's fast solve against
the reference QP solver, and the constraints each formulation promises."""

import numpy as np
import pytest
from skfem import Basis, LinearForm, MeshTri, asm
from skfem.helpers import dot

from bench.measure.difference import solution_difference
from conftest import square_scene
from formulations import get_formulation, solve
from formulations.cells.evaluation import normal_trace_matrix
from formulations.cells.load import body_load
from formulations.contact import contact_trace
from formulations.contact.reference_facets import gauss_legendre
from formulations.diagnostics import inf_sup_constant
from formulations.elasticity import assemble_elasticity, count_free_dofs, vector_element
from formulations.methods.mixed import bernstein, multiplier_segments
from formulations.methods.penalty import PRESSURE_CONSISTENCY
from scenes import get_scene

ORDERS = (2, 3)


def interpolant(basis, field):
    """DOF vector of the Lagrange interpolant of ``field`` (exact for polynomials of degree
    <= p): the field's value at every DOF location, component by component."""
    u = np.zeros(basis.N)
    values = field(basis.doflocs)
    for c, dofs in enumerate(basis.split_indices()):
        u[dofs] = values[c][dofs]
    return u


def cubic(x):
    return np.array([x[0] ** 2 * x[1] - 0.3 * x[1] ** 3 + x[0], 0.5 * x[0] ** 3 - x[0] * x[1]])


def quadratic(x):
    return np.array([x[0] ** 2 - 0.4 * x[0] * x[1], 0.7 * x[1] ** 2 + x[0]])


FIELDS = {2: quadratic, 3: cubic}


def perturbed_square(refinements=2):
    mesh = MeshTri.init_tensor(*(2 * [np.linspace(-1, 1, 5)])).refined(refinements)
    p = mesh.p.copy()
    interior = mesh.interior_nodes()
    p[:, interior] += 0.03 * np.random.default_rng(1).uniform(-1, 1, (2, interior.size))
    return MeshTri(p, mesh.t)


@pytest.mark.parametrize("order", ORDERS)
def test_strain_energy_of_a_polynomial_field_is_exact(order):
    # 1/2 u'Ku = 1/2 int sigma(u) : eps(u) for the interpolant of a degree-p field, against an
    # independent 2D Gauss-Legendre integral of the analytic strain energy on the square
    scene = square_scene(lambda x: 1.0 + 0 * x[0], poisson_ratio=0.3)
    elasticity = assemble_elasticity(scene, perturbed_square(), order)
    u = interpolant(elasticity.basis, FIELDS[order])
    lam, mu = elasticity.lame
    t, w = np.polynomial.legendre.leggauss(8)
    x, y = np.meshgrid(t, t, indexing="ij")
    h = 1e-6
    grad = np.array([[(FIELDS[order](np.array([x + h, y]))[i]
                       - FIELDS[order](np.array([x - h, y]))[i]) / (2 * h),
                      (FIELDS[order](np.array([x, y + h]))[i]
                       - FIELDS[order](np.array([x, y - h]))[i]) / (2 * h)] for i in (0, 1)])
    eps = 0.5 * (grad + grad.transpose(1, 0, 2, 3))
    density = lam * np.trace(eps) ** 2 + 2 * mu * (eps**2).sum(axis=(0, 1))
    exact = 0.5 * (density * np.outer(w, w)).sum()
    assert 0.5 * u @ (elasticity.K @ u) == pytest.approx(exact, rel=1e-8)


@pytest.mark.parametrize("order", (1, 2, 3))
def test_load_of_a_polynomial_and_of_a_jumping_body_force(order):
    # (f, v) for v the interpolant of a polynomial of degree p: exact for f of degree p (the
    # rule has degree 2p); for an f that jumps across x = 0.3, the adaptive rule's error is
    # ~2^-5 of the plain rule's on the cut elements, which cover ~1/10 of the square here: within
    # 1e-3 relative, and at least 20 times closer than the element's own rule
    mesh = perturbed_square(1)
    basis = Basis(mesh, vector_element(order))
    field = FIELDS.get(order, lambda z: np.array([z[0] - 0.2 * z[1], z[1] + 0.5]))
    v = interpolant(basis, field)
    t, w = np.polynomial.legendre.leggauss(12)

    def analytic(f, a=-1.0, b=1.0):  # int over [a, b] x [-1, 1] of f . v, Gauss-Legendre
        x, y = np.meshgrid(0.5 * (b - a) * t + 0.5 * (a + b), t, indexing="ij")
        pts = np.array([x, y])
        return 0.5 * (b - a) * ((f(pts) * field(pts)).sum(axis=0) * np.outer(w, w)).sum()

    def smooth(x):  # degree p
        return np.array([1 + x[0] ** order - x[1], x[1] ** order + 0.3 * x[0]])

    def jumping(x):
        return np.array([np.where(x[0] > 0.3, 2.0, -1.0) + 0 * x[1], 0 * x[0] + 0.5])

    assert body_load(smooth, basis) @ v == pytest.approx(analytic(smooth), rel=1e-12)
    exact = analytic(jumping, -1.0, 0.3) + analytic(jumping, 0.3, 1.0)
    plain = asm(LinearForm(lambda vv, ww: dot(jumping(ww.x), vv)), basis) @ v
    refined = body_load(jumping, basis) @ v
    assert refined == pytest.approx(exact, rel=1e-3)
    assert abs(refined - exact) * 20 < abs(plain - exact)


@pytest.mark.parametrize("order", ORDERS)
def test_normal_trace_and_mixed_rows_integrate_polynomials_exactly(order):
    # u_h . n at facet points equals the field's normal component there, and the mixed rows
    # int_S B_k u_h . n equal an independent Gauss integral of B_k times the analytic field
    scene = get_scene("free-boundary")
    mesh = scene.mesh.refined(1)
    disc = get_formulation("mixed")(scene, mesh, order=order)
    trace, basis = disc.trace, disc.elasticity.basis
    u = interpolant(basis, FIELDS[order])
    t = np.array([0.1, 0.5, 0.77])
    un = (normal_trace_matrix(basis, trace, t) @ u).reshape(trace.size, t.size)
    exact = np.einsum("ift,if->ft", FIELDS[order](trace.points(t)), trace.normal)
    assert np.abs(un - exact).max() < 1e-12
    # rows: segments from the mixed method's rule, Bernstein coefficients k = 0..p-1 each
    segment = multiplier_segments(trace.length)
    first = np.flatnonzero(np.diff(np.concatenate([[-1], segment])))
    breaks = np.append(trace.coordinate[0, first], trace.coordinate[1, -1])
    s, ws = gauss_legendre(12)
    expected = []
    for a, b in zip(breaks[:-1], breaks[1:], strict=True):
        x = a + (b - a) * s
        v_n = -FIELDS[order](np.array([x, -np.ones_like(x)]))[1]  # bottom: n = (0, -1)
        expected.extend((b - a) * (bernstein(order - 1, s) * v_n * ws).sum(axis=1))
    B_u = disc.qp.B @ u[disc.elasticity.free]
    assert np.abs(B_u - np.array(expected)).max() < 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize("formulation", ["mixed", "penalty", "vi"])
def test_fast_solver_agrees_with_reference(formulation, order):
    # the same tolerances as P1 (tests/formulations/solvers/test_active_set.py): Clarabel at 1e-10
    # leaves ~1e-8 in energy and ~1e-7 in lambda; a wrong active set gives >= 1e-3
    scene = get_scene("paper")
    disc = get_formulation(formulation)(scene, scene.mesh.refined(2), order=order)
    fast, reference = solve(disc, "active-set"), solve(disc, "reference")
    assert fast.status == "ok" and reference.status == "ok", (fast.reason, reference.reason)
    assert max(vars(fast.residuals).values()) < 1e-10
    energy, pressure = solution_difference(disc, fast, reference)
    assert energy <= 1e-7, energy
    # the penalty's pressure divides u's error by eps = eps_0 h / (p^2 E): the reference's
    # 1e-9 in u becomes ~1e-5 in lambda (measured 5.4e-6 for P2, 1.0e-5 for P3), so it is
    # held to PRESSURE_CONSISTENCY, the threshold at which the penalty flags its own pressure
    assert pressure <= (PRESSURE_CONSISTENCY if formulation == "penalty" else 1e-6), pressure


@pytest.mark.parametrize("order", ORDERS)
def test_vi_holds_at_every_lagrange_node_of_the_contact_boundary(order):
    scene = get_scene("free-boundary")
    mesh = scene.mesh.refined(2)
    sol = solve(get_formulation("vi")(scene, mesh, order=order), "active-set")
    nodes = np.linspace(0, 1, order + 1)
    gap = scene.gap(sol.trace.points(nodes))
    # u_n <= g at vertices and edge nodes (to the solver's round-off), and the row count is
    # one per vertex plus p - 1 per facet
    assert (sol.normal_displacement(nodes) - gap).max() <= 1e-12
    trace = contact_trace(scene, mesh)
    assert sol.multipliers.size == np.unique(trace.vertices).size + (order - 1) * trace.size


def test_dof_counts_match_the_assembled_spaces():
    scene = get_scene("paper")
    for order in (1, 2, 3):
        for mesh in (scene.mesh, scene.mesh.refined(1)):
            assert count_free_dofs(scene, mesh, order) == assemble_elasticity(
                scene, mesh, order).ndofs


@pytest.mark.parametrize("order", ORDERS)
def test_chosen_multiplier_space_is_inf_sup_stable_and_the_trace_mesh_is_not(order):
    # docs/theory.md, section 9: degree p - 1 on segments with h/H <= 1/2 keeps beta_h at
    # 0.38 (P2) / 0.30 (P3) under refinement; the same space on the trace mesh loses half of
    # beta_h per level (measured 0.086, 0.042, 0.021 for P2)
    scene = get_scene("paper")
    chosen, trace_mesh = [], []
    for refinements in (1, 2, 3):
        mesh = scene.mesh.refined(refinements)
        chosen.append(inf_sup_constant(get_formulation("mixed")(scene, mesh, order=order)))
        trace_mesh.append(inf_sup_constant(get_formulation("mixed")(scene, mesh, order=order,
                                                                    h_over_H=1.0)))
    assert min(chosen) > 0.25 and chosen[-1] > 0.9 * chosen[1]
    assert trace_mesh[-1] < 0.6 * trace_mesh[0] and trace_mesh[-1] < 0.1 * chosen[-1]
