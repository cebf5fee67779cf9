"""Planners: RRT-Connect with tree balancing.

:class:`BalancedRRTConnect` is OMPL's ``RRTConnect`` (``src/ompl/geometric/planners/
rrt/src/RRTConnect.cpp``) written as a Python ``ob.Planner``, plus one rule: when the
two trees drift apart in size, grow the smaller one (Kuffner's recommendation, as VAMP
does). Everything else keeps OMPL's semantics: trees rooted at every start state and
at goal states sampled while fewer than half of the goal tree's states were sampled,
``range`` defaulting to 0.2 x the space's maximum extent, the grow/connect loop, the
planner statuses, the solution added with ``pdef.addSolutionPath``.

Differences from stock, on purpose:

* no approximate solutions: a run that does not connect the trees ends with
  ``TIMEOUT`` and adds no path;
* ``plannerData()`` replaces ``getPlannerData`` (a Python ``getPlannerData`` aborts
  the process when C++ calls it), so ``ss.getPlannerData`` returns an empty graph;
* each solve reports a :class:`RunStats` record (``planner.stats``).
"""

from __future__ import annotations

import enum
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from .counting import ensure_counting, read_work
from .params import ParamSet
from .spaces import RealVectorPoints, StatePoints, points_for
from .trees import NO_PARENT

#: OMPL's default range as a fraction of the space's maximum extent
#: (``magic::MAX_MOTION_LENGTH_AS_SPACE_EXTENT_FRACTION``).
RANGE_AS_EXTENT_FRACTION = 0.2

START_TAG = 1
GOAL_TAG = 2


