"""The grow/connect loop of the RRT-Connect family, compiled.

:func:`run` is :meth:`ompl_balance.planners.BalancedRRTConnect`'s loop as OMPL's
``RRTConnect::solve`` has it (and the Python engine runs it): each iteration picks the
tree to grow (balancing, then the swap policy), draws a target (the sample policy), grows
the tree one step towards it from the node the nearest policy picks, and walks the other
tree towards the state just added until it is trapped or reaches it. It calls the
checker's kernels through the view it is given (:mod:`ompl_balance.core.checks`), so numba
compiles it once per kind of checker.

It runs iterations for a slice of time (its own monotonic clock, read once an iteration:
:mod:`ompl_balance.engine.clock`) and returns why it stopped (:class:`Stop`), so the Python
side (:mod:`ompl_balance.engine.driver`) polls the termination condition between calls,
feeds goal states, makes room in the trees and ends the solve when the trees
connect. Everything it changes lives in arrays the caller owns (:class:`Loop`), so a call
resumes where the last one stopped. The policies' rules are the functions of
:mod:`ompl_balance.policies`, compiled here, which the Python engine calls as they are: the
tree choice (balancing and swaps), whether a nearest policy ranks every node and which node
it picks, a node's cost and quality, the goal ball; the settings are
:data:`~ompl_balance.engine.settings.LoopSettings`, made from the planner's parameter table.
"""

from __future__ import annotations

import enum
from typing import Any, NamedTuple

import numpy as np
from numba.extending import register_jitable

from .. import policies
from ..core.array_kernels import copy_into
from ..core.checks import EXTENSION_BLOCKED, Count, growth_free, steps_free
from ..core.compiled_spaces import distance, equal, interpolate, row_distance, samples_from_uniforms, segment_count
from ..core.kernel_cache import njit, njit_borrowing
from ..core.layout import SpaceLayout
from ..policies import NearestPolicy, SamplePolicy
from .clock import monotonic_ns
from .events import Grow
from .index import KDIndex, indexed_nearest
from .settings import LoopSettings
from .uniforms import next_double

register_jitable(policies.tree_size_ratio)  # callable from the compiled choose_tree
register_jitable(policies.exhaustion_scale)  # ... and nearest_by_exhaustion
register_jitable(policies.nearest_not_exhausted)  # ... and ranked_node
register_jitable(policies.nearest_by_exhaustion)
choose_tree = njit(cache=True)(policies.choose_tree)
nearest_needs_ranking = njit_borrowing(policies.nearest_needs_ranking)
ranked_node = njit_borrowing(policies.ranked_node)
node_cost = njit(cache=True, inline="always")(policies.node_cost)
in_goal_ball = njit(cache=True, inline="always")(policies.in_goal_ball)
node_quality = njit(cache=True)(policies.node_quality)

NO_NODE = -1
START, GOAL = 0, 1  # tree indices


class Stop(enum.IntEnum):
    """Why :func:`run` returned."""

    SLICE = 0  # its slice of time is over
    NEED_GOAL = 1  # the goal tree wants a goal state (fed by the caller, then GOAL_FED set)
    NEED_ROOM = 2  # a tree or the record has less room than one iteration may need
    CONNECTED = 3  # the trees connected: Slot.START_NODE, Slot.GOAL_NODE
    RAISED = 4  # a check raised (checks.counts[Count.RAISED]): the caller reports the error


