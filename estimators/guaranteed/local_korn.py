"""Korn constants of vertex patches and of triangles from their geometry (docs/theory.md,
section 13.4, "Local Korn constants").

For a plane domain w star-shaped with respect to a point c, let theta be the smallest angle
between a ray from c and the boundary (the Horgan-Payne angle). Then every v in H^1(w)^2 with
int_w skw grad v = 0 satisfies

    ||grad v||_w^2 <= K ||eps(v)||_w^2,   K = 2 / sin^2(theta / 2)

(Kim, 2011, as used by Bertrand, Kober, Moldenhauer and Starke for weakly symmetric stress
equilibration; it rests on Horgan and Payne's K = 2 (1 + Gamma) = 2 / beta^2 and a lower
bound of the inf-sup constant beta of the divergence by the angle, whose proofs Costabel and
Dauge revisited for star-shaped domains). Sharp on a disc (theta = pi / 2, K = 4); checked
against discrete Korn constants in tests/estimators/guaranteed/test_local_korn.py. As |grad v|^2 =
|eps(v)|^2 + |skw grad v|^2 pointwise, the skew part then deviates from its mean by at most
(K - 1)^(1/2) ||eps(v)||_w.

On a polygon, the angle between a ray from c and an edge [a, b] is smallest at an end: it is
min(alpha_a, alpha_b), the angles of the triangle (c, a, b) at a and b, and c sees the whole
polygon when it lies strictly on the inner side of every edge. A triangle's best c is its
incentre (theta = half its smallest angle). An interior vertex's patch is seen from the
vertex; a boundary vertex sees its own facets at 0, and its patch from the best of its
triangles' centroids, incentres, edge midpoints and a barycentric lattice (LATTICE).
"""

from __future__ import annotations

import numpy as np

# Barycentric points (i, j, l) / 8 inside a triangle: candidate centres of boundary patches.
LATTICE = np.array([(i, j, 8 - i - j) for i in range(1, 7) for j in range(1, 8 - i)]) / 8.0


def korn_from_angle(theta: np.ndarray) -> np.ndarray:
    """K = 2 / sin^2(theta / 2) of the module docstring (inf where theta = 0)."""
    with np.errstate(divide="ignore"):
        return 2.0 / np.sin(np.asarray(theta) / 2) ** 2


def element_angles(mesh) -> np.ndarray:
    """The interior angles (3, n_el) of the triangles, at their vertices in ``mesh.t``'s
    order."""
    x = mesh.p[:, mesh.t]                                            # (2, 3, n_el)
    out = np.empty(mesh.t.shape)
    for i in range(3):
        u, w = x[:, (i + 1) % 3] - x[:, i], x[:, (i + 2) % 3] - x[:, i]
        cos = (u * w).sum(axis=0) / np.linalg.norm(u, axis=0) / np.linalg.norm(w, axis=0)
        out[i] = np.arccos(np.clip(cos, -1.0, 1.0))
    return out


def element_korn(mesh) -> np.ndarray:
    """K_T per triangle, seen from its incentre: theta = half the smallest angle."""
    return korn_from_angle(element_angles(mesh).min(axis=0) / 2)


def edge_angle(a, b, c, inner) -> np.ndarray:
    """min(alpha_a, alpha_b) of the module docstring for edges [a, b] (2, m) seen from
    centres c (2, m), 0 where c is not strictly on the side of ``inner`` (2, m)."""
    ab = b - a
    side = (ab[0] * (c - a)[1] - ab[1] * (c - a)[0]) * (ab[0] * (inner - a)[1]
                                                        - ab[1] * (inner - a)[0])
    scale = (ab**2).sum(axis=0) * np.maximum((((c - a) ** 2).sum(axis=0)),
                                             ((inner - a) ** 2).sum(axis=0))
    angles = []
    for start, end in ((a, b), (b, a)):
        u, w = c - start, end - start
        with np.errstate(invalid="ignore"):  # c at an end: not strictly inside, 0 below
            cos = (u * w).sum(axis=0) / np.linalg.norm(u, axis=0) / np.linalg.norm(w, axis=0)
        angles.append(np.arccos(np.clip(np.nan_to_num(cos), -1.0, 1.0)))
    return np.where(side > 1e-12 * scale, np.minimum(*angles), 0.0)


def _patch_pieces(mesh):
    """Per vertex: the edges of its patch's boundary (owner, a, b, inner point) and the
    candidate centres (owner, point)."""
    t, p = mesh.t, mesh.p
    owners, starts, ends, inners = [], [], [], []
    for i in range(3):  # the edge opposite each vertex, seen from that vertex's patch
        owners.append(t[i]), starts.append(t[(i + 1) % 3]), ends.append(t[(i + 2) % 3])
        inners.append(p[:, t[i]])
    boundary = mesh.boundary_facets()
    element = mesh.f2t[0, boundary]
    a, b = mesh.facets[:, boundary]
    third = t[:, element].sum(axis=0) - a - b
    for vertex in (a, b):  # a boundary facet bounds the patches of both its ends
        owners.append(vertex), starts.append(a), ends.append(b), inners.append(p[:, third])
    edges = (np.concatenate(owners), p[:, np.concatenate(starts)], p[:, np.concatenate(ends)],
             np.hstack(inners))
    x = p[:, t]
    lengths = np.array([np.linalg.norm(x[:, (i + 1) % 3] - x[:, (i + 2) % 3], axis=0)
                        for i in range(3)])
    incentre = (x * lengths[None]).sum(axis=1) / lengths.sum(axis=0)
    centres = [(np.arange(p.shape[1]), p)]  # an interior vertex sees its patch itself
    on_boundary = np.zeros(p.shape[1], dtype=bool)
    on_boundary[mesh.facets[:, boundary]] = True
    for i in range(3):  # a boundary vertex sees its own facets at 0: other centres
        near = np.flatnonzero(on_boundary[t[i]])
        points = [x.mean(axis=1), incentre, 0.5 * (x[:, i] + x[:, (i + 1) % 3]),
                  0.5 * (x[:, i] + x[:, (i + 2) % 3])]
        points += [np.einsum("j,cjn->cn", weights, x) for weights in LATTICE]
        centres += [(t[i, near], point[:, near]) for point in points]
    return edges, (np.concatenate([c[0] for c in centres]), np.hstack([c[1] for c in centres]))


def vertex_korn(mesh) -> np.ndarray:
    """K_z per vertex of the patch of its triangles (module docstring)."""
    (edge_owner, a, b, inner), (centre_owner, centre) = _patch_pieces(mesh)
    n_v = mesh.p.shape[1]
    edge_order = np.argsort(edge_owner, kind="stable")
    counts = np.bincount(edge_owner, minlength=n_v)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    repeats = counts[centre_owner]                          # one pair per (centre, edge)
    pair_centre = np.repeat(np.arange(centre_owner.size), repeats)
    offsets = np.arange(repeats.sum()) - np.repeat(np.cumsum(repeats) - repeats, repeats)
    pair_edge = edge_order[np.repeat(first[centre_owner], repeats) + offsets]
    angle = edge_angle(a[:, pair_edge], b[:, pair_edge], centre[:, pair_centre],
                        inner[:, pair_edge])
    seen = np.full(centre_owner.size, np.inf)
    np.minimum.at(seen, pair_centre, angle)                 # a centre's angle: its worst edge
    best = np.zeros(n_v)
    np.maximum.at(best, centre_owner, np.where(np.isfinite(seen), seen, 0.0))
    return korn_from_angle(best)
