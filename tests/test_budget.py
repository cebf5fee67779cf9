"""The work budget of one certified motion check, for the arm and for rigid bodies.

A proof that would exceed the budget stops and refuses its motion: never "free" unproved, counted
in ``motions_over_budget``, its work within the budget; a check within the budget answers as the
unbounded check does; lastValid and path certificates stay sound; OMPL's path simplifier keeps its
time limit where certified motions along grazing contacts used to take it seconds past it.

Oracles: dense exact re-checks that share nothing with the proof (a fresh checker's FCL collision
test at states 1e-4 rad apart for the arm, ``rigid_oracles.DenseCheck`` for rigid bodies), FCL's
calls counted by wrapping them, and the same certifier without a budget.
"""

import itertools
import json

import fcl
import numpy as np
import pytest
import trimesh
from fresh_process import run_with_seed
from ompl import geometric as og
from rigid_oracles import DenseCheck
from test_certified import dense_first_collision, grazing_edges, panda, random_edges
from test_rigid import STEP, _certified_in_compiled_code, l_mesh, mesh_world, short_edges
from test_validity import arm3_scene

from ompl_balance.collision.budget import FCL_QUERY_WORK, MOTION_BUDGET
from ompl_balance.collision.certified import MotionCertifier
from ompl_balance.collision.certified_lines import ALONG_TOLERANCE, along_certified, certified_lines, remember_certified
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.environment import Environment
from ompl_balance.collision.rigid.body import RigidBody
from ompl_balance.collision.rigid.checker import RigidBodyChecker
from ompl_balance.collision.rigid.kernels import RigidCertifiedMotions
from ompl_balance.validity import CertifiedMotionValidator, certify_path, setup_robot, space_for
from ompl_balance.worlds.mbm import load_mbm
from ompl_balance.worlds.rigid import rigid_problem

#: A motion of MotionBenchMaker's box problem 2 (VAMP's Panda) that OMPL's simplifier asked for:
#: the non-convex ``link6`` passes 0.2-0.3 mm from a wall of the box all along it, so the proof
#: bisects it to about half a millimetre of travel, each point one FCL collision test and one FCL
#: distance (about 430 of each, 0.7-1.1 s: one of the slowest motions of that problem's simplifications).
GRAZING_START = [
    0.27697346787469973, -0.48715997306267844, 0.4721298763948353, -2.1237533004529996,
    0.07073658308664414, 1.6310053407116294, 0.740843990834213,
]  # fmt: skip
GRAZING_END = [
    0.36769250913826934, -0.3636035973643641, 0.5736792771681534, -2.052428350221904,
    0.033216460998063344, 1.6626421236127218, 0.7267530188650511,
]  # fmt: skip


def box_problem(problem_id):
    return next(p for p in load_mbm("box", panda().joint_names) if p.id == problem_id)


class FclCalls:
    """FCL queries of the arm's certifier, counted by wrapping the checker's two FCL calls."""

    def __init__(self, monkeypatch):
        self.touching = self.distances = 0
        touching, distance = CollisionChecker.pair_touching, CollisionChecker.pair_distance

        def counted_touching(checker, *arguments):
            self.touching += 1
            return touching(checker, *arguments)

        def counted_distance(checker, *arguments):
            self.distances += 1
            return distance(checker, *arguments)

        monkeypatch.setattr(CollisionChecker, "pair_touching", counted_touching)
        monkeypatch.setattr(CollisionChecker, "pair_distance", counted_distance)

    def reading(self):
        return self.touching, self.distances


def arm_work(checker, calls, check):
    """Run ``check()``; return its answer and its work from independent counts: configurations
    placed and GJK bounds (the checker's counters, less the FCL distances they also count) at one
    unit each, FCL queries (counted by wrapping) at ``FCL_QUERY_WORK``."""
    before, (touching, distances) = checker.counters(), calls.reading()
    answer = check()
    after = checker.counters()
    fcl_distances, fcl_touching = calls.distances - distances, calls.touching - touching
    gjk = after["distance_queries"] - before["distance_queries"] - fcl_distances
    states = after["states_checked"] - before["states_checked"]
    refused = after["motions_over_budget"] - before["motions_over_budget"]
    return answer, states + gjk + FCL_QUERY_WORK * (fcl_distances + fcl_touching), refused