class Slot(enum.IntEnum):
    """The loop's integer state (:attr:`Loop.ints`)."""

    GREW_START = 0  # the tree the last iteration grew (1: start), kept across solves
    STEPS = 1  # connect steps since the last swap, kept across solves
    COLLIDED = 2  # the last connect ended trapped, kept across solves
    ITERATIONS = 3
    SWAPS = 4  # SWAPS + cause: swaps by policies.SwapCause (4 of them)
    REJECTIONS = 8  # samples the sample policy discarded
    NEXT_SAMPLE = 9  # next row of the block of uniform samples
    GOAL_FED = 10  # the caller fed the goal this iteration asked for
    SAMPLED_GOALS = 11  # PlannerInputStates::getSampledGoalsCount()
    MORE_GOALS = 12  # PlannerInputStates::haveMoreGoalStates()
    START_NODE = 13  # the connection, when CONNECTED
    GOAL_NODE = 14
    ROOM = 15  # nodes one iteration may add to a tree (for the record's room)
    START_COSTS = 16  # nodes whose neighbour-quality cost is known, per tree
    GOAL_COSTS = 17
    RECORDED = 18  # rows of the record in use
    CHECKS_AHEAD = 19  # 1: the checks take an iteration's extension and connect at once (growth_free)
    START_FITS = 20  # per tree, the size up to which every array of the tree has room for one more iteration
    GOAL_FITS = 21  # (the FITS last: a solve zeroes the slots before them and keeps these)
    COUNT = 22


class Real(enum.IntEnum):
    """The loop's real-valued state (:attr:`Loop.reals`)."""

    TREE_GAP = 0  # least distance between the trees seen after a connect ("approx goal distance")
    START_COST_MAX = 1  # largest neighbour-quality cost per tree
    GOAL_COST_MAX = 2
    COUNT = 3


class Record(enum.IntEnum):
    """Columns of the loop record's integer rows (:attr:`Loop.record`); ``record_target`` holds the targets."""

    ITERATION = 0
    KIND = 1  # 0: the tree choice; 1: an extension step; 2: a connect step
    GREW_START = 2  # choice: the tree grown before / step: the tree grown (1: start)
    STEPS = 3  # choice: steps passed to the rule / step: the node extended
    COLLIDED = 4  # choice: collided passed to the rule / step: the node was given (1) or looked up
    CHOSEN = 5  # choice: the tree chosen (1: start) / step: the outcome (Grow)
    CAUSE = 6  # choice: the swap cause (-1: no swap) / step: the node added (-1: none)
    COUNT = 7


class Tree(NamedTuple):
    """One tree's arrays (capacity rows): states (capacity, dim), parents, roots, failed
    extensions per node, neighbour-quality costs, every node's distance to a query (the ranking
    nearest policies' scratch), and its nearest-neighbour :class:`~ompl_balance.engine.index.KDIndex`."""

    states: np.ndarray
    parents: np.ndarray
    roots: np.ndarray
    failures: np.ndarray
    costs: np.ndarray
    distances: np.ndarray
    neighbours: KDIndex  # the nearest-neighbour index


class Loop(NamedTuple):
    """Everything :func:`run` reads and changes, owned by the caller.

    ``sizes`` (2,): nodes in the start and goal tree. ``ints`` (:class:`Slot`) and ``reals``
    (:class:`Real`): the loop's state. ``block`` (256, dim) uniform samples, refilled from
    ``uniforms`` (256, draws). ``chain`` (steps + 1, dim): the steps a growth checks together
    (:func:`_grow`; two rows: one step at a time). ``extension`` (2, dim): an extension's step
    while it is checked with the connect after it (:data:`Slot.CHECKS_AHEAD`). ``target`` (dim,): scratch. ``record``
    (rows, :class:`Record`) and ``record_target`` (rows, dim): what each iteration did.
    """

    sizes: np.ndarray
    ints: np.ndarray
    reals: np.ndarray
    block: np.ndarray
    uniforms: np.ndarray
    chain: np.ndarray
    extension: np.ndarray
    target: np.ndarray
    record: np.ndarray
    record_target: np.ndarray


