"""RRT* whose rewiring ball follows a settable ball-radius constant ``gamma``.

The radius schedule is ``min((gamma log N / N)^(1/d), eta)`` (:func:`~ompl_balance.gamma.rewire_radius`),
as in MATLAB's ``plannerRRTStar`` and its example "Calculating an Appropriate
BallRadiusConstant for plannerRRTStar"; :mod:`ompl_balance.gamma` estimates ``gamma`` for a
problem. The loop is OMPL's ``RRTstar`` (``src/ompl/geometric/planners/rrt/src/RRTstar.cpp``)
with og.RRTstar's parameters where they mean the same (``range``, ``rewire_factor``,
k-nearest mode, delayed collision checking, tree pruning).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import util as ou

from .core.params import Settings, param
from .core.planner import RANGE_AS_EXTENT_FRACTION, PlannerSpecs, TreePlanner
from .core.spaces import Points
from .core.trees import NO_PARENT, Tree
from .gamma import EstimateInterruptedError, beta_quantile_function, estimate_ball_radius_constant, rewire_radius

#: Monte Carlo samples used to estimate the free measure when ``ball_radius_constant`` is ``auto``.
AUTO_GAMMA_SAMPLES = 5000


@dataclass
class RRTstarSettings(Settings):
    """The parameters of :class:`BallRadiusRRTstar`: og.RRTstar's names where they mean the same,
    MATLAB ``plannerRRTStar``'s for the rest."""

    range: float = param(
        0.0,
        "eta: longest motion added in one step, and the cap of the rewiring radius (state-space distance); "
        "0 picks 0.2 x the space's maximum extent at setup() (og.RRTstar's range)",
        low=0.0,
        suggestion="0.:1.:10000.",
    )
    ball_radius_constant: float | str = param(
        "auto",
        "gamma (distance^d) of the rewiring radius min(rewire_factor * (gamma log N / N)^(1/d), range); auto "
        "estimates gamma* for the problem's free space at the first solve (ompl_balance.gamma."
        f"estimate_ball_radius_constant, {AUTO_GAMMA_SAMPLES} validity checks within the solve's time, fewer "
        "if it runs out, not counted in its stats)",
        kind=float,
        low=0.0,
        low_open=True,
        words=("auto",),
        suggestion="1.:1.:1000000.",
    )
    rewire_factor: float = param(
        1.0,
        "multiplies the rewiring radius (or, with use_k_nearest, og.RRTstar's k); og.RRTstar's factor "
        "multiplies OMPL's own radius constant instead (ompl_balance.gamma.ompl_ball_radius_constant converts)",
        low=0.0,
        low_open=True,
        suggestion="1.0:0.01:2.0",
    )
    use_k_nearest: bool = param(
        False,
        "rewire against the ceil(rewire_factor * 2^(d+1) e (1 + 1/d) log N) nearest nodes, as og.RRTstar's "
        "k-nearest mode, instead of the ball (ball_radius_constant is then unused)",
        accessor="KNearest",
    )
    delay_collision_checking: bool = param(
        True,
        "check a new state's candidate parents in order of cost until one is valid; false: check every "
        "candidate that improves on the best so far, in tree order (the same parent, more checks)",
        accessor="DelayCC",
    )
    tree_pruning: bool = param(
        False,
        "after a better solution, remove the nodes that cannot lead to a better one (straight-line cost from "
        "the start plus distance to the goal above the best cost) unless a kept node descends from them",
    )
    prune_threshold: float = param(
        0.05,
        "prune only when the best cost fell by more than this fraction since the last pruning",
        low=0.0,
        high=1.0,
        suggestion="0.:.01:1.",
    )
    goal_bias: float = param(
        0.05, "probability of sampling the goal region instead of the space", low=0.0, high=1.0, suggestion="0.:.05:1."
    )
    continue_after_goal_reached: bool = param(
        True,
        "keep improving the path after the first one until the termination condition, an iteration or "
        "node limit, or a satisfied cost threshold; false stops at the first path (MATLAB's default)",
    )
    max_iterations: int = param(
        0, "iterations per solve(); 0: no limit (og.RRTstar has none)", low=0, suggestion="0:1000:1000000"
    )
    max_nodes: int = param(
        0,
        "stop once the tree has this many nodes; 0: no limit (og.RRTstar has none)",
        low=0,
        suggestion="0:1000:1000000",
    )
    seed: int = param(
        0, "as BalancedRRTConnect's seed (numpy sampling in real-vector spaces)", low=0, suggestion="0:1:1000000"
    )


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
    states_checked, motions_checked, distance_queries: as in :class:`~ompl_balance.planners.RunStats`.
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
    best_costs: np.ndarray = field(repr=False)
    distance_queries: int = 0

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