# ------------------------------------------------------------------------------------------ the arm


def test_grazing_motion_over_budget_is_refused_counted_and_within_budget(monkeypatch):
    robot, environment = panda(), box_problem(2).environment
    a, b = np.array(GRAZING_START), np.array(GRAZING_END)
    calls = FclCalls(monkeypatch)
    unbounded = CollisionChecker(robot, environment)
    (free, _), work, refused = arm_work(
        unbounded, calls, lambda: MotionCertifier(unbounded, motion_budget=None).check(a, b)
    )
    assert free and not refused
    assert work > 4 * MOTION_BUDGET  # the proof the budget cuts short (without it, the checks below fail)
    oracle = CollisionChecker(robot, environment)
    assert dense_first_collision(oracle, a, b) is None  # refusing it is conservative

    checker = CollisionChecker(robot, environment)
    certifier = MotionCertifier(checker)
    (free, fraction), work, refused = arm_work(checker, calls, lambda: certifier.check(a, b))
    assert (free, fraction, refused) == (False, 0.0, 1) and work <= MOTION_BUDGET
    (free, fraction), work, refused = arm_work(checker, calls, lambda: certifier.check(a, b, last_valid=True))
    assert not free and refused == 1 and work <= MOTION_BUDGET
    assert 0.0 <= fraction < 1.0  # the certified prefix: free, and certified without a budget too
    if fraction > 0.0:
        assert dense_first_collision(oracle, a, b, until=fraction) is None
        assert MotionCertifier(unbounded, motion_budget=None).check(a, a + fraction * (b - a))[0]

    # through OMPL: the validator refuses it and reports the refusal with its counters
    ss = og.SimpleSetup(space_for(robot))
    _, validator = setup_robot(ss, CollisionChecker(robot, environment))
    si = ss.getSpaceInformation()
    s1, s2 = si.allocState(), si.allocState()
    for i in range(robot.dof):
        s1[i], s2[i] = float(a[i]), float(b[i])
    assert not si.checkMotion(s1, s2)
    assert validator.counters()["motions_over_budget"] == 1 and validator.motion_budget == MOTION_BUDGET

    # a path through it is not certified (the budget stopped the proof), and is without a budget
    path = np.stack([a, 0.5 * (a + b), b])
    assert not certify_path(CollisionChecker(robot, environment), path).certified
    assert certify_path(CollisionChecker(robot, environment), path, motion_budget=None).certified


@pytest.mark.parametrize("budget", [MOTION_BUDGET, 300])
def test_answers_within_the_budget_are_the_unbounded_ones(monkeypatch, budget):
    """The test arm among a box, a sphere, a cylinder, a cone and a non-convex ring (FCL on its
    pairs), random edges and grazing ones: every edge the budgeted certifier answers within its
    budget gets the unbounded answer, every refusal for the budget is counted and stays within
    it, and nothing certified collides."""
    robot, environment = arm3_scene()[:2]
    environment.add_mesh("ring", trimesh.creation.annulus(0.25, 0.32, 0.06), [0.0, 0.0, 0.45])
    calls = FclCalls(monkeypatch)
    oracle = CollisionChecker(robot, environment)
    edges = random_edges(robot, oracle, 60, np.random.default_rng(21), longest=0.8)
    # and edges 1e-5 rad either side of a contact: the colliding ones must never be certified
    edges += [
        edge
        for colliding, free, *_ in grazing_edges(robot, environment, 3, np.random.default_rng(22))
        for edge in (colliding, free)
    ]
    unbounded = MotionCertifier(CollisionChecker(robot, environment), motion_budget=None)
    checker = CollisionChecker(robot, environment)
    bounded = MotionCertifier(checker, motion_budget=budget)
    refusals = 0
    for a, b in edges:
        free_unbounded = unbounded.check(a, b)[0]
        for last_valid in (False, True):
            (free, fraction), work, refused = arm_work(checker, calls, lambda: bounded.check(a, b, last_valid))
            assert work <= budget
            if refused:
                assert not free
                refusals += 1
            else:
                assert free == free_unbounded
            if free:
                assert dense_first_collision(oracle, a, b) is None
            elif last_valid and fraction > 0.0:
                assert dense_first_collision(oracle, a, b, until=fraction) is None
    if budget < MOTION_BUDGET:
        assert refusals >= 5  # (the budget was met)
    assert checker.counters()["motions_over_budget"] == refusals


