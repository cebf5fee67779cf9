"""Cutting a triangle soup into compact pieces.

FCL tests a mesh as the set of its triangles, so a mesh cut into pieces collides exactly when
one of the pieces does. Pieces make the bounding volumes of the screening and the convex
hulls of the certified motions tight: a wall with a hole is one mesh whose hull covers the
hole, but its pieces' hulls do not.

:func:`split_triangles` cuts at the median triangle centroid across the longest extent of the
centroids, recursively, so pieces hold about equally many triangles and are spatially
compact; the result depends only on the triangles and their order.
"""

from __future__ import annotations

import numpy as np
import trimesh


def split_triangles(triangles: np.ndarray, pieces: int) -> list[np.ndarray]:
    """``triangles`` (t, 3, 3) cut into at most ``pieces`` compact groups of triangles (each (k, 3, 3)).

    Groups are halved, the one with the most triangles first, until there are ``pieces``
    groups or every group holds a single triangle.
    """
    if pieces < 1:
        raise ValueError(f"pieces must be at least 1, got {pieces}")
    groups = [np.asarray(triangles, dtype=float)]
    while len(groups) < pieces:
        largest = max(range(len(groups)), key=lambda i: len(groups[i]))
        group = groups[largest]
        if len(group) < 2:
            break
        centroids = group.mean(axis=1)
        axis = int(np.argmax(np.ptp(centroids, axis=0)))
        order = np.argsort(centroids[:, axis], kind="stable")
        middle = len(order) // 2
        groups[largest : largest + 1] = [group[order[:middle]], group[order[middle:]]]
    return groups


def soup_mesh(triangles: np.ndarray) -> trimesh.Trimesh:
    """A trimesh of the triangles (t, 3, 3) as they are: shared corners merged, no triangle
    removed (degenerate ones included: FCL tests them too)."""
    triangles = np.asarray(triangles, dtype=float).reshape(-1, 3, 3)
    vertices, inverse = np.unique(triangles.reshape(-1, 3), axis=0, return_inverse=True)
    return trimesh.Trimesh(vertices=vertices, faces=inverse.reshape(-1, 3), process=False)
