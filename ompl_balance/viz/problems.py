"""Scenes of problems: of an ``og.SimpleSetup`` the package's checkers check, of the package's
problem objects, and of the problems ``ompl-balance show`` takes by name.

* :func:`scene_of_setup`: a robot (the package's ``CollisionChecker``), a rigid body
  (``RigidBodyChecker``), an occupancy grid (``GridValidityChecker``), or any other checker of
  a 2-D space (``RealVectorStateSpace(2)`` or ``SE2StateSpace``), whose obstacles are drawn
  where its validity checker refuses the cells of a grid over the bounds (its states' positions);
* :func:`scene_of_problem`: ``MBMProblem`` (for the Panda it was made for), ``RigidBodyProblem``,
  the 2-D ``Problem`` and ``OccupancyProblem``;
* :func:`named_problem`: a name of ``ompl-balance show`` as a scene and a fresh ``SimpleSetup``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..collision.checker import CollisionChecker
from ..collision.rigid.checker import RigidBodyChecker
from ..worlds.boxes import PROBLEMS, TWIN_POCKETS, Problem
from ..worlds.occupancy import OCCUPANCY_PROBLEMS, OccupancyGrid, OccupancyProblem
from .scene import PlaneScene, RigidScene, RobotScene, Scene, occupied_blocks

#: Cells a side of the grid a 2-D world's validity checker is sampled on.
SAMPLED_CELLS = 200
#: OMPL's own 2-D test worlds (``ompl_balance.worlds.ompl_2d``) by the names ``show`` takes.
OMPL_2D = ("env1", "env2", "circles")


@dataclass
class Named:
    """A problem ``ompl-balance show`` took by name: its ``scene``, a ``setup()`` making a fresh
    ``og.SimpleSetup`` to plan in, its ``start`` and ``goal`` states (the first goal of several),
    and the seconds ``time_limit`` its source suggests (``None``: no suggestion)."""

    scene: Scene
    setup: Callable[[], og.SimpleSetup]
    start: np.ndarray
    goal: np.ndarray
    time_limit: float | None = None


def scene_of_setup(ss: og.SimpleSetup | ob.SpaceInformation, end_effector: str | None = None) -> Scene:
    """The scene of a problem set up in ``ss`` (see the module docstring); ``ValueError`` for a
    space and checker it cannot draw, naming what it can."""
    si = ss.getSpaceInformation() if isinstance(ss, og.SimpleSetup) else ss
    checker = si.getStateValidityChecker()
    inner = getattr(checker, "checker", None)
    if isinstance(inner, CollisionChecker):
        return RobotScene(inner, end_effector)
    if isinstance(inner, RigidBodyChecker):
        return RigidScene(inner)
    space = si.getStateSpace()
    se2 = isinstance(space, ob.SE2StateSpace)
    if not (se2 or (isinstance(space, ob.RealVectorStateSpace) and space.getDimension() == 2)):
        raise ValueError(
            f"show draws robots (the package's CollisionChecker), rigid bodies (RigidBodyChecker) and 2-D worlds "
            f"(RealVectorStateSpace(2), SE2StateSpace); this problem's space is {type(space).__name__} of dimension "
            f"{space.getDimension()} with a {type(checker).__name__}"
        )
    bounds = space.getBounds()
    low, high = np.array(bounds.low, dtype=float)[:2], np.array(bounds.high, dtype=float)[:2]
    grid = getattr(checker, "grid", None)
    if isinstance(grid, OccupancyGrid):
        return grid_scene("occupancy grid", grid, se2)
    occupied, cell = _sampled(si, low, high, se2)
    scene = PlaneScene("2-D world", low, high, occupied_blocks(occupied, low, cell), se2=se2)
    scene.notes.append(
        f"obstacles drawn where the validity checker refuses the centres of a {SAMPLED_CELLS} x {SAMPLED_CELLS} grid"
    )
    return scene


def _sampled(si: ob.SpaceInformation, low: np.ndarray, high: np.ndarray, se2: bool) -> tuple[np.ndarray, np.ndarray]:
    """Where ``si``'s validity checker refuses the centres of a grid of cells over ``low``..``high``
    (heading 0 in SE(2)): ``occupied`` (rows, cols) and the cell's (width, height)."""
    cell = (high - low) / SAMPLED_CELLS
    state = si.allocState()
    occupied = np.zeros((SAMPLED_CELLS, SAMPLED_CELLS), dtype=bool)
    xs = low[0] + (np.arange(SAMPLED_CELLS) + 0.5) * cell[0]
    ys = low[1] + (np.arange(SAMPLED_CELLS) + 0.5) * cell[1]
    for row, y in enumerate(ys.tolist()):
        for col, x in enumerate(xs.tolist()):
            if se2:
                state.setXY(x, y)
                state.setYaw(0.0)
            else:
                state[0], state[1] = x, y
            occupied[row, col] = not si.isValid(state)
    return occupied, cell


