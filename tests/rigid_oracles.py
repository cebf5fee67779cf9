"""Independent oracles for the rigid-body tests.

* :func:`triangles_separation`: a brute-force separating-axis test between triangle sets (numpy
  only, no FCL): the largest gap any candidate axis shows between two triangles (> 0: apart).
  For two triangles the candidate axes are both normals, the nine edge-edge cross products and
  each triangle's in-plane edge normals (which separate coplanar triangles), so the test is
  exact for convex sets; a solid box is tested as its 12 triangles plus containment of a
  triangle corner.
* :class:`DenseCheck`: FCL's collision test at poses along OMPL's interpolation, so close that
  no point of the body moves more than ``step`` between two (rotation sub-steps included).
"""

from __future__ import annotations

import math

import fcl
import numpy as np
from scipy.spatial.transform import Rotation

from ompl_balance.collision.geometry import fcl_transform


def place(triangles: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Body-frame triangles (t, 3, 3) at an SE(2) ``(x, y, yaw)`` or SE(3) ``(x, y, z, qx, qy, qz, qw)`` state."""
    if len(state) == 3:
        rotation = Rotation.from_euler("z", state[2]).as_matrix()
        translation = np.array([state[0], state[1], 0.0])
    else:
        rotation = Rotation.from_quat(state[3:]).as_matrix()
        translation = state[:3]
    return triangles @ rotation.T + translation


def _axes(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Candidate separating axes (k, m, 3) for every pair of triangles a (k, 3, 3) x b (m, 3, 3)."""
    ea = np.roll(a, -1, axis=1) - a  # (k, 3, 3) edges
    eb = np.roll(b, -1, axis=1) - b
    na = np.cross(ea[:, 0], ea[:, 1])  # (k, 3)
    nb = np.cross(eb[:, 0], eb[:, 1])
    k, m = len(a), len(b)
    axes = [np.broadcast_to(na[:, None], (k, m, 3)), np.broadcast_to(nb[None], (k, m, 3))]
    for i in range(3):
        for j in range(3):
            axes.append(np.cross(ea[:, None, i], eb[None, :, j]))
        axes.append(np.broadcast_to(np.cross(na, ea[:, i])[:, None], (k, m, 3)))
        axes.append(np.broadcast_to(np.cross(nb, eb[:, i])[None], (k, m, 3)))
    return np.stack(axes, axis=2)  # (k, m, axes, 3)


def triangles_separation(a: np.ndarray, b: np.ndarray) -> float:
    """min over triangle pairs of the largest normalised gap along a candidate axis: > 0 iff
    every triangle of ``a`` (k, 3, 3) is apart from every triangle of ``b`` (m, 3, 3)."""
    worst = math.inf
    for chunk in np.array_split(np.arange(len(a)), max(1, len(a) // 16)):
        axes = _axes(a[chunk], b)
        lengths = np.linalg.norm(axes, axis=-1)
        usable = lengths > 1e-12
        unit = np.where(usable[..., None], axes / np.where(usable, lengths, 1.0)[..., None], 0.0)
        pa = np.einsum("kxi,kmai->kmax", a[chunk], unit)  # projections of a's corners
        pb = np.einsum("mxi,kmai->kmax", b, unit)
        gap = np.maximum(pb.min(-1) - pa.max(-1), pa.min(-1) - pb.max(-1))
        gap = np.where(usable, gap, -math.inf)
        worst = min(worst, float(gap.max(axis=-1).min()))
    return worst


def box_triangles(half: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """The 12 triangles (12, 3, 3) of a box of half extents ``half`` at ``pose`` (4, 4)."""
    import trimesh

    box = trimesh.creation.box(extents=2.0 * np.asarray(half))
    return np.asarray(box.triangles) @ pose[:3, :3].T + pose[:3, 3]


def inside_box(points: np.ndarray, half: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Which ``points`` (n, 3) lie strictly inside the box (half extents, pose)."""
    local = (points - pose[:3, 3]) @ pose[:3, :3]
    return np.all(np.abs(local) < half, axis=1)


class DenseCheck:
    """FCL at dense poses along OMPL's interpolation of a rigid body's motion (the oracle)."""

    def __init__(self, body, environment, step: float):
        from ompl_balance.collision.rigid.motion import interpolate, motion_split, state_pose

        self._interpolate, self._split, self._pose = interpolate, motion_split, state_pose
        self.body, self.step = body, step
        self.parts = [(fcl.CollisionObject(p.shape.fcl_geometry(), fcl.Transform()), p.pose) for p in body.parts]
        self.obstacles = [
            fcl.CollisionObject(o.shape.fcl_geometry(), fcl_transform(o.pose)) for o in environment.obstacles
        ]

    def collides(self, state: np.ndarray) -> bool:
        pose = np.empty((4, 4))
        self._pose(np.asarray(state, dtype=float), pose)
        for part, offset in self.parts:
            placed = pose @ offset
            part.setTransform(fcl.Transform(placed[:3, :3], placed[:3, 3]))
            for obstacle in self.obstacles:
                if fcl.collide(part, obstacle, fcl.CollisionRequest(), fcl.CollisionResult()):
                    return True
        return False

    def first_collision(self, a: np.ndarray, b: np.ndarray, until: float = 1.0) -> float | None:
        """The fraction of the first colliding pose on ``a -> b`` (up to ``until``), or ``None``."""
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        if self.collides(a):  # (OMPL's interpolation may start in b's orientation: a is checked itself)
            return 0.0
        translation, angle, _jump = self._split(a, b)
        count = max(1, math.ceil((translation + angle * self.body.reach) * until / self.step))
        state = np.empty(len(a))
        for i in range(count + 1):
            t = until * i / count
            self._interpolate(a, b, t, state)
            if self.collides(state):
                return t
        return None
