"""RRT-Connect with tree balancing, and the classroom variants as named presets.

:class:`BalancedRRTConnect` is OMPL's ``RRTConnect`` (``src/ompl/geometric/planners/
rrt/src/RRTConnect.cpp``) written as a Python ``ob.Planner``, plus one rule: when the
two trees drift apart in size, grow the smaller one (Kuffner's recommendation, as VAMP
does). Everything else keeps OMPL's semantics: trees rooted at every start state and
at goal states sampled while fewer than half of the goal tree's states were sampled,
``range`` defaulting to 0.2 x the space's maximum extent, the grow/connect loop, the
planner statuses, the solution added with ``pdef.addSolutionPath``.

Differences from stock, on purpose (``docs/drop-in.md`` lists every difference):

* no approximate solutions: a run that does not connect the trees ends with
  ``TIMEOUT`` and adds no path;
* each solve reports a :class:`RunStats` record (``planner.stats``).

The same planner carries the classroom RRT-Connect variants as policies
(:mod:`ompl_balance.policies`), each a parameter: ``swap_policy`` (which tree grows),
``nearest_policy`` (which node it grows from) and ``sample_policy`` (towards what).
:data:`PRESETS` names the combinations the TU Berlin lab report "RRT Extensions" (2020)
compared (``SwapLimitRRTConnect``, ...); ``docs/variants.md`` measures them.
"""

from __future__ import annotations

import enum
import itertools
import math
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np
from ompl import base as ob
from ompl import util as ou

from .core.params import Settings, param
from .core.planner import GOAL_TAG, RANGE_AS_EXTENT_FRACTION, START_TAG, PlannerSpecs, TreePlanner
from .core.spaces import Points
from .core.trees import NO_PARENT, Tree
from .policies import (
    NEAREST_POLICIES,
    SAMPLE_POLICIES,
    SWAP_POLICIES,
    NearestFinder,
    NodeFailures,
    SampleContext,
    SamplerCounts,
    SwapCause,
    nearest_finder,
    target_sampler,
    tree_chooser,
)
from .samplers import PassageSampler

#: ``allocate(si) -> ob.ValidStateSampler`` (a valid-state sampler class is one).
ValidStateSamplerAllocator = Callable[[Any], Any]


@dataclass
class RRTConnectSettings(Settings):
    """The parameters of :class:`BalancedRRTConnect` (OMPL names; distances in the space's units)."""

    range: float = param(
        0.0,
        "longest motion added to a tree in one step; 0 picks 0.2 x the space's maximum extent at setup()",
        low=0.0,
        suggestion="0.:1.:10000.",
    )
    intermediate_states: bool = param(
        False,
        "add the states along each motion (at the validity-checking resolution) to the tree, "
        "as OMPL's RRTConnect with addIntermediateStates",
    )
    balance_tree_sizes: bool = param(
        True,
        "grow the smaller tree once |a - b| / min(a, b) reaches max_tree_size_ratio (a, b the tree sizes); "
        "otherwise swap_policy decides",
    )
    max_tree_size_ratio: float = param(
        1.0,
        "the balancing rule's ratio; 1.0 grows the smaller tree once it is less than half the size of the other",
        low=0.0,
        suggestion="0.:0.05:10.",
    )
    swap_policy: str = param(
        "alternate",
        "which tree grows when balancing does not decide: the other one each iteration (stock), "
        "the same one until swap_steps connect steps were taken, or until a connect collides",
        choices=SWAP_POLICIES,
    )
    swap_steps: int = param(10, "connect steps after which balance_steps swaps trees", low=1, suggestion="1:1:100")
    nearest_policy: str = param(
        "euclidean",
        "the node a tree grows from: the nearest, the nearest not exhausted (exhausted_after), "
        "or the least distance x exhaustion scale (exhaustion_target)",
        choices=NEAREST_POLICIES,
    )
    exhausted_after: int = param(15, "failed extensions after which a node is exhausted", low=1, suggestion="1:1:100")
    exhaustion_target: int = param(
        5, "failures at which the exhaustion scale is lowest (0.9)", low=1, suggestion="1:1:100"
    )
    sample_policy: str = param(
        "uniform",
        "where each iteration's target comes from (see ompl_balance.policies.target_sampler)",
        choices=SAMPLE_POLICIES,
    )
    goal_bias: float = param(
        0.05, "probability that goal_bias targets the other tree's root", low=0.0, high=1.0, suggestion="0.:.05:1."
    )
    uniform_rate: float = param(
        0.1,
        "probability that an iteration of goal_ball, neighbour_quality or valid_sampler targets a uniform sample "
        "of the whole space instead, which keeps those policies probabilistically complete; 0: their targets "
        "only (the strict rules)",
        low=0.0,
        high=1.0,
        suggestion="0.:.05:1.",
    )
    min_quality: float = param(
        0.0, "lowest acceptance probability of neighbour_quality", low=0.0, high=1.0, suggestion="0.:.05:1."
    )
    seed: int = param(
        0,
        "0: each solve draws its seed from an OMPL RNG (repeated by ompl.util.RNG.setSeed); > 0: every solve "
        "uses this seed (real-vector spaces; other spaces sample with OMPL's sampler and seed)",
        low=0,
        suggestion="0:1:1000000",
    )


