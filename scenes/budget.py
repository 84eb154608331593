"""The starting mesh's budget: a scene builds its initial mesh through ``tensor_mesh`` (or
calls ``check_vertex_count`` before building one of its own), which refuses a mesh larger than
the run allows before a single vertex is allocated (docs/reliability.md).

The caller of a scene factory sets the budget (``vertex_budget``) from its DOF budget; without
one, nothing is refused. The exact level-0 DOF count is checked again once the mesh exists
(``bench.matrix.run``); this guard only keeps a mistyped ``initial_divisions=20000`` from
allocating gigabytes first.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from math import prod

import numpy as np
from skfem import Mesh, MeshTet, MeshTri

from scenes.base import SceneError

_LIMIT: ContextVar[tuple[int, str] | None] = ContextVar("vertex_budget", default=None)
SLACK = 1000  # vertices allowed beyond the DOF budget: a mesh this small costs nothing
# a scene file's scene is built once when the file loads, before any run's budget is known
LOAD_VERTICES = 2_000_000


@contextmanager
def vertex_budget(max_vertices: int | None, budget: str) -> Iterator[None]:
    """Inside the block a starting mesh may have at most ``max_vertices`` vertices (None: no
    limit); ``budget`` names what sets it in the refusal, e.g. "max_dofs=300"."""
    token = _LIMIT.set(None if max_vertices is None else (int(max_vertices), budget))
    try:
        yield
    finally:
        _LIMIT.reset(token)


def dof_budget(max_dofs: int | None, option: str = "max_dofs"):
    """``vertex_budget`` of a DOF budget: every vertex off the clamped part carries at least
    one free DOF per direction, so a mesh of more than ``max_dofs + SLACK`` vertices could
    never fit ``max_dofs``."""
    return vertex_budget(None if max_dofs is None else int(max_dofs) + SLACK,
                         f"{option}={max_dofs}")


def check_vertex_count(vertices: int, what: str) -> None:
    """SceneError (one line) if a starting mesh of ``vertices`` vertices exceeds the budget."""
    limit = _LIMIT.get()
    if limit is not None and vertices > limit[0]:
        raise SceneError(f"the starting mesh ({what}) would have {vertices:,} vertices, more "
                         f"than {limit[1]} allows (at most {limit[0]:,}); give fewer "
                         "divisions or a larger budget")


def tensor_mesh(*grids: np.ndarray) -> Mesh:
    """``MeshTri.init_tensor`` (two grids) or ``MeshTet.init_tensor`` (three), after
    ``check_vertex_count``."""
    grids = [np.asarray(g, dtype=float) for g in grids]
    shape = " x ".join(str(len(g) - 1) for g in grids)
    check_vertex_count(prod(len(g) for g in grids), f"a {shape} grid")
    return (MeshTri if len(grids) == 2 else MeshTet).init_tensor(*grids)
