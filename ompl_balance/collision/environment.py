"""The static obstacles around a robot: named shapes at poses in the world frame.

An :class:`Environment` is what a collision checker checks a robot against. It holds
geometry only (no FCL objects, no bounding volumes): the checkers build those from it.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from .geometry import Shape, pose_matrix

#: The identity rotation as a quaternion, scalar last.
XYZW = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A static obstacle: ``shape`` at world ``pose`` (4, 4)."""

    name: str
    shape: Shape
    pose: np.ndarray


class Environment:
    """The static obstacles around a robot, in the robot's base (world) frame, metres.

    Poses are given as ``position`` (3,) of the shape's centre and a unit quaternion
    ``orientation_xyzw`` (scalar last), rotating shape axes into the world.
    """

    def __init__(self) -> None:
        self.obstacles: list[Obstacle] = []

    def add(
        self, name: str, shape: Shape, position: ArrayLike = (0.0, 0.0, 0.0), orientation_xyzw: Iterable[float] = XYZW
    ) -> None:
        if any(o.name == name for o in self.obstacles):
            raise ValueError(f"environment already has an obstacle named {name!r}")
        try:
            pose = pose_matrix(position, orientation_xyzw)
        except ValueError as error:
            raise ValueError(f"obstacle {name!r}: {error}") from error
        self.obstacles.append(Obstacle(name, shape, pose))

    def add_box(
        self,
        name: str,
        half_extents: Iterable[float],
        position: ArrayLike = (0.0, 0.0, 0.0),
        orientation_xyzw: Iterable[float] = XYZW,
    ) -> None:
        """A box with ``half_extents`` (hx, hy, hz), half the edge lengths."""
        self.add(name, Shape.box(half_extents), position, orientation_xyzw)

    def add_sphere(self, name: str, radius: float, position: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        self.add(name, Shape.sphere(radius), position)

    def add_cylinder(
        self,
        name: str,
        radius: float,
        length: float,
        position: ArrayLike = (0.0, 0.0, 0.0),
        orientation_xyzw: Iterable[float] = XYZW,
    ) -> None:
        """A cylinder along its local z, ``length`` the full height, centred on ``position``."""
        self.add(name, Shape.cylinder(radius, length), position, orientation_xyzw)

    def add_mesh(
        self,
        name: str,
        mesh: trimesh.Trimesh | str | Path,
        position: ArrayLike = (0.0, 0.0, 0.0),
        orientation_xyzw: Iterable[float] = XYZW,
    ) -> None:
        """A triangle mesh: a ``trimesh.Trimesh`` or a file trimesh can read."""
        if isinstance(mesh, trimesh.Trimesh):
            triangles = mesh
        else:
            try:
                loaded = trimesh.load(str(mesh), force="mesh")
            except Exception as error:
                raise ValueError(f"obstacle {name!r}: cannot read mesh {mesh}: {error}") from error
            if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
                raise ValueError(f"obstacle {name!r}: mesh file {mesh} holds no triangles")
            triangles = loaded
        self.add(name, Shape.from_mesh(triangles), position, orientation_xyzw)
