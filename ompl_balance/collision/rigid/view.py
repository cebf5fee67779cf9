"""The compiled view of a rigid-body checker: its arrays (:class:`RigidView`) and the state kernel.

A compiled planning loop (numba) holds a :class:`RigidView` and calls the kernels directly:

* :func:`state_status` ``(view, state) -> FREE | COLLIDING | UNDECIDED``;
* :func:`~ompl_balance.collision.rigid.advance.edge_status` ``(view, a, b, last_valid)``
  for a motion (see that module).

``FREE`` and ``COLLIDING`` are final. ``UNDECIDED`` leaves FCL queries in the view's work
arrays, which :meth:`~ompl_balance.collision.rigid.checker.RigidBodyChecker.decide` (Python)
answers; nothing else needs Python.

Collision pairs are (obstacle ``o``, body part ``g``), numbered ``o * parts + g``. A state is
*free* without FCL when every pair is cleared by bounding volumes that contain what FCL tests:
the body's sphere (about its frame origin) and each part's sphere against the obstacle's
oriented box and sphere, then the part's small covering spheres against the box, then, for
pairs of convex shapes, GJK on the hulls (:func:`~ompl_balance.collision.convex.distance_bounds`,
whose lower bound is rigorous). Pairs not cleared are left to FCL, so the answer is FCL's. A state is ``COLLIDING`` without FCL when
a corner of a part (of its FCL model) lies strictly inside a box obstacle, and when it is not
finite, lies outside the position bounds or has a quaternion off unit norm by more than 1e-9
(invalid, as OMPL.app's checker, ``satisfiesBounds``, has it).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ...core.kernel_cache import njit
from ..convex import ConvexParts, convex_part, distance_bounds, pack_parts
from ..screening import SLACK
from .motion import state_pose, valid_state

if TYPE_CHECKING:
    from ..environment import Obstacle
    from ..geometry import Shape
    from .body import RigidBody

#: Kernel answers: proved free of collision, in collision (or invalid), left to FCL.
FREE, COLLIDING, UNDECIDED = 0, 1, 2

#: ``counts`` entries: pairs :func:`state_status` left to FCL; hard segments ``edge_status``
#: left (-1: more than ``hard`` holds); poses evaluated and GJK bounds computed by the last call;
#: 1 when the last ``edge_status`` refused its motion because its work budget ran out.
UNDECIDED_PAIRS, HARD_SEGMENTS, POSES_EVALUATED, BOUNDS_COMPUTED, OVER_BUDGET = 0, 1, 2, 3, 4


class RigidView(NamedTuple):
    """A rigid-body checker's geometry and work arrays, for the compiled kernels.

    Parts ``g < G`` of the body, obstacles ``o < O``; pair ``p = o * G + g``. Lengths in the
    problem's unit (metres for the shipped problems; OMPL.app's files' own unit).

    ``dimension``: 2 (SE(2) states ``(x, y, yaw)``) or 3 (SE(3) states ``(x, y, z, qx, qy, qz,
    qw)``). ``low``, ``high`` (3,): position bounds (SE(2) uses x and y). ``body_radius``: the
    body's points are within this of its frame origin. Part ``g``: sphere ``part_centre[g]``
    (3,, body frame) of ``part_radius[g]`` holding it, small covering spheres rows
    ``sphere_start[g]:sphere_start[g + 1]`` of ``sphere_centre`` / ``sphere_radius``, and
    ``part_reach[g]``, the distance bound of its points from the frame origin (SE(3)) or z axis
    (SE(2)). Obstacle ``o``: oriented box (world centre ``box_centre[o]``, axes the columns of
    ``box_axes[o]``, half extents ``box_half[o]``) and sphere (``obstacle_centre[o]``,
    ``obstacle_radius[o]``). ``parts``: convex parts, the parts' hulls (rows ``g``, body frame)
    then the obstacles' (rows ``G + o``, world frame). ``solid[p]``: both hulls are the FCL
    models (convex shapes), so GJK decides their contact. ``corners_on_surface[g]``: every hull
    vertex of part ``g`` is a corner of its FCL model (a mesh's triangle corner, a box's corner);
    ``solid_box[o]``: obstacle ``o`` is an FCL box, so that such a corner strictly inside it is a
    contact FCL reports. ``fine``: screen states with the small
    spheres (off when body and world are all meshes: FCL then tests them whole, one call, and its
    own hierarchy does better than small spheres). ``probe``: certified motions first test a
    few states along the way (on when body and world are all meshes, see
    :func:`~ompl_balance.collision.rigid.kernels.probe_free`). ``clearance``: what certified motions
    keep; ``handover``: travel below which a non-solid pair's segment goes to FCL; ``scale``:
    the length scale of the tolerances (``max(1, reach)``); ``budget``: the work units one
    certified motion may spend (:mod:`ompl_balance.collision.budget`).

    Work arrays (written by the kernels): ``pose`` (1, 4, 4), ``identity`` (1, 4, 4), ``warm``
    (P, 3) last GJK direction per pair, ``simplex`` (4, 3) GJK's working simplex,
    ``placed_part`` (G, 3) and ``placed_sphere`` (S, 3) the spheres' world centres at ``pose``, ``undecided`` (P,) pairs left to FCL by
    :func:`state_status`, ``hard`` (H, 5) segments ``(pair, t0, t1, d0, d1)`` left to FCL by
    ``edge_status``, ``reached`` (1,) the fraction of the motion ``edge_status`` certified up to
    them, ``counts`` (5,) (see :data:`UNDECIDED_PAIRS` and after).
    """

    dimension: int
    low: np.ndarray
    high: np.ndarray
    body_radius: float
    part_centre: np.ndarray
    part_radius: np.ndarray
    part_reach: np.ndarray
    sphere_start: np.ndarray
    sphere_centre: np.ndarray
    sphere_radius: np.ndarray
    box_centre: np.ndarray
    box_axes: np.ndarray
    box_half: np.ndarray
    obstacle_centre: np.ndarray
    obstacle_radius: np.ndarray
    parts: ConvexParts
    solid: np.ndarray
    corners_on_surface: np.ndarray
    solid_box: np.ndarray
    fine: bool
    probe: bool
    clearance: float
    handover: float
    scale: float
    budget: int
    pose: np.ndarray
    identity: np.ndarray
    warm: np.ndarray
    simplex: np.ndarray
    placed_part: np.ndarray
    placed_sphere: np.ndarray
    undecided: np.ndarray
    hard: np.ndarray
    reached: np.ndarray
    counts: np.ndarray


#: Travel (as a fraction of the body's reach) below which a segment of a pair with a
#: non-convex mesh is handed to FCL's exact distance.
HANDOVER = 0.02


def build_view(
    body: RigidBody,
    obstacles: Sequence[Obstacle],
    low: np.ndarray,
    high: np.ndarray,
    spheres_per_part: int,
    clearance: float,
    budget: int,
) -> RigidView:
    """The :class:`RigidView` of ``body`` among ``obstacles`` within position bounds ``low``/``high`` (3,),
    certified motions keeping ``clearance`` within ``budget`` work units each."""
    outer, small, hulls = [], [], []
    for part in body.parts:
        centres, radii = part.shape.bounding_spheres(1)
        outer.append((centres[0] @ part.pose[:3, :3].T + part.pose[:3, 3], radii[0]))
        centres, radii = part.shape.bounding_spheres(spheres_per_part)
        small.append((centres @ part.pose[:3, :3].T + part.pose[:3, 3], radii))
        shape = part.shape
        hulls.append(convex_part(shape.kind, shape.dims, shape.hull_vertices(), part.pose))
    boxes, around = [], []
    for obstacle in obstacles:
        box_pose, half = obstacle.shape.bounding_box()
        pose = obstacle.pose @ box_pose
        boxes.append((pose[:3, 3], pose[:3, :3], half))
        centres, radii = obstacle.shape.bounding_spheres(1)
        around.append((obstacle.pose[:3, :3] @ centres[0] + obstacle.pose[:3, 3], radii[0]))
        shape = obstacle.shape
        hulls.append(convex_part(shape.kind, shape.dims, shape.hull_vertices(), obstacle.pose))
    convex = [p.shape.convex for p in body.parts]
    solid = np.array([o.shape.convex and c for o in obstacles for c in convex], dtype=bool)
    pairs = len(obstacles) * len(body.parts)
    reach = body.reach
    all_meshes = all(p.shape.mesh is not None for p in body.parts) and all(o.shape.mesh is not None for o in obstacles)
    return RigidView(
        dimension=2 if body.space == "SE2" else 3,
        low=np.ascontiguousarray(low, dtype=float),
        high=np.ascontiguousarray(high, dtype=float),
        body_radius=float(max(np.linalg.norm(c) + r for c, r in outer)),
        part_centre=np.array([c for c, _ in outer], dtype=float).reshape(-1, 3),
        part_radius=np.array([r for _, r in outer], dtype=float),
        part_reach=np.ascontiguousarray(body.part_reach, dtype=float),
        sphere_start=np.concatenate([[0], np.cumsum([len(r) for _, r in small])]).astype(np.int64),
        sphere_centre=np.concatenate([c for c, _ in small]).reshape(-1, 3).astype(float),
        sphere_radius=np.concatenate([r for _, r in small]).astype(float),
        box_centre=np.array([c for c, _, _ in boxes], dtype=float).reshape(-1, 3),
        box_axes=np.array([a for _, a, _ in boxes], dtype=float).reshape(-1, 3, 3),
        box_half=np.array([h for _, _, h in boxes], dtype=float).reshape(-1, 3),
        obstacle_centre=np.array([c for c, _ in around], dtype=float).reshape(-1, 3),
        obstacle_radius=np.array([r for _, r in around], dtype=float),
        parts=pack_parts(hulls),
        solid=solid,
        corners_on_surface=np.array([_corners_on_surface(p.shape) for p in body.parts], dtype=bool),
        solid_box=np.array([o.shape.kind == "box" for o in obstacles], dtype=bool),
        fine=not all_meshes,
        probe=all_meshes,
        clearance=float(clearance),
        handover=HANDOVER * reach,
        scale=max(1.0, reach),
        budget=int(budget),
        pose=np.eye(4).reshape(1, 4, 4).copy(),
        identity=np.eye(4).reshape(1, 4, 4),
        warm=np.zeros((pairs, 3)),
        simplex=np.zeros((4, 3)),
        placed_part=np.zeros((len(body.parts), 3)),
        placed_sphere=np.zeros((sum(len(r) for _, r in small), 3)),
        undecided=np.zeros(pairs, dtype=np.int64),
        hard=np.zeros((max(64, 16 * pairs), 5)),
        reached=np.ones(1),
        counts=np.zeros(5, dtype=np.int64),
    )


def _corners_on_surface(shape: Shape) -> bool:
    """Whether the vertices of ``shape``'s convex part (:func:`~ompl_balance.collision.convex.convex_part`)
    are points of what FCL tests: a box's corners, or a mesh's hull vertices that triangles use."""
    if shape.kind == "box":
        return True
    if shape.mesh is None:
        return False
    used = {tuple(v) for v in np.asarray(shape.mesh.vertices, dtype=float)[np.asarray(shape.mesh.faces).ravel()]}
    hull = shape.hull_vertices()
    return hull is not None and all(tuple(v) in used for v in hull)


# The kernels read the view's arrays into local variables before their loops: numba reloads a
# named tuple's fields on every access inside a loop, which costs several times the arithmetic.


@njit(cache=True, inline="always")
def _box_gap(
    box_centre: np.ndarray, box_axes: np.ndarray, box_half: np.ndarray, o: int, x: float, y: float, z: float
) -> float:  # pragma: no cover (compiled)
    """Distance from the point ``(x, y, z)`` to oriented box ``o`` (0 inside)."""
    gap = 0.0
    for axis in range(3):
        along = (
            (x - box_centre[o, 0]) * box_axes[o, 0, axis]
            + (y - box_centre[o, 1]) * box_axes[o, 1, axis]
            + (z - box_centre[o, 2]) * box_axes[o, 2, axis]
        )
        outside = abs(along) - box_half[o, axis]
        if outside > 0.0:
            gap += outside * outside
    return math.sqrt(gap)


@njit(cache=True, inline="always")
def _point_bound(view: RigidView, o: int, x: float, y: float, z: float) -> float:  # pragma: no cover (compiled)
    """Lower bound on the distance from ``(x, y, z)`` to obstacle ``o``: its box, and its sphere."""
    centre = view.obstacle_centre
    dx, dy, dz = x - centre[o, 0], y - centre[o, 1], z - centre[o, 2]
    box = _box_gap(view.box_centre, view.box_axes, view.box_half, o, x, y, z)
    return max(box, math.sqrt(dx * dx + dy * dy + dz * dz) - view.obstacle_radius[o])


@njit(cache=True, inline="always")
def _placed(pose: np.ndarray, point: np.ndarray) -> tuple[float, float, float]:  # pragma: no cover (compiled)
    """Body-frame ``point`` (3,) in the world, for the body at ``pose`` (4, 4)."""
    return (
        pose[0, 0] * point[0] + pose[0, 1] * point[1] + pose[0, 2] * point[2] + pose[0, 3],
        pose[1, 0] * point[0] + pose[1, 1] * point[1] + pose[1, 2] * point[2] + pose[1, 3],
        pose[2, 0] * point[0] + pose[2, 1] * point[1] + pose[2, 2] * point[2] + pose[2, 3],
    )


@njit(cache=True, inline="always")
def sphere_bound(view: RigidView, pose: np.ndarray, pair: int) -> float:  # pragma: no cover (compiled)
    """Lower bound on ``pair``'s distance with the body at ``pose`` (4, 4), from the part's sphere
    against the obstacle's box and sphere, less :data:`~ompl_balance.collision.screening.SLACK`."""
    parts = len(view.part_radius)
    o, g = pair // parts, pair % parts
    x, y, z = _placed(pose, view.part_centre[g])
    return _point_bound(view, o, x, y, z) - view.part_radius[g] - SLACK


