"""Stock og.RRTConnect and BalancedRRTConnect on MotionBenchMaker Panda problems, one run.

Both planners run through ``og.SimpleSetup`` with the package's collision checker and a
motion validator (``setup_robot(..., motion=...)``: ``certified``, the default, or
``discrete``) on the four dev scenarios (table_pick, table_under_pick, box,
bookshelf_small), VAMP's Panda model, all of a problem's goals as ``ob.GoalStates`` (any
goal is a success). Per scenario and planner it prints the success rate, the median time
(failed runs count with the time they took, i.e. the limit), the median states checked
and motions checked, and their ratios to stock RRTConnect. Planners alternate problem by
problem so the machine's slow phases hit both, after one untimed solve each (a process's
first use of a kernel loads it); ``BalancedRRTConnect`` on the compiled engine. Every
returned path is re-checked state by state with a fresh checker. (Certified against
discrete: ``bench_certified.py``.)

Run: ``python benchmarks/bench_mbm_rrtc.py [--problems 10] [--time-limit 10] [--motion certified]``
"""

from __future__ import annotations

import argparse

import numpy as np
from cells import medians, ratios, success
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect
from ompl_balance.bench.execution import seed_ompl
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.core.counting import measured_solve
from ompl_balance.validity import MOTION_VALIDATORS, CollisionChecker
from ompl_balance.worlds.mbm import SCENARIOS, load_mbm

PLANNERS = {"RRTConnect": og.RRTConnect, "BalancedRRTConnect": BalancedRRTConnect}


def solve(robot, problem, make_planner, time_limit: float, motion: str) -> dict:
    """One planning run; returns success, seconds, work counts and whether the path re-checks valid."""
    checker = CollisionChecker(robot, problem.environment)
    ss = problem.simple_setup(robot, checker, motion=motion)
    ss.setPlanner(make_planner(ss.getSpaceInformation()))
    run = measured_solve(ss, time_limit)
    path_valid = None
    if run.solved:
        path = ss.getSolutionPath()
        path.interpolate()  # states at the space's validity-checking resolution
        states = np.array([path.getState(i)[0 : robot.dof] for i in range(path.getStateCount())])
        path_valid = bool(CollisionChecker(robot, problem.environment).check(states).all())
    return {
        "solved": run.solved,
        "time": run.time,
        "checks": run.work.states_checked,
        "motions": run.work.motions_checked,
        "path_valid": path_valid,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--motion", choices=MOTION_VALIDATORS, default="certified", help="motion validator")
    parser.add_argument("--problems", type=int, default=10, help="first N problems of each scenario (default 10)")
    parser.add_argument("--time-limit", type=float, default=10.0, help="seconds per run (default 10)")
    parser.add_argument(
        "--scenarios", default=",".join(SCENARIOS), help="comma-separated subset of " + ", ".join(SCENARIOS)
    )
    args = parser.parse_args()
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_WARN)
    robot = load_panda_vamp()

    print(
        f"Panda (VAMP model), first {args.problems} problems per scenario, one run each, time limit "
        f"{args.time_limit:g} s, {args.motion} motions; ratios are to stock RRTConnect's medians\n"
    )
    print(
        "| scenario | planner | success | median time (ms) | median states checked | median motions "
        "| time ratio | checks ratio |"
    )
    print("|---|---|---|---|---|---|---|---|")
    # One untimed solve per planner first (a process's first use of a kernel loads it), then
    # OMPL's seed again, so that the timed runs draw what they draw without it.
    warm_up = load_mbm(args.scenarios.split(",")[0], robot.joint_names)[0]
    for make_planner in PLANNERS.values():
        solve(robot, warm_up, make_planner, args.time_limit, args.motion)
    seed_ompl(1)
    for scenario in args.scenarios.split(","):
        problems = load_mbm(scenario, robot.joint_names)[: args.problems]
        results = {name: [] for name in PLANNERS}
        for problem in problems:
            for name, make_planner in PLANNERS.items():
                result = solve(robot, problem, make_planner, args.time_limit, args.motion)
                if result["path_valid"] is False:
                    raise AssertionError(f"{scenario} problem {problem.id}: {name} returned a path in collision")
                results[name].append(result)
        cell = medians(results, ("time", "checks", "motions"))
        for name, runs in results.items():
            m, ratio = cell[name], ratios(cell[name], cell["RRTConnect"])
            print(
                f"| {scenario} | {name} | {success(runs):.0%} | {m['time'] * 1e3:.1f} | {m['checks']:.0f} "
                f"| {m['motions']:.0f} | {ratio['time']:.2f} | {ratio['checks']:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
