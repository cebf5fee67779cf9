"""The RRT-Connect family's policies: which tree grows, from which node, towards what.

RRT-Connect's loop (:mod:`ompl_balance.planners`) asks three questions each iteration;
each answer is a policy, chosen by one parameter and built once per solve, so a policy that
is not selected costs the loop nothing:

``swap_policy`` and ``balance_tree_sizes`` -> :class:`TreeChoice`
    which tree an iteration grows: the balancing rule (grow the smaller tree once the
    trees drift apart in size), else alternation, the swap limiter or the collision swap;
``nearest_policy`` -> :class:`NearestChoice`
    which node the tree grows from: the nearest, the nearest not yet exhausted, or the
    nearest by distance scaled with the node's failures;
``sample_policy`` -> :func:`target_choice`
    where the iteration's target comes from: uniform, goal bias, the goal ball ("control
    chosen"), neighbour quality, or a valid-state sampler.

The rules themselves are plain functions of numbers (:func:`choose_tree`,
:func:`exhaustion_scale`, :func:`node_quality`, ...): the Python engine calls them here, the
compiled engine (:mod:`ompl_balance.engine.loop`) compiles the same functions.

These are the variants compared against RRT-Connect in the TU Berlin lab report "RRT
Extensions" (2020); ``docs/variants.md`` measures them.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from ompl import base as ob

from .core.trees import Tree


class SwapPolicy(enum.IntEnum):
    """``swap_policy``: which tree an iteration grows when balancing does not decide (see :func:`choose_tree`)."""

    ALTERNATE = 0  # the other tree, every iteration (stock RRT-Connect)
    SWAP_LIMIT = 1  # the same tree until swap_steps connect steps were taken (the swap limiter)
    ON_COLLISION = 2  # the same tree until a connect ends in a collision


class NearestPolicy(enum.IntEnum):
    """``nearest_policy``: which node a tree grows from (see :class:`NearestChoice`)."""

    EUCLIDEAN = 0  # the nearest (the space's metric)
    EXHAUSTED = 1  # the nearest with fewer than exhausted_after failed extensions
    EXHAUSTION = 2  # the least distance x exhaustion_scale


class SamplePolicy(enum.IntEnum):
    """``sample_policy``: where an iteration's target comes from (see :func:`target_choice`)."""

    UNIFORM = 0
    GOAL_BIAS = 1
    GOAL_BALL = 2
    NEIGHBOUR_QUALITY = 3
    VALID_SAMPLER = 4


def _names(policy: type[enum.IntEnum]) -> tuple[str, ...]:
    return tuple(member.name.lower() for member in policy)


#: ``swap_policy`` choices, in :class:`SwapPolicy` order.
SWAP_POLICIES = _names(SwapPolicy)
#: ``nearest_policy`` choices, in :class:`NearestPolicy` order.
NEAREST_POLICIES = _names(NearestPolicy)
#: ``sample_policy`` choices, in :class:`SamplePolicy` order.
SAMPLE_POLICIES = _names(SamplePolicy)
#: Former names of policies, still accepted (with a message naming the new one).
RENAMED_POLICIES = {"balance_steps": "swap_limit"}

#: Draws a rejecting sample policy makes before the iteration is given up (OMPL's
#: ``magic::MAX_VALID_SAMPLE_ATTEMPTS``).
SAMPLE_ATTEMPTS = 100


class SwapCause(enum.IntEnum):
    """Why an iteration grew the other tree; ``RunStats.swaps_<cause>`` counts each."""

    ALTERNATE = 0  # alternation (stock RRT-Connect)
    BALANCE = 1  # the balancing rule chose the smaller tree
    STEPS = 2  # the swap limit of ``swap_limit`` was reached
    COLLISION = 3  # a connect ended in a collision under ``on_collision``


#: The causes' names, in :class:`SwapCause` order.
SWAP_CAUSES = tuple(cause.name.lower() for cause in SwapCause)


def _choice(name: str, value: str, accepted: tuple[str, ...]) -> int:
    if value not in accepted:
        raise ValueError(f"unknown {name} {value!r}; accepted: {', '.join(accepted)}")
    return accepted.index(value)


# -- swap_policy and balancing -------------------------------------------------------------