SIMPLIFY = """
import json, sys, time
from ompl import util as ou
ou.RNG.setSeed(int(sys.argv[1]))  # (OMPL's simplifier draws its shortcuts from OMPL's generator)
from ompl_balance import BalancedRRTConnect
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.worlds.mbm import load_mbm
robot = load_panda_vamp()
problem = next(p for p in load_mbm("box", robot.joint_names) if p.id == 2)
checker = CollisionChecker(robot, problem.environment)
ss = problem.simple_setup(robot, checker)
planner = BalancedRRTConnect(ss.getSpaceInformation())
for name, value in (("max_tree_size_ratio", "0.5"), ("range", "0.1"), ("seed", "1")):
    planner.params().setParam(name, value)
ss.setPlanner(planner)
ss.setup()
planner.wait_for_engine()
assert ss.solve(10.0) and ss.haveExactSolutionPath()
refused = checker.counters()["motions_over_budget"]
began = time.perf_counter()
ss.simplifySolution(1.0)
seconds = time.perf_counter() - began
path = ss.getSolutionPath()
states = [[path.getState(i)[j] for j in range(robot.dof)] for i in range(path.getStateCount())]
refused = checker.counters()["motions_over_budget"] - refused
print(json.dumps({"seconds": seconds, "refused": refused, "states": states}))
"""


def test_simplify_solution_keeps_its_time_limit():
    """BalancedRRTConnect[max_tree_size_ratio=0.5, range=0.1] on box problem 2 leaves a path along
    the box's walls, and OMPL's simplifier then asks for long motions grazing them whatever its
    time limit (one full pass: reduceVertices, collapseCloseVertices, shortcuts, B-spline
    smoothing). In a fresh process with OMPL's seed set, so that the simplifier takes the same
    shortcuts every time: ``simplifySolution(1.0)`` took 3-6 s on this machine before motions had
    a budget, 0.1-0.5 s since. The simplified path passes the dense re-check."""
    result = json.loads(run_with_seed(SIMPLIFY, 3).splitlines()[-1])
    assert result["seconds"] < 2.5  # (generous: a loaded machine)
    assert result["refused"] > 0  # (the budget was met)
    robot = panda()
    oracle = CollisionChecker(robot, box_problem(2).environment)
    for a, b in itertools.pairwise(np.array(result["states"])):
        assert dense_first_collision(oracle, a, b) is None


# ------------------------------------------------------------------------- pieces of certified edges


def test_along_certified_is_both_ends_on_a_kept_edge():
    """Against the geometry (an independent numpy oracle): a motion is along a kept edge when both
    its ends lie on the edge's segment, to rounding; not beyond its ends, not a hair off it, not
    from one edge to another, and not along an edge the ring has overwritten."""
    rng = np.random.default_rng(11)
    dof = 7
    lines = certified_lines(4, dof)
    edges = [(rng.uniform(-2, 2, dof), rng.uniform(-2, 2, dof)) for _ in range(4)]
    tie = rng.uniform(-2, 2, dof)  # (two joints move most, equally: either may lead a piece)
    edges.append((tie, tie + np.array([0.7, -0.7, 0.3, 0.0, 0.0, 0.0, 0.1])))
    for a, b in edges:
        remember_certified(lines, a, b)
    (a0, b0), kept = edges[0], edges[1:]  # (the fifth edge took the first one's place)
    assert not along_certified(lines, a0, b0)
    for a, b in kept:
        for _ in range(20):
            s, t = rng.uniform(0, 1, 2)
            p, q = a + s * (b - a), a + t * (b - a)
            assert along_certified(lines, p, q) and along_certified(lines, q, p)
            assert along_certified(lines, p, p)
            across = rng.normal(size=dof)
            across -= across @ (b - a) / ((b - a) @ (b - a)) * (b - a)  # (at a right angle to the edge)
            across /= np.linalg.norm(across)
            assert np.linalg.norm(across * 1e-14) < ALONG_TOLERANCE
            assert along_certified(lines, p + 1e-14 * across, q)  # (rounding)
            assert not along_certified(lines, p + 1e-9 * across, q)
            assert not along_certified(lines, p, a + 1.001 * (b - a))
            assert not along_certified(lines, a - 0.001 * (b - a), q)
    (a1, b1), (a2, b2) = kept[:2]
    assert not along_certified(lines, (a1 + b1) / 2, (a2 + b2) / 2)
    for bad in (np.nan, np.inf, -np.inf):
        q = a1.copy()
        q[3] = bad
        assert not along_certified(lines, a1, q) and not along_certified(lines, q, q)


