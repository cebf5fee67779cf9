"""What a plan's viewer draws, independent of the viewer: meshes, moving frames, states.

A :class:`Scene` describes one problem in metres, z up: the obstacles (meshes at world poses),
the robot as meshes fixed to moving *frames*, and what a state (an array, in the layout of the
problem's checker) does to those frames. Three kinds:

* :class:`RobotScene`: a URDF robot (:class:`~ompl_balance.collision.checker.CollisionChecker`),
  one frame per link that carries geometry; the states are joint values (rad, m); the traced
  point (path, tree nodes) is an end-effector link's origin;
* :class:`RigidScene`: a rigid body (:class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`)
  in SE(2) ``(x, y, yaw)`` or SE(3) ``(x, y, z, qx, qy, qz, qw)``; one frame, the body's;
* :class:`PlaneScene`: a point in a 2-D world, ``(x, y)`` or SE(2) ``(x, y, yaw)``, its obstacles
  drawn as low blocks on the floor.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike
from ompl import base as ob

from ..collision.checker import CollisionChecker
from ..collision.contacts import Contact, describe_contacts, geometry_names
from ..collision.geometry import Shape
from ..collision.kinematics import RobotModel, resolve_mesh_file
from ..collision.rigid.checker import RigidBodyChecker
from ..collision.rigid.motion import interpolate as rigid_interpolate
from ..collision.rigid.motion import motion_split, state_pose
from ..validity import rigid_state_values

Colour = tuple[int, int, int]


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh to draw: ``mesh`` (vertices in metres) placed at ``pose`` (4, 4) in its
    frame (a moving frame's, or the world's). ``colour``: its own RGB (0-255), or ``None`` for
    the colour of the layer it is drawn in (robot, obstacles, ...)."""

    name: str
    mesh: trimesh.Trimesh
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    colour: Colour | None = None

    @staticmethod
    def of_shape(name: str, shape: Shape, pose: np.ndarray | None = None) -> Mesh:
        """A collision shape's mesh (primitives tessellated)."""
        return Mesh(name, shape.trimesh(), np.eye(4) if pose is None else np.asarray(pose, dtype=float))

    def points(self, frame: np.ndarray | None = None) -> np.ndarray:
        """The mesh's vertices (v, 3) in the world, its frame at ``frame`` (4, 4; default: the world)."""
        pose = self.pose if frame is None else frame @ self.pose
        return np.asarray(self.mesh.vertices) @ pose[:3, :3].T + pose[:3, 3]


