"""One solve of an RRT-Connect planner, as both engines see it.

:class:`Solve` holds what the planner hands an engine for one ``solve()``: the trees and
what its policies keep across solves, this solve's settings, the planner input states and
the goal, and what the engine reports back (counts, the gap between the trees, the record).
Goal feeding and the acceptance of a connection are the same for both engines, so they live
here.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from ompl import base as ob
from ompl import util as ou

from ..core.planner import Progress
from ..core.spaces import Points
from ..core.trees import Tree
from ..policies import NodeFailures, SamplerCounts, SwapState
from .events import LoopCounts, LoopRecord
from .settings import RRTConnectSettings


@dataclass
class Solve:
    """What one solve's loop works with (see the module docstring)."""

    name: str  # the planner's name, for OMPL's messages
    si: ob.SpaceInformation
    points: Points
    settings: RRTConnectSettings
    start_tree: Tree
    goal_tree: Tree
    failures: dict[Tree, NodeFailures]  # per tree, kept across solves
    swap_state: SwapState  # what the tree choice remembers, kept across solves
    inputs: ob.PlannerInputStates
    goal: ob.GoalSampleableRegion
    progress: Progress
    rng: np.random.Generator  # the solve's random numbers (the targets' samples and draws)
    record: LoopRecord | None = None
    valid_sampler: ob.ValidStateSampler | None = None  # sample_policy = valid_sampler's (the planner's)
    counts: LoopCounts = field(default_factory=LoopCounts)
    sampler_counts: SamplerCounts = field(default_factory=SamplerCounts)  # what the sample policy did
    tree_gap: float = float("inf")  # least distance between the trees seen after a connect
    connection: tuple[int, int] | None = None  # (start node, goal node) of the accepted connection

    def wants_goal(self) -> bool:
        """OMPL's rule: goal states join the goal tree while fewer than half of its states were
        sampled (asked only while the goal has more: asking then adds nothing)."""
        size = len(self.goal_tree)
        inputs = self.inputs
        return size == 0 or (inputs.getSampledGoalsCount() < size // 2 and inputs.haveMoreGoalStates())

    def feed_goal(self, ptc: ob.PlannerTerminationCondition) -> bool:
        """Add the next goal state to the goal tree (waiting for one within ``ptc`` while it is
        empty); ``False`` when the goal tree is still empty (no valid goal state)."""
        empty = len(self.goal_tree) == 0
        state = self.inputs.nextGoal(ptc) if empty else self.inputs.nextGoal()
        if state is not None and self.points.is_finite(state):
            self.goal_tree.add(self.points.from_state(state))
        if len(self.goal_tree) == 0:
            ou.OMPL_ERROR(f"{self.name}: Unable to sample any valid states for goal tree")
            return False
        return True

    def accept(self, start_node: int, goal_node: int) -> bool:
        """Whether the goal takes the trees' roots of this connection as a start-goal pair
        (``isStartGoalPairValid``); records it if so.

        OMPL's own goal classes keep ``Goal::isStartGoalPairValid``, which takes every pair, so
        only a goal written in Python is asked (the roots made OMPL states for it).
        """
        if type(self.goal).__module__ != ob.Goal.__module__:
            points = self.points
            start_root = points.ompl_state(self.start_tree.state(self.start_tree.root(start_node)), 0)
            goal_root = points.ompl_state(self.goal_tree.state(self.goal_tree.root(goal_node)), 1)
            if not self.goal.isStartGoalPairValid(start_root, goal_root):
                return False
        self.connection = (start_node, goal_node)
        return True
