"""The grow/connect loop in Python: any OMPL space, the space information's own checkers.

:func:`run` is OMPL's ``RRTConnect::solve`` loop (``src/ompl/geometric/planners/rrt/src/
RRTConnect.cpp``) with the package's policies: each iteration picks the tree to grow
(:class:`~ompl_balance.policies.TreeChoice`), draws a target (the sample policy), grows the
tree one step towards it (:class:`Extender`) and walks the other tree towards the state
just added until it is trapped or reaches it. States and motions are checked with
``si.isValid`` and ``si.checkMotion``, so it works with any checker and motion validator.
It is the reference the compiled engine (:mod:`ompl_balance.engine.loop`) is held against.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from ompl import base as ob

from ..core.spaces import Points
from ..core.trees import NO_PARENT, Tree
from ..policies import NearestChoice, SampleContext, TargetChoice, TreeChoice, target_choice
from .events import Grow, GrowStep, LoopRecord, TreeChoiceEvent
from .solve import Solve


class LoopPolicies(NamedTuple):
    """A solve's policies as the Python engine calls them (the compiled engine runs the same rules
    from its settings: :mod:`ompl_balance.engine.loop`)."""

    tree_choice: TreeChoice  # which tree grows next
    nearest: NearestChoice  # which node extends towards a target
    targets: TargetChoice  # where an iteration's target comes from


def loop_policies(solve: Solve) -> LoopPolicies:
    """The policies of ``solve``'s settings, as objects over its trees and random numbers."""
    settings = solve.settings
    tree_choice = TreeChoice(
        settings.swap_policy,
        solve.swap_state,
        settings.balance_tree_sizes,
        settings.max_tree_size_ratio,
        settings.swap_steps,
    )
    nearest = NearestChoice(
        settings.nearest_policy, solve.failures, settings.exhausted_after, settings.exhaustion_target
    )
    context = SampleContext(
        solve.points,
        solve.start_tree,
        solve.goal_tree,
        solve.rng.random,
        solve.sampler_counts,
        nearest,
        settings.goal_bias,
        settings.min_quality,
        settings.uniform_rate,
    )
    if solve.valid_sampler is not None:
        context.valid_sampler = solve.valid_sampler
        context.checker, context.scratch = solve.si.getStateValidityChecker(), solve.si.allocState()
    return LoopPolicies(tree_choice, nearest, target_choice(settings.sample_policy, context))


@dataclass
class Extender:
    """One solve's extension step: what :meth:`grow` needs, fixed for the solve."""

    points: Points
    range: float
    intermediate_states: bool
    is_valid: Callable[[ob.State], bool]
    check_motion: Callable[[ob.State, ob.State], bool]
    step_may_stall: bool  # whether a step of ``range`` can round back onto its start
    nearest: NearestChoice
    record: LoopRecord | None

    def grow(
        self, tree: Tree, from_start: bool, target: Any, iteration: int, connect: bool, node: int | None = None
    ) -> tuple[Grow, int, float]:
        """Extend ``tree`` one step towards ``target``.

        Returns the outcome, the node added (``NO_PARENT`` when trapped) and the distance
        from the node extended to ``target`` (before the step). The node extended is
        ``node`` when given, else the one the nearest policy picks. Motions in the start
        tree are checked from the tree outwards; in the goal tree they run from the new
        state into the tree, so the new state is checked first (``checkMotion`` assumes its
        first state valid), exactly as OMPL does. A motion in collision counts as a failed
        extension of the node (for the nearest policies that count failures).
        """
        points = self.points
        given = node is not None
        if node is None:
            node, distance = self.nearest.node(tree, target)
        else:
            distance = points.distance(tree.state(node), target)
        outcome, added = self._step(tree, from_start, target, node, distance)
        if self.record is not None:
            step = GrowStep(iteration, from_start, connect, np.array(target, dtype=float), node, given, outcome, added)
            self.record.steps.append(step)
        return outcome, added, distance

    def _step(self, tree: Tree, from_start: bool, target: Any, node: int, distance: float) -> tuple[Grow, int]:
        points = self.points
        near = tree.state(node)
        reach = distance <= self.range
        new = target if reach else points.interpolate(near, target, self.range / distance)
        if not reach and self.step_may_stall and points.equal(near, new):
            return Grow.TRAPPED, NO_PARENT
        near_state, new_state = points.ompl_state(near, 0), points.ompl_state(new, 1)
        if from_start:
            valid = self.check_motion(near_state, new_state)
        else:
            valid = self.is_valid(new_state) and self.check_motion(new_state, near_state)
        if not valid:
            self.nearest.failed(tree, node)
            return Grow.TRAPPED, NO_PARENT
        added = node
        if self.intermediate_states:
            # States along the motion, ordered away from the tree's root.
            for point in points.segment_points(near, new):
                added = tree.add(point, added)
        else:
            added = tree.add(new, node)
        return (Grow.REACHED if reach else Grow.ADVANCED), added


