"""BalancedRRTConnect against stock og.RRTConnect, measured in one run.

Prints, per problem, median time, median validity checks, median motions checked and
success for stock ``og.RRTConnect``, ``BalancedRRTConnect`` and ``BalancedRRTConnect``
with balancing off, each with its ratio to stock (same ``SpaceInformation`` setup,
runs interleaved so the machine's slow phases hit all planners alike):

* ``bug_trap``: the built-in 2-D bug trap (checks cost ~1 us);
* ``shell7d``: a 7-D cube whose start sits inside a spherical shell with one opening
  facing away from the goal; each validity check is padded to ~20 us of busy work, as
  a real collision checker would cost;
* ``shell7d-free``: the same problem with no padding, to measure planner overhead:
  time per motion checked (every iteration checks at least one motion) of ours over
  stock's.

With ``--scans``, instead: how the tree scans' loading pays off (``ompl_balance.core.trees``).
Each run is a fresh process solving an impossible problem (a wall across the unit
cube, 2-D and 7-D, free checks) for ``--seconds``; per scan mode, the median iterations
and nodes (both trees) reached and the solve's wall time:

* ``numpy``: numpy scans whatever the tree size (the kernels never load);
* ``compiled``: the kernels loaded before the solve, used from the first node (the cost
  every planner's ``setup()`` used to pay inside ``SimpleSetup.solve``, not counted here);
* ``default``: numpy scans, and the kernels loaded in the background once a tree reaches
  ``COMPILED_SCANS_FROM`` nodes, then used.

Run: python benchmarks/bench_rrtc.py [--runs 30]
     python benchmarks/bench_rrtc.py --scans [--runs 5] [--seconds 2,5]
"""

from __future__ import annotations

import argparse
import math
import statistics
import subprocess
import sys
import time

from cells import medians, ratios, success
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect, CountingValidityChecker
from ompl_balance.core.counting import measured_solve
from ompl_balance.worlds.boxes import get_problem

DIM = 7
CHECK_COST_NS = 20_000


def shell_is_free(values, inner=0.3, outer=0.4, opening_cos=0.9) -> bool:
    """Free unless inside the shell inner <= |x| <= outer, except the cone around -x."""
    radius_sq = sum(v * v for v in values)
    if radius_sq < inner * inner or radius_sq > outer * outer:
        return True
    return -values[0] / math.sqrt(radius_sq) > opening_cos


def shell7d_setup(padded: bool) -> og.SimpleSetup:
    space = ob.RealVectorStateSpace(DIM)
    space.setBounds(-1.0, 1.0)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()

    def is_valid(state) -> bool:
        if padded:
            deadline = time.perf_counter_ns() + CHECK_COST_NS
            while time.perf_counter_ns() < deadline:
                pass
        return shell_is_free([state[i] for i in range(DIM)])

    si.setStateValidityChecker(CountingValidityChecker(si, is_valid))
    start, goal = space.allocState(), space.allocState()
    for i in range(DIM):
        start[i], goal[i] = 0.0, 0.0
    goal[0] = 0.8
    ss.setStartAndGoalStates(start, goal)
    return ss


PROBLEMS = {
    "bug_trap": lambda: get_problem("bug_trap").setup(),
    "shell7d": lambda: shell7d_setup(padded=True),
    "shell7d-free": lambda: shell7d_setup(padded=False),
}


def balanced(balance: bool):
    def make(si):
        planner = BalancedRRTConnect(si)
        planner.setBalanceTreeSizes(balance)
        return planner

    return make


PLANNERS = {
    "RRTConnect": og.RRTConnect,
    "BalancedRRTConnect": balanced(True),
    "BalancedRRTConnect[balance=0]": balanced(False),
}


def run(make_setup, make_planner, time_limit: float) -> dict:
    ss = make_setup()
    ss.setPlanner(make_planner(ss.getSpaceInformation()))
    run = measured_solve(ss, time_limit)
    return {
        "solved": run.solved,
        "time": run.time,
        "checks": run.work.states_checked,
        "motions": run.work.motions_checked,
    }


