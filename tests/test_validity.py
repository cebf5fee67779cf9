"""Collision answers against an independent FCL query, and the OMPL adapters against OMPL's own."""

import json
import subprocess
import sys
from pathlib import Path

import fcl
import numpy as np
import pytest
import trimesh
import yourdfpy
from ompl import base as ob
from ompl import geometric as og

from ompl_balance import BalancedRRTConnect
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.environment import Environment
from ompl_balance.collision.kernels import visiting_order
from ompl_balance.collision.kinematics import RobotModel
from ompl_balance.collision.robots import PANDA_VAMP_DIR, load_panda_vamp
from ompl_balance.core.counting import read_work
from ompl_balance.validity import MotionValidator, StateValidityChecker, setup_robot, space_for
from ompl_balance.worlds.mbm import load_mbm

REPO = Path(__file__).resolve().parents[1]

ROBOTS = Path(__file__).resolve().parent / "robots"


def arm3_scene():
    robot = RobotModel.from_urdf(ROBOTS / "arm3.urdf", ROBOTS / "arm3.srdf", package_map={"testbot": str(ROBOTS)})
    environment = Environment()
    environment.add_box("wall", [0.05, 0.4, 0.3], [0.55, 0.0, 0.3], [0.0, 0.0, 0.3826834, 0.9238795])
    environment.add_sphere("ball", 0.1, [-0.3, 0.35, 0.5])
    environment.add_cylinder("post", 0.05, 0.8, [-0.1, -0.5, 0.4], [0.3826834, 0.0, 0.0, 0.9238795])
    environment.add_mesh("cone", ROBOTS / "meshes" / "cone.obj", [0.0, 0.45, 0.2])
    return robot, environment, ROBOTS / "arm3.urdf"


def panda_scene():
    robot = load_panda_vamp()
    problem = load_mbm("table_pick", robot.joint_names)[0]
    return robot, problem.environment, PANDA_VAMP_DIR / "panda.urdf"


def independent_answers(robot, environment, urdf_path, q):
    """(env collision, self collision) per configuration: yourdfpy FK, fresh FCL objects, every pair."""
    urdf = yourdfpy.URDF.load(str(urdf_path), load_meshes=False, build_collision_scene_graph=False)
    collisions = [(link.name, c) for link in urdf.robot.links for c in link.collisions]
    assert [name for name, _ in collisions] == [g.link for g in robot.geometries]
    request = fcl.CollisionRequest()
    obstacles = [
        fcl.CollisionObject(o.shape.fcl_geometry(), fcl.Transform(o.pose[:3, :3], o.pose[:3, 3]))
        for o in environment.obstacles
    ]
    root = robot.link_names[0]
    env_hits, self_hits = [], []
    for x in q:
        urdf.update_cfg(dict(zip(robot.joint_names, x)))
        objects = []
        for (link, collision), geometry in zip(collisions, robot.geometries):
            origin = np.eye(4) if collision.origin is None else collision.origin
            pose = urdf.get_transform(link, root) @ origin
            objects.append(fcl.CollisionObject(geometry.shape.fcl_geometry(), fcl.Transform(pose[:3, :3], pose[:3, 3])))
        env_hits.append(any(fcl.collide(a, b, request, fcl.CollisionResult()) for a in objects for b in obstacles))
        self_hits.append(
            any(
                fcl.collide(objects[i], objects[j], request, fcl.CollisionResult())
                for i, j in robot.self_collision_pairs
            )
        )
    return np.array(env_hits), np.array(self_hits)


def check_scene(scene, count, seed):
    robot, environment, urdf_path = scene
    q = np.random.default_rng(seed).uniform(robot.lower, robot.upper, size=(count, robot.dof))
    env_hits, self_hits = independent_answers(robot, environment, urdf_path, q)
    # the sample must exercise every kind of answer
    assert env_hits.sum() >= 5 and self_hits.sum() >= 5 and (~env_hits & ~self_hits).sum() >= 5
    expected = ~(env_hits | self_hits)
    np.testing.assert_array_equal(CollisionChecker(robot, environment).check(q), expected)
    np.testing.assert_array_equal(CollisionChecker(robot, environment, spheres_per_geometry=1).check(q), expected)
    one_by_one = CollisionChecker(robot, environment, spheres_per_geometry=16)  # single-state path, many spheres
    np.testing.assert_array_equal([one_by_one.is_valid(x) for x in q[:80]], expected[:80])
    np.testing.assert_array_equal(CollisionChecker(robot, environment, prefilter=False).check(q), expected)
    self_only = CollisionChecker(robot)
    np.testing.assert_array_equal(self_only.check(q), ~self_hits)


