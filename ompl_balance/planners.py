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

The same planner carries the classroom RRT-Connect variants (issue #6) as orthogonal
policies, each a parameter: ``swap_policy`` (which tree grows), ``nearest_policy``
(which node it grows from) and ``sample_policy`` (towards what). :data:`PRESETS` names
the combinations the lab compared (``SwapLimitRRTConnect``, ...); docs/variants.md
measures them.
"""

from __future__ import annotations

import enum
import math
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from .counting import ensure_counting, read_work
from .gamma import estimate_ball_radius_constant, rewire_radius
from .params import ParamSet
from .samplers import PassageSampler
from .spaces import RealVectorPoints, StatePoints, points_for, prepare
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


# -- policies --------------------------------------------------------------------------
#
# Each policy is picked once per solve (a function chosen by name), so a policy that is
# not selected costs the grow/connect loop nothing.

#: ``swap_policy`` choices: which tree an iteration grows.
SWAP_POLICIES = ("alternate", "balance_nodes", "balance_steps", "on_collision")
#: ``nearest_policy`` choices: which node a tree is extended from.
NEAREST_POLICIES = ("euclidean", "exhausted", "exhaustion")
#: ``sample_policy`` choices: where an iteration's target comes from.
SAMPLE_POLICIES = ("uniform", "goal_bias", "goal_ball", "neighbour_quality", "valid_sampler")
#: Why a swap happened; ``RunStats.swaps_<cause>`` counts each.
SWAP_CAUSES = ("alternate", "balance", "steps", "collision")
ALTERNATE, BALANCE, STEPS, COLLISION = range(len(SWAP_CAUSES))

#: Draws a rejecting sample policy makes before the iteration is given up (OMPL's
#: ``magic::MAX_VALID_SAMPLE_ATTEMPTS``).
SAMPLE_ATTEMPTS = 100

#: ``choose(grew_start, start_size, goal_size, steps, collided) -> (grow_start, cause)``
TreeChooser = Callable[[bool, int, int, int, bool], tuple[bool, int]]


def tree_chooser(swap_policy: str, max_tree_size_ratio: float = 1.0, swap_steps: int = 1) -> TreeChooser:
    """The rule of ``swap_policy`` as a function ``choose``.

    ``choose(grew_start, start_size, goal_size, steps, collided)`` is given which tree
    the previous iteration grew (``True``: the start tree), the tree sizes, the
    extension steps taken in connect loops since the last swap, and whether the last
    connect ended in a collision (the last two restart at every swap). It returns
    ``(grow_start, cause)``, ``cause`` indexing :data:`SWAP_CAUSES` (why the choice is a
    swap, when it is one):

    ``alternate``      the other tree, every iteration (stock RRT-Connect);
    ``balance_nodes``  the smaller tree when :func:`balance_choice` engages, else alternate;
    ``balance_steps``  the same tree until ``swap_steps`` connect steps were taken since
                       the last swap, then the other (the lab's swap limiter);
    ``on_collision``   the same tree until a connect ends in a collision, then the other.
    """
    if swap_policy == "alternate":
        return lambda grew_start, start_size, goal_size, steps, collided: (not grew_start, ALTERNATE)
    if swap_policy == "balance_nodes":

        def balance_nodes(grew_start: bool, start_size: int, goal_size: int, steps: int, collided: bool) -> tuple[bool, int]:
            smaller_is_start = balance_choice(start_size, goal_size, True, max_tree_size_ratio)
            if smaller_is_start is None:
                return not grew_start, ALTERNATE
            return smaller_is_start, BALANCE

        return balance_nodes
    if swap_policy == "balance_steps":
        return lambda grew_start, start_size, goal_size, steps, collided: (
            (not grew_start if steps >= swap_steps else grew_start), STEPS
        )
    if swap_policy == "on_collision":
        return lambda grew_start, start_size, goal_size, steps, collided: (
            (not grew_start if collided else grew_start), COLLISION
        )
    raise ValueError(f"unknown swap_policy {swap_policy!r}; accepted: {', '.join(SWAP_POLICIES)}")


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


class NodeCosts:
    """``distance(start, node) + distance(node, goal)`` per node of one tree, and the largest.

    Computed for the nodes added since the last :meth:`update`, so each node once.
    """

    def __init__(self, distance: Callable) -> None:
        self._distance = distance
        self.values: list[float] = []
        self.max = 0.0

    def update(self, tree, start, goal) -> None:
        distance = self._distance
        for node in range(len(self.values), len(tree)):
            point = tree.state(node)
            cost = distance(start, point) + distance(point, goal)
            self.values.append(cost)
            self.max = max(self.max, cost)


#: ``(grew_start, steps, collided)`` before the first iteration: as if the goal tree had
#: just been grown and every rule were due to swap, so the first iteration grows the start tree.
_FIRST_LOOP_STATE = (False, sys.maxsize, True)


def _one_of(name: str, value: str, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(choices)}, got {value!r}")
    return value


def _at_least_one(name: str, value: int) -> int:
    if value < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value}")
    return int(value)


def _probability(name: str, value: float) -> float:
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be a number in [0, 1], got {value}")
    return float(value)


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
        during this solve, including those inside motion checks and those a
        valid-state sampler checked.
    motions_checked: motions handed to the motion validator during this solve.
    time: wall-clock seconds spent in ``solve()``.
    swaps_alternate, swaps_balance, swaps_steps, swaps_collision: ``tree_swaps`` by
        cause (:data:`SWAP_CAUSES`): alternation, the balancing rule, the swap limit
        of ``balance_steps``, a connect ending in collision under ``on_collision``.
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
    swaps_alternate: int = 0
    swaps_balance: int = 0
    swaps_steps: int = 0
    swaps_collision: int = 0
    sampler_rejections: int = 0
    sampler_checks: int = 0

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
    """RRT-Connect with tree balancing and the classroom variants as orthogonal policies.

    Parameters (``planner.params()``, OMPL string forms; camelCase accessors too):

    ``range`` (float, default 0 = 0.2 x the space's maximum extent at ``setup()``)
        longest motion added to a tree in one step.
    ``intermediate_states`` (bool, default false)
        add the states along each motion (at the validity-checking resolution) to the
        tree, as OMPL's ``RRTConnectIntermediate``.
    ``swap_policy`` (``alternate`` | ``balance_nodes`` | ``balance_steps`` |
    ``on_collision``, default ``balance_nodes``)
        which tree each iteration grows (:func:`tree_chooser`).
    ``balance_tree_sizes`` (bool, default true)
        the same as ``swap_policy == balance_nodes``: setting it true selects
        ``balance_nodes``; setting it false turns ``balance_nodes`` into ``alternate``
        and leaves the other swap policies alone.
    ``max_tree_size_ratio`` (float >= 0, default 1.0)
        ``balance_nodes`` grows the smaller tree once ``|a - b| / min(a, b)`` reaches
        this; 1.0 means "once it is less than half the size of the other".
    ``swap_steps`` (int >= 1, default 10)
        ``balance_steps`` swaps trees once this many connect steps were taken.
    ``nearest_policy`` (``euclidean`` | ``exhausted`` | ``exhaustion``, default ``euclidean``)
        the node a tree grows from: the nearest; the nearest with fewer than
        ``exhausted_after`` failed extensions (:func:`nearest_not_exhausted`); the one
        with the least distance x :func:`exhaustion_scale` (``exhaustion_target``).
        Failures are counted per node while one of the last two is selected.
    ``exhausted_after`` (int >= 1, default 15), ``exhaustion_target`` (int >= 1, default 5)
    ``sample_policy`` (``uniform`` | ``goal_bias`` | ``goal_ball`` |
    ``neighbour_quality`` | ``valid_sampler``, default ``uniform``)
        the target of each iteration: uniform in the bounds; with probability
        ``goal_bias`` the other tree's first root (the goal when growing the start
        tree, the start when growing the goal tree); a uniform sample no farther from
        the other tree's first root than start and goal are apart (``goal_ball``, the
        lab's "control chosen"); a uniform sample kept with probability
        :func:`node_quality` of its nearest node (``min_quality``); a sample of the
        space information's valid-state sampler (``si.allocValidStateSampler()``, or
        the allocator given to :meth:`setValidStateSamplerAllocator`), or a uniform
        sample when the valid-state sampler finds none (e.g. no obstacle near). The
        rejecting policies give up the iteration after :data:`SAMPLE_ATTEMPTS` draws.
    ``goal_bias`` (float in [0, 1], default 0.05), ``min_quality`` (float in [0, 1], default 0)
    ``seed`` (int >= 0, default 0)
        0: each solve draws its seed from an OMPL ``RNG`` (reproducible from
        ``ompl.util.RNG.setSeed``, different from one solve to the next); > 0: every
        solve uses this seed. Applies to real-vector spaces, where sampling is done in
        numpy; other spaces sample with OMPL's own sampler and OMPL's seed.
        ``seed > 0`` with ``sample_policy = valid_sampler`` is refused at ``setup()``:
        a valid-state sampler draws from OMPL's RNG, which the seed cannot repeat.

    Subclasses preset policies through ``POLICIES`` (parameter values set at
    construction) and ``VALID_STATE_SAMPLER`` (an allocator); their planner name is
    their class name. See :data:`PRESETS`.
    """

    POLICIES: dict[str, str] = {}
    VALID_STATE_SAMPLER: Callable[[ob.SpaceInformation], ob.ValidStateSampler] | None = None

    def __init__(self, si: ob.SpaceInformation, name: str | None = None) -> None:
        super().__init__(si, name or type(self).__name__)
        self._range = 0.0
        self._intermediate_states = False
        self._swap_policy = "balance_nodes"
        self._max_tree_size_ratio = 1.0
        self._swap_steps = 10
        self._nearest_policy = "euclidean"
        self._exhausted_after = 15
        self._exhaustion_target = 5
        self._sample_policy = "uniform"
        self._goal_bias = 0.05
        self._min_quality = 0.0
        self._seed = 0
        self._params = ParamSet()
        declare = self._params.declareParam
        declare("range", self.setRange, self.getRange, "0.:1.:10000.", float)
        declare("intermediate_states", self.setIntermediateStates, self.getIntermediateStates, "0,1", bool)
        declare("balance_tree_sizes", self.setBalanceTreeSizes, self.getBalanceTreeSizes, "0,1", bool)
        declare("max_tree_size_ratio", self.setMaxTreeSizeRatio, self.getMaxTreeSizeRatio, "0.:0.05:10.", float)
        declare("swap_policy", self.setSwapPolicy, self.getSwapPolicy, value_type=str, choices=SWAP_POLICIES)
        declare("swap_steps", self.setSwapSteps, self.getSwapSteps, "1:1:100", int)
        declare("nearest_policy", self.setNearestPolicy, self.getNearestPolicy, value_type=str, choices=NEAREST_POLICIES)
        declare("exhausted_after", self.setExhaustedAfter, self.getExhaustedAfter, "1:1:100", int)
        declare("exhaustion_target", self.setExhaustionTarget, self.getExhaustionTarget, "1:1:100", int)
        declare("sample_policy", self.setSamplePolicy, self.getSamplePolicy, value_type=str, choices=SAMPLE_POLICIES)
        declare("goal_bias", self.setGoalBias, self.getGoalBias, "0.:.05:1.", float)
        declare("min_quality", self.setMinQuality, self.getMinQuality, "0.:.05:1.", float)
        declare("seed", self.setSeed, self.getSeed, "0:1:1000000", int)
        if not self._params.setParams(self.POLICIES):
            raise ValueError(f"{type(self).__name__}.POLICIES has a bad entry: {self.POLICIES}")
        self._valid_state_sampler_allocator = type(self).VALID_STATE_SAMPLER
        self._valid_sampler: ob.ValidStateSampler | None = None
        self._rng = ou.RNG()  # per-planner stream, seeded from OMPL's global seed
        self._points: RealVectorPoints | StatePoints | None = None
        self._start_tree = None
        self._goal_tree = None
        self._failures: dict = {}  # tree -> NodeFailures
        self._find_by_failures: Callable[[object, object], tuple[int, float]] | None = None
        self._loop_state = _FIRST_LOOP_STATE
        self._sampler_rejections = self._sampler_checks = 0
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
        """``True`` selects ``swap_policy = balance_nodes``; ``False`` turns it into ``alternate``."""
        if balance:
            self._swap_policy = "balance_nodes"
        elif self._swap_policy == "balance_nodes":
            self._swap_policy = "alternate"

    def getBalanceTreeSizes(self) -> bool:  # noqa: N802
        return self._swap_policy == "balance_nodes"

    def setMaxTreeSizeRatio(self, ratio: float) -> None:  # noqa: N802
        if not math.isfinite(ratio) or ratio < 0:
            raise ValueError("max_tree_size_ratio must be a finite number >= 0")
        self._max_tree_size_ratio = float(ratio)

    def getMaxTreeSizeRatio(self) -> float:  # noqa: N802
        return self._max_tree_size_ratio

    def setSwapPolicy(self, policy: str) -> None:  # noqa: N802
        self._swap_policy = _one_of("swap_policy", policy, SWAP_POLICIES)

    def getSwapPolicy(self) -> str:  # noqa: N802
        return self._swap_policy

    def setSwapSteps(self, steps: int) -> None:  # noqa: N802
        self._swap_steps = _at_least_one("swap_steps", steps)

    def getSwapSteps(self) -> int:  # noqa: N802
        return self._swap_steps

    def setNearestPolicy(self, policy: str) -> None:  # noqa: N802
        self._nearest_policy = _one_of("nearest_policy", policy, NEAREST_POLICIES)

    def getNearestPolicy(self) -> str:  # noqa: N802
        return self._nearest_policy

    def setExhaustedAfter(self, failures: int) -> None:  # noqa: N802
        self._exhausted_after = _at_least_one("exhausted_after", failures)

    def getExhaustedAfter(self) -> int:  # noqa: N802
        return self._exhausted_after

    def setExhaustionTarget(self, failures: int) -> None:  # noqa: N802
        self._exhaustion_target = _at_least_one("exhaustion_target", failures)

    def getExhaustionTarget(self) -> int:  # noqa: N802
        return self._exhaustion_target

    def setSamplePolicy(self, policy: str) -> None:  # noqa: N802
        self._sample_policy = _one_of("sample_policy", policy, SAMPLE_POLICIES)

    def getSamplePolicy(self) -> str:  # noqa: N802
        return self._sample_policy

    def setGoalBias(self, probability: float) -> None:  # noqa: N802
        self._goal_bias = _probability("goal_bias", probability)

    def getGoalBias(self) -> float:  # noqa: N802
        return self._goal_bias

    def setMinQuality(self, quality: float) -> None:  # noqa: N802
        self._min_quality = _probability("min_quality", quality)

    def getMinQuality(self) -> float:  # noqa: N802
        return self._min_quality

    def setSeed(self, seed: int) -> None:  # noqa: N802
        if seed < 0:
            raise ValueError("seed must be >= 0 (0 draws each solve's seed from OMPL's RNG)")
        self._seed = int(seed)

    def getSeed(self) -> int:  # noqa: N802
        return self._seed

    @property
    def draws_from_ompl_rng(self) -> bool:
        """True when a solve draws from OMPL's global RNG (``sample_policy = valid_sampler``):
        the ``seed`` parameter cannot repeat such a solve, ``ompl.util.RNG.setSeed`` at the
        start of a fresh process can."""
        return self._sample_policy == "valid_sampler"

    def setValidStateSamplerAllocator(  # noqa: N802
        self, allocator: Callable[[ob.SpaceInformation], ob.ValidStateSampler] | None
    ) -> None:
        """The valid-state sampler of ``sample_policy = valid_sampler``: ``allocator(si)``,
        or ``si.allocValidStateSampler()`` when ``None``. Takes effect at ``setup()``."""
        self._valid_state_sampler_allocator = allocator

    # -- planner life cycle -------------------------------------------------------

    def setup(self) -> None:
        super().setup()
        si = self.getSpaceInformation()
        ensure_counting(si)
        prepare(si)
        if self._range < 1e-12:
            self._range = RANGE_AS_EXTENT_FRACTION * si.getMaximumExtent()
            ou.OMPL_INFORM(f"{self.getName()}: range computed to be {self._range:g}")
        self._check_policies()
        self._valid_sampler = None  # allocated again from the current allocator

    def _check_policies(self) -> None:
        """Refuse combinations of policies and parameters that cannot do what they say."""
        if self.draws_from_ompl_rng and self._seed > 0:
            raise ValueError(
                f"{self.getName()}: sample_policy=valid_sampler with seed={self._seed}: a valid-state sampler "
                "draws from OMPL's RNG, which the seed parameter cannot repeat; use seed=0 (and "
                "ompl.util.RNG.setSeed) or another sample_policy"
            )

    def clear(self) -> None:
        super().clear()
        self._start_tree = self._goal_tree = None
        self._failures = {}
        self._loop_state = _FIRST_LOOP_STATE
        self.stats = None

    # -- solving -------------------------------------------------------------------

    def solve(self, ptc: ob.PlannerTerminationCondition | float | Callable[[], bool]) -> ob.PlannerStatus:
        """Plan until a solution is found or ``ptc`` says stop (seconds, callable or condition)."""
        ptc = termination_condition(ptc)
        self.checkValidity()
        self._check_policies()
        si = self.getSpaceInformation()
        began = time.perf_counter()
        work_before = read_work(si)
        rng = np.random.default_rng(self._seed or self._rng.uniformInt(1, 2**31 - 2))
        self._points = points_for(si, rng)
        # Per solve, not per step: the calls the grow step makes, and whether a step can stall.
        self._is_valid, self._check_motion = si.isValid, si.checkMotion
        self._step_may_stall = self._points.may_stall(self._range)
        if self._start_tree is None:
            self._start_tree, self._goal_tree = self._points.new_tree(), self._points.new_tree()
            self._failures = {self._start_tree: NodeFailures(), self._goal_tree: NodeFailures()}
        self._sampler_rejections = self._sampler_checks = 0
        status, iterations, swaps = self._plan(ptc, rng)
        work = read_work(si) - work_before
        self.stats = RunStats(
            status=ob.PlannerStatus(status).asString(),
            iterations=iterations,
            start_tree_size=len(self._start_tree),
            goal_tree_size=len(self._goal_tree),
            tree_swaps=sum(swaps),
            states_checked=work.states_checked,
            motions_checked=work.motions_checked,
            time=time.perf_counter() - began,
            swaps_alternate=swaps[ALTERNATE],
            swaps_balance=swaps[BALANCE],
            swaps_steps=swaps[STEPS],
            swaps_collision=swaps[COLLISION],
            sampler_rejections=self._sampler_rejections,
            sampler_checks=self._sampler_checks,
        )
        return ob.PlannerStatus(status)

    def _plan(self, ptc: ob.PlannerTerminationCondition, rng: np.random.Generator) -> tuple[ob.PlannerStatus.PlannerStatusType, int, list[int]]:
        """The grow/connect loop; returns (status, iterations, tree swaps per cause)."""
        name = self.getName()
        swaps = [0] * len(SWAP_CAUSES)
        pdef = self.getProblemDefinition()  # keep the owner alive while its states are used
        goal = pdef.getGoal()
        if not isinstance(goal, ob.GoalSampleableRegion):
            ou.OMPL_ERROR(f"{name}: Unknown type of goal (a GoalSampleableRegion is needed)")
            return ob.PlannerStatus.UNRECOGNIZED_GOAL_TYPE, 0, swaps

        points, start_tree, goal_tree = self._points, self._start_tree, self._goal_tree
        inputs = self.getPlannerInputStates()
        while (state := inputs.nextStart()) is not None:
            if points.is_finite(state):
                start_tree.add(points.from_state(state))
            else:
                ou.OMPL_WARN(f"{name}: Skipping start state with non-finite values")
        if len(start_tree) == 0:
            ou.OMPL_ERROR(f"{name}: Motion planning start tree could not be initialized!")
            return ob.PlannerStatus.INVALID_START, 0, swaps
        if not goal.couldSample():
            ou.OMPL_ERROR(f"{name}: Insufficient states in sampleable goal region")
            return ob.PlannerStatus.INVALID_GOAL, 0, swaps
        ou.OMPL_INFORM(f"{name}: Starting planning with {len(start_tree) + len(goal_tree)} states already in datastructure")

        # The policies of this solve.
        choose_tree = tree_chooser(self._swap_policy, self._max_tree_size_ratio, self._swap_steps)
        self._find_by_failures = self._failure_nearest()
        sample = self._target_sampler(rng)

        status = ob.PlannerStatus.TIMEOUT
        iterations = 0
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
            iterations += 1

            grow_start, cause = choose_tree(grew_start, len(start_tree), len(goal_tree), steps, collided)
            if grow_start != grew_start:
                steps, collided = 0, False
                if iterations > 1:
                    swaps[cause] += 1
            grew_start = grow_start
            tree, other_tree = (start_tree, goal_tree) if grow_start else (goal_tree, start_tree)

            target, nearest = sample(grow_start)
            if target is None:
                continue
            grown, added = self._grow(tree, grow_start, target, nearest)
            if grown is Grow.TRAPPED:
                continue
            # Connect: walk the other tree towards the state just added until trapped or there.
            target = tree.state(added)  # stays valid: only the other tree grows while connecting
            connected, reached = self._grow(other_tree, not grow_start, target)
            steps += 1
            while connected is Grow.ADVANCED:
                # The state just added is the other tree's nearest to the target (it is
                # one range closer than any before), so the search is skipped.
                connected, reached = self._grow(other_tree, not grow_start, target, nearest=reached)
                steps += 1
            collided = connected is Grow.TRAPPED
            if collided:
                continue
            start_node, goal_node = (added, reached) if grow_start else (reached, added)
            start_root = points.ompl_state(start_tree.state(start_tree.root(start_node)), 0)
            goal_root = points.ompl_state(goal_tree.state(goal_tree.root(goal_node)), 1)
            if goal.isStartGoalPairValid(start_root, goal_root):
                self._add_solution(pdef, start_node, goal_node)
                status = ob.PlannerStatus.EXACT_SOLUTION
                break

        self._loop_state = (grew_start, steps, collided)
        ou.OMPL_INFORM(
            f"{name}: Created {len(start_tree) + len(goal_tree)} states "
            f"({len(start_tree)} start + {len(goal_tree)} goal)"
        )
        return status, iterations, swaps

    def _failure_nearest(self) -> Callable[[object, object], tuple[int, float]] | None:
        """``find(tree, target) -> (node, distance)`` of ``nearest_policy``; ``None`` for plain nearest."""
        failures = self._failures
        if self._nearest_policy == "exhausted":
            exhausted_after = self._exhausted_after

            def not_exhausted(tree, target) -> tuple[int, float]:
                counts = failures[tree].counts(len(tree))
                node, distance = tree.nearest(target)
                if counts[node] < exhausted_after:
                    return node, distance  # the nearest of all is not exhausted: no need to rank
                distances = tree.distances(target)
                node = nearest_not_exhausted(distances, counts, exhausted_after)
                return node, float(distances[node])

            return not_exhausted
        if self._nearest_policy == "exhaustion":
            exhaustion_target = self._exhaustion_target

            def by_exhaustion(tree, target) -> tuple[int, float]:
                distances = tree.distances(target)
                node = nearest_by_exhaustion(distances, failures[tree].counts(len(tree)), exhaustion_target)
                return node, float(distances[node])

            return by_exhaustion
        return None

    def _target_sampler(self, rng: np.random.Generator) -> Callable[[bool], tuple]:
        """``sample(grow_start) -> (target, nearest)`` of ``sample_policy``.

        ``target`` is ``None`` when the policy gave up the iteration; ``nearest`` is the
        node to extend from when the policy already found it, else ``None``.
        """
        policy, points = self._sample_policy, self._points
        start_tree, goal_tree = self._start_tree, self._goal_tree
        uniform, distance, random = points.sample, points.distance, rng.random
        if policy == "uniform":
            return lambda grow_start: (uniform(), None)
        if policy == "goal_bias":
            bias = self._goal_bias

            def biased(grow_start: bool) -> tuple:
                if random() < bias:
                    return (goal_tree if grow_start else start_tree).state(0), None
                return uniform(), None

            return biased
        if policy == "goal_ball":

            def in_goal_ball(grow_start: bool) -> tuple:
                centre = (goal_tree if grow_start else start_tree).state(0)
                radius = distance(start_tree.state(0), goal_tree.state(0))
                for _ in range(SAMPLE_ATTEMPTS):
                    point = uniform()
                    if distance(point, centre) <= radius:
                        return point, None
                    self._sampler_rejections += 1
                return None, None

            return in_goal_ball
        if policy == "neighbour_quality":
            costs = {start_tree: NodeCosts(distance), goal_tree: NodeCosts(distance)}
            min_quality = self._min_quality

            def quality_accepted(grow_start: bool) -> tuple:
                tree = start_tree if grow_start else goal_tree
                start, goal = start_tree.state(0), goal_tree.state(0)
                tree_costs = costs[tree]
                tree_costs.update(tree, start, goal)
                optimal = distance(start, goal)
                for _ in range(SAMPLE_ATTEMPTS):
                    point = uniform()
                    if self._find_by_failures is None:
                        nearest, _ = tree.nearest(point)
                    else:
                        nearest, _ = self._find_by_failures(tree, point)
                    if random() < node_quality(tree_costs.values[nearest], optimal, tree_costs.max, min_quality):
                        return point, nearest
                    self._sampler_rejections += 1
                return None, None

            return quality_accepted
        # valid_sampler: the checks it makes are read off the counting checker
        si = self.getSpaceInformation()
        sampler, checker, state = self._valid_state_sampler(), si.getStateValidityChecker(), si.allocState()

        def from_valid_sampler(grow_start: bool) -> tuple:
            before = checker.counters()["states_checked"]
            found = sampler.sample(state)
            self._sampler_checks += checker.counters()["states_checked"] - before
            if not found:
                # No state near an obstacle within the sampler's attempts (free space has
                # none): a uniform target keeps the planner growing, as RRT-Connect would.
                self._sampler_rejections += 1
                return uniform(), None
            return points.from_state(state), None

        return from_valid_sampler

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

    def _grow(self, tree, from_start: bool, target, nearest: int | None = None) -> tuple[Grow, int]:
        """Extend ``tree`` one step towards ``target``; return the outcome and the node added.

        The node extended is ``nearest`` when given, else the one ``nearest_policy``
        picks. Motions in the start tree are checked from the tree outwards; in the goal
        tree they run from the new state into the tree, so the new state is checked
        first (``checkMotion`` assumes its first state valid), exactly as OMPL does. A
        motion in collision counts as a failed extension of the node (when
        ``nearest_policy`` counts failures).
        """
        points = self._points
        if nearest is None:
            if self._find_by_failures is None:
                nearest, distance = tree.nearest(target)
            else:
                nearest, distance = self._find_by_failures(tree, target)
        else:
            distance = points.distance(tree.state(nearest), target)
        near = tree.state(nearest)
        reach = distance <= self._range
        new = target if reach else points.interpolate(near, target, self._range / distance)
        if not reach and self._step_may_stall and points.equal(near, new):
            return Grow.TRAPPED, NO_PARENT

        near_state, new_state = points.ompl_state(near, 0), points.ompl_state(new, 1)
        if from_start:
            valid = self._check_motion(near_state, new_state)
        else:
            valid = self._is_valid(new_state) and self._check_motion(new_state, near_state)
        if not valid:
            if self._find_by_failures is not None:
                self._failures[tree].record(nearest)
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


# -- named presets ---------------------------------------------------------------------
#
# The lab's variants (issue #6): each is plain RRT-Connect (alternating trees) with one
# change, so it compares against stock RRT-Connect as the lab's did.


class SwapLimitRRTConnect(BalancedRRTConnect):
    """Swap limiter: grow one tree until ``swap_steps`` connect steps were taken, then the other."""

    POLICIES = {"swap_policy": "balance_steps"}


class CollisionSwapRRTConnect(BalancedRRTConnect):
    """Collision swap: grow one tree until a connect ends in a collision, then the other."""

    POLICIES = {"swap_policy": "on_collision"}


class ExhaustedNodesRRTConnect(BalancedRRTConnect):
    """Exhausted nodes: a node with ``exhausted_after`` (15) failed extensions is no longer extended."""

    POLICIES = {"swap_policy": "alternate", "nearest_policy": "exhausted"}


class ExhaustionRRTConnect(BalancedRRTConnect):
    """Exhaustion heuristic: nearest by distance x :func:`exhaustion_scale` of the node's failures."""

    POLICIES = {"swap_policy": "alternate", "nearest_policy": "exhaustion"}


class NeighbourCostRRTConnect(BalancedRRTConnect):
    """Neighbour cost: keep a sample with the probability :func:`node_quality` of its nearest node."""

    POLICIES = {"swap_policy": "alternate", "sample_policy": "neighbour_quality"}


class GaussianPassageRRTConnect(BalancedRRTConnect):
    """Gaussian passage sampler: targets from :class:`~ompl_balance.samplers.PassageSampler`."""

    POLICIES = {"swap_policy": "alternate", "sample_policy": "valid_sampler"}
    VALID_STATE_SAMPLER = PassageSampler


class ControlChosenRRTConnect(BalancedRRTConnect):
    """Control chosen: samples within the goal ball (``goal_ball``) and collision swap."""

    POLICIES = {"swap_policy": "on_collision", "sample_policy": "goal_ball"}


class GoalBiasRRTConnect(BalancedRRTConnect):
    """Goal bias: with probability ``goal_bias`` (0.05) the target is the other tree's root."""

    POLICIES = {"swap_policy": "alternate", "sample_policy": "goal_bias"}


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


# -- RRT* with a ball-radius constant -----------------------------------------------------

#: Monte Carlo samples used to estimate the free measure when ``ball_radius_constant`` is ``auto``.
AUTO_GAMMA_SAMPLES = 5000


@dataclass
class RRTstarStats:
    """The work one ``BallRadiusRRTstar.solve()`` did, and how the best cost evolved.

    Attributes
    ----------
    status: the ``PlannerStatus`` as a string.
    iterations: main-loop iterations (one sample each) in this solve.
    tree_size: nodes in the tree when the solve ended (cumulative until ``clear()``).
    best_cost: cost of the best path to the goal (path length), ``inf`` if none.
    first_solution_iteration: iteration (1-based, this solve) that found the first
        path, ``None`` if none was found or a path existed before this solve.
    ball_radius_constant: the ``gamma`` used (estimated at setup in ``auto`` mode).
    rewires: tree nodes given a cheaper parent through a new node.
    states_checked, motions_checked: as in :class:`RunStats`.
    time: wall-clock seconds spent in ``solve()``.
    best_costs: ``(iterations,)`` best cost after each iteration, ``inf`` before the
        first path; never increases.
    """

    status: str
    iterations: int
    tree_size: int
    best_cost: float
    first_solution_iteration: int | None
    ball_radius_constant: float
    rewires: int
    states_checked: int
    motions_checked: int
    time: float
    best_costs: np.ndarray

    def as_dict(self) -> dict[str, float | int | str | None]:
        """The scalar fields (``best_costs`` left out)."""
        return {key: value for key, value in asdict(self).items() if key != "best_costs"}


def path_length_objective(pdef: ob.ProblemDefinition, si: ob.SpaceInformation) -> ob.OptimizationObjective:
    """The problem's path-length objective, or a new one set on ``pdef`` when it has none.

    As OMPL's ``RRTstar::setup``. Any other objective is refused with ``ValueError``:
    the planner's costs are distances (``si.distance``), exactly path length.
    """
    if not pdef.hasOptimizationObjective():
        objective = ob.PathLengthOptimizationObjective(si)
        pdef.setOptimizationObjective(objective)
        return objective
    objective = pdef.getOptimizationObjective()
    if not isinstance(objective, ob.PathLengthOptimizationObjective):
        raise ValueError(
            f"BallRadiusRRTstar optimises path length only; the problem's objective is {type(objective).__name__} "
            "(use ob.PathLengthOptimizationObjective, optionally with a cost threshold, or none)"
        )
    return objective


class BallRadiusRRTstar(ob.Planner):
    """RRT* whose rewiring ball follows ``min((gamma log N / N)^(1/d), eta)`` with a settable ``gamma``.

    Parameters (``planner.params()``, named as in MATLAB's ``plannerRRTStar``; camelCase
    accessors too):

    ``max_connection_distance`` (float, default 0 = 0.2 x the space's maximum extent at ``setup()``)
        ``eta``: longest motion added in one step, and the cap of the rewiring radius.
    ``ball_radius_constant`` (float > 0 or ``auto``, default 100)
        ``gamma`` (distance^d). ``auto``: at ``setup()``,
        :func:`~ompl_balance.gamma.estimate_ball_radius_constant` with
        ``AUTO_GAMMA_SAMPLES`` validity checks (not counted in the solve's stats).
    ``goal_bias`` (float in [0, 1], default 0.05)
        probability of sampling the goal region instead of the space.
    ``continue_after_goal_reached`` (bool, default true)
        keep improving the path after the first one until the termination condition,
        an iteration or node limit, or a satisfied cost threshold; false stops at the
        first path. (MATLAB's default is false; true is what an OMPL optimising
        planner does.)
    ``max_iterations`` (int >= 0, default 10000; 0 = no limit)
        iterations per ``solve()``.
    ``max_nodes`` (int >= 0, default 10000; 0 = no limit)
        stop once the tree has this many nodes.
    ``seed`` (int >= 0, default 0)
        as :class:`BalancedRRTConnect`'s ``seed`` (numpy sampling in real-vector spaces).

    As OMPL's ``RRTstar`` (radius mode, delayed collision checking): the new state's
    parent is the neighbour giving the cheapest valid path, candidates checked in
    order of cost; then every neighbour a path through the new state would make
    cheaper is rewired, and its subtree's costs updated. ``N`` is the tree size
    counting the new state. The run stops early when the problem's objective is
    satisfied by the best cost (``objective.isSatisfied``, e.g. a cost threshold).

    Differences from stock, on purpose: no approximate solutions (``TIMEOUT`` without
    a path); no pruning or informed sampling; only the path-length objective;
    ``plannerData()`` instead of ``getPlannerData``; each solve reports an
    :class:`RRTstarStats` (``planner.stats``).
    """

    def __init__(self, si: ob.SpaceInformation, name: str = "BallRadiusRRTstar") -> None:
        super().__init__(si, name)
        self._max_connection_distance = 0.0
        self._ball_radius_constant: float | str = 100.0
        self._goal_bias = 0.05
        self._continue_after_goal_reached = True
        self._max_iterations = 10000
        self._max_nodes = 10000
        self._seed = 0
        self._params = ParamSet()
        self._params.declareParam(
            "max_connection_distance", self.setMaxConnectionDistance, self.getMaxConnectionDistance, "0.:1.:10000.", float
        )
        self._params.declareParam("ball_radius_constant", self.setBallRadiusConstant, self.getBallRadiusConstant, "1.:1.:1000000.", str)
        self._params.declareParam("goal_bias", self.setGoalBias, self.getGoalBias, "0.:.05:1.", float)
        self._params.declareParam(
            "continue_after_goal_reached", self.setContinueAfterGoalReached, self.getContinueAfterGoalReached, "0,1", bool
        )
        self._params.declareParam("max_iterations", self.setMaxIterations, self.getMaxIterations, "0:1000:1000000", int)
        self._params.declareParam("max_nodes", self.setMaxNodes, self.getMaxNodes, "0:1000:1000000", int)
        self._params.declareParam("seed", self.setSeed, self.getSeed, "0:1:1000000", int)
        self._rng = ou.RNG()
        self._gamma_in_use: float | None = None
        self._points: RealVectorPoints | StatePoints | None = None
        self._tree = None
        self._costs = np.empty(0)  # cost-to-come of each node
        self._children: list[list[int]] = []
        self._goal_nodes: list[int] = []
        self.stats: RRTstarStats | None = None

    # -- parameters ---------------------------------------------------------------

    def params(self) -> ParamSet:
        """This planner's parameters (OMPL's ``ParamSet`` semantics)."""
        return self._params

    def setMaxConnectionDistance(self, distance: float) -> None:  # noqa: N802
        if not math.isfinite(distance) or distance < 0:
            raise ValueError("max_connection_distance must be a finite distance >= 0 (0 picks 0.2 x the space's extent)")
        self._max_connection_distance = float(distance)

    def getMaxConnectionDistance(self) -> float:  # noqa: N802
        return self._max_connection_distance

    def setBallRadiusConstant(self, gamma: float | str) -> None:  # noqa: N802
        """``gamma`` (distance^d, > 0), or ``"auto"`` to estimate it at ``setup()``."""
        if isinstance(gamma, str):
            text = gamma.strip().lower()
            if text == "auto":
                self._ball_radius_constant, self._gamma_in_use = "auto", None
                return
            try:
                gamma = float(text)
            except ValueError:
                raise ValueError("ball_radius_constant must be a positive number or 'auto'") from None
        if not math.isfinite(gamma) or gamma <= 0:
            raise ValueError("ball_radius_constant must be a positive number or 'auto'")
        self._ball_radius_constant = self._gamma_in_use = float(gamma)

    def getBallRadiusConstant(self) -> float | str:  # noqa: N802
        """The setting: a number or ``"auto"`` (see :meth:`getBallRadiusConstantInUse`)."""
        return self._ball_radius_constant

    def getBallRadiusConstantInUse(self) -> float | None:  # noqa: N802
        """The ``gamma`` the next solve uses; ``None`` in ``auto`` mode before ``setup()``."""
        return self._gamma_in_use

    def setGoalBias(self, bias: float) -> None:  # noqa: N802
        if not 0.0 <= bias <= 1.0:
            raise ValueError("goal_bias must be a probability in [0, 1]")
        self._goal_bias = float(bias)

    def getGoalBias(self) -> float:  # noqa: N802
        return self._goal_bias

    def setContinueAfterGoalReached(self, keep_going: bool) -> None:  # noqa: N802
        self._continue_after_goal_reached = bool(keep_going)

    def getContinueAfterGoalReached(self) -> bool:  # noqa: N802
        return self._continue_after_goal_reached

    def setMaxIterations(self, count: int) -> None:  # noqa: N802
        self._max_iterations = _non_negative_int("max_iterations", count)

    def getMaxIterations(self) -> int:  # noqa: N802
        return self._max_iterations

    def setMaxNodes(self, count: int) -> None:  # noqa: N802
        self._max_nodes = _non_negative_int("max_nodes", count)

    def getMaxNodes(self) -> int:  # noqa: N802
        return self._max_nodes

    def setSeed(self, seed: int) -> None:  # noqa: N802
        self._seed = _non_negative_int("seed", seed)

    def getSeed(self) -> int:  # noqa: N802
        return self._seed

    # -- planner life cycle -------------------------------------------------------

    def setup(self) -> None:
        super().setup()
        si = self.getSpaceInformation()
        ensure_counting(si)
        prepare(si)
        if self._max_connection_distance < 1e-12:
            self._max_connection_distance = RANGE_AS_EXTENT_FRACTION * si.getMaximumExtent()
            ou.OMPL_INFORM(f"{self.getName()}: max_connection_distance computed to be {self._max_connection_distance:g}")
        if self._gamma_in_use is None:
            self._gamma_in_use = self._estimate_gamma()

    def _estimate_gamma(self) -> float:
        seed = self._seed or self._rng.uniformInt(1, 2**31 - 2)
        gamma = estimate_ball_radius_constant(self.getSpaceInformation(), samples=AUTO_GAMMA_SAMPLES, rng=seed)
        ou.OMPL_INFORM(f"{self.getName()}: ball_radius_constant estimated to be {gamma:g}")
        return gamma

    def clear(self) -> None:
        super().clear()
        self._tree = None
        self._costs = np.empty(0)
        self._children, self._goal_nodes = [], []
        self.stats = None

    # -- solving -------------------------------------------------------------------

    def solve(self, ptc: ob.PlannerTerminationCondition | float | Callable[[], bool]) -> ob.PlannerStatus:
        """Plan until ``ptc`` says stop, a limit is reached or the objective is satisfied."""
        ptc = termination_condition(ptc)
        self.checkValidity()
        si = self.getSpaceInformation()
        pdef = self.getProblemDefinition()  # keep the owner alive while its states are used
        objective = path_length_objective(pdef, si)
        if self._gamma_in_use is None:
            self._gamma_in_use = self._estimate_gamma()
        began = time.perf_counter()
        work_before = read_work(si)
        rng = np.random.default_rng(self._seed or self._rng.uniformInt(1, 2**31 - 2))
        self._points = points_for(si, rng)
        if self._tree is None:
            self._tree = self._points.new_tree()
        best_before = self._best_cost()
        status, improvements, iterations, rewires = self._plan(ptc, pdef, objective, rng)
        work = read_work(si) - work_before

        best_costs = np.full(iterations, best_before)
        for iteration, cost in improvements:
            best_costs[iteration - 1 :] = cost
        first = improvements[0][0] if improvements and math.isinf(best_before) else None
        self.stats = RRTstarStats(
            status=ob.PlannerStatus(status).asString(),
            iterations=iterations,
            tree_size=len(self._tree),
            best_cost=self._best_cost(),
            first_solution_iteration=first,
            ball_radius_constant=self._gamma_in_use,
            rewires=rewires,
            states_checked=work.states_checked,
            motions_checked=work.motions_checked,
            time=time.perf_counter() - began,
            best_costs=best_costs,
        )
        return ob.PlannerStatus(status)

    def _plan(self, ptc, pdef, objective, rng) -> tuple[ob.PlannerStatus.PlannerStatusType, list[tuple[int, float]], int, int]:
        """The RRT* loop; returns (status, [(iteration, new best cost)], iterations, rewires)."""
        name = self.getName()
        si = self.getSpaceInformation()
        goal = pdef.getGoal()
        points, tree = self._points, self._tree
        inputs = self.getPlannerInputStates()
        while (state := inputs.nextStart()) is not None:
            if not points.is_finite(state):
                ou.OMPL_WARN(f"{name}: Skipping start state with non-finite values")
                continue
            root = self._add_node(points.from_state(state), NO_PARENT, 0.0)
            if goal.isSatisfied(state):
                self._goal_nodes.append(root)
        if len(tree) == 0:
            ou.OMPL_ERROR(f"{name}: There are no valid initial states!")
            return ob.PlannerStatus.INVALID_START, [], 0, 0
        sampleable = goal if isinstance(goal, ob.GoalSampleableRegion) else None
        goal_sample = si.allocState()
        ou.OMPL_INFORM(f"{name}: Starting planning with {len(tree)} states already in datastructure")

        check_motion, is_goal, ompl_state = si.checkMotion, goal.isSatisfied, points.ompl_state
        d, gamma, eta = si.getStateDimension(), self._gamma_in_use, self._max_connection_distance
        max_iterations, max_nodes = self._max_iterations or math.inf, self._max_nodes or math.inf
        best = self._best_cost()
        improvements: list[tuple[int, float]] = []
        iterations = rewires = 0
        while not ptc() and iterations < max_iterations and len(tree) < max_nodes:
            iterations += 1
            if (
                sampleable is not None
                and len(self._goal_nodes) < sampleable.maxSampleCount()
                and rng.random() < self._goal_bias
            ):
                sampleable.sampleGoal(goal_sample)
                if not points.is_finite(goal_sample):
                    continue
                target = points.from_state(goal_sample)
            else:
                target = points.sample()

            nearest, distance = tree.nearest(target)
            if distance == 0.0:
                continue  # the sample is a tree node already
            near_point = tree.state(nearest)
            new = target if distance <= eta else points.interpolate(near_point, target, eta / distance)
            new_state = ompl_state(new, 1)  # written once: every check below uses it
            if not check_motion(ompl_state(near_point, 0), new_state):
                continue

            # Parent: the neighbour giving the cheapest valid path, checked in order of cost.
            neighbours, distances = tree.near(new, rewire_radius(len(tree) + 1, d, gamma, eta))
            costs = self._costs
            through = costs[neighbours] + distances
            parent, cost = nearest, costs[nearest] + min(distance, eta)
            valid = {nearest: True}  # neighbour -> whether its motion to the new state is valid
            for i in through.argsort().tolist():
                if through[i] >= cost:
                    break
                neighbour = int(neighbours[i])
                valid[neighbour] = check_motion(ompl_state(tree.state(neighbour), 0), new_state)
                if valid[neighbour]:
                    parent, cost = neighbour, float(through[i])
                    break
            added = self._add_node(new, parent, cost)
            found_goal = is_goal(new_state)
            if found_goal:
                self._goal_nodes.append(added)

            # Rewire: neighbours reached more cheaply through the new state.
            costs = self._costs
            rewired = False
            for i in np.flatnonzero(cost + distances < costs[neighbours]).tolist():
                neighbour, through_new = int(neighbours[i]), cost + distances[i]
                if not through_new < costs[neighbour]:
                    continue  # an earlier rewire in this loop made it cheaper already
                if neighbour not in valid:
                    valid[neighbour] = check_motion(new_state, ompl_state(tree.state(neighbour), 0))
                if valid[neighbour]:
                    self._rewire(neighbour, added, through_new)
                    rewires += 1
                    rewired = True

            if (found_goal or rewired) and self._goal_nodes:
                candidate = self._best_cost()
                if candidate < best:
                    best = candidate
                    improvements.append((iterations, best))
                    if not self._continue_after_goal_reached or objective.isSatisfied(ob.Cost(best)):
                        break

        if self._goal_nodes:
            self._add_solution(pdef)
            status = ob.PlannerStatus.EXACT_SOLUTION
        else:
            status = ob.PlannerStatus.TIMEOUT
        ou.OMPL_INFORM(f"{name}: Created {len(tree)} states, {rewires} rewires; best cost {best:.4g}")
        return status, improvements, iterations, rewires

    def _add_node(self, point, parent: int, cost: float) -> int:
        """Add ``point`` to the tree under ``parent`` with cost-to-come ``cost``; return its index."""
        index = self._tree.add(point, parent)
        if index == len(self._costs):
            self._costs = np.concatenate([self._costs, np.empty(max(index, 1024))])
        self._costs[index] = cost
        self._children.append([])
        if parent != NO_PARENT:
            self._children[parent].append(index)
        return index

    def _rewire(self, node: int, parent: int, cost: float) -> None:
        """Make ``parent`` the parent of ``node``, whose cost-to-come becomes ``cost``."""
        children = self._children
        children[self._tree.parent(node)].remove(node)
        children[parent].append(node)
        subtree = [node]
        for member in subtree:  # grows while iterated: breadth-first through the subtree
            subtree.extend(children[member])
        subtree = np.fromiter(subtree, dtype=np.int64, count=len(subtree))
        self._tree.reparent(subtree, parent)
        self._costs[subtree] += cost - self._costs[node]

    def _best_cost(self) -> float:
        return float(self._costs[self._goal_nodes].min()) if self._goal_nodes else math.inf

    def _add_solution(self, pdef: ob.ProblemDefinition) -> None:
        """Add the path from the root to the cheapest goal node to ``pdef``."""
        best_goal = self._goal_nodes[int(self._costs[self._goal_nodes].argmin())]
        path = og.PathGeometric(self.getSpaceInformation())
        for node in reversed(self._tree.branch(best_goal)):
            path.append(self._points.ompl_state(self._tree.state(node)))
        pdef.addSolutionPath(path, False, 0.0, self.getName())

    # -- introspection ---------------------------------------------------------------

    def plannerData(self) -> ob.PlannerData:  # noqa: N802
        """The tree as an ``ob.PlannerData``: roots are start vertices, goal nodes goal vertices.

        Vertices carry tag 1, edges run parent -> child. The graph owns copies of the
        states. (``ss.getPlannerData`` returns an empty graph for Python planners.)
        """
        data = ob.PlannerData(self.getSpaceInformation())
        tree = self._tree
        if tree is None:
            return data
        goal_nodes = set(self._goal_nodes)
        keep_alive, indices = [], []  # the graph points into these states until it is decoupled
        for node in range(len(tree)):
            state = self._points.new_state(tree.state(node))
            keep_alive.append(state)
            vertex = ob.PlannerDataVertex(state, START_TAG)
            if tree.parent(node) == NO_PARENT:
                indices.append(data.addStartVertex(vertex))
            elif node in goal_nodes:
                indices.append(data.addGoalVertex(vertex))
            else:
                indices.append(data.addVertex(vertex))
        for node in range(len(tree)):
            if tree.parent(node) != NO_PARENT:
                data.addEdge(indices[tree.parent(node)], indices[node])
        data.decoupleFromPlanner()
        return data


def _non_negative_int(name: str, value: int) -> int:
    if isinstance(value, bool) or int(value) != value or value < 0:
        raise ValueError(f"{name} must be an integer >= 0, got {value!r}")
    return int(value)
