"""The Python side of the compiled engine: one solve, in slices between which Python acts.

:func:`run` prepares the arrays :func:`ompl_balance.engine.loop.run` works in (the
planner's own trees, grown in place), then calls it in slices of about two milliseconds
(the loop reads its own clock): between slices it polls the termination condition and acts
on a Ctrl-C (``KeyboardInterrupt``, where the process has Python's handler), and it acts on
why the slice stopped: a goal state to feed (OMPL's ``PlannerInputStates``), room to make in
the trees, a connection for the goal to accept. At the end the planner's trees, swap state,
counts and loop record hold what the compiled loop did, as if the Python engine had run.
"""

from __future__ import annotations

import _signal  # (the C module behind signal; see interrupts_between_slices)
import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
from ompl import base as ob

from ..core.checks import Count
from ..core.compiled_calls import entry_point
from ..core.layout import SpaceLayout
from ..core.spaces import SAMPLE_BLOCK, ArrayPoints, Points
from ..core.trees import ArrayTree
from ..policies import SwapCause
from . import loop
from .events import Grow, GrowStep, TreeChoiceEvent
from .index import INDEX_FROM, KDIndex, Setting, grown, new_index, truncate
from .loop import Real, Record, Slot, Stop
from .settings import RRTConnectSettings, loop_settings
from .solve import Solve
from .uniforms import bit_generator_address
from .views import EngineChecks

#: A slice of iterations lasts this long (ns, and the iteration under way at its end): the
#: termination condition's polling period (a slice costs some 20 microseconds of Python around it).
SLICE_NS = 2_000_000