def tree_size_ratio(start_size: int, goal_size: int) -> float:
    """``|a - b| / min(a, b)``: how much larger the larger tree is, relative to the smaller.

    Dividing by the *smaller* size is what makes the rule engage: with ``max(a, b)`` in
    the denominator (the first OMPL pull request) the ratio never reaches 1.
    """
    return abs(start_size - goal_size) / min(start_size, goal_size)


def choose_tree(
    swap_policy: int,
    balance_tree_sizes: bool,
    max_tree_size_ratio: float,
    swap_steps: int,
    grew_start: bool,
    start_size: int,
    goal_size: int,
    steps: int,
    collided: bool,
) -> tuple[bool, SwapCause]:
    """Which tree an iteration grows: ``(grow_start, cause)``, ``cause`` saying why, if it is a swap.

    Given which tree the previous iteration grew (``grew_start``), the tree sizes, the
    connect steps taken since the last swap and whether the last connect ended in a
    collision. The balancing rule first: with ``balance_tree_sizes`` and trees of different
    sizes, when :func:`tree_size_ratio` reaches ``max_tree_size_ratio`` the smaller tree
    grows. Otherwise ``swap_policy`` (a :class:`SwapPolicy`) decides:

    ``alternate``     the other tree, every iteration (stock RRT-Connect);
    ``swap_limit``    the same tree until ``swap_steps`` connect steps were taken since
                      the last swap, then the other (the swap limiter);
    ``on_collision``  the same tree until a connect ends in a collision, then the other.
    """
    if balance_tree_sizes and start_size != goal_size and tree_size_ratio(start_size, goal_size) >= max_tree_size_ratio:
        return start_size < goal_size, SwapCause.BALANCE
    if swap_policy == SwapPolicy.ALTERNATE:
        return not grew_start, SwapCause.ALTERNATE
    if swap_policy == SwapPolicy.SWAP_LIMIT:
        return (not grew_start if steps >= swap_steps else grew_start), SwapCause.STEPS
    return (not grew_start if collided else grew_start), SwapCause.COLLISION


def balance_choice(start_size: int, goal_size: int, balance: bool, max_ratio: float) -> bool | None:
    """Which tree the balancing rule grows: ``True`` start, ``False`` goal, ``None`` no preference
    (the swap policy decides); see :func:`choose_tree`."""
    grow_start, cause = choose_tree(SwapPolicy.ALTERNATE, balance, max_ratio, 1, False, start_size, goal_size, 0, False)
    return grow_start if cause is SwapCause.BALANCE else None


#: The swap state before a planner's first iteration: as if the goal tree had just been grown
#: and every rule were due to swap (connect steps beyond any limit, the last connect trapped),
#: so the first iteration grows the start tree unless balancing decides otherwise.
FIRST_SWAP_STATE = (False, 2**62, True)


@dataclass
class SwapState:
    """What the tree choice remembers between iterations (and solves, until ``clear()``)."""

    grew_start: bool = FIRST_SWAP_STATE[0]  # the tree the last iteration grew
    steps: int = FIRST_SWAP_STATE[1]  # connect steps since the last swap
    collided: bool = FIRST_SWAP_STATE[2]  # the last connect ended trapped


class TreeChoice:
    """The tree-choice rule of a solve: :meth:`next_tree` each iteration, told what connects did."""

    def __init__(
        self,
        swap_policy: str,
        state: SwapState,
        balance_tree_sizes: bool = False,
        max_tree_size_ratio: float = 1.0,
        swap_steps: int = 1,
    ) -> None:
        self.swap_policy = _choice("swap_policy", swap_policy, SWAP_POLICIES)
        self.state = state
        self.balance_tree_sizes = balance_tree_sizes
        self.max_tree_size_ratio = max_tree_size_ratio
        self.swap_steps = swap_steps

    def next_tree(self, start_size: int, goal_size: int) -> tuple[bool, SwapCause | None]:
        """The tree this iteration grows (``True``: the start tree) and, if it is a swap, why."""
        state = self.state
        grow_start, cause = choose_tree(
            self.swap_policy,
            self.balance_tree_sizes,
            self.max_tree_size_ratio,
            self.swap_steps,
            state.grew_start,
            start_size,
            goal_size,
            state.steps,
            state.collided,
        )
        swapped = grow_start != state.grew_start
        if swapped:
            state.steps, state.collided = 0, False
        state.grew_start = grow_start
        return grow_start, cause if swapped else None

    def connect_stepped(self) -> None:
        """A connect took one more step."""
        self.state.steps += 1

    def connect_ended(self, trapped: bool) -> None:
        """A connect ended: trapped (in a collision) or not."""
        self.state.collided = trapped


