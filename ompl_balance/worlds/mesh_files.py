"""Mesh files read as OMPL.app reads them (through Assimp): triangles, and the vertices Assimp keeps.

OMPL.app loads a robot or world file with Assimp (``aiProcess_Triangulate``,
``JoinIdenticalVertices``, ``GenNormals``, ``SortByPType``, ``OptimizeGraph``) and uses it twice:

* the **triangles**, placed by the scene's node transforms, are the collision model (FCL BVH);
* the **vertices** Assimp keeps are the robot's frame (their mean: the robot is centred on it)
  and the bounds it infers for a world (their box). Assimp keeps, per mesh (a COLLADA primitive
  element under one node; line elements included), each distinct corner: position, normal and
  texture coordinates; faces without normals get their face normal (``GenNormals``), lines none.
  Corners count as one when their positions agree exactly and their normals and texture
  coordinates to :data:`CORNER_TOLERANCE` (single precision, as Assimp stores them).

COLLADA files (``.dae``, read with pycollada) are turned to Y-up as Assimp turns them:
``Z_UP`` maps ``(x, y, z) -> (x, z, -y)``, ``X_UP`` maps ``(x, y, z) -> (-y, x, z)``, and the
``<unit meter>`` scale applies. Other formats (OBJ, STL, PLY, OFF, ...) are read with trimesh,
one mesh per object, each face's corners with the face normal (what Assimp keeps for files
without normals or texture coordinates).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

#: Corners closer than this in normal and texture coordinates are one vertex (see the module docstring).
CORNER_TOLERANCE = 1e-6

_UP_AXES = {
    "Y_UP": np.eye(3),
    "Z_UP": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
    "X_UP": np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
}


@dataclass(frozen=True)
class MeshFile:
    """A mesh file's geometry in OMPL.app's (Y-up) frame.

    ``meshes``: the triangles (t, 3, 3) of each mesh that has any; ``vertices`` (v, 3): the
    vertices Assimp keeps, line elements included (see the module docstring).
    """

    path: Path
    meshes: list[np.ndarray]
    vertices: np.ndarray

    @property
    def triangles(self) -> np.ndarray:
        """All triangles (t, 3, 3)."""
        return np.concatenate(self.meshes)

    @property
    def centre(self) -> np.ndarray:
        """The mean of the kept vertices (3,): OMPL.app's robot frame origin."""
        return self.vertices.mean(axis=0)


def read_mesh_file(path: str | Path) -> MeshFile:
    """Read a COLLADA, OBJ, STL, PLY or OFF file as OMPL.app does (see the module docstring).

    ``ValueError`` naming the file for a missing or unreadable file, one with no triangles, and
    one whose triangles all have zero area.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"mesh file {path} not found")
    try:
        meshes, vertices = _read_collada(path) if path.suffix.lower() == ".dae" else _read_trimesh(path)
    except Exception as error:  # the readers raise their own kinds for malformed files
        raise ValueError(f"cannot read mesh file {path}: {error}") from error
    meshes = [m for m in meshes if len(m)]
    if not meshes:
        raise ValueError(f"mesh file {path} holds no triangles")
    triangles = np.concatenate(meshes)
    areas = np.linalg.norm(np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]), axis=1)
    if not (areas > 0.0).any():
        raise ValueError(f"mesh file {path}: all {len(triangles)} triangles are degenerate (zero area)")
    if not np.isfinite(triangles).all():
        raise ValueError(f"mesh file {path} has vertices that are not finite numbers")
    return MeshFile(path, meshes, np.concatenate(vertices).astype(float))


def kept_corners(positions: np.ndarray, attributes: np.ndarray) -> np.ndarray:
    """The corners Assimp keeps of one mesh: rows of ``positions`` (k, 3) that are distinct in
    position (exactly, in single precision) or in ``attributes`` (k, m) (to :data:`CORNER_TOLERANCE`),
    the first of each kind in order. Returns their positions (u, 3)."""
    positions = np.asarray(positions, dtype=np.float32)
    attributes = np.asarray(attributes, dtype=np.float32).reshape(len(positions), -1)
    rows = np.concatenate([positions, attributes], axis=1)
    _, first = np.unique(rows, axis=0, return_index=True)  # exact duplicates go first
    first.sort()
    kept: dict[bytes, list[np.ndarray]] = {}
    keep = []
    for i in first.tolist():
        seen = kept.setdefault(positions[i].tobytes(), [])
        if any(float(np.sum((other - attributes[i]) ** 2)) <= CORNER_TOLERANCE**2 for other in seen):
            continue
        seen.append(attributes[i])
        keep.append(i)
    return positions[keep]


def _face_normals(triangles: np.ndarray) -> np.ndarray:
    """Unit normals (t, 3) of triangles (t, 3, 3); zero for degenerate ones (Assimp's ``NormalizeSafe``)."""
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0.0)


