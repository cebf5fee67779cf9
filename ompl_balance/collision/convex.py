"""Distance bounds between convex parts, compiled: GJK with a separating-plane lower bound.

A *convex part* is ``conv(vertices) + ball(pad) + disk(disk_radius, disk_axis)`` (a
Minkowski sum), which describes exactly a convex mesh's hull (vertices), a box (its
corners), a sphere (its centre, pad = radius) and a cylinder (its two end centres plus a
disk across its axis). A link geometry's part is in its body frame and placed by the body
pose; an obstacle's part is in the world frame. For a non-convex mesh the part is its
convex hull, which contains it: distances to the hull are lower bounds of distances to
the mesh.

:func:`distance_bounds` runs GJK (Gilbert, Johnson and Keerthi, "A fast procedure for
computing the distance between complex objects in three-dimensional space", IEEE J.
Robotics and Automation, 1988) on the Minkowski difference ``D = A - B``. For *any*
direction ``v``, the support point ``w`` of ``D`` towards ``-v`` minimises ``v . x`` over
``D``, so ``v . w / |v|`` is a lower bound on the distance (a separating plane), whatever
the accuracy of ``v``: the lower bound GJK returns is rigorous up to floating-point
rounding of dot products, and needs only the support functions to be right. The upper
bound is ``|v|`` for ``v`` a convex combination of points of ``D``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

#: GJK stops when its lower and upper bounds are within this many metres.
GJK_TOLERANCE = 1e-9
#: GJK stops after this many iterations (the bounds stay valid; polytopes converge far sooner).
GJK_ITERATIONS = 64


class ConvexParts(NamedTuple):
    """Convex parts as arrays: part ``i`` is ``conv(vertex[start[i]:start[i + 1]])`` plus a ball of
    radius ``pad[i]`` plus a disk of radius ``disk_radius[i]`` across unit ``disk_axis[i]``."""

    start: np.ndarray
    vertex: np.ndarray
    pad: np.ndarray
    disk_radius: np.ndarray
    disk_axis: np.ndarray


def convex_part(kind: str, dims: tuple[float, ...], mesh_vertices: np.ndarray | None, origin: np.ndarray) -> tuple:
    """``(vertices (m, 3), pad, disk_radius, disk_axis (3,))`` of a shape posed at ``origin`` (4, 4).

    ``kind`` and ``dims`` as :class:`~ompl_balance.collision.geometry.Shape`; for meshes the
    vertices of the convex hull (or all vertices: only their hull matters).
    """
    rotation, shift = origin[:3, :3], origin[:3, 3]
    axis, pad, disk = np.array([0.0, 0.0, 1.0]), 0.0, 0.0
    if kind == "mesh":
        assert mesh_vertices is not None
        local = np.asarray(mesh_vertices, dtype=float)
    elif kind == "box":
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        local = signs * np.asarray(dims, dtype=float)
    elif kind == "sphere":
        local, pad = np.zeros((1, 3)), float(dims[0])
    else:  # cylinder along local z: its axis segment plus a disk
        radius, length = dims
        local, disk = np.array([[0.0, 0.0, -0.5 * length], [0.0, 0.0, 0.5 * length]]), float(radius)
    return local @ rotation.T + shift, pad, disk, rotation @ axis


def pack_parts(parts: list[tuple]) -> ConvexParts:
    """:class:`ConvexParts` of a list of :func:`convex_part` results."""
    return ConvexParts(
        start=np.concatenate([[0], np.cumsum([len(p[0]) for p in parts])]).astype(np.int64),
        vertex=np.concatenate([p[0] for p in parts]).reshape(-1, 3) if parts else np.zeros((0, 3)),
        pad=np.array([p[1] for p in parts], dtype=float),
        disk_radius=np.array([p[2] for p in parts], dtype=float),
        disk_axis=np.array([p[3] for p in parts], dtype=float).reshape(-1, 3),
    )


Vector = tuple[float, float, float]


@njit(cache=True)
def _support(parts: ConvexParts, i: int, poses: np.ndarray, body: int, d: Vector) -> Vector:  # pragma: no cover
    """The point of part ``i`` placed at ``poses[body]`` (4, 4) farthest along world direction ``d``."""
    d0 = poses[body, 0, 0] * d[0] + poses[body, 1, 0] * d[1] + poses[body, 2, 0] * d[2]
    d1 = poses[body, 0, 1] * d[0] + poses[body, 1, 1] * d[1] + poses[body, 2, 1] * d[2]
    d2 = poses[body, 0, 2] * d[0] + poses[body, 1, 2] * d[1] + poses[body, 2, 2] * d[2]
    vertex = parts.vertex
    best, arg = -np.inf, parts.start[i]
    for v in range(parts.start[i], parts.start[i + 1]):
        along = vertex[v, 0] * d0 + vertex[v, 1] * d1 + vertex[v, 2] * d2
        if along > best:
            best, arg = along, v
    x, y, z = vertex[arg, 0], vertex[arg, 1], vertex[arg, 2]
    disk = parts.disk_radius[i]
    if disk > 0.0:
        u0, u1, u2 = parts.disk_axis[i, 0], parts.disk_axis[i, 1], parts.disk_axis[i, 2]
        along = d0 * u0 + d1 * u1 + d2 * u2
        p0, p1, p2 = d0 - along * u0, d1 - along * u1, d2 - along * u2
        norm = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        if norm > 0.0:
            x, y, z = x + disk * p0 / norm, y + disk * p1 / norm, z + disk * p2 / norm
    pad = parts.pad[i]
    if pad > 0.0:
        norm = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if norm > 0.0:
            x, y, z = x + pad * d0 / norm, y + pad * d1 / norm, z + pad * d2 / norm
    return (
        poses[body, 0, 0] * x + poses[body, 0, 1] * y + poses[body, 0, 2] * z + poses[body, 0, 3],
        poses[body, 1, 0] * x + poses[body, 1, 1] * y + poses[body, 1, 2] * z + poses[body, 1, 3],
        poses[body, 2, 0] * x + poses[body, 2, 1] * y + poses[body, 2, 2] * z + poses[body, 2, 3],
    )


@njit(cache=True)
def _dot(a: Vector, b: Vector) -> float:  # pragma: no cover (compiled)
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True)
def _sub(a: Vector, b: Vector) -> Vector:  # pragma: no cover (compiled)
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True)
def _along(a: Vector, t: float, d: Vector) -> Vector:  # pragma: no cover (compiled)
    """``a + t d``."""
    return (a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2])


@njit(cache=True)
def _cross(a: Vector, b: Vector) -> Vector:  # pragma: no cover (compiled)
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True)
def _closest_on_triangle(a: Vector, b: Vector, c: Vector) -> tuple[Vector, int, int, int, int]:  # pragma: no cover
    """Closest point to the origin on triangle ``abc`` (Ericson, "Real-Time Collision Detection",
    5.1.5), and the corners (0, 1, 2 for a, b, c; -1 unused) that span its region, and their number."""
    ab, ac = _sub(b, a), _sub(c, a)
    d1, d2 = -_dot(ab, a), -_dot(ac, a)
    if d1 <= 0.0 and d2 <= 0.0:
        return a, 0, -1, -1, 1
    d3, d4 = -_dot(ab, b), -_dot(ac, b)
    if d3 >= 0.0 and d4 <= d3:
        return b, 1, -1, -1, 1
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return _along(a, d1 / (d1 - d3), ab), 0, 1, -1, 2
    d5, d6 = -_dot(ab, c), -_dot(ac, c)
    if d6 >= 0.0 and d5 <= d6:
        return c, 2, -1, -1, 1
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return _along(a, d2 / (d2 - d6), ac), 0, 2, -1, 2
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        return _along(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), _sub(c, b)), 1, 2, -1, 2
    total = va + vb + vc
    if total == 0.0:  # degenerate: a corner stands (an upper bound; GJK goes on)
        return a, 0, -1, -1, 1
    return _along(_along(a, vb / total, ab), vc / total, ac), 0, 1, 2, 3


@njit(cache=True)
def _keep(simplex: np.ndarray, i: int, j: int, k: int, count: int) -> int:  # pragma: no cover (compiled)
    """Keep rows ``i, j, k`` (the first ``count`` of them, in order) of ``simplex`` at its front."""
    rows = (i, j, k)
    kept = np.empty((3, 3))
    for r in range(count):
        kept[r] = simplex[rows[r]]
    simplex[:count] = kept[:count]
    return count


@njit(cache=True)
def _row(simplex: np.ndarray, i: int) -> Vector:  # pragma: no cover (compiled)
    return (simplex[i, 0], simplex[i, 1], simplex[i, 2])


@njit(cache=True)
def _closest_on_simplex(simplex: np.ndarray, n: int) -> tuple[Vector, int]:  # pragma: no cover (compiled)
    """Closest point to the origin on the simplex ``simplex[:n]``; reduces the simplex to the
    points that span it and returns the point and their number (4 with the origin inside)."""
    if n == 1:
        return _row(simplex, 0), 1
    if n == 2:
        a, b = _row(simplex, 0), _row(simplex, 1)
        ab = _sub(b, a)
        length = _dot(ab, ab)
        t = -_dot(a, ab) / length if length > 0.0 else 0.0
        if t <= 0.0:
            return a, 1
        if t >= 1.0:
            simplex[0] = simplex[1]
            return b, 1
        return _along(a, t, ab), 2
    if n == 3:
        v, i, j, k, count = _closest_on_triangle(_row(simplex, 0), _row(simplex, 1), _row(simplex, 2))
        return v, _keep(simplex, i, j, k, count)
    # tetrahedron: the origin is inside, or closest to a face it lies outside of
    best, best_v = np.inf, (0.0, 0.0, 0.0)
    best_rows, best_count = (0, 0, 0), 0
    inside = True
    for opposite in range(4):
        f0, f1, f2 = (
            (1, 2, 3) if opposite == 0 else (0, 2, 3) if opposite == 1 else (0, 1, 3) if opposite == 2 else (0, 1, 2)
        )
        a, b, c, d = _row(simplex, f0), _row(simplex, f1), _row(simplex, f2), _row(simplex, opposite)
        normal = _cross(_sub(b, a), _sub(c, a))
        side_origin, side_other = -_dot(a, normal), _dot(_sub(d, a), normal)
        scale = math.sqrt(_dot(normal, normal) * _dot(_sub(d, a), _sub(d, a)))
        degenerate = abs(side_other) <= 1e-12 * scale
        if not degenerate and side_origin * side_other >= 0.0:
            continue  # the origin is on the tetrahedron's side of this face
        inside = False
        v, i, j, k, count = _closest_on_triangle(a, b, c)
        if _dot(v, v) < best:
            faces = (f0, f1, f2)
            best, best_v, best_count = _dot(v, v), v, count
            best_rows = (faces[i], faces[j] if count > 1 else 0, faces[k] if count > 2 else 0)
    if inside:
        return (0.0, 0.0, 0.0), 4
    return best_v, _keep(simplex, best_rows[0], best_rows[1], best_rows[2], best_count)


@njit(cache=True)
def distance_bounds(
    parts: ConvexParts,
    first: int,
    first_poses: np.ndarray,
    first_body: int,
    second: int,
    second_poses: np.ndarray,
    second_body: int,
    directions: np.ndarray,
    row: int,
    enough: float,
) -> tuple[float, float]:  # pragma: no cover (compiled)
    """Lower and upper bounds (m) on the distance between parts ``first`` and ``second``, placed at
    ``first_poses[first_body]`` and ``second_poses[second_body]`` (4, 4).

    Starts from ``directions[row]`` (3,), any nonzero vector of ``first - second`` (e.g. the
    result of an earlier call for the same pair), and leaves GJK's last direction there.
    Stops as soon as the lower bound reaches ``enough``, when the bounds meet within
    :data:`GJK_TOLERANCE`, or after :data:`GJK_ITERATIONS`. Touching or overlapping parts
    give an upper bound of 0 (and a lower bound of at most 0).
    """
    v = (directions[row, 0], directions[row, 1], directions[row, 2])
    if _dot(v, v) == 0.0:
        v = (1.0, 0.0, 0.0)
    simplex = np.empty((4, 3))
    n = 0
    lower, upper = -np.inf, np.inf  # upper: the nearest point of D seen (the start direction is none)
    for _ in range(GJK_ITERATIONS):
        w = _sub(
            _support(parts, first, first_poses, first_body, (-v[0], -v[1], -v[2])),
            _support(parts, second, second_poses, second_body, v),
        )
        lower = max(lower, _dot(v, w) / math.sqrt(_dot(v, v)))
        upper = min(upper, math.sqrt(_dot(w, w)))
        if lower >= enough or upper - lower <= GJK_TOLERANCE:
            break
        for k in range(n):
            if simplex[k, 0] == w[0] and simplex[k, 1] == w[1] and simplex[k, 2] == w[2]:
                n = -1  # no progress possible: the bounds stand
        if n < 0:
            break
        simplex[n, 0], simplex[n, 1], simplex[n, 2] = w
        closest, n = _closest_on_simplex(simplex, n + 1)
        if n == 4 or _dot(closest, closest) <= GJK_TOLERANCE * GJK_TOLERANCE:
            return min(lower, 0.0), 0.0
        v = closest
        upper = min(upper, math.sqrt(_dot(v, v)))
    directions[row, 0], directions[row, 1], directions[row, 2] = v
    return lower, upper
