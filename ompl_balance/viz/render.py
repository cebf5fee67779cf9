"""A :class:`~ompl_balance.viz.scene.Scene` and its :class:`~ompl_balance.viz.plan.Plan` drawn with viser.

:class:`Drawing` puts everything on a ``viser.ViserServer``'s scene, once: the obstacles, the
robot (one scene node per moving frame, its meshes below it), the robot at the start and at the
goal (translucent, each shown while the robot is elsewhere), the traced point's path, the trees
on request, and in red what collides at an invalid start or goal. :meth:`Drawing.show_frame`
then moves the robot to a frame of the animation by updating only the moving frames' poses. The
scene tree's names group the layers (``/obstacles``, ``/robot``, ``/start``, ``/goal``,
``/labels``, ``/path``, ``/trees``), which viser's scene panel shows and hides.

Imports viser: only the viewer's modules import this one, after
:func:`~ompl_balance.viz.extra.require_viser`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import viser
import viser.transforms as vtf

from ..collision.contacts import OBSTACLE, SELF, Contact
from . import style
from .camera import Camera, framing
from .plan import Plan
from .scene import Mesh, PlaneScene, Scene


class Drawing:
    """The scene and plan drawn on ``server`` (see the module docstring).

    Parameters
    ----------
    server:
        The viser server whose scene receives the drawing.
    scene, plan:
        What to draw.
    frames:
        The animation's states (m, state size); the robot starts at the first.
    trees:
        Draw the plan's trees.

    Attributes
    ----------
    camera:
        Where the view starts (:class:`~ompl_balance.viz.camera.Camera`).
    contacts:
        What collides at the start or goal when it is not valid, by ``"start"``/``"goal"``.
    frame:
        The frame shown.
    """

    def __init__(
        self, server: viser.ViserServer, scene: Scene, plan: Plan, frames: np.ndarray, trees: bool = False
    ) -> None:
        self.server, self.scene, self.plan, self.frames = server, scene, plan, frames
        self.handles: dict[str, Any] = {}  # scene tree name -> viser's handle
        self.poses = scene.frame_poses(frames) if len(frames) else np.zeros((0, len(scene.frames), 4, 4))
        self.contacts: dict[str, list[Contact]] = {}
        for label, state in (("start", plan.start), ("goal", plan.goal)):
            if state is not None and scene.problem(state):
                self.contacts[label] = scene.collisions(state)
        ends = [s[None] for s in (plan.start, plan.goal) if s is not None]
        low, high = scene.extent(np.concatenate([frames, *ends]) if ends else frames)
        self.camera: Camera = framing(low, high, isinstance(scene, PlaneScene))
        self.frame = 0
        self.ghosts = True  # the robot at the start and at the goal may be shown
        self._view(low, high)
        self._obstacles()
        self._robot()
        self._ends()
        self._path(0.004 * float(np.max(high - low)), trees)
        self.show_frame(0)

    # -- what is drawn

    def _view(self, low: np.ndarray, high: np.ndarray) -> None:
        """Up, lights, camera and a floor grid under the scene."""
        api, server, camera = self.server.scene, self.server, self.camera
        api.set_up_direction("+z")
        api.configure_default_lights(enabled=True, cast_shadow=False)
        # no environment map: its lighting costs a browser without a GPU (software WebGL) seconds
        # per load; a hemisphere light fills the shade instead
        api.configure_environment_map(hdri=None)
        api.add_light_hemisphere("/lights/sky", sky_color=(255, 255, 255), ground_color=(150, 150, 160), intensity=1.6)
        server.initial_camera.position = camera.position
        server.initial_camera.look_at = camera.look_at
        server.initial_camera.up = (0.0, 0.0, 1.0)
        server.initial_camera.fov = camera.fov
        cell = _nice(float(np.max(high - low)) / 10)
        api.add_grid(
            "/floor",
            width=float(high[0] - low[0]) * 1.4 + cell,
            height=float(high[1] - low[1]) * 1.4 + cell,
            cell_size=cell,
            section_size=5 * cell,
            position=(float(0.5 * (low[0] + high[0])), float(0.5 * (low[1] + high[1])), float(low[2]) - 1e-4),
        )

    def _obstacles(self) -> None:
        plane = isinstance(self.scene, PlaneScene)
        hit = {c.second_index for contacts in self.contacts.values() for c in contacts if c.kind == OBSTACLE}
        for i, mesh in enumerate(self.scene.obstacles):
            if i in hit:
                colour, opacity = style.CONTACT, None
            else:
                colour, opacity = (style.BLOCK, None) if plane else (style.OBSTACLE, style.OBSTACLE_OPACITY)
            self._mesh(f"/obstacles/{_node(mesh.name)}", mesh, colour, opacity, mesh.pose)

    def _robot(self) -> None:
        """A scene node per moving frame, its meshes below: the collision geometry (red where it
        collides at an invalid start the robot stays at), the visual meshes (shown instead of the
        collision geometry where the scene has them)."""
        scene, api = self.scene, self.server.scene
        self.frame_nodes: list[Any] = []
        for name in scene.frames:
            node = f"/robot/{_node(name)}"
            self.frame_nodes.append(api.add_frame(node, show_axes=False))
            self.handles[node] = self.frame_nodes[-1]
        stuck = _geometry_in(self.contacts.get("start", [])) if len(self.frames) <= 1 else set()
        for k, (f, mesh) in enumerate(scene.parts):
            colour = style.CONTACT if k in stuck else style.ROBOT
            name = f"/robot/{_node(scene.frames[f])}/collision/{_node(mesh.name)}"
            self._mesh(name, mesh, colour, None, mesh.pose, visible=not scene.visuals)
        for k, (f, mesh) in enumerate(scene.visuals):
            name = f"/robot/{_node(scene.frames[f])}/visual/{k}"
            self._mesh(name, mesh, mesh.colour or style.VISUAL, None, mesh.pose)

    def _ends(self) -> None:
        """The robot at the start and at the goal, translucent, labelled; red where it collides."""
        scene, api = self.scene, self.server.scene
        for label, state, colour in (("start", self.plan.start, style.START), ("goal", self.plan.goal, style.GOAL)):
            if state is None:
                continue
            poses = scene.frame_poses(state[None])[0]
            hits = _geometry_in(self.contacts.get(label, []))
            for k, (f, mesh) in enumerate(scene.parts):
                tint = style.CONTACT if k in hits else colour
                self._mesh(f"/{label}/{_node(mesh.name)}", mesh, tint, style.GHOST_OPACITY, poses[f] @ mesh.pose)
            tip = scene.tips(state[None])[0]
            problem = scene.problem(state)
            text = f"{label}: {problem}" if problem else label
            self.handles[f"/labels/{label}"] = api.add_label(f"/labels/{label}", text, position=tuple(tip))

    def _path(self, size: float, trees: bool) -> None:
        """The traced point along the animation, and the trees (nodes and edges) when asked for."""
        scene, api = self.scene, self.server.scene
        if len(self.frames) > 1:
            tips = scene.tips(self.frames)
            segments = np.stack([tips[:-1], tips[1:]], axis=1)
            self.handles["/path"] = api.add_line_segments(
                "/path", segments, style.PATH, thickness=3.0, thickness_units="screen"
            )
        for tree in self.plan.trees if trees else []:
            colour = style.TREES.get(tree.name, style.TREES["tree"])
            tips = scene.tips(tree.states) if len(tree.states) else np.zeros((0, 3))
            node = f"/trees/{_node(tree.name)}"
            if len(tree.edges):
                segments = np.stack([tips[tree.edges[:, 0]], tips[tree.edges[:, 1]]], axis=1)
                self.handles[f"{node}/edges"] = api.add_line_segments(
                    f"{node}/edges", segments, colour, thickness=1.5, thickness_units="screen"
                )
            if len(tips):
                self.handles[f"{node}/nodes"] = api.add_point_cloud(
                    f"{node}/nodes", tips.astype(np.float32), colour, point_size=size, point_shape="circle"
                )

    def _mesh(
        self,
        name: str,
        mesh: Mesh,
        colour: Sequence[int],
        opacity: float | None,
        pose: np.ndarray,
        visible: bool = True,
    ) -> Any:
        self.handles[name] = self.server.scene.add_mesh_simple(
            name,
            np.asarray(mesh.mesh.vertices, dtype=np.float32),
            np.asarray(mesh.mesh.faces, dtype=np.uint32),
            color=(int(colour[0]), int(colour[1]), int(colour[2])),
            opacity=opacity,
            position=pose[:3, 3],
            wxyz=_wxyz(pose),
            cast_shadow=False,
            receive_shadow=False,
            visible=visible,
        )
        return self.handles[name]

    # -- changes

    def nodes(self, prefix: str) -> list[Any]:
        """The handles of the scene nodes named ``prefix`` or below it (``"/trees"``, ...)."""
        return [handle for name, handle in self.handles.items() if name == prefix or name.startswith(prefix + "/")]

    def show_frame(self, k: int) -> None:
        """Move the robot to frame ``k`` of the animation (clipped to the frames there are); the
        robot at the start shows once the robot has left it, at the goal until it is there."""
        if len(self.poses):
            k = int(min(max(k, 0), len(self.poses) - 1))
            for node, pose in zip(self.frame_nodes, self.poses[k]):
                node.position = pose[:3, 3]
                node.wxyz = _wxyz(pose)
        self.frame = k if len(self.poses) else 0
        self._show_ends()

    def show_ends(self, shown: bool) -> None:
        """Show (or hide) the robot at the start and the goal, and their labels."""
        self.ghosts = shown
        for handle in self.nodes("/labels"):
            handle.visible = shown
        self._show_ends()

    def _show_ends(self) -> None:
        last = len(self.frames) - 1
        for label, away in (("start", self.frame > 0), ("goal", self.frame < last or last < 1)):
            for handle in self.nodes(f"/{label}"):
                if handle.visible != (self.ghosts and away):
                    handle.visible = self.ghosts and away


def _wxyz(pose: np.ndarray) -> np.ndarray:
    """The rotation of ``pose`` (4, 4) as a unit quaternion, scalar first (viser's order)."""
    return vtf.SO3.from_matrix(pose[:3, :3]).wxyz


def _node(name: str) -> str:
    """``name`` as one level of a scene tree name (no slashes or spaces)."""
    return name.replace("/", "_").replace(" ", "_") or "_"


def _geometry_in(contacts: list[Contact]) -> set[int]:
    """The robot's geometries (indices of the scene's parts) among ``contacts``."""
    return {c.first_index for c in contacts} | {c.second_index for c in contacts if c.kind == SELF}


def _nice(step: float) -> float:
    """The number 1, 2 or 5 times a power of ten nearest above ``step`` (> 0), for grid cells."""
    if not step > 0:
        return 1.0
    power = 10.0 ** math.floor(math.log10(step))
    return next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= step)
