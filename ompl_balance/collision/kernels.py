"""The robot checker and its motion validators as compiled kernels: their views for compiled code.

Three views (:mod:`ompl_balance.core.checks`), each a named tuple of arrays:

* :class:`RobotStates`: a :class:`~ompl_balance.collision.checker.CollisionChecker` deciding a
  configuration: the joint limits, then forward kinematics and the bounding-volume screening
  (:func:`~ompl_balance.collision.screening.screen`), and when a pair is not cleared, one exit
  to the checker's FCL test (:meth:`~ompl_balance.collision.checker.CollisionChecker.decide`);
* :class:`RobotDiscreteMotions`: the discrete motion validator
  (:class:`~ompl_balance.validity.MotionValidator`): the end state alone, then the states at
  ``j / n`` of the way (``n`` as OMPL's ``validSegmentCount``) in one batch of screening,
  visited coarse to fine (:func:`coarse_to_fine`), FCL on those the screening leaves;
* :class:`CertifiedMotions`: certified motions (:class:`~ompl_balance.collision.certified.MotionCertifier`):
  conservative advancement in compiled code (:func:`~ompl_balance.collision.advancement.advance`),
  and one exit to FCL for the hard segments of non-convex pairs, within the certifier's work
  budget per motion (:mod:`ompl_balance.collision.budget`).

The Python validators call these same kernels (through fixed-type entry points), so a stock
planner and the compiled engine get the same answers and the same counts. Work is counted
in the checker's :class:`~ompl_balance.collision.checker.WorkCounter` array.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import objmode

from ..core.check_overloads import register_kernels
from ..core.checks import Count, exit_handle, exit_target
from ..core.compiled_spaces import segment_count
from ..core.kernel_cache import njit
from ..core.layout import SpaceLayout
from .advancement import EdgeModel, EdgeScratch, EndMemory, advance, memory_row
from .budget import OverBudgetError, WorkBudget
from .certified_lines import CertifiedLines, along_certified, certified_lines, remember_certified
from .kinematics import LIMIT_TOLERANCE, Chain
from .screening import Volumes, screen


class RobotStates(NamedTuple):
    """A collision checker as compiled code sees it.

    ``chain`` and ``volumes``: the robot and the screening's bounding volumes; ``lower``,
    ``upper`` (dof,): the joint limits; ``q`` (1, dof), ``poses`` (1, bodies, 4, 4),
    ``obstacle_hits`` (1, obstacles, geometries) and ``self_hits`` (1, pairs): the screening's
    scratch for one configuration; ``handle``: the exit to the checker; ``counts``: its work
    counter's array.
    """

    chain: Chain
    volumes: Volumes
    lower: np.ndarray
    upper: np.ndarray
    q: np.ndarray
    poses: np.ndarray
    obstacle_hits: np.ndarray
    self_hits: np.ndarray
    handle: int
    counts: np.ndarray


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
    """The :class:`RobotStates` view of a :class:`~ompl_balance.collision.checker.CollisionChecker`."""
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
        exit_handle(checker),
        checker.counter.array,
    )


def _decide(handle: int, poses: np.ndarray, obstacle_hits: np.ndarray, self_hits: np.ndarray) -> bool:
    return bool(exit_target(handle).decide(poses, obstacle_hits, self_hits))


@njit(cache=True)
def within_limits(view: RobotStates, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Every value of ``q`` within its joint's limits, as :meth:`RobotModel.within_limits` (``False`` for NaN)."""
    for j in range(q.shape[0]):  # noqa: SIM110 (a loop numba compiles)
        if not (view.lower[j] - LIMIT_TOLERANCE <= q[j] <= view.upper[j] + LIMIT_TOLERANCE):
            return False
    return True


@njit(cache=True)
def decide_screened(
    view: RobotStates, poses: np.ndarray, obstacle_hits: np.ndarray, self_hits: np.ndarray
) -> bool:  # pragma: no cover (compiled)
    """FCL on what the screening of one configuration left (one exit to the checker)."""
    view.counts[Count.EXITS] += 1
    with objmode(free="boolean"):
        free = _decide(view.handle, poses, obstacle_hits, self_hits)
    return free