def test_collisions_agree_with_independent_fcl_arm3():
    check_scene(arm3_scene(), 300, seed=1)


def test_collisions_agree_with_independent_fcl_panda_table_pick():
    check_scene(panda_scene(), 250, seed=2)


def test_certified_free_tables_hold_no_contact_panda():
    # the forearm (link5) and everything below joint 7 are always close: their pairs get
    # tables over joints 6 and 7; a free cell must hold no contact anywhere in it, so
    # probe the free cells next to non-free ones (where a wrong bound would show first)
    robot, _, _ = panda_scene()
    volumes = CollisionChecker(robot)._volumes
    names = [g.link for g in robot.geometries]
    tabled = {(names[a], names[b]) for (a, b), k in zip(robot.self_collision_pairs, volumes.pair_table) if k >= 0}
    assert {("panda_link5", "panda_link7"), ("panda_link5", "panda_hand")} <= tabled
    rng = np.random.default_rng(3)
    request = fcl.CollisionRequest()
    for (a, b), k in zip(robot.self_collision_pairs, volumes.pair_table):
        if k < 0:
            continue
        rows, cols = volumes.table_cells[k]
        free = volumes.table_free[volumes.table_start[k] : volumes.table_start[k] + rows * cols].reshape(rows, cols)
        assert 0.5 < free.mean() < 1.0  # certifies most, not what it cannot
        padded = np.pad(free, 1, constant_values=True)
        border = free & ~(padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:])
        cells = np.argwhere(border)
        cells = cells[rng.choice(len(cells), size=min(len(cells), 400), replace=False)]
        joints = volumes.table_joints[k]
        values = volumes.table_low[k] + (cells + rng.uniform(size=cells.shape)) * volumes.table_cell[k]
        q = np.zeros((len(cells), robot.dof))
        q[:, robot.chain.source[joints]] = values  # the Panda's joints are its active joints
        poses = robot.body_poses(q)
        objects = [fcl.CollisionObject(robot.geometries[g].shape.fcl_geometry()) for g in (a, b)]
        for pose in poses:
            for obj, g in zip(objects, (a, b)):
                placed = pose[robot.geometries[g].body] @ robot.geometries[g].origin
                obj.setTransform(fcl.Transform(placed[:3, :3], placed[:3, 3]))
            assert not fcl.collide(objects[0], objects[1], request, fcl.CollisionResult()), (names[a], names[b])


@pytest.mark.parametrize("count", [1, 3, 8, 32])
def test_bounding_spheres_cover_every_surface_point(count):
    robot, environment, _ = arm3_scene()
    shapes = [g.shape for g in robot.geometries] + [o.shape for o in environment.obstacles]
    assert {s.kind for s in shapes} == {"box", "sphere", "cylinder", "mesh"}
    for shape in shapes:
        centres, radii = shape.bounding_spheres(count)
        assert 1 <= len(radii) <= count
        mesh = shape.trimesh()
        points = np.vstack([mesh.vertices, trimesh.sample.sample_surface(mesh, 2000, seed=5)[0]])
        if shape.kind != "mesh":  # FCL primitives are solids: the inside must be covered too
            points = np.vstack([points, trimesh.sample.volume_mesh(mesh, 2000)])
        gap = np.linalg.norm(points[:, None] - centres[None], axis=-1) - radii
        assert gap.min(axis=1).max() <= 1e-9, f"{shape.kind}: a point is outside every sphere"


def make_si(robot, checker, resolution=0.01):
    space = space_for(robot)
    si = ob.SpaceInformation(space)
    si.setStateValidityCheckingResolution(resolution)
    return space, si


