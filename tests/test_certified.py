"""Certified motions against an independent dense check, the travel bound against sampled motion,
grazing and self-collision edges, lastValid, clearance, bad input, and planning with the default validator.

The oracle: a fresh :class:`CollisionChecker` (FCL's collision test on the pairs its
screening does not clear, itself tested against yourdfpy's FK and FCL on every pair in
test_validity.py) at states at most ``STEP`` rad apart in every joint. It shares none of
what certification rests on: travel bounds, GJK distance bounds on convex hulls, the
advancement, FCL distances.
"""

import itertools

import fcl
import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from test_validity import FCLError, arm3_scene, failing_fcl

import ompl_balance
from ompl_balance import BalancedRRTConnect
from ompl_balance.collision import certified
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.environment import Environment
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.collision.travel import travel_weights
from ompl_balance.core.counting import read_work
from ompl_balance.validity import CertifiedMotionValidator, MotionValidator, certify_path, setup_robot, space_for
from ompl_balance.worlds.mbm import SCENARIOS, load_mbm

STEP = 1e-4  # rad: the oracle's resolution in every joint


_PANDA = {}


def panda():
    if "robot" not in _PANDA:
        _PANDA["robot"] = load_panda_vamp()
    return _PANDA["robot"]


def panda_scene(scenario="table_pick", index=0):
    robot = panda()
    return robot, load_mbm(scenario, robot.joint_names)[index].environment


