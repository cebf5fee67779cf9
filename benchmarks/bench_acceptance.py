"""OMPL's planner acceptance test (2denvs.cpp) for every package planner, next to stock.

Runs the harness of ``tests/acceptance.py`` (the port of OMPL's
``tests/geometric/2d/2denvs.cpp``) for stock ``og.RRTConnect``, stock ``og.RRTstar`` (the
control for the package's RRT*) and every planner the package exports, interleaved run
by run in one process, and prints a markdown table: per planner and test, success rate, average time per run/query (solve + simplify, OMPL's
average), average path length, the time ratio to stock from the same run, and whether
OMPL's thresholds (>= 95 %, < 2 x 0.01 s x MACHINE_SPEED_FACTOR, length < 100) are met.

A second table splits each planner's circles time: the seconds spent inside the
validity checker (timed per call, so it includes ~0.2 us of timing per check) against
the rest, during solve and during simplification, plus checks and iterations per query.
It runs each planner on its own (not interleaved), after the main table.

Run: python benchmarks/bench_acceptance.py [--map-runs 100] [--queries 100] [--no-breakdown]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ompl import util as ou

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from acceptance import (
    MACHINE_SPEED_FACTOR,
    MAP_RUNS,
    STOCK,
    STOCK_RRT_STAR,
    Outcome,
    package_planners,
    run_2d_circles_test,
    run_2d_map_test,
)

from ompl_balance.worlds.ompl_2d import RESOURCES, Circles2D, load_circles, load_environment, load_queries


class TimedCircles(Circles2D):
    """The circles checker, adding up the seconds its calls take (for the breakdown)."""

    def __init__(self, circles: Circles2D) -> None:
        super().__init__(list(circles.circles))
        self.seconds = 0.0

    def __call__(self, state) -> bool:
        began = time.perf_counter()
        free = self.no_overlap(state[0], state[1])
        self.seconds += time.perf_counter() - began
        return free


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:.1f}"


def results_table(map_outcomes: list[Outcome], circles_outcomes: list[Outcome]) -> str:
    stock_circles = circles_outcomes[0]
    lines = [
        "| planner | map: success | map: avg time (ms) | map: avg length | circles: success "
        "| circles: avg time (ms) = solve + simplify | x stock | circles: CPU ms (x stock) | circles: avg length "
        "| OMPL's thresholds |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for on_map, on_circles in zip(map_outcomes, circles_outcomes):
        unmet = [f"map: {text}" for text in on_map.unmet()] + [f"circles: {text}" for text in on_circles.unmet()]
        faults = len(on_map.faulty_paths) + len(on_circles.faulty_paths)
        if faults:
            unmet.append(f"{faults} paths fail the re-check")
        lines.append(
            f"| {on_map.planner} | {on_map.success:.0f} % | {_ms(on_map.avg_time)} | {on_map.avg_length:.1f} "
            f"| {on_circles.success:.0f} % | {_ms(on_circles.avg_time)} = {_ms(on_circles.solve_time / on_circles.runs)}"
            f" + {_ms(on_circles.simplify_time / on_circles.runs)} | {on_circles.avg_time / stock_circles.avg_time:.2f} "
            f"| {_ms(on_circles.avg_cpu_time)} ({on_circles.avg_cpu_time / stock_circles.avg_cpu_time:.2f}) "
            f"| {on_circles.avg_length:.1f} | {'met' if not unmet else 'NOT met: ' + '; '.join(unmet)} |"
        )
    return "\n".join(lines)


def breakdown_table(entries, circles: Circles2D, queries) -> str:
    lines = [
        "| planner | solve ms/query: checker + rest | simplify ms/query: checker + rest "
        "| checks/query: solve + simplify | us/check | iterations/query | planner us/iteration (excl. checker) |",
        "|---|---|---|---|---|---|---|",
    ]
    for entry in entries:
        (outcome,) = run_2d_circles_test([entry], TimedCircles(circles), queries)
        runs = outcome.runs
        solve_rest = outcome.solve_time - outcome.solve_checker_time
        per_iteration = f"{solve_rest / outcome.iterations * 1e6:.0f}" if outcome.iterations else "n/a"
        iterations = f"{outcome.iterations / runs:.0f}" if outcome.iterations else "n/a"
        checks = outcome.solve_checks + outcome.simplify_checks
        lines.append(
            f"| {entry.label} | {_ms(outcome.solve_time / runs)} = {_ms(outcome.solve_checker_time / runs)} + {_ms(solve_rest / runs)} "
            f"| {_ms(outcome.simplify_time / runs)} = {_ms(outcome.simplify_checker_time / runs)} + "
            f"{_ms((outcome.simplify_time - outcome.simplify_checker_time) / runs)} "
            f"| {outcome.solve_checks / runs:.0f} + {outcome.simplify_checks / runs:.0f} "
            f"| {(outcome.solve_checker_time + outcome.simplify_checker_time) / checks * 1e6:.1f} | {iterations} | {per_iteration} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--map-runs", type=int, default=MAP_RUNS, help="2-D map runs per planner (OMPL: 100)")
    parser.add_argument("--queries", type=int, default=None, help="circles queries to use (default: all 100, as OMPL)")
    parser.add_argument("--no-breakdown", action="store_true", help="skip the per-planner time breakdown")
    args = parser.parse_args()
    if not (RESOURCES / "env1.txt").is_file():
        sys.exit(f"OMPL's test resources are absent: expected env1.txt and circle_*.txt in {RESOURCES}")
    ou.setLogLevel(ou.LOG_ERROR)
    env = load_environment(RESOURCES / "env1.txt")
    circles = load_circles(RESOURCES / "circle_obstacles.txt")
    queries = load_queries(RESOURCES / "circle_queries.txt")[: args.queries]
    entries = [STOCK, STOCK_RRT_STAR, *package_planners()]

    load_before = os.getloadavg()
    began = time.perf_counter()
    map_outcomes = run_2d_map_test(entries, env, runs=args.map_runs)
    circles_outcomes = run_2d_circles_test(entries, circles, queries)
    print(
        f"2denvs.cpp port: {args.map_runs} map runs, {len(queries)} circles queries per planner, interleaved; "
        f"MACHINE_SPEED_FACTOR {MACHINE_SPEED_FACTOR:g} (time bound {2 * 0.01 * MACHINE_SPEED_FACTOR * 1e3:.0f} ms); "
        f"{time.perf_counter() - began:.0f} s; load average (1/5/15 min) "
        f"{' '.join(f'{v:.2f}' for v in load_before)} before, {' '.join(f'{v:.2f}' for v in os.getloadavg())} after\n"
    )
    print(results_table(map_outcomes, circles_outcomes))
    if not args.no_breakdown:
        print("\nWhere the circles time goes (each planner on its own, checker timed per call):\n")
        print(breakdown_table(entries, circles, queries))
        print(f"\nload average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
