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

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np
from ompl import base as ob
from ompl import util as ou

from .core.counting import WorkCount
from .core.layout import has_layout
from .core.planner import GOAL_TAG, RANGE_AS_EXTENT_FRACTION, START_TAG, PlannerSpecs, TreePlanner
from .core.spaces import ArrayPoints, Points
from .core.trees import NO_PARENT, Tree
from .engine import python_loop
from .engine.compiled import CompiledEngine, CompiledRun, room_per_iteration
from .engine.events import LoopCounts, LoopRecord
from .engine.settings import RRTConnectSettings
from .engine.solve import Solve
from .policies import NodeFailures, SamplerCounts, SwapCause, SwapState
from .samplers import PassageSampler

#: ``allocate(si) -> ob.ValidStateSampler`` (a valid-state sampler class is one).
ValidStateSamplerAllocator = Callable[[Any], Any]

#: Nodes one iteration may add beyond which a solve stays on the Python engine (a tiny ``range``).
MAX_ROOM = 1 << 20


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
    engine: the loop that ran, ``"compiled"`` or ``"python"``; ``"python, then compiled"`` for a
        solve with ``engine=auto`` that began on Python and went on compiled once the compiled
        engine had loaded (the same trees as on either engine alone).
    checks: how the compiled engine made the checks: ``"kernel"`` (the checker's compiled
        kernels) or ``"python"`` (``si.isValid``/``si.checkMotion``); ``"python"`` on the Python engine.
    exits: calls from compiled code out to Python (FCL queries a kernel cannot decide, a
        Python checker's calls); 0 on the Python engine.
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
    engine: str = "python"
    checks: str = "python"
    exits: int = 0

    def as_dict(self) -> dict[str, float | int | str]:
        return asdict(self)


@dataclass
class _LoopOutcome:
    """What :meth:`BalancedRRTConnect._plan` measured, for :class:`RunStats`."""

    counts: LoopCounts
    sampler: SamplerCounts
    start_tree_size: int
    goal_tree_size: int
    engine: str = "python"
    checks: str = "python"


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

    ``planner.loop_record = LoopRecord()`` (:class:`~ompl_balance.engine.events.LoopRecord`)
    makes the following solves append every tree choice and extension step to it, on
    either engine; ``None`` (the default) records nothing.
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
        self._engine = CompiledEngine()  # what compiled solves reuse
        # The trees and what the policies keep per node and between iterations: kept across
        # solves until clear().
        self._start_tree: Tree | None = None
        self._goal_tree: Tree | None = None
        self._failures: dict[Tree, NodeFailures] = {}
        self._swap_state = SwapState()
        # For the planner data, as OMPL's: the nodes joined by the last solution (start tree,
        # goal tree), and the least distance between the trees seen after a connect.
        self._connection: tuple[int, int] | None = None
        self._distance_between_trees = math.inf
        self.loop_record: LoopRecord | None = None

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
        if self.settings.engine != "python" and not self._why_not_compiled():
            self._load_engine(wait=self.settings.engine == "compiled")
        self._ready_trees()

    def wait_for_engine(self) -> None:
        """Make the compiled engine ready for this planner's solves now (after ``setup()``), as
        ``engine=compiled`` does at setup; with ``engine=auto`` it loads in the background
        instead, and solves run on the Python engine until it is ready. Benchmarks call this
        so that every timed solve runs on the same engine. Nothing to do where the compiled
        engine does not apply."""
        if self._points is None:  # (not set up)
            self.setup()
        if self.settings.engine != "python" and not self._why_not_compiled():
            self._load_engine(wait=True)
            self._ready_trees()

    def _load_engine(self, wait: bool) -> None:
        points = self._points
        assert isinstance(points, ArrayPoints)  # (checked by _why_not_compiled)
        self._engine.load(self.getSpaceInformation(), points.layout, self.settings.engine, wait=wait)

    def _check_policies(self) -> None:
        """Refuse combinations of policies and parameters that cannot do what they say."""
        name, settings = self.getName(), self.settings
        if self.draws_from_ompl_rng and settings.seed > 0:
            raise ValueError(
                f"{name}: sample_policy=valid_sampler with seed={settings.seed}: a valid-state sampler "
                "draws from OMPL's RNG, which the seed parameter cannot repeat; use seed=0 (and "
                "ompl.util.RNG.setSeed) or another sample_policy"
            )
        if settings.engine == "compiled":
            reason = self._why_not_compiled()
            if reason:
                raise ValueError(f"{name}: engine=compiled cannot run {reason}; use engine=auto or engine=python")

    def _why_not_compiled(self, points: Points | None = None) -> str:
        """Why the compiled engine cannot run this planner's solves ('' when it can)."""
        if self.settings.sample_policy == "valid_sampler":
            return "sample_policy=valid_sampler (a valid-state sampler is an OMPL object called per sample)"
        space = self.getSpaceInformation().getStateSpace()
        if points is None:
            if not has_layout(space):
                return f"a {type(space).__name__} (it plans in real-vector, SO(2), SO(3), SE(2), SE(3) spaces and their compounds)"
        elif not isinstance(points, ArrayPoints):
            return f"a {type(space).__name__} (it plans in real-vector, SO(2), SO(3), SE(2), SE(3) spaces and their compounds)"
        return ""

    def _before_solve(self, ptc: ob.PlannerTerminationCondition) -> None:
        self._check_policies()

    def clear(self) -> None:
        super().clear()
        # The trees are emptied, not made anew (as OMPL's planners clear their nearest-neighbour
        # structures): their arrays, and the compiled engine's for them, serve the next solve.
        for tree in (self._start_tree, self._goal_tree):
            if tree is not None:
                tree.clear()
        for failures in self._failures.values():
            failures.clear()
        self._swap_state = SwapState()
        self._connection = None
        self._distance_between_trees = math.inf
        if self._points is not None:  # (set up)
            self._ready_trees()

    def _ready_trees(self) -> None:
        """Make the planner's trees (:meth:`_trees`) and, where the compiled engine is loaded, its
        arrays for them and its settings now (as OMPL's planners allocate at setup and clear: a
        solve's time does not count them)."""
        trees = self._trees()
        points = self._points
        if isinstance(points, ArrayPoints) and (room := self._room(points)) <= MAX_ROOM:
            failures = (self._failures[trees[0]], self._failures[trees[1]])
            self._engine.prepare(points, self.settings, self.loop_record is not None, trees, failures, room)

    def _trees(self) -> tuple[Tree, Tree]:
        """The planner's trees (new, empty ones if it has none) and what the policies keep per node."""
        points = self._points
        assert points is not None  # (set up)
        if self._start_tree is None or self._goal_tree is None:
            self._start_tree, self._goal_tree = points.new_tree(), points.new_tree()
            self._failures = {self._start_tree: NodeFailures(), self._goal_tree: NodeFailures()}
        return self._start_tree, self._goal_tree

    # -- solving -------------------------------------------------------------------

    def _plan(
        self, ptc: ob.PlannerTerminationCondition, points: Points, rng: np.random.Generator
    ) -> tuple[ob.PlannerStatus.PlannerStatusType, _LoopOutcome]:
        """The grow/connect loop on the engine the settings choose; returns the status and what it measured."""
        name = self.getName()
        start_tree, goal_tree = self._trees()

        def result(
            status: ob.PlannerStatus.PlannerStatusType,
            solve: Solve | None = None,
            engine: str = "python",
            checks: str = "python",
        ) -> tuple[Any, _LoopOutcome]:
            counts = LoopCounts() if solve is None else solve.counts
            sampler = SamplerCounts() if solve is None else solve.sampler_counts
            return status, _LoopOutcome(counts, sampler, len(start_tree), len(goal_tree), engine, checks)

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
        solve = self._solve(points, rng, inputs, goal)
        compiled = self._compiled_engine(solve)
        engine, checks = "compiled", "python"
        if compiled is None:
            # engine=auto while the compiled engine loads: it takes over once loaded
            loaded = (lambda: self._compiled_engine(solve) is not None) if self.settings.engine == "auto" else None
            result_status = python_loop.run(solve, ptc, loaded)
            if result_status is None:
                compiled, engine = self._compiled_engine(solve), "python, then compiled"
                assert compiled is not None  # (loaded: it stays so)
            else:
                status, engine = result_status, "python"
        if compiled is not None:
            status, checks = compiled(ptc)
        self._distance_between_trees = solve.tree_gap
        if status == ob.PlannerStatus.EXACT_SOLUTION:
            assert solve.connection is not None
            path = self._add_solution(points, self._path_points(*solve.connection))
            self.progress.best_cost = path.length()
        ou.OMPL_INFORM(
            f"{name}: Created {len(start_tree) + len(goal_tree)} states "
            f"({len(start_tree)} start + {len(goal_tree)} goal)"
        )
        return result(status, solve, engine, checks)

    def _solve(self, points: Points, rng: np.random.Generator, inputs: ob.PlannerInputStates, goal: Any) -> Solve:
        """This solve around the planner's trees."""
        assert self._start_tree is not None and self._goal_tree is not None
        settings = self.settings
        return Solve(
            name=self.getName(),
            si=self.getSpaceInformation(),
            points=points,
            settings=settings,
            start_tree=self._start_tree,
            goal_tree=self._goal_tree,
            failures=self._failures,
            swap_state=self._swap_state,
            inputs=inputs,
            goal=goal,
            progress=self.progress,
            rng=rng,
            record=self.loop_record,
            valid_sampler=self._valid_state_sampler() if settings.sample_policy == "valid_sampler" else None,
            tree_gap=self._distance_between_trees,
        )

    def _compiled_engine(self, solve: Solve) -> CompiledRun | None:
        """The compiled engine's run of ``solve``, or ``None`` when this solve runs on the Python engine."""
        settings = self.settings
        if settings.engine == "python" or self._why_not_compiled(solve.points):
            return None
        points = solve.points
        assert isinstance(points, ArrayPoints)
        room = self._room(points)
        if room > MAX_ROOM:
            if settings.engine == "compiled":
                raise ValueError(
                    f"{self.getName()}: engine=compiled with range={settings.range:g}: an iteration may add "
                    f"{room} nodes; use a larger range or engine=python"
                )
            return None
        return self._engine.run_of(solve, points.layout, room, settings.engine, self.getName())

    def _room(self, points: ArrayPoints) -> int:
        """The nodes one iteration of the compiled loop may add to a tree (its arrays keep room for them)."""
        extent = self.getSpaceInformation().getStateSpace().getMaximumExtent()
        return room_per_iteration(points.layout, extent, self.settings.range, self.settings.intermediate_states)

    def _progress_extras(self) -> dict[str, Callable[[], str]]:
        return {
            "start tree size INTEGER": lambda: str(len(self._start_tree or ())),
            "goal tree size INTEGER": lambda: str(len(self._goal_tree or ())),
        }

    def _statistics(self, status: str, work: WorkCount, elapsed: float, outcome: _LoopOutcome) -> RunStats:
        counts, swaps = outcome.counts, outcome.counts.swaps
        return RunStats(
            status=status,
            iterations=counts.iterations,
            start_tree_size=outcome.start_tree_size,
            goal_tree_size=outcome.goal_tree_size,
            tree_swaps=sum(swaps),
            states_checked=work.states_checked,
            motions_checked=work.motions_checked,
            time=elapsed,
            distance_queries=work.distance_queries,
            swaps_alternate=swaps[SwapCause.ALTERNATE],
            swaps_balance=swaps[SwapCause.BALANCE],
            swaps_steps=swaps[SwapCause.STEPS],
            swaps_collision=swaps[SwapCause.COLLISION],
            sampler_rejections=outcome.sampler.rejections,
            sampler_checks=outcome.sampler.checks,
            engine=outcome.engine,
            checks=outcome.checks,
            exits=counts.exits,
        )

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

    POLICIES: ClassVar[dict[str, str]] = {**_PLAIN, "swap_policy": "swap_limit"}


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