# -- nearest_policy ------------------------------------------------------------------------


def exhaustion_scale(failures: Any, target: int) -> Any:
    """The exhaustion heuristic's distance factor, ``0.9 + 0.1 * |target - failures| / target``.

    1 for a node that never failed, lowest (0.9) for one that failed ``target`` times,
    above 1 beyond ``2 * target`` failures. ``failures`` is a count or an array of them.
    """
    return 0.9 + 0.1 * np.abs(target - failures) / target


def nearest_not_exhausted(distances: np.ndarray, failures: np.ndarray, exhausted_after: int) -> int:
    """Index of the nearest node with fewer than ``exhausted_after`` failed extensions (the first
    on ties).

    ``distances`` and ``failures`` are per node, ``(n,)``. When every node is exhausted,
    the nearest of all (the tree must grow from somewhere). (A loop that allocates nothing:
    the compiled engine compiles this function.)
    """
    found, closest = -1, 0
    for i in range(len(distances)):
        if distances[i] < distances[closest]:
            closest = i
        if failures[i] < exhausted_after and (found < 0 or distances[i] < distances[found]):
            found = i
    return found if found >= 0 else closest


def nearest_by_exhaustion(distances: np.ndarray, failures: np.ndarray, target: int) -> int:
    """Index of the node with the least ``distance * exhaustion_scale(failures, target)`` (the first
    on ties; a loop the compiled engine compiles)."""
    best, best_score = 0, np.inf
    for i in range(len(distances)):
        score = distances[i] * exhaustion_scale(failures[i], target)
        if score < best_score:
            best, best_score = i, score
    return best


def nearest_needs_ranking(nearest_policy: int, failures_of_nearest: int, exhausted_after: int) -> bool:
    """Whether the nearest policy must rank every node (rather than take the nearest): always for
    ``exhaustion``, for ``exhausted`` when the nearest node is exhausted, never for ``euclidean``."""
    if nearest_policy == NearestPolicy.EUCLIDEAN:
        return False
    return nearest_policy == NearestPolicy.EXHAUSTION or failures_of_nearest >= exhausted_after


def ranked_node(
    nearest_policy: int, distances: np.ndarray, failures: np.ndarray, exhausted_after: int, target: int
) -> int:
    """The node a ranking nearest policy picks, given every node's distance and failures."""
    if nearest_policy == NearestPolicy.EXHAUSTED:
        return nearest_not_exhausted(distances, failures, exhausted_after)
    return nearest_by_exhaustion(distances, failures, target)


class NodeFailures:
    """Failed extensions per node of one tree (an extension from the node hit a collision)."""

    def __init__(self, capacity: int = 1024) -> None:
        self.array = np.zeros(capacity, dtype=np.int64)  # counts of nodes 0 .. capacity - 1

    def reserve(self, size: int) -> None:
        """Room for the counts of ``size`` nodes (grown by doubling, new nodes at 0)."""
        if size > len(self.array):
            grown = np.zeros(max(size, 2 * len(self.array)), dtype=np.int64)
            grown[: len(self.array)] = self.array
            self.array = grown

    def clear(self) -> None:
        """No failures (the tree was emptied); the array stays, as compiled code may hold it."""
        self.array[:] = 0

    def record(self, node: int) -> None:
        self.reserve(node + 1)
        self.array[node] += 1

    def counts(self, size: int) -> np.ndarray:
        """Failures of nodes ``0 .. size - 1``, ``(size,)`` (a view)."""
        self.reserve(size)
        return self.array[:size]