class SolveArrays:
    """The arrays the compiled loop works in, made once for a planner's layout and reused by its
    solves (a short solve would spend more time allocating them than planning).

    :meth:`start` readies them for a solve: the loop's state zeroed and room made in the
    planner's trees. A tree's nearest-neighbour index and cost array stay with it while the
    planner keeps the tree (its nodes never change; later solves only add to it), and the
    loop's settings while the planner's are unchanged (:meth:`settings_for`).
    """

    def __init__(self, layout: SpaceLayout) -> None:
        self.layout = layout
        dim = layout.dim
        self.loop = loop.Loop(
            sizes=np.zeros(2, dtype=np.int64),
            ints=np.zeros(Slot.COUNT, dtype=np.int64),
            reals=np.zeros(Real.COUNT),
            block=np.empty((SAMPLE_BLOCK, dim)),
            uniforms=np.empty((SAMPLE_BLOCK, layout.total_draws)),
            chain=np.empty((2, dim)),
            extension=np.empty((2, dim)),
            target=np.empty(dim),
            record=np.empty((0, Record.COUNT), dtype=np.int64),
            record_target=np.empty((0, dim)),
        )
        self._planner_trees: tuple[ArrayTree, ...] = ()  # the trees the indexes and costs are for
        self.indexes: list[KDIndex] = []
        self.costs: list[np.ndarray] = []
        self.distances: list[np.ndarray] = []  # the ranking nearest policies' scratch, per tree
        self.failures: list[Any] = []
        self.room = 0
        self._fitted = False  # whether the loop's sizes with room (Slot.START_FITS, GOAL_FITS) are the arrays' own
        self._fits = [0, 0]  # those sizes (start tree, goal tree), as the loop's ints hold them
        self._settings: tuple[tuple[Any, ...], Any] | None = None  # the last solve's LoopSettings, and their source

    def settings_for(self, points: Points, settings: RRTConnectSettings, record: bool) -> Any:
        """The compiled loop's :data:`~ompl_balance.engine.settings.LoopSettings` for solves of a planner
        with ``settings`` on ``points``, recording or not: the last ones made when all three are
        unchanged (planners ask at setup, so that a solve finds them made)."""
        source = (points, record, *vars(settings).values())
        if self._settings is None or self._settings[0] != source:
            self._settings = (source, loop_settings(settings, points.may_stall(settings.range), record))
        return self._settings[1]

    def hold(self, start_tree: ArrayTree, goal_tree: ArrayTree, failures: tuple[Any, Any], room: int) -> None:
        """Keep arrays for the planner's trees ``start_tree``, ``goal_tree`` (with their
        :class:`~ompl_balance.policies.NodeFailures` ``failures``) with room for an iteration that
        adds ``room`` nodes: their index and cost arrays (new ones, sized for the trees'
        capacity, unless these are the trees held already, their indexes then cut back to the
        trees' sizes) and the loop's view of them (:attr:`trees`)."""
        held = self._planner_trees
        if len(held) == 2 and held[0] is start_tree and held[1] is goal_tree:
            for index, tree in zip(self.indexes, held):
                truncate(index, len(tree))  # (a tree the planner's clear() emptied)
        else:
            self._planner_trees = (start_tree, goal_tree)
            capacities = [len(tree.storage().parents) for tree in self._planner_trees]
            self.indexes = [new_index(self.layout, 0) for _ in capacities]  # (grown once a tree needs it)
            self.costs = [np.empty(capacity) for capacity in capacities]
            self.distances = [np.empty(capacity) for capacity in capacities]
            self.failures = list(failures)  # (made with the trees: new trees, new failures)
            self._fitted = False
        if room != self.room:
            self.room, self._fitted = room, False
        self.make_room()

    def start(self, solve: Solve, room: int, record: bool, steps_together: bool, per_iteration: bool) -> None:
        """Ready the arrays for ``solve`` (``room``: the nodes an iteration may add; ``record``:
        whether the loop records what it does; ``steps_together``: whether its checks take a
        connect's steps together, which the chain then has rows for: at most ``room``;
        ``per_iteration``: whether they take an iteration's extension and connect together,
        :data:`~ompl_balance.engine.loop.Slot.CHECKS_AHEAD`).

        The loop's state starts at zero, but for the sizes the trees' arrays have room for
        (:meth:`make_room`): they stay true while the planner keeps its trees (their arrays
        move only as they outgrow them), and the planner fits them at setup."""
        start_tree, goal_tree = solve.start_tree, solve.goal_tree
        assert isinstance(start_tree, ArrayTree) and isinstance(goal_tree, ArrayTree)
        self.loop.ints[: Slot.START_FITS] = 0  # (the sizes with room, the last slots, stay)
        self.loop.ints[Slot.CHECKS_AHEAD] = per_iteration
        self.loop.reals[:] = 0.0
        rows = 4 * room + 64 if record else 0
        if len(self.loop.record) < rows or (rows == 0 and len(self.loop.record)):
            self.loop = self.loop._replace(
                record=np.empty((rows, Record.COUNT), dtype=np.int64), record_target=np.empty((rows, self.layout.dim))
            )
        chain_rows = room + 1 if steps_together else 2
        if len(self.loop.chain) != chain_rows:
            self.loop = self.loop._replace(chain=np.empty((chain_rows, self.layout.dim)))
        self.hold(start_tree, goal_tree, (solve.failures[start_tree], solve.failures[goal_tree]), room)

    def make_room(self) -> None:
        """Room for one more iteration in both trees (and the record); :attr:`trees`: the trees'
        arrays as the loop takes them.

        Within a solve only the loop and the goal states fed add nodes, and neither moves an
        array that has room, so the arrays are looked at again only when a tree outgrows them.
        """
        start, goal = self._planner_trees
        start_size, goal_size = len(start), len(goal)
        sizes = self.loop.sizes
        sizes[0], sizes[1] = start_size, goal_size
        if len(self.loop.record):
            self._make_record_room()
        fits = self._fits
        if self._fitted and start_size <= fits[0] and goal_size <= fits[1]:
            return
        self._make_tree_room()
        self._fits = [_nodes_with_room(tree) - self.room for tree in self.trees]
        self.loop.ints[Slot.START_FITS : Slot.GOAL_FITS + 1] = self._fits
        self._fitted = True

    def _make_tree_room(self) -> None:
        """Room in the trees' arrays for one more iteration (the loop asks for more once a tree
        grows past the sizes :func:`_nodes_with_room` gives, the one statement of the bound)."""
        trees = []
        for t, tree in enumerate(self._planner_trees):
            needed = len(tree) + self.room
            tree.reserve(needed)
            storage = tree.storage()
            capacity = len(storage.parents)
            failures = self.failures[t]
            failures.reserve(capacity)
            if len(self.costs[t]) < capacity:
                self.costs[t] = _grown(self.costs[t], capacity)
                self.distances[t] = np.empty(capacity)
            # the index's arrays once the tree is large enough to be searched through them
            self.indexes[t] = index = grown(self.indexes[t], capacity if needed >= INDEX_FROM else 0)
            trees.append(
                loop.Tree(
                    storage.states,
                    storage.parents,
                    storage.roots,
                    failures.array,
                    self.costs[t],
                    self.distances[t],
                    index,
                )
            )
        self.trees = trees[0], trees[1]

    def _make_record_room(self) -> None:
        """Room in the record (the loop records: it has rows) for one more iteration's rows."""
        record = self.loop.record
        if len(record) - self.loop.ints[Slot.RECORDED] < self.room + 2:
            rows = 2 * len(record) + self.room
            self.loop = self.loop._replace(
                record=_grown(record, rows), record_target=_grown(self.loop.record_target, rows)
            )

    def adopt(self) -> None:
        """The planner's trees take the nodes the loop added."""
        start_size, goal_size = self.loop.sizes.tolist()
        start, goal = self._planner_trees
        start.adopt(start_size)
        goal.adopt(goal_size)


_RUNNERS: dict[Any, Callable[..., int]] = {}