def edge_whose_fresh_proof_exceeds_its_remembered_one(checker, rng):
    """An edge ``a -> b`` and a budget ``units`` within which a certifier refuses the edge the
    first time and certifies it the second, with the bounds at its ends remembered (``units``:
    the second proof's work, counted by a certifier with no budget)."""
    for a, b in random_edges(checker.robot, checker, 200, rng, longest=0.6):
        unbounded = MotionCertifier(checker, motion_budget=None)
        if not unbounded.check(a, b)[0]:
            continue
        before = checker.counters()
        unbounded.check(a, b)
        after = checker.counters()
        units = sum(after[key] - before[key] for key in ("states_checked", "distance_queries"))
        budgeted = MotionCertifier(checker, motion_budget=max(units, 1))
        if not budgeted.check(a, b)[0] and budgeted.check(a, b)[0]:
            return a, b, max(units, 1)
    raise AssertionError("no such edge among 200 (the search's premise no longer holds)")


def test_an_edge_certified_before_is_certified_again_when_its_own_proof_no_longer_fits():
    """OMPL's simplifier checks a path's edges again long after the planner certified them; by then
    the bounds at their ends are forgotten and the proof from scratch may exceed the budget. The
    validator must still accept the edges it certified (OMPL's ``PathGeometric::check``, through
    ``checkMotion``), and the pieces ``subdivide`` cuts them into: a refusal there makes
    ``checkAndRepair`` put random states into the path. Oracles: a fresh validator with the same
    budget refuses the edge (the premise), and a dense exact re-check finds it free."""
    robot = panda()
    environment = load_mbm("bookshelf_small", robot.joint_names)[1].environment
    checker = CollisionChecker(robot, environment)
    a, b, units = edge_whose_fresh_proof_exceeds_its_remembered_one(checker, np.random.default_rng(5))
    si = og.SimpleSetup(space_for(robot)).getSpaceInformation()
    validator = setup_robot(si, checker, motion_budget=units)[1]
    fresh = setup_robot(og.SimpleSetup(space_for(robot)).getSpaceInformation(), checker, motion_budget=units)[1]
    path = og.PathGeometric(si)
    for q in (a, b):
        state = si.allocState()
        for j, value in enumerate(q):
            state[j] = float(value)
        path.append(state)
    ends = path.getState(0), path.getState(1)
    assert not fresh.checkMotion(*ends)  # (the proof from scratch exceeds the budget)
    assert not validator.checkMotion(*ends)  # (so does the first: nothing remembered yet)
    assert validator.checkMotion(*ends)  # (the bounds at its ends remembered: certified)
    for step in range(300):  # other edges, until the bounds at a and b are forgotten
        q = a + 0.05 * np.sin(np.arange(robot.dof) + step)
        validator.certifier.check(q, q + 0.01)
    assert path.check()  # (OMPL's own check: every edge through checkMotion)
    path.subdivide()
    path.subdivide()
    assert path.check()
    assert validator.check_motion_last_valid(path.getState(1), path.getState(3)) == (True, 1.0)
    for bad in (np.nan, np.inf):
        far = si.allocState()
        for j, value in enumerate(b):
            far[j] = bad if j == 2 else float(value)
        assert not validator.checkMotion(path.getState(0), far)
    assert dense_first_collision(CollisionChecker(robot, environment), a, b) is None


