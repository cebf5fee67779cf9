"""MotionBenchMaker problems in the neutral JSON form (schema ``mbm-neutral-v1``).

One file per scenario: joint names, and per problem a start, one or more goals
(any goal is a success) and the obstacles (boxes with half extents, cylinders along
local z with full length, spheres; world frame = robot base). The problems were made
for VAMP's Panda model (:func:`ompl_balance.collision.robots.load_panda_vamp`).

The package ships four scenarios of MotionBenchMaker's Panda set, 100 problems each
(:data:`SCENARIOS`); :func:`load_mbm` takes their names or a file of the same schema.
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..collision.checker import CollisionChecker
from ..collision.environment import Environment
from ..collision.kinematics import RobotModel
from ..validity import setup_robot, space_for

#: The scenarios shipped with the package (``data/mbm/panda/<name>.json``).
SCENARIOS = ("table_pick", "table_under_pick", "box", "bookshelf_small")
MBM_DIR = Path(str(resources.files("ompl_balance") / "data" / "mbm" / "panda"))


def scenario_path(scenario: str | Path) -> Path:
    """The file of a shipped scenario (``"box"``), or ``scenario`` itself when it is a path."""
    if str(scenario) in SCENARIOS:
        return MBM_DIR / f"{scenario}.json"
    path = Path(scenario)
    if not path.is_file():
        raise ValueError(
            f"{str(scenario)!r} is neither a shipped MotionBenchMaker scenario ({', '.join(SCENARIOS)}) nor a file"
        )
    return path


@dataclass(frozen=True)
class MBMProblem:
    """One problem: ``start`` (dof,) and ``goals`` (k, dof) in rad, ordered as the loader's joint names."""

    scenario: str
    id: int
    start: np.ndarray
    goals: np.ndarray
    environment: Environment
    valid: bool  # the file's flag: start and a goal collision-free under VAMP's sphere model

    def simple_setup(
        self, robot: RobotModel, checker: CollisionChecker | None = None, motion: str = "certified"
    ) -> og.SimpleSetup:
        """A ``SimpleSetup`` for this problem: ``robot``'s joint space, the package's checker
        (``checker``, or a new one for this environment) and its ``motion`` validator
        (``"certified"`` or ``"discrete"``, see :func:`~ompl_balance.validity.setup_robot`),
        the start, and every goal as ``ob.GoalStates`` (any goal is a success).

        ``ValueError`` when ``robot`` has another number of joints than the problem's
        configurations (load the problems with ``load_mbm(scenario, robot.joint_names)``:
        it reorders them to the robot's joints and refuses joints the two do not share).
        """
        if robot.dof != len(self.start):
            raise ValueError(
                f"MotionBenchMaker {self.scenario} problem {self.id}: its configurations have {len(self.start)} joint "
                f"values but robot {robot.name!r} has {robot.dof} joints ({', '.join(robot.joint_names)}); load the "
                "problems with load_mbm(scenario, robot.joint_names) for the robot they were made for"
            )
        ss = og.SimpleSetup(space_for(robot))
        setup_robot(ss, checker or CollisionChecker(robot, self.environment), motion=motion)
        si = ss.getSpaceInformation()
        start = si.allocState()
        for i, value in enumerate(self.start):
            start[i] = float(value)
        goals = ob.GoalStates(si)
        for configuration in self.goals:
            goal = si.allocState()
            for i, value in enumerate(configuration):
                goal[i] = float(value)
            goals.addState(goal)
        ss.setStartState(start)
        ss.setGoal(goals)
        return ss


def load_mbm(scenario: str | Path, joint_names: list[str] | None = None) -> list[MBMProblem]:
    """The problems of a scenario: a shipped one by name (:data:`SCENARIOS`) or a JSON file.

    Configurations are reordered to ``joint_names`` (default: the file's order). Raises
    ``ValueError`` naming the file, problem and field for anything missing or malformed,
    and for joint names the file and ``joint_names`` do not share.
    """
    path = scenario_path(scenario)
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as error:
        raise ValueError(f"cannot read MotionBenchMaker file {path}: {error}") from error
    file_joints = _field(data, "joint_names", path)
    joint_names = list(file_joints) if joint_names is None else list(joint_names)
    unknown = sorted(set(file_joints) ^ set(joint_names))
    if unknown:
        raise ValueError(
            f"{path}: joint names {unknown} are not in both the file {file_joints} and the robot {joint_names}"
        )
    column = [file_joints.index(name) for name in joint_names]
    scenario = str(data.get("scenario", path.stem))
    return [
        _problem(p, scenario, column, f"{path} problem {p.get('id', i) if isinstance(p, dict) else i}")
        for i, p in enumerate(_field(data, "problems", path))
    ]