@njit(cache=True, inline="always")
def swept_bound(view: RigidView, start: np.ndarray, end: np.ndarray, o: int) -> float:  # pragma: no cover
    """Lower bound on obstacle ``o``'s distance from the whole body over a motion whose frame
    origin moves straight from pose ``start`` to pose ``end`` (4, 4), turning any way on the way:
    every point of the body stays within ``body_radius`` of that segment. From the obstacle's
    sphere (its centre's distance from the segment) and its box (from the segment's middle,
    less half its length), less :data:`~ompl_balance.collision.screening.SLACK`."""
    ax, ay, az = start[0, 3], start[1, 3], start[2, 3]
    ux, uy, uz = end[0, 3] - ax, end[1, 3] - ay, end[2, 3] - az
    cx, cy, cz = view.obstacle_centre[o, 0] - ax, view.obstacle_centre[o, 1] - ay, view.obstacle_centre[o, 2] - az
    length_squared = ux * ux + uy * uy + uz * uz
    s = 0.0 if length_squared == 0.0 else min(max((cx * ux + cy * uy + cz * uz) / length_squared, 0.0), 1.0)
    dx, dy, dz = cx - s * ux, cy - s * uy, cz - s * uz
    sphere = math.sqrt(dx * dx + dy * dy + dz * dz) - view.obstacle_radius[o]
    mx, my, mz = ax + 0.5 * ux, ay + 0.5 * uy, az + 0.5 * uz
    box = _box_gap(view.box_centre, view.box_axes, view.box_half, o, mx, my, mz) - 0.5 * math.sqrt(length_squared)
    return max(sphere, box) - view.body_radius - SLACK


