"""Bounding-sphere screening of a robot's collision pairs, compiled with numba.

Before FCL's exact test, every pair that could collide — a link geometry and an
obstacle, or two link geometries enabled for self-collision — is screened with
bounding volumes that contain what FCL tests:

* each link geometry is covered by one sphere and, inside it, by ``k`` smaller spheres
  (:meth:`~ompl_balance.collision.geometry.Shape.bounding_spheres`);
* each obstacle is contained in an oriented box
  (:meth:`~ompl_balance.collision.geometry.Shape.bounding_box`).

A pair is *cleared* when its big spheres are apart, or when no small sphere of one
touches the other's volume; only pairs that are not cleared go on to FCL.

Spheres cannot clear links that are always close, such as a Panda's forearm and hand
(``link5`` and ``link7``/``hand``, a few centimetres apart over most of the range). A
self-collision pair whose relative pose depends on two revolute joints only (one
geometry's body is an ancestor of the other's, two moving joints between them) gets a
*certified-free table* over those two joint values instead (:func:`free_table`): a
grid whose cells are marked free where FCL's distance at the cell centre exceeds how
far any point of the moving geometry can travel within the cell. Clearing is
conservative (volumes that do not touch hold geometries that do not touch; a slack of
:data:`SLACK` absorbs rounding), so the answer after FCL is FCL's own.

:func:`screen` does forward kinematics and the screening of ``n`` configurations in one
compiled call: a few microseconds per configuration, where the same steps in numpy
cost tens of microseconds of per-call overhead at these array sizes.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import fcl
import numpy as np

from ..core.kernel_cache import njit
from .cache import cached_arrays
from .geometry import fcl_transform
from .kinematics import Chain, RobotModel, _chain_poses_batch, chain_poses

if TYPE_CHECKING:
    from .environment import Obstacle

#: Slack (m) added to every bounding-volume test so that rounding never clears a contact.
SLACK = 1e-6


class Volumes(NamedTuple):
    """Bounding volumes of a robot's geometries and of the obstacles, as arrays.

    Geometry ``g`` hangs off body ``geometry_body[g]``; its big sphere has centre
    ``outer_centre[g]`` (body frame) and radius ``outer_radius[g]``; its small spheres
    are rows ``sphere_start[g]:sphere_start[g + 1]`` of ``sphere_centre`` (body frame)
    and ``sphere_radius``. Obstacle ``o``'s box has world centre ``box_centre[o]``, axes
    the columns of ``box_axes[o]`` and half extents ``box_half[o]``. ``pairs`` (P, 2)
    are the self-collision geometry pairs.

    Pair ``p`` has the certified-free table ``pair_table[p]`` (-1: none). Table ``k``
    spans the values of joints ``table_joints[k]`` (2,) from ``table_low[k]`` in
    ``table_cells[k]`` (2,) cells of ``table_cell[k]`` (2,) radians; its cells, row-major,
    are ``table_free[table_start[k]:]``.
    """

    geometry_body: np.ndarray
    outer_centre: np.ndarray
    outer_radius: np.ndarray
    sphere_start: np.ndarray
    sphere_centre: np.ndarray
    sphere_radius: np.ndarray
    box_centre: np.ndarray
    box_axes: np.ndarray
    box_half: np.ndarray
    pairs: np.ndarray
    pair_table: np.ndarray
    table_joints: np.ndarray
    table_low: np.ndarray
    table_cell: np.ndarray
    table_cells: np.ndarray
    table_start: np.ndarray
    table_free: np.ndarray


def build_volumes(robot: RobotModel, obstacles: Sequence[Obstacle], spheres_per_geometry: int) -> Volumes:
    """:class:`Volumes` for ``robot`` (a :class:`~ompl_balance.collision.kinematics.RobotModel`)
    among ``obstacles`` (:class:`~ompl_balance.validity.Obstacle` list)."""
    geometries = robot.geometries
    tables = _free_tables(robot)
    outer = [g.shape.bounding_spheres(1) for g in geometries]
    small = [g.shape.bounding_spheres(spheres_per_geometry) for g in geometries]
    in_body = lambda g, centres: centres @ g.origin[:3, :3].T + g.origin[:3, 3]  # noqa: E731
    boxes = []
    for o in obstacles:
        box_pose, half = o.shape.bounding_box()
        pose = o.pose @ box_pose
        boxes.append((pose[:3, 3], pose[:3, :3], half))
    return Volumes(
        geometry_body=np.array([g.body for g in geometries], dtype=np.int64),
        outer_centre=np.array([in_body(g, c)[0] for g, (c, _) in zip(geometries, outer)]).reshape(-1, 3),
        outer_radius=np.array([r[0] for _, r in outer], dtype=float),
        sphere_start=np.concatenate([[0], np.cumsum([len(r) for _, r in small])]).astype(np.int64),
        sphere_centre=np.concatenate([in_body(g, c) for g, (c, _) in zip(geometries, small)]).reshape(-1, 3)
        if geometries
        else np.zeros((0, 3)),
        sphere_radius=np.concatenate([r for _, r in small]) if geometries else np.zeros(0),
        box_centre=np.array([c for c, _, _ in boxes], dtype=float).reshape(-1, 3),
        box_axes=np.array([a for _, a, _ in boxes], dtype=float).reshape(-1, 3, 3),
        box_half=np.array([h for _, _, h in boxes], dtype=float).reshape(-1, 3),
        pairs=np.array(robot.self_collision_pairs, dtype=np.int64).reshape(-1, 2),
        **tables,
    )


#: Certified-free tables: cells per joint on the coarsest level, and the number of halvings.
TABLE_COARSE_CELLS, TABLE_LEVELS = 8, 4


def two_joint_path(chain: Chain, body_a: int, body_b: int) -> tuple[int, int] | None:
    """The two revolute joints ``(upper, lower)`` between ``body_a`` and its descendant
    ``body_b``, or ``None`` when ``body_b`` is not a descendant or other joints lie between."""
    path, body = [], body_b
    while body not in (body_a, 0):
        path.append(body - 1)  # joint k moves body k + 1
        body = chain.parent_body[body - 1]
    if body != body_a or len(path) != 2 or chain.slide[path].any():
        return None
    return path[1], path[0]


def free_table(robot: RobotModel, a: int, b: int, upper: int, lower: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Certified-free cells of geometry ``b`` against ``a`` over joints ``upper`` and ``lower``.

    ``b`` hangs below ``lower``, which hangs below ``upper``, which hangs below ``a``'s
    body, so their relative pose depends on these two joint values only. Changing them
    by ``(d_upper, d_lower)`` moves a point of ``b`` by at most ``|d_upper| rho_upper +
    |d_lower| rho_lower`` in ``a``'s frame, with ``rho`` the largest distance of a point
    of ``b`` from each joint's axis (a rotation by ``d`` moves a point at distance ``r``
    from its axis by at most ``d r``). Distance from an axis is convex, so for a mesh
    its vertices attain the largest; other shapes are bounded through their covering
    spheres. A cell is free when FCL's distance at its centre exceeds that bound for the
    cell's half widths. Cells are refined by halving, from :data:`TABLE_COARSE_CELLS`
    per joint, where the distance is positive but too small, down to
    :data:`TABLE_LEVELS` halvings.

    Returns ``low`` (2,), ``cell`` (2,) widths and the finest grid (cells, cells) bool.
    """
    chain = robot.chain
    geometry_a, geometry_b = robot.geometries[a], robot.geometries[b]
    radii: float | np.ndarray
    if geometry_b.shape.mesh is not None:
        centres, radii = np.asarray(geometry_b.shape.mesh.vertices, dtype=float), 0.0
    else:
        centres, radii = geometry_b.shape.bounding_spheres(8)
    centres = centres @ geometry_b.origin[:3, :3].T + geometry_b.origin[:3, 3]  # lower's child frame

    def from_axis(points: np.ndarray, axis: np.ndarray) -> np.ndarray:
        return np.linalg.norm(points - np.outer(points @ axis, axis), axis=1)

    rho_lower = float(np.max(from_axis(centres, chain.axis[lower]) + radii))
    # In upper's child frame a sphere centre x sits on a circle (as ``lower`` turns) about
    # t + R (x . axis) axis of radius |x - (x . axis) axis|, with t, R the offset of
    # ``lower`` (R = rotation_fixed - rotation_cos for a revolute joint).
    offset_rotation = chain.rotation_fixed[lower] - chain.rotation_cos[lower]
    along = np.outer(centres @ chain.axis[lower], chain.axis[lower]) @ offset_rotation.T + chain.translation[lower]
    rho_upper = float(np.max(from_axis(along, chain.axis[upper]) + from_axis(centres, chain.axis[lower]) + radii))
    rho = np.array([rho_upper, rho_lower])
    joints = np.array([upper, lower])
    # the values each joint takes over the robot's bounds (mimic joints scale and shift them)
    ends = chain.multiplier[joints, None] * np.stack([robot.lower, robot.upper], axis=1)[chain.source[joints]]
    ends += chain.shift[joints, None]
    low, high = ends.min(axis=1), ends.max(axis=1)

    by_value = chain._replace(
        source=np.arange(len(chain.source)), multiplier=np.ones(len(chain.source)), shift=np.zeros(len(chain.source))
    )  # chain_poses of joint values
    objects = [fcl.CollisionObject(g.shape.fcl_geometry(), fcl.Transform()) for g in (geometry_a, geometry_b)]
    values, poses = np.zeros(len(chain.source)), np.empty((robot.body_count, 4, 4))

    def distance(point: np.ndarray) -> float:
        values[joints] = point
        chain_poses(values, by_value, poses)
        for obj, geometry in zip(objects, (geometry_a, geometry_b)):
            obj.setTransform(fcl_transform(poses[geometry.body] @ geometry.origin))
        return fcl.distance(objects[0], objects[1], fcl.DistanceRequest(), fcl.DistanceResult())

    finest = TABLE_COARSE_CELLS << TABLE_LEVELS
    free = np.zeros((finest, finest), dtype=bool)
    pending = [(0, i, j) for i in range(TABLE_COARSE_CELLS) for j in range(TABLE_COARSE_CELLS)]
    while pending:
        level, i, j = pending.pop()
        cells = TABLE_COARSE_CELLS << level
        width = (high - low) / cells
        gap = distance(low + (np.array([i, j]) + 0.5) * width)
        if gap > float(rho @ (0.5 * width)) + SLACK:
            span = 1 << (TABLE_LEVELS - level)
            free[i * span : (i + 1) * span, j * span : (j + 1) * span] = True
        elif gap > 0.0 and level < TABLE_LEVELS:
            pending += [(level + 1, 2 * i + di, 2 * j + dj) for di in (0, 1) for dj in (0, 1)]
    return low, (high - low) / finest, free