_EUCLIDEAN, _EXHAUSTION = int(NearestPolicy.EUCLIDEAN), int(NearestPolicy.EXHAUSTION)
_UNIFORM, _GOAL_BIAS, _GOAL_BALL = int(SamplePolicy.UNIFORM), int(SamplePolicy.GOAL_BIAS), int(SamplePolicy.GOAL_BALL)
_SAMPLE_ATTEMPTS = policies.SAMPLE_ATTEMPTS
_TRAPPED, _ADVANCED, _REACHED = int(Grow.TRAPPED), int(Grow.ADVANCED), int(Grow.REACHED)
_CHOICE, _EXTENSION, _CONNECT_STEP = 0, 1, 2  # kinds of row in the loop record
UNCHECKED = -2  # steps laid out whose checks are still to be made (see _grow's ``checked``)


@njit_borrowing
def _uniform(layout: SpaceLayout, loop: Loop, bits: int) -> int:  # pragma: no cover (compiled)
    """The row of ``loop.block`` holding the next uniform sample (the block refilled as the Python
    engine refills its own from the same generator: ``bits`` is its address,
    :mod:`ompl_balance.engine.uniforms`)."""
    if loop.ints[Slot.NEXT_SAMPLE] == loop.block.shape[0]:
        for row in range(loop.uniforms.shape[0]):
            for k in range(loop.uniforms.shape[1]):
                loop.uniforms[row, k] = next_double(bits)
        samples_from_uniforms(layout, loop.uniforms, loop.block)
        loop.ints[Slot.NEXT_SAMPLE] = 0
    row = loop.ints[Slot.NEXT_SAMPLE]
    loop.ints[Slot.NEXT_SAMPLE] = row + 1
    return row


