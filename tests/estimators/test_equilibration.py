"""The patch layout's shared unknowns (docs/theory.md, 13.2): a DOF on a facet at a patch's
vertex is one unknown of that patch, held by one of the facet's two elements."""

import numpy as np
import pytest

from estimators.equilibration import _OPPOSITE_FACET, facet_holders
from estimators.rt_reference import ReferenceRT
from scenes import get_scene


def locally_refined_mesh():
    mesh = get_scene("hertz").mesh
    for _ in range(3):  # hanging-node-free local refinement: irregular neighbourhoods
        mesh = mesh.refined(np.arange(0, mesh.t.shape[1], 3))
    return mesh


@pytest.mark.parametrize("k", [1, 2, 3])
def test_every_read_holder_holds_the_same_dof_and_vertex_in_the_facets_first_element(k):
    """Checked against the definition entry by entry, not against another fast formula."""
    mesh = locally_refined_mesh()
    dofs = ReferenceRT.build(mesh, k, 2 * k + 2).element_dofs           # (n_rt, n_el)
    n_rt, n_el = dofs.shape
    holder = facet_holders(mesh, dofs, k)
    pair = np.repeat(np.arange(3 * n_el)[:, None], n_rt, axis=1)
    slot = np.repeat(np.arange(n_rt)[None, :], 3 * n_el, axis=0)
    facet_slot = slot < 3 * (k + 1)
    local_facet = np.where(facet_slot, slot // (k + 1), -1)
    read = local_facet != _OPPOSITE_FACET[pair % 3]     # the ZERO entries are never read
    held_pair, held_slot = holder // n_rt, holder % n_rt
    element, held_element = pair // 3, held_pair // 3
    # the same global DOF and the same patch vertex
    assert np.array_equal(dofs[held_slot, held_element][read], dofs[slot, element][read])
    assert np.array_equal(mesh.t[held_pair % 3, held_element][read],
                          mesh.t[pair % 3, element][read])
    # facet DOFs: the facet's first element; interior DOFs: themselves
    facet = mesh.t2f[np.maximum(local_facet, 0), element]
    on_facet = read & facet_slot
    assert np.array_equal(held_element[on_facet], mesh.f2t[0, facet[on_facet]])
    inside = ~facet_slot
    assert np.array_equal(holder[inside], (pair * n_rt + slot)[inside])