SCAN_RUN = """
import sys, time
from ompl import base as ob, geometric as og, util as ou
ou.setLogLevel(ou.LOG_ERROR)
from ompl_balance import BalancedRRTConnect
from ompl_balance.core import trees
mode, seconds, dim = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
if mode == "numpy":
    trees.COMPILED_SCANS_FROM = 10**12
elif mode == "compiled":
    trees.load_scans()
    trees.COMPILED_SCANS_FROM = 0
space = ob.RealVectorStateSpace(dim)
space.setBounds(0.0, 1.0)
ss = og.SimpleSetup(space)
ss.setStateValidityChecker(lambda state: not 0.45 < state[0] < 0.55)
start, goal = space.allocState(), space.allocState()
for i in range(dim):
    start[i] = goal[i] = 0.5
start[0], goal[0] = 0.1, 0.9
ss.setStartAndGoalStates(start, goal)
planner = BalancedRRTConnect(ss.getSpaceInformation())
planner.setSeed(3)
ss.setPlanner(planner)
began = time.perf_counter()
ss.solve(seconds)
stats = planner.stats
print(time.perf_counter() - began, stats.iterations, stats.start_tree_size + stats.goal_tree_size)
"""

SCAN_MODES = ("numpy", "compiled", "default")


def scans_main(runs: int, seconds: list[float]) -> None:
    """The ``--scans`` table (see the module docstring)."""
    from ompl_balance.core.trees import COMPILED_SCANS_FROM

    print(
        f"{runs} fresh processes per cell (modes interleaved); impossible problem; "
        f"COMPILED_SCANS_FROM = {COMPILED_SCANS_FROM}\n"
    )
    print("| dim | seconds | mode | median iterations | median nodes | median solve time (s) | iterations x numpy |")
    print("|---|---|---|---|---|---|---|")
    for dim in (2, 7):
        for limit in seconds:
            results: dict[str, list[list[float]]] = {mode: [] for mode in SCAN_MODES}
            for _ in range(runs):
                for mode in SCAN_MODES:
                    out = subprocess.run(
                        [sys.executable, "-c", SCAN_RUN, mode, str(limit), str(dim)],
                        capture_output=True,
                        text=True,
                        check=True,
                    ).stdout.split()
                    results[mode].append([float(value) for value in out])
            medians = {mode: [statistics.median(column) for column in zip(*rows)] for mode, rows in results.items()}
            for mode in SCAN_MODES:
                elapsed, iterations, nodes = medians[mode]
                ratio = iterations / medians["numpy"][1]
                print(
                    f"| {dim} | {limit:g} | {mode} | {iterations:.0f} | {nodes:.0f} | {elapsed:.3f} | {ratio:.2f} |",
                    flush=True,
                )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=None, help="runs per cell (default 30; 5 with --scans)")
    parser.add_argument("--time-limit", type=float, default=30.0, help="seconds per run (default 30)")
    parser.add_argument(
        "--problems", default=",".join(PROBLEMS), help="comma-separated subset of " + ", ".join(PROBLEMS)
    )
    parser.add_argument("--scans", action="store_true", help="measure the tree scans' loading instead")
    parser.add_argument("--seconds", default="1,2,5", help="--scans: comma-separated solve times (default 1,2,5)")
    args = parser.parse_args()
    if args.scans:
        scans_main(args.runs or 5, [float(value) for value in args.seconds.split(",")])
        return
    args.runs = args.runs or 30
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_WARN)

    print(f"{args.runs} runs per cell, time limit {args.time_limit:g} s; ratios are to stock RRTConnect's medians\n")
    print(
        "| problem | planner | success | median time (ms) | median checks | median motions | time ratio | checks ratio | time per motion ratio |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for problem in args.problems.split(","):
        results = {name: [] for name in PLANNERS}
        for _ in range(args.runs):
            for name, make_planner in PLANNERS.items():
                results[name].append(run(PROBLEMS[problem], make_planner, args.time_limit))
        for runs in results.values():
            for r in runs:
                r["time per motion"] = r["time"] / max(r["motions"], 1)
        cell = medians(results, ("time", "checks", "motions", "time per motion"))
        for name, runs in results.items():
            m, ratio = cell[name], ratios(cell[name], cell["RRTConnect"])
            print(
                f"| {problem} | {name} | {success(runs):.0%} | {m['time'] * 1e3:.1f} | {m['checks']:.0f} "
                f"| {m['motions']:.0f} | {ratio['time']:.2f} | {ratio['checks']:.2f} | {ratio['time per motion']:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