class Scene:
    """A problem as a viewer sees it (see the module docstring); the kinds fill in the methods.

    Attributes
    ----------
    title:
        What the scene is called (the problem's name).
    state_names:
        The names of a state's values (joints, ``x``, ``yaw``, ...).
    obstacles:
        Meshes in the world frame.
    frames:
        Names of the moving frames.
    parts:
        ``(frame index, Mesh)``: the robot's collision geometry.
    visuals:
        ``(frame index, Mesh)``: the robot's visual meshes, where the problem has them (else empty).
    tip:
        What :meth:`tips` traces ("end effector panda_hand", "body origin", ...).
    notes:
        What the viewer should tell the user about the scene (visual meshes missing, ...).
    """

    title: str
    state_names: tuple[str, ...]
    obstacles: list[Mesh]
    frames: list[str]
    parts: list[tuple[int, Mesh]]
    visuals: list[tuple[int, Mesh]]
    tip: str
    notes: list[str]

    @property
    def state_size(self) -> int:
        return len(self.state_names)

    def as_states(self, states: ArrayLike) -> np.ndarray:
        """``states`` as a float array (n, state size); ``ValueError`` naming the layout otherwise."""
        array = np.asarray(states, dtype=float)
        rows = array.reshape(1, -1) if array.ndim == 1 else array
        if rows.ndim != 2 or rows.shape[1] != self.state_size or not np.isfinite(rows).all():
            raise ValueError(
                f"a state of {self.title} is {self.state_size} finite numbers ({', '.join(self.state_names)}): "
                f"expected shape (n, {self.state_size}), got {array.shape}"
                + ("" if np.isfinite(array).all() else " with non-finite values")
            )
        return rows

    def values(self, state: ob.State) -> np.ndarray:
        """An OMPL state of the problem's space as this scene's array (state size,)."""
        return np.array([state[i] for i in range(self.state_size)], dtype=float)

    def frame_poses(self, states: np.ndarray) -> np.ndarray:
        """The moving frames' world poses (n, frames, 4, 4) at ``states`` (n, state size)."""
        raise NotImplementedError

    def tips(self, states: np.ndarray) -> np.ndarray:
        """The traced point (n, 3) at ``states`` (n, state size), metres."""
        raise NotImplementedError

    def interpolate(self, a: np.ndarray, b: np.ndarray, fractions: np.ndarray) -> np.ndarray:
        """States (m, state size) at ``fractions`` (m,) of the motion ``a -> b``, as OMPL interpolates."""
        return a + np.outer(fractions, b - a)

    def motion_length(self, a: np.ndarray, b: np.ndarray) -> float:
        """How long the motion ``a -> b`` looks (what spaces an animation's frames evenly)."""
        return float(np.linalg.norm(b - a))

    def collisions(self, state: np.ndarray, nearest: int = 0) -> list[Contact]:
        """The checker's :meth:`collisions` at ``state`` (empty for a point in a plane)."""
        return []

    def problem(self, state: np.ndarray) -> str:
        """Why ``state`` is not valid, in words ("" when it is)."""
        raise NotImplementedError

    def extent(self, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The box (low (3,), high (3,)) that holds the obstacles and the robot at ``states``."""
        points = [m.points() for m in self.obstacles]
        if len(states):
            poses = self.frame_poses(states[np.linspace(0, len(states) - 1, min(len(states), 32)).astype(int)])
            for frame, part in self.parts:
                points += [part.points(pose) for pose in poses[:, frame]]
        stacked = np.concatenate(points) if points else np.zeros((1, 3))
        return stacked.min(axis=0), stacked.max(axis=0)


# -- a URDF robot ---------------------------------------------------------------------------


class RobotScene(Scene):
    """A URDF robot among its checker's obstacles (see the module docstring).

    Parameters
    ----------
    checker:
        The robot's collision checker: its robot's collision geometry, its obstacles.
    end_effector:
        The link whose origin the path and the trees trace; default: the robot's last link
        (of ``robot.link_names``, depth first: a leaf at the end of the last chain).
    visuals:
        Read the URDF's ``<visual>`` meshes (when every one of them is found).
    title:
        The scene's name (default: the robot's).
    """

    def __init__(
        self, checker: CollisionChecker, end_effector: str | None = None, visuals: bool = True, title: str = ""
    ) -> None:
        robot = self.robot = checker.robot
        self.checker = checker
        self.title = title or robot.name
        self.state_names = tuple(robot.joint_names)
        self.notes = []
        if end_effector is None:
            end_effector = robot.link_names[-1]
        if end_effector not in robot.link_index:
            raise ValueError(
                f"end_effector {end_effector!r} is not a link of {robot.name!r}: {', '.join(robot.link_names)}"
            )
        self._tip = robot.link_index[end_effector]
        self.tip = f"end effector {end_effector}"
        self.obstacles = [Mesh.of_shape(o.name, o.shape, o.pose) for o in checker.environment.obstacles]
        # a link's geometry in the link's frame: the body pose times the geometry's origin, seen from the link
        q = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
        links, bodies = robot.fk(q)[0], robot.body_poses(q)[0]
        visual, note = _urdf_visuals(robot) if visuals else ([], "")
        self.notes += [note] if note else []
        used = sorted({robot.link_index[g.link] for g in robot.geometries} | {robot.link_index[v[0]] for v in visual})
        slot = {link: k for k, link in enumerate(used)}
        self._links = np.array(used, dtype=int)
        self.frames = [robot.link_names[i] for i in used]
        names = geometry_names([g.link for g in robot.geometries])
        self.parts = []
        for name, g in zip(names, robot.geometries):
            i = robot.link_index[g.link]
            local = np.linalg.inv(links[i]) @ bodies[g.body] @ g.origin
            self.parts.append((slot[i], Mesh(name, g.shape.trimesh(), local)))
        self.visuals = [(slot[robot.link_index[link]], mesh) for link, mesh in visual]

    def frame_poses(self, states: np.ndarray) -> np.ndarray:
        return self.robot.fk(states)[:, self._links]

    def tips(self, states: np.ndarray) -> np.ndarray:
        return self.robot.fk(states)[:, self._tip, :3, 3]

    def collisions(self, state: np.ndarray, nearest: int = 0) -> list[Contact]:
        return self.checker.collisions(state, nearest)

    def problem(self, state: np.ndarray) -> str:
        robot = self.robot
        outside = [
            f"{name} = {value:.4g} outside [{low:.4g}, {high:.4g}]"
            for name, value, low, high in zip(robot.joint_names, state, robot.lower, robot.upper)
            if not low - 1e-12 <= value <= high + 1e-12
        ]
        if outside:
            return "outside the joint limits: " + ", ".join(outside)
        contacts = self.checker.collisions(state)
        return f"in collision: {describe_contacts(contacts)}" if contacts else ""


def _urdf_visuals(robot: RobotModel) -> tuple[list[tuple[str, Mesh]], str]:
    """``(link, Mesh in the link's frame)`` of every ``<visual>`` of the robot's URDF (a mesh file
    of several parts: a Mesh per part, in its own colour), and a note when there are visuals but
    one of them cannot be read (then none is shown). None without a URDF file or visuals."""
    import yourdfpy

    if robot.urdf_path is None:
        return [], ""
    try:
        urdf = yourdfpy.URDF.load(
            str(robot.urdf_path),
            build_scene_graph=False,
            load_meshes=False,
            build_collision_scene_graph=False,
            load_collision_meshes=False,
        )
    except Exception:  # (the robot loaded from it: a problem of its visuals only, drawn as collision geometry)
        return [], "the URDF's visual elements could not be read: the collision geometry is shown"
    materials = {m.name: m for m in urdf.robot.materials if m.name}
    found: list[tuple[str, Mesh]] = []
    for link in urdf.robot.links:
        if link.name not in robot.link_index:
            continue
        for k, visual in enumerate(link.visuals):
            origin = np.eye(4) if visual.origin is None else np.asarray(visual.origin, dtype=float)
            colour = _material_colour(visual.material, materials)
            try:
                meshes = _visual_meshes(robot, link.name, visual.geometry)
            except (OSError, ValueError) as error:  # a mesh not found or unreadable: no visuals at all
                return [], f"the collision geometry is shown, not the visual meshes: {error}"
            for j, (mesh, own) in enumerate(meshes):
                name = f"{link.name}/visual{k}" + (f"[{j}]" if len(meshes) > 1 else "")
                found.append((link.name, Mesh(name, mesh, origin, colour or own)))
    return found, ""


def _visual_meshes(robot: RobotModel, link: str, geometry: Any) -> list[tuple[trimesh.Trimesh, Colour | None]]:
    """The meshes of a ``<visual>``'s geometry, each with the colour its file gives it (if any)."""
    if geometry is None:
        return []
    if geometry.box is not None:
        return [(trimesh.creation.box(extents=np.asarray(geometry.box.size, dtype=float)), None)]
    if geometry.sphere is not None:
        return [(trimesh.creation.icosphere(subdivisions=3, radius=float(geometry.sphere.radius)), None)]
    if geometry.cylinder is not None:
        cylinder = geometry.cylinder
        return [(trimesh.creation.cylinder(radius=float(cylinder.radius), height=float(cylinder.length)), None)]
    if geometry.mesh is None or robot.urdf_path is None:
        return []
    try:
        path = resolve_mesh_file(robot.urdf_path, geometry.mesh.filename, link, robot.package_map)
    except FileNotFoundError:
        raise FileNotFoundError(f"link {link!r}: visual mesh {geometry.mesh.filename!r} not found") from None
    loaded = trimesh.load(str(path))
    parts = loaded.dump(concatenate=False) if isinstance(loaded, trimesh.Scene) else [loaded]
    meshes = [m for m in parts if isinstance(m, trimesh.Trimesh) and len(m.faces)]
    if not meshes:
        raise ValueError(f"visual mesh {path} holds no triangles")
    for mesh in meshes:
        if geometry.mesh.scale is not None:
            mesh.apply_scale(geometry.mesh.scale)
    return [(mesh, _own_colour(mesh)) for mesh in meshes]


def _material_colour(material: Any, materials: dict[str, Any]) -> Colour | None:
    """The RGB (0-255) of a URDF material (looked up by name when only named), or ``None``."""
    if material is None:
        return None
    if material.color is None and material.name in materials:
        material = materials[material.name]
    if material.color is None or material.color.rgba is None:
        return None
    red, green, blue = (round(255 * float(c)) for c in np.clip(np.asarray(material.color.rgba, dtype=float)[:3], 0, 1))
    return red, green, blue


def _own_colour(mesh: trimesh.Trimesh) -> Colour | None:
    """The colour a mesh file gives a mesh (its material's main colour, or its faces' mean
    colour), or ``None``."""
    visual = mesh.visual
    material = getattr(visual, "material", None)
    colour = getattr(material, "main_color", None) if material is not None else None
    if colour is None and getattr(visual, "kind", None) in ("face", "vertex"):
        colour = np.asarray(getattr(visual, "face_colors", ())).mean(axis=0)
    if colour is None:
        return None
    red, green, blue = (round(float(c)) for c in np.asarray(colour)[:3])
    return red, green, blue


# -- a rigid body ---------------------------------------------------------------------------


class RigidScene(Scene):
    """A rigid body in SE(2) or SE(3) among its checker's obstacles (see the module docstring)."""

    def __init__(self, checker: RigidBodyChecker, title: str = "") -> None:
        body = checker.body
        self.checker = checker
        self.title = title or body.name
        self.state_names = ("x", "y", "yaw") if body.space == "SE2" else ("x", "y", "z", "qx", "qy", "qz", "qw")
        self.notes = []
        self.tip = "body origin"
        self.obstacles = [Mesh.of_shape(o.name, o.shape, o.pose) for o in checker.environment.obstacles]
        self.frames = [body.name]
        self.parts = [(0, Mesh.of_shape(p.name, p.shape, p.pose)) for p in body.parts]
        self.visuals = []

    def as_states(self, states: ArrayLike) -> np.ndarray:
        return self.checker.body.as_states(states)

    def values(self, state: ob.State) -> np.ndarray:
        return rigid_state_values(state, self.state_size)

    def frame_poses(self, states: np.ndarray) -> np.ndarray:
        poses = np.empty((len(states), 1, 4, 4))
        for i, state in enumerate(np.ascontiguousarray(states, dtype=float)):
            state_pose(state, poses[i, 0])
        return poses

    def tips(self, states: np.ndarray) -> np.ndarray:
        return self.frame_poses(states)[:, 0, :3, 3]

    def interpolate(self, a: np.ndarray, b: np.ndarray, fractions: np.ndarray) -> np.ndarray:
        out = np.empty((len(fractions), len(a)))
        a, b = np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float)
        for i, t in enumerate(fractions):
            rigid_interpolate(a, b, float(t), out[i])
        return out

    def motion_length(self, a: np.ndarray, b: np.ndarray) -> float:
        translation, angle, _jump = motion_split(
            np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float)
        )
        return float(translation + angle * self.checker.body.reach)

    def collisions(self, state: np.ndarray, nearest: int = 0) -> list[Contact]:
        return self.checker.collisions(state, nearest)

    def problem(self, state: np.ndarray) -> str:
        if not self.checker.inside_bounds(state):
            low, high = self.checker.bounds
            return f"outside the position bounds {low.tolist()} .. {high.tolist()}"
        contacts = self.checker.collisions(state)
        return f"in collision: {describe_contacts(contacts)}" if contacts else ""


