"""The contact boundary Gamma_C (docs/theory.md, sections 1 and 15.6): the kinds of facet it is
made of, each a registered unit (``boundary``: the registry and what every kind answers;
``edges``, ``triangles`` and ``quadrilaterals``, the latter two sharing ``surfaces``), their
reference facets (``reference_facets``), the 3D nodal contact of triangles
(``surface_nodes``) and the mixed method's multiplier patches on them (``patches``).
``contact_trace`` gives a mesh's Gamma_C, the kind its cell family declares; ``gap_interpolant``
the gap's Lagrange interpolant on it."""

from __future__ import annotations

from formulations.contact import (  # noqa: F401  (register themselves)
    edges,
    quadrilaterals,
    triangles,
)
from formulations.contact.boundary import boundary_kind
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
