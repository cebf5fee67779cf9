"""Rigid bodies: OMPL's interpolation, the checker against a brute-force triangle test, certified
motions against a dense exact check with rotation sub-steps, the compiled view, bad input.

Oracles (``rigid_oracles``): a numpy separating-axis test of every triangle pair (no FCL), and
FCL's collision test at poses along OMPL's interpolation so dense that no point of the body moves
more than ``STEP`` between two; neither shares the screening, the bounds or the advancement.
"""

import itertools
import math

import fcl
import numpy as np
import pytest
import trimesh
from numba import njit
from ompl import base as ob
from rigid_oracles import DenseCheck, box_triangles, inside_box, place, triangles_separation
from scipy.spatial.transform import Rotation
from test_validity import FCLError, failing_fcl

from ompl_balance import BalancedRRTConnect
from ompl_balance.collision.environment import Environment
from ompl_balance.collision.geometry import Shape
from ompl_balance.collision.rigid.advance import edge_status
from ompl_balance.collision.rigid.body import RigidBody
from ompl_balance.collision.rigid.checker import RigidBodyChecker
from ompl_balance.collision.rigid.kernels import RigidCertifiedMotions, rigid_certified_motion_free
from ompl_balance.collision.rigid.motion import interpolate, motion_split, state_pose
from ompl_balance.collision.rigid.view import COLLIDING, FREE, UNDECIDED, state_status
from ompl_balance.validity import certify_path, rigid_body_space, rigid_state_values, set_rigid_state
from ompl_balance.worlds.rigid import rigid_problem

STEP = 1e-3  # the dense check's resolution: largest move of any point between two checked poses


def random_states(space, count, rng, low, high):
    positions = rng.uniform(low, high, size=(count, len(low)))
    if space == "SE2":
        return np.hstack([positions, rng.uniform(-math.pi, math.pi, size=(count, 1))])
    return np.hstack([positions, Rotation.random(count, random_state=int(rng.integers(1 << 30))).as_quat()])


def l_mesh():
    """A non-convex L of two boxes as one triangle soup (24 triangles)."""
    a = trimesh.creation.box(extents=(0.6, 0.1, 0.1))
    b = trimesh.creation.box(extents=(0.1, 0.4, 0.1))
    b.apply_translation((0.25, 0.15, 0.0))
    return np.concatenate([a.triangles, b.triangles])


def mesh_world(rng, count=10):
    """``count`` random tetrahedra (triangle soups, not closed as one) and the world's triangles."""
    environment, triangles = Environment(), []
    for i in range(count):
        corners = rng.uniform(-0.4, 0.4, size=(4, 3)) + rng.uniform(-0.8, 0.8, size=3)
        faces = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
        tetrahedron = trimesh.Trimesh(corners, faces, process=False)
        environment.add_mesh(f"tet{i}", tetrahedron)
        triangles.append(tetrahedron.triangles)
    return environment, np.concatenate(triangles)


# -- OMPL's interpolation --------------------------------------------------------------------


@pytest.mark.parametrize("space_name", ["SE2", "SE3"])
def test_interpolation_is_ompls(space_name):
    """interpolate matches OMPL's own space.interpolate, including turns the long way round."""
    rng = np.random.default_rng(1)
    space = rigid_body_space(
        space_name, [-2.0] * (2 if space_name == "SE2" else 3), [2.0] * (2 if space_name == "SE2" else 3)
    )
    a_state, b_state, out = space.allocState(), space.allocState(), space.allocState()
    states = random_states(
        space_name,
        200,
        rng,
        np.full(3, -2.0)[: 2 if space_name == "SE2" else 3],
        np.full(3, 2.0)[: 2 if space_name == "SE2" else 3],
    )
    ours = np.empty(states.shape[1])
    for a, b in zip(states[::2], states[1::2]):
        set_rigid_state(a_state, a)
        set_rigid_state(b_state, b)
        for t in (0.0, 0.3, 0.5, 0.97, 1.0):
            space.interpolate(a_state, b_state, t, out)
            interpolate(a, b, t, ours)
            np.testing.assert_allclose(ours, rigid_state_values(out, len(a)), atol=1e-12)


