"""Convex parts (collision/convex.py): support points and GJK distance bounds against independent oracles.

* Support points, whether a part climbs its hull's edge graph or scans its vertices, against the
  brute-force maximum of ``p . d`` over *every* vertex the part was given (interior points
  included): the Panda's link hulls, random point clouds with many interior points, boxes (ties),
  points on a cube's faces, and flat or collinear clouds (which scan).
* :func:`distance_bounds` against FCL's exact distance between the hulls as triangle meshes (or 0
  when they intersect or one holds the other): the lower bound never exceeds it, the upper bound
  never falls below it.
"""

import math

import fcl
import numpy as np
import pytest
import scipy.spatial
from numba import njit
from scipy.spatial.transform import Rotation

from ompl_balance.collision.convex import (
    CLIMB_VERTICES,
    ConvexParts,
    _support,
    convex_part,
    distance_bounds,
    hull_graph,
    pack_parts,
)
from ompl_balance.collision.robots import load_panda_vamp

ROUNDING = 1e-12  # relative: support values, and metres for the distance bounds

_PANDA = {}


def panda_parts() -> list[tuple]:
    """The Panda's link geometries as the certifier builds their convex parts (body frames)."""
    if "parts" not in _PANDA:
        robot = load_panda_vamp()
        _PANDA["parts"] = [
            convex_part(g.shape.kind, g.shape.dims, g.shape.hull_vertices(), g.origin) for g in robot.geometries
        ]
    return _PANDA["parts"]


def cloud_part(points: np.ndarray) -> tuple:
    return np.asarray(points, dtype=float), 0.0, 0.0, np.array([0.0, 0.0, 1.0])


@njit
def support_values(parts, i, pose, directions):  # pragma: no cover (compiled)
    """``p . d`` for the support point ``p`` of part ``i`` at ``pose`` (1, 4, 4) along each direction."""
    out = np.empty(len(directions))
    for k in range(len(directions)):
        d = (directions[k, 0], directions[k, 1], directions[k, 2])
        x, y, z = _support(parts, i, pose, 0, d)
        out[k] = x * d[0] + y * d[1] + z * d[2]
    return out


def climbs(parts: ConvexParts, i: int) -> bool:
    first = parts.start[i]
    return bool(parts.neighbour_start[first + 1] > parts.neighbour_start[first])


def probe_directions(rng, count):
    """Random directions, the axes, cube map cell boundaries and face ties, the zero vector."""
    special = [[1, 0, 0], [0, -1, 0], [0, 0, 1], [1, 1, 1], [-1, 1, -1], [1, 0.5, 0], [1, -0.5, 0.5], [0, 0, 0]]
    scaled = rng.normal(size=(count, 3)) * 10.0 ** rng.uniform(-3, 3, size=(count, 1))
    return np.concatenate([np.array(special, dtype=float), rng.normal(size=(count, 3)), scaled])


def random_pose(rng, shift=0.5):
    pose = np.eye(4)
    pose[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 30))).as_matrix()
    pose[:3, 3] = rng.uniform(-shift, shift, size=3)
    return pose.reshape(1, 4, 4)


def assert_supports_exact(entries, parts, rng, count=3000):
    """Every part's support values against the brute-force maximum over all its given vertices."""
    for i, (points, pad, disk, _axis) in enumerate(entries):
        assert pad == 0.0 and disk == 0.0
        for pose in (np.eye(4).reshape(1, 4, 4), random_pose(rng)):
            directions = probe_directions(rng, count)
            placed = points @ pose[0, :3, :3].T + pose[0, :3, 3]
            brute = (directions @ placed.T).max(axis=1)
            found = support_values(parts, i, pose, directions)
            scale = np.maximum(1.0, np.abs(brute)) * np.maximum(1.0, np.linalg.norm(directions, axis=1))
            worst = np.abs(found - brute) / scale
            assert worst.max() <= ROUNDING, (i, len(points), directions[np.argmax(worst)], worst.max())


def assert_kept_hull_holds_all(entries, parts):
    """A climbing part's kept vertices are among its given points and their hull holds them all."""
    for i, (points, *_) in enumerate(entries):
        kept = parts.vertex[parts.start[i] : parts.start[i + 1]]
        assert {tuple(v) for v in kept} <= {tuple(v) for v in points}
        if climbs(parts, i):
            equations = scipy.spatial.ConvexHull(kept).equations
            outside = (points @ equations[:, :3].T + equations[:, 3]).max()
            assert outside <= ROUNDING * max(1.0, np.abs(points).max()), (i, outside)


