"""Robot model from a URDF (+ optional SRDF) and batched forward kinematics in numpy.

The kinematic tree is reduced to *bodies*: the root link and the child frame of every
moving joint. Links hanging off a body by fixed joints are folded into it as a constant
offset, and a mimic joint moves with the active joint it follows
(``multiplier * q + offset``). Forward kinematics therefore costs one 4 x 4 product per
moving joint and configuration; :func:`chain_poses` does it compiled (numba), so that
one configuration costs about a microsecond instead of the tens of microseconds that
numpy's per-call overhead adds for arrays this small, and ``n`` configurations cost
one call.

Configurations are vectors of the *active* joints (revolute, continuous, prismatic;
not mimic) in :attr:`RobotModel.joint_names` order, radians and metres. Continuous
joints get the bounds ``[-pi, pi]`` (a real-vector space does not wrap around).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path
from typing import Any, NamedTuple
from urllib.parse import unquote, urlparse

import numpy as np
import trimesh
import yourdfpy
from numpy.typing import ArrayLike

from ..core.kernel_cache import njit, njit_borrowing
from .geometry import Shape
from .urdf import check_urdf

MOVING_JOINTS = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class LinkGeometry:
    """One ``<collision>`` element: ``shape`` posed at ``origin`` (4, 4) in its body's frame."""

    link: str
    body: int
    origin: np.ndarray
    shape: Shape
    source: str | None = None  # the mesh file it was loaded from


@dataclass(frozen=True)
class _MovingJoint:
    name: str
    kind: str  # "revolute" (also continuous) or "prismatic"
    parent_body: int
    offset: np.ndarray  # (4, 4) parent body frame -> joint frame at q = 0
    axis: np.ndarray  # (3,) unit, joint frame
    source: int  # index of the active joint driving it
    multiplier: float
    shift: float


#: Radians (or metres) beyond a joint limit that still count as within it: rounding, not motion.
LIMIT_TOLERANCE = 1e-12


class Chain(NamedTuple):
    """The kinematic chain as arrays, for :func:`chain_poses` (``joints`` moving joints).

    Joint ``k`` moves body ``k + 1`` relative to body ``parent_body[k]`` (parents come
    first) by the value ``v = multiplier[k] * q[source[k]] + shift[k]``: rotation
    ``rotation_fixed + sin(v) rotation_sin - cos(v) rotation_cos`` (joints, 3, 3) and
    translation ``translation + v slide`` (joints, 3). ``axis`` (joints, 3) is the unit
    joint axis in the child body's frame.
    """

    source: np.ndarray
    multiplier: np.ndarray
    shift: np.ndarray
    parent_body: np.ndarray
    rotation_fixed: np.ndarray
    rotation_sin: np.ndarray
    rotation_cos: np.ndarray
    translation: np.ndarray
    slide: np.ndarray
    axis: np.ndarray


@njit_borrowing
def chain_poses(q: np.ndarray, chain: Chain, poses: np.ndarray) -> None:  # pragma: no cover (compiled)
    """World poses of the bodies of one configuration ``q`` (dof,) into ``poses`` (bodies, 4, 4)."""
    poses[0] = 0.0
    for axis in range(4):
        poses[0, axis, axis] = 1.0
    for k in range(len(chain.source)):
        value = chain.multiplier[k] * q[chain.source[k]] + chain.shift[k]
        sin, cos = np.sin(value), np.cos(value)
        parent = poses[chain.parent_body[k]]  # an earlier body: never the one written here
        body = poses[k + 1]
        for row in range(3):
            body[row, 0], body[row, 1], body[row, 2], body[row, 3] = 0.0, 0.0, 0.0, parent[row, 3]
        # body = parent @ local, each entry of the joint's local transform computed once
        for m in range(3):
            for col in range(3):
                local = (
                    chain.rotation_fixed[k, m, col]
                    + sin * chain.rotation_sin[k, m, col]
                    - cos * chain.rotation_cos[k, m, col]
                )
                for row in range(3):
                    body[row, col] += parent[row, m] * local
            local = chain.translation[k, m] + value * chain.slide[k, m]
            for row in range(3):
                body[row, 3] += parent[row, m] * local
        body[3, 0], body[3, 1], body[3, 2], body[3, 3] = 0.0, 0.0, 0.0, 1.0


