"""Certified against discrete motion validation: planning on MotionBenchMaker Panda problems.

Stock ``og.RRTConnect`` and ``BalancedRRTConnect`` plan on the four dev scenarios
(table_pick, table_under_pick, box, bookshelf_small; VAMP's Panda, all of a problem's
goals as ``ob.GoalStates``) through ``og.SimpleSetup`` with the package's checker and
either motion validator: ``setup_robot(ss, checker, motion="certified")`` (the default)
or ``motion="discrete"`` (OMPL's discrete states, ``validSegmentCount`` per edge). Both
validators run on the same problems and runs, alternating, in one process, after one untimed
solve of each planner with each validator (a process's first use of a kernel loads it);
``BalancedRRTConnect`` on the compiled engine.

Every returned path is re-checked independently: a fresh checker without pre-filter
(``prefilter=False``: FCL on every pair, no spheres, hulls or tables) at states at most
``--step`` rad apart in every joint along each segment (default 0.005 rad). Per
scenario, planner and validator it prints the success rate, the median planning time
(failed runs count with their time, i.e. the limit), how many returned paths collide in
the re-check, the median number of edges checked per run, the planning time per edge
checked, the work per edge (configurations evaluated; distance queries: GJK bounds on
convex hulls and FCL distances), and the ratios certified / discrete of the median times
and of the total planning time.

Run: ``python benchmarks/bench_certified.py [--problems 10] [--runs 3] [--time-limit 10]
[--scenarios table_pick,box] [--step 0.005]``
"""

from __future__ import annotations

import argparse
import itertools
import platform
import statistics
import time
from importlib import metadata

import numpy as np
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect
from ompl_balance.bench.execution import seed_ompl
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.core.counting import measured_solve
from ompl_balance.worlds.mbm import SCENARIOS, MBMProblem, load_mbm

PLANNERS = {"RRTConnect": og.RRTConnect, "BalancedRRTConnect": BalancedRRTConnect}
VALIDATORS = ("certified", "discrete")


def dense_collisions(reference: CollisionChecker, states: np.ndarray, step: float) -> int:
    """Number of segments of the path ``states`` (n, dof) with a colliding state at most ``step`` apart."""
    colliding = 0
    for a, b in itertools.pairwise(states):
        count = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        t = np.arange(count + 1) / count
        if not reference.check(a + t[:, None] * (b - a)).all():
            colliding += 1
    return colliding


def solve(robot, problem: MBMProblem, planner: str, motion: str, time_limit: float, step: float) -> dict:
    """One planning run and the dense re-check of its path."""
    checker = CollisionChecker(robot, problem.environment)
    ss = problem.simple_setup(robot, checker, motion=motion)
    ss.setPlanner(PLANNERS[planner](ss.getSpaceInformation()))
    run = measured_solve(ss, time_limit)
    colliding = None
    if run.solved:
        path = ss.getSolutionPath()
        states = np.array([path.getState(i)[0 : robot.dof] for i in range(path.getStateCount())])
        colliding = dense_collisions(CollisionChecker(robot, problem.environment, prefilter=False), states, step)
    return {
        "solved": run.solved,
        "time": run.time,
        "motions": run.work.motions_checked,
        "states": run.work.states_checked,
        "distances": run.work.distance_queries,
        "colliding": colliding,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", type=int, default=10, help="first N problems of each scenario (default 10)")
    parser.add_argument("--runs", type=int, default=3, help="runs per problem, planner and validator (default 3)")
    parser.add_argument("--time-limit", type=float, default=10.0, help="seconds per run (default 10)")
    parser.add_argument("--step", type=float, default=0.005, help="re-check resolution, rad per joint (default 0.005)")
    parser.add_argument(
        "--scenarios", default=",".join(SCENARIOS), help="comma-separated subset of " + ", ".join(SCENARIOS)
    )
    args = parser.parse_args()
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_ERROR)
    robot = load_panda_vamp()
    began = time.perf_counter()
    print(
        f"VAMP's Panda, first {args.problems} problems per scenario, {args.runs} runs each, "
        f"{args.time_limit:g} s limit; re-check every {args.step:g} rad (FCL, no pre-filter); "
        f"Python {platform.python_version()}, ompl {metadata.version('ompl')}\n"
    )
    print(
        "| scenario | planner | validator | success | median time (ms) | colliding paths | median edges "
        "| time / edge (us) | states / edge | distance queries / edge | time ratio (median) | time ratio (total) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    # One untimed solve per planner and validator first: a process's first use of a kernel loads
    # it from numba's cache (or, after an update, compiles it), which is no solve's time. Then
    # OMPL's seed again, so that the timed runs draw what they draw without the warm-up.
    warm_up = load_mbm(args.scenarios.split(",")[0], robot.joint_names)[0]
    for planner in PLANNERS:
        for motion in VALIDATORS:
            solve(robot, warm_up, planner, motion, args.time_limit, args.step)
    seed_ompl(1)
    totals: dict[tuple[str, str], list[dict]] = {}
    for scenario in args.scenarios.split(","):
        problems = load_mbm(scenario, robot.joint_names)[: args.problems]
        results: dict[tuple[str, str], list[dict]] = {(p, v): [] for p in PLANNERS for v in VALIDATORS}
        for problem in problems:
            for _run in range(args.runs):
                for planner in PLANNERS:
                    for motion in VALIDATORS:
                        results[planner, motion].append(
                            solve(robot, problem, planner, motion, args.time_limit, args.step)
                        )
        for (planner, motion), runs in results.items():
            totals.setdefault((planner, motion), []).extend(runs)
        for planner in PLANNERS:
            discrete = results[planner, "discrete"]
            for motion in VALIDATORS:
                print(_row(scenario, planner, motion, results[planner, motion], discrete), flush=True)
    for planner in PLANNERS:
        for motion in VALIDATORS:
            print(_row("all", planner, motion, totals[planner, motion], totals[planner, "discrete"]))
    print(f"\nwhole script: {time.perf_counter() - began:.0f} s")


def _row(scenario: str, planner: str, motion: str, runs: list[dict], discrete: list[dict]) -> str:
    solved = [r for r in runs if r["solved"]]
    median = statistics.median(r["time"] for r in runs)
    motions = max(1, sum(r["motions"] for r in runs))
    colliding = sum(1 for r in solved if r["colliding"])
    ratio_median = median / statistics.median(r["time"] for r in discrete)
    ratio_total = sum(r["time"] for r in runs) / sum(r["time"] for r in discrete)
    return (
        f"| {scenario} | {planner} | {motion} | {len(solved)}/{len(runs)} | {median * 1e3:.1f} "
        f"| {colliding}/{len(solved)} | {statistics.median(r['motions'] for r in runs):.0f} "
        f"| {sum(r['time'] for r in runs) / motions * 1e6:.0f} | {sum(r['states'] for r in runs) / motions:.1f} "
        f"| {sum(r['distances'] for r in runs) / motions:.2f} | {ratio_median:.2f} | {ratio_total:.2f} |"
    )


if __name__ == "__main__":
    main()