def random_edges(robot, checker, count, rng):
    edges = []
    while len(edges) < count:
        a = rng.uniform(robot.lower, robot.upper)
        if checker.is_valid(a):
            edges.append((a, rng.uniform(robot.lower, robot.upper)))
    return edges


def check_motion_validator(robot, environment, edges_count, seed):
    rng = np.random.default_rng(seed)
    checker = CollisionChecker(robot, environment)
    space, si = make_si(robot, checker)
    _validity, motion = setup_robot(si, checker, motion="discrete")
    si.setup()
    _discrete_space, discrete_si = make_si(robot, checker)
    discrete_si.setStateValidityChecker(StateValidityChecker(discrete_si, CollisionChecker(robot, environment)))
    discrete_si.setup()
    s1, s2, last = si.allocState(), si.allocState(), si.allocState()
    outcomes = []
    for a, b in random_edges(robot, checker, edges_count, rng):
        space.copyFromReals(s1, list(a))
        space.copyFromReals(s2, list(b))
        nd = space.validSegmentCount(s1, s2)
        before = read_work(si)
        valid = si.checkMotion(s1, s2)
        work = read_work(si) - before
        assert work.motions_checked == 1
        assert work.states_checked == nd if valid else 1 <= work.states_checked <= nd
        assert valid == discrete_si.checkMotion(s1, s2)
        # last valid state: the first invalid state walking from s1, as OMPL's overload
        walk = checker.check(a + (np.arange(1, nd + 1) / nd)[:, None] * (b - a))
        valid_again, fraction = motion.check_motion_last_valid(s1, s2, last)
        assert valid_again == valid == walk.all()
        if not valid:
            first = int(np.argmin(walk))
            assert fraction == pytest.approx(first / nd)
            np.testing.assert_allclose(last[0 : robot.dof], a + first / nd * (b - a), atol=1e-12)
        outcomes.append(valid)
    assert 3 <= sum(outcomes) <= len(outcomes) - 3, "edges should be both free and colliding"


def test_motion_validator_matches_discrete_arm3():
    robot, environment, _ = arm3_scene()
    check_motion_validator(robot, environment, 60, seed=3)


def test_motion_validator_matches_discrete_panda():
    robot, environment, _ = panda_scene()
    check_motion_validator(robot, environment, 40, seed=4)


def test_coarse_to_fine_visits_every_state_once():
    for nd in range(1, 40):
        order = tuple(visiting_order(nd).tolist())
        assert sorted(order) == list(range(nd)) and order[0] == nd - 1
    assert visiting_order(8)[:4].tolist() == [7, 3, 1, 5]


def test_space_bounds_and_planning_with_rrtconnect():
    robot, environment, _ = arm3_scene()
    space = space_for(robot)
    bounds = space.getBounds()
    assert [bounds.low[i] for i in range(3)] == pytest.approx(list(robot.lower))
    assert [bounds.high[i] for i in range(3)] == pytest.approx(list(robot.upper))
    checker = CollisionChecker(robot, environment)
    ss = og.SimpleSetup(space)
    validity, motion = setup_robot(ss, checker)
    si = ss.getSpaceInformation()
    assert si.getStateValidityChecker() is validity and si.getMotionValidator() is motion
    start, goal = si.allocState(), si.allocState()
    for i, (a, b) in enumerate(zip([0.0, -1.0, 0.1], [2.5, 1.0, 0.1])):  # copyFromReals needs space.setup()
        start[i], goal[i] = a, b
    ss.setStartAndGoalStates(start, goal)
    ss.setPlanner(og.RRTConnect(si))
    assert ss.solve(5.0)
    path = ss.getSolutionPath()
    states = np.array([path.getState(i)[0:3] for i in range(path.getStateCount())])
    assert checker.check(states).all()
    work = read_work(si)
    assert work.motions_checked > 0 and work.states_checked > work.motions_checked


