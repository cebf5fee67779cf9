"""``show``: a problem and its plan in the browser, live or as one self-contained HTML file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob
from ompl import geometric as og

from ..collision.checker import CollisionChecker
from ..collision.rigid.checker import RigidBodyChecker
from .extra import require_viser
from .live import LiveViewer
from .page import write_page
from .plan import Plan, animation_frames, goal_state, path_states, planner_trees, start_state
from .problems import scene_of_problem, scene_of_setup
from .scene import RigidScene, RobotScene, Scene

#: Frames of a path's animation.
FRAMES = 150


def show(
    problem_or_simple_setup: Any,
    path: og.PathGeometric | ArrayLike | None = None,
    trees: bool = False,
    file: str | Path | None = None,
    *,
    end_effector: str | None = None,
    host: str = "127.0.0.1",
    port: int = 8080,
    open_browser: bool = True,
    wait: bool = True,
) -> Path | LiveViewer:
    """Show a problem and its plan: the robot or body, the obstacles, start and goal, the path
    animated (a slider and a play button) and, with ``trees``, the planner's trees.

    Parameters
    ----------
    problem_or_simple_setup:
        An ``og.SimpleSetup`` after a solve (any planner, stock or the package's) whose validity
        checker is the package's robot or rigid-body checker, an occupancy grid's, or any checker
        of a 2-D space (``RealVectorStateSpace(2)``, ``SE2StateSpace``: its obstacles are drawn
        where it refuses the cells of a grid); a ``CollisionChecker`` (a robot of yours among
        your ``Environment``) or ``RigidBodyChecker`` with ``path``; or one of the package's
        problems (``MBMProblem``, ``RigidBodyProblem``, ``Problem``, ``OccupancyProblem``).
    path:
        The path to animate: an ``og.PathGeometric`` or states (n, state size) in the checker's
        layout (joint values in ``robot.joint_names`` order; ``(x, y, yaw)``;
        ``(x, y, z, qx, qy, qz, qw)``; ``(x, y)``). Default: the setup's solution path, if any.
    trees:
        Draw the planner's trees (a ``SimpleSetup``'s planner): every node at the end effector's
        (or body's, or point's) position, edges as straight lines, coloured by tree.
    file:
        Write one self-contained HTML file here (it opens from disk in a browser, offline)
        instead of serving a live viewer.
    end_effector:
        The robot link the path and trees trace (default: the robot's last link).
    host, port:
        Where the live viewer listens: this machine only by default; ``host="0.0.0.0"`` shares
        it with the network; ``port=0`` takes a free port.
    open_browser:
        Open the live viewer in the default browser.
    wait:
        Block until Ctrl-C, then stop the live viewer; ``False`` returns the running viewer.

    Returns
    -------
    pathlib.Path or LiveViewer
        The file written, or the live viewer (stopped already when ``wait``).

    Raises
    ------
    MissingExtraError
        viser is not installed (the ``viz`` extra).
    TypeError, ValueError
        For what cannot be shown, naming what can.
    """
    require_viser()
    scene, plan = scene_and_plan(problem_or_simple_setup, path, trees, end_effector)
    frames = animation_frames(scene, plan.path, FRAMES)
    if not len(frames) and plan.start is not None:  # no path: the robot stays at the start
        frames = plan.start[None]
    if file is not None:
        return write_page(scene, plan, frames, file, trees).path
    viewer = LiveViewer(scene, plan, frames, trees, host, port)
    viewer.present(open_browser, wait)
    return viewer


def scene_and_plan(
    shown: Any, path: og.PathGeometric | ArrayLike | None, trees: bool, end_effector: str | None = None
) -> tuple[Scene, Plan]:
    """What :func:`show` shows of ``shown`` (its first argument) and ``path``."""
    if isinstance(shown, og.SimpleSetup):
        return _of_setup(shown, path, trees, end_effector)
    if trees:
        raise ValueError(
            f"trees=True needs the og.SimpleSetup that was solved (its planner holds the trees), got {type(shown).__name__}"
        )
    if isinstance(shown, CollisionChecker):
        scene: Scene = RobotScene(shown, end_effector)
        start = goal = None
    elif isinstance(shown, RigidBodyChecker):
        scene = RigidScene(shown)
        start = goal = None
    else:
        scene, start, goal = scene_of_problem(shown, end_effector)
    states = _states(scene, path)
    if len(states):
        start, goal = (states[0] if start is None else start), (states[-1] if goal is None else goal)
    return scene, Plan(start, goal, states)


def _of_setup(ss: og.SimpleSetup, path: Any, trees: bool, end_effector: str | None) -> tuple[Scene, Plan]:
    scene = scene_of_setup(ss, end_effector)
    si = ss.getSpaceInformation()
    solved = ss.haveSolutionPath()
    if path is None and solved:
        path = ss.getSolutionPath()
    states = _states(scene, path)
    planner = ss.getPlanner()
    status = _words(ss.getLastPlannerStatus()) if planner is not None else ""
    start = start_state(ss, scene)
    goal = goal_state(ss.getGoal(), scene)
    if goal is not None and len(states) and isinstance(ss.getGoal(), ob.GoalStates):
        goal = states[-1]  # of several goal states, the one reached
    found = planner_trees(si, planner, scene) if trees and planner is not None else []
    return scene, Plan(start, goal, states, found, status, planner.getName() if planner is not None else "")


def _words(status: Any) -> str:
    """An OMPL planner status in OMPL's words ("Exact solution", "Timeout", ...)."""
    return str(status.asString() if hasattr(status, "asString") else status)


def _states(scene: Scene, path: Any) -> np.ndarray:
    if path is None:
        return np.zeros((0, scene.state_size))
    if isinstance(path, og.PathGeometric):
        return scene.as_states(path_states(scene, path))
    return scene.as_states(path)
