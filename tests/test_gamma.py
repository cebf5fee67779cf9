"""Ball-radius maths: closed forms, the schedule, the free-measure estimate, OMPL's equivalent."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from scipy.stats import binom, binomtest

from ompl_balance.cli import main
from ompl_balance.gamma import (
    STOP_CHECK_EVERY,
    EstimateInterruptedError,
    ball_radius_constant,
    clopper_pearson,
    estimate_ball_radius_constant,
    estimate_free_measure,
    ompl_ball_radius_constant,
    ompl_rewire_factor,
    rewire_radius,
    unit_ball_volume,
)
from ompl_balance.worlds.occupancy import GridValidityChecker, OccupancyGrid, OccupancyProblem, rooms_problem

ou.setLogLevel(ou.LOG_WARN)
PI = math.pi

# Volumes of the unit d-ball: V_1 = 2, V_2 = pi, V_d = 2 pi / d * V_{d-2}.
CLOSED_FORMS = {
    1: 2.0,
    2: PI,
    3: 4 * PI / 3,
    4: PI**2 / 2,
    5: 8 * PI**2 / 15,
    6: PI**3 / 6,
    7: 16 * PI**3 / 105,
    8: PI**4 / 24,
    9: 32 * PI**4 / 945,
    10: PI**5 / 120,
}


@pytest.mark.parametrize("d", sorted(CLOSED_FORMS))
def test_unit_ball_volume_closed_forms(d):
    assert unit_ball_volume(d) == pytest.approx(CLOSED_FORMS[d], rel=1e-12)


@pytest.mark.parametrize("bad", [0, -1, 2.5, True])
def test_unit_ball_volume_rejects_bad_dimensions(bad):
    with pytest.raises(ValueError, match="dimension"):
        unit_ball_volume(bad)


@pytest.mark.parametrize(("d", "free"), [(1, 3.0), (2, 1.0), (3, 314.0), (6, 0.25), (10, 7.0)])
def test_ball_radius_constant_matches_the_formula(d, free):
    assert ball_radius_constant(d, free) == pytest.approx(2**d * (1 + 1 / d) * free / CLOSED_FORMS[d], rel=1e-12)


def test_ball_radius_constant_example_value():
    # d = 2, unit square free: 4 * 1.5 / pi
    assert ball_radius_constant(2, 1.0) == pytest.approx(6 / PI)
    with pytest.raises(ValueError, match="free_measure"):
        ball_radius_constant(2, 0.0)


def test_rewire_radius_saturates_at_eta():
    # (100 * log 10 / 10)^(1/2) = 4.8 > eta = 1: saturated
    assert rewire_radius(10, 2, 100.0, 1.0) == 1.0
    counts = np.arange(2, 50)
    assert np.all(rewire_radius(counts, 2, 1e6, 0.5) == 0.5)


def test_rewire_radius_decays_as_documented():
    counts = np.unique(np.logspace(0.5, 7, 60).astype(int))
    radii = rewire_radius(counts, 3, 10.0)
    assert np.allclose(radii, (10.0 * np.log(counts) / counts) ** (1 / 3))
    assert np.all(np.diff(radii) < 0)  # past n = e it only shrinks
    assert rewire_radius(1, 3, 10.0) == 0.0
    assert rewire_radius(1000, 2, 100.0, math.inf) == pytest.approx(math.sqrt(100 * math.log(1000) / 1000))
    # scalar ints and arrays agree
    assert rewire_radius(1000, 2, 100.0, 0.7) == pytest.approx(float(rewire_radius(np.array([1000]), 2, 100.0, 0.7)[0]))


@pytest.mark.parametrize(
    ("args", "what"),
    [((0, 2, 1.0), "n"), ((10, 2, 0.0), "gamma"), ((10, 2, 1.0, 0.0), "eta"), ((10, 0, 1.0), "dimension")],
)
def test_rewire_radius_rejects_bad_arguments(args, what):
    with pytest.raises(ValueError, match=what):
        rewire_radius(*args)


# -- free measure ----------------------------------------------------------------------


def _checkerboard_setup(fraction_occupied: float = 0.3) -> tuple[ob.SpaceInformation, OccupancyGrid, og.SimpleSetup]:
    """A 20 x 20 grid over [0, 4]^2 with a known set of occupied cells."""
    rng = np.random.default_rng(7)
    occupied = rng.random((20, 20)) < fraction_occupied
    grid = OccupancyGrid(occupied, 0.2)
    ss = OccupancyProblem("random", grid, (0.0, 0.0), (1.0, 1.0)).setup()
    return ss.getSpaceInformation(), grid, ss


def test_exact_free_measure_counts_cells():
    si, grid, _ss = _checkerboard_setup()
    free = estimate_free_measure(si, grid=grid)
    assert free.exact and free.samples == 0
    assert free.measure == pytest.approx(grid.free_area)
    assert free.measure == pytest.approx((~grid.occupied).sum() * 0.04)
    assert free.low == free.high == free.measure


def test_monte_carlo_estimate_is_within_its_interval_in_95_percent_of_trials():
    si, grid, _ss = _checkerboard_setup()
    exact = grid.free_area
    samples, trials = 100, 1000
    covered = 0
    for seed in range(trials):
        free = estimate_free_measure(si, samples=samples, confidence=0.95, rng=seed)
        assert free.low <= free.measure <= free.high
        covered += free.low <= exact <= free.high
    assert covered >= 0.95 * trials, f"interval covered the exact measure in {covered}/{trials} trials"


def test_interval_coverage_is_at_least_the_confidence_level():
    """Exact coverage of the reported interval, summed over every outcome of the binomial."""
    for samples in (20, 100):
        intervals = [_reported_interval(free, samples) for free in range(samples + 1)]
        for fraction in (0.05, 0.5, 0.7025, 0.99):
            coverage = sum(
                binom.pmf(free, samples, fraction)
                for free, (low, high) in enumerate(intervals)
                if low <= fraction <= high
            )
            assert coverage >= 0.95, (fraction, samples, coverage)


def _reported_interval(free: int, samples: int) -> tuple[float, float]:
    """The interval ``estimate_free_measure`` reports when exactly ``free`` of ``samples`` states are valid.

    The space is the unit square (measure 1), so measures are fractions.
    """
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    calls = []

    def first_ones_valid(state) -> bool:
        calls.append(None)
        return len(calls) <= free

    si.setStateValidityChecker(first_ones_valid)
    estimate = estimate_free_measure(si, samples=samples, confidence=0.95, rng=0)
    assert estimate.free_fraction == pytest.approx(free / samples)
    return estimate.low, estimate.high


def test_monte_carlo_interval_narrows_with_samples():
    si, _grid, _ss = _checkerboard_setup()
    small = estimate_free_measure(si, samples=200, rng=1)
    large = estimate_free_measure(si, samples=4000, rng=1)
    assert large.high - large.low < (small.high - small.low) / 3


def test_monte_carlo_estimate_rejects_bad_arguments():
    si, _grid, _ss = _checkerboard_setup()
    with pytest.raises(ValueError, match="samples"):
        estimate_free_measure(si, samples=0)
    with pytest.raises(ValueError, match="confidence"):
        estimate_free_measure(si, confidence=1.0)
    with pytest.raises(ValueError, match="boolean"):
        estimate_free_measure(si, grid=np.zeros((3, 3)))


@pytest.mark.parametrize("samples", [1, 2, 17, 100, 5000])
def test_clopper_pearson_is_scipys_exact_interval(samples):
    for free in sorted({0, 1, samples // 3, samples // 2, samples - 1, samples}):
        expected = binomtest(free, samples).proportion_ci(confidence_level=0.95, method="exact")
        low, high = clopper_pearson(free, samples, 0.95)
        assert low == pytest.approx(expected.low, abs=1e-10) and high == pytest.approx(expected.high, abs=1e-10)


def test_a_stopped_estimate_uses_the_samples_drawn_so_far():
    si, _grid, _ss = _checkerboard_setup()
    asked = []
    free = estimate_free_measure(si, samples=5000, rng=2, stop=lambda: asked.append(1) or len(asked) > 3)
    assert free.samples == 3 * STOP_CHECK_EVERY and len(asked) == 4
    same = estimate_free_measure(si, samples=3 * STOP_CHECK_EVERY, rng=2)  # the same draws, unstopped
    assert (free.measure, free.low, free.high) == (same.measure, same.low, same.high)
    with pytest.raises(EstimateInterruptedError, match="before the first sample"):
        estimate_free_measure(si, samples=5000, rng=2, stop=lambda: True)


def test_estimated_constant_uses_the_upper_end_of_the_interval():
    si, grid, _ss = _checkerboard_setup()
    free = estimate_free_measure(si, samples=1000, rng=3)
    assert estimate_ball_radius_constant(si, samples=1000, rng=3) == pytest.approx(ball_radius_constant(2, free.high))
    assert estimate_ball_radius_constant(si, grid=grid) == pytest.approx(ball_radius_constant(2, grid.free_area))


# -- OMPL's schedule ------------------------------------------------------------------------


def _ompl_radius(n: int, d: int, space_measure: float, rewire_factor: float, eta: float) -> float:
    """OMPL's RRTstar radius, written out from RRTstar.cpp (calculateRewiringLowerBounds, getNeighbors)."""
    r_rrt = rewire_factor * (2 * (1 + 1 / d) * (space_measure / CLOSED_FORMS[d])) ** (1 / d)
    return min(eta, r_rrt * (math.log(n) / n) ** (1 / d))


