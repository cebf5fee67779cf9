"""A rigid body moving in SE(2) or SE(3): shapes rigidly joined in one body frame.

States, as float64 arrays, in OMPL's order:

* SE(2): ``(x, y, yaw)``, metres and radians: the body frame at ``(x, y, 0)`` turned by ``yaw``
  about the world z axis (OMPL's ``SE2StateSpace``; OMPL.app's planar robots);
* SE(3): ``(x, y, z, qx, qy, qz, qw)``: position, then the orientation as a unit quaternion,
  scalar last (OMPL's ``SE3StateSpace``: its position, then its ``SO3StateSpace`` component's
  ``x, y, z, w``).

A point ``p`` of the body (body frame) is at ``R p + t`` in the world. The body's *reach* is
how far its points are from the frame origin (SE(3)) or from the frame's z axis (SE(2)): a
rotation by ``phi`` moves no point farther than ``reach * phi``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from ..convex import convex_part
from ..geometry import Shape
from .pieces import soup_mesh, split_triangles

#: The state spaces a rigid body moves in, and the length of their states.
STATE_SIZES = {"SE2": 3, "SE3": 7}
#: Names of the state values, per space.
STATE_NAMES = {"SE2": ("x", "y", "yaw"), "SE3": ("x", "y", "z", "qx", "qy", "qz", "qw")}


@dataclass(frozen=True, eq=False)
class BodyPart:
    """``shape`` at ``pose`` (4, 4) in the body frame."""

    name: str
    shape: Shape
    pose: np.ndarray


class RigidBody:
    """Shapes rigidly joined in one body frame, moving in ``space`` (``"SE2"`` or ``"SE3"``).

    Parameters
    ----------
    space:
        ``"SE2"`` or ``"SE3"`` (see the module docstring for the state layouts).
    parts:
        ``(name, shape, pose)`` triples: a :class:`~ompl_balance.collision.geometry.Shape`
        and its pose (4, 4) in the body frame (identity if ``None``).
    name:
        What error messages call the body.
    """

    def __init__(self, space: str, parts: Iterable[tuple[str, Shape, np.ndarray | None]], name: str = "body") -> None:
        if space not in STATE_SIZES:
            raise ValueError(f"space must be one of {', '.join(map(repr, STATE_SIZES))}, got {space!r}")
        self.space = space
        self.name = name
        self.parts = [BodyPart(n, s, np.eye(4) if p is None else np.asarray(p, dtype=float)) for n, s, p in parts]
        if not self.parts:
            raise ValueError(f"rigid body {name!r} has no parts")
        for part in self.parts:
            if part.pose.shape != (4, 4) or not np.isfinite(part.pose).all():
                raise ValueError(f"rigid body {name!r} part {part.name!r}: pose must be a finite 4 x 4 matrix")
        self.part_reach = np.array([self._reach(p) for p in self.parts])

    @staticmethod
    def from_triangles(space: str, triangles: np.ndarray, pieces: int = 8, name: str = "body") -> RigidBody:
        """A body of one triangle soup (t, 3, 3) in the body frame, cut into at most ``pieces``
        compact parts (:func:`~ompl_balance.collision.rigid.pieces.split_triangles`): FCL's
        answer is the same, the bounding volumes are tighter. Keep ``pieces=1`` for a convex
        mesh: a whole closed convex mesh is certified as the solid it bounds."""
        triangles = np.asarray(triangles, dtype=float).reshape(-1, 3, 3)
        if len(triangles) == 0:
            raise ValueError(f"rigid body {name!r}: the mesh has no triangles")
        groups = split_triangles(triangles, pieces)
        parts = [(f"{name}[{i}]", Shape.from_mesh(soup_mesh(g)), None) for i, g in enumerate(groups)]
        return RigidBody(space, parts, name)

    @staticmethod
    def from_meshes(space: str, meshes: Sequence[trimesh.Trimesh], name: str = "body") -> RigidBody:
        """A body of several meshes, one part each, in their common frame."""
        return RigidBody(space, [(f"{name}[{i}]", Shape.from_mesh(m), None) for i, m in enumerate(meshes)], name)

    def __repr__(self) -> str:
        return f"RigidBody({self.space!r}, {len(self.parts)} parts, name={self.name!r})"

    @property
    def state_size(self) -> int:
        """3 for SE(2), 7 for SE(3)."""
        return STATE_SIZES[self.space]

    @property
    def reach(self) -> float:
        """The largest distance of a point of the body from its frame origin (SE(3)) or z axis (SE(2))."""
        return float(self.part_reach.max())

    def _reach(self, part: BodyPart) -> float:
        """Distance bound of ``part``'s points from the frame origin (SE(3)) or z axis (SE(2)):
        exact over a mesh's hull vertices and a box's corners, padded for spheres and cylinders."""
        shape = part.shape
        vertices, pad, disk, _axis = convex_part(shape.kind, shape.dims, shape.hull_vertices(), part.pose)
        if self.space == "SE2":
            vertices = vertices[:, :2]
        return float(np.linalg.norm(vertices, axis=1).max()) + pad + disk

    def as_states(self, states: ArrayLike) -> np.ndarray:
        """``states`` as a float array (n, 3) or (n, 7); ``ValueError`` for a wrong shape or non-finite values.

        SE(3) orientations must be unit quaternions to 1e-9, as OMPL's ``SO3StateSpace`` requires.
        """
        array = np.asarray(states, dtype=float)
        rows = array.reshape(1, -1) if array.ndim == 1 else array
        size = self.state_size
        if rows.ndim != 2 or rows.shape[1] != size:
            raise ValueError(
                f"{self.space} states of rigid body {self.name!r} are ({', '.join(STATE_NAMES[self.space])}): "
                f"expected shape (n, {size}) or ({size},), got {array.shape}"
            )
        if not np.isfinite(rows).all():
            row, column = np.argwhere(~np.isfinite(rows))[0]
            raise ValueError(f"state {row} has non-finite {STATE_NAMES[self.space][column]} = {rows[row, column]}")
        if size == 7:
            norms = np.linalg.norm(rows[:, 3:], axis=1)
            bad = np.flatnonzero(np.abs(norms - 1.0) > 1e-9)
            if len(bad):
                raise ValueError(f"state {bad[0]} has a quaternion of norm {norms[bad[0]]!r}; it must be 1 (to 1e-9)")
        return np.ascontiguousarray(rows)
