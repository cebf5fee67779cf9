"""OMPL's path simplification with certified motions: its time, each checkMotion's, and the budget's refusals.

Per problem and planner: one solve (``measured_solve``: 10 s for the Panda, the problem's own
limit for rigid bodies), then ``ss.simplifySolution(limit)`` timed. OMPL's simplifier always
runs one full pass (shortcuts, B-spline smoothing, ``reduceVertices``, ``collapseCloseVertices``)
whatever its limit, so it keeps the limit only if every ``checkMotion`` has a bounded cost. Every
``checkMotion`` that reaches the certified validator is timed by wrapping the validator's method:
stock RRT-Connect's planning and every simplification (BalancedRRTConnect's compiled engine calls
the validator's kernel directly; its motions are counted, not timed). Motions refused for the
work budget come from the checker's counters (``motions_over_budget``; none where a package
version has no budget). Planners: stock ``og.RRTConnect``, ``BalancedRRTConnect`` with its
defaults, and ``BalancedRRTConnect[max_tree_size_ratio=0.5;range=0.1]``, in turn on each
problem; MotionBenchMaker's four Panda scenarios (VAMP's Panda, all of a problem's goals) and
the shipped rigid-body problems. OMPL's seed is set once at the start.

Run: ``python benchmarks/bench_simplify.py [--problems 25] [--rigid-runs 3] [--limit 1] [--motion-budget N|none]``
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from cells import success
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect, validity
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.core.counting import measured_solve
from ompl_balance.validity import CollisionChecker, setup_robot
from ompl_balance.worlds.mbm import SCENARIOS, load_mbm
from ompl_balance.worlds.rigid import RIGID_PROBLEMS, rigid_problem


def balanced(**parameters: str) -> Callable[[Any], BalancedRRTConnect]:
    def make(si: Any) -> BalancedRRTConnect:
        planner = BalancedRRTConnect(si)
        for name, value in parameters.items():
            assert planner.params().setParam(name, value)
        return planner

    return make


PLANNERS: dict[str, Callable[[Any], Any]] = {
    "RRTConnect": og.RRTConnect,
    "BalancedRRTConnect": balanced(),
    "BalancedRRTConnect[max_tree_size_ratio=0.5;range=0.1]": balanced(max_tree_size_ratio="0.5", range="0.1"),
}

#: Seconds of every ``checkMotion`` that reached a certified validator, by phase.
CHECKS: dict[str, list[float]] = {"plan": [], "simplify": []}
PHASE = ["plan"]


def time_check_motion(cls: type) -> None:
    """Time every ``checkMotion`` of the validator class ``cls`` into :data:`CHECKS`."""
    check_motion = cls.checkMotion

    def timed(self: Any, s1: Any, s2: Any) -> bool:
        began = time.perf_counter()
        try:
            return check_motion(self, s1, s2)
        finally:
            CHECKS[PHASE[0]].append(time.perf_counter() - began)

    cls.checkMotion = timed


def refused(checker: Any) -> int:
    return checker.counters().get("motions_over_budget", 0)


def run(ss: og.SimpleSetup, checker: Any, make_planner: Callable[[Any], Any], time_limit: float, limit: float) -> dict:
    """One solve and, when it found a path, one timed simplification."""
    ss.setPlanner(make_planner(ss.getSpaceInformation()))
    PHASE[0] = "plan"
    before = checker.counters()
    solved = measured_solve(ss, time_limit).solved
    planned = checker.counters()
    result = {
        "solved": solved,
        "motions": planned["motions_checked"] - before["motions_checked"],
        "refused": refused(checker) - before.get("motions_over_budget", 0),
        "simplify": None,
        "simplify refused": 0,
    }
    if solved:
        PHASE[0] = "simplify"
        began = time.perf_counter()
        ss.simplifySolution(limit)
        result["simplify"] = time.perf_counter() - began
        result["simplify refused"] = refused(checker) - planned.get("motions_over_budget", 0)
    return result


def row(name: str, planner: str, runs: list[dict], limit: float) -> str:
    times = [r["simplify"] for r in runs if r["simplify"] is not None]
    motions, refusals = sum(r["motions"] for r in runs), sum(r["refused"] for r in runs)
    return (
        f"| {name} | {planner} | {success(runs):.0%} | {motions} | {refusals} ({refusals / max(motions, 1):.3%}) "
        f"| {statistics.median(times):.3f} | {max(times):.3f} | {sum(t > 1.5 * limit for t in times)} "
        f"| {sum(r['simplify refused'] for r in runs)} |"
    )


def check_times(label: str) -> str:
    cells = []
    for phase in ("plan", "simplify"):
        ms = np.array(CHECKS[phase]) * 1e3
        if len(ms):
            cells.append(
                f"{phase}: {len(ms)} checks, median {np.median(ms):.3f} ms, 99.9th percentile "
                f"{np.percentile(ms, 99.9):.1f} ms, max {ms.max():.1f} ms"
            )
        CHECKS[phase].clear()
    return f"checkMotion through the validator, {label}: " + "; ".join(cells)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", type=int, default=25, help="first N problems of each scenario (default 25)")
    parser.add_argument("--scenarios", default=",".join(SCENARIOS), help="comma-separated Panda scenarios")
    parser.add_argument("--rigid", default=",".join(RIGID_PROBLEMS), help="comma-separated rigid-body problems")
    parser.add_argument("--rigid-runs", type=int, default=3, help="runs per rigid-body problem and planner")
    parser.add_argument("--limit", type=float, default=1.0, help="simplifySolution's time limit (s, default 1)")
    parser.add_argument("--motion-budget", help="work units per motion check, or none (default: the package's)")
    args = parser.parse_args()
    budget: dict[str, int | None] = {}
    if args.motion_budget is not None:  # (passed only when asked: a version without a budget runs the default)
        budget["motion_budget"] = None if args.motion_budget == "none" else int(args.motion_budget)
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_ERROR)
    time_check_motion(validity.CertifiedMotionValidator)
    time_check_motion(validity.RigidBodyCertifiedMotionValidator)
    print(
        f"simplifySolution({args.limit:g}) after one solve per problem and planner; motion budget: "
        f"{budget.get('motion_budget', 'the default')}\n"
    )
    print(
        "| problems | planner | success | motions while planning | refused while planning | simplify median (s) "
        "| simplify max (s) | simplify over 1.5x the limit | refused while simplifying |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    robot = load_panda_vamp()
    for scenario in filter(None, args.scenarios.split(",")):
        results: dict[str, list[dict]] = {name: [] for name in PLANNERS}
        for problem in load_mbm(scenario, robot.joint_names)[: args.problems]:
            for name, make_planner in PLANNERS.items():
                checker = CollisionChecker(robot, problem.environment)
                ss = problem.simple_setup(robot, checker)
                if budget:
                    setup_robot(ss, checker, **budget)
                results[name].append(run(ss, checker, make_planner, 10.0, args.limit))
        for name, runs in results.items():
            print(row(scenario, name, runs, args.limit), flush=True)
    panda = check_times("Panda")
    for problem_name in filter(None, args.rigid.split(",")):
        problem = rigid_problem(problem_name)
        results = {name: [] for name in PLANNERS}
        for _ in range(args.rigid_runs):
            for name, make_planner in PLANNERS.items():
                if name.endswith("]"):  # (range=0.1 is a Panda setting)
                    continue
                checker = problem.checker(**budget)
                ss = problem.simple_setup(checker=checker)
                results[name].append(run(ss, checker, make_planner, problem.time_limit or 10.0, args.limit))
        for name, runs in results.items():
            if runs:
                print(row(problem_name, name, runs, args.limit), flush=True)
    print("\n" + panda)
    print(check_times("rigid bodies"))


if __name__ == "__main__":
    main()