def dense_first_collision(oracle, a, b, until=1.0):
    """Fraction of the first colliding state on ``a -> b`` (states at most STEP apart, up to
    ``until``), or None."""
    count = max(1, int(np.ceil(np.abs(b - a).max() * until / STEP)))
    t = until * np.arange(count + 1) / count
    for chunk in np.array_split(np.arange(len(t)), max(1, len(t) // 4096)):
        first = oracle.first_collision(a + t[chunk, None] * (b - a), first_chunk=len(chunk))
        if first >= 0:
            return float(t[chunk[first]])
    return None


def random_edges(robot, oracle, count, rng, longest=1.2):
    """``count`` edges from valid states, of random direction and length up to ``longest`` rad."""
    edges = []
    span = robot.upper - robot.lower
    while len(edges) < count:
        a = rng.uniform(robot.lower, robot.upper)
        if not oracle.is_valid(a):
            continue
        direction = rng.normal(size=robot.dof) * span
        b = np.clip(a + direction / np.abs(direction).max() * rng.uniform(0.02, longest), robot.lower, robot.upper)
        edges.append((a, b))
    return edges


def check_edges(robot, environment, edges, certifier=None):
    """Every edge: certified only if the oracle finds no collision; the lastValid fraction is at
    or before the first collision and its prefix is free. Returns (certified, oracle-free) counts.

    The two ways of checking (without and with lastValid) do different work, so near the work
    budget one may refuse a free edge the other certifies."""
    oracle = CollisionChecker(robot, environment)
    certifier = certifier or certified.MotionCertifier(CollisionChecker(robot, environment))
    certified_count = free_count = 0
    for a, b in edges:
        first = dense_first_collision(oracle, a, b)
        over_budget = certifier.checker.counters()["motions_over_budget"]
        valid, fraction = certifier.check(a, b)
        assert not (valid and first is not None), f"edge certified free collides at t = {first}: {a} -> {b}"
        assert fraction == (1.0 if valid else 0.0)
        valid_again, fraction = certifier.check(a, b, last_valid=True)
        over_budget = certifier.checker.counters()["motions_over_budget"] > over_budget
        assert valid_again == valid or (first is None and (not valid or over_budget)), "last_valid changed the verdict"
        if first is not None:  # (a start in collision: nothing is certified, fraction 0)
            assert fraction < first or fraction == first == 0.0
        if 0.0 < fraction < 1.0:
            assert dense_first_collision(oracle, a, b, until=fraction) is None, "the certified prefix collides"
        certified_count += valid
        free_count += first is None
    return certified_count, free_count


# ---------------------------------------------------------------------------------------- travel bound


def surface_points(geometry):
    """Points of a link geometry in its body frame: mesh vertices, tessellation vertices of primitives."""
    shape = geometry.shape
    points = np.asarray(shape.mesh.vertices if shape.kind == "mesh" else shape.trimesh().vertices, dtype=float)
    return points @ geometry.origin[:3, :3].T + geometry.origin[:3, 3]


def lowest_common_body(chain, a, b):
    ancestors = set()
    while True:
        ancestors.add(a)
        if a == 0:
            break
        a = int(chain.parent_body[a - 1])
    while b not in ancestors:
        b = int(chain.parent_body[b - 1])
    return b


def travel_ratios(robot, rng, edges=40, steps=64):
    """Largest (sampled path length of a point) / (travel bound) for each geometry and self pair."""
    environment_weight, self_weight = travel_weights(robot)
    points = [surface_points(g) for g in robot.geometries]
    worst_environment, worst_self = 0.0, 0.0
    for _ in range(edges):
        a, b = rng.uniform(robot.lower, robot.upper), rng.uniform(robot.lower, robot.upper)
        poses = robot.body_poses(a + np.linspace(0, 1, steps + 1)[:, None] * (b - a))
        world = [poses[:, g.body, :3, :3] @ p.T + poses[:, g.body, :3, 3:] for g, p in zip(robot.geometries, points)]
        for g in range(len(robot.geometries)):
            length = np.linalg.norm(np.diff(world[g], axis=0), axis=1).sum(axis=0).max()
            bound = environment_weight[g] @ np.abs(b - a)
            if bound == 0.0:  # the root body's geometries do not move
                assert length < 1e-12
                continue
            worst_environment = max(worst_environment, length / bound)
        for p, (ga, gb) in enumerate(robot.self_collision_pairs):
            common = lowest_common_body(robot.chain, robot.geometries[ga].body, robot.geometries[gb].body)
            inverse = np.linalg.inv(poses[:, common])
            length = 0.0
            for g in (ga, gb):  # both geometries' paths in the common body's frame
                local = inverse[:, :3, :3] @ world[g] + inverse[:, :3, 3:]
                length += np.linalg.norm(np.diff(local, axis=0), axis=1).sum(axis=0).max()
            worst_self = max(worst_self, length / (self_weight[p] @ np.abs(b - a)))
    return worst_environment, worst_self


@pytest.mark.parametrize("robot_name", ["arm3", "panda", "example-robot-data panda"])
def test_travel_bound_holds_for_sampled_points_and_is_not_loose(robot_name):
    # the bound must hold for every point (ratio <= 1) and would not if it were halved (ratio > 0.5)
    if robot_name == "arm3":
        robot = arm3_scene()[0]
    elif robot_name == "panda":
        robot = panda()
    else:
        robots = pytest.importorskip("ompl_balance.collision.robots")
        try:
            robot = robots.load_example_robot_data_panda()
        except ImportError as error:
            pytest.skip(str(error))
    worst_environment, worst_self = travel_ratios(robot, np.random.default_rng(1))
    assert 0.5 < worst_environment <= 1.0 + 1e-9
    assert 0.3 < worst_self <= 1.0 + 1e-9


def test_travel_bound_too_small_certifies_a_colliding_edge(monkeypatch):
    # the certificate rests on the travel bound: scaled by 0.2 it lets colliding edges through
    robot, environment = arm3_scene()[:2]
    oracle = CollisionChecker(robot, environment)
    scaled = lambda robot: tuple(0.2 * w for w in travel_weights(robot))  # noqa: E731
    monkeypatch.setattr(certified, "travel_weights", scaled)
    weak = certified.MotionCertifier(CollisionChecker(robot, environment))
    edges = random_edges(robot, oracle, 200, np.random.default_rng(2), longest=2.5)
    assert any(weak.check(a, b)[0] and dense_first_collision(oracle, a, b) is not None for a, b in edges)


# ---------------------------------------------------------------------------------------- against the oracle


def test_random_edges_arm3_every_obstacle_kind():
    robot, environment = arm3_scene()[:2]
    assert {o.shape.kind for o in environment.obstacles} == {"box", "sphere", "cylinder", "mesh"}
    edges = random_edges(robot, CollisionChecker(robot, environment), 150, np.random.default_rng(3))
    certified_count, free_count = check_edges(robot, environment, edges)
    assert 20 <= free_count <= 130  # both kinds of edge
    assert certified_count >= 0.9 * free_count  # and it does not just reject


@pytest.mark.parametrize("scenario", ["table_pick", "bookshelf_small"])
def test_random_edges_panda(scenario):
    robot, environment = panda_scene(scenario)
    edges = random_edges(robot, CollisionChecker(robot, environment), 60, np.random.default_rng(4), longest=2.5)
    certified_count, free_count = check_edges(robot, environment, edges)
    assert 5 <= free_count <= 55
    assert certified_count >= 0.9 * free_count


@pytest.mark.slow
@pytest.mark.parametrize("scenario", ["arm3", *SCENARIOS])
def test_random_edges_many(scenario):
    robot, environment = arm3_scene()[:2] if scenario == "arm3" else panda_scene(scenario)
    edges = random_edges(robot, CollisionChecker(robot, environment), 2000, np.random.default_rng(5))
    certified_count, free_count = check_edges(robot, environment, edges)
    assert certified_count >= 0.9 * free_count


def grazing_edges(robot, environment, count, rng, longest=0.8):
    """Pairs of edges on either side of the contact boundary: the same edge shifted by ``l d``
    in joint space, ``l`` bisected until the colliding and the free shift differ by 1e-5 rad."""
    oracle = CollisionChecker(robot, environment)
    found = []
    for a, b in random_edges(robot, oracle, 100 * count, rng, longest):
        if len(found) == count:
            break
        if dense_first_collision(oracle, a, b) is None:
            continue
        direction = rng.normal(size=robot.dof)
        direction /= np.linalg.norm(direction)

        def shifted(step, a=a, b=b, direction=direction):
            return np.clip(a + step * direction, robot.lower, robot.upper), np.clip(
                b + step * direction, robot.lower, robot.upper
            )

        free = next((s for s in (0.05, 0.1, 0.2, 0.4) if dense_first_collision(oracle, *shifted(s)) is None), None)
        if free is None:
            continue
        colliding = 0.0
        while free - colliding > 1e-5:
            middle = 0.5 * (colliding + free)
            if dense_first_collision(oracle, *shifted(middle)) is None:
                free = middle
            else:
                colliding = middle
        found.append((shifted(colliding), shifted(free), shifted, free))
    assert len(found) == count
    return found


@pytest.mark.parametrize("scene", ["arm3", "panda"])
def test_grazing_edges(scene):
    # 1e-5 rad apart in joint space: the colliding one is rejected, its lastValid prefix is free
    robot, environment = arm3_scene()[:2] if scene == "arm3" else panda_scene("table_pick")
    pairs = grazing_edges(robot, environment, 4, np.random.default_rng(6), longest=0.5)
    check_edges(robot, environment, [edge for colliding, free, *_ in pairs for edge in (colliding, free)])


@pytest.mark.slow
@pytest.mark.parametrize("scenario", ["arm3", "self-collision", *SCENARIOS])
def test_grazing_edges_many(scenario):
    if scenario == "arm3":
        robot, environment = arm3_scene()[:2]
    elif scenario == "self-collision":
        robot, environment = panda(), Environment()
    else:
        robot, environment = panda_scene(scenario)
    pairs = grazing_edges(robot, environment, 20, np.random.default_rng(15), longest=0.5)
    check_edges(robot, environment, [edge for colliding, free, *_ in pairs for edge in (colliding, free)])


def test_self_collision_edges_panda():
    # no obstacles: every collision is a self-collision, many of them between the forearm
    # and the hand (certified-free tables) or across the elbow
    robot = panda()
    environment = Environment()
    edges = random_edges(robot, CollisionChecker(robot, environment), 40, np.random.default_rng(7), longest=2.0)
    certified_count, free_count = check_edges(robot, environment, edges)
    assert free_count <= 36 and certified_count >= 0.9 * free_count
    pairs = grazing_edges(robot, environment, 2, np.random.default_rng(8), longest=0.5)
    check_edges(robot, environment, [edge for colliding, free, *_ in pairs for edge in (colliding, free)])


def test_prefilter_off_reference_agrees():
    # the reference (FCL distances only, no spheres, hulls or tables) is safe too, and both
    # certify the clearly free edges (the reference without a work budget: FCL on every pair
    # over the whole edge takes far more than a check of the default budget may)
    robot, environment = arm3_scene()[:2]
    reference = certified.MotionCertifier(CollisionChecker(robot, environment, prefilter=False), motion_budget=None)
    fast = certified.MotionCertifier(CollisionChecker(robot, environment))
    edges = random_edges(robot, CollisionChecker(robot, environment), 25, np.random.default_rng(9), longest=0.6)
    check_edges(robot, environment, edges, reference)
    agree = sum(reference.check(a, b)[0] == fast.check(a, b)[0] for a, b in edges)
    assert agree >= 23


def test_example_robot_data_panda():
    # 8 joints, a prismatic finger joint and its mimic, STL meshes
    robots = pytest.importorskip("ompl_balance.collision.robots")
    try:
        robot = robots.load_example_robot_data_panda()
    except ImportError as error:
        pytest.skip(str(error))
    environment = load_mbm("table_pick", panda().joint_names)[0].environment
    edges = random_edges(robot, CollisionChecker(robot, environment), 40, np.random.default_rng(10), longest=2.0)
    certified_count, free_count = check_edges(robot, environment, edges)
    assert 5 <= free_count <= 35 and certified_count >= 0.9 * free_count


def test_non_convex_meshes_are_finished_with_fcl(monkeypatch):
    # a ring around the arm's column (not convex: its hull fills the hole) and the Panda's
    # link6 (not convex either): their pairs near contact go to FCL's exact distance
    import trimesh

    robot, environment = arm3_scene()[:2]
    environment.add_mesh("ring", trimesh.creation.annulus(0.25, 0.32, 0.06), [0.0, 0.0, 0.45])
    assert not environment.obstacles[-1].shape.convex
    calls = []
    exact = CollisionChecker.pair_distance
    monkeypatch.setattr(CollisionChecker, "pair_distance", lambda *a: calls.append(1) or exact(*a))
    edges = random_edges(robot, CollisionChecker(robot, environment), 40, np.random.default_rng(13), longest=0.8)
    certified_count, free_count = check_edges(robot, environment, edges)
    assert 8 <= free_count <= 34 and certified_count >= 0.9 * free_count and calls
    pairs = grazing_edges(robot, environment, 2, np.random.default_rng(14), longest=0.5)
    check_edges(robot, environment, [edge for colliding, free, *_ in pairs for edge in (colliding, free)])


def test_touching_non_convex_parts_are_tested_with_fcl_first(monkeypatch):
    """Where the hull of the Panda's non-convex link touches an obstacle, the kernel asks FCL about
    that stretch before certifying the rest of the edge: an edge FCL finds in contact there is
    refused after a few configurations (not after the whole edge's bisection), and every verdict
    agrees with the dense re-check. Edges as RRT-Connect extends them: from the problem's start
    and goals, up to 2.5 rad towards uniform samples."""
    robot = panda()
    problem = load_mbm("box", robot.joint_names)[0]
    assert not all(geometry.shape.convex for geometry in robot.geometries)
    outcomes = []
    touch = certified.MotionCertifier.hard_segments_touch
    monkeypatch.setattr(
        certified.MotionCertifier,
        "hard_segments_touch",
        lambda self, *arguments: outcomes.append(touch(self, *arguments)) or outcomes[-1],
    )
    oracle, checker = CollisionChecker(robot, problem.environment), CollisionChecker(robot, problem.environment)
    certifier = certified.MotionCertifier(checker)
    rng = np.random.default_rng(7)
    refused_at_probe = 0
    for a in [problem.start, *problem.goals] * 100:
        toward = rng.uniform(robot.lower, robot.upper) - a
        b = a + toward * min(1.0, 2.5 / np.linalg.norm(toward))
        probes, states = len(outcomes), checker.counters()["states_checked"]
        valid, _ = certifier.check(a, b)
        first = dense_first_collision(oracle, a, b)
        assert not (valid and first is not None), f"edge certified free collides at t = {first}: {a} -> {b}"
        if len(outcomes) > probes and outcomes[-1]:
            assert not valid and first is not None  # FCL's contact is the re-check's
            assert checker.counters()["states_checked"] - states < 60
            refused_at_probe += 1
    assert refused_at_probe >= 3


def test_hard_segments_staged_in_parts_get_the_same_answers(monkeypatch):
    """Edges whose hard segments outnumber what the certifier's exit stages at once send them to
    FCL in parts: a certifier staging one segment at a time answers every edge as one with the
    usual room, with the same work counted, and such edges are met. Edges as RRT-Connect extends
    them in the Panda's box problem (its non-convex link touches the obstacles' hulls)."""
    robot = panda()
    problem = load_mbm("box", robot.joint_names)[0]
    usual = certified.MotionCertifier(CollisionChecker(robot, problem.environment))
    exits = certified.segment_exits
    monkeypatch.setattr(certified, "segment_exits", lambda certifier, dof, rows: exits(certifier, dof, 1))
    one_at_a_time = certified.MotionCertifier(CollisionChecker(robot, problem.environment))
    kinds = []
    answer = certified.MotionCertifier.answer
    monkeypatch.setattr(
        certified.MotionCertifier, "answer", lambda self, kind, count: kinds.append(kind) or answer(self, kind, count)
    )
    rng = np.random.default_rng(11)
    for a in [problem.start, *problem.goals] * 40:
        toward = rng.uniform(robot.lower, robot.upper) - a
        b = a + toward * min(1.0, 2.5 / np.linalg.norm(toward))
        assert one_at_a_time.check(a, b) == usual.check(a, b)
    assert one_at_a_time.checker.counters() == usual.checker.counters()
    assert kinds.count(certified.Exit.STAGE_SEGMENTS) >= 3


def test_an_error_in_fcl_on_hard_segments_reaches_the_caller(monkeypatch):
    """FCL raising on the hard segments the kernel sends to the certifier: ``check`` raises that
    error; once FCL answers again, the certifier answers every edge as a fresh one does."""
    robot = panda()
    problem = load_mbm("box", robot.joint_names)[0]
    certifier = certified.MotionCertifier(CollisionChecker(robot, problem.environment))
    rng = np.random.default_rng(12)
    edges = []
    for a in [problem.start, *problem.goals] * 10:
        toward = rng.uniform(robot.lower, robot.upper) - a
        edges.append((a, a + toward * min(1.0, 2.5 / np.linalg.norm(toward))))
    raised = 0
    with monkeypatch.context() as patched:
        for name in ("pair_touching", "pair_distance"):
            patched.setattr(certifier.checker, name, failing_fcl)
        for a, b in edges:
            try:
                certifier.check(a, b)
            except FCLError:
                raised += 1
    assert raised >= 3
    fresh = certified.MotionCertifier(CollisionChecker(robot, problem.environment))
    assert [certifier.check(a, b) for a, b in edges] == [fresh.check(a, b) for a, b in edges]


def test_probe_order_visits_every_segment_coarse_to_fine():
    """Segments are probed once each; the first 2**j - 1 probed leave no run of more than about
    n / 2**j consecutive segments (along the motion) unprobed."""
    from ompl_balance.collision.bisection import probe_order

    rng = np.random.default_rng(3)
    for n in [0, 1, 2, 3, 5, 8, 13, 100, 147]:
        middles = rng.random(n)
        order = probe_order(middles)
        assert sorted(order.tolist()) == list(range(n))
        ranks = np.argsort(np.argsort(middles))[order]  # the probed segments' places along the motion
        for j in range(1, max(n, 1).bit_length() + 1):
            probed = np.sort(ranks[: 2**j - 1])
            gaps = np.diff(np.concatenate(([-1], probed, [n])))
            assert gaps.max() - 1 <= int(np.ceil(n / 2**j)), (n, j, probed)


def test_contacts_at_middles_are_looked_for_in_probe_order_up_to_the_first():
    """The midpoints are tested in :func:`probe_order`'s order and the search stops at the first
    contact; without one every midpoint is tested once."""
    from ompl_balance.collision.bisection import contact_at_middles, probe_order

    middles = np.random.default_rng(5).random(21)
    order = probe_order(middles).tolist()
    for contact in (order[0], order[7], order[-1], None):
        tested: list[tuple[int, float]] = []

        def touching(i: int, t: float) -> bool:
            tested.append((i, t))
            return i == contact

        assert contact_at_middles(middles, touching) == (contact is not None)
        stop = len(order) if contact is None else order.index(contact) + 1
        assert tested == [(i, float(middles[i])) for i in order[:stop]]
    assert not contact_at_middles(np.empty(0), touching)


# ---------------------------------------------------------------------------------------- work, clearance, input


def test_far_edges_need_few_bounds():
    # a short edge far from everything: the two ends, no distance query, fewer states than OMPL's resolution
    robot, _ = arm3_scene()[:2]
    environment = Environment()
    environment.add_box("far", [0.1, 0.1, 0.1], [5.0, 0.0, 0.0])
    checker = CollisionChecker(robot, environment)
    certifier = certified.MotionCertifier(checker)
    a, b = np.array([0.0, 0.0, 0.1]), np.array([0.3, 0.2, 0.15])
    assert certifier.check(a, b) == (True, 1.0)
    counts = checker.counters()
    assert counts["motions_checked"] == 1 and counts["distance_queries"] <= 2 and counts["states_checked"] <= 3
    space = space_for(robot)
    space.setup()
    s1, s2 = space.allocState(), space.allocState()
    space.copyFromReals(s1, list(a))
    space.copyFromReals(s2, list(b))
    assert counts["states_checked"] < space.validSegmentCount(s1, s2)


def fcl_clearance(robot, environment, q):
    """Smallest FCL distance between the collision pairs at each configuration of ``q`` (independent of the package)."""
    links = [fcl.CollisionObject(g.shape.fcl_geometry()) for g in robot.geometries]
    obstacles = [
        fcl.CollisionObject(o.shape.fcl_geometry(), fcl.Transform(o.pose[:3, :3], o.pose[:3, 3]))
        for o in environment.obstacles
    ]
    smallest = []
    for poses in robot.body_poses(q):
        for link, g in zip(links, robot.geometries):
            pose = poses[g.body] @ g.origin
            link.setTransform(fcl.Transform(pose[:3, :3], pose[:3, 3]))
        pairs = [(link, o) for link in links for o in obstacles] + [
            (links[i], links[j]) for i, j in robot.self_collision_pairs
        ]
        smallest.append(min(fcl.distance(x, y, fcl.DistanceRequest(), fcl.DistanceResult()) for x, y in pairs))
    return np.array(smallest)


def test_clearance_is_kept():
    robot, environment = arm3_scene()[:2]
    clearance = 0.04
    keeping = certified.MotionCertifier(CollisionChecker(robot, environment), clearance=clearance)
    edges = random_edges(robot, CollisionChecker(robot, environment), 30, np.random.default_rng(11), longest=0.6)
    kept = 0
    for a, b in edges:
        if keeping.check(a, b)[0]:
            kept += 1
            assert fcl_clearance(robot, environment, a + np.linspace(0, 1, 41)[:, None] * (b - a)).min() > clearance
    assert kept >= 5
    # free edges that pass a few millimetres from contact: certified without clearance, never with
    touching = certified.MotionCertifier(CollisionChecker(robot, environment))
    near = [
        shifted(free + 0.01)
        for _c, _f, shifted, free in grazing_edges(robot, environment, 4, np.random.default_rng(12))
    ]
    for a, b in near:
        distances = fcl_clearance(robot, environment, a + np.linspace(0, 1, 41)[:, None] * (b - a))
        assert not keeping.check(a, b)[0] or distances.min() > clearance
    assert sum(touching.check(a, b)[0] and not keeping.check(a, b)[0] for a, b in near) >= 2
    with pytest.raises(ValueError, match="clearance"):
        certified.MotionCertifier(CollisionChecker(robot, environment), clearance=-0.1)


def test_bad_input_is_invalid_not_an_exception():
    robot, environment = arm3_scene()[:2]
    checker = CollisionChecker(robot, environment)
    ss = og.SimpleSetup(space_for(robot))
    _validity, validator = setup_robot(ss, checker)
    assert isinstance(validator, CertifiedMotionValidator)
    si = ss.getSpaceInformation()
    si.setup()
    good, bad, last = si.allocState(), si.allocState(), si.allocState()
    for i, value in enumerate([0.0, 0.0, 0.1]):
        good[i], bad[i] = value, value
    bad[1] = float("nan")
    assert not si.checkMotion(good, bad) and not si.checkMotion(bad, good)
    assert validator.check_motion_last_valid(good, bad, last) == (False, 0.0)
    assert [last[i] for i in range(3)] == [0.0, 0.0, 0.1]  # s1: nothing of the edge is certified
    bad[1] = float("inf")
    assert validator.check_motion_last_valid(good, bad, last) == (False, 0.0)
    assert [last[i] for i in range(3)] == [0.0, 0.0, 0.1]
    bad[1] = 0.0
    bad[2] = 0.5  # the slide's range is [0, 0.2]
    assert not si.checkMotion(good, bad)
    assert checker.counters()["motions_checked"] == 5


def test_setup_robot_motion_names():
    robot, environment = arm3_scene()[:2]
    checker = CollisionChecker(robot, environment)
    for motion, kind in (("certified", CertifiedMotionValidator), ("discrete", MotionValidator)):
        ss = og.SimpleSetup(space_for(robot))
        assert isinstance(setup_robot(ss, checker, motion=motion)[1], kind)
    with pytest.raises(ValueError, match=r"'certified', 'discrete'.*'exact'"):
        setup_robot(og.SimpleSetup(space_for(robot)), checker, motion="exact")
    with pytest.raises(ValueError, match="clearance"):
        setup_robot(og.SimpleSetup(space_for(robot)), checker, motion="discrete", clearance=0.01)
    assert setup_robot(og.SimpleSetup(space_for(robot)), checker, clearance=0.02)[1].clearance == 0.02
    assert ompl_balance.CertifiedMotionValidator is CertifiedMotionValidator
    assert ompl_balance.certify_path is certify_path


def test_certify_path_arrays_and_ompl_paths():
    robot, environment = arm3_scene()[:2]
    checker = CollisionChecker(robot, environment)
    oracle = CollisionChecker(robot, environment)
    rng = np.random.default_rng(12)
    edges = random_edges(robot, oracle, 200, rng, longest=1.5)
    free = [e for e in edges if dense_first_collision(oracle, *e) is None]
    colliding = [e for e in edges if dense_first_collision(oracle, *e) is not None and oracle.is_valid(e[1])]
    good = np.array([free[0][0], free[0][1]])
    certificate = certify_path(checker, good)
    assert certificate.certified and certificate.segments == 1 and certificate.first_bad_segment is None
    assert certificate.smallest_clearance == pytest.approx(fcl_clearance(robot, environment, good).min(), abs=1e-4)
    a, b = colliding[0]
    path = np.array([free[0][0], free[0][1], a, b])  # segment 1 jumps, segment 2 collides at least
    first = dense_first_collision(oracle, a, b)
    ompl_path = og.PathGeometric(ob.SpaceInformation(space_for(robot)))
    space = space_for(robot)
    si = ob.SpaceInformation(space)
    ompl_path = og.PathGeometric(si)
    for q in path:
        state = si.allocState()
        for i, value in enumerate(q):
            state[i] = float(value)
        ompl_path.append(state)
    for given in (path, ompl_path):
        certificate = certify_path(checker, given)
        assert not certificate.certified and certificate.first_bad_segment in (1, 2)
        if certificate.first_bad_segment == 2:
            assert certificate.certified_fraction < first
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        certify_path(checker, np.zeros((2, 4)))
    with pytest.raises(ValueError, match="non-finite"):
        certify_path(checker, [[0.0, np.nan, 0.1], [0.0, 0.0, 0.1]])


def test_warm_up_compiles_the_kernels_real_certifiers_use():
    from ompl_balance.collision import kernels

    kernels.warm_up()
    warmed = set(kernels.certified_motion_free.signatures)
    robot, environment = arm3_scene()[:2]
    certifier = certified.MotionCertifier(CollisionChecker(robot, environment))
    certifier.check(np.zeros(3), np.full(3, 0.1))
    certifier.check(np.zeros(3), np.full(3, 0.1), last_valid=True)
    assert set(kernels.certified_motion_free.signatures) == warmed  # nothing compiled for the real robot


# ---------------------------------------------------------------------------------------- planning


def plan_and_recheck(scenario, index, planner_class, simplify=True):
    robot = panda()
    problem = load_mbm(scenario, robot.joint_names)[index]
    checker = CollisionChecker(robot, problem.environment)
    ss = problem.simple_setup(robot, checker)  # the default: certified motions
    assert isinstance(ss.getSpaceInformation().getMotionValidator(), CertifiedMotionValidator)
    ss.setPlanner(planner_class(ss.getSpaceInformation()))
    assert ss.solve(10.0) and ss.haveExactSolutionPath()
    oracle = CollisionChecker(robot, problem.environment)
    paths = [ss.getSolutionPath()]
    if simplify:
        ss.simplifySolution()  # PathSimplifier goes through the same motion validator
        paths.append(ss.getSolutionPath())
    for path in paths:
        states = np.array([path.getState(i)[0 : robot.dof] for i in range(path.getStateCount())])
        # without a work budget: a fresh certificate remembers no bounds from the planner's edges,
        # so near the budget it may need more work for a segment than the validator did
        assert certify_path(checker, states, motion_budget=None).certified
        for a, b in itertools.pairwise(states):
            assert dense_first_collision(oracle, a, b) is None
    return ss


@pytest.mark.parametrize("scenario", SCENARIOS)
@pytest.mark.parametrize("planner_class", [og.RRTConnect, BalancedRRTConnect], ids=["RRTConnect", "Balanced"])
def test_planned_paths_pass_the_dense_recheck(scenario, planner_class):
    for index in (0, 1):
        plan_and_recheck(scenario, index, planner_class)


@pytest.mark.slow
@pytest.mark.parametrize("scenario", SCENARIOS)
@pytest.mark.parametrize("planner_class", [og.RRTConnect, BalancedRRTConnect], ids=["RRTConnect", "Balanced"])
def test_planned_paths_pass_the_dense_recheck_many(scenario, planner_class):
    for index in range(2, 12):
        plan_and_recheck(scenario, index, planner_class)


def test_run_stats_count_distance_queries():
    robot = panda()
    problem = load_mbm("box", robot.joint_names)[2]
    ss = problem.simple_setup(robot)
    ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
    ss.setup()
    before = read_work(ss.getSpaceInformation())
    assert ss.solve(10.0)
    stats, work = ss.getPlanner().stats, read_work(ss.getSpaceInformation()) - before
    assert stats.distance_queries == work.distance_queries > 0
    assert stats.motions_checked == work.motions_checked and stats.states_checked == work.states_checked
