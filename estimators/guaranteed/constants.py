"""The two domain constants of the guaranteed bound (docs/theory.md, section 13.4).

* Korn-type: C_K^2 = sup_v ||skw grad v||^2 / a(v, v) over v = 0 on Gamma_D, which bounds the
  skew-symmetric part of a row-wise reconstruction;
* trace: C_T^2 = sup_v ||v . n||_{0,Gamma_C}^2 / a(v, v), which bounds the dual norm of a
  negative part of the auxiliary contact traction;
* Friedrichs: C_F^2 = sup_v ||v||_0^2 / a(v, v), which bounds the dual norm of the load that
  restores the balance of patches the discrete solution does not balance exactly;
* tangential trace, on a scene with friction: C_Tt^2 = sup_v ||v - (v . n) n||_{0,Gamma_C}^2 /
  a(v, v), which bounds the dual norm of the shear traction's excess (17.5).

Each is the largest eigenvalue of a generalised eigenproblem on P2 finite elements of the
scene's initial mesh refined uniformly. Discrete suprema approach the true ones from below; the
value used is the one on the finer of two meshes plus the change between them, once per scene
and process.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import LinearOperator, eigsh
from skfem import Basis, BilinearForm, FacetBasis, asm
from skfem.helpers import dot

from formulations.elasticity import assemble_elasticity
from formulations.solvers.backends import factorise

MIN_DOFS = 1500  # the coarser of the two meshes has at least this many P2 DOFs


@dataclass(frozen=True)
class DomainConstants:
    korn: float        # C_K
    trace: float       # C_T
    friedrichs: float  # C_F
    coarse: tuple[float, ...]  # the same on the coarser mesh
    dofs: int          # free DOFs of the finer mesh
    tangential_trace: float | None = None  # C_Tt (None: the scene has no friction)


@BilinearForm
def _skew(u, v, w):
    """(skw grad u, skw grad v): each pair i < j twice (in 2D the one pair)."""
    d = u.grad.shape[0]
    return sum(0.5 * (u.grad[i, j] - u.grad[j, i]) * (v.grad[i, j] - v.grad[j, i])
               for i in range(d) for j in range(i + 1, d))


@BilinearForm
def _mass(u, v, w):
    return dot(u, v)


@BilinearForm
def _normal_mass(u, v, w):
    return dot(u, w.n) * dot(v, w.n)


@BilinearForm
def _tangential_mass(u, v, w):
    return dot(u, v) - dot(u, w.n) * dot(v, w.n)


def _largest(scene, mesh) -> tuple[list[float], int]:
    elasticity = assemble_elasticity(scene, mesh, order=2)
    free = elasticity.free
    K = elasticity.K[free][:, free].tocsc()
    skew = asm(_skew, Basis(mesh, elasticity.basis.elem, intorder=2))[free][:, free]
    surface = FacetBasis(mesh, elasticity.basis.elem, facets=scene.contact_facets(mesh),
                         intorder=4)
    matrices = [skew, asm(_normal_mass, surface)[free][:, free],
                asm(_mass, Basis(mesh, elasticity.basis.elem, intorder=4))[free][:, free]]
    if scene.friction.active:  # C_Tt only where a shear traction is charged (17.5)
        matrices.append(asm(_tangential_mass, surface)[free][:, free])
    solve = factorise(K)  # once for every problem (a 3D P2 factorisation costs seconds)
    inverse = LinearOperator(K.shape, matvec=solve, dtype=float)
    values = []
    for A in matrices:
        top = eigsh(A.tocsc(), k=1, M=K, Minv=inverse, which="LA", return_eigenvectors=False)
        values.append(float(np.sqrt(max(top[0], 0.0))))
    return values, int(free.size)


_CACHE: dict[str, DomainConstants] = {}


def domain_constants(scene) -> DomainConstants:
    """C_K, C_T and C_F of ``scene`` (cached per scene name and parameters)."""
    key = f"{scene.name}:{sorted(scene.parameters.items())!r}"
    if key not in _CACHE:
        mesh = scene.mesh
        while 2 * (mesh.p.shape[1] + mesh.facets.shape[1]) < MIN_DOFS:
            mesh = mesh.refined()
        coarse, _ = _largest(scene, mesh)
        fine, dofs = _largest(scene, mesh.refined())
        korn, trace, friedrichs, *tangential = (f + abs(f - c)
                                                for f, c in zip(fine, coarse, strict=True))
        _CACHE[key] = DomainConstants(korn=korn, trace=trace, friedrichs=friedrichs,
                                      coarse=tuple(coarse), dofs=dofs,
                                      tangential_trace=tangential[0] if tangential else None)
    return _CACHE[key]