def test_non_finite_and_out_of_limit_configurations_are_not_valid():
    robot, environment, _ = arm3_scene()
    checker = CollisionChecker(robot, environment)
    free = next(q for q in np.random.default_rng(0).uniform(robot.lower, robot.upper, (100, 3)) if checker.is_valid(q))
    outside = free.copy()
    outside[1] = robot.upper[1] + 1e-9
    rows = np.array([free, [0.0, 0.0, np.inf], [0.0, np.nan, 0.0], outside])
    assert checker.check(rows).tolist() == [True, False, False, False]
    assert [checker.is_valid(q) for q in rows] == [True, False, False, False]
    _space, si = make_si(robot, checker)
    validity = StateValidityChecker(si, checker)
    state = si.allocState()
    for q in rows:
        for i in range(3):
            state[i] = float(q[i])
        assert validity.isValid(state) == checker.is_valid(q)


@pytest.mark.parametrize("planner", [og.RRTConnect, BalancedRRTConnect])
def test_a_non_finite_robot_start_is_an_invalid_start(planner):
    robot, environment, _ = arm3_scene()
    checker = CollisionChecker(robot, environment)
    ss = og.SimpleSetup(space_for(robot))
    setup_robot(ss, checker)
    start, goal = ss.getSpaceInformation().allocState(), ss.getSpaceInformation().allocState()
    for i in range(3):
        start[i], goal[i] = 0.0, 0.0
    start[1] = float("nan")
    ss.setStartAndGoalStates(start, goal)
    ss.setPlanner(planner(ss.getSpaceInformation()))
    assert ss.solve(0.5) == ob.PlannerStatus.INVALID_START


def test_bad_input():
    robot, environment, _ = arm3_scene()
    checker = CollisionChecker(robot, environment)
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        checker.check([0.0, 0.0])
    _space, si = make_si(robot, checker)
    with pytest.raises(ValueError, match="dimension 2"):
        setup_robot(ob.SpaceInformation(ob.RealVectorStateSpace(2)), checker)
    with pytest.raises(ValueError, match="'wall'"):
        environment.add_box("wall", [1, 1, 1])
    with pytest.raises(ValueError, match=r"'tilted'.*quaternion"):
        environment.add_box("tilted", [1, 1, 1], orientation_xyzw=[0, 0, 1, 1])
    with pytest.raises(ValueError, match="positive"):
        environment.add_sphere("flat", 0.0)
    discrete = MotionValidator(si, checker)
    assert isinstance(discrete, ob.MotionValidator)
    good, state = si.allocState(), si.allocState()
    good[0], good[1], good[2] = 0.0, 0.0, 0.0
    state[0], state[1], state[2] = 0.0, float("nan"), 0.0
    assert discrete.check_motion_last_valid(good, state) == (False, 0.0)  # NaN: invalid, no exception
    last = si.allocState()
    for end in (float("nan"), float("inf")):
        state[1] = end
        last[0], last[1], last[2] = 9.0, 9.0, 9.0
        assert discrete.check_motion_last_valid(good, state, last) == (False, 0.0)
        assert [last[i] for i in range(3)] == [0.0, 0.0, 0.0]  # s1, not the stale or non-finite values


def test_warm_up_compiles_the_kernels_real_checkers_use():
    # the runner's forkserver warms the kernels with stand-in arrays: their types must be the
    # ones real robots pass, or each run would compile (or load) the kernels again; so the
    # process never holds more than one compiled version of each, whatever ran before
    from ompl_balance.collision.kinematics import _chain_poses_batch
    from ompl_balance.collision.screening import screen, warm_up

    warm_up()
    robot, environment, _ = arm3_scene()
    checker = CollisionChecker(robot, environment)
    q = np.zeros((2, robot.dof))
    checker.check(q)
    checker.is_valid(q[0])
    robot.body_poses(q)
    assert len(screen.signatures) == 1 and len(_chain_poses_batch.signatures) == 1


class FCLError(RuntimeError):
    """The error the tests have FCL raise."""


def failing_fcl(*arguments):
    raise FCLError("the test's FCL failure")


def state_fcl_decides(checker, rng):
    """A free configuration whose screening leaves a pair to FCL (the checker's exit taken)."""
    while True:
        q = rng.uniform(checker.robot.lower, checker.robot.upper)
        exits = checker.counter.exits
        if checker.is_valid(q) and checker.counter.exits > exits:
            return q


