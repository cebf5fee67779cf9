"""What collides: ``collisions(q)`` of the robot and rigid-body checkers against FCL's own collision
tests and distances on every pair, brute force, with geometry placed independently (the robot's
body poses times each geometry's origin; rigid states turned into poses by scipy), and against
the checkers' own validity answers."""

import math

import fcl
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.contacts import Contact, describe_contacts
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.worlds.mbm import load_mbm
from ompl_balance.worlds.rigid import rigid_problem


def _placed(shape, pose):
    return fcl.CollisionObject(shape.fcl_geometry(), fcl.Transform(pose[:3, :3], pose[:3, 3]))


def _brute_force(pairs):
    """``{(kind, first, second): distance}`` for every pair (0.0 when FCL's test finds contact)."""
    found = {}
    for key, a, b in pairs:
        if fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()):
            found[key] = 0.0
        else:
            found[key] = fcl.distance(a, b, fcl.DistanceRequest(), fcl.DistanceResult())
    return found


def _robot_pairs(checker, q):
    robot = checker.robot
    poses = robot.body_poses(q)[0]
    links = [_placed(g.shape, poses[g.body] @ g.origin) for g in robot.geometries]
    obstacles = [_placed(o.shape, o.pose) for o in checker.environment.obstacles]
    pairs = [(("obstacle", g, o), links[g], obstacles[o]) for o in range(len(obstacles)) for g in range(len(links))]
    return pairs + [(("self", a, b), links[a], links[b]) for a, b in robot.self_collision_pairs]


def _rigid_pairs(checker, state):
    pose = np.eye(4)
    if len(state) == 3:
        pose[:3, :3] = Rotation.from_euler("z", state[2]).as_matrix()
        pose[:2, 3] = state[:2]
    else:
        pose[:3, :3] = Rotation.from_quat(state[3:]).as_matrix()
        pose[:3, 3] = state[:3]
    parts = [_placed(p.shape, pose @ p.pose) for p in checker.body.parts]
    obstacles = [_placed(o.shape, o.pose) for o in checker.environment.obstacles]
    return [(("obstacle", p, o), parts[p], obstacles[o]) for o in range(len(obstacles)) for p in range(len(parts))]


def _agrees(contacts, truth, nearest):
    """``contacts`` are the pairs in contact, or the ``nearest`` closest pairs with FCL's distances."""
    touching = {key for key, distance in truth.items() if distance == 0.0}
    keys = [(c.kind, c.first_index, c.second_index) for c in contacts]
    if touching:
        assert set(keys) == touching and len(keys) == len(touching)
        assert all(c.touching and c.distance == 0.0 for c in contacts)
        return
    closest = sorted(truth.values())[:nearest]
    assert [c.distance for c in contacts] == pytest.approx(closest, rel=1e-9, abs=1e-12)
    assert all(not c.touching and truth[key] == pytest.approx(c.distance) for c, key in zip(contacts, keys))


@pytest.fixture(scope="module")
def panda_checker():
    robot = load_panda_vamp()
    problem = load_mbm("table_pick", robot.joint_names)[0]
    return CollisionChecker(robot, problem.environment)


def test_robot_collisions_are_fcls_pairs_in_contact_or_the_nearest(panda_checker):
    robot = panda_checker.robot
    rng = np.random.default_rng(7)
    configurations = rng.uniform(robot.lower, robot.upper, size=(40, robot.dof))
    colliding = free = 0
    for q in configurations:
        truth = _brute_force(_robot_pairs(panda_checker, q))
        contacts = panda_checker.collisions(q)
        if contacts:
            _agrees(contacts, truth, 0)
        assert bool(contacts) == any(d == 0.0 for d in truth.values())
        assert bool(contacts) == (not panda_checker.is_valid(q))  # the screened check says the same
        _agrees(panda_checker.collisions(q, nearest=3), truth, 3)
        colliding += bool(contacts)
        free += not contacts
    assert colliding >= 5 and free >= 5  # both kinds of configuration were tried


def test_robot_contacts_name_the_link_and_the_obstacle(panda_checker):
    robot = panda_checker.robot
    q = np.clip(np.zeros(robot.dof), robot.lower, robot.upper)
    rng = np.random.default_rng(3)
    while not (contacts := panda_checker.collisions(q)):
        q = rng.uniform(robot.lower, robot.upper)
    names = {o.name for o in panda_checker.environment.obstacles}
    for contact in contacts:
        assert contact.first == robot.geometries[contact.first_index].link
        if contact.kind == "obstacle":
            assert contact.second == panda_checker.environment.obstacles[contact.second_index].name in names
            assert str(contact) == f"{contact.first} with obstacle {contact.second!r}"
        else:
            assert contact.second == robot.geometries[contact.second_index].link
            assert str(contact) == f"{contact.first} with {contact.second} (self-collision)"
    assert describe_contacts(contacts, limit=1).startswith(str(contacts[0]))


@pytest.mark.parametrize("name", ["se2_bugtrap", "se3_cage"])
def test_rigid_collisions_are_fcls_pairs_in_contact_or_the_nearest(name):
    problem = rigid_problem(name)
    checker = problem.checker()
    rng = np.random.default_rng(11)
    colliding = free = 0
    for _ in range(60):
        position = rng.uniform(problem.low, problem.high)
        if problem.space == "SE2":
            state = np.array([*position, rng.uniform(-math.pi, math.pi)])
        else:
            quaternion = rng.normal(size=4)
            state = np.array([*position, *(quaternion / np.linalg.norm(quaternion))])
        truth = _brute_force(_rigid_pairs(checker, state))
        contacts = checker.collisions(state)
        assert bool(contacts) == any(d == 0.0 for d in truth.values())
        assert bool(contacts) == (not checker.is_valid(state))
        if contacts:
            _agrees(contacts, truth, 0)
        _agrees(checker.collisions(state, nearest=2), truth, 2)
        parts, obstacles = problem.body.parts, problem.environment.obstacles
        assert all((c.first, c.second) == (parts[c.first_index].name, obstacles[c.second_index].name) for c in contacts)
        colliding += bool(contacts)
        free += not contacts
    assert colliding >= 5 and free >= 5


def test_collisions_refuse_bad_input(panda_checker):
    robot = panda_checker.robot
    with pytest.raises(ValueError, match=r"shape \(n, 7\)"):
        panda_checker.collisions(np.zeros(robot.dof + 1))
    with pytest.raises(ValueError, match="one configuration"):
        panda_checker.collisions(np.zeros((2, robot.dof)))
    with pytest.raises(ValueError, match="non-finite"):
        panda_checker.collisions(np.full(robot.dof, np.nan))
    with pytest.raises(ValueError, match="nearest must be"):
        panda_checker.collisions(np.zeros(robot.dof), nearest=-1)
    checker = rigid_problem("se3_cage").checker()
    with pytest.raises(ValueError, match="has 7 values"):
        checker.collisions(np.zeros(3))
    with pytest.raises(ValueError, match="quaternion of norm"):
        checker.collisions(np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0]))


def test_a_contact_in_words():
    touching = Contact("panda_hand", "shelf", "obstacle", True, 0.0, 8, 2)
    apart = Contact("panda_link5", "panda_link7", "self", False, 0.0213, 5, 7)
    assert str(touching) == "panda_hand with obstacle 'shelf'"
    assert str(apart) == "panda_link5 0.0213 m from panda_link7 (self-collision)"
    assert describe_contacts([touching] * 8, limit=6).endswith("and 2 more")
    assert describe_contacts([]) == ""