@pytest.mark.parametrize("se2", [False, True])
@pytest.mark.parametrize("gamma", [100.0, 2647.5, 5.0])
def test_ompl_rewire_factor_gives_the_same_radius(se2, gamma):
    ss = rooms_problem(se2=se2).setup()
    si = ss.getSpaceInformation()
    d, measure = si.getStateDimension(), si.getSpaceMeasure()
    planner = og.RRTstar(si)
    planner.setKNearest(True)
    factor = ompl_rewire_factor(si, gamma, planner)
    assert planner.getKNearest() is False
    assert planner.getRewireFactor() == pytest.approx(factor)
    eta = 4.0
    for n in (2, 10, 100, 1000, 10_000, 1_000_000):
        assert _ompl_radius(n, d, measure, factor, eta) == pytest.approx(rewire_radius(n, d, gamma, eta), rel=1e-12)
        assert _ompl_radius(n, d, measure, factor, math.inf) == pytest.approx(rewire_radius(n, d, gamma), rel=1e-12)


@pytest.mark.parametrize("se2", [False, True])
@pytest.mark.parametrize("factor", [1.0, 1.1, 1.7])
def test_ompl_ball_radius_constant_is_the_gamma_of_ompls_schedule(se2, factor):
    si = rooms_problem(se2=se2).setup().getSpaceInformation()
    d, measure = si.getStateDimension(), si.getSpaceMeasure()
    gamma = ompl_ball_radius_constant(si, factor)
    assert ompl_rewire_factor(si, gamma) == pytest.approx(factor, rel=1e-12)
    for n in (2, 100, 10_000, 1_000_000):
        assert rewire_radius(n, d, gamma, 4.0) == pytest.approx(_ompl_radius(n, d, measure, factor, 4.0), rel=1e-12)
    with pytest.raises(ValueError, match="rewire_factor"):
        ompl_ball_radius_constant(si, 0.0)


