"""The classroom RRT-Connect variants side by side on the 2-D bug trap.

Each preset is ``BalancedRRTConnect`` with a few policies set (see docs/variants.md);
the last run shows the same thing done by hand with ``setParam``. Prints, per planner,
the status, collision queries, nodes and tree swaps by cause.
Run: ``python examples/variants_2d.py``.
"""

from ompl import util as ou

from ompl_balance.planners import PRESETS, BalancedRRTConnect
from ompl_balance.samplers import GaussianValidStateSampler
from ompl_balance.worlds.boxes import get_problem

ou.setLogLevel(ou.LOG_WARN)


def report(planner, status) -> None:
    s = planner.stats
    print(
        f"{planner.getName():26s} {status!s:15s} queries {s.states_checked:6d}  "
        f"nodes {s.start_tree_size + s.goal_tree_size:5d}  swaps: alternate {s.swaps_alternate}, "
        f"balance {s.swaps_balance}, steps {s.swaps_steps}, collision {s.swaps_collision}"
    )


for planner_class in PRESETS.values():
    ss = get_problem("bug_trap").setup()
    planner = planner_class(ss.getSpaceInformation())
    ss.setPlanner(planner)
    report(planner, ss.solve(10.0))

# By hand: Gaussian samples near obstacles, tree balancing, skip nodes that failed 10 times.
ss = get_problem("bug_trap").setup()
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
report(planner, ss.solve(10.0))