class CostTree:
    """RRT*'s tree: nodes with their cost-to-come, children lists, and the nodes in the goal."""

    def __init__(self, tree: Tree) -> None:
        self.tree = tree
        self.costs = np.empty(0)  # cost-to-come of each node
        self.children: list[list[int]] = []
        self.goal_nodes: list[int] = []

    def __len__(self) -> int:
        return len(self.tree)

    def add(self, point: Any, parent: int, cost: float) -> int:
        """Add ``point`` under ``parent`` with cost-to-come ``cost``; return its index."""
        index = self.tree.add(point, parent)
        if index == len(self.costs):
            self.costs = np.concatenate([self.costs, np.empty(max(index, 1024))])
        self.costs[index] = cost
        self.children.append([])
        if parent != NO_PARENT:
            self.children[parent].append(index)
        return index

    def rewire(self, node: int, parent: int, cost: float) -> None:
        """Make ``parent`` the parent of ``node``, whose cost-to-come becomes ``cost``."""
        children = self.children
        children[self.tree.parent(node)].remove(node)
        children[parent].append(node)
        members = [node]
        for member in members:  # grows while iterated: breadth-first through the subtree
            members.extend(children[member])
        subtree = np.fromiter(members, dtype=np.int64, count=len(members))
        self.tree.reparent(subtree, parent)
        self.costs[subtree] += cost - self.costs[node]

    def best_goal(self) -> int:
        """The goal node with the least cost (``NO_PARENT`` when there is none)."""
        if not self.goal_nodes:
            return NO_PARENT
        return self.goal_nodes[int(self.costs[self.goal_nodes].argmin())]

    def best_cost(self) -> float:
        return float(self.costs[self.goal_nodes].min()) if self.goal_nodes else math.inf

    def best_branch(self) -> list[int]:
        """Nodes from the root to the cheapest goal node."""
        return list(reversed(self.tree.branch(self.best_goal())))

    def prune(self, keep: np.ndarray) -> int:
        """Remove the nodes where ``keep`` is false, unless a kept node descends from them
        (roots are always kept); returns how many were removed. Nodes are renumbered in order."""
        size = len(self)
        keep = keep[:size].copy()
        keep[self.tree.parents[:size] == NO_PARENT] = True
        parents = self.tree.parents
        for node in np.flatnonzero(keep).tolist():  # the ancestors of a kept node are kept
            parent = int(parents[node])
            while parent != NO_PARENT and not keep[parent]:
                keep[parent] = True
                parent = int(parents[parent])
        kept = np.flatnonzero(keep)
        new_index = self.tree.compact(keep)
        self.costs = self.costs[kept]
        self.children = [[] for _ in kept]
        for node, parent in enumerate(self.tree.parents[: len(kept)].tolist()):
            if parent != NO_PARENT:
                self.children[parent].append(node)
        self.goal_nodes = [int(new_index[node]) for node in self.goal_nodes if keep[node]]
        return size - len(kept)


def _solution_lower_bounds(points: Points, tree: Tree, goal: ob.Goal) -> np.ndarray:
    """Per node, a lower bound on the cost of any path from a start through it to the goal:
    the straight-line distance from the nearest root plus the goal region's distance
    (og.RRTstar's admissible solution heuristic for path length)."""
    size = len(tree)
    roots = np.flatnonzero(tree.parents[:size] == NO_PARENT)
    to_come = np.min([tree.distances(tree.state(int(root))) for root in roots], axis=0)
    if isinstance(goal, ob.GoalRegion):
        threshold, distance_goal = goal.getThreshold(), goal.distanceGoal
        to_go = np.array(
            [max(distance_goal(points.ompl_state(tree.state(node))) - threshold, 0.0) for node in range(size)]
        )
    else:
        to_go = np.zeros(size)  # no distance to an arbitrary goal: 0 is still a lower bound
    return np.asarray(to_come + to_go)


