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

Support functions
-----------------
A part's support point along ``d`` is its vertex with the largest ``v . d``, plus the
disk's and the ball's extreme points along ``d``. A part of at most
:data:`CLIMB_VERTICES` vertices scans them all. A larger one (the Panda's link hulls have
102 to 260 vertices) *climbs* the graph of its convex hull's edges: from a seed vertex,
move to the neighbour with the largest ``v . d`` as long as that is strictly larger than
the current vertex's, and stop at a vertex with no larger neighbour (hill climbing, as in
Cameron, "Enhancing GJK: computing minimum and penetration distances between convex
polyhedra", ICRA 1997). That vertex is a support point: a convex polytope lies in the cone
of its edges at any of its vertices, so at a vertex that is not a maximum of ``v . d``
some edge leads up, and the graph holds every edge of the hull (it is the edges of Qhull's
triangulated facets: the hull's edges plus diagonals of its non-triangular facets, which
do no harm). The walk ends because ``v . d`` strictly increases at every move. Any seed
gives the same answer; a good one saves moves: a cube map cuts each face of the cube of
directions into :data:`SEED_CELLS` x :data:`SEED_CELLS` cells, each holding the support
vertex of its centre direction, so the walk mostly just verifies its seed (1.6 vertices
visited a call on the Panda's hulls).

:func:`pack_parts` builds the graph with Qhull (``scipy.spatial.ConvexHull``) and keeps
only a large part's hull vertices (a point inside the hull is never a support point).
Large parts Qhull cannot hull (flat or collinear points), or with points on their hull's
surface that are not Qhull vertices, keep their points and scan them.

Measured on an AMD EPYC core (one support call, random directions): a scan costs 15 ns
plus 0.8 ns a vertex, a climb about 55 ns at 50 vertices and 60 ns at 150 to 260. In GJK
(:func:`distance_bounds`, a hull against a box at random poses), where successive
directions are close and a scan's branches are predicted well, the two cost the same
near 96 vertices (random ellipsoid hulls); on the Panda's hulls against a box climbing
takes 0.83 us a call instead of 0.95 at 102 vertices, 0.68 instead of 1.00 at 152, 0.77
instead of 1.50 at 260.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import scipy.spatial

from ..core.kernel_cache import njit, njit_borrowing

#: GJK stops when its lower and upper bounds are within this many metres.
GJK_TOLERANCE = 1e-9
#: GJK stops after this many iterations (the bounds stay valid; polytopes converge far sooner).
GJK_ITERATIONS = 64
#: Parts with more vertices than this climb their hull's edge graph for support points, the
#: others scan their vertices: in GJK the two cost the same near this size (module docstring).
CLIMB_VERTICES = 96
#: The climbing seeds' cube map cuts each face of the cube of directions into this many cells
#: across (6 x 4 x 4 seeds a part): 1.6 vertices visited a climb on the Panda's hulls, 1.3 with
#: 8 cells across, which cost more comparisons than they save.
SEED_CELLS = 4
#: A large part's points at least this far (m per metre of its largest coordinate, at least 1 m)
#: inside every facet plane of its Qhull hull are dropped: they are inside the hull of its
#: vertices. Far above the planes' rounding (about 1e-16 m per metre).
INSIDE_MARGIN = 1e-12


class ConvexParts(NamedTuple):
    """Convex parts as arrays: part ``i`` is ``conv(vertex[start[i]:start[i + 1]])`` plus a ball of
    radius ``pad[i]`` plus a disk of radius ``disk_radius[i]`` across unit ``disk_axis[i]``.

    The graph that large parts climb (see the module docstring) in compressed rows: vertex
    ``v``'s neighbours are ``neighbour[neighbour_start[v]:neighbour_start[v + 1]]`` (indices
    into ``vertex``, of the same part); a part whose vertices have no neighbours scans them.
    ``seed[i, face, a, b]`` (parts, 6, :data:`SEED_CELLS`, :data:`SEED_CELLS`) is the vertex
    where part ``i`` starts climbing for directions in cell ``(a, b)`` of the cube map's
    ``face`` (:func:`_seed_cell`); for a part that scans, its first vertex.
    """

    start: np.ndarray
    vertex: np.ndarray
    pad: np.ndarray
    disk_radius: np.ndarray
    disk_axis: np.ndarray
    neighbour_start: np.ndarray
    neighbour: np.ndarray
    seed: np.ndarray


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


def hull_graph(points: np.ndarray, climb_above: int = CLIMB_VERTICES) -> tuple[np.ndarray, np.ndarray | None]:
    """``(kept (k, 3), edges (e, 2) or None)``: the points of ``points`` (n, 3) that may be support
    points of their convex hull, and the hull's edges (both ways, indices into ``kept``) to climb.

    With a graph, ``kept`` are Qhull's hull vertices; the other points were at least
    :data:`INSIDE_MARGIN` (scaled) inside every facet plane. No graph (the part scans ``kept``) when
    Qhull fails (flat or collinear points: all are kept), when a point that is not a Qhull
    vertex lies nearer the surface than that (kept, with the vertices), when at most
    ``climb_above`` points are kept, or when a vertex is on fewer than 3 edges (not the graph
    of a solid polytope).
    """
    try:
        qhull = scipy.spatial.ConvexHull(points)
    except scipy.spatial.QhullError:  # flat or collinear
        return points, None
    normals, offsets = qhull.equations[:, :3], qhull.equations[:, 3]  # unit outward normals
    outermost = np.concatenate(
        [(chunk @ normals.T + offsets).max(axis=1) for chunk in np.array_split(points, max(1, len(points) // 512))]
    )
    vertex = np.zeros(len(points), dtype=bool)
    vertex[qhull.vertices] = True
    kept = vertex | (outermost > -INSIDE_MARGIN * max(1.0, float(np.abs(points).max())))
    if kept.sum() > vertex.sum() or vertex.sum() <= climb_above:
        return points[kept], None
    index = np.cumsum(vertex) - 1  # a vertex's row in points[vertex]
    edges = index[qhull.simplices[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)]
    edges = np.unique(np.concatenate([edges, edges[:, ::-1]]), axis=0)  # sorted by first vertex
    edges = edges[edges[:, 0] != edges[:, 1]]
    if np.bincount(edges[:, 0], minlength=vertex.sum()).min() < 3:
        return points[vertex], None
    return points[vertex], edges


def _cube_map_directions() -> np.ndarray:
    """(6, :data:`SEED_CELLS`, :data:`SEED_CELLS`, 3): each cube map cell's centre direction (:func:`_seed_cell`)."""
    centre = -1.0 + (2.0 * np.arange(SEED_CELLS) + 1.0) / SEED_CELLS
    directions = np.zeros((6, SEED_CELLS, SEED_CELLS, 3))
    for face in range(6):
        axis = face // 2
        directions[face, :, :, axis] = 1.0 if face % 2 == 0 else -1.0
        directions[face, :, :, (axis + 1) % 3] = centre[:, None]
        directions[face, :, :, (axis + 2) % 3] = centre[None, :]
    return directions


def pack_parts(parts: list[tuple], climb_above: int = CLIMB_VERTICES) -> ConvexParts:
    """:class:`ConvexParts` of a list of :func:`convex_part` results.

    A part of more than ``climb_above`` vertices keeps what :func:`hull_graph` keeps (its hull
    vertices, as a rule) and climbs its graph for support points; the others keep their
    vertices and scan them.
    """
    kept, graphs = [], []
    for p in parts:
        points = np.asarray(p[0], dtype=float).reshape(-1, 3)
        if len(points) == 0:
            raise ValueError("a convex part needs at least one vertex")
        edges = None
        if len(points) > climb_above:
            points, edges = hull_graph(np.unique(points, axis=0), climb_above)
        kept.append(points)
        graphs.append(edges)
    start = np.concatenate([[0], np.cumsum([len(points) for points in kept])]).astype(np.int64)
    degree = np.zeros(start[-1], dtype=np.int64)
    seed = np.repeat(start[:-1], 6 * SEED_CELLS * SEED_CELLS).reshape(len(parts), 6, SEED_CELLS, SEED_CELLS)
    neighbour = [np.zeros(0, dtype=np.int64)]
    directions = _cube_map_directions()
    for i, (points, edges) in enumerate(zip(kept, graphs, strict=True)):
        if edges is not None:
            degree[start[i] : start[i + 1]] = np.bincount(edges[:, 0], minlength=len(points))
            neighbour.append(start[i] + edges[:, 1])
            # the support vertex of each cell's centre direction (any vertex would do; this one is near)
            seed[i] = start[i] + np.argmax(directions @ points.T, axis=-1)
    return ConvexParts(
        start=start,
        vertex=np.concatenate(kept) if parts else np.zeros((0, 3)),
        pad=np.array([p[1] for p in parts], dtype=float),
        disk_radius=np.array([p[2] for p in parts], dtype=float),
        disk_axis=np.array([p[3] for p in parts], dtype=float).reshape(-1, 3),
        neighbour_start=np.concatenate([[0], np.cumsum(degree)]).astype(np.int64),
        neighbour=np.concatenate(neighbour).astype(np.int64),
        seed=seed.astype(np.int64),
    )


Vector = tuple[float, float, float]


@njit(cache=True, inline="always")
def _seed_cell(d0: float, d1: float, d2: float) -> tuple[int, int, int]:  # pragma: no cover (compiled)
    """The cube map cell ``(face, a, b)`` of direction ``(d0, d1, d2)``: ``face`` is ``2 k`` (``2 k + 1``)
    for the largest component ``k`` positive (negative); ``a`` and ``b`` cut ``[-1, 1]`` into
    :data:`SEED_CELLS` for components ``k + 1`` and ``k + 2`` (mod 3) over component ``k``'s size.
    By comparisons (a division would cost more than the rest); any direction (zero, NaN) gives a cell."""
    a0, a1, a2 = abs(d0), abs(d1), abs(d2)
    if a0 >= a1 and a0 >= a2:
        face, size, u, w = (0 if d0 >= 0.0 else 1), a0, d1, d2
    elif a1 >= a2:
        face, size, u, w = (2 if d1 >= 0.0 else 3), a1, d2, d0
    else:
        face, size, u, w = (4 if d2 >= 0.0 else 5), a2, d0, d1
    a, b = 0, 0
    for k in range(1, SEED_CELLS):  # cell boundaries at u / size = 2 k / SEED_CELLS - 1
        boundary = (2 * k - SEED_CELLS) * size
        a += int(SEED_CELLS * u > boundary)
        b += int(SEED_CELLS * w > boundary)
    return face, a, b


# Inlined into distance_bounds: a call passes every array of ConvexParts (0.4 us a GJK call
# with the graph's arrays added, 10 support calls).
@njit(cache=True, inline="always")
def _support(parts: ConvexParts, i: int, poses: np.ndarray, body: int, d: Vector) -> Vector:  # pragma: no cover
    """The point of part ``i`` placed at ``poses[body]`` (4, 4) farthest along world direction ``d``:
    the vertex found by climbing or scanning (module docstring), plus the disk's and the
    ball's extreme points along ``d``."""
    d0 = poses[body, 0, 0] * d[0] + poses[body, 1, 0] * d[1] + poses[body, 2, 0] * d[2]
    d1 = poses[body, 0, 1] * d[0] + poses[body, 1, 1] * d[1] + poses[body, 2, 1] * d[2]
    d2 = poses[body, 0, 2] * d[0] + poses[body, 1, 2] * d[1] + poses[body, 2, 2] * d[2]
    vertex, neighbour_start, neighbour = parts.vertex, parts.neighbour_start, parts.neighbour
    first, end = parts.start[i], parts.start[i + 1]
    # (an if and an else, the scan after them: numba then drops the reference counting of the
    # arrays; other shapes cost distance_bounds an increment of every array at each support)
    if neighbour_start[first + 1] > neighbour_start[first]:  # a graph: climb it
        face, a, b = _seed_cell(d0, d1, d2)
        arg = parts.seed[i, face, a, b]
        best = vertex[arg, 0] * d0 + vertex[arg, 1] * d1 + vertex[arg, 2] * d2
        at = -1
        while arg != at:  # to the best neighbour, while it is strictly better
            at = arg
            for e in range(neighbour_start[at], neighbour_start[at + 1]):
                v = neighbour[e]
                along = vertex[v, 0] * d0 + vertex[v, 1] * d1 + vertex[v, 2] * d2
                if along > best:
                    best, arg = along, v
        first = end  # nothing to scan
    else:
        best, arg = -np.inf, first
    for v in range(first, end):
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


@njit_borrowing
def _keep(simplex: np.ndarray, i: int, j: int, k: int, count: int) -> int:  # pragma: no cover (compiled)
    """Keep rows ``i < j < k`` (the first ``count`` of them) of ``simplex`` at its front."""
    rows = (i, j, k)
    for r in range(count):
        row = rows[r]  # (ascending, so row >= r: the rows still to move are not yet overwritten)
        simplex[r, 0], simplex[r, 1], simplex[r, 2] = simplex[row, 0], simplex[row, 1], simplex[row, 2]
    return count


@njit_borrowing
def _row(simplex: np.ndarray, i: int) -> Vector:  # pragma: no cover (compiled)
    return (simplex[i, 0], simplex[i, 1], simplex[i, 2])


@njit_borrowing
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
            simplex[0, 0], simplex[0, 1], simplex[0, 2] = b
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


@njit_borrowing
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
    simplex: np.ndarray,
    enough: float,
) -> tuple[float, float]:  # pragma: no cover (compiled)
    """Lower and upper bounds (m) on the distance between parts ``first`` and ``second``, placed at
    ``first_poses[first_body]`` and ``second_poses[second_body]`` (4, 4).

    Starts from ``directions[row]`` (3,), any nonzero vector of ``first - second`` (e.g. the
    result of an earlier call for the same pair), and leaves GJK's last direction there.
    ``simplex`` (4, 3) is GJK's working simplex (scratch: the kernel allocates nothing).
    Stops as soon as the lower bound reaches ``enough``, when the bounds meet within
    :data:`GJK_TOLERANCE`, or after :data:`GJK_ITERATIONS`. Touching or overlapping parts
    give an upper bound of 0 (and a lower bound of at most 0).
    """
    v = (directions[row, 0], directions[row, 1], directions[row, 2])
    if _dot(v, v) == 0.0:
        v = (1.0, 0.0, 0.0)
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
