"""The contact boundary Gamma_C of one mesh (docs/theory.md, section 1): the registered kind
its cell family declares (``formulations.contact_boundary``; edges in
``formulations.contact_edges``, triangles in ``formulations.contact_surface``, quadrilateral
faces in ``formulations.contact_faces``), and the gap's
interpolant on it."""

from __future__ import annotations

from formulations import (  # noqa: F401  (register themselves)
    contact_edges,
    contact_faces,
    contact_surface,
)
from formulations.contact_boundary import boundary_kind
from scenes import Scene


def contact_trace(scene: Scene, mesh):
    """Gamma_C of ``mesh``: the contact boundary its cell family declares."""
    from formulations.cells import family_of  # the families import the formulations' kernels

    return boundary_kind(family_of(mesh).contact_boundary).of(scene, mesh)


def gap_interpolant(scene: Scene, trace, order: int):
    """g_h: the P_order Lagrange interpolant of g on each contact facet, as a function of the
    local coordinates t (n_facets, nq). The penalty and Nitsche's method use it
    (docs/theory.md, sections 3 and 12) so that g - g_h, multiplied by 1/eps or gamma, cannot
    spoil lambda_h between quadrature points."""
    return trace.interpolant_of(scene.gap, order)