# ------------------------------------------------------------------------------------------ rigid bodies


def sliding_past_a_wall(gap):
    """A 0.2 m cube sliding 1 m along a wall, ``gap`` metres from it: convex parts and a box, so
    GJK decides every bound (no FCL); near the wall the proof takes about ``1 / gap`` segments."""
    body = RigidBody.from_meshes("SE3", [trimesh.creation.box(extents=(0.2, 0.2, 0.2))])
    environment = Environment()
    environment.add_box("wall", (0.05, 1.0, 1.0), (0.0, 0.0, 0.0))
    identity = [0.0, 0.0, 0.0, 1.0]
    x = -0.15 - gap
    return body, environment, np.array([x, -0.5, 0.0, *identity]), np.array([x, 0.5, 0.0, *identity])


def rigid_work(checker, check):
    """Run ``check()``; its answer, its work (poses and GJK bounds: no FCL in these worlds) and
    whether it was refused for the budget."""
    before = checker.counters()
    answer = check()
    after = checker.counters()
    work = sum(after[k] - before[k] for k in ("states_checked", "distance_queries"))
    return answer, work, after["motions_over_budget"] - before["motions_over_budget"]


def test_rigid_motion_over_budget_is_refused_counted_and_within_budget():
    body, environment, a, b = sliding_past_a_wall(1e-4)
    dense = DenseCheck(body, environment, STEP)
    assert dense.first_collision(a, b) is None
    unbounded = RigidBodyChecker(body, environment, motion_budget=None)
    (free, _), work, refused = rigid_work(unbounded, lambda: unbounded.certify(a, b))
    assert free and not refused and work > 2 * MOTION_BUDGET  # what the budget cuts short

    checker = RigidBodyChecker(body, environment)
    (free, fraction), work, refused = rigid_work(checker, lambda: checker.certify(a, b))
    assert (free, fraction, refused) == (False, 0.0, 1) and work <= MOTION_BUDGET
    (free, fraction), work, refused = rigid_work(checker, lambda: checker.certify(a, b, last_valid=True))
    assert not free and refused == 1 and work <= MOTION_BUDGET and 0.0 <= fraction < 1.0
    if fraction > 0.0:
        prefix = a + fraction * (b - a)  # (a translation: OMPL's interpolation is linear here)
        assert dense.first_collision(a, prefix) is None and unbounded.certify(a, prefix)[0]

    # the compiled kernel, as the compiled engine calls it, refuses and counts alike
    compiled = RigidBodyChecker(body, environment)
    view = compiled.kernel_view()
    assert view is not None
    assert not _certified_in_compiled_code(RigidCertifiedMotions(view, view.counts), a, b)
    assert compiled.counters()["motions_over_budget"] == 1

    # a path certificate claims nothing the budget stopped
    assert not certify_path(checker, np.stack([a, b])).certified
    assert certify_path(checker, np.stack([a, b]), motion_budget=None).certified

    # farther from the wall, the same motion is certified within the budget
    body, environment, a, b = sliding_past_a_wall(0.05)
    checker = RigidBodyChecker(body, environment)
    assert checker.certify(a, b) == (True, 1.0) and checker.counters()["motions_over_budget"] == 0