@njit(cache=True)
def hull_bound(
    view: RigidView, poses: np.ndarray, pair: int, enough: float
) -> tuple[float, float]:  # pragma: no cover (compiled)
    """Lower and upper bounds on ``pair``'s distance from GJK on the convex hulls, with the
    body at ``poses[0]`` ((1, 4, 4)); stops once the lower bound reaches ``enough``. Warm-started
    from, and leaving its direction in, ``view.warm[pair]``; the lower bound is less ``SLACK``."""
    parts = len(view.part_radius)
    o, g = pair // parts, pair % parts
    warm = view.warm
    if warm[pair, 0] == 0.0 and warm[pair, 1] == 0.0 and warm[pair, 2] == 0.0:
        x, y, z = _placed(poses[0], view.part_centre[g])
        warm[pair, 0] = x - view.obstacle_centre[o, 0]
        warm[pair, 1] = y - view.obstacle_centre[o, 1]
        warm[pair, 2] = z - view.obstacle_centre[o, 2]
    # (the body's and the obstacles' row of their poses as a plain int: with numba's literal 0s
    # the robot layer's compilation of distance_bounds would not serve here)
    pose_row = int(0)  # noqa: UP018, RUF046
    lower, upper = distance_bounds(
        view.parts, g, poses, pose_row, parts + o, view.identity, pose_row, warm, pair, view.simplex, enough + SLACK
    )
    return lower - SLACK, upper