class BallRadiusRRTstar(TreePlanner):
    """RRT* whose rewiring ball follows ``min(rewire_factor * (gamma log N / N)^(1/d), range)``
    with a settable ``gamma``.

    Constructed as OMPL's ``og.RRTstar``: ``BallRadiusRRTstar(si, name=None)``. Parameters are
    those of :class:`RRTstarSettings`, through ``planner.params()`` or the camelCase accessors
    (og.RRTstar's names: ``setRange``, ``setGoalBias``, ``setRewireFactor``, ``setKNearest``,
    ``setDelayCC``, ``setTreePruning``, ``setPruneThreshold``); :meth:`getBallRadiusConstantInUse`
    tells the ``gamma`` of the next solve (the estimate, in ``auto`` mode).

    As OMPL's ``RRTstar``: the new state's parent is the neighbour giving the cheapest
    valid path; then every neighbour a path through the new state would make cheaper is
    rewired, and its subtree's costs updated. ``N`` is the tree size counting the new
    state. The run stops early when the problem's objective is satisfied by the best
    cost (``objective.isSatisfied``, e.g. a cost threshold).

    Differences from stock, on purpose (``docs/drop-in.md`` lists them all): no approximate
    solutions (``TIMEOUT`` without a path); no informed or rejection sampling; only the
    path-length objective; each solve reports an :class:`RRTstarStats` (``planner.stats``).
    """

    Settings = RRTstarSettings
    Stats = RRTstarStats
    SPECS = PlannerSpecs(optimizingPaths=True)

    def __init__(self, si: ob.SpaceInformation, name: str | None = None) -> None:
        super().__init__(si, name)
        self._estimated_gamma: float | None = None
        self._tree: CostTree | None = None
        self._pruned_cost = math.inf  # the best cost at the last pruning
        beta_quantile_function()  # the estimate's interval needs scipy: loaded now, not in a solve

    def getBallRadiusConstantInUse(self) -> float:  # noqa: N802
        """The ``gamma`` the next solve uses: in ``auto`` mode the estimate, made now if no
        solve made it yet (kept until ``setup()``; a solve whose time ran out during the
        estimate keeps one from the samples it drew)."""
        gamma = self._gamma_in_use()
        if gamma is None:
            gamma = self._estimated_gamma = self._estimate_gamma()
        return gamma

    def _gamma_in_use(self) -> float | None:
        gamma = self.settings.ball_radius_constant
        return self._estimated_gamma if gamma == "auto" else float(gamma)

    # -- planner life cycle -------------------------------------------------------

    def setup(self) -> None:
        super().setup()
        settings = self.settings
        if settings.range < 1e-12:
            settings.range = RANGE_AS_EXTENT_FRACTION * self.getSpaceInformation().getMaximumExtent()
            ou.OMPL_INFORM(f"{self.getName()}: range computed to be {settings.range:g}")
        self._estimated_gamma = None  # the problem may have changed: estimate again when needed

    def _estimate_gamma(self, ptc: ob.PlannerTerminationCondition | None = None) -> float:
        seed = self.settings.seed or self._draw_seed()
        gamma = estimate_ball_radius_constant(
            self.getSpaceInformation(), samples=AUTO_GAMMA_SAMPLES, rng=seed, stop=ptc
        )
        ou.OMPL_INFORM(f"{self.getName()}: ball_radius_constant estimated to be {gamma:g}")
        return gamma

    def clear(self) -> None:
        super().clear()
        self._tree = None
        self._pruned_cost = math.inf

    # -- solving -------------------------------------------------------------------

    def _before_solve(self, ptc: ob.PlannerTerminationCondition) -> None:
        path_length_objective(self.getProblemDefinition(), self.getSpaceInformation())
        if not self.settings.use_k_nearest and self._gamma_in_use() is None:
            try:
                self._estimated_gamma = self._estimate_gamma(ptc)
            except EstimateInterruptedError:
                ou.OMPL_INFORM(f"{self.getName()}: the time ran out before ball_radius_constant was estimated")

    def _neighbours(self, tree: Tree, point: Any, dimension: int, gamma: float) -> tuple[np.ndarray, np.ndarray]:
        """The nodes a new state at ``point`` is connected and rewired against, and their distances:
        within the rewiring radius, or (``use_k_nearest``) og.RRTstar's ``k`` nearest, by index."""
        settings, n = self.settings, len(tree) + 1
        if not settings.use_k_nearest:
            radius = settings.rewire_factor * rewire_radius(n, dimension, gamma)
            return tree.near(point, min(radius, settings.range))
        k_rrt = settings.rewire_factor * 2.0 ** (dimension + 1) * math.e * (1.0 + 1.0 / dimension)
        k = math.ceil(k_rrt * math.log(n))
        distances = tree.distances(point)
        if k < len(distances):
            nearest = np.sort(np.argpartition(distances, k - 1)[:k])
            return nearest, distances[nearest]
        return np.arange(len(distances)), distances

    def _plan(
        self, ptc: ob.PlannerTerminationCondition, points: Points, rng: np.random.Generator
    ) -> tuple[ob.PlannerStatus.PlannerStatusType, dict[str, Any]]:
        """The RRT* loop; returns the status and the loop's statistics."""
        name, settings = self.getName(), self.settings
        si = self.getSpaceInformation()
        pdef = self.getProblemDefinition()  # keep the owner alive while its states are used
        objective, goal = pdef.getOptimizationObjective(), pdef.getGoal()
        gamma = math.nan if settings.use_k_nearest else self._gamma_in_use()
        if self._tree is None:
            self._tree = CostTree(points.new_tree())
        nodes = self._tree
        tree = nodes.tree
        best_before = nodes.best_cost()
        improvements: list[tuple[int, float]] = []  # (iteration, new best cost)
        progress = self.progress
        progress.best_cost = best_before
        rewires = 0

        def result(status: ob.PlannerStatus.PlannerStatusType) -> tuple[Any, dict[str, Any]]:
            iterations = progress.iterations
            best_costs = np.full(iterations, best_before)
            for iteration, cost in improvements:
                best_costs[iteration - 1 :] = cost
            first = improvements[0][0] if improvements and math.isinf(best_before) else None
            return status, {
                "iterations": iterations,
                "tree_size": len(nodes),
                "best_cost": nodes.best_cost(),
                "first_solution_iteration": first,
                "ball_radius_constant": gamma,
                "rewires": rewires,
                "best_costs": best_costs,
            }

        if gamma is None:  # the time ran out while gamma was estimated
            return result(ob.PlannerStatus.TIMEOUT)
        inputs = self.getPlannerInputStates()
        while (state := inputs.nextStart()) is not None:
            if not points.is_finite(state):
                ou.OMPL_WARN(f"{name}: Skipping start state with non-finite values")
                continue
            root = nodes.add(points.from_state(state), NO_PARENT, 0.0)
            if goal.isSatisfied(state):
                nodes.goal_nodes.append(root)
        if len(tree) == 0:
            ou.OMPL_ERROR(f"{name}: There are no valid initial states!")
            return result(ob.PlannerStatus.INVALID_START)
        sampleable = goal if isinstance(goal, ob.GoalSampleableRegion) else None
        goal_sample = si.allocState()
        ou.OMPL_INFORM(f"{name}: Starting planning with {len(tree)} states already in datastructure")

        check_motion, is_goal, ompl_state = si.checkMotion, goal.isSatisfied, points.ompl_state
        d, eta, delay_checks = si.getStateDimension(), settings.range, settings.delay_collision_checking
        max_iterations, max_nodes = settings.max_iterations or math.inf, settings.max_nodes or math.inf
        best = nodes.best_cost()
        while not ptc() and progress.iterations < max_iterations and len(tree) < max_nodes:
            progress.iterations += 1
            if (
                sampleable is not None
                and len(nodes.goal_nodes) < sampleable.maxSampleCount()
                and rng.random() < settings.goal_bias
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

            # Parent: the neighbour giving the cheapest valid path.
            neighbours, distances = self._neighbours(tree, new, d, gamma)
            costs = nodes.costs
            neighbour_costs = costs[neighbours]  # adding the new node below changes none of them
            through = neighbour_costs + distances
            parent, cost = nearest, costs[nearest] + min(distance, eta)
            valid = {nearest: True}  # neighbour -> whether its motion to the new state is valid
            # Delayed: candidates in order of cost, up to the first valid one. Not delayed (as
            # og.RRTstar's setDelayCC(false)): every candidate cheaper than the best so far.
            for i in through.argsort().tolist() if delay_checks else range(len(neighbours)):
                if through[i] >= cost:
                    if delay_checks:
                        break
                    continue
                neighbour = int(neighbours[i])
                valid[neighbour] = check_motion(ompl_state(tree.state(neighbour), 0), new_state)
                if valid[neighbour]:
                    parent, cost = neighbour, float(through[i])
                    if delay_checks:
                        break
            added = nodes.add(new, parent, cost)
            found_goal = is_goal(new_state)
            if found_goal:
                nodes.goal_nodes.append(added)

            # Rewire: neighbours reached more cheaply through the new state.
            costs = nodes.costs
            rewired = False
            for i in np.flatnonzero(cost + distances < neighbour_costs).tolist():
                neighbour, through_new = int(neighbours[i]), cost + distances[i]
                if not through_new < costs[neighbour]:
                    continue  # an earlier rewire in this loop made it cheaper already
                if neighbour not in valid:
                    valid[neighbour] = check_motion(new_state, ompl_state(tree.state(neighbour), 0))
                if valid[neighbour]:
                    nodes.rewire(neighbour, added, through_new)
                    rewires += 1
                    rewired = True

            if (found_goal or rewired) and nodes.goal_nodes:
                candidate = nodes.best_cost()
                if candidate < best:
                    best = progress.best_cost = candidate
                    improvements.append((progress.iterations, best))
                    if settings.tree_pruning:
                        self._prune(points, goal, best)
                    if not settings.continue_after_goal_reached or objective.isSatisfied(ob.Cost(best)):
                        break

        if nodes.goal_nodes:
            self._add_solution(points, [tree.state(node) for node in nodes.best_branch()])
            status = ob.PlannerStatus.EXACT_SOLUTION
        else:
            status = ob.PlannerStatus.TIMEOUT
        ou.OMPL_INFORM(f"{name}: Created {len(tree)} states, {rewires} rewires; best cost {best:.4g}")
        return result(status)

    def _prune(self, points: Points, goal: ob.Goal, best: float) -> None:
        """og.RRTstar's tree pruning, once the best cost fell by more than ``prune_threshold``
        since the last pruning: remove the nodes whose :func:`_solution_lower_bounds` exceed
        ``best``, unless a kept node descends from them (the best goal node is kept)."""
        if math.isfinite(self._pruned_cost) and abs(best - self._pruned_cost) / self._pruned_cost <= (
            self.settings.prune_threshold
        ):
            return
        nodes = self._tree
        assert nodes is not None
        keep = _solution_lower_bounds(points, nodes.tree, goal) <= best
        keep[nodes.best_goal()] = True  # rounding must not prune the solution
        removed = nodes.prune(keep)
        self._pruned_cost = best
        ou.OMPL_DEBUG(f"{self.getName()}: pruned {removed} states")

    def _progress_extras(self) -> dict[str, Callable[[], str]]:
        return {"tree size INTEGER": lambda: str(len(self._tree or ()))}

    def _fill_planner_data(self, data: ob.PlannerData, points: Points, keep_alive: list[ob.State]) -> None:
        """og.RRTstar's graph: the best goal node as the goal vertex, roots as start vertices,
        edges parent -> child, every vertex tag 0."""
        if self._tree is not None:
            best = self._tree.best_goal()
            goal_nodes = () if best == NO_PARENT else (best,)
            self._add_tree(data, points, self._tree.tree, 0, keep_alive, goal_nodes=goal_nodes)