@dataclass
class RunStats:
    """The work one ``solve()`` of an RRT-Connect planner did.

    Attributes
    ----------
    status: the ``PlannerStatus`` as a string (``"Exact solution"``, ``"Timeout"``, ...).
    iterations: main-loop iterations (one sample each).
    start_tree_size, goal_tree_size: nodes in each tree when the solve ended
        (cumulative over solves until ``clear()``, as the trees are).
    tree_swaps: iterations that grew a different tree than the iteration before.
    states_checked: states whose validity the space information's checker decided
        during this solve, including those inside motion checks and those a
        valid-state sampler checked.
    motions_checked: motions handed to the motion validator during this solve.
    time: wall-clock seconds spent in ``solve()``.
    distance_queries: exact distance queries a certified motion validator made (0 for others).
    swaps_alternate, swaps_balance, swaps_steps, swaps_collision: ``tree_swaps`` by
        :class:`~ompl_balance.policies.SwapCause`.
    sampler_rejections: samples the sample policy drew and discarded (outside the
        goal ball, refused for neighbour quality, or a valid-state sampler's
        ``sample()`` returning ``False``).
    sampler_checks: validity checks made inside the valid-state sampler (part of
        ``states_checked``, not in addition to it).
    """

    status: str
    iterations: int
    start_tree_size: int
    goal_tree_size: int
    tree_swaps: int
    states_checked: int
    motions_checked: int
    time: float
    distance_queries: int = 0
    swaps_alternate: int = 0
    swaps_balance: int = 0
    swaps_steps: int = 0
    swaps_collision: int = 0
    sampler_rejections: int = 0
    sampler_checks: int = 0

    def as_dict(self) -> dict[str, float | int | str]:
        return asdict(self)


class Grow(enum.Enum):
    """Outcome of one extension step, as OMPL's ``RRTConnect::GrowState``."""

    TRAPPED = 0  # no progress: the motion was invalid
    ADVANCED = 1  # a step of length ``range`` towards the target was added
    REACHED = 2  # the target itself was added


@dataclass
class Extender:
    """One solve's extension step: what :meth:`grow` needs, fixed for the solve."""

    points: Points
    range: float
    intermediate_states: bool
    is_valid: Callable[[ob.State], bool]
    check_motion: Callable[[ob.State, ob.State], bool]
    step_may_stall: bool  # whether a step of ``range`` can round back onto its start
    find_nearest: NearestFinder | None  # the nearest policy; None: the nearest node
    failures: dict[Tree, NodeFailures]  # recorded while a failure-counting nearest policy is on

    def grow(self, tree: Tree, from_start: bool, target: Any, nearest: int | None = None) -> tuple[Grow, int, float]:
        """Extend ``tree`` one step towards ``target``.

        Returns the outcome, the node added (``NO_PARENT`` when trapped) and the distance
        from the node extended to ``target`` (before the step). The node extended is
        ``nearest`` when given, else the one the nearest policy picks. Motions in the start
        tree are checked from the tree outwards; in the goal tree they run from the new
        state into the tree, so the new state is checked first (``checkMotion`` assumes its
        first state valid), exactly as OMPL does. A motion in collision counts as a failed
        extension of the node (when the nearest policy counts failures).
        """
        points = self.points
        if nearest is None:
            nearest, distance = tree.nearest(target) if self.find_nearest is None else self.find_nearest(tree, target)
        else:
            distance = points.distance(tree.state(nearest), target)
        near = tree.state(nearest)
        reach = distance <= self.range
        new = target if reach else points.interpolate(near, target, self.range / distance)
        if not reach and self.step_may_stall and points.equal(near, new):
            return Grow.TRAPPED, NO_PARENT, distance

        near_state, new_state = points.ompl_state(near, 0), points.ompl_state(new, 1)
        if from_start:
            valid = self.check_motion(near_state, new_state)
        else:
            valid = self.is_valid(new_state) and self.check_motion(new_state, near_state)
        if not valid:
            if self.find_nearest is not None:
                self.failures[tree].record(nearest)
            return Grow.TRAPPED, NO_PARENT, distance

        if self.intermediate_states:
            # States along the motion, ordered away from the tree's root.
            added = nearest
            for point in points.segment_points(near, new):
                added = tree.add(point, added)
        else:
            added = tree.add(new, nearest)
        return (Grow.REACHED if reach else Grow.ADVANCED), added, distance


