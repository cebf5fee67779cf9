"""OMPL.app's problem files: the loader against hand-computed poses on meshes the tests write
(axis-angle, the robot's centring on Assimp's kept vertices, COLLADA's up axis, bounds inference),
bad input, and (with ``OMPLAPP_RESOURCES`` naming a copy of OMPL.app's ``resources`` folder) every
shipped ``.path`` state valid and the bounds OMPL.app inferred into its own files.

OMPL.app's files are under a licence that forbids redistributing them: none is in this
repository, and the tests that read them skip without the variable.
"""

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
from rigid_oracles import place, triangles_separation

from ompl_balance.worlds.mesh_files import kept_corners, read_mesh_file
from ompl_balance.worlds.omplapp import axis_angle_quaternion, load_omplapp, read_omplapp_path

Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])  # (x, y, z) -> (x, z, -y)


def collada(path, positions, triangles, lines=(), up="Z_UP", matrix=None):
    """Write a COLLADA file: one geometry (``<triangles>`` and, if any, ``<lines>``, positions only)
    under one node with ``matrix`` (4, 4)."""
    matrix = np.eye(4) if matrix is None else np.asarray(matrix)
    floats = " ".join(f"{v:.9g}" for v in np.asarray(positions, dtype=float).ravel())
    tri = " ".join(str(i) for i in np.asarray(triangles).ravel())
    line_element = ""
    if len(lines):
        indices = " ".join(str(i) for i in np.asarray(lines).ravel())
        line_element = (
            f'<lines count="{len(lines)}" material="m"><input offset="0" semantic="VERTEX" source="#v"/>'
            f"<p>{indices}</p></lines>"
        )
    text = f"""<?xml version="1.0" encoding="UTF-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><up_axis>{up}</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="pa" count="{len(positions) * 3}">{floats}</float_array>
   <technique_common><accessor source="#pa" count="{len(positions)}" stride="3">
    <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
   </accessor></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="{len(triangles)}" material="m"><input offset="0" semantic="VERTEX" source="#v"/><p>{tri}</p></triangles>
  {line_element}
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n">
  <matrix>{" ".join(f"{v:.9g}" for v in matrix.ravel())}</matrix>
  <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
 <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""
    Path(path).write_text(text)


def box(lo, hi):
    """Corner positions (8, 3) and triangles (12, 3) of an axis-aligned box."""
    mesh = trimesh.creation.box(bounds=[lo, hi])
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def write_cfg(folder, lines):
    path = Path(folder) / "problem.cfg"
    path.write_text("\n".join(lines) + "\n")
    return path


SE3_LINES = [
    "[problem]",
    "name = test",
    "robot = robot.dae",
    "world = world.dae",
    "start.x = 0.0",
    "start.y = 0.0",
    "start.z = 0.0",
    "start.theta = 0",
    "start.axis.x = 1",
    "start.axis.y = 0",
    "start.axis.z = 0",
    "goal.x = 0.0",
    "goal.y = 0.0",
    "goal.z = -8.0",
    "goal.theta = 1.5707963267948966",
    "goal.axis.x = 0",
    "goal.axis.y = 0",
    "goal.axis.z = 2",
    "[benchmark]",
    "time_limit = 7.5",
]


@pytest.fixture
def scene(tmp_path):
    """A robot (a box under a node translation, plus two line-only points) and a world (a slab),
    both Z_UP; returns the folder and what the test computes by hand."""
    corners, faces = box([-1.0, -0.5, -0.25], [1.0, 0.5, 0.25])
    extra = np.array([[4.0, 0.0, 0.0], [4.0, 2.0, 0.0]])  # in lines only
    positions = np.vstack([corners, extra])
    shift = np.array([10.0, 20.0, 30.0])
    matrix = np.eye(4)
    matrix[:3, 3] = shift
    collada(tmp_path / "robot.dae", positions, faces, lines=[[8, 9]], matrix=matrix)
    world_corners, world_faces = box([-5.0, -5.0, 4.0], [5.0, 5.0, 5.0])  # z_up: y in [4, 5] after conversion
    collada(tmp_path / "world.dae", world_corners, world_faces)
    # by hand: Assimp keeps each box corner once per face normal (3 per corner), the line's
    # two points once each; then the node shift, then Z_UP -> Y_UP
    kept = np.vstack([np.repeat(corners, 3, axis=0), extra]) + shift
    centre = (kept @ Z_UP.T).mean(axis=0)
    return tmp_path, centre, (corners + shift) @ Z_UP.T, faces, world_corners @ Z_UP.T


def test_robot_is_centred_on_assimps_vertices_and_turned_y_up(scene):
    folder, centre, robot_corners, faces, world_corners = scene
    robot = read_mesh_file(folder / "robot.dae")
    assert len(robot.vertices) == 8 * 3 + 2
    np.testing.assert_allclose(robot.centre, centre, atol=1e-6)
    np.testing.assert_allclose(
        np.sort(robot.triangles.reshape(-1, 3), axis=0), np.sort(robot_corners[faces].reshape(-1, 3), axis=0), atol=1e-6
    )
    world = read_mesh_file(folder / "world.dae")
    np.testing.assert_allclose(world.vertices.min(axis=0), world_corners.min(axis=0), atol=1e-6)
    assert world.vertices[:, 1].min() == pytest.approx(4.0) and world.vertices[:, 2].max() == pytest.approx(5.0)


def test_load_se3_poses_bounds_time_limit(scene):
    folder, centre, robot_corners, faces, world_corners = scene
    problem = load_omplapp(write_cfg(folder, SE3_LINES))
    assert problem.space == "SE3" and problem.name == "test" and problem.time_limit == 7.5
    np.testing.assert_allclose(problem.start, [0, 0, 0, 0, 0, 0, 1], atol=1e-12)
    s = math.sin(math.pi / 4)
    np.testing.assert_allclose(problem.goal, [0, 0, -8, 0, 0, s, s], atol=1e-12)  # axis (0, 0, 2) normalised
    # bounds: the world's vertices' box, widened to hold the start and goal positions
    low, high = world_corners.min(axis=0), world_corners.max(axis=0)
    np.testing.assert_allclose(problem.low, np.minimum(low, [0, 0, -8]))
    np.testing.assert_allclose(problem.high, np.maximum(high, [0, 0, 0]))
    # the body is the robot's triangles less the centre: placed at a state as OMPL.app places it
    body = np.concatenate([p.shape.mesh.triangles for p in problem.body.parts])
    np.testing.assert_allclose(
        np.sort(body.reshape(-1, 3), axis=0), np.sort((robot_corners - centre)[faces].reshape(-1, 3), axis=0), atol=1e-6
    )
    # the checker agrees with the triangles, placed by hand (the slab spans y in [4, 5])
    checker = problem.checker()
    triangles = (robot_corners - centre)[faces]
    world = world_corners[box([-5.0, -5.0, 4.0], [5.0, 5.0, 5.0])[1]]
    for y in (2.0, 3.5, 3.7, 3.9, 4.5):
        for theta in (0.0, math.pi / 2):
            state = np.array([0.0, y, 0.0, *axis_angle_quaternion((1.0, 0.0, 0.0), theta)])
            state[2] = -1.0  # inside the bounds
            free = triangles_separation(place(triangles, state), world) > 0
            assert checker.is_valid(state) == free


def test_load_se2_frame_has_z_zero(tmp_path):
    corners, faces = box([-1.0, -1.0, -1.0], [1.0, 3.0, 1.0])  # z_up: becomes y in [-1, 1], z in [-3, 1]
    collada(tmp_path / "robot.dae", corners + np.array([5.0, 0.0, 0.0]), faces)
    world, world_faces = box([10.0, 10.0, -1.0], [11.0, 11.0, 1.0])
    collada(tmp_path / "world.dae", world, world_faces)
    lines = ["[problem]", "robot = robot.dae", "world = world.dae", "start.x = 0", "start.y = 0", "start.theta = 0.5",
             "goal.x = 3", "goal.y = -4", "goal.theta = -2", "volume.min.x = -9", "volume.min.y = -9",
             "volume.max.x = 9", "volume.max.y = 2"]  # fmt: skip
    problem = load_omplapp(write_cfg(tmp_path, lines))
    assert problem.space == "SE2" and problem.time_limit is None
    np.testing.assert_allclose(problem.start, [0, 0, 0.5])
    np.testing.assert_allclose(problem.low, [-9, -9])
    np.testing.assert_allclose(problem.high, [9, 2])
    body = np.concatenate([p.shape.mesh.vertices for p in problem.body.parts])
    # the frame: the corners' mean in x and y, z kept (SE(2) robots are centred in the plane)
    np.testing.assert_allclose(body.min(axis=0), [-1.0, -1.0, -3.0], atol=1e-9)
    np.testing.assert_allclose(body.max(axis=0), [1.0, 1.0, 1.0], atol=1e-9)


def test_kept_corners_join_exact_positions_and_close_attributes():
    positions = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 0, 0]], dtype=float)
    normals = np.array([[0, 0, 1], [0, 0, 1 + 1e-8], [0, 1, 0], [0, 0, 1], [0, 0, 1]], dtype=float)
    np.testing.assert_array_equal(kept_corners(positions, normals), [[0, 0, 0], [0, 0, 0], [1, 0, 0]])
    assert len(kept_corners(positions, np.zeros((5, 0)))) == 2


def test_obj_objects_are_meshes_and_degenerate_mesh_is_refused(tmp_path):
    text = "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n"
    (tmp_path / "two.obj").write_text(text)
    assert len(read_mesh_file(tmp_path / "two.obj").meshes) == 2
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match=r"flat\.obj: all 1 triangles are degenerate"):
        read_mesh_file(tmp_path / "flat.obj")
    with pytest.raises(ValueError, match="not found"):
        read_mesh_file(tmp_path / "missing.stl")


def _error(folder, lines, pattern):
    path = write_cfg(folder, lines)
    with pytest.raises(ValueError, match=pattern) as raised:
        load_omplapp(path)
    assert str(path) in str(raised.value) and "\n" not in str(raised.value)


def test_bad_input_names_the_file_and_line(scene):
    folder = scene[0]
    replace = lambda index, line: [line if i == index else old for i, old in enumerate(SE3_LINES)]  # noqa: E731
    _error(folder, replace(2, "robot = nowhere.dae"), r"problem\.cfg:3: robot = nowhere\.dae: mesh file .* not found")
    _error(folder, replace(4, "start.x 0.0"), r"problem\.cfg:5: expected 'key = value'")
    _error(folder, replace(4, "start.x = zero"), r"problem\.cfg:5: start\.x = 'zero' is not a finite number")
    _error(  # naming what collides
        folder,
        replace(5, "start.y = 4.0"),
        r"problem\.cfg:5: the start state .* is in collision with the world: \S+ with obstacle '.+'",
    )
    _error(folder, [line for line in SE3_LINES if not line.startswith("goal.theta")], r"has no goal\.theta")
    _error(
        folder, [*SE3_LINES[:2], "control = blimp", *SE3_LINES[2:]], r"problem\.cfg:3: control = blimp: control-based"
    )
    _error(
        folder,
        [*SE3_LINES[:2], "volume.min.x = 0", *SE3_LINES[2:]],
        r"problem\.cfg:3: the volume bounds are incomplete",
    )
    for time_limit in ("-5", "0", "nan"):  # the last line of SE3_LINES
        _error(
            folder,
            replace(len(SE3_LINES) - 1, f"time_limit = {time_limit}"),
            rf"problem\.cfg:{len(SE3_LINES)}: time_limit = '{time_limit}' is not a positive number of seconds",
        )
    _error(folder, replace(0, "[problem"), r"problem\.cfg:1: malformed section header")
    _error(folder, [*SE3_LINES, "[problem]", "start.x = 1"], r"start\.x is given twice \(first on line 5\)")
    (folder / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    _error(folder, replace(3, "world = flat.obj"), r"problem\.cfg:4: world = flat\.obj: .* degenerate")
    with pytest.raises(ValueError, match="not found"):
        load_omplapp(folder / "none.cfg")


def test_path_files(tmp_path):
    (tmp_path / "a.path").write_text("1 2 3 0 0 0 1.000001\n\n4 5 6 0 0.6 0 0.8\n")
    states = read_omplapp_path(tmp_path / "a.path", "SE3")
    np.testing.assert_allclose(np.linalg.norm(states[:, 3:], axis=1), 1.0)
    (tmp_path / "b.path").write_text("1 2 3\n4 5\n")
    with pytest.raises(ValueError, match=r"b\.path:2: expected 3 numbers"):
        read_omplapp_path(tmp_path / "b.path")
    (tmp_path / "c.path").write_text("1 2 3 0 0 0 2\n")
    with pytest.raises(ValueError, match=r"c\.path:1: the quaternion has norm 2"):
        read_omplapp_path(tmp_path / "c.path")


# -- OMPL.app's own files (not shipped: OMPLAPP_RESOURCES names the user's copy) ---------------

RESOURCES = os.environ.get("OMPLAPP_RESOURCES")
needs_resources = pytest.mark.skipif(
    not RESOURCES or not Path(RESOURCES).is_dir(), reason="set OMPLAPP_RESOURCES to OMPL.app's resources folder"
)


def _cfgs_with_paths():
    if not RESOURCES:
        return []
    return sorted(p for p in Path(RESOURCES).glob("*/*.cfg") if p.with_suffix(".path").is_file())


@needs_resources
@pytest.mark.slow
@pytest.mark.parametrize("cfg", _cfgs_with_paths(), ids=lambda p: p.stem)
def test_omplapp_paths_are_valid(cfg):
    """The solution paths OMPL.app ships: every state valid under the loader and checker."""
    text = cfg.read_text()
    world = re.search(r"^\s*world\s*=\s*(\S+)", text, re.M).group(1)
    if not (cfg.parent / world).is_file():
        pytest.skip(f"{world} is not in this copy of the resources")
    problem = load_omplapp(cfg, validate=False)
    states = read_omplapp_path(cfg.with_suffix(".path"), problem.space)
    checker = problem.checker()
    invalid = np.flatnonzero(~checker.check(states))
    assert len(invalid) == 0, f"invalid states {invalid.tolist()} of {len(states)}"


@needs_resources
@pytest.mark.parametrize("name", ["Home", "Abstract", "cubicles"])
def test_inferred_bounds_are_those_omplapp_wrote(name, tmp_path):
    """These files carry the bounds OMPL.app inferred: without them the loader infers the same."""
    cfg = Path(RESOURCES) / "3D" / f"{name}.cfg"
    if not cfg.is_file():
        pytest.skip(f"{cfg} is not in this copy of the resources")
    written = load_omplapp(cfg, validate=False)
    lines = [line for line in cfg.read_text().splitlines() if not line.strip().startswith("volume.")]
    lines = [re.sub(r"^(robot|world)\s*=\s*(\S+)", lambda m: f"{m[1]} = {cfg.parent / m[2]}", line) for line in lines]
    inferred = load_omplapp(write_cfg(tmp_path, lines), validate=False)
    np.testing.assert_allclose(inferred.low, written.low, atol=5e-3)  # (cubicles.cfg rounds to 0.01)
    np.testing.assert_allclose(inferred.high, written.high, atol=5e-3)