@njit(cache=True)
def robot_state_free(view: RobotStates, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """:meth:`CollisionChecker.is_valid` of ``q`` (dof,): within the limits and free; counts one state."""
    view.counts[Count.STATES] += 1
    if not within_limits(view, q):
        return False
    for j in range(q.shape[0]):
        view.q[0, j] = q[j]
    maybe = screen(view.q, view.chain, view.volumes, view.poses, view.obstacle_hits, view.self_hits)
    return not maybe[0] or decide_screened(view, view.poses[0], view.obstacle_hits[0], view.self_hits[0])


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
        robot_states(checker), layout, q, poses, obstacle_hits, self_hits, order, intervals, checker.counter.array
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
        if maybe[k] and not decide_screened(view.states, poses[k], obstacle_hits[k], self_hits[k]):
            return False
    return True


class CertifiedMotions(NamedTuple):
    """Certified motions as compiled code sees them: the checker's ``states`` view, the
    certifier's ``edge`` model, end ``memory`` and ``scratch`` (:mod:`~ompl_balance.collision.advancement`),
    the edges it certified lately (:mod:`~ompl_balance.collision.certified_lines`),
    the exit ``handle`` to the certifier (FCL on the hard segments) and the work ``counts``."""

    states: RobotStates
    edge: EdgeModel
    memory: EndMemory
    lines: CertifiedLines
    scratch: EdgeScratch
    handle: int
    counts: np.ndarray


#: What the exits to FCL answer: no (not free, no contact), yes (free, a contact), or the
#: motion's work budget ran out first; and a motion's proof (:func:`prove_edge`): no, yes (certified)
#: or over budget.
EXIT_NO, EXIT_YES, EXIT_OVER_BUDGET = 0, 1, 2


def _exact(
    handle: int, a: np.ndarray, b: np.ndarray, pairs: np.ndarray, spans: np.ndarray, start: int, end: int, left: int
) -> int:
    budget = WorkBudget(left)
    free = exit_target(handle).hard_segments_free(a, b, pairs, spans, start, end, budget)
    return EXIT_YES if free else EXIT_OVER_BUDGET if budget.exhausted else EXIT_NO


def _touching(
    handle: int, a: np.ndarray, b: np.ndarray, pairs: np.ndarray, spans: np.ndarray, left: int
) -> tuple[int, int]:
    budget = WorkBudget(left)
    try:
        touching = exit_target(handle).hard_segments_touch(a, b, pairs, spans, budget)
    except OverBudgetError:
        return EXIT_OVER_BUDGET, budget.spent
    return EXIT_YES if touching else EXIT_NO, budget.spent


@njit(cache=True)
def certified_edge_free(
    edge: EdgeModel,
    memory: EndMemory,
    lines: CertifiedLines,
    scratch: EdgeScratch,
    counts: np.ndarray,
    handle: int,
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
    proof = prove_edge(edge, memory, scratch, counts, handle, a, b)
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
    handle: int,
    a: np.ndarray,
    b: np.ndarray,
) -> int:  # pragma: no cover (compiled)
    """The proof that ``a -> b`` is free: advancement, stopping at the first failure, then FCL
    on the hard segments through the exit ``handle``; ``EXIT_YES`` (certified), ``EXIT_NO`` (a
    contact, or a segment that cannot be certified) or ``EXIT_OVER_BUDGET``. Counts the
    configurations evaluated and the distance queries in ``counts``.

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
        touching, used = hard_segments_touch(handle, a, b, hard_pair[:hard], hard_span[:hard], edge.budget - spent)
        spent += used
        if touching == EXIT_OVER_BUDGET:
            return EXIT_OVER_BUDGET
        if touching != EXIT_NO:
            return EXIT_NO
    if hard == 0:
        return EXIT_YES
    counts[Count.EXITS] += 1
    return hard_segments_free(handle, a, b, hard_pair[:hard], hard_span[:hard], start, end, edge.budget - spent)


@njit(cache=True)
def hard_segments_free(
    handle: int, a: np.ndarray, b: np.ndarray, pairs: np.ndarray, spans: np.ndarray, start: int, end: int, left: int
) -> int:  # pragma: no cover (compiled)
    """The exit to the certifier behind ``handle``: FCL on the hard segments of ``a -> b`` with
    ``left`` work units: :data:`EXIT_YES` (certified), :data:`EXIT_NO` or :data:`EXIT_OVER_BUDGET`."""
    with objmode(free="int64"):
        free = _exact(handle, a, b, pairs, spans, start, end, left)
    return free


@njit(cache=True)
def hard_segments_touch(
    handle: int, a: np.ndarray, b: np.ndarray, pairs: np.ndarray, spans: np.ndarray, left: int
) -> tuple[int, int]:  # pragma: no cover (compiled)
    """The exit to the certifier behind ``handle``: whether FCL finds a contact in the hard segments
    of ``a -> b`` with ``left`` work units (:data:`EXIT_YES`, :data:`EXIT_NO` or
    :data:`EXIT_OVER_BUDGET`), and the work units it spent."""
    with objmode(touching="int64", spent="int64"):
        touching, spent = _touching(handle, a, b, pairs, spans, left)
    return touching, spent


@njit(cache=True)
def certified_motion_free(view: CertifiedMotions, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """The certified motion kernel of a :class:`CertifiedMotions` view (:func:`certified_edge_free`)."""
    return certified_edge_free(view.edge, view.memory, view.lines, view.scratch, view.counts, view.handle, a, b)


register_kernels(RobotStates, state=robot_state_free)
register_kernels(RobotDiscreteMotions, state="states", motion=robot_discrete_motion_free)
register_kernels(CertifiedMotions, state="states", motion=certified_motion_free)


def warm_stand_ins() -> tuple[Chain, Volumes, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The arrays of a :class:`RobotStates` view of a one-joint robot without geometry, but its
    exit handle and counts: arguments of the types every robot passes."""
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
    states = RobotStates(*warm_stand_ins(), 0, new_counts())
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
    certified = CertifiedMotions(states, edge, end_memory(2, 1, 0), certified_lines(1, 1), scratch, 0, states.counts)
    certified_motion_free(certified, q, q)
    # (and the kernel the Python callers reach through the certifier's entry point)
    certified_edge_free(edge, certified.memory, certified.lines, scratch, states.counts, 0, q, q)
    warm_exits_once()


class _AllFree:
    """An exit target answering every query "free" (for :func:`warm_exits`)."""

    def decide(self, *arguments: Any) -> bool:
        return True

    def hard_segments_free(self, *arguments: Any) -> bool:
        return True

    def hard_segments_touch(self, *arguments: Any) -> bool:
        return False


_EXITS_WARM = [False]


def warm_exits_once() -> None:
    """:func:`warm_exits`, the first time a process calls this."""
    if not _EXITS_WARM[0]:
        warm_exits()
        _EXITS_WARM[0] = True


def warm_exits() -> None:
    """Run each exit to Python once: numba makes a kernel's ``objmode`` code ready the first
    time it runs in a process (about a tenth of a second), which would otherwise fall on the
    first FCL query of a solve. That readies it for the kernels compiled in the same process as
    these (numba finds the block's code again by the identity it gave it when compiling); a
    kernel compiled by another process, and cached, gets its block ready at its first exit (the
    benchmark runner times such a solve again: :class:`~ompl_balance.bench.execution.NumbaCompiling`)."""
    target = _AllFree()
    handle = exit_handle(target)
    q = np.zeros(1)
    decide_screened(
        RobotStates(*warm_stand_ins(), handle, np.zeros(len(Count), dtype=np.int64)),
        np.zeros((2, 4, 4)),
        np.zeros((0, 0), dtype=np.bool_),
        np.zeros(0, dtype=np.bool_),
    )
    hard_segments_free(handle, q, q, np.zeros(0, dtype=np.int64), np.zeros((0, 4)), 0, 1, 1)
    hard_segments_touch(handle, q, q, np.zeros(0, dtype=np.int64), np.zeros((0, 4)), 1)
