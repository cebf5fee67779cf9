"""BallRadiusRRTstar against stock og.RRTstar on the same radius schedule, measured in one run.

Problem: the built-in ``rooms`` occupancy map (R^2, 40 m x 40 m), every validity check
padded to ``--check-us`` microseconds of busy work (default 20, what a real collision
checker costs). Both planners get ``eta = --eta`` m, goal bias 0.05 and the ball-radius
constant gamma* of the map's exact free area; stock ``og.RRTstar`` is put on the same
radius schedule with :func:`ompl_balance.gamma.ompl_rewire_factor` (radius mode,
``rewire_factor`` from the derivation, ``range = eta``). Runs are interleaved.

Prints medians over ``--runs`` runs and ratios ours / stock of

* equal iterations (``--iterations``): time per 1000 iterations, validity checks per
  iteration, best cost;
* equal wall time (``--seconds``): best cost, iterations done.

Run: python benchmarks/bench_rrtstar.py [--runs 3] [--iterations 1000] [--seconds 3]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ompl_balance.core.counting import read_work
from ompl_balance.gamma import ball_radius_constant, ompl_rewire_factor
from ompl_balance.rrtstar import BallRadiusRRTstar
from ompl_balance.worlds.occupancy import OccupancyGrid, OccupancyProblem, rooms_problem


class PaddedGridChecker(ob.StateValidityChecker):
    """The grid test plus ``cost_ns`` of busy work per state, counting states."""

    def __init__(self, si: ob.SpaceInformation, grid: OccupancyGrid, cost_ns: int) -> None:
        super().__init__(si)
        self._grid, self._cost_ns = grid, cost_ns
        self.states_checked = 0

    def isValid(self, state) -> bool:
        self.states_checked += 1
        deadline = time.perf_counter_ns() + self._cost_ns
        while time.perf_counter_ns() < deadline:
            pass
        return self._grid.is_free(state[0], state[1])

    def counters(self) -> dict[str, int]:
        return {"states_checked": self.states_checked}


def padded_setup(problem: OccupancyProblem, cost_ns: int) -> og.SimpleSetup:
    ss = problem.setup()
    si = ss.getSpaceInformation()
    si.setStateValidityChecker(PaddedGridChecker(si, problem.grid, cost_ns))
    return ss


def run(
    kind: str, problem: OccupancyProblem, gamma: float, eta: float, cost_ns: int, iterations: int, seconds: float
) -> dict:
    """One run of ``kind`` ("ours"/"stock") stopped after ``iterations`` (if > 0) or ``seconds``."""
    ss = padded_setup(problem, cost_ns)
    si = ss.getSpaceInformation()
    if kind == "ours":
        planner = BallRadiusRRTstar(si)
        planner.setBallRadiusConstant(gamma)
        planner.setRange(eta)
        planner.setMaxIterations(iterations)
        planner.setMaxNodes(0)
        count_iterations = None
    else:
        planner = og.RRTstar(si)
        planner.setRange(eta)
        planner.setGoalBias(0.05)
        ompl_rewire_factor(si, gamma, planner)
        count_iterations = planner.numIterations
    ss.setPlanner(planner)
    ss.setup()
    before = read_work(si)
    began = time.perf_counter()
    if iterations > 0 and count_iterations is not None:
        ss.solve(ob.PlannerTerminationCondition(lambda: count_iterations() >= iterations))
    else:
        ss.solve(seconds if iterations == 0 else 3600.0)
    elapsed = time.perf_counter() - began
    done = planner.stats.iterations if kind == "ours" else planner.numIterations()
    pdef = ss.getProblemDefinition()
    cost = ss.getSolutionPath().length() if pdef.hasExactSolution() else math.inf
    return {"time": elapsed, "iterations": done, "checks": (read_work(si) - before).states_checked, "cost": cost}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--iterations", type=int, default=1000)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--eta", type=float, default=4.0)
    parser.add_argument("--check-us", type=float, default=20.0)
    args = parser.parse_args()
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_WARN)

    problem = rooms_problem()
    gamma = ball_radius_constant(2, problem.grid.free_area)
    cost_ns = round(args.check_us * 1000)
    print(f"rooms (R^2, 40 m x 40 m), gamma* = {gamma:.1f} m^2, eta = {args.eta} m, check padded to {args.check_us} us")

    equal_iterations = {"ours": [], "stock": []}
    equal_time = {"ours": [], "stock": []}
    for _ in range(args.runs):
        for kind in ("stock", "ours"):
            equal_iterations[kind].append(run(kind, problem, gamma, args.eta, cost_ns, args.iterations, args.seconds))
            equal_time[kind].append(run(kind, problem, gamma, args.eta, cost_ns, 0, args.seconds))

    def median(records, key, per_iteration=False):
        return statistics.median(r[key] / r["iterations"] if per_iteration else r[key] for r in records)

    print(f"\nequal iterations ({args.iterations}), medians of {args.runs} runs")
    print(f"{'':10}{'s/1000 it':>12}{'checks/it':>12}{'best cost':>12}")
    rows = {}
    for kind in ("stock", "ours"):
        records = equal_iterations[kind]
        rows[kind] = (1000 * median(records, "time", True), median(records, "checks", True), median(records, "cost"))
        print(f"{kind:10}{rows[kind][0]:12.3f}{rows[kind][1]:12.1f}{rows[kind][2]:12.2f}")
    ratios = [ours / stock for ours, stock in zip(rows["ours"], rows["stock"])]
    print(f"{'ratio':10}{ratios[0]:12.2f}{ratios[1]:12.2f}{ratios[2]:12.3f}   (ours / stock)")

    print(f"\nequal wall time ({args.seconds} s), medians of {args.runs} runs")
    print(f"{'':10}{'iterations':>12}{'best cost':>12}")
    rows = {}
    for kind in ("stock", "ours"):
        records = equal_time[kind]
        rows[kind] = (median(records, "iterations"), median(records, "cost"))
        print(f"{kind:10}{rows[kind][0]:12.0f}{rows[kind][1]:12.2f}")
    print(
        f"{'ratio':10}{rows['ours'][0] / rows['stock'][0]:12.2f}{rows['ours'][1] / rows['stock'][1]:12.3f}   (ours / stock)"
    )


if __name__ == "__main__":
    main()