class NearestChoice:
    """The node a tree grows from towards a target under ``nearest_policy`` (a :class:`NearestPolicy`
    name), and what a failed extension changes; ``failures`` holds each tree's :class:`NodeFailures`.

    The planner asks the policy for each extension step and for the first step of each
    connect. A connect's further steps extend the node the step before added, as
    RRT-Connect's connect does. For ``euclidean`` and ``exhausted`` that node is the
    policy's choice anyway: it is one ``range`` nearer the target than any node the step
    before could choose from, and it never failed. ``exhaustion`` may prefer an older node
    that failed about ``exhaustion_target`` times (its distance scaled by 0.9), among them
    the node the step before extended; extending that one again lands on the state just
    added, so a connect asking the policy could add that state over and over and never end.
    """

    def __init__(
        self,
        nearest_policy: str,
        failures: dict[Tree, NodeFailures],
        exhausted_after: int = 15,
        exhaustion_target: int = 5,
    ) -> None:
        self.policy = _choice("nearest_policy", nearest_policy, NEAREST_POLICIES)
        self.failures = failures
        self.exhausted_after = exhausted_after
        self.exhaustion_target = exhaustion_target

    def node(self, tree: Tree, target: Any) -> tuple[int, float]:
        """The node to extend and its distance to ``target`` (the compiled engine's ``_find_nearest``
        takes the same steps on its own tree arrays)."""
        policy = self.policy
        if policy != NearestPolicy.EXHAUSTION:
            node, distance = tree.nearest(target)
            if policy == NearestPolicy.EUCLIDEAN:
                return node, distance
            failures = self.failures[tree].counts(len(tree))
            if not nearest_needs_ranking(policy, int(failures[node]), self.exhausted_after):
                return node, distance
        failures = self.failures[tree].counts(len(tree))
        distances = tree.distances(target)
        node = ranked_node(policy, distances, failures, self.exhausted_after, self.exhaustion_target)
        return node, float(distances[node])

    def failed(self, tree: Tree, node: int) -> None:
        """An extension from ``node`` hit a collision (remembered by the policies that count failures)."""
        if self.policy != NearestPolicy.EUCLIDEAN:
            self.failures[tree].record(node)


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


def node_cost(start_distance: float, goal_distance: float) -> float:
    """A node's cost for :func:`node_quality`: its distance from the start plus its distance to the goal."""
    return start_distance + goal_distance


def in_goal_ball(distance: float, radius: float) -> bool:
    """Whether a sample ``distance`` from the goal ball's centre lies in it (``goal_ball``)."""
    return distance <= radius


class NodeCosts:
    """:func:`node_cost` per node of one tree, and the largest.

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
            cost = node_cost(distance(start, point), distance(point, goal))
            self.values.append(cost)
            self.max = max(self.max, cost)


@dataclass
class SamplerCounts:
    """What a sample policy did in one solve (reported in ``RunStats``)."""

    rejections: int = 0  # draws discarded, or a valid-state sampler that found nothing
    checks: int = 0  # validity checks made inside a valid-state sampler


class TargetChoice(Protocol):
    """Where an iteration's target comes from."""

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        """The target (``None``: the policy gave up the iteration) and the node to extend
        towards it when the policy already found it (``None``: the nearest policy decides)."""
        ...


@dataclass
class SampleContext:
    """What the sample policies draw on in one solve."""

    points: Any  # the solve's Points (core.spaces)
    start_tree: Tree
    goal_tree: Tree
    random: Callable[[], float]  # uniform in [0, 1), from the solve's generator
    counts: SamplerCounts
    nearest: NearestChoice | None = None  # the nearest policy (None: tree.nearest)
    goal_bias: float = 0.05
    min_quality: float = 0.0
    uniform_rate: float = 0.0  # goal_ball, neighbour_quality, valid_sampler: probability of a uniform target
    valid_sampler: ob.ValidStateSampler | None = None
    checker: Any = None  # the counting validity checker, to attribute checks to the sampler
    scratch: ob.State | None = None  # an OMPL state the valid-state sampler writes into


class UniformTargets:
    """``uniform``: a uniform sample of the space."""

    def __init__(self, context: SampleContext) -> None:
        self.sample = context.points.sample

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        return self.sample(), None


class GoalBiasTargets:
    """``goal_bias``: with probability ``goal_bias`` the other tree's first root, else uniform."""

    def __init__(self, context: SampleContext) -> None:
        self.context = context

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        context = self.context
        if context.random() < context.goal_bias:
            return (context.goal_tree if grow_start else context.start_tree).state(0), None
        return context.points.sample(), None