def _runner(key: Any, *arguments: Any) -> Callable[..., int]:
    """:func:`ompl_balance.engine.loop.run` for the types of ``arguments``, called without numba's
    type dispatch (tens of microseconds a call; working the types out takes milliseconds, so it
    is done once per kind of view and layout: ``key``, the view's and layout's
    :func:`~ompl_balance.engine.loading.view_key`)."""
    if key not in _RUNNERS:
        _RUNNERS[key] = entry_point(loop.run, arguments)
    return _RUNNERS[key]


def _nodes_with_room(tree: loop.Tree) -> int:
    """Nodes ``tree``'s arrays have room for (its index's: below :data:`INDEX_FROM` nodes, none needed)."""
    rows = min(len(tree.states), len(tree.parents), len(tree.failures), len(tree.costs), len(tree.distances))
    index = tree.neighbours
    if index.ints[Setting.AXES] and len(index.order) < rows:
        rows = max(len(index.order), INDEX_FROM - 1)
    return rows


def _grown(array: np.ndarray, rows: int) -> np.ndarray:
    grown = np.empty((rows, *array.shape[1:]), dtype=array.dtype)
    grown[: len(array)] = array
    return grown


def _nothing() -> None:
    """No SIGINT to act on (what :func:`interrupts_between_slices` yields where it leaves SIGINT alone)."""


#: :func:`interrupts_between_slices` of a solve whose kernels never call Python (made once: a solve's
#: fixed cost counts).
_HANDLER_KEPT = contextlib.nullcontext(_nothing)


def interrupts_between_slices(exits: bool) -> contextlib.AbstractContextManager[Callable[[], None]]:
    """Ctrl-C during a compiled solve, acted on between slices: yields ``check()``, which calls
    the process's SIGINT handler (Python's raises ``KeyboardInterrupt``) if SIGINT came since
    the last call.

    Python runs a signal's handler wherever its interpreter next runs, which in a compiled
    slice is inside a kernel's exit to Python, where the ``KeyboardInterrupt`` would become the
    error of the check in progress. So while a solve whose kernels may call Python
    (``exits``) runs, SIGINT only sets a flag, where the process handles it in Python (main
    thread only: Python delivers signals there). Without exits the interpreter next runs after
    the slice, where ``KeyboardInterrupt`` is safe, and the handler stays as it was; so it does
    where SIGINT is ignored (a background job) or left to the system (it ends the process).
    """
    if not exits or threading.current_thread() is not threading.main_thread():
        return _HANDLER_KEPT
    return _flag_interrupts()


@contextlib.contextmanager
def _flag_interrupts() -> Iterator[Callable[[], None]]:
    """SIGINT sets a flag while the solve runs (main thread, a solve whose kernels call Python;
    see :func:`interrupts_between_slices`)."""
    # (signal's own functions wrap _signal's, turning each handler into an enum: 7 us a solve)
    handler = _signal.getsignal(signal.SIGINT)
    if not callable(handler):
        yield _nothing
        return
    caught: list[int] = []

    def check() -> None:
        if caught:
            caught.clear()
            handler(signal.SIGINT, None)

    _signal.signal(signal.SIGINT, lambda number, frame: caught.append(number))
    try:
        yield check
    finally:
        _signal.signal(signal.SIGINT, handler)
        check()  # a SIGINT in the last slice


