"""Rigid-body problems: a mesh robot in SE(2) or SE(3) among obstacles, ready to plan in.

:class:`RigidBodyProblem` holds a body, its obstacles, position bounds, start and goal; its
:meth:`~RigidBodyProblem.simple_setup` is an ``og.SimpleSetup`` with the package's checker and
certified (default) or discrete motions. Problems come from OMPL.app's problem files
(:func:`~ompl_balance.worlds.omplapp.load_omplapp`) or from the set the package ships
(:data:`RIGID_PROBLEMS`, :func:`rigid_problem`), from easy to hard:

``se2_slot``
    A rod must turn to pass through a gap in a wall (SE(2)).
``se2_bugtrap``
    An L-shaped robot starts inside a trap whose only exit is a channel (SE(2)).
``se3_slot``
    A T-shaped robot must turn flat to pass through a slot in a wall.
``se3_cage``
    An L-shaped robot starts inside a closed cage with one narrow window: one tree is trapped.
``se3_room``
    An L-shaped robot crosses a cluttered room through a hatch or a window in a partition.
``se3_maze``
    A six-armed "jack" winds through a two-storey maze, turning to pass a hole in the floor.

The robots are triangle meshes the package writes itself (:func:`write_robot_meshes`, files in
``ompl_balance/data/rigid/``), one convex box per part; obstacles are boxes. Lengths in metres.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np
import trimesh
from ompl import base as ob
from ompl import geometric as og

from ..collision.budget import MOTION_BUDGET
from ..collision.environment import Environment
from ..collision.rigid.body import RigidBody
from ..collision.rigid.checker import RigidBodyChecker
from ..collision.rigid.pieces import soup_mesh
from ..validity import rigid_body_space, set_rigid_state, setup_rigid_body
from .mesh_files import read_mesh_file

RIGID_DIR = Path(str(resources.files("ompl_balance") / "data" / "rigid"))


@dataclass(frozen=True, eq=False)
class RigidBodyProblem:
    """A rigid body among obstacles, with a start and a goal.

    ``start`` and ``goal``: states ``(x, y, yaw)`` (SE(2)) or ``(x, y, z, qx, qy, qz, qw)``
    (SE(3)); ``low``/``high``: position bounds (2 or 3 numbers). ``goal_threshold``: how close
    (OMPL's state distance) a path must end to the goal. ``time_limit``: the seconds the source
    suggests per run (OMPL.app's ``[benchmark] time_limit``). ``objective``: ``"length"`` when
    the source asks for short paths (OMPL.app's ``objective = length``), with its cost
    ``objective_threshold``. ``source``: the problem file, if any.
    """

    name: str
    body: RigidBody
    environment: Environment
    start: np.ndarray
    goal: np.ndarray
    low: np.ndarray
    high: np.ndarray
    time_limit: float | None = None
    goal_threshold: float = 1e-6
    objective: str | None = None
    objective_threshold: float | None = None
    source: Path | None = field(default=None)

    @property
    def space(self) -> str:
        """``"SE2"`` or ``"SE3"``."""
        return self.body.space

    def checker(self, clearance: float = 0.0, motion_budget: int | None = MOTION_BUDGET) -> RigidBodyChecker:
        """A new checker for this problem (its own work counter), with the problem's bounds; its
        certified motions keep ``clearance`` within ``motion_budget`` work units each (see
        :class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`)."""
        return RigidBodyChecker(
            self.body, self.environment, (self.low, self.high), clearance=clearance, motion_budget=motion_budget
        )

    def simple_setup(self, motion: str = "certified", checker: RigidBodyChecker | None = None) -> og.SimpleSetup:
        """An ``og.SimpleSetup`` over OMPL's ``SE2StateSpace``/``SE3StateSpace`` with the problem's
        bounds, ``checker`` (or a new one) as validity checker, the ``motion`` validator
        (``"certified"`` or ``"discrete"``, see :func:`~ompl_balance.validity.setup_rigid_body`),
        the start and goal, and the path-length objective when the problem asks for it."""
        ss = og.SimpleSetup(rigid_body_space(self.space, self.low.tolist(), self.high.tolist()))
        setup_rigid_body(ss, checker or self.checker(), motion=motion)
        si = ss.getSpaceInformation()
        start, goal = si.allocState(), si.allocState()
        set_rigid_state(start, self.start)
        set_rigid_state(goal, self.goal)
        ss.setStartAndGoalStates(start, goal, self.goal_threshold)
        if self.objective == "length":
            objective = ob.PathLengthOptimizationObjective(si)
            if self.objective_threshold is not None:
                objective.setCostThreshold(ob.Cost(self.objective_threshold))
            ss.setOptimizationObjective(objective)
        return ss


# -- the robots the package ships: boxes (centre, extents) per part, in the body frame -------

#: Robot name -> space and parts ``(part name, centre (3,), extents (3,))``.
ROBOTS: dict[str, tuple[str, tuple[tuple[str, tuple[float, ...], tuple[float, ...]], ...]]] = {
    "rod": ("SE2", (("bar", (0.0, 0.0, 0.0), (0.8, 0.08, 0.2)),)),
    "ell_planar": (
        "SE2",
        (("long", (0.0, 0.0, 0.0), (0.4, 0.08, 0.2)), ("short", (0.16, 0.12, 0.0), (0.08, 0.16, 0.2))),
    ),
    "tee": ("SE3", (("cross", (0.05, 0.0, 0.0), (0.1, 0.8, 0.1)), ("stem", (-0.225, 0.0, 0.0), (0.45, 0.1, 0.1)))),
    "ell": (
        "SE3",
        (("long", (0.0, 0.0, 0.0), (0.6, 0.08, 0.08)), ("short", (0.26, 0.19, 0.0), (0.08, 0.3, 0.08))),
    ),
    "jack": (
        "SE3",
        (
            ("x", (0.0, 0.0, 0.0), (0.7, 0.08, 0.08)),
            ("y", (0.0, 0.0, 0.0), (0.08, 0.7, 0.08)),
            ("z", (0.0, 0.0, 0.0), (0.08, 0.08, 0.7)),
        ),
    ),
}


def robot_obj(name: str) -> str:
    """The OBJ text of shipped robot ``name``: one object (a closed box of 12 triangles) per part."""
    _space, parts = ROBOTS[name]
    lines = [f"# robot {name!r} of ompl_balance's shipped rigid-body problems (ompl_balance.worlds.rigid)"]
    offset = 1
    for part, centre, extents in parts:
        box = trimesh.creation.box(extents=extents)
        lines.append(f"o {part}")
        lines += [f"v {x + centre[0]:.6f} {y + centre[1]:.6f} {z + centre[2]:.6f}" for x, y, z in box.vertices]
        lines += [f"f {a + offset} {b + offset} {c + offset}" for a, b, c in box.faces]
        offset += len(box.vertices)
    return "\n".join(lines) + "\n"


def write_robot_meshes(folder: str | Path = RIGID_DIR) -> list[Path]:
    """Write every shipped robot's OBJ file (:func:`robot_obj`) into ``folder``; returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name in ROBOTS:
        path = folder / f"{name}.obj"
        path.write_text(robot_obj(name))
        paths.append(path)
    return paths


@functools.cache
def shipped_robot(name: str) -> RigidBody:
    """Shipped robot ``name`` read from its OBJ file, one part per object (each a convex box)."""
    space, _parts = ROBOTS[name]
    meshes = read_mesh_file(RIGID_DIR / f"{name}.obj").meshes
    return RigidBody.from_meshes(space, [soup_mesh(m) for m in meshes], name)


# -- the problems ----------------------------------------------------------------------------


def _quaternion(axis: Sequence[float], angle: float) -> tuple[float, float, float, float]:
    """Unit quaternion ``(x, y, z, w)`` of a rotation by ``angle`` (rad) about ``axis``."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    s = math.sin(0.5 * angle)
    return (float(axis[0] * s), float(axis[1] * s), float(axis[2] * s), math.cos(0.5 * angle))


def _add_boxes(environment: Environment, boxes: Sequence[tuple[str, Sequence[float], Sequence[float]]]) -> None:
    """Add boxes given by ``(name, low corner (3,), high corner (3,))``."""
    for name, low, high in boxes:
        low_, high_ = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
        environment.add_box(name, 0.5 * (high_ - low_), 0.5 * (low_ + high_))


def _shell(low: Sequence[float], high: Sequence[float], thickness: float = 0.1) -> list:
    """Six walls enclosing the box ``low``..``high`` from outside."""
    lo, hi, t = np.asarray(low, dtype=float), np.asarray(high, dtype=float), thickness
    walls = []
    for axis in range(3):
        for side, name in ((0, "min"), (1, "max")):
            a, b = lo - t, hi + t
            if side == 0:
                b = b.copy()
                b[axis] = lo[axis]
            else:
                a = a.copy()
                a[axis] = hi[axis]
            walls.append((f"shell_{'xyz'[axis]}{name}", a.tolist(), b.tolist()))
    return walls


def _se2_slot() -> RigidBodyProblem:
    environment = Environment()
    _add_boxes(
        environment,
        [("wall_left", (-2.0, -0.05, -0.5), (-0.15, 0.05, 0.5)), ("wall_right", (0.15, -0.05, -0.5), (2.0, 0.05, 0.5))],
    )
    return RigidBodyProblem(
        "se2_slot", shipped_robot("rod"), environment, np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0]),
        np.array([-2.0, -2.0]), np.array([2.0, 2.0]), time_limit=5.0,
    )  # fmt: skip


def _se2_bugtrap() -> RigidBodyProblem:
    environment = Environment()
    _add_boxes(
        environment,
        [
            ("trap_bottom", (-0.9, -0.9, -0.5), (0.9, -0.8, 0.5)),
            ("trap_top", (-0.9, 0.8, -0.5), (0.9, 0.9, 0.5)),
            ("trap_back", (-0.9, -0.8, -0.5), (-0.8, 0.8, 0.5)),
            ("trap_front_low", (0.8, -0.8, -0.5), (0.9, -0.2, 0.5)),
            ("trap_front_high", (0.8, 0.2, -0.5), (0.9, 0.8, 0.5)),
            ("lip_low", (0.3, -0.3, -0.5), (0.8, -0.2, 0.5)),
            ("lip_high", (0.3, 0.2, -0.5), (0.8, 0.3, 0.5)),
        ],
    )
    return RigidBodyProblem(
        "se2_bugtrap", shipped_robot("ell_planar"), environment, np.array([-0.3, 0.0, math.pi / 2]),
        np.array([1.6, 0.0, 0.0]), np.array([-2.0, -2.0]), np.array([2.0, 2.0]), time_limit=10.0,
    )  # fmt: skip


def _se3_slot() -> RigidBodyProblem:
    environment = Environment()
    _add_boxes(
        environment,
        [
            ("wall_top", (-0.05, -2.0, 0.2), (0.05, 2.0, 2.0)),
            ("wall_bottom", (-0.05, -2.0, -2.0), (0.05, 2.0, -0.2)),
            ("wall_left", (-0.05, -2.0, -0.2), (0.05, -0.6, 0.2)),
            ("wall_right", (-0.05, 0.6, -0.2), (0.05, 2.0, 0.2)),
        ],
    )
    standing = _quaternion((1.0, 0.0, 0.0), math.pi / 2)
    return RigidBodyProblem(
        "se3_slot", shipped_robot("tee"), environment, np.array([-1.0, 0.0, 0.0, *standing]),
        np.array([1.0, 0.0, 0.0, *standing]), np.full(3, -2.0), np.full(3, 2.0), time_limit=10.0,
    )  # fmt: skip


def _se3_cage() -> RigidBodyProblem:
    environment = Environment()
    inner, t = 0.7, 0.1
    walls = [w for w in _shell((-inner,) * 3, (inner,) * 3, t) if w[0] != "shell_xmax"]
    window_y, window_z = 0.35, 0.15
    x0, x1 = inner, inner + t
    walls += [
        ("window_top", (x0, -inner - t, window_z), (x1, inner + t, inner + t)),
        ("window_bottom", (x0, -inner - t, -inner - t), (x1, inner + t, -window_z)),
        ("window_left", (x0, -inner - t, -window_z), (x1, -window_y, window_z)),
        ("window_right", (x0, window_y, -window_z), (x1, inner + t, window_z)),
    ]
    _add_boxes(environment, walls)
    upright = _quaternion((1.0, 0.0, 0.0), math.pi / 2)
    return RigidBodyProblem(
        "se3_cage", shipped_robot("ell"), environment, np.array([-0.2, 0.0, 0.0, *upright]),
        np.array([1.6, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]), np.full(3, -2.0), np.full(3, 2.0), time_limit=20.0,
    )  # fmt: skip


#: The clutter of ``se3_room``: (name, low corner, high corner), metres.
ROOM_CLUTTER = (
    ("clutter_00", (0.0, 0.46, 2.26), (0.29, 1.01, 3.0)),
    ("clutter_01", (3.61, 3.16, 1.34), (4.27, 3.55, 1.73)),
    ("clutter_02", (0.64, 2.48, 0.66), (1.41, 3.06, 2.24)),
    ("clutter_03", (3.79, 4.03, 0.12), (4.23, 4.64, 0.65)),
    ("clutter_04", (4.22, 1.95, 0.28), (4.74, 2.35, 0.6)),
    ("clutter_05", (0.75, 0.0, 0.0), (1.42, 0.34, 1.46)),
    ("clutter_06", (3.27, 1.43, 0.0), (3.71, 1.96, 1.47)),
    ("clutter_07", (3.3, 0.0, 0.0), (3.61, 0.9, 0.84)),
    ("clutter_08", (1.19, 0.14, 0.2), (1.98, 0.75, 0.83)),
    ("clutter_09", (3.5, 2.36, 2.25), (3.77, 2.57, 2.86)),
    ("clutter_10", (4.72, 4.49, 0.74), (5.0, 4.92, 1.3)),
    ("clutter_11", (0.0, 0.13, 0.59), (0.51, 0.55, 1.83)),
    ("clutter_12", (0.0, 1.38, 0.0), (0.75, 2.21, 1.26)),
    ("clutter_13", (0.07, 2.9, 0.25), (0.72, 3.21, 1.14)),
    ("clutter_14", (3.07, 1.48, 1.44), (3.3, 1.76, 2.42)),
    ("clutter_15", (4.41, 3.2, 0.0), (4.67, 3.8, 1.55)),
    ("clutter_16", (0.98, 3.57, 0.12), (1.69, 4.33, 1.38)),
    ("clutter_17", (1.28, 2.79, 1.36), (1.58, 3.27, 2.26)),
    ("clutter_18", (3.49, 1.13, 2.05), (3.86, 1.77, 2.75)),
    ("clutter_19", (0.01, 0.56, 1.91), (0.28, 0.99, 2.88)),
    ("clutter_20", (3.4, 1.17, 1.2), (4.15, 1.82, 2.67)),
    ("clutter_21", (0.55, 4.02, 1.7), (0.99, 4.74, 2.44)),
)


def _se3_room() -> RigidBodyProblem:
    """A 5 x 5 x 3 m room cut in two by a wall with a low hatch and a window (0.5 x 0.5 m each),
    boxes strewn on both sides; from the floor of one half to the ceiling of the other."""
    environment = Environment()
    x0, x1 = 2.45, 2.55
    partition = [
        ("partition_a", (x0, 0.0, 0.0), (x1, 0.8, 3.0)),
        ("partition_b", (x0, 1.3, 0.0), (x1, 3.6, 3.0)),
        ("partition_c", (x0, 4.1, 0.0), (x1, 5.0, 3.0)),
        ("over_door", (x0, 0.8, 0.5), (x1, 1.3, 3.0)),
        ("under_window", (x0, 3.6, 0.0), (x1, 4.1, 1.8)),
        ("over_window", (x0, 3.6, 2.3), (x1, 4.1, 3.0)),
    ]
    _add_boxes(environment, [*_shell((0.0, 0.0, 0.0), (5.0, 5.0, 3.0)), *partition, *ROOM_CLUTTER])
    return RigidBodyProblem(
        "se3_room", shipped_robot("ell"), environment, np.array([0.5, 4.5, 0.5, 0.0, 0.0, 0.0, 1.0]),
        np.array([4.5, 0.5, 2.5, *_quaternion((0.0, 0.0, 1.0), math.pi / 2)]), np.full(3, 0.2),
        np.array([4.8, 4.8, 2.8]), time_limit=20.0,
    )  # fmt: skip


def _maze_walls() -> list:
    """Walls of ``se3_maze``: two storeys of 4 x 4 cells (1 m), each a serpentine, joined by a
    0.7 m square hole in the floor above the ground storey's last cell."""
    t = 0.05  # half thickness
    walls = [
        # ground storey: rows joined at alternate ends (walls along x at y = 1, 2, 3)
        ("ground_1", (0.0, 1 - t, 0.0), (3.0, 1 + t, 1.0)),
        ("ground_2", (1.0, 2 - t, 0.0), (4.0, 2 + t, 1.0)),
        ("ground_3", (0.0, 3 - t, 0.0), (3.0, 3 + t, 1.0)),
        # upper storey: columns joined at alternate ends (walls along y at x = 1, 2, 3)
        ("upper_1", (1 - t, 1.0, 1.0), (1 + t, 4.0, 2.0)),
        ("upper_2", (2 - t, 0.0, 1.0), (2 + t, 3.0, 2.0)),
        ("upper_3", (3 - t, 1.0, 1.0), (3 + t, 4.0, 2.0)),
        # the floor between the storeys, a hole at x in [0.15, 0.85], y in [3.15, 3.85]
        ("floor_west", (0.0, 0.0, 1 - t), (0.15, 4.0, 1 + t)),
        ("floor_east", (0.85, 0.0, 1 - t), (4.0, 4.0, 1 + t)),
        ("floor_south", (0.15, 0.0, 1 - t), (0.85, 3.15, 1 + t)),
        ("floor_north", (0.15, 3.85, 1 - t), (0.85, 4.0, 1 + t)),
    ]
    return [*_shell((0.0, 0.0, 0.0), (4.0, 4.0, 2.0)), *walls]


def _se3_maze() -> RigidBodyProblem:
    environment = Environment()
    _add_boxes(environment, _maze_walls())
    return RigidBodyProblem(
        "se3_maze", shipped_robot("jack"), environment, np.array([0.5, 0.5, 0.5, 0.0, 0.0, 0.0, 1.0]),
        np.array([3.5, 3.5, 1.5, 0.0, 0.0, 0.0, 1.0]), np.zeros(3), np.array([4.0, 4.0, 2.0]), time_limit=60.0,
    )  # fmt: skip


_BUILDERS: dict[str, Callable[[], RigidBodyProblem]] = {
    "se2_slot": _se2_slot,
    "se2_bugtrap": _se2_bugtrap,
    "se3_slot": _se3_slot,
    "se3_cage": _se3_cage,
    "se3_room": _se3_room,
    "se3_maze": _se3_maze,
}

#: The shipped problems, easy to hard per space (see the module docstring).
RIGID_PROBLEMS = tuple(_BUILDERS)


def rigid_problem(name: str | Path) -> RigidBodyProblem:
    """A shipped problem by name (:data:`RIGID_PROBLEMS`), or an OMPL.app ``.cfg`` file by path
    (:func:`~ompl_balance.worlds.omplapp.load_omplapp`)."""
    if str(name) in _BUILDERS:
        return _BUILDERS[str(name)]()
    if str(name).endswith(".cfg") or Path(name).is_file():
        from .omplapp import load_omplapp

        return load_omplapp(name)
    raise ValueError(
        f"{str(name)!r} is neither a shipped rigid-body problem ({', '.join(RIGID_PROBLEMS)}) nor an OMPL.app .cfg file"
    )
