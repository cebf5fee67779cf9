"""Conservative advancement of every collision pair along one edge, compiled.

:func:`advance` certifies the straight joint-space edge ``q(t) = a + t (b - a)`` pair by
pair. A pair with distance lower bounds ``d0, d1`` at ``t0, t1`` and a travel bound ``V``
per unit ``t`` (:mod:`ompl_balance.collision.travel`) stays at least
``max(d0 - V (t - t0), d1 - V (t1 - t)) >= (d0 + d1 - V (t1 - t0)) / 2`` apart on the
segment, so the segment is certified when ``d0 + d1 - 2 clearance > V (t1 - t0)``.
Otherwise its end bounds are sharpened (a bound computed "good enough" for a longer
segment may be improved), and if that does not do it, the segment is cut in half and
its midpoint bounded; pairs are independent, so a pair far from contact is done after a
bound or two while a close one is cut finely. Bounds come cheapest first
(:func:`sphere_bounds`, :func:`hull_bounds`): the pair's bounding spheres, then GJK on convex parts
(:func:`~ompl_balance.collision.convex.distance_bounds`), warm-started from the
pair's last separating direction and stopped as soon as the bound suffices.

Self pairs with a certified-free table (:func:`~ompl_balance.collision.screening.free_table`)
are also certified by the table: in its two joint values a segment of the edge is a
straight line, certified when every cell it crosses is free (:func:`table_span_free`).

A pair whose convex parts are its FCL model (primitives, convex meshes) is decided here:
a GJK upper bound within :data:`DISTANCE_TOLERANCE` of the clearance is a contact. Other
pairs (a non-convex mesh and its hull) are handed over to FCL's exact distance when a
segment of travel at most ``handover`` metres still fails (the *hard* segments), or, where
only a yes or no is wanted, as soon as their convex parts touch at a segment's end: there
the mesh is likeliest in contact, which FCL tells in one test, and the caller may ask FCL
before the rest of the edge is certified (``probe``).

Every call has a work budget (:mod:`ompl_balance.collision.budget`): each configuration placed
and each GJK bound costs one unit, and a proof that would need more stops there, the edge
refused (``exhausted``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..core.array_kernels import copy_into
from ..core.kernel_cache import njit, njit_borrowing
from .convex import ConvexParts, Vector, distance_bounds
from .kinematics import Chain, chain_poses
from .screening import SLACK, Volumes

#: Metres within which a pair counts as in contact beyond the clearance: FCL's distances
#: are iterative (GJK, tolerance about 1e-6) for primitives, and every exact distance is
#: taken less this.
DISTANCE_TOLERANCE = 1e-5
#: A failing segment is halved on sphere bounds alone, without GJK, while its travel bound
#: is at most this many times the room its end bounds leave (a level or two more).
SPHERE_REACH = 8.0
#: A segment whose travel bound is below this (m) and is still not certified is not cut
#: again: the edge is rejected (grazing contact).
MIN_TRAVEL = 1e-7
#: Deepest bisection level (segments of 2**-MAX_LEVEL of the edge); a segment that deep
#: and still uncertified fails.
MAX_LEVEL = 48


class Model(NamedTuple):
    """What :func:`advance` needs besides the chain and the checker's :class:`Volumes`.

    ``parts``: the convex parts of the link geometries (body frames) then of the obstacles
    (world frame). Obstacle ``o`` is inside the sphere ``obstacle_centre[o]``,
    ``obstacle_radius[o]`` as well as its box. ``environment_weight`` (geometries, dof)
    and ``self_weight`` (self pairs, dof) are the travel weights. Per pair: ``fixed``
    distance (pairs no joint moves; NaN for the others) and ``solid``: its convex parts are
    its FCL model, so contacts are decided here. ``joint_lower``, ``joint_upper`` (dof,):
    the joint bounds the travel weights hold within. Pair ``o * geometries + g`` is geometry
    ``g`` against obstacle ``o``; pair ``obstacles * geometries + s`` is self pair ``s``.
    """

    parts: ConvexParts
    obstacle_centre: np.ndarray
    obstacle_radius: np.ndarray
    environment_weight: np.ndarray
    self_weight: np.ndarray
    fixed: np.ndarray
    solid: np.ndarray
    joint_lower: np.ndarray
    joint_upper: np.ndarray


class Remembered(NamedTuple):
    """Bounds known at remembered configurations, one row each, (configurations, pairs):
    ``lower`` (a row of NaN: a configuration not seen yet), ``upper`` (inf: unknown) and
    ``final`` (the lower bound cannot be sharpened)."""

    lower: np.ndarray
    upper: np.ndarray
    final: np.ndarray


@njit(cache=True, inline="always")
def _placed(poses: np.ndarray, body: int, points: np.ndarray, i: int) -> Vector:  # pragma: no cover (compiled)
    """Body-frame point ``points[i]`` (3,) in the world, for the body at ``poses[body]`` (4, 4)."""
    x, y, z = points[i, 0], points[i, 1], points[i, 2]
    return (
        poses[body, 0, 0] * x + poses[body, 0, 1] * y + poses[body, 0, 2] * z + poses[body, 0, 3],
        poses[body, 1, 0] * x + poses[body, 1, 1] * y + poses[body, 1, 2] * z + poses[body, 1, 3],
        poses[body, 2, 0] * x + poses[body, 2, 1] * y + poses[body, 2, 2] * z + poses[body, 2, 3],
    )


@njit(cache=True)
def sphere_bounds(
    poses: np.ndarray, volumes: Volumes, model: Model, pairs: np.ndarray, out: np.ndarray
) -> None:  # pragma: no cover (compiled)
    """Lower bounds (m) from the bounding spheres of each of ``pairs`` at body ``poses`` into ``out``.

    A geometry's sphere against an obstacle's box and its sphere; two geometries' spheres
    against each other; the fixed distance of pairs no joint moves. Less
    :data:`~ompl_balance.collision.screening.SLACK` for rounding.
    """
    geometries, environment = len(volumes.outer_radius), len(volumes.box_half) * len(volumes.outer_radius)
    for i in range(len(pairs)):
        pair = pairs[i]
        if not math.isnan(model.fixed[pair]):
            out[i] = model.fixed[pair]
        elif pair < environment:
            o, g = pair // geometries, pair % geometries
            x, y, z = _placed(poses, volumes.geometry_body[g], volumes.outer_centre, g)
            gap = 0.0
            for axis in range(3):
                along = (
                    (x - volumes.box_centre[o, 0]) * volumes.box_axes[o, 0, axis]
                    + (y - volumes.box_centre[o, 1]) * volumes.box_axes[o, 1, axis]
                    + (z - volumes.box_centre[o, 2]) * volumes.box_axes[o, 2, axis]
                )
                outside = abs(along) - volumes.box_half[o, axis]
                if outside > 0.0:
                    gap += outside * outside
            dx = x - model.obstacle_centre[o, 0]
            dy = y - model.obstacle_centre[o, 1]
            dz = z - model.obstacle_centre[o, 2]
            around = math.sqrt(dx * dx + dy * dy + dz * dz) - model.obstacle_radius[o]
            out[i] = max(math.sqrt(gap), around) - volumes.outer_radius[g] - SLACK
        else:
            first, second = volumes.pairs[pair - environment, 0], volumes.pairs[pair - environment, 1]
            x, y, z = _placed(poses, volumes.geometry_body[first], volumes.outer_centre, first)
            u, v, w = _placed(poses, volumes.geometry_body[second], volumes.outer_centre, second)
            between = math.sqrt((x - u) ** 2 + (y - v) ** 2 + (z - w) ** 2)
            out[i] = between - volumes.outer_radius[first] - volumes.outer_radius[second] - SLACK


@njit(cache=True)
def hull_bounds(
    pair: int,
    poses: np.ndarray,
    volumes: Volumes,
    model: Model,
    warm: np.ndarray,
    identity: np.ndarray,
    simplex: np.ndarray,
    enough: float,
) -> tuple[float, float]:  # pragma: no cover (compiled)
    """Lower and upper bounds (m) on ``pair``'s distance at body ``poses`` from GJK on its convex parts.

    ``warm`` (pairs, 3) holds each pair's last GJK direction; ``identity`` (1, 4, 4) places
    the obstacles; ``simplex`` (4, 3) is GJK's scratch. Stops once the lower bound reaches
    ``enough``. The lower bound is less :data:`~ompl_balance.collision.screening.SLACK` for
    rounding.
    """
    if not math.isnan(model.fixed[pair]):
        return model.fixed[pair], model.fixed[pair]
    geometries, environment = len(volumes.outer_radius), len(volumes.box_half) * len(volumes.outer_radius)
    if pair < environment:
        o, g = pair // geometries, pair % geometries
        body = volumes.geometry_body[g]
        if warm[pair, 0] == 0.0 and warm[pair, 1] == 0.0 and warm[pair, 2] == 0.0:
            centre = _placed(poses, body, volumes.outer_centre, g)
            for axis in range(3):
                warm[pair, axis] = centre[axis] - model.obstacle_centre[o, axis]
        # (a plain int: numba's literal 0 would compile distance_bounds once more, as it does
        # for every literal argument of a kernel)
        obstacles_body = int(0)  # noqa: UP018, RUF046
        lower, upper = distance_bounds(
            model.parts, g, poses, body, geometries + o, identity, obstacles_body, warm, pair, simplex, enough + SLACK
        )
        return lower - SLACK, upper
    first, second = volumes.pairs[pair - environment, 0], volumes.pairs[pair - environment, 1]
    first_body, second_body = volumes.geometry_body[first], volumes.geometry_body[second]
    if warm[pair, 0] == 0.0 and warm[pair, 1] == 0.0 and warm[pair, 2] == 0.0:
        centre = _placed(poses, first_body, volumes.outer_centre, first)
        other = _placed(poses, second_body, volumes.outer_centre, second)
        for axis in range(3):
            warm[pair, axis] = centre[axis] - other[axis]
    lower, upper = distance_bounds(
        model.parts, first, poses, first_body, second, poses, second_body, warm, pair, simplex, enough + SLACK
    )
    return lower - SLACK, upper


@njit(cache=True, inline="always")
def _table_axis(
    a: np.ndarray, delta: np.ndarray, t0: float, chain: Chain, volumes: Volumes, table: int, k: int
) -> tuple[float, float, float, float]:  # pragma: no cover (compiled)
    """Axis ``k`` of certified-free table ``table`` along ``a + t delta``: the cell coordinate
    ``u(t) = low + t slope`` as ``(low, slope)``, the first ``t`` after ``t0`` where ``u``
    crosses a cell boundary, and the ``t`` between crossings (inf: ``u`` is constant)."""
    joint = volumes.table_joints[table, k]
    value = chain.multiplier[joint] * a[chain.source[joint]] + chain.shift[joint]
    rate = chain.multiplier[joint] * delta[chain.source[joint]]
    low = (value - volumes.table_low[table, k]) / volumes.table_cell[table, k]
    slope = rate / volumes.table_cell[table, k]
    u = low + t0 * slope
    if slope > 0.0:
        return low, slope, t0 + (math.floor(u) + 1.0 - u) / slope, 1.0 / slope
    if slope < 0.0:
        return low, slope, t0 + (math.ceil(u) - 1.0 - u) / slope, -1.0 / slope
    return low, slope, np.inf, np.inf


@njit(cache=True, inline="always")
def _table_cell(u: float, cells: int) -> int:  # pragma: no cover (compiled)
    """The cell of coordinate ``u`` on an axis of ``cells`` cells (the upper bound itself in the
    last, closed, cell); -1 outside."""
    cell = math.floor(u)
    if cell == cells and u <= cells + 1e-9:
        return cells - 1
    return cell if 0 <= cell < cells else -1


@njit(cache=True)
def table_span_free(
    a: np.ndarray, delta: np.ndarray, t0: float, t1: float, chain: Chain, volumes: Volumes, table: int
) -> bool:  # pragma: no cover (compiled)
    """Whether ``a + t delta``, ``t in [t0, t1]``, crosses free cells of certified-free table ``table`` only.

    In the table's two joint values the edge is a straight line ``u(t)`` (in cells);
    between consecutive crossings of cell boundaries it stays in one closed cell, tested
    at the middle of the stretch. (A crossing ``t`` off by rounding moves by far less than
    the tables' slack of :data:`~ompl_balance.collision.screening.SLACK`.) Scalars only: it
    runs for every self pair a segment does not certify, so allocations would cost more
    than the walk.
    """
    rows, columns = volumes.table_cells[table, 0], volumes.table_cells[table, 1]
    low_row, slope_row, next_row, step_row = _table_axis(a, delta, t0, chain, volumes, table, 0)
    low_column, slope_column, next_column, step_column = _table_axis(a, delta, t0, chain, volumes, table, 1)
    begin = t0
    while begin < t1:
        end = min(next_row, next_column, t1)
        middle = 0.5 * (begin + end)
        row = _table_cell(low_row + middle * slope_row, rows)
        column = _table_cell(low_column + middle * slope_column, columns)
        if row < 0 or column < 0 or not volumes.table_free[volumes.table_start[table] + row * columns + column]:
            return False
        if next_row <= end:
            next_row += step_row
        if next_column <= end:
            next_column += step_column
        begin = end
    return True


@njit(cache=True)
def grown(array: np.ndarray, size: int) -> np.ndarray:  # pragma: no cover (compiled)
    """``array``, or a copy at least twice as long when it is shorter than ``size``."""
    if len(array) >= size:
        return array
    bigger = np.empty((max(size, 2 * len(array)), *array.shape[1:]), dtype=array.dtype)
    # (value by value: ``bigger[: len(array)] = array`` compiles numba's shape-mismatch message
    # along, a second per kind of array, and the layers grow seven kinds)
    into = bigger.reshape(-1)
    for i, value in enumerate(array.flat):
        into[i] = value
    return bigger


class EdgeModel(NamedTuple):
    """What :func:`advance` certifies against, fixed for a certifier: the robot's ``chain``, the
    checker's ``volumes``, the certifier's :class:`Model`, ``clearance`` (m: pairs must stay
    farther apart), ``handover`` (m of travel below which non-convex pairs go to FCL),
    ``floor`` (m: a segment failing with less travel fails the edge) and ``budget``: the work
    units one motion check may spend (:mod:`ompl_balance.collision.budget`)."""

    chain: Chain
    volumes: Volumes
    model: Model
    clearance: float
    handover: float
    floor: float
    budget: int


class EdgeScratch(NamedTuple):
    """What :func:`advance` writes besides the remembered bounds: ``warm`` (pairs, 3) each
    pair's last GJK direction, ``simplex`` (4, 3) GJK's working simplex, ``speed`` (pairs,) each
    pair's travel bound per unit ``t`` on the last edge, and the hard segments, pair
    ``hard_pair[i]`` (capacity,) over ``hard_span[i]`` = (t0, t1, d0, d1) (capacity, 4), grown
    when needed."""

    warm: np.ndarray
    simplex: np.ndarray
    speed: np.ndarray
    hard_pair: np.ndarray
    hard_span: np.ndarray


class EndMemory(NamedTuple):
    """Bounds at the last edge end configurations, one row each, reused in turn (oldest first).

    Planners extend from the same tree states again and again; what was computed there is
    kept (as lower bounds they hold for any edge). ``keys`` (rows, dof) are the configurations
    of rows in ``used``; ``generation`` (rows,) counts each row's reuses (so Python-side
    memories of a row can tell a new configuration); ``next`` (1,) the row reused next;
    ``bounds`` the remembered bounds.
    """

    keys: np.ndarray
    used: np.ndarray
    generation: np.ndarray
    next: np.ndarray
    bounds: Remembered


def end_memory(rows: int, dof: int, pairs: int) -> EndMemory:
    """An empty :class:`EndMemory` of ``rows`` configurations of ``dof`` joints and ``pairs`` pairs."""
    return EndMemory(
        np.zeros((rows, dof)),
        np.zeros(rows, dtype=np.bool_),
        np.zeros(rows, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        Remembered(np.full((rows, pairs), np.nan), np.full((rows, pairs), np.inf), np.zeros((rows, pairs), dtype=bool)),
    )


@njit_borrowing
def memory_row(memory: EndMemory, q: np.ndarray) -> int:  # pragma: no cover (compiled)
    """The row of configuration ``q`` (dof,) in ``memory``; the oldest row, cleared, if ``q`` is not remembered."""
    keys = memory.keys
    for row in range(keys.shape[0]):
        if memory.used[row]:
            same = True
            for j in range(q.shape[0]):
                if keys[row, j] != q[j]:
                    same = False
                    break
            if same:
                return row
    row = memory.next[0]
    memory.next[0] = (row + 1) % keys.shape[0]
    copy_into(q, keys[row])
    memory.used[row] = True
    memory.generation[row] += 1
    bounds = memory.bounds
    for pair in range(bounds.lower.shape[1]):
        bounds.lower[row, pair], bounds.upper[row, pair], bounds.final[row, pair] = np.nan, np.inf, False
    return row


@njit(cache=True, inline="always")
def _parts_touch(lower: np.ndarray, final: np.ndarray, clearance: float) -> bool:  # pragma: no cover (compiled)
    """Whether a segment's convex parts are within ``clearance`` at an end: its lower bound
    ``lower`` (2,) there at most that, and ``final`` (2,) (GJK's, which cannot be sharpened)."""
    return (final[0] and lower[0] <= clearance) or (final[1] and lower[1] <= clearance)


@njit(cache=True)
def _exhausted(
    stop: bool,
    bad: float,
    seg_k: np.ndarray,
    width: float,
    first: int,
    count: int,
    split: np.ndarray,
    splits: int,
    hard: int,
    evaluated: int,
    bounded: int,
    hard_pair: np.ndarray,
    hard_span: np.ndarray,
) -> tuple[bool, float, int, int, int, np.ndarray, np.ndarray, bool]:  # pragma: no cover (compiled)
    """What :func:`advance` returns when its budget runs out: the edge fails, and (unless
    ``stop``) is certified up to the least of ``bad`` and the starts of the segments still
    unproved: those of the level not yet looked at (``first`` to ``count``), those to be halved
    (``split[:splits]``) and the hard segments."""
    if stop:
        return True, 0.0, hard, evaluated, bounded, hard_pair, hard_span, True
    for i in range(first, count):
        bad = min(bad, seg_k[i] * width)
    for i in range(splits):
        bad = min(bad, seg_k[split[i]] * width)
    for i in range(hard):
        bad = min(bad, hard_span[i, 0])
    return True, bad, hard, evaluated, bounded, hard_pair, hard_span, True


@njit(cache=True)
def advance(
    a: np.ndarray,
    b: np.ndarray,
    edge: EdgeModel,
    remembered: Remembered,
    start: int,
    end: int,
    settle: float,
    stop: bool,
    probe: bool,
    scratch: EdgeScratch,
    budget: int,
) -> tuple[bool, float, int, int, int, np.ndarray, np.ndarray, bool]:  # pragma: no cover (compiled)
    """Certify the edge ``a -> b`` (dof,) for every pair but the hard segments.

    ``edge``: what to certify against (:class:`EdgeModel`). ``remembered`` rows ``start`` and
    ``end`` hold the bounds known at ``a`` and ``b`` and receive what is computed there.
    ``stop``: return at the first failure; otherwise a segment reaching a failure found
    earlier is refined to ``settle`` (m) of travel only (where the last certified fraction is
    wanted, not a certificate). ``scratch``: see :class:`EdgeScratch`.

    With ``stop``, a segment of a non-convex pair whose convex parts are within the clearance at
    an end (GJK's bound there is final) is a hard segment at once, however long: halving it
    would leave a hard segment at every ``handover`` of travel along the stretch where the parts
    touch, and most such edges collide there, which FCL finds in one test. ``probe`` (with
    ``stop``): return undecided (``failed`` False, ``bad`` 0, the hard segments so far) at the
    end of the first bisection level that hands such a segment over, before the rest of the
    edge is certified, for the caller to test them first.

    ``budget``: the work units this call may spend. The bound: configurations placed plus GJK
    bounds computed <= ``budget``; the unit that would exceed it is not spent, the edge fails
    (``exhausted``) and ``bad`` moves back to the start of the first segment still unproved
    (hard segments included: the caller does not finish them).

    Returns ``failed`` (an end outside the joint bounds or not finite, a contact, or a
    segment that cannot be certified), ``bad`` (the edge is certified for all pairs on
    ``[0, bad]``, hard segments aside), the number of hard segments, the numbers of
    configurations evaluated and of GJK distance bounds computed, the (possibly grown)
    hard arrays, and ``exhausted``: the budget ran out (then ``failed`` too).
    """
    chain, volumes, model = edge.chain, edge.volumes, edge.model
    clearance, handover, floor = edge.clearance, edge.handover, edge.floor
    warm, simplex, speed = scratch.warm, scratch.simplex, scratch.speed
    hard_pair, hard_span = scratch.hard_pair, scratch.hard_span
    dof = len(a)
    for j in range(dof):
        for value in (a[j], b[j]):  # (NaN fails both comparisons)
            if not (model.joint_lower[j] <= value <= model.joint_upper[j]):
                return True, 0.0, 0, 0, 0, hard_pair, hard_span, False
    if budget < 2:  # (not even the two ends can be placed)
        return True, 0.0, 0, 0, 0, hard_pair, hard_span, True
    geometries, obstacles = len(volumes.outer_radius), len(volumes.box_half)
    pairs = obstacles * geometries + len(volumes.pairs)
    delta = b - a
    identity = np.eye(4).reshape(1, 4, 4)
    contact = clearance + DISTANCE_TOLERANCE
    for g in range(geometries):
        rate = 0.0
        for j in range(dof):
            rate += abs(delta[j]) * model.environment_weight[g, j]
        for o in range(obstacles):
            speed[o * geometries + g] = rate
    for s in range(len(volumes.pairs)):
        rate = 0.0
        for j in range(dof):
            rate += abs(delta[j]) * model.self_weight[s, j]
        speed[obstacles * geometries + s] = rate

    # evaluated configurations: t and body poses; 0 and 1 are the ends
    point_t = np.empty(16)
    point_poses = np.empty((16, len(chain.source) + 1, 4, 4))
    point_t[0], point_t[1] = 0.0, 1.0
    chain_poses(a, chain, point_poses[0])
    chain_poses(b, chain, point_poses[1])
    points = 2
    failed, bad, hard = False, 1.0, 0

    # segments of the current level: pair, index k (it spans [k, k + 1] * width), its two
    # points, lower bounds there and whether they are final (cannot be sharpened)
    seg_pair = np.arange(pairs)
    seg_k = np.zeros(pairs, dtype=np.int64)
    seg_point = np.zeros((pairs, 2), dtype=np.int64)
    seg_point[:, 1] = 1
    seg_lower = np.empty((pairs, 2))
    seg_final = np.zeros((pairs, 2), dtype=np.bool_)
    spheres, members, q = np.empty(pairs), np.empty(pairs, dtype=np.int64), np.empty(dof)
    for side, row in enumerate((start, end)):
        if pairs > 0 and math.isnan(remembered.lower[row, 0]):  # a configuration not seen before
            sphere_bounds(point_poses[side], volumes, model, seg_pair, remembered.lower[row])
        for pair in range(pairs):
            seg_lower[pair, side], seg_final[pair, side] = remembered.lower[row, pair], remembered.final[row, pair]
            if model.solid[pair] and remembered.upper[row, pair] <= contact:
                failed = True
                bad = min(bad, float(side))
    if failed and stop:
        return failed, 0.0, hard, 2, 0, hard_pair, hard_span, False
    count, level = pairs, 0
    evaluated, bounded = 2, 0
    touched = False  # a hard segment was handed over where its pair's convex parts touch
    while count > 0:
        width = 0.5**level
        split = np.empty(count, dtype=np.int64)
        splits = 0
        for e in range(count):
            pair, t0 = seg_pair[e], seg_k[e] * width
            if t0 >= bad:
                continue
            travel = speed[pair] * width
            need = travel + 2.0 * clearance
            if seg_lower[e, 0] + seg_lower[e, 1] > need:
                continue
            table = volumes.pair_table[pair - obstacles * geometries] if pair >= obstacles * geometries else -1
            if table >= 0 and table_span_free(a, delta, t0, t0 + width, chain, volumes, table):
                continue
            # sharpen the end bounds with GJK, the smaller first, unless halving with the
            # sphere bounds will do in a level or two
            first = 0 if seg_lower[e, 0] <= seg_lower[e, 1] else 1
            spare = seg_lower[e, 0] + seg_lower[e, 1] - 2.0 * clearance
            halve = spare > 0.0 and travel <= SPHERE_REACH * spare and (model.solid[pair] or travel > handover)
            for side in (first, 1 - first):
                if seg_final[e, side] or halve:
                    continue
                if evaluated + bounded >= budget:  # (one more bound would exceed the budget)
                    return _exhausted(
                        stop, bad, seg_k, width, e, count, split, splits, hard, evaluated, bounded, hard_pair, hard_span
                    )
                point = seg_point[e, side]
                target = need - seg_lower[e, 1 - side]
                lower, upper = hull_bounds(pair, point_poses[point], volumes, model, warm, identity, simplex, target)
                bounded += 1
                seg_lower[e, side] = max(seg_lower[e, side], lower)
                seg_final[e, side] = lower < target
                if point < 2:
                    row = start if point == 0 else end
                    remembered.lower[row, pair], remembered.final[row, pair] = seg_lower[e, side], seg_final[e, side]
                    remembered.upper[row, pair] = min(remembered.upper[row, pair], upper)
                if model.solid[pair] and upper <= contact:
                    failed = True
                    if stop:
                        return failed, 0.0, hard, evaluated, bounded, hard_pair, hard_span, False
                    bad = min(bad, point_t[point])
                if seg_lower[e, 0] + seg_lower[e, 1] > need:
                    break
            if seg_lower[e, 0] + seg_lower[e, 1] > need or t0 >= bad:
                continue
            touching = stop and not model.solid[pair] and _parts_touch(seg_lower[e], seg_final[e], clearance)
            if (not model.solid[pair] and travel <= handover) or touching:
                hard_pair = grown(hard_pair, hard + 1)
                hard_span = grown(hard_span, hard + 1)
                hard_pair[hard] = pair
                hard_span[hard, 0], hard_span[hard, 1] = t0, t0 + width
                hard_span[hard, 2], hard_span[hard, 3] = seg_lower[e, 0], seg_lower[e, 1]
                hard += 1
                touched = touched or touching
                continue
            if travel < floor or level >= MAX_LEVEL or (failed and t0 + width >= bad and travel < settle):
                failed = True
                if stop:
                    return failed, 0.0, hard, evaluated, bounded, hard_pair, hard_span, False
                bad = min(bad, t0)
                continue
            split[splits] = e
            splits += 1

        # halve the segments that need it: one forward kinematics and one sweep of sphere
        # bounds per midpoint, GJK for the pairs the spheres leave short
        order = split[:splits][np.argsort(seg_k[split[:splits]])]
        next_pair = np.empty(2 * splits, dtype=np.int64)
        next_k = np.empty(2 * splits, dtype=np.int64)
        next_point = np.empty((2 * splits, 2), dtype=np.int64)
        next_lower = np.empty((2 * splits, 2))
        next_final = np.empty((2 * splits, 2), dtype=np.bool_)
        following, group = 0, 0
        while group < splits:
            k = seg_k[order[group]]
            last = group
            while last < splits and seg_k[order[last]] == k:
                last += 1
            if evaluated + bounded >= budget:  # (placing the midpoint would exceed the budget)
                return _exhausted(
                    stop, bad, seg_k, width, count, count, split, splits, hard, evaluated, bounded, hard_pair, hard_span
                )
            points += 1
            point_t = grown(point_t, points)
            point_poses = grown(point_poses, points)
            middle = points - 1
            point_t[middle] = (k + 0.5) * width
            for j in range(dof):
                q[j] = a[j] + point_t[middle] * delta[j]
            chain_poses(q, chain, point_poses[middle])
            evaluated += 1
            for i in range(last - group):
                members[i] = seg_pair[order[group + i]]
            sphere_bounds(point_poses[middle], volumes, model, members[: last - group], spheres)
            for i in range(last - group):
                e = order[group + i]
                pair = seg_pair[e]
                target = 0.5 * speed[pair] * width + 2.0 * clearance - min(seg_lower[e, 0], seg_lower[e, 1])
                lower, final = spheres[i], False
                spare = spheres[i] + min(seg_lower[e, 0], seg_lower[e, 1]) - 2.0 * clearance
                if lower < target and not (spare > 0.0 and 0.5 * speed[pair] * width <= SPHERE_REACH * spare):
                    if evaluated + bounded >= budget:
                        return _exhausted(
                            stop,
                            bad,
                            seg_k,
                            width,
                            count,
                            count,
                            split,
                            splits,
                            hard,
                            evaluated,
                            bounded,
                            hard_pair,
                            hard_span,
                        )
                    lower, upper = hull_bounds(
                        pair, point_poses[middle], volumes, model, warm, identity, simplex, target
                    )
                    bounded += 1
                    lower, final = max(lower, spheres[i]), lower < target
                    if model.solid[pair] and upper <= contact:
                        failed = True
                        if stop:
                            return failed, 0.0, hard, evaluated, bounded, hard_pair, hard_span, False
                        bad = min(bad, point_t[middle])
                for side in range(2):
                    child = following + side
                    next_pair[child], next_k[child] = pair, 2 * k + side
                    next_point[child, side] = seg_point[e, side]
                    next_point[child, 1 - side] = middle
                    next_lower[child, side], next_final[child, side] = seg_lower[e, side], seg_final[e, side]
                    next_lower[child, 1 - side], next_final[child, 1 - side] = lower, final
                following += 2
            group = last
        if probe and touched:  # (the level's contacts of convex pairs found first: they cost no FCL test)
            return False, 0.0, hard, evaluated, bounded, hard_pair, hard_span, False
        seg_pair, seg_k, seg_point, seg_lower, seg_final = next_pair, next_k, next_point, next_lower, next_final
        count = following
        level += 1
    return failed, bad, hard, evaluated, bounded, hard_pair, hard_span, False