# -- a point in a plane ---------------------------------------------------------------------

#: Height (m per metre of the world's larger side) of a 2-D world's obstacle blocks.
BLOCK_HEIGHT = 0.04


class PlaneScene(Scene):
    """A point robot in a 2-D world (see the module docstring).

    Parameters
    ----------
    title:
        The world's name.
    low, high:
        The world's bounds (2,) in metres.
    blocks:
        Obstacles as axis-aligned rectangles ``(x_min, y_min, x_max, y_max)`` (m).
    discs:
        Circular obstacles ``(x, y, r)`` (m).
    is_free:
        The world's validity test of a position ``(x, y)``.
    se2:
        States are ``(x, y, yaw)`` (the point has a heading) instead of ``(x, y)``.
    """

    def __init__(
        self,
        title: str,
        low: ArrayLike,
        high: ArrayLike,
        blocks: Sequence[Sequence[float]] = (),
        discs: Sequence[Sequence[float]] = (),
        is_free: Callable[[float, float], bool] | None = None,
        se2: bool = False,
    ) -> None:
        self.title = title
        self.low, self.high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
        self.se2 = se2
        self.state_names = ("x", "y", "yaw") if se2 else ("x", "y")
        self.notes = []
        self.tip = "position"
        self._is_free = is_free
        side = float(np.max(self.high - self.low))
        self.height = BLOCK_HEIGHT * side
        self.obstacles = []
        for k, (x0, y0, x1, y1) in enumerate(blocks):
            box = trimesh.creation.box(extents=(x1 - x0, y1 - y0, self.height))
            box.apply_translation((0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * self.height))
            self.obstacles.append(Mesh(f"block{k}", box))
        for k, (x, y, r) in enumerate(discs):
            disc = trimesh.creation.cylinder(radius=r, height=self.height, sections=48)
            disc.apply_translation((x, y, 0.5 * self.height))
            self.obstacles.append(Mesh(f"disc{k}", disc))
        radius = 0.02 * side
        marker = trimesh.creation.icosphere(subdivisions=2, radius=radius)
        self.parts = [(0, Mesh("point", marker, _translation((0.0, 0.0, self.height + radius))))]
        if se2:  # a nose showing the heading
            nose = trimesh.creation.cone(radius=0.6 * radius, height=2.5 * radius)
            pose = _translation((radius, 0.0, self.height + radius)) @ _rotation_y(math.pi / 2)
            self.parts.append((0, Mesh("heading", nose, pose)))
        self.frames = ["robot"]
        self.visuals = []

    def values(self, state: ob.State) -> np.ndarray:
        return rigid_state_values(state, 3) if self.se2 else np.array([state[0], state[1]], dtype=float)

    def frame_poses(self, states: np.ndarray) -> np.ndarray:
        poses = np.tile(np.eye(4), (len(states), 1, 1, 1))
        poses[:, 0, 0, 3], poses[:, 0, 1, 3] = states[:, 0], states[:, 1]
        if self.se2:
            c, s = np.cos(states[:, 2]), np.sin(states[:, 2])
            poses[:, 0, 0, 0], poses[:, 0, 0, 1], poses[:, 0, 1, 0], poses[:, 0, 1, 1] = c, -s, s, c
        return poses

    def tips(self, states: np.ndarray) -> np.ndarray:
        return np.column_stack([states[:, 0], states[:, 1], np.full(len(states), self.height * 1.5)])

    def interpolate(self, a: np.ndarray, b: np.ndarray, fractions: np.ndarray) -> np.ndarray:
        out = a + np.outer(fractions, b - a)
        if self.se2:  # the heading turns the shorter way, as OMPL's SO(2)
            turn = math.remainder(float(b[2] - a[2]), 2 * math.pi)
            out[:, 2] = np.remainder(a[2] + fractions * turn + math.pi, 2 * math.pi) - math.pi
        return out

    def motion_length(self, a: np.ndarray, b: np.ndarray) -> float:
        return float(np.linalg.norm(b[:2] - a[:2]))

    def problem(self, state: np.ndarray) -> str:
        x, y = float(state[0]), float(state[1])
        if not (self.low[0] <= x <= self.high[0] and self.low[1] <= y <= self.high[1]):
            return f"outside the bounds {self.low.tolist()} .. {self.high.tolist()}"
        if self._is_free is not None and not self._is_free(x, y):
            return f"the point ({x:.4g}, {y:.4g}) lies in an obstacle"
        return ""

    def extent(self, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.array([*self.low, 0.0]), np.array([*self.high, 2 * self.height])


def occupied_blocks(occupied: np.ndarray, low: ArrayLike, cell: ArrayLike) -> list[tuple[float, float, float, float]]:
    """The occupied cells of a grid as rectangles ``(x_min, y_min, x_max, y_max)``: each row's runs
    of occupied cells, runs of equal columns in consecutive rows merged. ``occupied`` (rows, cols),
    row 0 at ``y = low[1]``, column 0 at ``x = low[0]``; ``cell`` the cell's (width, height)."""
    occupied = np.asarray(occupied, dtype=bool)
    (x0, y0), (w, h) = np.asarray(low, dtype=float), np.asarray(cell, dtype=float)
    open_runs: dict[tuple[int, int], int] = {}  # (first col, end col) -> first row
    blocks = []

    def close(run: tuple[int, int], first_row: int, end_row: int) -> None:
        blocks.append((x0 + run[0] * w, y0 + first_row * h, x0 + run[1] * w, y0 + end_row * h))

    for row in range(occupied.shape[0] + 1):
        runs = set()
        if row < occupied.shape[0]:
            padded = np.concatenate([[False], occupied[row], [False]])
            edges = np.flatnonzero(padded[1:] != padded[:-1])
            runs = {(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])}
        for run in list(open_runs):
            if run not in runs:
                close(run, open_runs.pop(run), row)
        for run in runs:
            open_runs.setdefault(run, row)
    return blocks


def _translation(offset: Sequence[float]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = offset
    return pose


def _rotation_y(angle: float) -> np.ndarray:
    pose = np.eye(4)
    c, s = math.cos(angle), math.sin(angle)
    pose[0, 0], pose[0, 2], pose[2, 0], pose[2, 2] = c, s, -s, c
    return pose