@njit_borrowing
def _find_nearest(
    settings: LoopSettings, layout: SpaceLayout, tree: Tree, size: int, target: np.ndarray
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """The node the nearest policy extends towards ``target``, and its distance (first on ties):
    the nearest, unless the policy ranks every node (as ``NearestChoice.node`` does)."""
    policy = settings.nearest_policy
    if policy != _EXHAUSTION:
        node, best = indexed_nearest(tree.neighbours, layout, tree.states, size, target)
        if not nearest_needs_ranking(policy, tree.failures[node], settings.exhausted_after):
            return node, best
    distances = tree.distances[:size]
    for i in range(size):
        distances[i] = row_distance(layout, tree.states, i, target)
    node = ranked_node(policy, distances, tree.failures[:size], settings.exhausted_after, settings.exhaustion_target)
    return node, distances[node]


@njit_borrowing
def _add(tree: Tree, size: int, state: np.ndarray, parent: int) -> None:  # pragma: no cover (compiled)
    copy_into(state, tree.states[size])
    tree.parents[size] = parent
    tree.roots[size] = size if parent == NO_NODE else tree.roots[parent]
    tree.failures[size] = 0


@njit_borrowing
def _note(loop: Loop, iteration: int, kind: int, a: int, b: int, c: int, d: int, e: int) -> int:  # pragma: no cover
    """Append a row to the loop record (columns of :class:`Record`); returns its index."""
    row = loop.ints[Slot.RECORDED]
    loop.record[row, Record.ITERATION], loop.record[row, Record.KIND] = iteration, kind
    loop.record[row, Record.GREW_START], loop.record[row, Record.STEPS] = a, b
    loop.record[row, Record.COLLIDED], loop.record[row, Record.CHOSEN], loop.record[row, Record.CAUSE] = c, d, e
    loop.ints[Slot.RECORDED] = row + 1
    return row


@njit_borrowing
def _node_towards(
    settings: LoopSettings,
    layout: SpaceLayout,
    trees: tuple[Tree, Tree],
    loop: Loop,
    t: int,
    target: np.ndarray,
    given: int,
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """The node of tree ``t`` to extend towards ``target``: ``given``, or the nearest policy's
    (``given`` is ``NO_NODE``); and its distance to ``target``."""
    if given == NO_NODE:
        return _find_nearest(settings, layout, trees[t], loop.sizes[t], target)
    return given, distance(layout, trees[t].states[given], target)


@njit_borrowing
def _add_step(
    layout: SpaceLayout,
    settings: LoopSettings,
    tree: Tree,
    loop: Loop,
    t: int,
    near: np.ndarray,
    new: np.ndarray,
    node: int,
) -> int:  # pragma: no cover (compiled)
    """Add to tree ``t`` the step from its node ``node`` (at ``near``) to ``new``: the node at ``new``
    (with ``intermediate_states``, first the states along the motion, ordered away from the
    tree's root); returns the node added last."""
    added = node
    if settings.intermediate_states:
        count = segment_count(layout, near, new)
        for step in range(1, count):
            interpolate(layout, near, new, step / count, loop.target)
            _add(tree, loop.sizes[t], loop.target, added)
            added = loop.sizes[t]
            loop.sizes[t] += 1
    _add(tree, loop.sizes[t], new, added)
    added = loop.sizes[t]
    loop.sizes[t] += 1
    return added


@njit_borrowing
def _step_taken(
    settings: LoopSettings,
    loop: Loop,
    connect: bool,
    t: int,
    node: int,
    given: bool,
    outcome: int,
    added: int,
    target: np.ndarray,
) -> None:  # pragma: no cover (compiled)
    """Count a connect's step (the swap limiter's steps) and, when recording, note the step."""
    if connect:
        loop.ints[Slot.STEPS] += 1
    if settings.record:
        kind = _CONNECT_STEP if connect else _EXTENSION
        row = _note(loop, loop.ints[Slot.ITERATIONS], kind, 1 - t, node, int(given), outcome, added)
        copy_into(target, loop.record_target[row])


@njit_borrowing
def _lay_out(
    layout: SpaceLayout,
    settings: LoopSettings,
    chain: np.ndarray,
    start: np.ndarray,
    target: np.ndarray,
    gap: float,
    connect: bool,
) -> tuple[int, bool, bool, float]:  # pragma: no cover (compiled)
    """Lay out in ``chain`` the steps from ``start`` (``gap`` from ``target``) towards ``target``:
    ``chain[0]`` the start, ``chain[k]`` where step ``k`` ends; one step, or with ``connect`` as many
    as the chain holds. Returns the steps, whether the last one reaches ``target``, whether the
    next one stalls (it rounds back onto its start: trapped, unchecked) and the gap left."""
    copy_into(start, chain[0])
    steps, reached, stalled = 0, False, False
    while steps + 1 < chain.shape[0] and not reached and (connect or steps == 0):
        if gap <= settings.range:
            copy_into(target, chain[steps + 1])
            reached = True
        else:
            interpolate(layout, chain[steps], target, settings.range / gap, chain[steps + 1])
            if settings.step_may_stall and equal(layout, chain[steps], chain[steps + 1]):
                stalled = True
                break
            gap = distance(layout, chain[steps + 1], target)
        steps += 1
    return steps, reached, stalled, gap


@njit(cache=True, inline="always")
def _grow(
    checks: Any,
    layout: SpaceLayout,
    settings: LoopSettings,
    trees: tuple[Tree, Tree],
    loop: Loop,
    t: int,
    target: np.ndarray,
    node: int,
    gap: float,
    given: bool,
    connect: bool,
    checked: int,
) -> tuple[int, int]:  # pragma: no cover (compiled)
    """Grow tree ``t`` from ``node`` (``gap`` from ``target``; ``given``: the sample policy chose the
    node) towards ``target``: one step of at most ``range`` (the extension), or with ``connect``
    steps until one is trapped or reaches ``target``.

    Returns the outcome of the last step (:class:`~ompl_balance.engine.events.Grow`) and the
    node it added. As the Python engine's ``Extender``: motions in the start tree run outwards,
    in the goal tree from the new state in (the new state checked first); a step in collision
    counts as a failed extension of its node for the nearest policies that count failures. The
    steps ahead are laid out in ``loop.chain`` and checked together
    (:func:`~ompl_balance.core.checks.steps_free`: one exit to Python for a checker written in
    Python, where one step at a time makes one or two per step), as many as the chain holds at a
    time; the states tested, the nodes added and the record are those of one step at a time.
    ``checked``: how many of the first steps laid out are free when they were checked already
    (:func:`_growth_checked`), else :data:`UNCHECKED`.
    """
    tree, chain = trees[t], loop.chain
    while True:
        steps, reached, stalled, gap = _lay_out(layout, settings, chain, tree.states[node], target, gap, connect)
        if checked != UNCHECKED:
            free, checked = checked, UNCHECKED
        else:
            free = steps_free(checks, chain, steps, t == START) if steps > 0 else 0
        for k in range(1, free + 1):
            added = _add_step(layout, settings, tree, loop, t, chain[k - 1], chain[k], node)
            outcome = _REACHED if reached and k == steps else _ADVANCED
            _step_taken(settings, loop, connect, t, node, given, outcome, added, target)
            node, given = added, True  # (a connect's next step extends the node just added)
        if checks.counts[Count.RAISED] != 0:
            return _TRAPPED, NO_NODE
        if free < steps or stalled:
            if free < steps and settings.nearest_policy != _EUCLIDEAN:  # (the policies that rank count failures)
                tree.failures[node] += 1
            _step_taken(settings, loop, connect, t, node, given, _TRAPPED, NO_NODE, target)
            return _TRAPPED, NO_NODE
        if reached:
            return _REACHED, node
        if not connect:
            return _ADVANCED, node
        # a connect longer than the chain: on from the node added last


@njit(cache=True, inline="always")
def _growth_checked(
    checks: Any,
    layout: SpaceLayout,
    settings: LoopSettings,
    trees: tuple[Tree, Tree],
    loop: Loop,
    t: int,
    target: np.ndarray,
    node: int,
    gap: float,
) -> tuple[int, int, float, int]:  # pragma: no cover (compiled)
    """The iteration's extension of tree ``t`` (from ``node``, ``gap`` from ``target``) and the other
    tree's connect towards its new state, checked in one call
    (:func:`~ompl_balance.core.checks.growth_free`) before either grows: the connect starts from
    the other tree's node nearest that state whether or not the extension is free, so its steps
    are known in advance, and a checker whose calls are costly (a vectorized function) is asked
    once an iteration (:data:`Slot.CHECKS_AHEAD`).

    Returns the extension's free steps (1 or 0), the connect's node and gap, and its first
    chain's free steps, for :func:`_grow` (``checked``); :data:`UNCHECKED` throughout when the
    extension stalls (``_grow`` finds it trapped without a check)."""
    extension = loop.extension
    steps, _reached, stalled, _gap = _lay_out(layout, settings, extension, trees[t].states[node], target, gap, False)
    if stalled:
        return UNCHECKED, NO_NODE, 0.0, UNCHECKED
    o = 1 - t
    near, near_gap = _node_towards(settings, layout, trees, loop, o, extension[1], NO_NODE)
    connect_steps, _reached, _stalled, _gap = _lay_out(
        layout, settings, loop.chain, trees[o].states[near], extension[1], near_gap, True
    )
    free = growth_free(checks, extension, t == START, loop.chain, connect_steps, o == START)
    if free == EXTENSION_BLOCKED:
        return 0, near, near_gap, UNCHECKED
    return steps, near, near_gap, free


@njit_borrowing
def _update_costs(layout: SpaceLayout, trees: tuple[Tree, Tree], loop: Loop, t: int) -> None:  # pragma: no cover
    """Neighbour-quality costs (:func:`~ompl_balance.policies.node_cost`) of tree ``t``'s new nodes."""
    start, goal = trees[START].states[0], trees[GOAL].states[0]
    tree = trees[t]
    largest = loop.reals[Real.START_COST_MAX + t]
    for node in range(loop.ints[Slot.START_COSTS + t], loop.sizes[t]):
        point = tree.states[node]
        cost = node_cost(distance(layout, start, point), distance(layout, point, goal))
        tree.costs[node] = cost
        largest = max(largest, cost)
    loop.reals[Real.START_COST_MAX + t] = largest
    loop.ints[Slot.START_COSTS + t] = loop.sizes[t]


#: :func:`_target`'s row for the other tree's root (a goal-biased target), not a row of the block.
OTHER_ROOT = -1


@njit_borrowing
def _target(
    layout: SpaceLayout, settings: LoopSettings, trees: tuple[Tree, Tree], loop: Loop, bits: int, t: int
) -> tuple[int, int, bool]:  # pragma: no cover (compiled)
    """The iteration's target: its row of ``loop.block`` (:data:`OTHER_ROOT`: the other tree's
    root), the node to extend when the policy found it (``NO_NODE``: look it up), and ``False``
    when the policy gave up. (A row, not the array: a kernel that returns an array needs numba's
    reference counts, see :func:`~ompl_balance.core.kernel_cache.njit_borrowing`.)"""
    policy = settings.sample_policy
    if policy == _UNIFORM:
        return _uniform(layout, loop, bits), NO_NODE, True
    other = trees[1 - t]
    if policy == _GOAL_BIAS:
        if next_double(bits) < settings.goal_bias:
            return OTHER_ROOT, NO_NODE, True
        return _uniform(layout, loop, bits), NO_NODE, True
    # goal_ball and neighbour_quality: uniform targets at uniform_rate keep them complete
    if settings.uniform_rate > 0.0 and next_double(bits) < settings.uniform_rate:
        return _uniform(layout, loop, bits), NO_NODE, True
    start, goal = trees[START].states[0], trees[GOAL].states[0]
    if policy == _GOAL_BALL:
        centre = other.states[0]
        radius = distance(layout, start, goal)
        for _ in range(_SAMPLE_ATTEMPTS):
            row = _uniform(layout, loop, bits)
            if in_goal_ball(distance(layout, loop.block[row], centre), radius):
                return row, NO_NODE, True
            loop.ints[Slot.REJECTIONS] += 1
        return 0, NO_NODE, False
    _update_costs(layout, trees, loop, t)
    tree = trees[t]
    optimal = distance(layout, start, goal)
    for _ in range(_SAMPLE_ATTEMPTS):
        row = _uniform(layout, loop, bits)
        node, _gap = _find_nearest(settings, layout, tree, loop.sizes[t], loop.block[row])
        quality = node_quality(tree.costs[node], optimal, loop.reals[Real.START_COST_MAX + t], settings.min_quality)
        if next_double(bits) < quality:
            return row, node, True
        loop.ints[Slot.REJECTIONS] += 1
    return 0, NO_NODE, False


@njit_borrowing
def run(
    checks: Any,
    layout: SpaceLayout,
    settings: LoopSettings,
    trees: tuple[Tree, Tree],
    loop: Loop,
    bits: int,
    slice_ns: int,
) -> int:  # pragma: no cover (compiled)
    """Run iterations of the loop for ``slice_ns`` nanoseconds (the iteration under way when they
    are over finishes; ``slice_ns <= 0``: none); returns why it stopped (:class:`Stop`). Random
    numbers come from the numpy generator whose bit generator is at address ``bits``
    (:func:`~ompl_balance.engine.uniforms.bit_generator_address`).

    Compiled without numba's reference counts, as every kernel it calls once an iteration or
    more often (:func:`~ompl_balance.core.kernel_cache.njit_borrowing`): it only borrows the
    caller's arrays, and counting each of the dozens a view, the trees and the loop hold, at
    each call and field read, took most of a 2-D solve's time."""
    ints, sizes = loop.ints, loop.sizes
    room = ints[Slot.ROOM]
    deadline = monotonic_ns() + slice_ns
    while monotonic_ns() < deadline:
        if ints[Slot.GOAL_FED] == 0:
            if sizes[START] > ints[Slot.START_FITS] or sizes[GOAL] > ints[Slot.GOAL_FITS]:
                return Stop.NEED_ROOM
            if settings.record and loop.record.shape[0] - ints[Slot.RECORDED] < room + 2:
                return Stop.NEED_ROOM
            # goal states join the goal tree while fewer than half of its states were sampled
            if sizes[GOAL] == 0 or (ints[Slot.MORE_GOALS] != 0 and ints[Slot.SAMPLED_GOALS] < sizes[GOAL] // 2):
                return Stop.NEED_GOAL
        ints[Slot.GOAL_FED] = 0
        ints[Slot.ITERATIONS] += 1
        iteration = ints[Slot.ITERATIONS]

        grew_start = ints[Slot.GREW_START] != 0
        steps, collided = ints[Slot.STEPS], ints[Slot.COLLIDED] != 0
        grow_start, swap_cause = choose_tree(
            settings.swap_policy,
            settings.balance_tree_sizes,
            settings.max_tree_size_ratio,
            settings.swap_steps,
            grew_start,
            sizes[START],
            sizes[GOAL],
            steps,
            collided,
        )
        cause = swap_cause.value
        swapped = grow_start != grew_start
        if swapped:
            ints[Slot.STEPS], ints[Slot.COLLIDED] = 0, 0
            if iteration > 1:
                ints[Slot.SWAPS + cause] += 1
        if settings.record:
            _note(
                loop,
                iteration,
                _CHOICE,
                int(grew_start),
                steps,
                int(collided),
                int(grow_start),
                cause if swapped else -1,
            )
        ints[Slot.GREW_START] = 1 if grow_start else 0
        t = START if grow_start else GOAL
        o = 1 - t

        row, given, found = _target(layout, settings, trees, loop, bits, t)
        if not found:
            continue
        target = trees[o].states[0] if row == OTHER_ROOT else loop.block[row]
        node, gap = _node_towards(settings, layout, trees, loop, t, target, given)
        checked, near, near_gap, connect_checked = UNCHECKED, NO_NODE, 0.0, UNCHECKED
        if ints[Slot.CHECKS_AHEAD] != 0:
            checked, near, near_gap, connect_checked = _growth_checked(
                checks, layout, settings, trees, loop, t, target, node, gap
            )
        grown, added = _grow(
            checks, layout, settings, trees, loop, t, target, node, gap, given != NO_NODE, False, checked
        )
        if checks.counts[Count.RAISED] != 0:
            return Stop.RAISED
        if grown == _TRAPPED:
            continue
        # connect: walk the other tree towards the state just added until trapped or there;
        # each further step extends the node just added (see policies.NearestChoice)
        reach = trees[t].states[added]  # stays put: only the other tree grows while connecting
        if near == NO_NODE:  # (not found with the checks ahead)
            near, near_gap = _node_towards(settings, layout, trees, loop, o, reach, NO_NODE)
        connected, reached = _grow(
            checks, layout, settings, trees, loop, o, reach, near, near_gap, False, True, connect_checked
        )
        if checks.counts[Count.RAISED] != 0:
            return Stop.RAISED
        # OMPL's "approx goal distance": the other tree's nearest node to the state just added
        gap = near_gap
        if connected == _REACHED:
            gap = 0.0
        elif settings.nearest_policy != _EUCLIDEAN:
            gap = indexed_nearest(trees[o].neighbours, layout, trees[o].states, sizes[o], reach)[1]
        loop.reals[Real.TREE_GAP] = min(loop.reals[Real.TREE_GAP], gap)
        collided = connected == _TRAPPED
        ints[Slot.COLLIDED] = 1 if collided else 0
        if collided:
            continue
        ints[Slot.START_NODE], ints[Slot.GOAL_NODE] = (added, reached) if grow_start else (reached, added)
        return Stop.CONNECTED
    return Stop.SLICE
