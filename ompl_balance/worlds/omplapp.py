"""OMPL.app's problem files (``.cfg``) and solution paths (``.path``), read as OMPL.app reads them.

A ``.cfg`` file names a robot and a world mesh and gives the start and goal of the robot
(``[problem]``), and optionally position bounds and a time limit (``[benchmark]``).
:func:`load_omplapp` builds the :class:`~ompl_balance.worlds.rigid.RigidBodyProblem` exactly
as OMPL.app (``SE2RigidBodyPlanning``/``SE3RigidBodyPlanning``, its benchmark tool and its
GUI) builds it:

* the problem is SE(3) when ``start.z`` is given, else SE(2);
* meshes are read as Assimp reads them (:mod:`~ompl_balance.worlds.mesh_files`: COLLADA turned
  Y-up, node transforms applied); file names are relative to the ``.cfg`` file's folder;
* the robot's frame is the mean of the robot mesh's vertices (its z set to 0 in SE(2)), and its
  triangles are shifted by it; the world's triangles stay where they are;
* start and goal: SE(3) ``x, y, z`` and a rotation of ``theta`` radians about
  ``axis.x, axis.y, axis.z`` (OMPL's ``setAxisAngle``: identity for a zero axis), SE(2) ``x, y,
  theta``;
* bounds: ``volume.min.*``/``volume.max.*`` when all are given, else the box of the world
  mesh's vertices; then widened to contain the start and goal positions (OMPL.app's
  ``InferProblemDefinitionBounds``, with its default factor 1 and margin 0);
* the state validity checking resolution stays OMPL's default (1 % of the space's extent),
  as in OMPL.app; a path is within ``problem.threshold`` (default 1e-6) of the goal.

A state is valid when it is inside the bounds and the robot's triangles do not touch the
world's (FCL), as in OMPL.app. For the package's checker the robot is cut into up to
:data:`ROBOT_PIECES` parts and the world into pieces of about :data:`WORLD_PIECE_TRIANGLES`
triangles (:mod:`~ompl_balance.collision.rigid.pieces`): the same triangles, so the same
answers, with tighter bounding volumes.

OMPL.app's own problem files come under a licence that forbids redistributing them; the
package ships none. Point the loader at your copy of OMPL.app's ``resources`` folder.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..collision.contacts import describe_contacts
from ..collision.environment import Environment
from ..collision.rigid.body import RigidBody
from ..collision.rigid.pieces import soup_mesh, split_triangles
from .mesh_files import MeshFile, read_mesh_file
from .rigid import RigidBodyProblem

#: The robot mesh is cut into at most this many parts.
ROBOT_PIECES = 8
#: The world mesh is cut into pieces of about this many triangles ...
WORLD_PIECE_TRIANGLES = 64
#: ... and at most this many pieces.
WORLD_PIECES = 256

_AXES = ("x", "y", "z")


@dataclass(frozen=True)
class _Entry:
    value: str
    line: int


class _Config:
    """A ``.cfg`` file: ``[section]`` headers and ``key = value`` lines (``#`` and ``;`` start
    comments), keys as ``section.key`` in lower case, each with its line number."""

    def __init__(self, path: Path):
        self.path = path
        self.entries: dict[str, _Entry] = {}
        self.sections: dict[str, int] = {}
        try:
            text = path.read_text()
        except (OSError, UnicodeDecodeError) as error:
            raise ValueError(f"cannot read OMPL.app problem file {path}: {error}") from error
        section = ""
        for number, raw in enumerate(text.splitlines(), start=1):
            line = raw.split("#", 1)[0].strip()
            if not line or line.startswith(";"):
                continue
            if line.startswith("["):
                if not line.endswith("]") or len(line) < 3:
                    raise ValueError(f"{path}:{number}: malformed section header {raw.strip()!r}")
                section = line[1:-1].strip().lower()
                self.sections.setdefault(section, number)
                continue
            if "=" not in line:
                raise ValueError(f"{path}:{number}: expected 'key = value' or '[section]', got {raw.strip()!r}")
            key, value = (part.strip() for part in line.split("=", 1))
            if not key:
                raise ValueError(f"{path}:{number}: a line with no key: {raw.strip()!r}")
            name = f"{section}.{key.lower()}" if section else key.lower()
            if name in self.entries and section in ("problem", "benchmark"):
                raise ValueError(f"{path}:{number}: {key} is given twice (first on line {self.entries[name].line})")
            self.entries.setdefault(name, _Entry(value, number))

    def has(self, key: str) -> bool:
        return key in self.entries

    def text(self, key: str, why: str = "") -> _Entry:
        if key not in self.entries:
            section, _, name = key.partition(".")
            where = f"line {self.sections[section]}" if section in self.sections else "the file"
            raise ValueError(f"{self.path}: [{section}] (at {where}) has no {name}{why}")
        return self.entries[key]

    def number(self, key: str, why: str = "") -> float:
        """The value of ``key``, a finite number."""
        return self._accepted(key, why, math.isfinite, "a finite number")

    def seconds(self, key: str) -> float:
        """The value of ``key``, a positive number of seconds."""
        return self._accepted(key, "", lambda value: 0 < value < math.inf, "a positive number of seconds")

    def _accepted(self, key: str, why: str, accept: Callable[[float], bool], accepted: str) -> float:
        """The value of ``key`` as a number that ``accept`` takes; ``ValueError`` naming the file,
        line, key, value and what is ``accepted`` otherwise."""
        entry = self.text(key, why)
        try:
            value = float(entry.value)
        except ValueError:
            value = math.nan
        if not accept(value):
            raise ValueError(f"{self.path}:{entry.line}: {key.partition('.')[2]} = {entry.value!r} is not {accepted}")
        return value

    def at(self, key: str) -> str:
        """``file:line`` of ``key``."""
        return f"{self.path}:{self.entries[key].line}"


def axis_angle_quaternion(axis: tuple[float, float, float], angle: float) -> np.ndarray:
    """OMPL's ``SO3StateSpace::StateType::setAxisAngle``: the quaternion ``(x, y, z, w)`` of a
    rotation by ``angle`` (rad) about ``axis`` (any length; identity for a zero axis)."""
    norm = math.sqrt(sum(a * a for a in axis))
    if norm < 1e-9:
        return np.array([0.0, 0.0, 0.0, 1.0])
    s = math.sin(0.5 * angle) / norm
    return np.array([axis[0] * s, axis[1] * s, axis[2] * s, math.cos(0.5 * angle)])


def load_omplapp(cfg_path: str | Path, validate: bool = True) -> RigidBodyProblem:
    """The geometric problem of an OMPL.app ``.cfg`` file (see the module docstring).

    ``ValueError`` naming the file (and line) for: a missing or unreadable file, a malformed
    line, a missing or non-numeric entry, a ``time_limit`` that is not a positive number of seconds,
    a missing or unreadable mesh, a mesh without
    triangles or only degenerate ones, inconsistent bounds, control-based problems
    (``control = ...``) or other state spaces (``statespace = dubins``, ...), which the loader
    does not plan for, and (``validate``, the default) a start or goal in collision. With
    ``validate=False`` such a problem loads, and OMPL's planners report it when they solve.
    """
    path = Path(cfg_path)
    if not path.is_file():
        raise ValueError(f"OMPL.app problem file {path} not found")
    config = _Config(path)
    for key, what in (("problem.control", "control-based problems"), ("problem.statespace", "other state spaces")):
        if config.has(key):
            raise ValueError(
                f"{config.at(key)}: {key.partition('.')[2]} = {config.entries[key].value}: {what} are not supported; "
                "the loader reads geometric SE(2) and SE(3) rigid-body problems"
            )
    space = "SE3" if config.has("problem.start.z") else "SE2"
    why = f" (needed for an {space} problem)"
    robot_file = _mesh(config, "problem.robot", why)
    world_file = _mesh(config, "problem.world", why)
    start, goal = (_state(config, side, space, why) for side in ("start", "goal"))

    centre = robot_file.centre.copy()
    if space == "SE2":
        centre[2] = 0.0
    body = RigidBody.from_triangles(space, robot_file.triangles - centre, ROBOT_PIECES, name=Path(robot_file.path).stem)
    environment = Environment()
    world = world_file.triangles
    pieces = min(WORLD_PIECES, max(1, math.ceil(len(world) / WORLD_PIECE_TRIANGLES)))
    for i, group in enumerate(split_triangles(world, pieces)):
        environment.add_mesh(f"{Path(world_file.path).stem}[{i}]", soup_mesh(group))

    axes = 3 if space == "SE3" else 2
    low, high = _bounds(config, world_file, axes)
    positions = np.array([start[:axes], goal[:axes]])
    low, high = np.minimum(low, positions.min(axis=0)), np.maximum(high, positions.max(axis=0))

    objective = None
    objective_threshold = None
    if config.has("problem.objective"):
        objective = config.entries["problem.objective"].value.lower()
        if not objective.startswith("length"):
            raise ValueError(
                f"{config.at('problem.objective')}: objective = {objective}: only 'length' is supported "
                "(the package's planners find feasible paths)"
            )
        objective = "length"
        if config.has("problem.objective.threshold"):
            objective_threshold = config.number("problem.objective.threshold")
    problem = RigidBodyProblem(
        name=config.entries["problem.name"].value if config.has("problem.name") else path.stem,
        body=body,
        environment=environment,
        start=start,
        goal=goal,
        low=low,
        high=high,
        time_limit=config.seconds("benchmark.time_limit") if config.has("benchmark.time_limit") else None,
        goal_threshold=config.number("problem.threshold") if config.has("problem.threshold") else 1e-6,
        objective=objective,
        objective_threshold=objective_threshold,
        source=path,
    )
    checker = problem.checker()
    for side, state in (("start", start), ("goal", goal)) if validate else ():
        key = f"problem.{side}.x"
        if not checker.inside_bounds(state):
            raise ValueError(f"{config.at(key)}: the {side} state {state.tolist()} is outside the bounds")
        if not checker.is_valid(state):
            raise ValueError(
                f"{config.at(key)}: the {side} state {state.tolist()} is in collision with the world: "
                f"{describe_contacts(checker.collisions(state))}"
            )
    return problem


def _mesh(config: _Config, key: str, why: str) -> MeshFile:
    entry = config.text(key, why)
    file = Path(entry.value)
    if not file.is_absolute():
        file = config.path.parent / file
    try:
        return read_mesh_file(file)
    except ValueError as error:
        raise ValueError(f"{config.at(key)}: {key.partition('.')[2]} = {entry.value}: {error}") from error


def _state(config: _Config, side: str, space: str, why: str) -> np.ndarray:
    number = lambda name: config.number(f"problem.{side}.{name}", why)  # noqa: E731
    if space == "SE2":
        return np.array([number("x"), number("y"), number("theta")])
    axis = (number("axis.x"), number("axis.y"), number("axis.z"))
    rotation = axis_angle_quaternion(axis, number("theta"))
    return np.array([number("x"), number("y"), number("z"), *rotation])


def _bounds(config: _Config, world: MeshFile, axes: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``volume`` bounds when all are given, else the world vertices' box (OMPL.app's inference)."""
    keys = [f"problem.volume.{end}.{axis}" for end in ("min", "max") for axis in _AXES[:axes]]
    given = [k for k in keys if config.has(k)]
    if given and len(given) < len(keys):
        missing = ", ".join(k.partition(".")[2] for k in keys if k not in given)
        raise ValueError(f"{config.at(given[0])}: the volume bounds are incomplete: missing {missing}")
    if not given:
        return world.vertices[:, :axes].min(axis=0), world.vertices[:, :axes].max(axis=0)
    low = np.array([config.number(k) for k in keys[:axes]])
    high = np.array([config.number(k) for k in keys[axes:]])
    if (low > high).any():
        axis = int(np.argmax(low > high))
        raise ValueError(
            f"{config.at(keys[axis])}: volume.min.{_AXES[axis]} = {low[axis]} is above volume.max.{_AXES[axis]} = "
            f"{high[axis]}"
        )
    return low, high