def grid_scene(title: str, grid: OccupancyGrid, se2: bool = False) -> PlaneScene:
    """An occupancy grid's world: its occupied cells as blocks."""
    resolution = float(grid.resolution)
    blocks = occupied_blocks(grid.occupied, grid.low, (resolution, resolution))
    return PlaneScene(title, grid.low, grid.high, blocks, is_free=grid.is_free, se2=se2)


def box_scene(problem: Problem) -> PlaneScene:
    """A built-in box world (the unit square)."""
    return PlaneScene(problem.name, (0.0, 0.0), (1.0, 1.0), problem.boxes, is_free=problem.world().is_free)


def scene_of_problem(problem: Any, end_effector: str | None = None) -> tuple[Scene, np.ndarray, np.ndarray]:
    """The scene, start and goal of one of the package's problem objects; ``TypeError`` naming the
    objects it takes otherwise."""
    from ..worlds.mbm import MBMProblem
    from ..worlds.rigid import RigidBodyProblem

    if isinstance(problem, RigidBodyProblem):
        return RigidScene(problem.checker(), problem.name), problem.start, problem.goal
    if isinstance(problem, MBMProblem):
        from ..collision.robots import load_panda_vamp

        robot = load_panda_vamp()
        if robot.dof != len(problem.start):
            raise ValueError(
                f"MotionBenchMaker problem {problem.scenario}.{problem.id:03d} has {len(problem.start)} joint values, "
                f"the shipped Panda {robot.dof}: show its SimpleSetup (problem.simple_setup(robot)) instead"
            )
        title = f"{problem.scenario}.{problem.id:03d}"
        scene = RobotScene(CollisionChecker(robot, problem.environment), end_effector, title=title)
        return scene, problem.start, problem.goals[0]
    if isinstance(problem, Problem):
        return box_scene(problem), np.array(problem.start), np.array(problem.goal)
    if isinstance(problem, OccupancyProblem):
        return grid_scene(problem.name, problem.grid, problem.se2), np.array(problem.start), np.array(problem.goal)
    raise TypeError(
        "show takes an og.SimpleSetup (after a solve), a CollisionChecker or RigidBodyChecker with a path, or one "
        f"of the package's problems (MBMProblem, RigidBodyProblem, Problem, OccupancyProblem); got {type(problem).__name__}"
    )