class Grow(enum.Enum):
    """Outcome of one extension step, as OMPL's ``RRTConnect::GrowState``."""

    TRAPPED = 0  # no progress: the motion was invalid
    ADVANCED = 1  # a step of length ``range`` towards the target was added
    REACHED = 2  # the target itself was added


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
    trees are equal) the planner alternates as stock RRT-Connect does.
    """
    if not balance or start_size == goal_size:
        return None
    if tree_size_ratio(start_size, goal_size) >= max_ratio:
        return start_size < goal_size
    return None


@dataclass
class RunStats:
    """The work one ``solve()`` did.

    Attributes
    ----------
    status: the ``PlannerStatus`` as a string (``"Exact solution"``, ``"Timeout"``, ...).
    iterations: main-loop iterations (one sample each).
    start_tree_size, goal_tree_size: nodes in each tree when the solve ended
        (cumulative over solves until ``clear()``, as the trees are).
    tree_swaps: iterations that grew a different tree than the iteration before.
    states_checked: states whose validity the space information's checker decided
        during this solve, including those inside motion checks.
    motions_checked: motions handed to the motion validator during this solve.
    time: wall-clock seconds spent in ``solve()``.
    """

    status: str
    iterations: int
    start_tree_size: int
    goal_tree_size: int
    tree_swaps: int
    states_checked: int
    motions_checked: int
    time: float

    def as_dict(self) -> dict[str, float | int | str]:
        return asdict(self)


def termination_condition(limit: ob.PlannerTerminationCondition | float | Callable[[], bool]) -> ob.PlannerTerminationCondition:
    """A ``PlannerTerminationCondition`` from what ``solve`` was given.

    C++ callers (``SimpleSetup``, ``Benchmark``) pass a condition; Python callers may
    pass a time limit in seconds (must be positive and finite) or a callable that
    returns ``True`` when planning should stop.
    """
    if isinstance(limit, ob.PlannerTerminationCondition):
        return limit
    if isinstance(limit, (int, float)) and not isinstance(limit, bool):
        if not math.isfinite(limit) or limit <= 0:
            raise ValueError(f"solve() time limit must be a positive number of seconds, got {limit!r}")
        return ob.timedPlannerTerminationCondition(float(limit))
    if callable(limit):
        return ob.PlannerTerminationCondition(limit)
    raise TypeError(
        f"solve() takes a PlannerTerminationCondition, a time limit in seconds or a callable, got {type(limit).__name__}"
    )


class BalancedRRTConnect(ob.Planner):
    """RRT-Connect that grows the smaller tree when the trees drift apart in size.

    Parameters (``planner.params()``, OMPL string forms; camelCase accessors too):

    ``range`` (float, default 0 = 0.2 x the space's maximum extent at ``setup()``)
        longest motion added to a tree in one step.
    ``intermediate_states`` (bool, default false)
        add the states along each motion (at the validity-checking resolution) to the
        tree, as OMPL's ``RRTConnectIntermediate``.
    ``balance_tree_sizes`` (bool, default true)
        apply the balancing rule (:func:`balance_choice`).
    ``max_tree_size_ratio`` (float >= 0, default 1.0)
        grow the smaller tree once ``|a - b| / min(a, b)`` reaches this; 1.0 means
        "once it is less than half the size of the other".
    ``seed`` (int >= 0, default 0)
        0: each solve draws its seed from an OMPL ``RNG`` (reproducible from
        ``ompl.util.RNG.setSeed``, different from one solve to the next); > 0: every
        solve uses this seed. Applies to real-vector spaces, where sampling is done in
        numpy; other spaces sample with OMPL's own sampler and OMPL's seed.
    """

    def __init__(self, si: ob.SpaceInformation, name: str = "BalancedRRTConnect") -> None:
        super().__init__(si, name)
        self._range = 0.0
        self._intermediate_states = False
        self._balance_tree_sizes = True
        self._max_tree_size_ratio = 1.0
        self._seed = 0
        self._params = ParamSet()
        self._params.declareParam("range", self.setRange, self.getRange, "0.:1.:10000.", float)
        self._params.declareParam("intermediate_states", self.setIntermediateStates, self.getIntermediateStates, "0,1", bool)
        self._params.declareParam("balance_tree_sizes", self.setBalanceTreeSizes, self.getBalanceTreeSizes, "0,1", bool)
        self._params.declareParam("max_tree_size_ratio", self.setMaxTreeSizeRatio, self.getMaxTreeSizeRatio, "0.:0.05:10.", float)
        self._params.declareParam("seed", self.setSeed, self.getSeed, "0:1:1000000", int)
        self._rng = ou.RNG()  # per-planner stream, seeded from OMPL's global seed
        self._points: RealVectorPoints | StatePoints | None = None
        self._start_tree = None
        self._goal_tree = None
        self._grow_start_next = True
        self.stats: RunStats | None = None

    # -- parameters ---------------------------------------------------------------

    def params(self) -> ParamSet:
        """This planner's parameters (OMPL's ``ParamSet`` semantics)."""
        return self._params

    def setRange(self, distance: float) -> None:  # noqa: N802 (OMPL's names)
        if not math.isfinite(distance) or distance < 0:
            raise ValueError("range must be a finite distance >= 0 (0 picks 0.2 x the space's extent)")
        self._range = float(distance)

    def getRange(self) -> float:  # noqa: N802
        return self._range

    def setIntermediateStates(self, add: bool) -> None:  # noqa: N802
        self._intermediate_states = bool(add)

    def getIntermediateStates(self) -> bool:  # noqa: N802
        return self._intermediate_states

    def setBalanceTreeSizes(self, balance: bool) -> None:  # noqa: N802
        self._balance_tree_sizes = bool(balance)

    def getBalanceTreeSizes(self) -> bool:  # noqa: N802
        return self._balance_tree_sizes

    def setMaxTreeSizeRatio(self, ratio: float) -> None:  # noqa: N802
        if not math.isfinite(ratio) or ratio < 0:
            raise ValueError("max_tree_size_ratio must be a finite number >= 0")
        self._max_tree_size_ratio = float(ratio)

    def getMaxTreeSizeRatio(self) -> float:  # noqa: N802
        return self._max_tree_size_ratio

    def setSeed(self, seed: int) -> None:  # noqa: N802
        if seed < 0:
            raise ValueError("seed must be >= 0 (0 draws each solve's seed from OMPL's RNG)")
        self._seed = int(seed)

    def getSeed(self) -> int:  # noqa: N802
        return self._seed

    # -- planner life cycle -------------------------------------------------------

    def setup(self) -> None:
        super().setup()
        si = self.getSpaceInformation()
        ensure_counting(si)
        if self._range < 1e-12:
            self._range = RANGE_AS_EXTENT_FRACTION * si.getMaximumExtent()
            ou.OMPL_INFORM(f"{self.getName()}: range computed to be {self._range:g}")

    def clear(self) -> None:
        super().clear()
        self._start_tree = self._goal_tree = None
        self._grow_start_next = True
        self.stats = None

    # -- solving -------------------------------------------------------------------

    def solve(self, ptc: ob.PlannerTerminationCondition | float | Callable[[], bool]) -> ob.PlannerStatus:
        """Plan until a solution is found or ``ptc`` says stop (seconds, callable or condition)."""
        ptc = termination_condition(ptc)
        self.checkValidity()
        si = self.getSpaceInformation()
        began = time.perf_counter()
        work_before = read_work(si)
        self._points = points_for(si, np.random.default_rng(self._seed or self._rng.uniformInt(1, 2**31 - 2)))
        if self._start_tree is None:
            self._start_tree, self._goal_tree = self._points.new_tree(), self._points.new_tree()
        status, iterations, swaps = self._plan(ptc)
        work = read_work(si) - work_before
        self.stats = RunStats(
            status=ob.PlannerStatus(status).asString(),
            iterations=iterations,
            start_tree_size=len(self._start_tree),
            goal_tree_size=len(self._goal_tree),
            tree_swaps=swaps,
            states_checked=work.states_checked,
            motions_checked=work.motions_checked,
            time=time.perf_counter() - began,
        )
        return ob.PlannerStatus(status)

    def _plan(self, ptc: ob.PlannerTerminationCondition) -> tuple[ob.PlannerStatus.PlannerStatusType, int, int]:
        """The grow/connect loop; returns (status, iterations, tree swaps)."""
        name = self.getName()
        pdef = self.getProblemDefinition()  # keep the owner alive while its states are used
        goal = pdef.getGoal()
        if not isinstance(goal, ob.GoalSampleableRegion):
            ou.OMPL_ERROR(f"{name}: Unknown type of goal (a GoalSampleableRegion is needed)")
            return ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE, 0, 0

        points, start_tree, goal_tree = self._points, self._start_tree, self._goal_tree
        inputs = self.getPlannerInputStates()
        while (state := inputs.nextStart()) is not None:
            start_tree.add(points.from_state(state))
        if len(start_tree) == 0:
            ou.OMPL_ERROR(f"{name}: Motion planning start tree could not be initialized!")
            return ob.PlannerStatus.INVALID_START, 0, 0
        if not goal.couldSample():
            ou.OMPL_ERROR(f"{name}: Insufficient states in sampleable goal region")
            return ob.PlannerStatus.INVALID_GOAL, 0, 0
        ou.OMPL_INFORM(f"{name}: Starting planning with {len(start_tree) + len(goal_tree)} states already in datastructure")

        status = ob.PlannerStatus.TIMEOUT
        iterations = swaps = 0
        while not ptc():
            # Goal states join the goal tree while fewer than half of its states were sampled.
            if len(goal_tree) == 0 or inputs.getSampledGoalsCount() < len(goal_tree) // 2:
                state = inputs.nextGoal(ptc) if len(goal_tree) == 0 else inputs.nextGoal()
                if state is not None:
                    goal_tree.add(points.from_state(state))
                if len(goal_tree) == 0:
                    ou.OMPL_ERROR(f"{name}: Unable to sample any valid states for goal tree")
                    status = ob.PlannerStatus.INVALID_GOAL
                    break
            iterations += 1

            grow_start = balance_choice(len(start_tree), len(goal_tree), self._balance_tree_sizes, self._max_tree_size_ratio)
            if grow_start is None:
                grow_start = self._grow_start_next
            swaps += iterations > 1 and grow_start != (not self._grow_start_next)
            self._grow_start_next = not grow_start
            tree, other_tree = (start_tree, goal_tree) if grow_start else (goal_tree, start_tree)

            grown, added = self._grow(tree, grow_start, points.sample())
            if grown is Grow.TRAPPED:
                continue
            # Connect: walk the other tree towards the state just added until trapped or there.
            target = tree.state(added)  # stays valid: only the other tree grows while connecting
            connected, reached = self._grow(other_tree, not grow_start, target)
            while connected is Grow.ADVANCED:
                # The state just added is the other tree's nearest to the target (it is
                # one range closer than any before), so the search is skipped.
                connected, reached = self._grow(other_tree, not grow_start, target, nearest=reached)
            if connected is not Grow.REACHED:
                continue
            start_node, goal_node = (added, reached) if grow_start else (reached, added)
            start_root = points.ompl_state(start_tree.state(start_tree.root(start_node)), 0)
            goal_root = points.ompl_state(goal_tree.state(goal_tree.root(goal_node)), 1)
            if goal.isStartGoalPairValid(start_root, goal_root):
                self._add_solution(pdef, start_node, goal_node)
                status = ob.PlannerStatus.EXACT_SOLUTION
                break

        ou.OMPL_INFORM(
            f"{name}: Created {len(start_tree) + len(goal_tree)} states "
            f"({len(start_tree)} start + {len(goal_tree)} goal)"
        )
        return status, iterations, swaps

    def _grow(self, tree, from_start: bool, target, nearest: int | None = None) -> tuple[Grow, int]:
        """Extend ``tree`` one step towards ``target``; return the outcome and the node added.

        Motions in the start tree are checked from the tree outwards; in the goal tree
        they run from the new state into the tree, so the new state is checked first
        (``checkMotion`` assumes its first state valid), exactly as OMPL does.
        """
        points = self._points
        if nearest is None:
            nearest, distance = tree.nearest(target)
        else:
            distance = points.distance(tree.state(nearest), target)
        near = tree.state(nearest)
        reach = distance <= self._range
        new = target if reach else points.interpolate(near, target, self._range / distance)
        if not reach and points.equal(near, new):
            return Grow.TRAPPED, NO_PARENT

        si = self.getSpaceInformation()
        near_state, new_state = points.ompl_state(near, 0), points.ompl_state(new, 1)
        if from_start:
            valid = si.checkMotion(near_state, new_state)
        else:
            valid = si.isValid(new_state) and si.checkMotion(new_state, near_state)
        if not valid:
            return Grow.TRAPPED, NO_PARENT

        if self._intermediate_states:
            # States along the motion, ordered away from the tree's root.
            added = nearest
            for point in points.segment_points(near, new):
                added = tree.add(point, added)
        else:
            added = tree.add(new, nearest)
        return (Grow.REACHED if reach else Grow.ADVANCED), added

    def _add_solution(self, pdef: ob.ProblemDefinition, start_node: int, goal_node: int) -> None:
        """Add the path start root -> start_node -> goal_node -> goal root to ``pdef``."""
        start_tree, goal_tree, points = self._start_tree, self._goal_tree, self._points
        # The connecting step added the same state to both trees: step back one node
        # in a tree that made progress so the path does not repeat it.
        if start_tree.parent(start_node) != NO_PARENT:
            start_node = start_tree.parent(start_node)
        else:
            goal_node = goal_tree.parent(goal_node)
        path = og.PathGeometric(self.getSpaceInformation())
        for node in reversed(start_tree.branch(start_node)):
            path.append(points.ompl_state(start_tree.state(node)))
        for node in goal_tree.branch(goal_node):
            path.append(points.ompl_state(goal_tree.state(node)))
        pdef.addSolutionPath(path, False, 0.0, self.getName())

    # -- introspection ---------------------------------------------------------------

    def plannerData(self) -> ob.PlannerData:  # noqa: N802
        """Both trees as an ``ob.PlannerData``.

        Start-tree vertices carry tag 1 (roots are start vertices), goal-tree vertices
        tag 2 (roots are goal vertices); edges run parent -> child in both trees. The
        graph owns copies of the states. (``ss.getPlannerData`` returns an empty graph
        for Python planners: OMPL's bindings cannot call back into them safely.)
        """
        si = self.getSpaceInformation()
        data = ob.PlannerData(si)
        if self._start_tree is None:
            return data
        keep_alive = []  # the graph points into these states until it is decoupled
        for tree, tag, add_root in (
            (self._start_tree, START_TAG, data.addStartVertex),
            (self._goal_tree, GOAL_TAG, data.addGoalVertex),
        ):
            indices = []
            for node in range(len(tree)):
                state = self._points.new_state(tree.state(node))
                keep_alive.append(state)
                vertex = ob.PlannerDataVertex(state, tag)
                indices.append(add_root(vertex) if tree.parent(node) == NO_PARENT else data.addVertex(vertex))
            for node in range(len(tree)):
                if tree.parent(node) != NO_PARENT:
                    data.addEdge(indices[tree.parent(node)], indices[node])
        data.decoupleFromPlanner()
        return data