def read_omplapp_path(path: str | Path, space: str | None = None) -> np.ndarray:
    """The states of an OMPL.app ``.path`` file (one state per line: ``x y yaw`` or
    ``x y z qx qy qz qw``) as an array (n, 3) or (n, 7), quaternions normalised (files print
    them to a few digits). ``space`` (``"SE2"``/``"SE3"``), if given, must match the file.
    ``ValueError`` naming the file and line for anything else."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"cannot read OMPL.app path file {path}: {error}") from error
    size = {"SE2": 3, "SE3": 7}.get(space or "", 0)
    rows, lines = [], []
    for number, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip():
            continue
        try:
            values = [float(v) for v in raw.split()]
        except ValueError:
            values = []
        size = size or len(values)
        if len(values) != size or size not in (3, 7) or not all(map(math.isfinite, values)):
            expected = f"{size} numbers" if size in (3, 7) else "3 (SE(2)) or 7 (SE(3)) numbers"
            raise ValueError(f"{path}:{number}: expected {expected} per state, got {raw.strip()!r}")
        rows.append(values)
        lines.append(number)
    if not rows:
        raise ValueError(f"{path} holds no states")
    states = np.array(rows)
    if size == 7:  # files print a few digits: the quaternions are unit to that precision
        norms = np.linalg.norm(states[:, 3:], axis=1)
        far = np.flatnonzero(np.abs(norms - 1.0) > 1e-3)
        if len(far):
            raise ValueError(f"{path}:{lines[far[0]]}: the quaternion has norm {norms[far[0]]:.6g}, not 1")
        states[:, 3:] /= norms[:, None]
    return states