def test_rotation_angle_and_the_jump_case():
    rng = np.random.default_rng(2)
    states = random_states("SE3", 100, rng, np.zeros(3), np.ones(3))
    for a, b in zip(states[::2], states[1::2]):
        translation, angle, jump = motion_split(a, b)
        relative = Rotation.from_quat(a[3:]).inv() * Rotation.from_quat(b[3:])
        assert math.isclose(angle, relative.magnitude(), abs_tol=1e-9)
        assert math.isclose(translation, float(np.linalg.norm(b[:3] - a[:3])), rel_tol=1e-12)
        assert not jump
    a = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    b = a.copy()
    b[3:] = Rotation.from_rotvec([3e-5, 0.0, 0.0]).as_quat()  # |q_a . q_b| > 1 - 1e-9
    translation, angle, jump = motion_split(a, b)
    assert jump and math.isclose(angle, 3e-5, rel_tol=1e-6)
    out = np.empty(7)
    interpolate(a, b, 0.0, out)
    np.testing.assert_array_equal(out[3:], b[3:])  # OMPL's interpolation is in b's orientation at once
    assert motion_split(np.array([0.0, 0.0, 3.0]), np.array([0.0, 0.0, -3.0]))[1] == pytest.approx(2 * math.pi - 6.0)


@pytest.mark.parametrize("space", ["SE2", "SE3"])
def test_no_point_travels_farther_than_translation_plus_reach_times_angle(space):
    """Sampled along the interpolation, every vertex's path stays within the travel bound."""
    body = RigidBody.from_triangles(space, l_mesh(), pieces=3)
    vertices = np.unique(np.concatenate([p.shape.mesh.vertices for p in body.parts]), axis=0)
    rng = np.random.default_rng(3)
    states = random_states(
        space, 60, rng, np.full(3, -1.0)[: 2 if space == "SE2" else 3], np.full(3, 1.0)[: 2 if space == "SE2" else 3]
    )
    state, pose = np.empty(states.shape[1]), np.empty((4, 4))
    for a, b in zip(states[::2], states[1::2]):
        translation, angle, _ = motion_split(a, b)
        bound = translation + body.reach * angle
        points = []
        for t in np.linspace(0.0, 1.0, 201):
            interpolate(a, b, t, state)
            state_pose(state, pose)
            points.append(vertices @ pose[:3, :3].T + pose[:3, 3])
        travelled = np.linalg.norm(np.diff(np.array(points), axis=0), axis=2).sum(axis=0)
        assert travelled.max() <= bound * (1 + 1e-9) + 1e-12


# -- states against the brute-force triangle test -------------------------------------------


def test_checker_agrees_with_brute_force_triangles_mesh_world():
    """A non-convex mesh body among tetrahedra: FCL's answer is the triangles' (SAT oracle)."""
    rng = np.random.default_rng(4)
    environment, world = mesh_world(rng)
    triangles = l_mesh()
    body = RigidBody.from_triangles("SE3", triangles, pieces=4)
    checkers = [RigidBodyChecker(body, environment), RigidBodyChecker(body, environment, prefilter=False)]
    states = random_states("SE3", 400, rng, np.full(3, -1.0), np.full(3, 1.0))
    expected, kept = [], []
    for state in states:
        separation = triangles_separation(place(triangles, state), world)
        if abs(separation) > 1e-9:  # not within rounding of touching
            expected.append(separation > 0)
            kept.append(state)
    expected, kept = np.array(expected), np.array(kept)
    assert expected.sum() >= 50 and (~expected).sum() >= 50
    for checker in checkers:
        np.testing.assert_array_equal(checker.check(kept), expected)
        np.testing.assert_array_equal([checker.is_valid(s) for s in kept[:100]], expected[:100])


