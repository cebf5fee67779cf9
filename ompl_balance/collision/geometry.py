"""Collision shapes: one description, three views of it.

A :class:`Shape` is a box, sphere, cylinder or triangle mesh in its own frame (metres).
The collision layer needs it three ways:

* as an FCL geometry for the exact test (:meth:`Shape.fcl_geometry`; meshes become
  ``fcl.BVHModel``, primitives FCL's own shapes),
* as a trimesh mesh (:meth:`Shape.trimesh`), for bounds and for independent checks,
* as cheap bounding volumes for the numpy pre-filter: spheres covering the shape
  (:meth:`Shape.bounding_spheres`, for robot links) or one oriented box around it
  (:meth:`Shape.bounding_box`, for obstacles).

Both bounding volumes are conservative for FCL's answer: if they do not touch, FCL
cannot report a contact. For meshes FCL tests triangles, so covering every triangle
suffices; for primitives (solids in FCL) the spheres cover the whole solid.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Protocol

import fcl
import numpy as np
import scipy.spatial
import trimesh
from numpy.typing import ArrayLike

from .cache import cached_arrays

Trimesh = trimesh.Trimesh

SHAPE_KINDS = ("box", "sphere", "cylinder", "mesh")

_SPHERES_OF: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # Shape -> {count: (centres, radii)}


@dataclass(frozen=True, eq=False)
class Shape:
    """A collision shape in its own frame.

    ``kind`` is one of :data:`SHAPE_KINDS`. ``dims`` holds the sizes in metres:
    box ``(hx, hy, hz)`` half extents; sphere ``(r,)``; cylinder ``(r, length)`` with the
    axis along local z and ``length`` the full height, centred on the origin; mesh ``()``
    with the triangles in ``mesh``.
    """

    kind: str
    dims: tuple[float, ...] = ()
    mesh: trimesh.Trimesh | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        expected = {"box": 3, "sphere": 1, "cylinder": 2, "mesh": 0}
        if self.kind not in expected:
            raise ValueError(f"unknown shape kind {self.kind!r}; expected one of {SHAPE_KINDS}")
        if len(self.dims) != expected[self.kind]:
            raise ValueError(f"{self.kind} needs {expected[self.kind]} dimensions, got {self.dims}")
        if not all(np.isfinite(d) and d > 0 for d in self.dims):
            raise ValueError(f"{self.kind} dimensions must be positive and finite, got {self.dims}")
        if (self.kind == "mesh") != (self.mesh is not None):
            raise ValueError("a mesh shape needs a mesh, and only a mesh shape takes one")
        if self.mesh is not None and len(self.mesh.faces) == 0:
            raise ValueError("mesh shape has no triangles")

    @staticmethod
    def box(half_extents: Iterable[float]) -> Shape:
        return Shape("box", tuple(float(h) for h in half_extents))

    @staticmethod
    def sphere(radius: float) -> Shape:
        return Shape("sphere", (float(radius),))

    @staticmethod
    def cylinder(radius: float, length: float) -> Shape:
        return Shape("cylinder", (float(radius), float(length)))

    @staticmethod
    def from_mesh(mesh: trimesh.Trimesh) -> Shape:
        return Shape("mesh", (), mesh)

    def fcl_geometry(self) -> fcl.CollisionGeometry:
        """A new FCL geometry for this shape (BVH model for meshes)."""
        if self.kind == "box":
            return fcl.Box(*(2.0 * np.asarray(self.dims)))
        if self.kind == "sphere":
            return fcl.Sphere(self.dims[0])
        if self.kind == "cylinder":
            return fcl.Cylinder(*self.dims)
        mesh = self._triangles()
        model = fcl.BVHModel()
        model.beginModel(len(mesh.vertices), len(mesh.faces))
        model.addSubModel(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int32))
        model.endModel()
        return model

    def trimesh(self) -> Trimesh:
        """This shape as a triangle mesh (primitives tessellated; cylinders with 64 sides)."""
        if self.kind == "box":
            return trimesh.creation.box(extents=2.0 * np.asarray(self.dims))
        if self.kind == "sphere":
            return trimesh.creation.icosphere(subdivisions=3, radius=self.dims[0])
        if self.kind == "cylinder":
            return trimesh.creation.cylinder(radius=self.dims[0], height=self.dims[1], sections=64)
        return self._triangles()

    def _triangles(self) -> Trimesh:
        """The mesh of a mesh shape."""
        if self.mesh is None:
            raise ValueError(f"a {self.kind} shape has no triangle mesh; use trimesh() for a tessellation")
        return self.mesh

    def hull_vertices(self) -> np.ndarray | None:
        """Vertices (m, 3) of a mesh's convex hull (``None`` for primitives); computed once.

        Only the hull matters for support functions, so this is what the distance bounds
        use. Flat or degenerate meshes keep all their (distinct) vertices.
        """
        if self.mesh is None:
            return None
        if self not in _HULL_OF:
            vertices, solid = _convex_hull(self.mesh)
            vertices.setflags(write=False)
            _HULL_OF[self] = vertices, solid
        return _HULL_OF[self][0]

    @property
    def convex(self) -> bool:
        """Whether the shape is (nearly) its convex hull, so that FCL's distance to it is the hull's.

        Primitives are convex; a mesh counts as convex when it is closed and its volume is
        within 0.1 % of its hull's (its triangles are then the hull's surface but for small
        dents: the hull is what is treated as in contact).
        """
        if self.mesh is None:
            return True
        self.hull_vertices()
        return bool(_HULL_OF[self][1])

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        """An oriented box containing the shape: ``(pose (4, 4) in the shape frame, half extents (3,))``."""
        if self.kind == "box":
            return np.eye(4), np.asarray(self.dims)
        if self.kind == "sphere":
            return np.eye(4), np.full(3, self.dims[0])
        if self.kind == "cylinder":
            r, length = self.dims
            return np.eye(4), np.array([r, r, 0.5 * length])
        to_box, extents = trimesh.bounds.oriented_bounds(self.mesh)
        return np.linalg.inv(to_box), 0.5 * np.asarray(extents)

    def bounding_spheres(self, count: int) -> tuple[np.ndarray, np.ndarray]:
        """At most ``count`` spheres covering the shape: ``(centres (m, 3), radii (m,))``, shape frame.

        Starting from one piece (the whole shape), the piece with the largest sphere is
        cut in two across its longest extent until there are ``count`` pieces: boxes and
        cylinders are cut as boxes (a cylinder through its bounding box), meshes as sets of
        triangles split at the median centroid (long triangles are subdivided first, to
        edges of at most 1/count of the mesh's radius, covering the same surface). Each piece gets the sphere about its box
        centre that holds it; for meshes, every vertex of the piece's triangles (FCL tests
        a mesh's triangles, so covering every triangle covers what FCL can touch).
        """
        if count < 1:
            raise ValueError(f"bounding_spheres needs count >= 1, got {count}")
        known = _SPHERES_OF.setdefault(self, {})  # robots share shapes across checkers; compute once
        if count not in known:

            def compute() -> dict[str, np.ndarray]:
                centres, radii = self._covering_spheres(count)
                return {"centres": centres, "radii": radii}

            mesh = () if self.mesh is None else (np.asarray(self.mesh.vertices), np.asarray(self.mesh.faces))
            arrays = cached_arrays("spheres", (self.kind, self.dims, *mesh, count), compute)
            centres, radii = arrays["centres"], arrays["radii"]
            centres.setflags(write=False)
            radii.setflags(write=False)
            known[count] = centres, radii
        return known[count]

    def _covering_spheres(self, count: int) -> tuple[np.ndarray, np.ndarray]:
        if self.kind == "sphere":
            return np.zeros((1, 3)), np.array([self.dims[0]])
        if self.kind == "mesh":
            # cut long triangles first (the pieces cover the same surface) so spheres can shrink
            mesh = self._triangles()
            whole = _TrianglePiece(np.asarray(mesh.triangles, dtype=float))
            vertices, faces = trimesh.remesh.subdivide_to_size(
                mesh.vertices, mesh.faces, max_edge=whole.radius / count, max_iter=20
            )
            pieces: list[_Piece] = [_TrianglePiece(np.asarray(vertices, dtype=float)[faces])]
        else:
            _pose, half = self.bounding_box()  # identity pose for box and cylinder
            pieces = [_BoxPiece(np.zeros(3), np.asarray(half, dtype=float))]
        while len(pieces) < count:
            widest = max(range(len(pieces)), key=lambda i: pieces[i].radius)
            halves = pieces[widest].split()
            if halves is None:  # a single triangle: nothing left to cut
                break
            pieces[widest : widest + 1] = halves
        return np.array([p.centre for p in pieces]), np.array([p.radius for p in pieces])


_HULL_OF: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # Shape -> (hull vertices, convex)


def _convex_hull(mesh: trimesh.Trimesh) -> tuple[np.ndarray, bool]:
    """The vertices of ``mesh``'s convex hull and whether the mesh is closed and fills it.

    The hull (Qhull) is checked to hold every vertex of the mesh, to 1e-9 m; a hull that
    fails the check or has no volume is replaced by all the mesh's vertices (the same
    convex set, only slower to search).
    """
    points = np.unique(np.asarray(mesh.vertices, dtype=float), axis=0)
    try:
        hull = scipy.spatial.ConvexHull(points)
    except scipy.spatial.QhullError:  # flat or degenerate
        return points, False
    outside = max(
        float((chunk @ hull.equations[:, :3].T + hull.equations[:, 3]).max())
        for chunk in np.array_split(points, max(1, len(points) // 512))
    )
    if not (hull.volume > 0.0 and outside <= 1e-9):
        return points, False
    merged = mesh.copy()
    merged.merge_vertices()
    # closed and of the hull's volume (to 0.1 %): the triangles are the hull's surface but for dents
    solid = bool(merged.is_watertight and abs(abs(merged.volume) - hull.volume) <= 1e-3 * hull.volume)
    return points[hull.vertices], solid


class _Piece(Protocol):
    """A piece of a shape and the sphere about ``centre`` (3,) of ``radius`` that holds it."""

    centre: np.ndarray
    radius: float

    def split(self) -> list[_Piece] | None: ...


class _BoxPiece:
    """An axis-aligned box ``centre`` (3,) +- ``half`` (3,) and its circumscribed sphere."""

    def __init__(self, centre: np.ndarray, half: np.ndarray):
        self.centre, self.half = centre, half
        self.radius = float(np.linalg.norm(half))

    def split(self) -> list[_Piece]:
        axis = int(np.argmax(self.half))
        half = self.half.copy()
        half[axis] *= 0.5
        step = np.zeros(3)
        step[axis] = half[axis]
        return [_BoxPiece(self.centre - step, half), _BoxPiece(self.centre + step, half)]


class _TrianglePiece:
    """Triangles (t, 3, 3) and the sphere about their vertices' box centre holding every vertex."""

    def __init__(self, triangles: np.ndarray):
        self.triangles = triangles
        points = triangles.reshape(-1, 3)
        self.centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
        self.radius = float(np.sqrt(((points - self.centre) ** 2).sum(axis=1).max()))

    def split(self) -> list[_Piece] | None:
        if len(self.triangles) < 2:
            return None
        centroids = self.triangles.mean(axis=1)
        axis = int(np.argmax(np.ptp(centroids, axis=0)))
        order = np.argsort(centroids[:, axis], kind="stable")
        middle = len(order) // 2
        return [_TrianglePiece(self.triangles[order[:middle]]), _TrianglePiece(self.triangles[order[middle:]])]


def pose_matrix(
    position: ArrayLike = (0.0, 0.0, 0.0), orientation_xyzw: Iterable[float] = (0.0, 0.0, 0.0, 1.0)
) -> np.ndarray:
    """Homogeneous transform (4, 4) from a position (m) and a unit quaternion, scalar last."""
    orientation_xyzw = [float(v) for v in orientation_xyzw]
    x, y, z, w = orientation_xyzw
    norm = np.sqrt(x * x + y * y + z * z + w * w)
    if not np.isfinite(norm) or abs(norm - 1.0) > 1e-3:
        raise ValueError(f"orientation_xyzw must be a unit quaternion [x, y, z, w], got {list(orientation_xyzw)}")
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    pose = np.eye(4)
    pose[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    position = np.asarray(position, dtype=float)
    if position.shape != (3,) or not np.all(np.isfinite(position)):
        raise ValueError(f"position must be 3 finite numbers, got {position.tolist()}")
    pose[:3, 3] = position
    return pose


def fcl_transform(pose: np.ndarray) -> fcl.Transform:
    """FCL transform of a (4, 4) homogeneous pose."""
    return fcl.Transform(pose[:3, :3], pose[:3, 3])
