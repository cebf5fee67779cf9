"""The classroom RRT-Connect variants side by side on a 2-D problem (the bug trap by default).

Each preset is ``BalancedRRTConnect`` with a few policies set (see docs/variants.md);
the last run shows the same thing done by hand with ``setParam``. Prints, per planner,
the status, collision queries, nodes and tree swaps by cause.
Run: ``python examples/variants_2d.py [--problem bug_trap] [--time-limit 10]``.
"""

import argparse

from ompl import util as ou

from ompl_balance.planners import PRESETS, BalancedRRTConnect
from ompl_balance.samplers import GaussianValidStateSampler
from ompl_balance.worlds.boxes import PROBLEMS, get_problem


def report(planner, status) -> None:
    s = planner.stats
    print(
        f"{planner.getName():26s} {status!s:15s} queries {s.states_checked:6d}  "
        f"nodes {s.start_tree_size + s.goal_tree_size:5d}  swaps: alternate {s.swaps_alternate}, "
        f"balance {s.swaps_balance}, steps {s.swaps_steps}, collision {s.swaps_collision}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problem", choices=PROBLEMS, default="bug_trap", help="built-in 2-D problem")
    parser.add_argument("--time-limit", type=float, default=10.0, help="seconds of planning per planner (default 10)")
    args = parser.parse_args()
    if not args.time_limit > 0:
        parser.error(f"--time-limit must be a positive number of seconds, got {args.time_limit}")
    ou.setLogLevel(ou.LOG_WARN)

    for planner_class in PRESETS.values():
        ss = get_problem(args.problem).setup()
        planner = planner_class(ss.getSpaceInformation())
        ss.setPlanner(planner)
        report(planner, ss.solve(args.time_limit))

    # By hand: Gaussian samples near obstacles, tree balancing, skip nodes that failed 10 times.
    ss = get_problem(args.problem).setup()
    ss.getSpaceInformation().setValidStateSamplerAllocator(GaussianValidStateSampler)
    planner = BalancedRRTConnect(ss.getSpaceInformation(), name="GaussianExhaustedRRTConnect")
    planner.params().setParams(
        {
            "sample_policy": "valid_sampler",
            "balance_tree_sizes": "1",
            "nearest_policy": "exhausted",
            "exhausted_after": "10",
        }
    )
    ss.setPlanner(planner)
    report(planner, ss.solve(args.time_limit))


if __name__ == "__main__":
    main()
