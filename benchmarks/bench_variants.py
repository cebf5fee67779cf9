"""The classroom RRT-Connect variants (PRESETS) against stock og.RRTConnect, in one run.

Per problem and planner: the engine its runs took (``compiled`` or ``python`` for the
package's planners, each run on the engine it will use, as ``ompl-balance bench`` runs them;
``C++`` for stock), success, median time, median collision queries (states the
validity checker decided, including those inside motion checks and inside a valid-state
sampler: one counter, no double counting), median nodes (both trees; stock's from
``getPlannerData``), each with its ratio to stock RRTConnect's median in the same run.
Runs are interleaved (run i of every planner, then run i + 1) so slow phases of the
shared machine hit all planners alike.

Then, per preset, the collision-query ratio to plain RRT-Connect that the TU Berlin lab
report "RRT Extensions" (2020) measured (their 6-DOF problem, 10 runs, averages) next to
ours on each problem, and on how many of our problems the change goes the report's way:
each ratio read as "fewer" (< 0.9), "same" (0.9 to 1.1) or "more" (> 1.1) queries.

Problems: the built-in 2-D suite (``ompl_balance.worlds.boxes``), ``twin_pockets`` (start and
goal in pockets that open away from each other: every way out leaves the goal ball of
``ControlChosenRRTConnect``) and ``circle`` (SO(2), an obstacle between 0.5 and 1.0 rad,
start 0, goal 1.5: the way goes round the far side, where no obstacle is near). With
``--mbm N``, also the first N problems of each shipped MotionBenchMaker Panda scenario with
VAMP's Panda, the package's checker and certified motions (``--mbm 3``: about a minute).

Run: python benchmarks/bench_variants.py [--runs 20] [--time-limit 10] [--mbm 0] [--planners ...]
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

from cells import medians, ratios, success
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ompl_balance.core.counting import measured_solve
from ompl_balance.planners import PRESETS
from ompl_balance.worlds.boxes import PROBLEMS, TWIN_POCKETS, circle_setup

#: The report's averages: (time s, nodes, collision queries); "plain" is RRT-Connect.
REPORT = {
    "plain": (39.4, 11660, 579757),
    "SwapLimitRRTConnect": (3.7, 1866, 45541),
    "CollisionSwapRRTConnect": (21.6, 10732, 536918),
    "ExhaustedNodesRRTConnect": (54.2, 12813, 604321),
    "ExhaustionRRTConnect": (31.3, 9700, 478535),
    "NeighbourCostRRTConnect": (29.7, 13372, 658073),
    "GaussianPassageRRTConnect": (29.0, 9419, 481298),
    "ControlChosenRRTConnect": (23.3, 12862, 282697),
    "GoalBiasRRTConnect": (29.5, 8309, 457102),
}

PLANNERS = {"RRTConnect": og.RRTConnect, **PRESETS}


def strict(preset: str) -> Callable[[ob.SpaceInformation], ob.Planner]:
    """``preset`` with ``uniform_rate = 0``: targets from its sample policy only."""

    def make(si: ob.SpaceInformation) -> ob.Planner:
        planner = PRESETS[preset](si)
        planner.setUniformRate(0.0)
        return planner

    return make


#: Run only when named in ``--planners``.
STRICT = {
    f"{name}[uniform_rate=0]": strict(name)
    for name in ("NeighbourCostRRTConnect", "GaussianPassageRRTConnect", "ControlChosenRRTConnect")
}

#: A ratio within this band of 1 reads as "same": differences of less than 10 %.
SAME_BAND = 0.1

SETUPS: dict[str, Callable[[], og.SimpleSetup]] = {
    **{name: problem.setup for name, problem in PROBLEMS.items()},
    "twin_pockets": TWIN_POCKETS.setup,
    "circle": circle_setup,
}


def effect(ratio: float) -> str:
    """ "fewer", "same" or "more" (collision queries than the reference)."""
    if ratio < 1 - SAME_BAND:
        return "fewer"
    return "more" if ratio > 1 + SAME_BAND else "same"


def mbm_problems(count: int) -> dict[str, Callable[[], og.SimpleSetup]]:
    """``name -> make_setup`` for the first ``count`` problems of each shipped Panda scenario."""
    from ompl_balance.collision.robots import load_panda_vamp
    from ompl_balance.validity import CollisionChecker
    from ompl_balance.worlds.mbm import SCENARIOS, load_mbm

    robot = load_panda_vamp()
    problems = {}
    for scenario in SCENARIOS:
        for problem in load_mbm(scenario, robot.joint_names)[:count]:
            checker = CollisionChecker(robot, problem.environment)

            def make_setup(problem=problem, checker=checker):
                return problem.simple_setup(robot, checker)

            problems[f"{problem.scenario}#{problem.id}"] = make_setup
    return problems


def run(make_setup, make_planner, time_limit: float) -> dict:
    """One solve (set up outside the timing; the package's planners on the engine they will
    use for every run, as ``ompl-balance bench`` runs them) and its work."""
    ss = make_setup()
    si = ss.getSpaceInformation()
    planner = make_planner(si)
    ss.setPlanner(planner)
    run = measured_solve(ss, time_limit)
    stats = getattr(planner, "stats", None)
    if stats is not None:
        nodes, engine = stats.start_tree_size + stats.goal_tree_size, stats.engine
    else:
        data = ob.PlannerData(si)
        ss.getPlannerData(data)
        nodes, engine = data.numVertices(), "C++"
    return {
        "solved": run.solved,
        "time": run.time,
        "queries": run.work.states_checked,
        "nodes": nodes,
        "engine": engine,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=20, help="runs per planner and problem (default 20)")
    parser.add_argument("--time-limit", type=float, default=10.0, help="seconds per run (default 10)")
    parser.add_argument(
        "--problems",
        default=",".join(SETUPS),
        help="comma-separated subset of " + ", ".join(SETUPS) + " ('' for none)",
    )
    parser.add_argument(
        "--planners",
        default=",".join(PLANNERS),
        help="comma-separated subset of "
        + ", ".join([*PLANNERS, *STRICT])
        + " (default: all but the [uniform_rate=0] ones; RRTConnect, the reference, always runs)",
    )
    parser.add_argument(
        "--mbm", type=int, default=0, help="also the first N problems of each MBM Panda scenario (default 0)"
    )
    args = parser.parse_args()
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_NONE)

    problems = {name: SETUPS[name] for name in args.problems.split(",") if name}
    if args.mbm > 0:
        problems.update(mbm_problems(args.mbm))
    chosen = {"RRTConnect", *args.planners.split(",")}
    planners = {name: make for name, make in {**PLANNERS, **STRICT}.items() if name in chosen}

    print(f"{args.runs} runs per cell, time limit {args.time_limit:g} s; ratios are to stock RRTConnect's medians\n")
    print(
        "| problem | planner | engine | success | median time (ms) | median collision queries | median nodes "
        "| time ratio | queries ratio | nodes ratio |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    query_ratios: dict[str, dict[str, float]] = {name: {} for name in planners}
    for problem, make_setup in problems.items():
        results: dict[str, list[dict]] = {name: [] for name in planners}
        for _ in range(args.runs):
            for name, make_planner in planners.items():
                results[name].append(run(make_setup, make_planner, args.time_limit))
        cell = medians(results, ("time", "queries", "nodes"))
        for name, runs in results.items():
            m, ratio = cell[name], ratios(cell[name], cell["RRTConnect"])
            query_ratios[name][problem] = ratio["queries"]
            engines = "/".join(sorted({r["engine"] for r in runs}))
            print(
                f"| {problem} | {name} | {engines} | {success(runs):.0%} | {m['time'] * 1e3:.1f} | {m['queries']:.0f} "
                f"| {m['nodes']:.0f} | {ratio['time']:.2f} | {ratio['queries']:.2f} | {ratio['nodes']:.2f} |",
                flush=True,
            )

    print('\n"RRT Extensions" (2020): collision-query ratio to plain RRT-Connect, the report\'s and ours\n')
    print("| preset | report | " + " | ".join(problems) + " | goes the report's way |")
    print("|---|---|" + "---|" * len(problems) + "---|")
    for name in planners:
        if name not in REPORT:
            continue
        report = REPORT[name][2] / REPORT["plain"][2]
        ours = [query_ratios[name][problem] for problem in problems]
        agree = sum(effect(ratio) == effect(report) for ratio in ours)
        cells = " | ".join(f"{ratio:.2f} ({effect(ratio)})" for ratio in ours)
        print(f"| {name} | {report:.2f} ({effect(report)}) | {cells} | {agree} of {len(ours)} |")


if __name__ == "__main__":
    main()