_TABLES_OF: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # robot -> _free_tables(robot)


def _free_tables(robot: RobotModel) -> dict[str, np.ndarray]:
    """The ``Volumes`` fields of the certified-free tables of ``robot``'s self-collision pairs.

    A fraction of a second per table: computed once per robot and process, and kept in
    the disk cache (:mod:`ompl_balance.collision.cache`) under everything they are computed from.
    """
    if robot not in _TABLES_OF:
        key = [
            *robot.chain,
            robot.lower,
            robot.upper,
            np.array(robot.self_collision_pairs),
            TABLE_COARSE_CELLS,
            TABLE_LEVELS,
            SLACK,
        ]
        for g in robot.geometries:
            mesh = () if g.shape.mesh is None else (np.asarray(g.shape.mesh.vertices), np.asarray(g.shape.mesh.faces))
            key += [g.body, g.origin, g.shape.kind, g.shape.dims, *mesh]
        _TABLES_OF[robot] = cached_arrays("free_tables", key, lambda: _compute_free_tables(robot))
    return _TABLES_OF[robot]


def _compute_free_tables(robot: RobotModel) -> dict[str, np.ndarray]:
    pair_table: list[int] = []
    joints: list[tuple[int, int]] = []
    lows: list[np.ndarray] = []
    cells: list[np.ndarray] = []
    counts: list[tuple[int, ...]] = []
    starts: list[int] = []
    grids: list[np.ndarray] = []
    start = 0
    for a, b in robot.self_collision_pairs:
        body_a, body_b = robot.geometries[a].body, robot.geometries[b].body
        path, ancestor, moving = two_joint_path(robot.chain, body_a, body_b), a, b
        if path is None:
            path, ancestor, moving = two_joint_path(robot.chain, body_b, body_a), b, a
        if path is None:
            pair_table.append(-1)
            continue
        low, cell, free = free_table(robot, ancestor, moving, *path)
        pair_table.append(len(joints))
        joints.append(path)
        lows.append(low)
        cells.append(cell)
        counts.append(free.shape)
        starts.append(start)
        grids.append(free.ravel())
        start += free.size
    return {
        "pair_table": np.array(pair_table, dtype=np.int64),
        "table_joints": np.array(joints, dtype=np.int64).reshape(-1, 2),
        "table_low": np.array(lows, dtype=float).reshape(-1, 2),
        "table_cell": np.array(cells, dtype=float).reshape(-1, 2),
        "table_cells": np.array(counts, dtype=np.int64).reshape(-1, 2),
        "table_start": np.array(starts, dtype=np.int64),
        "table_free": np.concatenate(grids) if grids else np.zeros(0, dtype=bool),
    }


