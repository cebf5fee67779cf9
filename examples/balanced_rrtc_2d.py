"""Plan through the narrow gap with BalancedRRTConnect via SimpleSetup; print the path and stats.

Run: python examples/balanced_rrtc_2d.py [--problem narrow_gap] [--time-limit 5]
"""

import argparse

from ompl import util as ou

from ompl_balance import BalancedRRTConnect
from ompl_balance.worlds.boxes import PROBLEMS, get_problem


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problem", choices=PROBLEMS, default="narrow_gap", help="built-in 2-D problem")
    parser.add_argument("--time-limit", type=float, default=5.0, help="seconds of planning (default 5)")
    args = parser.parse_args()
    if not args.time_limit > 0:
        parser.error(f"--time-limit must be a positive number of seconds, got {args.time_limit}")
    ou.setLogLevel(ou.LOG_WARN)

    problem = get_problem(args.problem)  # narrow_gap: a wall across the unit square with a gap 0.02 wide
    ss = problem.setup()  # og.SimpleSetup with a counting validity checker

    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.params().setParam("max_tree_size_ratio", "1.0")  # grow the smaller tree once it is < half the other
    ss.setPlanner(planner)

    status = ss.solve(args.time_limit)
    print(f"status: {status.asString()}")
    if ss.haveExactSolutionPath():
        path = ss.getSolutionPath()
        print(f"path: {path.getStateCount()} states, length {path.length():.3f}")
        for i in range(path.getStateCount()):
            state = path.getState(i)
            print(f"  ({state[0]:.3f}, {state[1]:.3f})")
    stats = planner.stats
    print(
        f"iterations {stats.iterations}, trees {stats.start_tree_size} start + {stats.goal_tree_size} goal, "
        f"{stats.tree_swaps} tree swaps, {stats.states_checked} states and {stats.motions_checked} motions checked, "
        f"{stats.time * 1e3:.1f} ms"
    )


if __name__ == "__main__":
    main()