@pytest.mark.parametrize("budget", [MOTION_BUDGET, 400])
def test_rigid_answers_within_the_budget_are_the_unbounded_ones(monkeypatch, budget):
    """A non-convex body among tetrahedra and a box (FCL distances finish the pairs with meshes):
    within the budget the answers are the unbounded ones, refusals are counted and within the
    budget (FCL's calls counted by wrapping them), and nothing certified collides."""
    rng = np.random.default_rng(17)
    environment, _ = mesh_world(rng)
    environment.add_box("box", (0.3, 0.1, 0.3), (0.2, -0.3, 0.1))
    body = RigidBody.from_triangles("SE3", l_mesh(), pieces=2)
    low, high = np.full(3, -1.2), np.full(3, 1.2)
    calls = [0]
    for name in ("collide", "distance"):
        original = getattr(fcl, name)
        monkeypatch.setattr(
            fcl, name, lambda *arguments, call=original: calls.__setitem__(0, calls[0] + 1) or call(*arguments)
        )
    unbounded = RigidBodyChecker(body, environment, (low, high), motion_budget=None)
    checker = RigidBodyChecker(body, environment, (low, high), motion_budget=budget)
    assert not checker.view.probe  # (a box among the meshes: no probing states, all work is the proof's)
    dense = DenseCheck(body, environment, STEP)
    edges = [(a, b) for a, b in short_edges("SE3", 50, rng, low, high, 0.5) if checker.is_valid(a)]
    refusals = 0
    for a, b in edges:
        free_unbounded = unbounded.certify(a, b)[0]
        for last_valid in (False, True):
            before, fcl_calls = checker.counters(), calls[0]
            free, fraction = checker.certify(a, b, last_valid)
            after = checker.counters()
            distances = after["distance_queries"] - before["distance_queries"]
            queries = calls[0] - fcl_calls
            # poses, GJK bounds (the distance queries less FCL's) and FCL queries; FCL distances
            # are at most the queries, so this is at most the work counted
            work = after["states_checked"] - before["states_checked"] + distances + (FCL_QUERY_WORK - 1) * queries
            assert work <= budget
            if after["motions_over_budget"] > before["motions_over_budget"]:
                assert not free
                refusals += 1
            else:
                assert free == free_unbounded
            if free:
                assert dense.first_collision(a, b) is None
            elif last_valid and fraction > 0.0:
                assert dense.first_collision(a, b, until=fraction) is None
    assert refusals >= (5 if budget < MOTION_BUDGET else 0)


def test_shipped_rigid_problem_plans_with_the_default_budget():
    """se2_bugtrap with stock RRT-Connect: solved, and its planning refuses next to no motion for the budget."""
    problem = rigid_problem("se2_bugtrap")
    checker = problem.checker()
    ss = problem.simple_setup(checker=checker)
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    assert ss.solve(problem.time_limit) and ss.haveExactSolutionPath()
    counters = checker.counters()
    assert counters["motions_over_budget"] <= 0.001 * counters["motions_checked"]


# ------------------------------------------------------------------------------------------ bad values

BAD_BUDGETS = [0, -5, 2.5, float("inf"), float("nan"), "2048", True]


@pytest.mark.parametrize("bad", BAD_BUDGETS, ids=repr)
def test_bad_budgets_are_one_line_errors(bad):
    robot, environment = arm3_scene()[:2]
    checker = CollisionChecker(robot, environment)
    body, world, _, _ = sliding_past_a_wall(0.05)
    ss = og.SimpleSetup(space_for(robot))
    attempts = [
        lambda: MotionCertifier(checker, motion_budget=bad),
        lambda: CertifiedMotionValidator(ss.getSpaceInformation(), checker, motion_budget=bad),
        lambda: setup_robot(ss, checker, motion_budget=bad),
        lambda: certify_path(checker, np.zeros((2, robot.dof)), motion_budget=bad),
        lambda: RigidBodyChecker(body, world, motion_budget=bad),
        lambda: rigid_problem("se2_slot").checker(motion_budget=bad),
    ]
    for attempt in attempts:
        with pytest.raises(ValueError) as error:
            attempt()
        message = str(error.value)
        assert "\n" not in message and "motion_budget" in message and repr(bad) in message


def test_good_budgets_and_the_discrete_validator():
    robot, environment = arm3_scene()[:2]
    checker = CollisionChecker(robot, environment)
    for good in (1, np.int64(5000), None):
        assert MotionCertifier(checker, motion_budget=good).motion_budget == good
    a = 0.5 * (robot.lower + robot.upper)
    assert not MotionCertifier(checker, motion_budget=1).check(a, a)[0]  # (not even the ends fit)
    assert checker.counters()["motions_over_budget"] == 1
    ss = og.SimpleSetup(space_for(robot))
    with pytest.raises(ValueError, match="needs motion='certified'"):
        setup_robot(ss, checker, motion="discrete", motion_budget=100)