@njit(cache=True)
def _to_world(pose: np.ndarray, centre: np.ndarray, out: np.ndarray) -> None:  # pragma: no cover (compiled)
    for row in range(3):
        out[row] = pose[row, 0] * centre[0] + pose[row, 1] * centre[1] + pose[row, 2] * centre[2] + pose[row, 3]


@njit(cache=True)
def _sphere_touches_box(centre: np.ndarray, radius: float, volumes: Volumes, o: int) -> bool:  # pragma: no cover
    """Whether a sphere (world ``centre``, ``radius``) reaches obstacle ``o``'s box."""
    gap = 0.0
    for axis in range(3):
        along = 0.0
        for row in range(3):
            along += (centre[row] - volumes.box_centre[o, row]) * volumes.box_axes[o, row, axis]
        outside = abs(along) - volumes.box_half[o, axis]
        if outside > 0.0:
            gap += outside * outside
    reach = radius + SLACK
    return gap <= reach * reach


@njit(cache=True)
def _spheres_touch(a: np.ndarray, radius_a: float, b: np.ndarray, radius_b: float) -> bool:  # pragma: no cover
    reach = radius_a + radius_b + SLACK
    dx, dy, dz = a[0] - b[0], a[1] - b[1], a[2] - b[2]
    return dx * dx + dy * dy + dz * dz <= reach * reach