def named_problem(name: str, end_effector: str | None = None) -> Named:
    """The problem ``ompl-balance show NAME`` plans: a built-in 2-D world, an occupancy world, one of
    OMPL's 2-D test worlds, a MotionBenchMaker Panda problem ``SCENARIO.ID``, a shipped rigid-body
    problem, or an OMPL.app ``.cfg`` file. ``ValueError`` naming what it takes otherwise."""
    boxes = {**PROBLEMS, TWIN_POCKETS.name: TWIN_POCKETS}
    if name in boxes:
        problem = boxes[name]
        return Named(box_scene(problem), problem.setup, np.array(problem.start), np.array(problem.goal))
    if name in OCCUPANCY_PROBLEMS:
        grid_problem = OCCUPANCY_PROBLEMS[name]()
        scene = grid_scene(name, grid_problem.grid, grid_problem.se2)
        return Named(scene, grid_problem.setup, np.array(grid_problem.start), np.array(grid_problem.goal))
    if name in OMPL_2D:
        return _ompl_2d(name)
    from ..bench.problems import problem_by_name
    from ..worlds.rigid import RIGID_PROBLEMS, rigid_problem

    if name in RIGID_PROBLEMS or name.endswith(".cfg") or Path(name).is_file():
        rigid = rigid_problem(name)
        checker = rigid.checker()
        return Named(
            RigidScene(checker, rigid.name), lambda: rigid.simple_setup(checker=checker), rigid.start, rigid.goal,
            rigid.time_limit,
        )  # fmt: skip
    try:
        spec = problem_by_name(name)
    except ValueError as error:
        raise ValueError(
            f"{error}; 2-D worlds also: {', '.join([TWIN_POCKETS.name, *OCCUPANCY_PROBLEMS, *OMPL_2D])}; "
            "or an OMPL.app .cfg file"
        ) from None
    if spec.kind != "mbm":  # (the other kinds by name are the 2-D and rigid ones above)
        raise ValueError(f"cannot show problem {name!r} of kind {spec.kind}")
    from ..worlds.mbm import load_mbm

    ss = spec.build()
    robot_scene = scene_of_setup(ss, end_effector)
    robot_scene.title = name
    robot = robot_scene.robot if isinstance(robot_scene, RobotScene) else None
    mbm = next(p for p in load_mbm(spec.source, robot.joint_names if robot else None) if p.id == spec.problem_id)
    built = [ss]

    def setup() -> og.SimpleSetup:  # the first call hands over the setup the scene's checker belongs to
        return built.pop() if built else spec.build()

    return Named(robot_scene, setup, mbm.start, mbm.goals[0])


def _ompl_2d(name: str) -> Named:
    """One of OMPL's 2-D test worlds: a grid map (``env1``, ``env2``) with its start and goal cells,
    or the circles with the first of OMPL's queries among them."""
    from ..worlds.ompl_2d import (
        circles_space_information,
        load_circles,
        load_environment,
        load_queries,
        map_space_information,
    )

    if name == "circles":
        circles = load_circles("circle_obstacles")
        query = load_queries("circle_queries")[0]
        low, high = (circles.min_x, circles.min_y), (circles.max_x, circles.max_y)
        scene = PlaneScene(name, low, high, discs=circles.circles, is_free=circles.no_overlap)
        start, goal = np.array(query.start), np.array(query.goal)

        def circles_setup() -> og.SimpleSetup:
            return _with_query(og.SimpleSetup(circles_space_information(circles)), start, goal)

        return Named(scene, circles_setup, start, goal)
    env = load_environment(name)
    occupied = np.array(env.grid, dtype=int).T != 0  # grid[x][y]: rows are y
    blocks = occupied_blocks(occupied, (0.0, 0.0), (1.0, 1.0))
    scene = PlaneScene(name, (0.0, 0.0), (env.width, env.height), blocks, is_free=env.is_free)
    start, goal = np.array(env.start, dtype=float), np.array(env.goal, dtype=float)

    def map_setup() -> og.SimpleSetup:
        return _with_query(og.SimpleSetup(map_space_information(env)), start, goal)

    return Named(scene, map_setup, start, goal)


def _with_query(ss: og.SimpleSetup, start: np.ndarray, goal: np.ndarray) -> og.SimpleSetup:
    si = ss.getSpaceInformation()
    a, b = si.allocState(), si.allocState()
    a[0], a[1] = float(start[0]), float(start[1])
    b[0], b[1] = float(goal[0]), float(goal[1])
    ss.setStartAndGoalStates(a, b)
    return ss