#: ``(grew_start, steps, collided)`` before the first iteration: as if the goal tree had
#: just been grown and every rule were due to swap, so the first iteration grows the start tree.
_FIRST_LOOP_STATE = (False, sys.maxsize, True)


class BalancedRRTConnect(TreePlanner):
    """RRT-Connect with tree balancing and the classroom variants as policies.

    Parameters are those of :class:`RRTConnectSettings`, through ``planner.params()``
    (OMPL string forms) or the camelCase accessors (``setMaxTreeSizeRatio``, ...).

    Constructed as OMPL's ``og.RRTConnect``: ``BalancedRRTConnect(si, addIntermediateStates=False,
    name=None)``; ``addIntermediateStates`` sets ``intermediate_states`` and, as stock, appends
    ``Intermediate`` to the default name.

    Subclasses preset policies through ``POLICIES`` (parameter values set at
    construction) and ``VALID_STATE_SAMPLER`` (an allocator); their planner name is
    their class name. See :data:`PRESETS`.
    """

    Settings = RRTConnectSettings
    Stats = RunStats
    SPECS = PlannerSpecs(recognizedGoal=ob.GoalType.GOAL_SAMPLEABLE_REGION, directed=True)
    SIGNATURE = "(si, addIntermediateStates=False, name=None)"
    POLICIES: ClassVar[dict[str, str]] = {}
    VALID_STATE_SAMPLER: ClassVar[type | None] = None  # a valid-state sampler class

    def __init__(self, si: ob.SpaceInformation, addIntermediateStates: bool = False, name: str | None = None) -> None:  # noqa: N803 (OMPL's name)
        if not isinstance(addIntermediateStates, (bool, np.bool_)):
            self._refuse_argument(
                "addIntermediateStates must be a bool (a planner name goes in name=...)", addIntermediateStates
            )
        if name is None and addIntermediateStates:
            name = f"{type(self).__name__}Intermediate"
        super().__init__(si, name)
        self.settings.update({**self.POLICIES, "intermediate_states": bool(addIntermediateStates)})
        self._valid_state_sampler_allocator: ValidStateSamplerAllocator | None = type(self).VALID_STATE_SAMPLER
        self._valid_sampler: ob.ValidStateSampler | None = None
        # The trees and what the policies record per node: kept across solves until clear().
        self._start_tree: Tree | None = None
        self._goal_tree: Tree | None = None
        self._failures: dict[Tree, NodeFailures] = {}
        self._loop_state = _FIRST_LOOP_STATE
        # For the planner data, as OMPL's: the nodes joined by the last solution (start tree,
        # goal tree), and the least distance between the trees seen after a connect.
        self._connection: tuple[int, int] | None = None
        self._distance_between_trees = math.inf

    @property
    def draws_from_ompl_rng(self) -> bool:
        """True when a solve draws from OMPL's global RNG (``sample_policy = valid_sampler``):
        the ``seed`` parameter cannot repeat such a solve, ``ompl.util.RNG.setSeed`` at the
        start of a fresh process can."""
        return bool(self.settings.sample_policy == "valid_sampler")

    def setValidStateSamplerAllocator(self, allocator: ValidStateSamplerAllocator | None) -> None:  # noqa: N802
        """The valid-state sampler of ``sample_policy = valid_sampler``: ``allocator(si)``,
        or ``si.allocValidStateSampler()`` when ``None``. Takes effect at ``setup()``."""
        self._valid_state_sampler_allocator = allocator

    # -- planner life cycle -------------------------------------------------------

    def setup(self) -> None:
        super().setup()
        if self.settings.range < 1e-12:
            self.settings.range = RANGE_AS_EXTENT_FRACTION * self.getSpaceInformation().getMaximumExtent()
            ou.OMPL_INFORM(f"{self.getName()}: range computed to be {self.settings.range:g}")
        self._check_policies()
        self._valid_sampler = None  # allocated again from the current allocator

    def _check_policies(self) -> None:
        """Refuse combinations of policies and parameters that cannot do what they say."""
        if self.draws_from_ompl_rng and self.settings.seed > 0:
            raise ValueError(
                f"{self.getName()}: sample_policy=valid_sampler with seed={self.settings.seed}: a valid-state sampler "
                "draws from OMPL's RNG, which the seed parameter cannot repeat; use seed=0 (and "
                "ompl.util.RNG.setSeed) or another sample_policy"
            )

    def _before_solve(self, ptc: ob.PlannerTerminationCondition) -> None:
        self._check_policies()

    def clear(self) -> None:
        super().clear()
        self._start_tree = self._goal_tree = None
        self._failures = {}
        self._loop_state = _FIRST_LOOP_STATE
        self._connection = None
        self._distance_between_trees = math.inf

    # -- solving -------------------------------------------------------------------

    def _plan(
        self, ptc: ob.PlannerTerminationCondition, points: Points, rng: np.random.Generator
    ) -> tuple[ob.PlannerStatus.PlannerStatusType, dict[str, Any]]:
        """The grow/connect loop; returns the status and the loop's statistics."""
        settings, name = self.settings, self.getName()
        si = self.getSpaceInformation()
        if self._start_tree is None or self._goal_tree is None:
            self._start_tree, self._goal_tree = points.new_tree(), points.new_tree()
            self._failures = {self._start_tree: NodeFailures(), self._goal_tree: NodeFailures()}
        start_tree, goal_tree = self._start_tree, self._goal_tree
        swaps = [0] * len(SwapCause)
        counts = SamplerCounts()

        def result(status: ob.PlannerStatus.PlannerStatusType, iterations: int = 0) -> tuple[Any, dict[str, Any]]:
            return status, dict(
                iterations=iterations,
                start_tree_size=len(start_tree),
                goal_tree_size=len(goal_tree),
                tree_swaps=sum(swaps),
                sampler_rejections=counts.rejections,
                sampler_checks=counts.checks,
                **{f"swaps_{cause.name.lower()}": swaps[cause] for cause in SwapCause},
            )

        pdef = self.getProblemDefinition()  # keep the owner alive while its states are used
        goal = pdef.getGoal()
        if not isinstance(goal, ob.GoalSampleableRegion):
            ou.OMPL_ERROR(f"{name}: Unknown type of goal (a GoalSampleableRegion is needed)")
            return result(ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE)
        inputs = self.getPlannerInputStates()
        while (state := inputs.nextStart()) is not None:
            if points.is_finite(state):
                start_tree.add(points.from_state(state))
            else:
                ou.OMPL_WARN(f"{name}: Skipping start state with non-finite values")
        if len(start_tree) == 0:
            ou.OMPL_ERROR(f"{name}: Motion planning start tree could not be initialized!")
            return result(ob.PlannerStatus.INVALID_START)
        if not goal.couldSample():
            ou.OMPL_ERROR(f"{name}: Insufficient states in sampleable goal region")
            return result(ob.PlannerStatus.INVALID_GOAL)
        ou.OMPL_INFORM(
            f"{name}: Starting planning with {len(start_tree) + len(goal_tree)} states already in datastructure"
        )

        # The policies of this solve.
        choose_tree = tree_chooser(
            settings.swap_policy, settings.balance_tree_sizes, settings.max_tree_size_ratio, settings.swap_steps
        )
        find_nearest = nearest_finder(
            settings.nearest_policy, self._failures, settings.exhausted_after, settings.exhaustion_target
        )
        extender = Extender(
            points,
            settings.range,
            settings.intermediate_states,
            si.isValid,
            si.checkMotion,
            points.may_stall(settings.range),
            find_nearest,
            self._failures,
        )
        sample = target_sampler(settings.sample_policy, self._sample_context(points, rng, counts, find_nearest))
        nearest_is_euclidean = find_nearest is None

        status = ob.PlannerStatus.TIMEOUT
        progress = self.progress
        grew_start, steps, collided = self._loop_state
        while not ptc():
            # Goal states join the goal tree while fewer than half of its states were sampled.
            if len(goal_tree) == 0 or inputs.getSampledGoalsCount() < len(goal_tree) // 2:
                state = inputs.nextGoal(ptc) if len(goal_tree) == 0 else inputs.nextGoal()
                if state is not None and points.is_finite(state):
                    goal_tree.add(points.from_state(state))
                if len(goal_tree) == 0:
                    ou.OMPL_ERROR(f"{name}: Unable to sample any valid states for goal tree")
                    status = ob.PlannerStatus.INVALID_GOAL
                    break
            progress.iterations += 1

            grow_start, cause = choose_tree(grew_start, len(start_tree), len(goal_tree), steps, collided)
            if grow_start != grew_start:
                steps, collided = 0, False
                if progress.iterations > 1:
                    swaps[cause] += 1
            grew_start = grow_start
            tree, other_tree = (start_tree, goal_tree) if grow_start else (goal_tree, start_tree)

            target, nearest = sample(grow_start)
            if target is None:
                continue
            grown, added, _ = extender.grow(tree, grow_start, target, nearest)
            if grown is Grow.TRAPPED:
                continue
            # Connect: walk the other tree towards the state just added until trapped or there.
            target = tree.state(added)  # stays valid: only the other tree grows while connecting
            connected, reached, gap = extender.grow(other_tree, not grow_start, target)
            steps += 1
            while connected is Grow.ADVANCED:
                # Each further step extends the node just added (why not the nearest policy's
                # choice: see policies.nearest_finder).
                connected, reached, gap = extender.grow(other_tree, not grow_start, target, nearest=reached)
                steps += 1
            # OMPL's "approx goal distance": the other tree's nearest node to the state just
            # added, after the connect (the node the last step extended, for the plain nearest).
            if connected is Grow.REACHED:
                gap = 0.0
            elif not nearest_is_euclidean:
                gap = other_tree.nearest(target)[1]
            self._distance_between_trees = min(self._distance_between_trees, gap)
            collided = connected is Grow.TRAPPED
            if collided:
                continue
            start_node, goal_node = (added, reached) if grow_start else (reached, added)
            start_root = points.ompl_state(start_tree.state(start_tree.root(start_node)), 0)
            goal_root = points.ompl_state(goal_tree.state(goal_tree.root(goal_node)), 1)
            if goal.isStartGoalPairValid(start_root, goal_root):
                path = self._path_points(start_node, goal_node)
                self._add_solution(points, path)
                progress.best_cost = sum(points.distance(a, b) for a, b in itertools.pairwise(path))
                status = ob.PlannerStatus.EXACT_SOLUTION
                break

        self._loop_state = (grew_start, steps, collided)
        ou.OMPL_INFORM(
            f"{name}: Created {len(start_tree) + len(goal_tree)} states "
            f"({len(start_tree)} start + {len(goal_tree)} goal)"
        )
        return result(status, progress.iterations)

    def _progress_extras(self) -> dict[str, Callable[[], str]]:
        return {
            "start tree size INTEGER": lambda: str(len(self._start_tree or ())),
            "goal tree size INTEGER": lambda: str(len(self._goal_tree or ())),
        }

    def _sample_context(
        self, points: Points, rng: np.random.Generator, counts: SamplerCounts, find_nearest: NearestFinder | None
    ) -> SampleContext:
        assert self._start_tree is not None and self._goal_tree is not None
        context = SampleContext(
            points,
            self._start_tree,
            self._goal_tree,
            rng.random,
            counts,
            find_nearest,
            self.settings.goal_bias,
            self.settings.min_quality,
            self.settings.uniform_rate,
        )
        if self.settings.sample_policy == "valid_sampler":
            si = self.getSpaceInformation()
            context.valid_sampler = self._valid_state_sampler()
            context.checker, context.scratch = si.getStateValidityChecker(), si.allocState()
        return context

    def _valid_state_sampler(self) -> ob.ValidStateSampler:
        """The valid-state sampler of ``sample_policy = valid_sampler``, allocated once per setup."""
        if self._valid_sampler is None:
            si = self.getSpaceInformation()
            allocate = self._valid_state_sampler_allocator
            sampler = si.allocValidStateSampler() if allocate is None else allocate(si)
            if not isinstance(sampler, ob.ValidStateSampler):
                raise TypeError(
                    f"{self.getName()}: the valid-state sampler allocator returned {type(sampler).__name__}, "
                    "not an ompl.base.ValidStateSampler"
                )
            self._valid_sampler = sampler
        return self._valid_sampler

    def _path_points(self, start_node: int, goal_node: int) -> list[Any]:
        """The points of the path start root -> start_node -> goal_node -> goal root; records
        the connection for the planner data."""
        start_tree, goal_tree = self._start_tree, self._goal_tree
        assert start_tree is not None and goal_tree is not None
        # The connecting step added the same state to both trees: step back one node
        # in a tree that made progress so the path does not repeat it.
        if start_tree.parent(start_node) != NO_PARENT:
            start_node = start_tree.parent(start_node)
        else:
            goal_node = goal_tree.parent(goal_node)
        self._connection = (start_node, goal_node)
        return [start_tree.state(node) for node in reversed(start_tree.branch(start_node))] + [
            goal_tree.state(node) for node in goal_tree.branch(goal_node)
        ]

    def _graph_properties(self) -> dict[str, str]:
        # As OMPL's RRTConnect, in C++'s default number format (inf until a connect was tried).
        return {"approx goal distance REAL": f"{self._distance_between_trees:g}"}

    def _fill_planner_data(self, data: ob.PlannerData, points: Points, keep_alive: list[ob.State]) -> None:
        """OMPL's RRT-Connect graph: start-tree vertices tag 1 (roots start vertices) with edges
        parent -> child, goal-tree vertices tag 2 (roots goal vertices) with edges child ->
        parent, and the edge joining the trees when a solve connected them, so a solution is
        a directed path from a start vertex to a goal vertex."""
        if self._start_tree is None or self._goal_tree is None:
            return
        start = self._add_tree(data, points, self._start_tree, START_TAG, keep_alive)
        goal = self._add_tree(data, points, self._goal_tree, GOAL_TAG, keep_alive, goal_tree=True)
        if self._connection is not None:
            start_node, goal_node = self._connection
            data.addEdge(start[start_node], goal[goal_node])