@njit(cache=True)
def _chain_poses_batch(q: np.ndarray, chain: Chain, poses: np.ndarray) -> None:  # pragma: no cover (compiled)
    for i in range(len(q)):
        chain_poses(q[i], chain, poses[i])


class RobotModel:
    """Kinematics, joint limits and collision geometry of a URDF robot.

    Build it with :meth:`from_urdf`. Attributes:

    ``joint_names`` (dof,), ``lower``/``upper`` (dof,) joint bounds; ``link_names``
    (links,) in the order of :meth:`fk`'s output; ``geometries`` the collision shapes;
    ``self_collision_pairs`` the geometry index pairs checked for self-collision.
    """

    def __init__(
        self,
        urdf: yourdfpy.URDF,
        geometries_of: Callable[[Any], Iterable[tuple[np.ndarray, Shape, str | None]]],
        disabled_links: set[frozenset[str]],
        name: str,
    ):
        robot = urdf.robot
        joints_by_child = {j.child: j for j in robot.joints}
        children: dict[str, list] = {}
        for j in robot.joints:
            children.setdefault(j.parent, []).append(j)
        roots = [link.name for link in robot.links if link.name not in joints_by_child]
        if len(roots) != 1:
            raise ValueError(f"URDF {name!r} must form one tree with a single root link, found roots {roots}")

        active = [j for j in robot.joints if j.type in MOVING_JOINTS and j.mimic is None]
        self.name = name
        #: The URDF file and ROS package map the robot was read from (:meth:`from_urdf`), for
        #: what reads more of it than collision geometry (a viewer's visual meshes); else None.
        self.urdf_path: Path | None = None
        self.package_map: dict[str, str] = {}
        self.joint_names: list[str] = [j.name for j in active]
        bounds = np.array([_limits(j) for j in active]).reshape(-1, 2)
        self.lower, self.upper = bounds[:, 0], bounds[:, 1]
        active_index = {n: i for i, n in enumerate(self.joint_names)}

        # walk the tree depth-first from the root: bodies, moving joints, folded offsets
        self.link_names: list[str] = []
        link_body: list[int] = []
        link_offset: list[np.ndarray] = []
        self._joints: list[_MovingJoint] = []
        body_parent = [-1]
        stack = [(roots[0], 0, np.eye(4))]
        while stack:
            link, body, offset = stack.pop()
            self.link_names.append(link)
            link_body.append(body)
            link_offset.append(offset)
            for j in reversed(children.get(link, [])):
                origin = offset @ (np.eye(4) if j.origin is None else j.origin)
                if j.type == "fixed":
                    stack.append((j.child, body, origin))
                    continue
                if j.type not in MOVING_JOINTS:
                    raise ValueError(
                        f"joint {j.name!r} has unsupported type {j.type!r} (supported: fixed, {', '.join(MOVING_JOINTS)})"
                    )
                driver, mult, shift = j.name, 1.0, 0.0
                if j.mimic is not None:
                    driver = j.mimic.joint
                    mult = 1.0 if j.mimic.multiplier is None else float(j.mimic.multiplier)
                    shift = 0.0 if j.mimic.offset is None else float(j.mimic.offset)
                    if driver not in active_index:
                        raise ValueError(f"mimic joint {j.name!r} follows {driver!r}, which is not an active joint")
                axis = np.array([1.0, 0.0, 0.0]) if j.axis is None else np.asarray(j.axis, dtype=float)
                self._joints.append(
                    _MovingJoint(
                        j.name,
                        "prismatic" if j.type == "prismatic" else "revolute",
                        body,
                        origin,
                        axis / np.linalg.norm(axis),
                        active_index[driver],
                        mult,
                        shift,
                    )
                )
                body_parent.append(body)
                stack.append((j.child, len(self._joints), np.eye(4)))
        joints = self._joints
        offsets = np.array([j.offset for j in joints]).reshape(-1, 4, 4)
        axis = np.array([j.axis for j in joints]).reshape(-1, 3)
        # Each joint's transform parent body -> child body is offset @ motion(value). With K the
        # cross-product matrix of the axis, a revolute motion rotates by I + sin(v) K + (1 - cos(v)) K^2
        # (Rodrigues), so the rotation block is  R_off (I + K^2) + sin(v) R_off K - cos(v) R_off K^2;
        # a prismatic one keeps R_off and moves the origin by v R_off axis.
        revolute = np.array([j.kind == "revolute" for j in joints], dtype=float)[:, None, None]
        x, y, z = axis.T
        zero = np.zeros_like(x)
        cross = np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=-1).reshape(-1, 3, 3)
        rotation = offsets[:, :3, :3]
        self.chain = Chain(
            source=np.array([j.source for j in joints], dtype=np.int64),
            multiplier=np.array([j.multiplier for j in joints], dtype=float),
            shift=np.array([j.shift for j in joints], dtype=float),
            parent_body=np.array([j.parent_body for j in joints], dtype=np.int64),
            rotation_fixed=np.ascontiguousarray(rotation + revolute * (rotation @ cross @ cross)),
            rotation_sin=np.ascontiguousarray(revolute * (rotation @ cross)),
            rotation_cos=np.ascontiguousarray(revolute * (rotation @ cross @ cross)),
            translation=np.ascontiguousarray(offsets[:, :3, 3]),
            slide=np.ascontiguousarray((1.0 - revolute[:, :, 0]) * (rotation @ axis[:, :, None])[:, :, 0]),
            axis=np.ascontiguousarray(axis),
        )
        self._link_body = np.array(link_body)
        self._link_offset = np.array(link_offset)
        self.link_index = {n: i for i, n in enumerate(self.link_names)}

        self.geometries: list[LinkGeometry] = []
        for link in robot.links:
            body, offset = link_body[self.link_index[link.name]], link_offset[self.link_index[link.name]]
            for origin, shape, source in geometries_of(link):
                self.geometries.append(LinkGeometry(link.name, body, offset @ origin, shape, source))

        # self-collision: geometry pairs on different links, not disabled by the SRDF and
        # not adjacent (same body, or bodies joined by one moving joint)
        unknown = {n for pair in disabled_links for n in pair} - set(self.link_index)
        if unknown:
            raise ValueError(f"SRDF disable_collisions names links not in the URDF: {sorted(unknown)}")
        self.self_collision_pairs: list[tuple[int, int]] = []
        for a, b in combinations(range(len(self.geometries)), 2):
            ga, gb = self.geometries[a], self.geometries[b]
            adjacent = ga.body == gb.body or body_parent[ga.body] == gb.body or body_parent[gb.body] == ga.body
            if ga.link != gb.link and not adjacent and frozenset((ga.link, gb.link)) not in disabled_links:
                self.self_collision_pairs.append((a, b))

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    @property
    def body_count(self) -> int:
        """Number of rigid bodies: the root plus one per moving joint (mimic ones included)."""
        return len(self._joints) + 1

    @staticmethod
    def from_urdf(
        urdf_path: str | Path, srdf_path: str | Path | None = None, package_map: dict[str, str] | None = None
    ) -> RobotModel:
        """Load a robot from a URDF file and, optionally, its MoveIt SRDF.

        ``package_map`` maps ROS package names to directories for ``package://NAME/...``
        mesh paths. Without an entry, ``NAME/...`` is looked for beside the URDF and in
        its parent directories, and a parent directory called ``NAME`` is taken as the
        package. Only ``<collision>`` elements are read; ``<visual>`` is ignored.
        """
        urdf_path = Path(urdf_path)
        check_urdf(urdf_path)  # what and where, before yourdfpy's terser messages
        try:
            urdf = yourdfpy.URDF.load(
                str(urdf_path),
                build_scene_graph=False,
                load_meshes=False,
                build_collision_scene_graph=False,
                load_collision_meshes=False,
            )
        except Exception as error:  # yourdfpy raises many types for broken files
            raise ValueError(f"cannot parse URDF {urdf_path}: {error}") from error
        if urdf.robot is None or not urdf.robot.links:
            raise ValueError(f"cannot parse URDF {urdf_path}: no <robot> with links")
        resolve = _MeshResolver(urdf_path.parent, package_map or {})
        disabled = _srdf_disabled_pairs(Path(srdf_path)) if srdf_path is not None else set()
        model = RobotModel(urdf, lambda link: _link_shapes(link, resolve), disabled, urdf.robot.name)
        model.urdf_path, model.package_map = urdf_path.resolve(), dict(package_map or {})
        return model

    def as_array(self, q: ArrayLike, finite: bool = True) -> np.ndarray:
        """``q`` as a float array (n, dof); raises ``ValueError`` for a wrong shape, and for
        non-finite values unless ``finite`` is false."""
        q = np.asarray(q, dtype=float)
        q2 = q.reshape(1, -1) if q.ndim == 1 else q
        if q2.ndim != 2 or q2.shape[1] != self.dof:
            raise ValueError(
                f"configurations must have shape (n, {self.dof}) for joints {self.joint_names}, got {q.shape}"
            )
        if finite and not np.isfinite(q2).all():
            row, col = np.argwhere(~np.isfinite(q2))[0]
            raise ValueError(
                f"configuration {row} has non-finite value {q2[row, col]} for joint {self.joint_names[col]!r}"
            )
        return q2

    def within_limits(self, q: np.ndarray) -> np.ndarray:
        """Per configuration of ``q`` (n, dof): every value finite and within its joint's limits
        (up to :data:`LIMIT_TOLERANCE`, what interpolating between states at a limit can round
        beyond it), (n,) bool."""
        return np.all((q >= self.lower - LIMIT_TOLERANCE) & (q <= self.upper + LIMIT_TOLERANCE), axis=1)

    def body_poses(self, q: ArrayLike) -> np.ndarray:
        """World poses of the bodies, (n, bodies, 4, 4), for configurations ``q`` (n, dof)."""
        q = self.as_array(q)
        poses = np.empty((len(q), self.body_count, 4, 4))
        _chain_poses_batch(q, self.chain, poses)
        return poses

    def fk(self, q: ArrayLike) -> np.ndarray:
        """World poses of all links, (n, links, 4, 4), in :attr:`link_names` order.

        ``q`` is (n, dof) or (dof,) in :attr:`joint_names` order; the root link is the world frame.
        """
        return self.body_poses(q)[:, self._link_body] @ self._link_offset


