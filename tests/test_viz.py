"""The viewer without a browser: what it reads from a solve, the scenes it builds, the file it
writes, the command's messages, and that nothing on the planning path imports it."""

import re
import signal
import subprocess
import sys
import textwrap
import urllib.request

import numpy as np
import pytest
import trimesh
from fresh_process import with_ctrl_c_as_in_a_terminal
from ompl import base as ob
from ompl import geometric as og

from ompl_balance import BalancedRRTConnect, CollisionChecker, Environment, RobotModel, setup_robot, space_for
from ompl_balance.cli import main
from ompl_balance.validity import rigid_state_values, set_rigid_state
from ompl_balance.viz.api import scene_and_plan, show
from ompl_balance.viz.plan import animation_frames
from ompl_balance.viz.problems import OMPL_2D, named_problem, scene_of_setup
from ompl_balance.viz.scene import PlaneScene, RobotScene, occupied_blocks
from ompl_balance.worlds.boxes import PROBLEMS
from ompl_balance.worlds.occupancy import OCCUPANCY_PROBLEMS

INSTALL = "pip install 'ompl-balance[viz]'"


def _run(code, timeout=300):
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout, check=False
    )


def test_planning_imports_no_viewer():
    done = _run(
        """
        import sys
        import ompl_balance
        from ompl_balance import BalancedRRTConnect, PROBLEMS
        ss = PROBLEMS["maze"].setup()
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setEngine("python")  # (the compiled engine's first compile is not what is tested)
        ss.setPlanner(planner)
        assert ss.solve(5.0)
        print("after planning:", "ompl_balance.viz" in sys.modules, "viser" in sys.modules)
        ompl_balance.show  # the name loads the viewer's modules, not viser
        print("after the name:", "ompl_balance.viz" in sys.modules, "viser" in sys.modules)
        """
    )
    assert done.returncode == 0, done.stderr
    said = [line for line in done.stdout.splitlines() if line.startswith("after")]
    assert said == ["after planning: False False", "after the name: True False"]


def test_without_viser_show_says_which_extra_in_one_line(tmp_path):
    done = _run(
        f"""
        import sys
        sys.modules["viser"] = None  # as if the viz extra were not installed
        from ompl_balance.cli import main
        code = main(["show", "open", "-o", {str(tmp_path / "plan.html")!r}])
        import ompl_balance
        from ompl_balance.bench.errors import MissingExtraError
        try:
            ompl_balance.show(ompl_balance.PROBLEMS["open"])
        except MissingExtraError as error:
            print(error)
        sys.exit(code)
        """
    )
    assert done.returncode == 2
    lines = [line for line in done.stderr.splitlines() if line.startswith("ompl-balance show:")]
    assert lines == [f"ompl-balance show: showing plans needs viser (the viz extra): {INSTALL}"]
    assert done.stdout.strip() == f"showing plans needs viser (the viz extra): {INSTALL}"
    assert not (tmp_path / "plan.html").exists()


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            ["nowhere"],
            r"^ompl-balance show: unknown problem 'nowhere'; built-in: open, .*rooms_se2, env1, env2, circles",
        ),
        (["open", "--planner", "NoSuchPlanner"], r"^ompl-balance show: planner 'NoSuchPlanner': name: unknown planner"),
        (["open", "--planner", "RRTConnect[speed=2]"], r"^ompl-balance show: planner 'RRTConnect\[speed=2\]': .*speed"),
    ],
)
def test_bad_input_is_one_line_naming_what_is_accepted(arguments, message, capsys, tmp_path):
    assert main(["show", *arguments, "-o", str(tmp_path / "plan.html")]) == 2
    error = capsys.readouterr().err
    assert re.match(message, error) and error.count("\n") == 1, error
    assert not (tmp_path / "plan.html").exists()


