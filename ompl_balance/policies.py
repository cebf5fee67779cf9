"""The RRT-Connect family's policies: which tree grows, from which node, towards what.

RRT-Connect's loop (:mod:`ompl_balance.planners`) asks three questions each iteration;
each answer is a policy, chosen by one parameter and made into a function once per solve,
so a policy that is not selected costs the loop nothing:

``swap_policy`` and ``balance_tree_sizes`` -> :func:`tree_chooser`
    which tree an iteration grows: the balancing rule (grow the smaller tree once the
    trees drift apart in size), else alternation, the swap limiter or the collision swap;
``nearest_policy`` -> :func:`nearest_finder`
    which node the tree grows from: the nearest, the nearest not yet exhausted, or the
    nearest by distance scaled with the node's failures;
``sample_policy`` -> :func:`target_sampler`
    where the iteration's target comes from: uniform, goal bias, the goal ball ("control
    chosen"), neighbour quality, or a valid-state sampler.

These are the variants compared against RRT-Connect in the TU Berlin lab report "RRT
Extensions" (2020); ``docs/variants.md`` measures them.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from ompl import base as ob

from .core.trees import Tree

#: ``swap_policy`` choices: which tree an iteration grows when balancing does not decide.
SWAP_POLICIES = ("alternate", "balance_steps", "on_collision")
#: ``nearest_policy`` choices: which node a tree is extended from.
NEAREST_POLICIES = ("euclidean", "exhausted", "exhaustion")
#: ``sample_policy`` choices: where an iteration's target comes from.
SAMPLE_POLICIES = ("uniform", "goal_bias", "goal_ball", "neighbour_quality", "valid_sampler")

#: Draws a rejecting sample policy makes before the iteration is given up (OMPL's
#: ``magic::MAX_VALID_SAMPLE_ATTEMPTS``).
SAMPLE_ATTEMPTS = 100


class SwapCause(enum.IntEnum):
    """Why an iteration grew the other tree; ``RunStats.swaps_<cause>`` counts each."""

    ALTERNATE = 0  # alternation (stock RRT-Connect)
    BALANCE = 1  # the balancing rule chose the smaller tree
    STEPS = 2  # the swap limit of ``balance_steps`` was reached
    COLLISION = 3  # a connect ended in a collision under ``on_collision``


#: The causes' names, in :class:`SwapCause` order.
SWAP_CAUSES = tuple(cause.name.lower() for cause in SwapCause)


def tree_size_ratio(start_size: int, goal_size: int) -> float:
    """``|a - b| / min(a, b)``: how much larger the larger tree is, relative to the smaller.

    Dividing by the *smaller* size is what makes the rule engage: with ``max(a, b)`` in
    the denominator (the first OMPL pull request) the ratio never reaches 1.
    """
    return abs(start_size - goal_size) / min(start_size, goal_size)


def balance_choice(start_size: int, goal_size: int, balance: bool, max_ratio: float) -> bool | None:
    """Which tree the balancing rule grows: ``True`` start, ``False`` goal, ``None`` no preference.

    The smaller tree is grown when ``balance`` is on and
    ``tree_size_ratio(start_size, goal_size) >= max_ratio``; otherwise (and when the
    trees are equal) the swap policy decides.
    """
    if not balance or start_size == goal_size:
        return None
    if tree_size_ratio(start_size, goal_size) >= max_ratio:
        return start_size < goal_size
    return None


#: ``choose(grew_start, start_size, goal_size, steps, collided) -> (grow_start, cause)``
TreeChooser = Callable[[bool, int, int, int, bool], tuple[bool, SwapCause]]


def tree_chooser(
    swap_policy: str, balance_tree_sizes: bool = False, max_tree_size_ratio: float = 1.0, swap_steps: int = 1
) -> TreeChooser:
    """The tree-choice rule as a function ``choose``.

    ``choose(grew_start, start_size, goal_size, steps, collided)`` is given which tree
    the previous iteration grew (``True``: the start tree), the tree sizes, the
    extension steps taken in connect loops since the last swap, and whether the last
    connect ended in a collision (the last two restart at every swap). It returns
    ``(grow_start, cause)``, ``cause`` saying why the choice is a swap, when it is one.

    With ``balance_tree_sizes``, the smaller tree is grown whenever
    :func:`balance_choice` engages; otherwise ``swap_policy`` decides:

    ``alternate``      the other tree, every iteration (stock RRT-Connect);
    ``balance_steps``  the same tree until ``swap_steps`` connect steps were taken since
                       the last swap, then the other (the swap limiter);
    ``on_collision``   the same tree until a connect ends in a collision, then the other.
    """
    if swap_policy == "alternate":

        def rule(grew_start: bool, steps: int, collided: bool) -> tuple[bool, SwapCause]:
            return not grew_start, SwapCause.ALTERNATE

    elif swap_policy == "balance_steps":

        def rule(grew_start: bool, steps: int, collided: bool) -> tuple[bool, SwapCause]:
            return (not grew_start if steps >= swap_steps else grew_start), SwapCause.STEPS

    elif swap_policy == "on_collision":

        def rule(grew_start: bool, steps: int, collided: bool) -> tuple[bool, SwapCause]:
            return (not grew_start if collided else grew_start), SwapCause.COLLISION

    else:
        raise ValueError(f"unknown swap_policy {swap_policy!r}; accepted: {', '.join(SWAP_POLICIES)}")
    if not balance_tree_sizes:
        return lambda grew_start, start_size, goal_size, steps, collided: rule(grew_start, steps, collided)

    def balanced(
        grew_start: bool, start_size: int, goal_size: int, steps: int, collided: bool
    ) -> tuple[bool, SwapCause]:
        smaller_is_start = balance_choice(start_size, goal_size, True, max_tree_size_ratio)
        if smaller_is_start is None:
            return rule(grew_start, steps, collided)
        return smaller_is_start, SwapCause.BALANCE

    return balanced


# -- nearest_policy ------------------------------------------------------------------------


def exhaustion_scale(failures: np.ndarray | int, target: int) -> np.ndarray | float:
    """The exhaustion heuristic's distance factor, ``0.9 + 0.1 * |target - failures| / target``.

    1 for a node that never failed, lowest (0.9) for one that failed ``target`` times,
    above 1 beyond ``2 * target`` failures.
    """
    return 0.9 + 0.1 * np.abs(target - failures) / target


def nearest_not_exhausted(distances: np.ndarray, failures: np.ndarray, exhausted_after: int) -> int:
    """Index of the nearest node with fewer than ``exhausted_after`` failed extensions.

    ``distances`` and ``failures`` are per node, ``(n,)``. When every node is exhausted,
    the nearest of all (the tree must grow from somewhere).
    """
    candidates = np.where(failures < exhausted_after, distances, np.inf)
    index = int(candidates.argmin())
    return index if candidates[index] < np.inf else int(distances.argmin())


def nearest_by_exhaustion(distances: np.ndarray, failures: np.ndarray, target: int) -> int:
    """Index of the node with the least ``distance * exhaustion_scale(failures, target)``."""
    return int((distances * exhaustion_scale(failures, target)).argmin())


class NodeFailures:
    """Failed extensions per node of one tree (an extension from the node hit a collision)."""

    def __init__(self, capacity: int = 1024) -> None:
        self._counts = np.zeros(capacity, dtype=np.int64)

    def _reserve(self, size: int) -> None:
        if size > len(self._counts):
            grown = np.zeros(max(size, 2 * len(self._counts)), dtype=np.int64)
            grown[: len(self._counts)] = self._counts
            self._counts = grown

    def record(self, node: int) -> None:
        self._reserve(node + 1)
        self._counts[node] += 1

    def counts(self, size: int) -> np.ndarray:
        """Failures of nodes ``0 .. size - 1``, ``(size,)`` (a view)."""
        self._reserve(size)
        return self._counts[:size]


#: ``find(tree, target) -> (node, distance)``: the node a tree grows from towards ``target``.
NearestFinder = Callable[[Tree, Any], tuple[int, float]]


def nearest_finder(
    nearest_policy: str, failures: dict[Tree, NodeFailures], exhausted_after: int = 15, exhaustion_target: int = 5
) -> NearestFinder | None:
    """The node choice of ``nearest_policy``; ``None`` for the plain nearest (``tree.nearest``).

    ``exhausted``: the nearest node with fewer than ``exhausted_after`` failures
    (:func:`nearest_not_exhausted`); ``exhaustion``: the least distance x
    :func:`exhaustion_scale` (``exhaustion_target``). ``failures`` holds each tree's
    :class:`NodeFailures`, which the planner records while such a policy is selected.

    The planner asks the policy for each extension step and for the first step of each
    connect. A connect's further steps extend the node the step before added, as
    RRT-Connect's connect does. For ``euclidean`` and ``exhausted`` that node is the
    policy's choice anyway: it is one ``range`` nearer the target than any node the step
    before could choose from, and it never failed. ``exhaustion`` may prefer an older node
    that failed about ``exhaustion_target`` times (its distance scaled by 0.9), among them
    the node the step before extended; extending that one again lands on the state just
    added, so a connect asking the policy could add that state over and over and never end.
    """
    if nearest_policy == "exhausted":

        def not_exhausted(tree: Tree, target: Any) -> tuple[int, float]:
            counts = failures[tree].counts(len(tree))
            node, distance = tree.nearest(target)
            if counts[node] < exhausted_after:
                return node, distance  # the nearest of all is not exhausted: no need to rank
            distances = tree.distances(target)
            node = nearest_not_exhausted(distances, counts, exhausted_after)
            return node, float(distances[node])

        return not_exhausted
    if nearest_policy == "exhaustion":

        def by_exhaustion(tree: Tree, target: Any) -> tuple[int, float]:
            distances = tree.distances(target)
            node = nearest_by_exhaustion(distances, failures[tree].counts(len(tree)), exhaustion_target)
            return node, float(distances[node])

        return by_exhaustion
    if nearest_policy == "euclidean":
        return None
    raise ValueError(f"unknown nearest_policy {nearest_policy!r}; accepted: {', '.join(NEAREST_POLICIES)}")


# -- sample_policy -------------------------------------------------------------------------


def node_quality(cost: float, optimal_cost: float, max_cost: float, min_quality: float) -> float:
    """A node's quality, ``1 - (cost - optimal_cost) / (max_cost - optimal_cost)``, at least ``min_quality``.

    Urmson and Simmons' hRRT quality: a node's cost is ``distance(start, node) +
    distance(node, goal)``, ``optimal_cost`` is ``distance(start, goal)`` and
    ``max_cost`` the largest cost in the tree. 1 while every node costs the optimum.
    """
    spread = max_cost - optimal_cost
    if spread <= 0.0:
        return 1.0
    return max(min_quality, 1.0 - (cost - optimal_cost) / spread)


class NodeCosts:
    """``distance(start, node) + distance(node, goal)`` per node of one tree, and the largest.

    Computed for the nodes added since the last :meth:`update`, so each node once.
    """

    def __init__(self, distance: Callable[[Any, Any], float]) -> None:
        self._distance = distance
        self.values: list[float] = []
        self.max = 0.0

    def update(self, tree: Tree, start: Any, goal: Any) -> None:
        distance = self._distance
        for node in range(len(self.values), len(tree)):
            point = tree.state(node)
            cost = distance(start, point) + distance(point, goal)
            self.values.append(cost)
            self.max = max(self.max, cost)


@dataclass
class SamplerCounts:
    """What a sample policy did in one solve (reported in ``RunStats``)."""

    rejections: int = 0  # draws discarded, or a valid-state sampler that found nothing
    checks: int = 0  # validity checks made inside a valid-state sampler


#: ``sample(grow_start) -> (target, nearest)``; ``target`` is ``None`` when the policy gave up
#: the iteration, ``nearest`` the node to extend from when the policy already found it.
TargetSampler = Callable[[bool], tuple[Any, int | None]]


@dataclass
class SampleContext:
    """What the sample policies draw on in one solve."""

    points: Any  # the solve's Points (core.spaces)
    start_tree: Tree
    goal_tree: Tree
    random: Callable[[], float]  # uniform in [0, 1), from the solve's generator
    counts: SamplerCounts
    find_nearest: NearestFinder | None = None  # the nearest policy (None: tree.nearest)
    goal_bias: float = 0.05
    min_quality: float = 0.0
    uniform_rate: float = 0.0  # goal_ball, neighbour_quality, valid_sampler: probability of a uniform target
    valid_sampler: ob.ValidStateSampler | None = None
    checker: Any = None  # the counting validity checker, to attribute checks to the sampler
    scratch: ob.State | None = None  # an OMPL state the valid-state sampler writes into


def target_sampler(sample_policy: str, context: SampleContext) -> TargetSampler:
    """The target choice of ``sample_policy`` as a function ``sample(grow_start)``.

    ``uniform``            a uniform sample within the bounds;
    ``goal_bias``          with probability ``goal_bias`` the other tree's first root (the goal
                           when growing the start tree, the start when growing the goal tree);
    ``goal_ball``          a uniform sample no farther from the other tree's first root than
                           start and goal are apart ("control chosen");
    ``neighbour_quality``  a uniform sample kept with probability :func:`node_quality` of the
                           node ``context.find_nearest`` (the nearest policy) picks for it;
    ``valid_sampler``      a sample of ``context.valid_sampler``, or a uniform sample when it
                           finds none (free space has no state near an obstacle).

    ``goal_ball``, ``neighbour_quality`` and ``valid_sampler`` never target some states
    (those outside the ball; those whose nearest node has quality 0 under ``min_quality``
    0, such as the costliest node of a tree; those far from obstacles), which can leave a
    problem unsolved for ever. With probability ``context.uniform_rate`` their iteration
    targets a uniform sample instead, which makes them probabilistically complete as
    RRT-Connect is. The rejecting policies give up the iteration after
    :data:`SAMPLE_ATTEMPTS` draws.
    """
    points, start_tree, goal_tree = context.points, context.start_tree, context.goal_tree
    uniform, distance, random, counts = points.sample, points.distance, context.random, context.counts
    uniform_rate = context.uniform_rate

    def or_uniform(sampler: TargetSampler) -> TargetSampler:
        """``sampler``, except that an iteration targets a uniform sample with probability ``uniform_rate``."""
        if uniform_rate <= 0.0:
            return sampler

        def mixed(grow_start: bool) -> tuple[Any, int | None]:
            return (uniform(), None) if random() < uniform_rate else sampler(grow_start)

        return mixed

    if sample_policy == "uniform":
        return lambda grow_start: (uniform(), None)
    if sample_policy == "goal_bias":
        bias = context.goal_bias

        def biased(grow_start: bool) -> tuple[Any, int | None]:
            if random() < bias:
                return (goal_tree if grow_start else start_tree).state(0), None
            return uniform(), None

        return biased
    if sample_policy == "goal_ball":

        def in_goal_ball(grow_start: bool) -> tuple[Any, int | None]:
            centre = (goal_tree if grow_start else start_tree).state(0)
            radius = distance(start_tree.state(0), goal_tree.state(0))
            for _ in range(SAMPLE_ATTEMPTS):
                point = uniform()
                if distance(point, centre) <= radius:
                    return point, None
                counts.rejections += 1
            return None, None

        return or_uniform(in_goal_ball)
    if sample_policy == "neighbour_quality":
        costs = {start_tree: NodeCosts(distance), goal_tree: NodeCosts(distance)}
        min_quality, find_nearest = context.min_quality, context.find_nearest

        def quality_accepted(grow_start: bool) -> tuple[Any, int | None]:
            tree = start_tree if grow_start else goal_tree
            start, goal = start_tree.state(0), goal_tree.state(0)
            tree_costs = costs[tree]
            tree_costs.update(tree, start, goal)
            optimal = distance(start, goal)
            for _ in range(SAMPLE_ATTEMPTS):
                point = uniform()
                nearest, _ = tree.nearest(point) if find_nearest is None else find_nearest(tree, point)
                if random() < node_quality(tree_costs.values[nearest], optimal, tree_costs.max, min_quality):
                    return point, nearest
                counts.rejections += 1
            return None, None

        return or_uniform(quality_accepted)
    if sample_policy == "valid_sampler":
        sampler, checker, state = context.valid_sampler, context.checker, context.scratch
        if sampler is None or checker is None or state is None:
            raise ValueError("sample_policy valid_sampler needs a valid-state sampler, the checker and a scratch state")

        def from_valid_sampler(grow_start: bool) -> tuple[Any, int | None]:
            before = checker.counters()["states_checked"]
            found = sampler.sample(state)
            counts.checks += checker.counters()["states_checked"] - before
            if not found:
                # No state near an obstacle within the sampler's attempts (free space has
                # none): a uniform target keeps the planner growing, as RRT-Connect would.
                counts.rejections += 1
                return uniform(), None
            return points.from_state(state), None

        return or_uniform(from_valid_sampler)
    raise ValueError(f"unknown sample_policy {sample_policy!r}; accepted: {', '.join(SAMPLE_POLICIES)}")