class GoalBallTargets:
    """``goal_ball``: a uniform sample no farther from the other tree's first root than start
    and goal are apart ("control chosen"); gives up after :data:`SAMPLE_ATTEMPTS` draws."""

    def __init__(self, context: SampleContext) -> None:
        self.context = context

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        context = self.context
        distance = context.points.distance
        centre = (context.goal_tree if grow_start else context.start_tree).state(0)
        radius = distance(context.start_tree.state(0), context.goal_tree.state(0))
        for _ in range(SAMPLE_ATTEMPTS):
            point = context.points.sample()
            if in_goal_ball(distance(point, centre), radius):
                return point, None
            context.counts.rejections += 1
        return None, None


class QualityTargets:
    """``neighbour_quality``: a uniform sample kept with the probability :func:`node_quality` of
    the node the nearest policy picks for it; gives up after :data:`SAMPLE_ATTEMPTS` draws."""

    def __init__(self, context: SampleContext) -> None:
        self.context = context
        distance = context.points.distance
        self.costs = {context.start_tree: NodeCosts(distance), context.goal_tree: NodeCosts(distance)}

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        context = self.context
        distance = context.points.distance
        tree = context.start_tree if grow_start else context.goal_tree
        start, goal = context.start_tree.state(0), context.goal_tree.state(0)
        costs = self.costs[tree]
        costs.update(tree, start, goal)
        optimal = distance(start, goal)
        for _ in range(SAMPLE_ATTEMPTS):
            point = context.points.sample()
            nearest, _ = tree.nearest(point) if context.nearest is None else context.nearest.node(tree, point)
            if context.random() < node_quality(costs.values[nearest], optimal, costs.max, context.min_quality):
                return point, nearest
            context.counts.rejections += 1
        return None, None


class ValidSamplerTargets:
    """``valid_sampler``: a sample of the context's valid-state sampler, or a uniform sample when
    it finds none (free space has no state near an obstacle)."""

    def __init__(self, context: SampleContext) -> None:
        if context.valid_sampler is None or context.checker is None or context.scratch is None:
            raise ValueError("sample_policy valid_sampler needs a valid-state sampler, the checker and a scratch state")
        self.context = context

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        context = self.context
        before = context.checker.counters()["states_checked"]
        found = context.valid_sampler.sample(context.scratch)  # type: ignore[union-attr]
        context.counts.checks += context.checker.counters()["states_checked"] - before
        if not found:
            # a uniform target keeps the planner growing, as RRT-Connect would
            context.counts.rejections += 1
            return context.points.sample(), None
        return context.points.from_state(context.scratch), None


class MixedWithUniform:
    """A policy whose iteration targets a uniform sample instead with probability ``uniform_rate``."""

    def __init__(self, policy: TargetChoice, context: SampleContext) -> None:
        self.policy = policy
        self.context = context

    def target(self, grow_start: bool) -> tuple[Any, int | None]:
        context = self.context
        if context.random() < context.uniform_rate:
            return context.points.sample(), None
        return self.policy.target(grow_start)


_TARGETS: dict[str, Callable[[SampleContext], TargetChoice]] = {
    "uniform": UniformTargets,
    "goal_bias": GoalBiasTargets,
    "goal_ball": GoalBallTargets,
    "neighbour_quality": QualityTargets,
    "valid_sampler": ValidSamplerTargets,
}
#: The policies that never target some states, made complete by uniform targets at ``uniform_rate``.
_RESTRICTED = ("goal_ball", "neighbour_quality", "valid_sampler")


def target_choice(sample_policy: str, context: SampleContext) -> TargetChoice:
    """The target choice of ``sample_policy`` (see the classes above).

    ``goal_ball``, ``neighbour_quality`` and ``valid_sampler`` never target some states
    (those outside the ball; those whose nearest node has quality 0 under ``min_quality``
    0, such as the costliest node of a tree; those far from obstacles), which can leave a
    problem unsolved for ever. With probability ``context.uniform_rate`` their iteration
    targets a uniform sample instead, which makes them probabilistically complete as
    RRT-Connect is.
    """
    _choice("sample_policy", sample_policy, SAMPLE_POLICIES)
    policy = _TARGETS[sample_policy](context)
    if sample_policy in _RESTRICTED and context.uniform_rate > 0.0:
        return MixedWithUniform(policy, context)
    return policy
