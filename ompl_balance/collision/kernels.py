"""The robot checker and its motion validators as compiled kernels: their views for compiled code.

Three views (:mod:`ompl_balance.core.checks`), each a named tuple of arrays:

* :class:`RobotStates`: a :class:`~ompl_balance.collision.checker.CollisionChecker` deciding a
  configuration: the joint limits, then forward kinematics and the bounding-volume screening
  (:func:`~ompl_balance.collision.screening.screen`), and when a pair is not cleared, one exit
  to the checker's FCL test (:meth:`~ompl_balance.collision.checker.CollisionChecker.decide`) on
  the screening's arrays for one configuration, which the checker owns;
* :class:`RobotDiscreteMotions`: the discrete motion validator
  (:class:`~ompl_balance.validity.MotionValidator`): the end state alone, then the states at
  ``j / n`` of the way (``n`` as OMPL's ``validSegmentCount``) in one batch of screening,
  visited coarse to fine (:func:`coarse_to_fine`), FCL on those the screening leaves;
* :class:`CertifiedMotions`: certified motions (:class:`~ompl_balance.collision.certified.MotionCertifier`):
  conservative advancement in compiled code (:func:`~ompl_balance.collision.advancement.advance`),
  and one exit to FCL for the hard segments of non-convex pairs, within the certifier's work
  budget per motion (:mod:`ompl_balance.collision.budget`), the segments staged in the
  certifier's :class:`SegmentExits`.

The exits are C callbacks (:mod:`ompl_balance.core.checks`): they carry integers, the query is in
the staging arrays, and an error in one (FCL's, a Ctrl-C) sets ``counts[Count.RAISED]`` for the
caller to raise (:func:`~ompl_balance.core.checks.raise_kept`).

The Python validators call these same kernels (through fixed-type entry points), so a stock
planner and the compiled engine get the same answers and the same counts. Work is counted
in the checker's :class:`~ompl_balance.collision.checker.WorkCounter` array.
"""

from __future__ import annotations

import enum
from typing import Any, NamedTuple

import numpy as np

from ..core.array_kernels import copy_into
from ..core.check_overloads import register_kernels
from ..core.checks import EXIT_ADDRESS, Count, exit_handle
from ..core.compiled_spaces import segment_count
from ..core.function_pointers import call_exit, counted_exit
from ..core.kernel_cache import njit
from ..core.layout import SpaceLayout
from .advancement import EdgeModel, EdgeScratch, EndMemory, advance, memory_row
from .certified_lines import CertifiedLines, along_certified, certified_lines, remember_certified
from .kinematics import LIMIT_TOLERANCE, Chain
from .screening import Volumes, screen


class RobotStates(NamedTuple):
    """A collision checker as compiled code sees it.

    ``chain`` and ``volumes``: the robot and the screening's bounding volumes; ``lower``,
    ``upper`` (dof,): the joint limits; ``q`` (1, dof), ``poses`` (1, bodies, 4, 4),
    ``obstacle_hits`` (1, obstacles, geometries) and ``self_hits`` (1, pairs): the screening's
    scratch for one configuration, the checker's own (its exit reads them); ``address`` and
    ``handle``: the exit to the checker (:class:`Exit`); ``counts``: its work counter's array.
    """

    chain: Chain
    volumes: Volumes
    lower: np.ndarray
    upper: np.ndarray
    q: np.ndarray
    poses: np.ndarray
    obstacle_hits: np.ndarray
    self_hits: np.ndarray
    address: int
    handle: int
    counts: np.ndarray


class Exit(enum.IntEnum):
    """What the robot kernels' exits ask (the ``kind`` of :func:`~ompl_balance.core.function_pointers.call_exit`)."""

    DECIDE = 0  # the checker: FCL on the configuration in its view's one-row arrays: 1 free, 0 not
    STAGE_SEGMENTS = 1  # the certifier: keep the segments staged, more follow
    SEGMENTS_FREE = 2  # the certifier: FCL certifies the segments: EXIT_YES, EXIT_NO or EXIT_OVER_BUDGET
    SEGMENTS_TOUCH = 3  # the certifier: FCL finds a contact in them: EXIT_YES, EXIT_NO or EXIT_OVER_BUDGET