def run(
    solve: Solve,
    ptc: ob.PlannerTerminationCondition,
    checks: EngineChecks,
    key: Any,
    room: int,
    arrays: SolveArrays,
) -> ob.PlannerStatus.PlannerStatusType:
    """The loop of ``solve`` on the compiled engine, as :func:`ompl_balance.engine.python_loop.run`,
    in ``arrays`` (``key``: the :func:`~ompl_balance.engine.loading.view_key` of ``checks.view``
    and the layout; ``room``: the nodes an iteration may add)."""
    settings = arrays.settings_for(solve.points, solve.settings, solve.record is not None)
    arrays.start(solve, room, settings.record, checks.steps_together, checks.per_iteration)
    layout, ints, reals = arrays.layout, arrays.loop.ints, arrays.loop.reals
    state = solve.swap_state
    ints[Slot.GREW_START], ints[Slot.STEPS], ints[Slot.COLLIDED] = state.grew_start, state.steps, state.collided
    # the Python engine's block of samples where it began this solve (else a fresh block at the
    # first sample, as the Python engine's), and its counts
    points = solve.points
    assert isinstance(points, ArrayPoints)
    block, next_sample = points.block()
    if len(block):
        arrays.loop.block[:] = block
    ints[Slot.NEXT_SAMPLE] = next_sample if len(block) else SAMPLE_BLOCK
    ints[Slot.ITERATIONS] = solve.counts.iterations
    ints[Slot.SWAPS : Slot.SWAPS + len(SwapCause)] = solve.counts.swaps
    ints[Slot.ROOM] = room
    reals[Real.TREE_GAP] = solve.tree_gap
    exits_before = int(checks.view.counts[Count.EXITS])
    status = ob.PlannerStatus.TIMEOUT
    bits = bit_generator_address(solve.rng)  # (solve keeps the generator alive)
    run_slice = _runner(key, checks.view, layout, settings, arrays.trees, arrays.loop, bits, SLICE_NS)

    def feed_goal() -> bool:
        """The goal state the next iteration asks for, fed; ``False`` when there is none."""
        if not solve.feed_goal(ptc):
            return False
        arrays.make_room()
        ints[Slot.GOAL_FED] = 1
        return True

    with interrupts_between_slices(checks.exits) as act_on_interrupt:
        try:
            while not ptc():
                # (a slice's first iteration asks here rather than by a stop, a slice the fewer)
                if ints[Slot.GOAL_FED] == 0 and solve.wants_goal() and not feed_goal():
                    status = ob.PlannerStatus.INVALID_GOAL
                    break
                ints[Slot.SAMPLED_GOALS] = solve.inputs.getSampledGoalsCount()
                ints[Slot.MORE_GOALS] = solve.inputs.haveMoreGoalStates()
                stop = run_slice(checks.view, layout, settings, arrays.trees, arrays.loop, bits, SLICE_NS)
                arrays.adopt()
                act_on_interrupt()
                solve.progress.iterations = int(ints[Slot.ITERATIONS])
                if stop == Stop.NEED_ROOM:
                    arrays.make_room()
                elif stop == Stop.NEED_GOAL:
                    if not feed_goal():
                        status = ob.PlannerStatus.INVALID_GOAL
                        break
                elif stop == Stop.CONNECTED and solve.accept(int(ints[Slot.START_NODE]), int(ints[Slot.GOAL_NODE])):
                    status = ob.PlannerStatus.EXACT_SOLUTION
                    break
                elif stop == Stop.RAISED:
                    checks.raise_error()
        finally:
            arrays.adopt()
            _report(solve, arrays.loop, int(checks.view.counts[Count.EXITS]) - exits_before)
    return status


def _report(solve: Solve, arrays: loop.Loop, exits: int) -> None:
    """Hand what the compiled loop did to the planner's side: swap state, counts, gap, record."""
    ints = arrays.ints.tolist()
    state = solve.swap_state
    state.grew_start, state.steps, state.collided = (
        bool(ints[Slot.GREW_START]),
        ints[Slot.STEPS],
        bool(ints[Slot.COLLIDED]),
    )
    counts = solve.counts
    counts.iterations = ints[Slot.ITERATIONS]
    counts.swaps = ints[Slot.SWAPS : Slot.SWAPS + len(SwapCause)]  # (by cause, in SwapCause order)
    counts.exits = exits
    solve.sampler_counts.rejections += ints[Slot.REJECTIONS]
    solve.progress.iterations = counts.iterations
    solve.tree_gap = float(arrays.reals[Real.TREE_GAP])
    if solve.record is not None:
        _fill_record(solve, arrays)


def _fill_record(solve: Solve, arrays: loop.Loop) -> None:
    record = solve.record
    assert record is not None
    rows, targets = arrays.record, arrays.record_target
    for row in range(int(arrays.ints[Slot.RECORDED])):
        iteration, kind, a, b, c, d, e = (int(value) for value in rows[row])
        if kind == 0:
            cause = None if e < 0 else SwapCause(e)
            record.choices.append(TreeChoiceEvent(iteration, bool(a), b, bool(c), bool(d), cause))
        else:
            record.steps.append(GrowStep(iteration, bool(a), kind == 2, targets[row].copy(), b, bool(c), Grow(d), e))


def warm_up_arguments(view: object, layout: SpaceLayout) -> tuple[Any, ...]:
    """Arguments of :func:`ompl_balance.engine.loop.run` of the types a solve with ``view`` passes
    (a call of no iterations: ``slice_ns`` 0)."""
    settings = loop_settings(RRTConnectSettings(range=1.0), step_may_stall=False, record=False)
    tree = loop.Tree(
        np.zeros((1, layout.dim)),
        np.zeros(1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.zeros(1),
        np.zeros(1),
        new_index(layout, 1),
    )
    arrays = SolveArrays(layout).loop
    return view, layout, settings, (tree, tree), arrays, bit_generator_address(_WARM_UP_RNG), 0


_WARM_UP_RNG = np.random.default_rng(0)


def warm_up(view: object, layout: SpaceLayout) -> None:
    """Compile :func:`ompl_balance.engine.loop.run` for ``view``'s kind of checks (or load it from
    numba's cache), and run it once (no iterations)."""
    loop.run(*warm_up_arguments(view, layout))
