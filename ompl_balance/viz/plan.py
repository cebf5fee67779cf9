"""What a solve left to look at: the path, the trees, the start and goal, as arrays of states.

A :class:`Plan` is read from an ``og.SimpleSetup`` after a solve (:func:`path_states`,
:func:`planner_trees`, :func:`start_state`, :func:`goal_state`), or made from states the user
gives, in the layout of the problem's :class:`~ompl_balance.viz.scene.Scene`.
:func:`animation_frames` cuts the path into the frames of its animation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .scene import Scene

#: Tags of tree vertices in OMPL's RRT-Connect and the package's planners, by tree.
TREE_NAMES = {1: "start tree", 2: "goal tree"}


@dataclass(frozen=True)
class Tree:
    """A planner's tree: ``states`` (n, state size) and ``edges`` (m, 2) of row indices; ``name`` says which."""

    name: str
    states: np.ndarray
    edges: np.ndarray


@dataclass
class Plan:
    """What is shown of a problem's solve.

    Attributes
    ----------
    start, goal:
        The start state and the goal state (state size,), or ``None`` when unknown.
    path:
        The solution path's states (n, state size); (0, state size) when there is none.
    trees:
        The planner's trees (empty unless asked for).
    status:
        How the solve ended, in OMPL's words ("Exact solution", "Timeout", ...); "" without a solve.
    planner:
        The planner's name ("" when there was none).
    """

    start: np.ndarray | None
    goal: np.ndarray | None
    path: np.ndarray
    trees: list[Tree] = field(default_factory=list)
    status: str = ""
    planner: str = ""


def path_states(scene: Scene, path: og.PathGeometric) -> np.ndarray:
    """The states of ``path`` (n, state size) in ``scene``'s layout."""
    return np.array([scene.values(path.getState(i)) for i in range(path.getStateCount())]).reshape(-1, scene.state_size)


def planner_trees(si: ob.SpaceInformation, planner: ob.Planner, scene: Scene) -> list[Tree]:
    """The planner's graph as trees, one per vertex tag (OMPL's RRT-Connect and the package's
    planners tag the start tree 1 and the goal tree 2; a one-tree planner's vertices share a tag)."""
    data = ob.PlannerData(si)
    planner.getPlannerData(data)
    count = data.numVertices()
    states = np.array([scene.values(data.getVertex(i).getState()) for i in range(count)]).reshape(-1, scene.state_size)
    tags = np.array([data.getVertex(i).getTag() for i in range(count)], dtype=int)
    edges = np.array([(i, int(j)) for i in range(count) for j in data.getEdges(i)], dtype=int).reshape(-1, 2)
    trees = []
    for tag in sorted(set(tags.tolist())):
        rows = np.flatnonzero(tags == tag)
        index = np.full(count, -1)
        index[rows] = np.arange(len(rows))
        inside = edges[(index[edges[:, 0]] >= 0) & (index[edges[:, 1]] >= 0)]
        name = TREE_NAMES.get(tag, "tree") if len(set(tags.tolist())) > 1 else "tree"
        trees.append(Tree(name, states[rows], index[inside]))
    return trees


def goal_state(goal: ob.Goal | None, scene: Scene) -> np.ndarray | None:
    """The first state of a ``GoalState`` or ``GoalStates`` goal, or ``None`` for other goals."""
    if isinstance(goal, ob.GoalStates):
        return scene.values(goal.getState(0)) if goal.getStateCount() else None
    if isinstance(goal, ob.GoalState):
        return scene.values(goal.getState())
    return None


def start_state(ss: og.SimpleSetup, scene: Scene) -> np.ndarray | None:
    """The problem's first start state, or ``None`` when it has none or OMPL refuses to hand it over.

    ``ProblemDefinition.getStartState`` is not used (OMPL 2.0.1's bindings free the state it
    returns twice). OMPL gives a planner its start states through ``PlannerInputStates``, which
    skips states the validity checker refuses; so for the moment of reading, every state is
    valid (the problem's own checker is put back right after).
    """
    si = ss.getSpaceInformation()
    pdef = ss.getProblemDefinition()
    if pdef.getStartStateCount() == 0:
        return None
    checker = si.getStateValidityChecker()
    planner = og.RRTConnect(si)
    planner.setProblemDefinition(pdef)
    si.setStateValidityChecker(lambda state: True)
    try:
        inputs = ob.PlannerInputStates(planner)
        state = inputs.nextStart()
        values = None if state is None else scene.values(state)
    finally:
        si.setStateValidityChecker(checker)
    return values


def animation_frames(scene: Scene, path: np.ndarray, count: int = 150) -> np.ndarray:
    """The states (m, state size) of an animation of ``path`` (n, state size): about ``count``
    frames (at least the path's states), every state of the path among them, the motions between
    them cut into frames in proportion to their lengths (``scene.motion_length``), as the scene
    interpolates them (``scene.interpolate``, OMPL's interpolation)."""
    if len(path) < 2:
        return path.copy()
    lengths = np.array([scene.motion_length(path[i], path[i + 1]) for i in range(len(path) - 1)])
    total = float(lengths.sum())
    if total > 0:
        steps = np.maximum(1, np.round(lengths / total * max(count - 1, len(lengths))).astype(int))
    else:
        steps = np.ones(len(lengths), dtype=int)
    frames = [path[:1]]
    for i, n in enumerate(steps.tolist()):
        frames.append(scene.interpolate(path[i], path[i + 1], np.arange(1, n + 1) / n))
    return np.concatenate(frames)