@pytest.mark.parametrize(
    ("motion", "engine"),
    [("discrete", "compiled"), ("discrete", "python"), ("discrete", "stock"), ("certified", "compiled")],
)
def test_an_error_in_fcl_reaches_the_caller_and_the_planner_plans_on(motion, engine, monkeypatch):
    """FCL raising in a state check that compiled code sent to it (through the checker's exit)
    ends the solve with that error, on both engines and under a stock planner; once FCL answers
    again, the same planner solves, and its path's states are free. The package's planners solve
    from a seed whose solve is known to reach FCL; the stock planner (which no seed parameter
    repeats) starts where FCL decides. (The certified motions of this scene never reach FCL: its
    obstacles are convex. Their exit's errors are tested in test_certified.py.)"""
    robot, environment, _ = arm3_scene()
    checker = CollisionChecker(robot, environment)
    ss = og.SimpleSetup(space_for(robot))
    setup_robot(ss, checker, motion=motion)
    si = ss.getSpaceInformation()
    start, goal = si.allocState(), si.allocState()
    begin = state_fcl_decides(checker, np.random.default_rng(5)) if engine == "stock" else [0.0, -1.0, 0.1]
    for i, (a, b) in enumerate(zip(begin, [2.5, 1.0, 0.1])):
        start[i], goal[i] = a, b
    ss.setStartAndGoalStates(start, goal)
    planner = og.RRTConnect(si) if engine == "stock" else BalancedRRTConnect(si)
    if engine != "stock":
        planner.setEngine(engine)
        planner.params().setParam("seed", "2")  # (its solve reaches FCL: 12 exits, 2 certified)
    ss.setPlanner(planner)
    with monkeypatch.context() as patched:
        for name in ("decide", "pair_touching", "pair_distance"):
            patched.setattr(checker, name, failing_fcl)
        with pytest.raises(FCLError, match="the test's FCL failure"):
            ss.solve(10.0)
    if engine == "stock":
        return
    assert ss.solve(10.0)
    path = ss.getSolutionPath()
    assert checker.check(np.array([path.getState(i)[0:3] for i in range(path.getStateCount())])).all()


FIRST_FCL_QUERIES = """
import json, sys
import numpy as np
from numba.core import event
from ompl import geometric as og, util as ou
ou.setLogLevel(ou.LOG_ERROR)
sys.path.insert(0, "tests")
from test_validity import arm3_scene, state_fcl_decides
from ompl_balance import BalancedRRTConnect
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.validity import setup_robot, space_for
robot, environment, _ = arm3_scene()
compiling = event.TimingListener()
with event.install_listener("numba:compile", compiling):
    checker = CollisionChecker(robot, environment)
    state_fcl_decides(checker, np.random.default_rng(5))
    ss = og.SimpleSetup(space_for(robot))
    setup_robot(ss, checker, motion="certified")
    si = ss.getSpaceInformation()
    start, goal = si.allocState(), si.allocState()
    for i, (a, b) in enumerate(zip([0.0, -1.0, 0.1], [2.5, 1.0, 0.1])):
        start[i], goal[i] = a, b
    ss.setStartAndGoalStates(start, goal)
    planner = BalancedRRTConnect(si)
    planner.setEngine("compiled")
    planner.params().setParam("seed", "2")
    ss.setPlanner(planner)
    ss.setup()
    planner.wait_for_engine()
    before = checker.counter.exits
    solved = bool(ss.solve(10.0))
print(json.dumps({"compiled": compiling.done, "solved": solved, "exits": [before, checker.counter.exits - before]}))
"""


def test_a_fresh_process_compiles_nothing_at_its_first_fcl_queries():
    """A process whose kernels and engine numba's cache holds takes its first FCL queries, from a
    Python check and from a compiled solve, without numba compiling anything (an exit is a C
    callback, nothing of it is compiled lazily). The first run fills the cache where it is cold."""
    command = [sys.executable, "-c", FIRST_FCL_QUERIES]
    subprocess.run(command, capture_output=True, text=True, timeout=900, cwd=REPO, check=True)
    result = subprocess.run(command, capture_output=True, text=True, timeout=300, cwd=REPO, check=True)
    answer = json.loads(result.stdout.strip().splitlines()[-1])
    assert answer["solved"] and answer["exits"][0] >= 1 and answer["exits"][1] >= 1
    assert not answer["compiled"], "numba compiled in a process whose kernels were cached"
