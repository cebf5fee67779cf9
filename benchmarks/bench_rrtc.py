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

Run: python benchmarks/bench_rrtc.py [--runs 30]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=30, help="runs per planner and problem (default 30)")
    parser.add_argument("--time-limit", type=float, default=30.0, help="seconds per run (default 30)")
    parser.add_argument(
        "--problems", default=",".join(PROBLEMS), help="comma-separated subset of " + ", ".join(PROBLEMS)
    )
    args = parser.parse_args()
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
        medians = {
            name: {key: statistics.median(r[key] for r in runs) for key in ("time", "checks", "motions")}
            for name, runs in results.items()
        }
        per_motion = {
            name: statistics.median(r["time"] / max(r["motions"], 1) for r in runs) for name, runs in results.items()
        }
        stock = medians["RRTConnect"]
        for name, runs in results.items():
            m = medians[name]
            success = sum(r["solved"] for r in runs) / len(runs)
            print(
                f"| {problem} | {name} | {success:.0%} | {m['time'] * 1e3:.1f} | {m['checks']:.0f} | {m['motions']:.0f} "
                f"| {m['time'] / stock['time']:.2f} | {m['checks'] / stock['checks']:.2f} "
                f"| {per_motion[name] / per_motion['RRTConnect']:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