def _read_collada(path: Path) -> tuple[list[np.ndarray], list[np.ndarray]]:
    with warnings.catch_warnings():  # pycollada builds numpy matrices, which numpy warns about
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        return _collada_meshes(path)


def _collada_meshes(path: Path) -> tuple[list[np.ndarray], list[np.ndarray]]:
    import collada

    document = collada.Collada(str(path), ignore=[collada.common.DaeUnsupportedError, collada.common.DaeBrokenRefError])
    if document.scene is None:
        raise ValueError("the COLLADA document has no visual scene")
    up = _UP_AXES.get(document.assetInfo.upaxis or "Y_UP", np.eye(3)) * float(document.assetInfo.unitmeter or 1.0)
    meshes, vertices = [], []
    for geometry in document.scene.objects("geometry"):
        for element in geometry.primitives():
            lines = isinstance(element, collada.lineset.BoundLineSet)
            triangles = lines or isinstance(element, collada.triangleset.BoundTriangleSet)
            primitive = element if triangles else element.triangleset()  # polygons and polylists, as fans
            corners = 2 if lines else 3
            index = np.asarray(primitive.vertex_index, dtype=np.int64).reshape(-1, corners)
            if len(index) == 0:
                continue
            corner_positions = (np.asarray(primitive.vertex, dtype=float) @ up.T)[index]
            attributes = []
            normal = getattr(primitive, "normal", None)
            if normal is not None and getattr(primitive, "normal_index", None) is not None:
                attributes.append(np.asarray(normal, dtype=float)[np.asarray(primitive.normal_index).reshape(-1)])
            elif not lines:
                attributes.append(np.repeat(_face_normals(corner_positions), 3, axis=0))
            for coordinates, indices in zip(primitive.texcoordset or (), primitive.texcoord_indexset or ()):
                attributes.append(np.asarray(coordinates, dtype=float)[np.asarray(indices).reshape(-1)])
            flat = corner_positions.reshape(-1, 3)
            attribute_rows = np.concatenate(attributes, axis=1) if attributes else np.zeros((len(flat), 0))
            vertices.append(kept_corners(flat, attribute_rows))
            if not lines:
                meshes.append(corner_positions)
    return meshes, vertices


def _read_trimesh(path: Path) -> tuple[list[np.ndarray], list[np.ndarray]]:
    # Assimp makes a mesh of each OBJ object and group; trimesh merges them unless asked not to
    options: dict[str, Any] = {}
    if path.suffix.lower() == ".obj":
        options = {"split_objects": True, "split_groups": True, "group_material": False}
    loaded = trimesh.load(str(path), process=False, **options)
    parts = loaded.dump() if isinstance(loaded, trimesh.Scene) else [loaded]
    meshes, vertices = [], []
    for part in parts:
        if not isinstance(part, trimesh.Trimesh) or len(part.faces) == 0:
            continue
        triangles = np.asarray(part.triangles, dtype=float)
        meshes.append(triangles)
        vertices.append(kept_corners(triangles.reshape(-1, 3), np.repeat(_face_normals(triangles), 3, axis=0)))
    return meshes, vertices