def _limits(joint: yourdfpy.Joint) -> tuple[float, float]:
    if joint.type == "continuous":
        return -np.pi, np.pi
    limit = joint.limit
    if limit is None or limit.lower is None or limit.upper is None:
        raise ValueError(f"joint {joint.name!r} ({joint.type}) has no <limit lower upper>")
    if not limit.lower <= limit.upper:
        raise ValueError(f"joint {joint.name!r} has lower limit {limit.lower} above upper limit {limit.upper}")
    return float(limit.lower), float(limit.upper)


class _MeshResolver:
    """Maps URDF mesh file names (``package://``, ``file://``, relative, absolute) to existing files."""

    def __init__(self, urdf_dir: Path, package_map: dict[str, str]):
        self.urdf_dir = urdf_dir.resolve()
        self.package_map = {k: Path(v) for k, v in package_map.items()}

    def candidates(self, filename: str) -> list[Path]:
        if filename.startswith("package://"):
            package, _, rest = filename[len("package://") :].partition("/")
            found = [self.package_map[package] / rest] if package in self.package_map else []
            for folder in (self.urdf_dir, *self.urdf_dir.parents):
                found.append(folder / package / rest)
                if folder.name == package:
                    found.append(folder / rest)
            return found
        if filename.startswith("file://"):
            return [Path(unquote(urlparse(filename).path))]
        return [self.urdf_dir / filename]

    def __call__(self, filename: str, link: str) -> Path:
        tried = self.candidates(filename)
        for path in tried:
            if path.is_file():
                return path
        raise FileNotFoundError(
            f"link {link!r}: collision mesh {filename!r} not found (tried {', '.join(map(str, tried[:4]))}"
            f"{', ...' if len(tried) > 4 else ''}); pass package_map={{'PACKAGE': '/path/to/package'}}"
        )