def test_panda_link_hulls_climb_to_the_brute_force_support():
    entries = panda_parts()
    parts = pack_parts(entries)
    sizes = [len(p[0]) for p in entries]
    assert max(sizes) > CLIMB_VERTICES  # (the Panda's hulls have 18 to 260 vertices)
    for i, size in enumerate(sizes):
        assert climbs(parts, i) == (size > CLIMB_VERTICES)
    assert_kept_hull_holds_all(entries, parts)
    assert_supports_exact(entries, parts, np.random.default_rng(1))
    # every part climbing, the fingers' 18-vertex hulls too
    everything = pack_parts(entries, climb_above=4)
    assert all(climbs(everything, i) for i in range(len(entries)))
    assert_kept_hull_holds_all(entries, everything)
    assert_supports_exact(entries, everything, np.random.default_rng(2))


def test_random_clouds_keep_their_hull_vertices_and_climb_to_the_brute_force_support():
    rng = np.random.default_rng(3)
    sphere = rng.normal(size=(400, 3))
    sphere /= np.linalg.norm(sphere, axis=1)[:, None]
    clouds = [
        np.concatenate([0.2 * sphere, 0.15 * rng.uniform(-1, 1, size=(2000, 3)) / math.sqrt(3)]),  # + interior
        rng.uniform(-1, 1, size=(3000, 3)) * (0.3, 0.05, 0.2),  # a box of points
        rng.normal(size=(3000, 3)) * (1.0, 0.01, 0.3) + (5.0, -2.0, 1.0),  # thin, far from the origin
        np.concatenate([sphere * (0.5, 0.2, 0.1), np.zeros((50, 3))]),  # an ellipsoid, its centre repeated
        sphere[:40] @ np.diag([1e-3, 2e-3, 1e-3]),  # millimetres
    ]
    entries = [cloud_part(c) for c in clouds]
    parts = pack_parts(entries, climb_above=16)
    for i, cloud in enumerate(clouds):
        assert climbs(parts, i)
        hull = scipy.spatial.ConvexHull(cloud)
        assert parts.start[i + 1] - parts.start[i] == len(hull.vertices)  # interior points dropped
    assert_kept_hull_holds_all(entries, parts)
    assert_supports_exact(entries, parts, rng)


def test_boxes_and_surface_points():
    rng = np.random.default_rng(4)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    grid = np.linspace(-1, 1, 7)
    faces = np.array(
        [p for p in np.stack(np.meshgrid(grid, grid, grid), axis=-1).reshape(-1, 3) if np.abs(p).max() == 1]
    )
    box = convex_part("box", (0.1, 0.2, 0.3), None, random_pose(rng)[0])
    entries = [cloud_part(corners * (0.1, 0.2, 0.3)), cloud_part(faces * (0.1, 0.2, 0.3)), box]
    parts = pack_parts(entries, climb_above=4)
    assert climbs(parts, 0) and climbs(parts, 2)  # square facets: triangulated, ties everywhere
    assert not climbs(parts, 1)  # points on the faces that are not vertices: scanned
    assert_kept_hull_holds_all(entries, parts)
    assert_supports_exact(entries, parts, rng)


def test_flat_and_collinear_clouds_scan():
    rng = np.random.default_rng(5)
    flat = rng.uniform(-1, 1, size=(500, 3)) @ np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    tilted = flat @ Rotation.random(random_state=6).as_matrix().T + (0.3, -0.2, 0.1)
    line = np.outer(rng.uniform(-1, 1, size=300), [0.2, -0.5, 0.7])
    for cloud in (flat, tilted, line):
        kept, edges = hull_graph(cloud)
        assert edges is None
        assert len(kept) >= 3  # no point dropped that could support (Qhull failed: all kept)
    entries = [cloud_part(c) for c in (flat, tilted, line)]
    parts = pack_parts(entries, climb_above=16)
    assert not any(climbs(parts, i) for i in range(len(entries)))
    assert_supports_exact(entries, parts, rng)


def test_pack_parts_keeps_pads_disks_and_small_parts():
    rng = np.random.default_rng(7)
    entries = [
        convex_part("sphere", (0.1,), None, random_pose(rng)[0]),
        convex_part("cylinder", (0.05, 0.3), None, random_pose(rng)[0]),
        *panda_parts()[:2],
    ]
    parts = pack_parts(entries)
    assert np.array_equal(parts.vertex[: parts.start[2]], np.concatenate([entries[0][0], entries[1][0]]))
    assert np.array_equal(parts.pad, [0.1, 0.0, 0.0, 0.0]) and np.array_equal(parts.disk_radius, [0.0, 0.05, 0.0, 0.0])
    empty = pack_parts([])
    assert len(empty.start) == 1 and empty.vertex.shape == (0, 3) and empty.seed.shape[0] == 0
    with pytest.raises(ValueError, match="at least one vertex"):
        pack_parts([cloud_part(np.zeros((0, 3)))])