# -- named presets ---------------------------------------------------------------------
#
# The lab report's variants: each is plain RRT-Connect (alternating trees, no balancing)
# with one change, so it compares against stock RRT-Connect as the report's did.

_PLAIN = {"balance_tree_sizes": "0"}


class SwapLimitRRTConnect(BalancedRRTConnect):
    """Swap limiter: grow one tree until ``swap_steps`` connect steps were taken, then the other."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "swap_policy": "balance_steps"}


class CollisionSwapRRTConnect(BalancedRRTConnect):
    """Collision swap: grow one tree until a connect ends in a collision, then the other."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "swap_policy": "on_collision"}


class ExhaustedNodesRRTConnect(BalancedRRTConnect):
    """Exhausted nodes: a node with ``exhausted_after`` (15) failed extensions is no longer extended."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "nearest_policy": "exhausted"}


class ExhaustionRRTConnect(BalancedRRTConnect):
    """Exhaustion heuristic: nearest by distance x exhaustion scale of the node's failures."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "nearest_policy": "exhaustion"}


class NeighbourCostRRTConnect(BalancedRRTConnect):
    """Neighbour cost: keep a sample with the probability ``node_quality`` of its nearest node."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "sample_policy": "neighbour_quality"}


class GaussianPassageRRTConnect(BalancedRRTConnect):
    """Gaussian passage sampler: targets from :class:`~ompl_balance.samplers.PassageSampler`."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "sample_policy": "valid_sampler"}
    VALID_STATE_SAMPLER = PassageSampler


class ControlChosenRRTConnect(BalancedRRTConnect):
    """Control chosen: samples within the goal ball (``goal_ball``) and collision swap."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "swap_policy": "on_collision", "sample_policy": "goal_ball"}


class GoalBiasRRTConnect(BalancedRRTConnect):
    """Goal bias: with probability ``goal_bias`` (0.05) the target is the other tree's root."""

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "sample_policy": "goal_bias"}


#: Planner name -> class, for side-by-side runs (``ompl-balance compare --planners``).
PRESETS: dict[str, type[BalancedRRTConnect]] = {
    planner.__name__: planner
    for planner in (
        BalancedRRTConnect,
        SwapLimitRRTConnect,
        CollisionSwapRRTConnect,
        ExhaustedNodesRRTConnect,
        ExhaustionRRTConnect,
        NeighbourCostRRTConnect,
        GaussianPassageRRTConnect,
        ControlChosenRRTConnect,
        GoalBiasRRTConnect,
    )
}