# (as plain integers for compiled code)
_DECIDE, _STAGE_SEGMENTS, _SEGMENTS_FREE, _SEGMENTS_TOUCH = (int(kind) for kind in Exit)


def screening_arrays(checker: Any, rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Scratch for screening ``rows`` configurations of ``checker``'s robot: q, poses, obstacle and self hits."""
    robot = checker.robot
    geometries, obstacles = len(robot.geometries), len(checker.environment.obstacles)
    return (
        np.zeros((rows, robot.dof)),
        np.zeros((rows, robot.body_count, 4, 4)),
        np.zeros((rows, obstacles, geometries), dtype=np.bool_),
        np.zeros((rows, len(robot.self_collision_pairs)), dtype=np.bool_),
    )


def robot_states(checker: Any) -> RobotStates:
    """The :class:`RobotStates` view of a :class:`~ompl_balance.collision.checker.CollisionChecker`
    (the checker makes it once: its exit answers about this view's arrays)."""
    robot = checker.robot
    q, poses, obstacle_hits, self_hits = screening_arrays(checker, 1)
    return RobotStates(
        robot.chain,
        checker.volumes,
        np.ascontiguousarray(robot.lower, dtype=float),
        np.ascontiguousarray(robot.upper, dtype=float),
        q,
        poses,
        obstacle_hits,
        self_hits,
        EXIT_ADDRESS,
        exit_handle(checker),
        checker.counter.array,
    )


@njit(cache=True)
def within_limits(view: RobotStates, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Every value of ``q`` within its joint's limits, as :meth:`RobotModel.within_limits` (``False`` for NaN)."""
    for j in range(q.shape[0]):  # noqa: SIM110 (a loop numba compiles)
        if not (view.lower[j] - LIMIT_TOLERANCE <= q[j] <= view.upper[j] + LIMIT_TOLERANCE):
            return False
    return True


@njit(cache=True)
def decide_screened(view: RobotStates) -> bool:  # pragma: no cover (compiled)
    """FCL on what the screening of one configuration left, in the view's one-row arrays (one
    exit to the checker); ``False`` with ``counts[Count.RAISED]`` set when the checker raised."""
    return counted_exit(view.counts, view.address, view.handle, _DECIDE, 0) == 1


@njit(cache=True)
def robot_state_free(view: RobotStates, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """:meth:`CollisionChecker.is_valid` of ``q`` (dof,): within the limits and free; counts one state."""
    view.counts[Count.STATES] += 1
    if not within_limits(view, q):
        return False
    for j in range(q.shape[0]):
        view.q[0, j] = q[j]
    maybe = screen(view.q, view.chain, view.volumes, view.poses, view.obstacle_hits, view.self_hits)
    return not maybe[0] or decide_screened(view)


class RobotDiscreteMotions(NamedTuple):
    """The discrete motion validator as compiled code sees it.

    ``states``: the checker's :class:`RobotStates`; ``layout``: the joint space's
    (:mod:`ompl_balance.core.layout`); ``q``, ``poses``, ``obstacle_hits``, ``self_hits``: screening
    scratch for ``rows`` states of an edge; ``order`` (rows + 1,) and ``intervals`` (2 rows + 2, 2):
    scratch of :func:`coarse_to_fine`; ``counts``: the checker's work counter's array.
    """

    states: RobotStates
    layout: SpaceLayout
    q: np.ndarray
    poses: np.ndarray
    obstacle_hits: np.ndarray
    self_hits: np.ndarray
    order: np.ndarray
    intervals: np.ndarray
    counts: np.ndarray


def robot_discrete_motions(checker: Any, layout: SpaceLayout, rows: int) -> RobotDiscreteMotions:
    """The :class:`RobotDiscreteMotions` view of ``checker`` in ``layout``, with scratch for ``rows`` states."""
    q, poses, obstacle_hits, self_hits = screening_arrays(checker, rows)
    order = np.zeros(rows + 1, dtype=np.int64)
    intervals = np.zeros((2 * rows + 2, 2), dtype=np.int64)
    return RobotDiscreteMotions(
        checker.kernel_view(), layout, q, poses, obstacle_hits, self_hits, order, intervals, checker.counter.array
    )


@njit(cache=True)
def coarse_to_fine(n: int, order: np.ndarray, intervals: np.ndarray) -> None:  # pragma: no cover (compiled)
    """Visiting order of the states ``j / n``, ``j = 1 .. n`` (as indices ``j - 1``) into ``order[:n]``.

    The end state first, then breadth-first bisection of ``(0, n)``: the midpoint, the
    quarter points, and so on, so that an obstacle across the edge is met early.
    ``intervals`` (at least 2 n + 1 rows) is the bisection's queue.
    """
    order[0] = n - 1
    count, head, tail = 1, 0, 1
    intervals[0, 0], intervals[0, 1] = 0, n
    while head < tail:
        low, high = intervals[head, 0], intervals[head, 1]
        head += 1
        if high - low < 2:
            continue
        middle = (low + high) // 2
        order[count] = middle - 1
        count += 1
        intervals[tail, 0], intervals[tail, 1] = low, middle
        intervals[tail + 1, 0], intervals[tail + 1, 1] = middle, high
        tail += 2


def visiting_order(n: int) -> np.ndarray:
    """:func:`coarse_to_fine`'s order of the states ``j / n``, ``j = 1 .. n``, as an ``(n,)`` array
    of indices ``j - 1``: the end state first, then breadth-first bisection."""
    order = np.empty(n, dtype=np.int64)
    coarse_to_fine(n, order, np.empty((2 * n + 1, 2), dtype=np.int64))
    return order


@njit(cache=True)
def robot_discrete_motion_free(view: RobotDiscreteMotions, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """:meth:`MotionValidator.checkMotion` of ``a -> b``: ``b`` on the single-state path (it decides
    most colliding edges), then the states between in one batch, FCL in coarse-to-fine order
    until the first collision. Counts one motion and the states of the batch."""
    view.counts[Count.MOTIONS] += 1
    if not robot_state_free(view.states, b):
        return False
    for j in range(a.shape[0]):
        if not np.isfinite(a[j]):
            return False
    n = segment_count(view.layout, a, b)
    if n < 2:
        return True
    rows = n - 1
    q, poses, obstacle_hits, self_hits = view.q, view.poses, view.obstacle_hits, view.self_hits
    order, intervals = view.order, view.intervals
    if rows > q.shape[0]:  # an edge longer than the scratch was sized for
        q = np.empty((rows, a.shape[0]))
        poses = np.empty((rows, view.poses.shape[1], 4, 4))
        obstacle_hits = np.empty((rows, view.obstacle_hits.shape[1], view.obstacle_hits.shape[2]), dtype=np.bool_)
        self_hits = np.empty((rows, view.self_hits.shape[1]), dtype=np.bool_)
        order = np.empty(n + 1, dtype=np.int64)
        intervals = np.empty((2 * n + 2, 2), dtype=np.int64)
    coarse_to_fine(n, order, intervals)
    for k in range(rows):  # order[0] is b itself
        t = (order[k + 1] + 1) / n
        for j in range(a.shape[0]):
            q[k, j] = a[j] + t * (b[j] - a[j])
    view.counts[Count.STATES] += rows
    maybe = screen(q[:rows], view.states.chain, view.states.volumes, poses, obstacle_hits, self_hits)
    for k in range(rows):
        if maybe[k]:
            _stage_screened(view.states, poses, obstacle_hits, self_hits, k)
            if not decide_screened(view.states):
                return False
    return True


@njit(cache=True)
def _stage_screened(
    view: RobotStates, poses: np.ndarray, obstacle_hits: np.ndarray, self_hits: np.ndarray, k: int
) -> None:  # pragma: no cover (compiled)
    """Row ``k`` of a batch's screening arrays into the view's one-row arrays, which the checker's
    exit reads (element by element: see :func:`~ompl_balance.core.array_kernels.copy_into`)."""
    for body in range(poses.shape[1]):
        for i in range(4):
            for j in range(4):
                view.poses[0, body, i, j] = poses[k, body, i, j]
    for o in range(obstacle_hits.shape[1]):
        for g in range(obstacle_hits.shape[2]):
            view.obstacle_hits[0, o, g] = obstacle_hits[k, o, g]
    copy_into(self_hits[k], view.self_hits[0])


class SegmentExits(NamedTuple):
    """A certifier's exit to FCL for the hard segments of an edge, and what it stages there.

    ``address`` and ``handle``: the exit to the certifier (:class:`Exit`); ``ends`` (2, dof): the
    edge's ends; ``pairs`` (rows,) and ``spans`` (rows, 4): hard segments, ``(pair, (t0, t1, d0,
    d1))`` (more than ``rows`` go in parts: :func:`segments_exit`); ``numbers`` (:class:`Staged`)
    int64: the query's numbers.
    """

    address: int
    handle: int
    ends: np.ndarray
    pairs: np.ndarray
    spans: np.ndarray
    numbers: np.ndarray


class Staged(enum.IntEnum):
    """The entries of :attr:`SegmentExits.numbers`."""

    START_ROW = 0  # the end memory's rows of the edge's ends
    END_ROW = 1
    WORK_LEFT = 2  # the work units the query may spend
    SEGMENTS = 3  # the segments of the query, in all its parts
    WORK_SPENT = 4  # the work units it spent (its answer)


def segment_exits(certifier: Any, dof: int, rows: int) -> SegmentExits:
    """The :class:`SegmentExits` of ``certifier`` (the exit's target) for a robot of ``dof`` joints,
    staging up to ``rows`` (>= 1) segments at a time."""
    if rows < 1:
        raise ValueError(f"a segment exit stages at least 1 segment at a time, got {rows}")
    return SegmentExits(
        EXIT_ADDRESS,
        exit_handle(certifier),
        np.zeros((2, dof)),
        np.zeros(rows, dtype=np.int64),
        np.zeros((rows, 4)),
        np.zeros(len(Staged), dtype=np.int64),
    )


class CertifiedMotions(NamedTuple):
    """Certified motions as compiled code sees them: the checker's ``states`` view, the
    certifier's ``edge`` model, end ``memory`` and ``scratch`` (:mod:`~ompl_balance.collision.advancement`),
    the edges it certified lately (:mod:`~ompl_balance.collision.certified_lines`),
    its ``exits`` to FCL on the hard segments and the work ``counts``."""

    states: RobotStates
    edge: EdgeModel
    memory: EndMemory
    lines: CertifiedLines
    scratch: EdgeScratch
    exits: SegmentExits
    counts: np.ndarray


#: What the exits to FCL answer: no (not free, no contact), yes (free, a contact), or the
#: motion's work budget ran out first; and a motion's proof (:func:`prove_edge`): no, yes (certified)
#: or over budget.
EXIT_NO, EXIT_YES, EXIT_OVER_BUDGET = 0, 1, 2


@njit(cache=True)
def certified_edge_free(
    edge: EdgeModel,
    memory: EndMemory,
    lines: CertifiedLines,
    scratch: EdgeScratch,
    counts: np.ndarray,
    exits: SegmentExits,
    a: np.ndarray,
    b: np.ndarray,
) -> bool:  # pragma: no cover (compiled)
    """:meth:`MotionCertifier.check` of ``a -> b`` (no ``last_valid``): the proof
    (:func:`prove_edge`), kept in ``lines`` when it certifies the motion; a motion it does not
    certify is still certified when it lies on an edge kept there (a piece of a certified edge,
    :mod:`~ompl_balance.collision.certified_lines`). Counts one motion, and a refusal for the
    budget in ``counts[Count.OVER_BUDGET]``. (The parts of a :class:`CertifiedMotions` view it
    needs, so that Python callers pass no more.)
    """
    counts[Count.MOTIONS] += 1
    proof = prove_edge(edge, memory, scratch, counts, exits, a, b)
    if proof == EXIT_YES:
        remember_certified(lines, a, b)
        return True
    if along_certified(lines, a, b):
        return True
    if proof == EXIT_OVER_BUDGET:
        counts[Count.OVER_BUDGET] += 1
    return False


@njit(cache=True)
def prove_edge(
    edge: EdgeModel,
    memory: EndMemory,
    scratch: EdgeScratch,
    counts: np.ndarray,
    exits: SegmentExits,
    a: np.ndarray,
    b: np.ndarray,
) -> int:  # pragma: no cover (compiled)
    """The proof that ``a -> b`` is free: advancement, stopping at the first failure, then FCL
    on the hard segments through ``exits``; ``EXIT_YES`` (certified), ``EXIT_NO`` (a contact, a
    segment that cannot be certified, or an error in the exit: ``counts[Count.RAISED]`` set) or
    ``EXIT_OVER_BUDGET``. Counts the configurations evaluated and the distance queries in ``counts``.

    Where a non-convex pair's convex parts touch, the advancement stops at the end of that
    bisection level and FCL tests those segments for a contact first (most such edges collide
    there); only if it finds none is the edge certified in full.

    The bound: the work of the whole proof (both advancement passes and the FCL queries of the
    exits, :mod:`ompl_balance.collision.budget`) <= ``edge.budget``; a proof that would need
    more stops with ``EXIT_OVER_BUDGET``.
    """
    start, end = memory_row(memory, a), memory_row(memory, b)
    spent = 0
    # (``stop`` as a plain bool: numba's literal True would compile advance a second time, 12 s,
    # beside the entry point the certifier compiles for Python callers)
    stop = bool(True)  # noqa: UP018 (see above)
    for probe in (True, False):
        failed, bad, hard, evaluated, bounded, hard_pair, hard_span, exhausted = advance(
            a, b, edge, memory.bounds, start, end, edge.floor, stop, probe, scratch, edge.budget - spent
        )
        counts[Count.STATES] += evaluated
        counts[Count.DISTANCE_QUERIES] += bounded
        spent += evaluated + bounded
        if exhausted:
            return EXIT_OVER_BUDGET
        if failed:
            return EXIT_NO
        if bad == 1.0:  # certified but for the hard segments
            break
        counts[Count.EXITS] += 1  # undecided at a touching segment: FCL looks there first
        touching = segments_exit(
            exits, _SEGMENTS_TOUCH, a, b, hard_pair[:hard], hard_span[:hard], 0, 0, edge.budget - spent
        )
        spent += exits.numbers[Staged.WORK_SPENT]
        if touching < 0:
            counts[Count.RAISED] = 1
            return EXIT_NO
        if touching == EXIT_OVER_BUDGET:
            return EXIT_OVER_BUDGET
        if touching != EXIT_NO:
            return EXIT_NO
    if hard == 0:
        return EXIT_YES
    counts[Count.EXITS] += 1
    free = segments_exit(
        exits, _SEGMENTS_FREE, a, b, hard_pair[:hard], hard_span[:hard], start, end, edge.budget - spent
    )
    if free < 0:
        counts[Count.RAISED] = 1
        return EXIT_NO
    return free


@njit(cache=True)
def segments_exit(
    exits: SegmentExits,
    kind: int,
    a: np.ndarray,
    b: np.ndarray,
    pairs: np.ndarray,
    spans: np.ndarray,
    start: int,
    end: int,
    left: int,
) -> int:  # pragma: no cover (compiled)
    """Ask the certifier behind ``exits`` query ``kind`` (:class:`Exit`: ``SEGMENTS_FREE`` or
    ``SEGMENTS_TOUCH``) about the hard segments ``pairs`` (hard,), ``spans`` (hard, 4) of ``a ->
    b``, with the end-memory rows ``start``, ``end`` and ``left`` work units: its answer, -1 when it
    raised. The segments are staged ``len(exits.pairs)`` at a time, the parts before the last
    kept by the certifier (``STAGE_SEGMENTS``); ``exits.numbers[Staged.WORK_SPENT]`` holds the work
    units the query spent."""
    copy_into(a, exits.ends[0])
    copy_into(b, exits.ends[1])
    numbers, total = exits.numbers, pairs.shape[0]
    numbers[Staged.START_ROW], numbers[Staged.END_ROW], numbers[Staged.WORK_LEFT] = start, end, left
    numbers[Staged.SEGMENTS], numbers[Staged.WORK_SPENT] = total, 0
    rows, first = exits.pairs.shape[0], 0
    while True:
        count = min(rows, total - first)
        for i in range(count):
            exits.pairs[i] = pairs[first + i]
            for j in range(4):
                exits.spans[i, j] = spans[first + i, j]
        first += count
        if first == total:
            return call_exit(exits.address, exits.handle, kind, count)
        if call_exit(exits.address, exits.handle, _STAGE_SEGMENTS, count) < 0:
            return -1


@njit(cache=True)
def certified_motion_free(view: CertifiedMotions, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """The certified motion kernel of a :class:`CertifiedMotions` view (:func:`certified_edge_free`)."""
    return certified_edge_free(view.edge, view.memory, view.lines, view.scratch, view.counts, view.exits, a, b)


register_kernels(RobotStates, state=robot_state_free)
register_kernels(RobotDiscreteMotions, state="states", motion=robot_discrete_motion_free)
register_kernels(CertifiedMotions, state="states", motion=certified_motion_free)


def warm_stand_ins() -> tuple[Chain, Volumes, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The arrays of a :class:`RobotStates` view of a one-joint robot without geometry, but its
    exit and counts: arguments of the types every robot passes."""
    from .screening import stand_ins

    chain, volumes = stand_ins()
    q = np.zeros(1)
    return (
        chain,
        volumes,
        q,
        q,
        np.zeros((1, 1)),
        np.zeros((1, 2, 4, 4)),
        np.zeros((1, 0, 0), dtype=np.bool_),
        np.zeros((1, 0), dtype=np.bool_),
    )


def warm_up() -> None:
    """Compile the kernels of the three views, or load them from numba's cache, for the argument
    types every robot passes (a one-joint robot without geometry stands in), as
    :func:`~ompl_balance.collision.screening.warm_up` does for the checker's screening."""
    from ..core.checks import new_counts
    from ..core.layout import Leaf
    from .advancement import MIN_TRAVEL, Model, end_memory
    from .budget import MOTION_BUDGET
    from .convex import pack_parts
    from .screening import stand_ins

    chain, volumes = stand_ins()
    q = np.zeros(1)
    states = RobotStates(*warm_stand_ins(), 0, 0, new_counts())  # (no exit: nothing to decide)
    robot_state_free(states, q)
    one = np.ones(1)
    layout = SpaceLayout(
        np.array([int(Leaf.REAL)]),
        np.zeros(1, dtype=np.int64),
        np.ones(1, dtype=np.int64),
        one,
        one,
        np.ones(1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.ones(1, dtype=np.int64),
        q,
        q,
        1,
        1,
    )
    discrete = RobotDiscreteMotions(
        states,
        layout,
        np.zeros((1, 1)),
        np.zeros((1, 2, 4, 4)),
        np.zeros((1, 0, 0), dtype=np.bool_),
        np.zeros((1, 0), dtype=np.bool_),
        np.zeros(2, dtype=np.int64),
        np.zeros((4, 2), dtype=np.int64),
        states.counts,
    )
    robot_discrete_motion_free(discrete, q, q)
    model = Model(
        parts=pack_parts([]),
        obstacle_centre=np.zeros((0, 3)),
        obstacle_radius=np.zeros(0),
        environment_weight=np.zeros((0, 1)),
        self_weight=np.zeros((0, 1)),
        fixed=np.zeros(0),
        solid=np.zeros(0, dtype=bool),
        joint_lower=q,
        joint_upper=q,
    )
    edge = EdgeModel(chain, volumes, model, 0.0, 0.01, MIN_TRAVEL, MOTION_BUDGET)
    scratch = EdgeScratch(
        np.zeros((0, 3)), np.zeros((4, 3)), np.zeros(0), np.zeros(1, dtype=np.int64), np.zeros((1, 4))
    )
    exits = SegmentExits(
        0, 0, np.zeros((2, 1)), np.zeros(1, dtype=np.int64), np.zeros((1, 4)), np.zeros(len(Staged), dtype=np.int64)
    )
    certified = CertifiedMotions(
        states, edge, end_memory(2, 1, 0), certified_lines(1, 1), scratch, exits, states.counts
    )
    certified_motion_free(certified, q, q)
    # (and the kernel the Python callers reach through the certifier's entry point)
    certified_edge_free(edge, certified.memory, certified.lines, scratch, states.counts, exits, q, q)
