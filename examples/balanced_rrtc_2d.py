"""Plan through the narrow gap with BalancedRRTConnect via SimpleSetup; print the path and stats.

Run: python examples/balanced_rrtc_2d.py
"""

from ompl import util as ou

from ompl_balance import BalancedRRTConnect
from ompl_balance.worlds.boxes import get_problem

ou.setLogLevel(ou.LOG_WARN)

problem = get_problem("narrow_gap")  # a wall across the unit square with a gap 0.02 wide
ss = problem.setup()  # og.SimpleSetup with a counting validity checker

planner = BalancedRRTConnect(ss.getSpaceInformation())
planner.params().setParam("max_tree_size_ratio", "1.0")  # grow the smaller tree once it is < half the other
ss.setPlanner(planner)

status = ss.solve(5.0)
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