@njit(cache=True)
def _certified_free(q: np.ndarray, chain: Chain, volumes: Volumes, table: int) -> bool:  # pragma: no cover
    """Whether configuration ``q`` falls in a free cell of certified-free table ``table``."""
    index = volumes.table_start[table]
    for k in range(2):
        joint = volumes.table_joints[table, k]
        value = chain.multiplier[joint] * q[chain.source[joint]] + chain.shift[joint]
        cell = int(np.floor((value - volumes.table_low[table, k]) / volumes.table_cell[table, k]))
        if cell < 0 or cell >= volumes.table_cells[table, k]:
            return False  # outside the joint's bounds: not covered
        index += cell * volumes.table_cells[table, 1] if k == 0 else cell
    return volumes.table_free[index]


@njit(cache=True)
def screen(
    q: np.ndarray,
    chain: Chain,
    volumes: Volumes,
    poses: np.ndarray,
    obstacle_hits: np.ndarray,
    self_hits: np.ndarray,
) -> np.ndarray:  # pragma: no cover (compiled)
    """Forward kinematics and screening of configurations ``q`` (n, dof).

    Writes the body poses into ``poses`` (n, bodies, 4, 4), ``obstacle_hits`` (n,
    obstacles, geometries) and ``self_hits`` (n, pairs): True where the pair is not
    cleared. Returns ``maybe`` (n,) bool: True where some pair is not cleared.
    """
    geometries, obstacles, pairs = len(volumes.outer_radius), len(volumes.box_half), len(volumes.pairs)
    outer = np.empty((geometries, 3))
    small = np.empty((len(volumes.sphere_radius), 3))
    maybe = np.zeros(len(q), dtype=np.bool_)
    obstacle_hits[:] = False
    self_hits[:] = False
    for i in range(len(q)):
        chain_poses(q[i], chain, poses[i])
        for g in range(geometries):
            pose = poses[i, volumes.geometry_body[g]]
            _to_world(pose, volumes.outer_centre[g], outer[g])
            for s in range(volumes.sphere_start[g], volumes.sphere_start[g + 1]):
                _to_world(pose, volumes.sphere_centre[s], small[s])
        for o in range(obstacles):
            for g in range(geometries):
                if not _sphere_touches_box(outer[g], volumes.outer_radius[g], volumes, o):
                    continue
                for s in range(volumes.sphere_start[g], volumes.sphere_start[g + 1]):
                    if _sphere_touches_box(small[s], volumes.sphere_radius[s], volumes, o):
                        obstacle_hits[i, o, g] = maybe[i] = True
                        break
        for p in range(pairs):
            table = volumes.pair_table[p]
            if table >= 0 and _certified_free(q[i], chain, volumes, table):
                continue
            a, b = volumes.pairs[p, 0], volumes.pairs[p, 1]
            if not _spheres_touch(outer[a], volumes.outer_radius[a], outer[b], volumes.outer_radius[b]):
                continue
            for sa in range(volumes.sphere_start[a], volumes.sphere_start[a + 1]):
                # a small sphere of a must reach b's big sphere before its small ones are tried
                if not _spheres_touch(small[sa], volumes.sphere_radius[sa], outer[b], volumes.outer_radius[b]):
                    continue
                for sb in range(volumes.sphere_start[b], volumes.sphere_start[b + 1]):
                    if _spheres_touch(small[sa], volumes.sphere_radius[sa], small[sb], volumes.sphere_radius[sb]):
                        self_hits[i, p] = maybe[i] = True
                        break
                if self_hits[i, p]:
                    break
    return maybe


