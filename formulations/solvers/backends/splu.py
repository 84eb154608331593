"""``splu``: scipy's SuperLU, always available. Forming S_C would take |C| solves (measured:
minutes per level at 5e5 DOFs on adaptive meshes, where |C| is in the thousands), so with splu
the active-set solver factorises the augmented saddle-point system once per iteration instead
(``formulations.solvers.augmented``); nested iteration keeps that to one to three
factorisations per level.
"""

from __future__ import annotations

from scipy.sparse.linalg import splu

from formulations.solvers.backends.base import Backend, register_backend


def factorise(K):
    return splu(K).solve


register_backend(Backend(
    "splu", rank=2, factorise=factorise, condense=None,
    description="scipy's SuperLU; no cheap S_C (the augmented iteration)",
    # peak 0.244 / 0.953 GiB at 10 512 / 100 800 DOFs (bench scaling), the line through them;
    # beyond 1e5 unmeasured, where SuperLU's superlinear fill may exceed it
    memory_gib=(0.1612, 7.851e-6)))