# -- distance bounds --------------------------------------------------------------------------


def hull_mesh(points: np.ndarray) -> tuple[fcl.BVHModel, np.ndarray]:
    """The convex hull of ``points`` as an FCL triangle mesh, and its facet equations."""
    hull = scipy.spatial.ConvexHull(points)
    model = fcl.BVHModel()
    model.beginModel(len(points), len(hull.simplices))
    model.addSubModel(np.asarray(points, dtype=float), hull.simplices.astype(np.int32))
    model.endModel()
    return model, hull.equations


def true_distance(first, second, first_pose, second_pose) -> float:
    """Distance between two solid hulls: FCL's between their triangles, 0 when the triangles meet or
    one hull holds a vertex of the other."""
    (a, a_equations, a_points), (b, b_equations, b_points) = first, second
    x = fcl.CollisionObject(a, fcl.Transform(first_pose[:3, :3], first_pose[:3, 3]))
    y = fcl.CollisionObject(b, fcl.Transform(second_pose[:3, :3], second_pose[:3, 3]))
    if fcl.collide(x, y, fcl.CollisionRequest(), fcl.CollisionResult()):
        return 0.0
    # a vertex of one inside the other (in the other's frame)
    for points, pose, equations, other in (
        (a_points, first_pose, b_equations, second_pose),
        (b_points, second_pose, a_equations, first_pose),
    ):
        world = points @ pose[:3, :3].T + pose[:3, 3]
        local = (world - other[:3, 3]) @ other[:3, :3]
        if ((local @ equations[:, :3].T + equations[:, 3]).max(axis=1) <= 0.0).any():
            return 0.0
    return fcl.distance(x, y, fcl.DistanceRequest(), fcl.DistanceResult())


@njit
def bounds_at(parts, first, first_poses, second, second_poses, starts):  # pragma: no cover (compiled)
    """GJK's bounds for each pose pair, each from its own start direction."""
    out = np.empty((len(first_poses), 2))
    directions, simplex = np.zeros((1, 3)), np.empty((4, 3))
    for k in range(len(first_poses)):
        directions[0] = starts[k]
        out[k] = distance_bounds(parts, first, first_poses, k, second, second_poses, k, directions, 0, simplex, np.inf)
    return out


@pytest.mark.parametrize(("first", "second"), [(1, "box"), (6, "box"), (9, "box"), (6, 0), (2, 7)])
def test_distance_bounds_bracket_the_exact_distance(first, second):
    rng = np.random.default_rng(8)
    entries = list(panda_parts())
    if second == "box":
        entries.append(convex_part("box", (0.12, 0.05, 0.2), None, np.eye(4)))
        second = len(entries) - 1
    parts = pack_parts(entries)
    meshes = {i: (*hull_mesh(entries[i][0]), entries[i][0]) for i in (first, second)}
    radius = {i: np.linalg.norm(entries[i][0], axis=1).max() for i in (first, second)}
    count = 150
    first_poses = np.stack([random_pose(rng)[0] for _ in range(count)])
    second_poses = np.stack([random_pose(rng)[0] for _ in range(count)])
    gap = rng.uniform(-0.5, 1.0, size=count) * (radius[first] + radius[second])  # some overlap
    for k in range(count):
        direction = rng.normal(size=3)
        first_poses[k, :3, 3] = second_poses[k, :3, 3] + direction / np.linalg.norm(direction) * gap[k]
    starts = first_poses[:, :3, 3] - second_poses[:, :3, 3] + 1e-9
    found = bounds_at(parts, first, first_poses, second, second_poses, starts)
    separated = tight = 0
    for k in range(count):
        truth = true_distance(meshes[first], meshes[second], first_poses[k], second_poses[k])
        lower, upper = found[k]
        assert lower <= truth + ROUNDING, (k, lower, truth)
        assert upper >= truth - ROUNDING, (k, upper, truth)
        if truth > 0.0:
            separated += 1
            tight += upper - lower <= 1e-6
    assert separated >= count // 4 and tight >= 0.9 * separated  # not vacuous: GJK converges