#: Iterations between two asks of :func:`run`'s ``hand_over``.
HAND_OVER_EVERY = 32


def run(
    solve: Solve, ptc: ob.PlannerTerminationCondition, hand_over: Callable[[], bool] | None = None
) -> ob.PlannerStatus.PlannerStatusType | None:
    """The loop until the trees connect (``EXACT_SOLUTION``, ``solve.connection`` set), ``ptc``
    says stop (``TIMEOUT``) or no goal state can be had (``INVALID_GOAL``); or ``None`` at the start
    of an iteration where ``hand_over()`` (asked every :data:`HAND_OVER_EVERY` iterations) says
    the compiled engine, loaded meanwhile, takes the rest of the solve: everything the loop keeps
    is in ``solve`` and the points' block of samples, so the compiled engine goes on with the
    same trees and random numbers (``tests/test_engine.py``)."""
    settings, points, counts = solve.settings, solve.points, solve.counts
    start_tree, goal_tree = solve.start_tree, solve.goal_tree
    choice, nearest, targets = loop_policies(solve)
    record = solve.record
    extender = Extender(
        points,
        settings.range,
        settings.intermediate_states,
        solve.si.isValid,
        solve.si.checkMotion,
        points.may_stall(settings.range),
        nearest,
        record,
    )
    plain_nearest = settings.nearest_policy == "euclidean"
    while not ptc():
        if hand_over is not None and counts.iterations % HAND_OVER_EVERY == 0 and hand_over():
            return None
        if solve.wants_goal() and not solve.feed_goal(ptc):
            return ob.PlannerStatus.INVALID_GOAL
        counts.iterations += 1
        iteration = solve.progress.iterations = counts.iterations

        before = choice.state.grew_start, choice.state.steps, choice.state.collided
        grow_start, cause = choice.next_tree(len(start_tree), len(goal_tree))
        if cause is not None and iteration > 1:
            counts.swaps[cause] += 1
        if record is not None:
            record.choices.append(TreeChoiceEvent(iteration, *before, grow_start, cause))
        tree, other_tree = (start_tree, goal_tree) if grow_start else (goal_tree, start_tree)

        target, node = targets.target(grow_start)
        if target is None:
            continue
        grown, added, _ = extender.grow(tree, grow_start, target, iteration, False, node)
        if grown is Grow.TRAPPED:
            continue
        # Connect: walk the other tree towards the state just added until trapped or there.
        target = tree.state(added)  # stays valid: only the other tree grows while connecting
        connected, reached, gap = extender.grow(other_tree, not grow_start, target, iteration, True)
        choice.connect_stepped()
        while connected is Grow.ADVANCED:
            # Each further step extends the node just added (why not the nearest policy's
            # choice: see policies.NearestChoice).
            connected, reached, gap = extender.grow(other_tree, not grow_start, target, iteration, True, reached)
            choice.connect_stepped()
        # OMPL's "approx goal distance": the other tree's nearest node to the state just
        # added, after the connect (the node the last step extended, for the plain nearest).
        if connected is Grow.REACHED:
            gap = 0.0
        elif not plain_nearest:
            gap = other_tree.nearest(target)[1]
        solve.tree_gap = min(solve.tree_gap, gap)
        choice.connect_ended(connected is Grow.TRAPPED)
        if connected is Grow.TRAPPED:
            continue
        start_node, goal_node = (added, reached) if grow_start else (reached, added)
        if solve.accept(start_node, goal_node):
            return ob.PlannerStatus.EXACT_SOLUTION
    return ob.PlannerStatus.TIMEOUT