@pytest.mark.parametrize("space", ["SE2", "SE3"])
def test_checker_agrees_with_brute_force_solid_boxes(space):
    """Convex mesh parts among FCL boxes (solids): contact iff a triangle meets a box's surface or
    lies inside it (SAT on the box's triangles, and corner containment)."""
    parts = [trimesh.creation.box(extents=(0.5, 0.08, 0.1)), trimesh.creation.box(extents=(0.08, 0.3, 0.1))]
    parts[1].apply_translation((0.21, 0.19, 0.0))
    body = RigidBody.from_meshes(space, parts)
    environment = Environment()
    boxes = [
        ((0.3, 0.05, 0.4), (0.0, 0.3, 0.0), (0.0, 0.0, 0.2, 0.98)),
        ((0.1, 0.5, 0.4), (0.6, -0.2, 0.0), (0, 0, 0, 1)),
    ]
    for i, (half, position, quaternion) in enumerate(boxes):
        norm = np.linalg.norm(quaternion)
        environment.add_box(f"box{i}", half, position, np.array(quaternion) / norm)
    triangles = np.concatenate([p.triangles for p in parts])
    rng = np.random.default_rng(5)
    states = random_states(
        space, 600, rng, np.full(3, -1.0)[: 2 if space == "SE2" else 3], np.full(3, 1.0)[: 2 if space == "SE2" else 3]
    )
    expected, kept = [], []
    for state in states:
        placed = place(triangles, state)
        contact, margin = False, math.inf
        for obstacle in environment.obstacles:
            half = np.asarray(obstacle.shape.dims)
            separation = triangles_separation(placed, box_triangles(half, obstacle.pose))
            margin = min(margin, abs(separation))
            contact |= separation <= 0 or bool(inside_box(placed.reshape(-1, 3), half, obstacle.pose).any())
        if margin > 1e-9:
            expected.append(not contact)
            kept.append(state)
    expected, kept = np.array(expected), np.array(kept)
    assert expected.sum() >= 50 and (~expected).sum() >= 50
    checker = RigidBodyChecker(body, environment)
    np.testing.assert_array_equal(checker.check(kept), expected)
    np.testing.assert_array_equal([checker.is_valid(s) for s in kept], expected)
    np.testing.assert_array_equal(RigidBodyChecker(body, environment, prefilter=False).check(kept), expected)