@pytest.mark.parametrize(
    ("arguments", "message"),
    [(["open", "-o", "plan.png"], "must name an .html file"), (["open", "-o", "/nowhere/plan.html"], "does not exist")],
)
def test_the_output_file_is_checked_before_planning(arguments, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as raised:
        main(["show", *arguments])
    assert raised.value.code == 2 and message in capsys.readouterr().err


def test_show_refuses_what_it_cannot_draw(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(TypeError, match=r"show takes an og\.SimpleSetup"):
        show(object(), file="unused.html")
    space = ob.RealVectorStateSpace(3)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda state: True)
    with pytest.raises(ValueError, match=r"show draws robots .* RealVectorStateSpace of dimension 3"):
        show(ss, file="unused.html")
    with pytest.raises(ValueError, match=r"trees=True needs the og\.SimpleSetup"):
        show(PROBLEMS["maze"], trees=True, file="unused.html")


@pytest.fixture(scope="module")
def table_pick():
    return named_problem("table_pick.001")


def test_the_plan_read_from_a_stock_planners_solve_is_that_solve(table_pick):
    ss = table_pick.setup()
    si = ss.getSpaceInformation()
    checker = si.getStateValidityChecker()
    planner = og.RRTConnect(si)
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    _scene, plan = scene_and_plan(ss, None, True)
    path = ss.getSolutionPath()
    expected = np.array([[path.getState(i)[j] for j in range(7)] for i in range(path.getStateCount())])
    assert np.array_equal(plan.path, expected)
    assert np.allclose(plan.start, table_pick.start) and np.allclose(plan.goal, expected[-1])
    data = ob.PlannerData(si)
    planner.getPlannerData(data)
    assert [tree.name for tree in plan.trees] == ["start tree", "goal tree"]
    assert sum(len(tree.states) for tree in plan.trees) == data.numVertices()
    tags = [data.getVertex(i).getTag() for i in range(data.numVertices())]
    within = [(i, j) for i in range(data.numVertices()) for j in data.getEdges(i) if tags[i] == tags[j]]
    assert sum(len(tree.edges) for tree in plan.trees) == len(within) >= data.numEdges() - 1  # (less the bridge)
    assert plan.status == "Exact solution" and plan.planner == "RRTConnect"
    # reading the start put the problem's own checker back, and the setup plans again
    assert si.getStateValidityChecker() is checker
    ss.clear()
    assert ss.solve(10.0)


def test_frames_pass_through_every_state_of_the_path_evenly(table_pick):
    scene = table_pick.scene
    path = np.array([table_pick.start, 0.5 * (table_pick.start + table_pick.goal), table_pick.goal])
    path[1, 0] += 0.3
    frames = animation_frames(scene, path, 120)
    assert 115 <= len(frames) <= 125
    rows = [int(np.flatnonzero((frames == state).all(axis=1))[0]) for state in path]
    assert rows == sorted(rows) and rows[0] == 0 and rows[-1] == len(frames) - 1
    steps = np.linalg.norm(np.diff(frames, axis=0), axis=1)
    assert steps.max() < 1.2 * steps.mean()


def test_a_rigid_bodys_frames_follow_ompls_interpolation():
    problem = named_problem("se3_cage")
    scene = problem.scene
    frames = animation_frames(scene, np.stack([problem.start, problem.goal]), 11)
    space = ob.SE3StateSpace()
    a, b, out = space.allocState(), space.allocState(), space.allocState()
    set_rigid_state(a, problem.start)
    set_rigid_state(b, problem.goal)
    assert len(frames) == 11
    for k, frame in enumerate(frames):
        space.interpolate(a, b, k / 10, out)
        assert np.allclose(frame, rigid_state_values(out, 7), atol=1e-9)


def test_the_robots_meshes_sit_where_the_checker_puts_its_geometry(table_pick):
    scene = table_pick.scene
    robot = scene.robot
    rng = np.random.default_rng(5)
    for q in rng.uniform(robot.lower, robot.upper, size=(5, robot.dof)):
        frames = scene.frame_poses(q[None])[0]
        bodies = robot.body_poses(q)[0]
        for (frame, part), geometry in zip(scene.parts, robot.geometries):
            shown = part.points(frames[frame])
            placed = bodies[geometry.body] @ geometry.origin
            expected = np.asarray(geometry.shape.trimesh().vertices) @ placed[:3, :3].T + placed[:3, 3]
            assert np.allclose(shown, expected, atol=1e-9)


@pytest.mark.parametrize("name", [*PROBLEMS, "twin_pockets", *OCCUPANCY_PROBLEMS, *OMPL_2D])
def test_every_2d_world_has_its_obstacles_and_a_valid_start_and_goal(name):
    problem = named_problem(name)
    scene = problem.scene
    assert isinstance(scene, PlaneScene)
    assert scene.problem(problem.start) == "" and scene.problem(problem.goal) == ""
    assert bool(scene.obstacles) == (name != "open")


def test_a_plain_2d_checkers_obstacles_are_where_it_refuses_states():
    """A 2-D setup's checker sampled on a grid: the blocks drawn are the boxes, to a cell."""
    problem = PROBLEMS["bug_trap"]
    scene = scene_of_setup(problem.setup())
    assert isinstance(scene, PlaneScene) and scene.notes
    cell = 1.0 / 200
    rng = np.random.default_rng(2)
    points = rng.uniform(0.0, 1.0, size=(4000, 2))
    in_block = np.zeros(len(points), dtype=bool)
    for mesh in scene.obstacles:
        (x0, y0, _), (x1, y1, _) = mesh.mesh.bounds
        in_block |= (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
    world = problem.world()
    blocked = np.array([not world.is_free(x, y) for x, y in points])
    near_edge = np.array(
        [
            any(min(abs(x - b[0]), abs(x - b[2]), abs(y - b[1]), abs(y - b[3])) < cell for b in problem.boxes)
            for x, y in points
        ]
    )
    assert np.array_equal(in_block[~near_edge], blocked[~near_edge])


def test_occupied_blocks_cover_the_occupied_cells_exactly():
    rng = np.random.default_rng(9)
    for _ in range(20):
        occupied = rng.random((17, 23)) < 0.3
        covered = np.zeros(occupied.shape, dtype=int)
        for x0, y0, x1, y1 in occupied_blocks(occupied, (-1.0, 2.0), (0.5, 0.25)):
            c0, c1 = round((x0 + 1.0) / 0.5), round((x1 + 1.0) / 0.5)
            r0, r1 = round((y0 - 2.0) / 0.25), round((y1 - 2.0) / 0.25)
            covered[r0:r1, c0:c1] += 1
        assert np.array_equal(covered, occupied.astype(int))


URDF = """<?xml version="1.0"?>
<robot name="pointer">
  <material name="teal"><color rgba="0 0.5 0.5 1"/></material>
  <link name="base">
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry><material name="teal"/></visual>
  </link>
  <link name="arm">
    <collision><origin xyz="0.25 0 0"/><geometry><box size="0.5 0.05 0.05"/></geometry></collision>
    <visual><origin xyz="0.25 0 0"/><geometry><mesh filename="{mesh}"/></geometry></visual>
  </link>
  <joint name="turn" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def _pointer(folder, mesh="arm.stl"):
    trimesh.creation.box(extents=(0.5, 0.05, 0.05)).export(folder / "arm.stl")
    (folder / "pointer.urdf").write_text(URDF.format(mesh=mesh))
    return RobotModel.from_urdf(folder / "pointer.urdf")


def test_a_users_own_robot_is_shown_with_its_visual_meshes(tmp_path):
    robot = _pointer(tmp_path)
    environment = Environment()
    environment.add_box("post", (0.05, 0.05, 0.2), (0.0, 0.4, 0.2))
    checker = CollisionChecker(robot, environment)
    ss = og.SimpleSetup(space_for(robot))
    setup_robot(ss, checker)
    si = ss.getSpaceInformation()
    start, goal = si.allocState(), si.allocState()
    start[0], goal[0] = -2.5, 1.2  # the post (at 1.57 rad) stays beyond the goal
    ss.setStartAndGoalStates(start, goal)
    ss.setPlanner(BalancedRRTConnect(si))
    assert ss.solve(5.0)
    scene, _plan = scene_and_plan(ss, None, False)
    assert isinstance(scene, RobotScene) and scene.notes == []
    assert [(scene.frames[f], mesh.colour) for f, mesh in scene.visuals] == [("base", (0, 128, 128)), ("arm", None)]
    file = show(ss, file=tmp_path / "pointer.html")
    html = file.read_text()
    assert "__VISER_EMBED_DATA__" in html
    assert not re.search(r"""(?:src|href)\s*=\s*["']?(?:https?:)?//""", html), "the file loads from the network"
    assert file.stat().st_size < 20e6


def test_missing_visual_meshes_leave_the_collision_geometry_and_say_so(tmp_path):
    robot = _pointer(tmp_path, mesh="nowhere.stl")
    scene = RobotScene(CollisionChecker(robot))
    assert scene.visuals == []
    assert scene.notes == [
        "the collision geometry is shown, not the visual meshes: link 'arm': visual mesh 'nowhere.stl' not found"
    ]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["table_pick.001", "se3_cage"])
def test_the_command_writes_the_file_of_a_panda_and_a_rigid_body(name, tmp_path, capsys):
    file = tmp_path / "plan.html"
    assert main(["show", name, "-o", str(file), "--time-limit", "60"]) == 0
    out = capsys.readouterr().out
    written = re.search(r"wrote .* \(([\d.]+) MB, ([\d.]+) s\)", out)
    assert written, out
    assert file.stat().st_size < 20e6 and float(written.group(2)) < 30.0  # (writing takes a second or two)
    assert "__VISER_EMBED_DATA__" in file.read_text()


def test_the_live_command_ends_cleanly_on_ctrl_c():
    arguments = [
        "show",
        "maze",
        "--planner",
        "RRTConnect",
        "--port",
        "0",
        "--no-browser",
    ]  # (stock: nothing to compile)
    command = with_ctrl_c_as_in_a_terminal([sys.executable, "-X", "faulthandler", "-m", "ompl_balance.cli", *arguments])
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        address = None
        for line in process.stdout:
            found = re.search(r"at (http://127\.0\.0\.1:\d+) \(Ctrl-C to stop\)", line)
            if found:
                address = found.group(1)
                break
        assert address, "the command never said where the viewer is"
        with urllib.request.urlopen(address, timeout=10) as answer:
            assert answer.status == 200
        process.send_signal(signal.SIGINT)
        try:
            out, _ = process.communicate(timeout=60)
        except subprocess.TimeoutExpired:  # (where it stands: every thread's stack, by faulthandler)
            process.send_signal(signal.SIGABRT)
            out, _ = process.communicate(timeout=30)
            pytest.fail(f"the viewer did not stop within 60 s of Ctrl-C:\n{out}")
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 0, out
    assert "viewer stopped" in out and "Traceback" not in out


@pytest.mark.parametrize("command", [True, False])
def test_ctrl_c_as_soon_as_the_viewer_is_up_stops_it(command, monkeypatch, capsys):
    """A Ctrl-C between the viewer starting and its wait for Ctrl-C (here: while the browser is
    being opened) stops the viewer's server, whose threads would otherwise keep the process alive
    after the command or script ends: the command ends as on any Ctrl-C, ``show`` raises it."""
    import threading
    import webbrowser

    def interrupted(url):
        raise KeyboardInterrupt

    monkeypatch.setattr(webbrowser, "open", interrupted)
    before = set(threading.enumerate())
    if command:
        assert main(["show", "maze", "--planner", "RRTConnect", "--port", "0"]) == 0
        assert "viewer stopped" in capsys.readouterr().out
    else:
        with pytest.raises(KeyboardInterrupt):
            show(named_problem("maze").setup(), port=0)
    left = [thread for thread in set(threading.enumerate()) - before if not thread.daemon]
    for thread in left:
        thread.join(timeout=10.0)
    assert not [thread for thread in left if thread.is_alive()]