def test_ompl_default_factor_differs_by_the_measure_ratio_and_a_power_of_two():
    """OMPL with rewire_factor 1 uses gamma = 2 (1 + 1/d) mu(X) / zeta_d: 2^(d-1) mu(X_free) / mu(X) below gamma*."""
    problem = rooms_problem()
    si = problem.setup().getSpaceInformation()
    d = si.getStateDimension()
    gamma_star = ball_radius_constant(d, problem.grid.free_area)
    ompl_gamma = 2 * (1 + 1 / d) * si.getSpaceMeasure() / unit_ball_volume(d)
    assert ompl_rewire_factor(si, ompl_gamma) == pytest.approx(1.0)
    assert gamma_star / ompl_gamma == pytest.approx(2 ** (d - 1) * problem.grid.free_area / si.getSpaceMeasure())


# -- occupancy grids and the command -----------------------------------------------------------


def test_grid_checker_agrees_with_the_grid():
    problem = rooms_problem()
    ss = problem.setup()
    si = ss.getSpaceInformation()
    checker = si.getStateValidityChecker()
    assert isinstance(checker, GridValidityChecker)
    rng = np.random.default_rng(0)
    xy = rng.uniform(-1.0, 41.0, size=(300, 2))
    state = si.allocState()
    expected = problem.grid.free_mask(xy)
    for (x, y), free in zip(xy, expected):
        state[0], state[1] = x, y
        assert si.isValid(state) == free
    assert checker.counters()["states_checked"] == 300
    assert not expected[(xy < 0).any(axis=1)].any()  # outside the grid is never free


def test_rooms_problem_start_and_goal_are_free_and_far_apart():
    for se2 in (False, True):
        problem = rooms_problem(se2=se2)
        assert problem.grid.is_free(*problem.start[:2]) and problem.grid.is_free(*problem.goal[:2])
        assert math.dist(problem.start[:2], problem.goal[:2]) > 0.8 * problem.grid.high[0]


def test_occupancy_grid_rejects_bad_input():
    with pytest.raises(ValueError, match="2-D boolean"):
        OccupancyGrid(np.zeros((4, 4)), 0.1)
    with pytest.raises(ValueError, match="resolution"):
        OccupancyGrid(np.zeros((4, 4), dtype=bool), -1.0)


def test_gamma_command_prints_the_exact_estimate(capsys):
    assert main(["gamma", "--problem", "rooms"]) == 0
    out = capsys.readouterr().out
    gamma_star = ball_radius_constant(2, rooms_problem().grid.free_area)
    assert f"{gamma_star:.6g}" in out and "exact" in out


def test_gamma_command_monte_carlo_and_bad_problem(capsys):
    assert main(["gamma", "--problem", "maze", "--samples", "500", "--seed", "1"]) == 0
    assert "interval" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["gamma", "--problem", "nowhere"])
    assert "unknown problem 'nowhere'" in capsys.readouterr().err