def test_bounds_and_invalid_states():
    body = RigidBody.from_triangles("SE3", l_mesh(), pieces=1)
    checker = RigidBodyChecker(body, bounds=([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]))
    assert checker.is_valid([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    assert not checker.is_valid([1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])  # outside: invalid, as OMPL.app has it
    assert not checker.is_valid([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.1])  # not a unit quaternion
    assert not checker.is_valid([math.nan, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    assert not checker.certify([0.0] * 6 + [1.0], [2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])[0]
    with pytest.raises(ValueError, match="7 values"):
        checker.is_valid([0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"shape \(n, 7\)"):
        checker.check(np.zeros((3, 6)))
    with pytest.raises(ValueError, match="position bounds"):
        RigidBodyChecker(body, bounds=([0.0, 0.0], [1.0, 1.0]))
    with pytest.raises(ValueError, match="low > high"):
        RigidBodyChecker(body, bounds=([1.0, 0.0, 0.0], [0.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match="clearance"):
        RigidBodyChecker(body, clearance=-1.0)
    with pytest.raises(ValueError, match="space must be"):
        RigidBody("SE4", [("a", Shape.sphere(1.0), None)])
    with pytest.raises(ValueError, match="no parts"):
        RigidBody("SE3", [])
    with pytest.raises(ValueError, match="quaternion of norm"):
        body.as_states([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0]])


# -- certified motions against the dense check ----------------------------------------------


def certified_edges_against_dense(checker, dense, edges):
    """Every certified edge is free under the dense check; a last_valid fraction has a free
    prefix ending at or before the first collision. Returns (certified, dense-free) counts."""
    certified = free = 0
    for a, b in edges:
        first = dense.first_collision(a, b)
        ok, fraction = checker.certify(a, b)
        if ok:
            assert first is None, f"certified an edge colliding at t={first}: {a} -> {b}"
            certified += 1
        free += first is None
        ok, fraction = checker.certify(a, b, last_valid=True)
        if ok:
            assert first is None and fraction == 1.0
        else:
            assert 0.0 <= fraction < 1.0
            if fraction > 0.0:
                assert dense.first_collision(a, b, until=fraction) is None
    return certified, free


def short_edges(space, count, rng, low, high, longest):
    a = random_states(space, count, rng, low, high)
    b = random_states(space, count, rng, low, high)
    t = rng.uniform(0.02, longest, size=(count, 1))
    if space == "SE3":
        ends = np.empty_like(a)
        for i in range(count):
            interpolate(a[i], b[i], float(t[i, 0]), ends[i])
        ends[:, 3:] /= np.linalg.norm(ends[:, 3:], axis=1, keepdims=True)
    else:
        ends = a + t * (b - a)
        ends[:, 2] = (ends[:, 2] + math.pi) % (2 * math.pi) - math.pi
    return list(zip(a, ends))


@pytest.mark.parametrize("space", ["SE2", "SE3"])
def test_certified_edges_are_free_convex_parts_among_boxes(space):
    """GJK decides every pair (convex parts, FCL boxes): no FCL distance needed."""
    parts = [trimesh.creation.box(extents=(0.5, 0.08, 0.1)), trimesh.creation.box(extents=(0.08, 0.3, 0.1))]
    parts[1].apply_translation((0.21, 0.19, 0.0))
    body = RigidBody.from_meshes(space, parts)
    environment = Environment()
    environment.add_box("wall", (0.05, 0.8, 0.5), (0.0, 0.0, 0.0))
    environment.add_box("post", (0.1, 0.1, 0.5), (0.6, 0.5, 0.0), (0.0, 0.0, 0.38268343, 0.92387953))
    environment.add_sphere("ball", 0.15, (-0.6, -0.5, 0.0))
    axes = 2 if space == "SE2" else 3
    low, high = np.full(axes, -1.0), np.full(axes, 1.0)
    checker = RigidBodyChecker(body, environment, (low, high))
    dense = DenseCheck(body, environment, STEP)
    edges = short_edges(space, 60, np.random.default_rng(6), low, high, 0.5)
    edges = [(a, b) for a, b in edges if checker.is_valid(a)]
    certified, free = certified_edges_against_dense(checker, dense, edges)
    assert free >= 10 and certified >= 0.8 * free  # the proof is not vacuous
    assert checker.counters()["motions_checked"] == 2 * len(edges)


@pytest.mark.parametrize("with_box", [False, True], ids=["meshes", "meshes and a box"])
def test_certified_edges_are_free_non_convex_meshes(with_box):
    """A non-convex body among tetrahedra: hull bounds, then FCL's exact distances finish (the
    whole body against the whole world when both are meshes, pair by pair with a box among them)."""
    rng = np.random.default_rng(7)
    environment, _ = mesh_world(rng)
    if with_box:
        environment.add_box("box", (0.3, 0.1, 0.3), (0.2, -0.3, 0.1))
    body = RigidBody.from_triangles("SE3", l_mesh(), pieces=2)
    low, high = np.full(3, -1.2), np.full(3, 1.2)
    checker = RigidBodyChecker(body, environment, (low, high))
    dense = DenseCheck(body, environment, STEP)
    edges = [(a, b) for a, b in short_edges("SE3", 40, rng, low, high, 0.4) if checker.is_valid(a)]
    certified, free = certified_edges_against_dense(checker, dense, edges)
    assert free >= 8 and certified >= 0.7 * free
    reference = RigidBodyChecker(body, environment, (low, high), prefilter=False)
    for a, b in edges[:10]:
        if reference.certify(a, b)[0]:
            assert dense.first_collision(a, b) is None


@njit
def _certified_in_compiled_code(view, a, b):  # pragma: no cover (compiled)
    return rigid_certified_motion_free(view, a, b)


def test_probing_a_motion_changes_no_answer_and_refuses_colliding_motions_without_fcl_distances():
    """Body and world all meshes: certified motions are probed at a few states first. The
    answers are those of the same checker without the probe (from Python and from compiled
    code), certified motions are free under the dense check, and the probe spares FCL's
    distances on the colliding motions it catches."""
    rng = np.random.default_rng(12)
    environment, _ = mesh_world(rng, count=16)
    body = RigidBody.from_triangles("SE3", l_mesh(), pieces=2)
    low, high = np.full(3, -1.2), np.full(3, 1.2)
    probed = RigidBodyChecker(body, environment, (low, high))
    unprobed = RigidBodyChecker(body, environment, (low, high))
    unprobed.view = unprobed.view._replace(probe=False)  # (the same checker, the probe switched off)
    assert probed.view.probe
    dense = DenseCheck(body, environment, STEP)
    edges = [
        (a, b) for a, b in short_edges("SE3", 60, rng, low, high, 0.9) if probed.is_valid(a) and probed.is_valid(b)
    ]
    compiled = RigidBodyChecker(body, environment, (low, high))  # (held: its exit is held weakly)
    view = compiled.kernel_view()
    assert view is not None
    motions = RigidCertifiedMotions(view, view.counts)
    answers = []
    for a, b in edges:
        answer = probed.certify(a, b)
        assert answer == unprobed.certify(a, b)
        assert _certified_in_compiled_code(motions, a, b) == answer[0]
        if answer[0]:
            assert dense.first_collision(a, b) is None
        answers.append(answer[0])
    assert 5 <= sum(answers) <= len(answers) - 10  # both kinds of motion were met
    assert probed.counters()["distance_queries"] < 0.5 * unprobed.counters()["distance_queries"]
    for work in ("motions_checked", "distance_queries"):  # compiled code probes and counts alike
        assert compiled.counters()[work] == probed.counters()[work]


def test_distances_at_motions_ends_are_kept_and_change_no_answer(monkeypatch):
    """Motions that share their ends, as a planner's do (a path walked forth and back): the
    checker keeps FCL's exact distances at the ends, so it asks FCL less often than checkers
    that see each motion afresh, and answers every motion as they do (and certified motions are
    free under the dense check). Without a work budget: a distance kept costs a motion nothing,
    so near its budget a motion's answer may depend on those met before."""
    rng = np.random.default_rng(5)
    environment, _ = mesh_world(rng, count=16)
    body = RigidBody.from_triangles("SE3", l_mesh(), pieces=2)
    low, high = np.full(3, -1.2), np.full(3, 1.2)
    calls = [0]
    fcl_distance = fcl.distance

    def counted(*arguments):
        calls[0] += 1
        return fcl_distance(*arguments)

    monkeypatch.setattr(fcl, "distance", counted)
    keeping = RigidBodyChecker(body, environment, (low, high), motion_budget=None)
    walk = [next(s for s in random_states("SE3", 100, rng, low, high) if keeping.is_valid(s))]
    for target in random_states("SE3", 200, rng, low, high):  # short steps, as a planner's range
        step = np.empty(7)
        interpolate(walk[-1], target, 0.1, step)
        step[3:] /= np.linalg.norm(step[3:])
        if keeping.is_valid(step):
            walk.append(step)
    motions = list(itertools.pairwise(walk))
    motions += [(b, a) for a, b in motions]  # every end met again
    calls[0] = 0
    kept = [keeping.certify(a, b, last_valid=True) for a, b in motions]
    with_memory, calls[0] = calls[0], 0
    afresh = [
        RigidBodyChecker(body, environment, (low, high), motion_budget=None).certify(a, b, last_valid=True)
        for a, b in motions
    ]
    assert kept == afresh
    assert 0 < with_memory < 0.9 * calls[0]
    dense = DenseCheck(body, environment, STEP)
    for (a, b), (certified, _) in zip(motions, kept):
        if certified:
            assert dense.first_collision(a, b) is None


def test_clearance_keeps_motions_away():
    body = RigidBody.from_meshes("SE3", [trimesh.creation.box(extents=(0.2, 0.2, 0.2))])
    environment = Environment()
    environment.add_box("wall", (0.05, 1.0, 1.0), (0.0, 0.0, 0.0))
    identity = [0.0, 0.0, 0.0, 1.0]
    a, b = np.array([-0.5, -0.5, 0.0, *identity]), np.array([-0.5, 0.5, 0.0, *identity])  # 0.35 from the wall
    assert RigidBodyChecker(body, environment, clearance=0.3).certify(a, b)[0]
    assert not RigidBodyChecker(body, environment, clearance=0.4).certify(a, b)[0]


def test_grazing_and_touching_edges_terminate_and_are_refused():
    body = RigidBody.from_meshes("SE3", [trimesh.creation.box(extents=(0.2, 0.2, 0.2))])
    environment = Environment()
    environment.add_box("wall", (0.05, 1.0, 1.0), (0.0, 0.0, 0.0))
    checker = RigidBodyChecker(body, environment)
    identity = [0.0, 0.0, 0.0, 1.0]
    touching = -0.15  # the box's face on the wall's
    ok, _ = checker.certify(np.array([touching, -0.5, 0.0, *identity]), np.array([touching, 0.5, 0.0, *identity]))
    assert not ok
    ok, fraction = checker.certify(np.array([-1.0, 0.0, 0.0, *identity]), np.array([1.0, 0.0, 0.0, *identity]), True)
    assert not ok and 0.4 < fraction < 0.425  # contact at x = -0.15: t = 0.425


# -- the compiled view ----------------------------------------------------------------------


@njit
def _loop(view, states):  # what an engine's compiled loop does: kernels on the view, no Python
    status = np.empty(len(states), dtype=np.int64)
    for i in range(len(states)):
        status[i] = state_status(view, states[i])
    edges = np.empty(len(states) - 1, dtype=np.int64)
    for i in range(len(states) - 1):
        edges[i] = edge_status(view, states[i], states[i + 1], False)[0]
    return status, edges


def test_kernels_run_from_compiled_code_and_decide_leaves_the_rest_to_fcl():
    rng = np.random.default_rng(8)
    environment, _ = mesh_world(rng)
    environment.add_box("box", (0.2, 0.2, 0.2), (0.0, 0.0, 0.0))
    body = RigidBody.from_triangles("SE3", l_mesh(), pieces=2)
    checker = RigidBodyChecker(body, environment, (np.full(3, -1.2), np.full(3, 1.2)))
    states = random_states("SE3", 300, rng, np.full(3, -1.2), np.full(3, 1.2))
    status, edges = _loop(checker.view, states)
    assert {FREE, COLLIDING, UNDECIDED} <= set(status.tolist())
    expected = checker.check(states)
    for state, kernel in zip(states, status):
        if kernel == UNDECIDED:
            assert state_status(checker.view, state) == UNDECIDED
            assert checker.decide(state)[0] == checker.is_valid(state)
        else:
            assert (kernel == FREE) == checker.is_valid(state)
    assert np.array_equal(expected, [checker.is_valid(s) for s in states])
    for i, kernel in enumerate(edges):
        a, b = states[i], states[i + 1]
        if kernel == UNDECIDED:
            edge_status(checker.view, a, b, False)
            assert checker.decide(a, b) == checker.certify(a, b)
        else:
            assert (kernel == FREE) == checker.certify(a, b)[0]


def test_ompl_state_conversions_round_trip():
    for space_name, values in (("SE2", [0.1, -0.2, 2.5]), ("SE3", [0.1, -0.2, 0.3, 0.0, 0.6, 0.0, 0.8])):
        space = rigid_body_space(
            space_name,
            [-1.0] * (len(values) - 1 if space_name == "SE2" else 3),
            [1.0] * (len(values) - 1 if space_name == "SE2" else 3),
        )
        state = space.allocState()
        set_rigid_state(state, np.array(values))
        np.testing.assert_allclose(rigid_state_values(state, len(values)), values)
    with pytest.raises(ValueError, match="'SE2' or 'SE3'"):
        rigid_body_space("R3", [0.0], [1.0])
    assert isinstance(rigid_body_space("SE3", [0, 0, 0], [1, 1, 1]), ob.SE3StateSpace)


def test_warm_up_compiles_the_kernels_real_checkers_use():
    from ompl_balance.collision.rigid.checker import warm_up
    from ompl_balance.worlds.rigid import rigid_problem

    warm_up()
    kernels = (state_status, edge_status)
    before = [set(k.signatures) for k in kernels]
    for name in ("se2_slot", "se3_room"):
        checker = rigid_problem(name).checker()
        checker.certify(rigid_problem(name).start, rigid_problem(name).goal)
    assert [set(k.signatures) for k in kernels] == before


@pytest.mark.parametrize("name", ["se2_bugtrap", "se3_slot"])
def test_discrete_validator_matches_ompls_own(name):
    """The batched discrete validator answers as OMPL's DiscreteMotionValidator, over the same
    validity checker, and its last valid state is the state before the first invalid one."""
    from ompl import geometric as og

    from ompl_balance.core.counting import read_work
    from ompl_balance.validity import RigidBodyValidityChecker, setup_rigid_body
    from ompl_balance.worlds.rigid import rigid_problem

    problem = rigid_problem(name)
    checker = problem.checker()
    ss = og.SimpleSetup(rigid_body_space(problem.space, problem.low.tolist(), problem.high.tolist()))
    _, validator = setup_rigid_body(ss, checker, motion="discrete")
    si = ss.getSpaceInformation()
    si.setup()
    stock = og.SimpleSetup(rigid_body_space(problem.space, problem.low.tolist(), problem.high.tolist()))
    stock_si = stock.getSpaceInformation()
    stock_si.setStateValidityChecker(RigidBodyValidityChecker(stock_si, problem.checker()))
    stock_si.setup()
    space = si.getStateSpace()
    s1, s2, last, probe = si.allocState(), si.allocState(), si.allocState(), si.allocState()
    rng = np.random.default_rng(9)
    outcomes = []
    for a, b in short_edges(problem.space, 80, rng, problem.low, problem.high, 0.6):
        if not checker.is_valid(a):
            continue
        set_rigid_state(s1, a)
        set_rigid_state(s2, b)
        before = read_work(si)
        valid = si.checkMotion(s1, s2)
        assert (read_work(si) - before).motions_checked == 1
        assert valid == stock_si.checkMotion(s1, s2)
        valid_again, fraction = validator.check_motion_last_valid(s1, s2, last)
        assert valid_again == valid
        if not valid:
            nd = space.validSegmentCount(s1, s2)
            walk = []
            for j in range(1, nd + 1):
                space.interpolate(s1, s2, j / nd, probe)
                walk.append(checker.is_valid(rigid_state_values(probe, len(a))))
            first = walk.index(False)
            assert fraction == pytest.approx(first / nd)
            space.interpolate(s1, s2, first / nd, probe)
            np.testing.assert_allclose(rigid_state_values(last, len(a)), rigid_state_values(probe, len(a)), atol=1e-9)
        outcomes.append(valid)
    assert 5 <= sum(outcomes) <= len(outcomes) - 5


def test_an_error_in_fcl_reaches_the_caller_and_the_planner_plans_on(monkeypatch):
    """FCL raising in what the compiled engine's kernels left undecided (reached through the
    checker's exit) ends the solve with that error; once FCL answers again, the same planner
    solves, and its path is certified."""
    problem = rigid_problem("se3_room")
    checker = problem.checker()
    ss = problem.simple_setup(checker=checker)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    planner.params().setParam("seed", "1")  # (its solve reaches FCL: 16 exits)
    ss.setPlanner(planner)
    with monkeypatch.context() as patched:
        patched.setattr(checker, "decide", failing_fcl)
        with pytest.raises(FCLError, match="the test's FCL failure"):
            ss.solve(30.0)
    assert ss.solve(30.0)
    assert certify_path(checker, ss.getSolutionPath()).certified
