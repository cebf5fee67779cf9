"""Valid-state samplers: valid samples near obstacles, OMPL's behaviour, counting, seeding, C++ callers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fresh_process import run_with_seed
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ompl_balance.samplers import BridgeTestValidStateSampler, GaussianValidStateSampler, PassageSampler
from ompl_balance.worlds.boxes import BoxWorld2D, get_problem

ou.setLogLevel(ou.LOG_WARN)
SAMPLERS = [GaussianValidStateSampler, BridgeTestValidStateSampler, PassageSampler]


def clearance(world: BoxWorld2D, x: float, y: float) -> float:
    """Distance from (x, y) to the nearest box of ``world`` (0 inside one)."""
    return min(
        math.hypot(max(x_min - x, 0.0, x - x_max), max(y_min - y, 0.0, y - y_max))
        for x_min, y_min, x_max, y_max in world.boxes
    )


def draw(sampler: ob.ValidStateSampler, si: ob.SpaceInformation, count: int) -> list[tuple[float, float]]:
    state = si.allocState()
    points = []
    while len(points) < count:
        if sampler.sample(state):
            points.append((state[0], state[1]))
    return points


def space_information(is_valid) -> ob.SpaceInformation:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(is_valid)
    si.setup()
    return si


#: Three boxes scattered in the unit square: plenty of room far from any obstacle.
SCATTERED = BoxWorld2D(((0.15, 0.15, 0.3, 0.3), (0.6, 0.45, 0.85, 0.6), (0.3, 0.7, 0.4, 0.9)))


@pytest.mark.parametrize("sampler_class", SAMPLERS)
def test_samples_are_valid_and_closer_to_obstacles_than_uniform(sampler_class):
    world = SCATTERED
    si = space_information(world)
    samples = draw(sampler_class(si), si, 500)
    uniform = draw(ob.UniformValidStateSampler(si), si, 500)
    assert all(world.is_free(x, y) and 0 <= x <= 1 and 0 <= y <= 1 for x, y in samples)
    mean_clearance = np.mean([clearance(world, x, y) for x, y in samples])
    uniform_clearance = np.mean([clearance(world, x, y) for x, y in uniform])
    assert mean_clearance < 0.8 * uniform_clearance


@pytest.mark.parametrize(
    ("sampler_class", "checks_free", "checks_blocked"),
    [
        # OMPL's loops: Gaussian checks a pair per attempt; the bridge test stops at a
        # valid first state and checks the midpoint of two invalid ones; the passage
        # sampler checks a valid centre and its 8 neighbours (none colliding can never
        # reach 1), or only an invalid centre.
        (GaussianValidStateSampler, 2, 2),
        (BridgeTestValidStateSampler, 1, 3),
        (PassageSampler, 9, 1),
    ],
)
def test_each_attempt_checks_what_ompl_checks_and_failure_returns_false(sampler_class, checks_free, checks_blocked):
    for is_valid, checks in ((lambda state: True, checks_free), (lambda state: False, checks_blocked)):
        sampler = sampler_class(space_information(is_valid))
        sampler.setNrAttempts(7)
        assert sampler.sample(sampler._scratch) is False
        assert sampler.validity_checks == 7 * checks


def test_gaussian_keeps_the_valid_one_of_the_pair():
    si = space_information(lambda state: state[0] < 0.5)
    sampler = GaussianValidStateSampler(si)
    state = si.allocState()
    for _ in range(50):
        assert sampler.sample(state)
        assert state[0] < 0.5
        assert state[0] > 0.5 - 6 * sampler.getStdDev()  # its partner was on the other side


def test_passage_sampler_accepts_by_the_colliding_count():
    free = space_information(lambda state: True)
    sampler = PassageSampler(free, neighbours=5, min_colliding=0, max_colliding=0)
    assert sampler.sample(sampler._scratch) is True
    assert sampler.validity_checks == 1 + 5  # the centre and all five neighbours


def test_validity_checks_are_the_checkers_checks():
    problem = get_problem("narrow_gap")
    si = problem.setup().getSpaceInformation()
    checker = si.getStateValidityChecker()
    for sampler_class in SAMPLERS:
        sampler = sampler_class(si)
        before = checker.states_checked
        draw(sampler, si, 20)
        assert sampler.validity_checks == checker.states_checked - before > 20


@pytest.mark.parametrize("sampler_class", SAMPLERS)
def test_sample_near_stays_near_and_valid(sampler_class):
    problem = get_problem("narrow_gap")
    world = problem.world()
    si = problem.setup().getSpaceInformation()
    sampler = sampler_class(si)
    near, state = si.allocState(), si.allocState()
    near[0], near[1] = 0.5, 0.5  # in the gap
    distance = 0.05
    offsets = []
    while len(offsets) < 50:
        if sampler.sampleNear(state, near, distance):
            assert world(state)
            offsets.append(math.hypot(state[0] - 0.5, state[1] - 0.5))
    assert np.mean(offsets) < 3 * distance


class CountingBridge(BridgeTestValidStateSampler):
    """Counts the samples C++ asks for and those found (class attributes: no reference to the instance)."""

    samples = found = 0

    def sample(self, state):
        CountingBridge.samples += 1
        found = super().sample(state)
        CountingBridge.found += found
        return found


def test_prm_grows_its_roadmap_from_a_python_sampler_given_through_the_allocator():
    """PRM's roadmap growth (in this thread, as ``growRoadmap`` runs it) asks the Python sampler
    for every milestone: each sample found is a milestone, and nothing else is."""
    ss = get_problem("narrow_gap").setup()
    ss.getSpaceInformation().setValidStateSamplerAllocator(CountingBridge)
    prm = og.PRM(ss.getSpaceInformation())
    ss.setPlanner(prm)
    ss.setup()
    CountingBridge.samples = CountingBridge.found = 0
    prm.growRoadmap(0.2)
    assert CountingBridge.samples > 0
    assert prm.milestoneCount() == CountingBridge.found > 0


def test_parameters_are_checked():
    si = get_problem("open").setup().getSpaceInformation()
    sampler = PassageSampler(si)
    assert sampler.getStdDev() == pytest.approx(0.05 * math.sqrt(2))
    assert GaussianValidStateSampler(si).getStdDev() == pytest.approx(0.1 * math.sqrt(2))
    assert (sampler.getNeighbours(), sampler.getMinColliding(), sampler.getMaxColliding()) == (8, 1, 7)
    params = sampler.params()
    assert params.setParam("standard_deviation", "0.02") and sampler.getStdDev() == 0.02
    for name, value in (
        ("standard_deviation", "0"),
        ("min_colliding", "8"),
        ("max_colliding", "9"),
        ("neighbours", "0"),
    ):
        assert params.setParam(name, value) is False, name
    with pytest.raises(ValueError, match="min_colliding <= max_colliding"):
        PassageSampler(si, neighbours=4, min_colliding=3, max_colliding=2)


SEEDED_SAMPLES = """
import sys
from ompl import util as ou
ou.RNG.setSeed(int(sys.argv[1]))
from ompl_balance.worlds.boxes import get_problem
from ompl_balance.samplers import BridgeTestValidStateSampler, GaussianValidStateSampler, PassageSampler
si = get_problem("maze").setup().getSpaceInformation()
state = si.allocState()
out = []
for sampler in (GaussianValidStateSampler(si), BridgeTestValidStateSampler(si), PassageSampler(si)):
    for _ in range(5):
        sampler.sample(state)
        out.append((round(state[0], 12), round(state[1], 12)))
print(out)
"""


def seeded_samples(seed: int) -> str:
    return run_with_seed(SEEDED_SAMPLES, seed)


def test_ompl_seed_repeats_the_samples():
    first, second, other = seeded_samples(11), seeded_samples(11), seeded_samples(12)
    assert first and first == second
    assert other != first