def _field(record: Any, name: str, where: object) -> Any:
    if not isinstance(record, dict) or name not in record:
        raise ValueError(f"{where}: missing field {name!r}")
    return record[name]


def _configurations(values: Any, width: int, where: str) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.ndim != 2 or array.shape[1] != width or not np.all(np.isfinite(array)):
        raise ValueError(f"{where}: expected finite configurations of {width} joint values, got {values!r}")
    return array


def _problem(record: Any, scenario: str, column: list[int], where: str) -> MBMProblem:
    start = _configurations([_field(record, "start", where)], len(column), f"{where} start")[0, column]
    goals = _configurations(_field(record, "goals", where), len(column), f"{where} goals")[:, column]
    environment = Environment()
    for index, obstacle in enumerate(_field(record, "obstacles", where)):
        name = str(obstacle.get("name", f"obstacle{index}")) if isinstance(obstacle, dict) else f"obstacle{index}"
        at = f"{where} obstacle {name!r}"
        kind = _field(obstacle, "type", at)
        pose = (_field(obstacle, "position", at), _field(obstacle, "orientation_xyzw", at))
        try:
            if kind == "box":
                environment.add_box(name, _field(obstacle, "half_extents", at), *pose)
            elif kind == "cylinder":
                environment.add_cylinder(name, _field(obstacle, "radius", at), _field(obstacle, "length", at), *pose)
            elif kind == "sphere":
                environment.add_sphere(name, _field(obstacle, "radius", at), pose[0])
            else:
                raise ValueError(f"unknown obstacle type {kind!r} (box, cylinder, sphere)")
        except (TypeError, ValueError) as error:
            raise ValueError(f"{at}: {error}") from error
    return MBMProblem(
        scenario, int(_field(record, "id", where)), start, goals, environment, bool(record.get("valid", True))
    )


# -- problems of benchmark runs -------------------------------------------------------


@functools.lru_cache(maxsize=4)
def _robot(robot_dir: str) -> RobotModel:
    """The robot of a folder (``""``: the Panda shipped with the package), loaded once per process."""
    from ..collision.robots import load_panda_vamp

    return load_panda_vamp(robot_dir or None)


@functools.lru_cache(maxsize=16)
def _scenario(source: str, robot_dir: str) -> dict[int, MBMProblem]:
    """A scenario's problems by id, joints ordered as the robot's; loaded once per process."""
    return {problem.id: problem for problem in load_mbm(source, _robot(robot_dir).joint_names)}


def problem_setup(source: str, problem_id: int, robot_dir: str = "", motion: str = "certified") -> og.SimpleSetup:
    """The ``SimpleSetup`` of problem ``problem_id`` of scenario ``source`` (a shipped name or a
    file) for the robot in ``robot_dir`` (``""``: the shipped Panda), with the ``motion``
    validator. Robot and scenario are read once per process."""
    return _scenario(source, robot_dir)[problem_id].simple_setup(_robot(robot_dir), motion=motion)


def load_shipped_data() -> None:
    """Read the shipped Panda and scenarios into the caches of :func:`problem_setup`.

    The forkserver of a benchmark sweep with MotionBenchMaker problems calls this (by
    importing :mod:`ompl_balance.bench.preload_mbm`), so every run's process, forked from
    it, starts with them instead of reading them again (~0.1 s a run).
    """
    for scenario in SCENARIOS:
        _scenario(scenario, "")


def files_digest(paths: Sequence[Path]) -> str:
    """A short hash of the files' contents (a problem read from them changes when they do)."""
    digest = hashlib.blake2b(digest_size=8)
    for path in paths:
        digest.update(path.read_bytes())
    return digest.hexdigest()