def resolve_mesh_file(
    urdf_path: str | Path, filename: str, link: str, package_map: dict[str, str] | None = None
) -> Path:
    """The file a URDF's mesh ``filename`` (``package://``, ``file://``, relative or absolute) names,
    looked for as :meth:`RobotModel.from_urdf` looks for collision meshes; ``FileNotFoundError``
    naming the places tried and ``link``."""
    return _MeshResolver(Path(urdf_path).parent, package_map or {})(filename, link)


def _link_shapes(link: yourdfpy.Link, resolve: _MeshResolver) -> Iterator[tuple[np.ndarray, Shape, str | None]]:
    """``(origin (4, 4), Shape, source file or None)`` for each ``<collision>`` of a yourdfpy link."""
    for collision in link.collisions:
        origin = np.eye(4) if collision.origin is None else np.asarray(collision.origin, dtype=float)
        geometry = collision.geometry
        if geometry is None:
            raise ValueError(f"link {link.name!r}: <collision> without <geometry>")
        if geometry.box is not None:
            yield origin, Shape.box(0.5 * np.asarray(geometry.box.size, dtype=float)), None
        elif geometry.sphere is not None:
            yield origin, Shape.sphere(geometry.sphere.radius), None
        elif geometry.cylinder is not None:
            yield origin, Shape.cylinder(geometry.cylinder.radius, geometry.cylinder.length), None
        elif geometry.mesh is not None:
            path = resolve(geometry.mesh.filename, link.name)
            try:
                mesh = trimesh.load(str(path), force="mesh")
            except Exception as error:
                raise ValueError(f"link {link.name!r}: cannot read collision mesh {path}: {error}") from error
            if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
                raise ValueError(f"link {link.name!r}: collision mesh {path} holds no triangles")
            if geometry.mesh.scale is not None:
                mesh.apply_scale(geometry.mesh.scale)
            yield origin, Shape.from_mesh(mesh), str(path)
        else:
            raise ValueError(
                f"link {link.name!r}: unsupported collision geometry (supported: box, sphere, cylinder, mesh)"
            )


def _srdf_disabled_pairs(srdf_path: Path) -> set[frozenset[str]]:
    """Link pairs of the SRDF's ``<disable_collisions link1 link2>`` elements."""
    if not srdf_path.is_file():
        raise FileNotFoundError(f"SRDF file not found: {srdf_path}")
    try:
        root = ET.parse(srdf_path).getroot()
    except ET.ParseError as error:
        raise ValueError(f"cannot parse SRDF {srdf_path}: {error}") from error
    pairs = set()
    for element in root.iter("disable_collisions"):
        a, b = element.get("link1"), element.get("link2")
        if not a or not b:
            raise ValueError(f"SRDF {srdf_path}: <disable_collisions> needs link1 and link2, got {element.attrib}")
        pairs.add(frozenset((a, b)))
    return pairs