@njit(cache=True)
def _corner_inside(view: RigidView, pose: np.ndarray, o: int, g: int) -> bool:  # pragma: no cover (compiled)
    """Whether a hull vertex of part ``g``, the body at ``pose``, lies strictly inside box ``o``."""
    vertex, centre, axes, half = view.parts.vertex, view.box_centre, view.box_axes, view.box_half
    for v in range(view.parts.start[g], view.parts.start[g + 1]):
        x, y, z = _placed(pose, vertex[v])
        inside = True
        for axis in range(3):
            along = (
                (x - centre[o, 0]) * axes[o, 0, axis]
                + (y - centre[o, 1]) * axes[o, 1, axis]
                + (z - centre[o, 2]) * axes[o, 2, axis]
            )
            if abs(along) >= half[o, axis] - SLACK:
                inside = False
                break
        if inside:
            return True
    return False


@njit(cache=True)
def state_status(view: RigidView, state: np.ndarray) -> int:  # pragma: no cover (compiled)
    """``FREE``, ``COLLIDING`` (an invalid state) or ``UNDECIDED`` for ``state`` (3,) or (7,).

    Pairs are screened obstacle by obstacle (those the body's sphere reaches), part by part,
    until one is not cleared: the part's sphere against the obstacle's box and sphere, then
    (``view.fine``) its small spheres against the box and, for convex pairs, GJK. A pair not
    cleared, or not screened after that, whose part has a corner strictly inside an FCL box
    obstacle is a contact (``COLLIDING``). ``UNDECIDED``
    leaves the pairs FCL must test in ``view.undecided[:view.counts[0]]``: that pair first (the
    likeliest contact), then every pair not screened yet; the body pose is in ``view.pose[0]``.
    ``view.counts[3]`` counts the GJK bounds computed.
    """
    counts = view.counts
    counts[UNDECIDED_PAIRS] = 0
    counts[BOUNDS_COMPUTED] = 0
    if not valid_state(state, view.low, view.high):
        return COLLIDING
    pose = view.pose[0]
    state_pose(state, pose)
    box_centre, box_axes, box_half = view.box_centre, view.box_axes, view.box_half
    around, around_radius = view.obstacle_centre, view.obstacle_radius
    part_radius, sphere_start, sphere_radius = view.part_radius, view.sphere_start, view.sphere_radius
    placed_part, placed_sphere, undecided_pairs = view.placed_part, view.placed_sphere, view.undecided
    fine, solid, body_radius = view.fine, view.solid, view.body_radius
    solid_box, corners_on_surface = view.solid_box, view.corners_on_surface
    parts = len(part_radius)
    for g in range(parts):
        placed_part[g, 0], placed_part[g, 1], placed_part[g, 2] = _placed(pose, view.part_centre[g])
    if fine:
        for s in range(len(sphere_radius)):
            placed_sphere[s, 0], placed_sphere[s, 1], placed_sphere[s, 2] = _placed(pose, view.sphere_centre[s])
    undecided = 0
    for o in range(len(box_half)):
        x, y, z = pose[0, 3], pose[1, 3], pose[2, 3]
        gap = max(
            _box_gap(box_centre, box_axes, box_half, o, x, y, z),
            math.sqrt((x - around[o, 0]) ** 2 + (y - around[o, 1]) ** 2 + (z - around[o, 2]) ** 2) - around_radius[o],
        )
        if gap > body_radius + SLACK:
            continue
        for g in range(parts):
            x, y, z = placed_part[g, 0], placed_part[g, 1], placed_part[g, 2]
            if undecided > 0:  # FCL will be needed anyway: the rest goes to it unscreened, but
                # a contact found here spares FCL
                if solid_box[o] and corners_on_surface[g] and _corner_inside(view, pose, o, g):
                    return COLLIDING
                undecided_pairs[undecided] = o * parts + g
                undecided += 1
                continue
            gap = max(
                _box_gap(box_centre, box_axes, box_half, o, x, y, z),
                math.sqrt((x - around[o, 0]) ** 2 + (y - around[o, 1]) ** 2 + (z - around[o, 2]) ** 2)
                - around_radius[o],
            )
            if gap > part_radius[g] + SLACK:
                continue
            cleared = False
            if fine:
                cleared = True
                for s in range(sphere_start[g], sphere_start[g + 1]):
                    x, y, z = placed_sphere[s, 0], placed_sphere[s, 1], placed_sphere[s, 2]
                    if _box_gap(box_centre, box_axes, box_half, o, x, y, z) <= sphere_radius[s] + SLACK:
                        cleared = False
                        break
                pair = o * parts + g
                if not cleared and solid[pair]:
                    counts[BOUNDS_COMPUTED] += 1
                    cleared = hull_bound(view, view.pose, pair, SLACK)[0] > 0.0
            if not cleared:
                if solid_box[o] and corners_on_surface[g] and _corner_inside(view, pose, o, g):
                    return COLLIDING
                undecided_pairs[undecided] = o * parts + g
                undecided += 1
    counts[UNDECIDED_PAIRS] = undecided
    return FREE if undecided == 0 else UNDECIDED


@njit(cache=True)
def states_status(
    view: RigidView, states: np.ndarray, poses: np.ndarray, undecided: np.ndarray
) -> np.ndarray:  # pragma: no cover (compiled)
    """:func:`state_status` of each row of ``states`` (n, 3) or (n, 7): statuses (n,); the body
    poses into ``poses`` (n, 4, 4) and the pairs left to FCL into ``undecided`` (n, P) bool.
    ``view.counts[3]`` counts the GJK bounds computed."""
    status = np.empty(len(states), dtype=np.int64)
    bounds = 0
    pose = view.pose[0]
    for i in range(len(states)):
        status[i] = state_status(view, states[i])
        bounds += view.counts[BOUNDS_COMPUTED]
        # (element by element: an array assigned to a slice has numba compile its shape-mismatch
        # error, string formatting and all, some 3 s of the first compilation)
        for row in range(4):
            for column in range(4):
                poses[i, row, column] = pose[row, column]
        for pair in range(undecided.shape[1]):
            undecided[i, pair] = False
        for k in range(view.counts[UNDECIDED_PAIRS]):
            undecided[i, view.undecided[k]] = True
    view.counts[BOUNDS_COMPUTED] = bounds
    return status