def stand_ins() -> tuple[Chain, Volumes]:
    """A one-joint chain and the volumes of a robot without geometry: arrays of the types
    real robots pass, for compiling the kernels ahead of use."""
    integers, reals = (lambda *shape: np.zeros(shape, dtype=np.int64)), (lambda *shape: np.zeros(shape))
    chain = Chain(
        integers(1),
        reals(1),
        reals(1),
        integers(1),
        reals(1, 3, 3),
        reals(1, 3, 3),
        reals(1, 3, 3),
        reals(1, 3),
        reals(1, 3),
        reals(1, 3),
    )
    volumes = Volumes(
        integers(0),
        reals(0, 3),
        reals(0),
        integers(1),
        reals(0, 3),
        reals(0),
        reals(0, 3),
        reals(0, 3, 3),
        reals(0, 3),
        integers(0, 2),
        integers(0),
        integers(0, 2),
        reals(0, 2),
        reals(0, 2),
        integers(0, 2),
        integers(0),
        np.zeros(0, dtype=bool),
    )
    return chain, volumes


def warm_up() -> None:
    """Compile the kernels, or load them from numba's cache, for the argument types every
    robot's checker uses (a robot with no geometry stands in): about half a second,
    spent here instead of in a robot's first check. The benchmark runner's forkserver
    does this once (:mod:`ompl_balance.collision.warm_kernels`), so run processes start warm."""
    chain, volumes = stand_ins()
    q, poses = np.zeros((1, 1)), np.zeros((1, 2, 4, 4))
    screen(q, chain, volumes, poses, np.zeros((1, 0, 0), dtype=bool), np.zeros((1, 0), dtype=bool))
    _chain_poses_batch(q, chain, poses)
