"""Your own checker: stock RRT-Connect and BalancedRRTConnect with the checkers users write.

Worlds the package was never tuned on, each with one validity function written three ways, as
an OMPL user would write it:

``trap``
    2-D: the start inside a square room whose only door faces away from the goal (~1 us checks);
``slalom``
    2-D: three staggered walls between the start and the goal (~1 us checks);
``comb``
    2-D: seven walls with narrow gaps at alternate ends (~1.5 us checks; solves of tens of ms,
    where a solve's fixed costs weigh least);
``arm7``
    7-D: a planar arm of seven links among four discs, the start reaching right and the goal
    reaching left (forward kinematics and disc tests, ~15-20 us checks in Python).

Checkers (``--checkers``):

``callable``
    a plain Python function of an OMPL state, ``ss.setStateValidityChecker(fn)``;
``numba``
    the same test as a ``numba.njit`` function of the coordinates, ``setup_checker(ss, fn)``;
``vectorized``
    the same test as a numpy function of an ``(n, d)`` array, ``setup_checker(ss, fn, vectorized=True)``.

For each world and checker, stock ``og.RRTConnect`` and ``BalancedRRTConnect`` (defaults,
``engine=auto``) solve ``--runs`` times, interleaved run by run; each run builds a fresh
``SimpleSetup``, sets the planner up and (the package's) loads its engine untimed, then times
``ss.solve`` within OMPL's time limit evaluated where the planner asks (``measured_solve``).
Stock with a plain callable runs on a ``SimpleSetup`` no planner of the package has touched,
as a user runs it (the package wraps a checker to count its work at setup). Printed per cell:
success, median time, median checks (the validity function's calls: counted in the function
for a callable, by the checker for the others), the ratio of medians to stock with the same
checker and to stock with the plain callable, the median of each run's time per check, and
the path the package's checks took (``engine``, ``checks``, calls out of compiled code per
solve). ``--profile`` prints where a Balanced solve's time goes with the plain callable
(cProfile); ``--exits`` only times a call out of the compiled loop with a plain callable, by
the states it carries, against stock's call from C++ per state, and a solve's fixed cost.

    python benchmarks/bench_checkers.py [--runs 30] [--worlds trap,slalom,comb,arm7] [--profile] [--exits]
"""

from __future__ import annotations

import argparse
import cProfile
import math
import pstats
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect, setup_checker
from ompl_balance.core.counting import measured_solve

# -- 2-D worlds: boxes (x0, y0, x1, y1) in the unit square ----------------------------------------

TRAP = (
    (0.30, 0.30, 0.70, 0.33),  # the room's floor, between the start and the goal
    (0.30, 0.30, 0.33, 0.70),
    (0.67, 0.30, 0.70, 0.70),
    (0.30, 0.67, 0.46, 0.70),  # the roof, with a door from 0.46 to 0.54
    (0.54, 0.67, 0.70, 0.70),
)
SLALOM = ((0.20, 0.00, 0.25, 0.85), (0.45, 0.15, 0.50, 1.00), (0.70, 0.00, 0.75, 0.85))
# seven walls, each with a gap of 0.04 at alternate ends: long solves, many checks
COMB = tuple(
    (x, 0.04, x + 0.02, 1.0) if index % 2 == 0 else (x, 0.0, x + 0.02, 0.96)
    for index, x in enumerate((0.12, 0.24, 0.36, 0.48, 0.60, 0.72, 0.84))
)
#: name -> (boxes, start, goal)
PLANAR = {
    "trap": (TRAP, (0.5, 0.4), (0.5, 0.1)),
    "slalom": (SLALOM, (0.05, 0.05), (0.95, 0.95)),
    "comb": (COMB, (0.05, 0.5), (0.95, 0.5)),
}

# -- 7-D world: a planar arm of seven links among discs -------------------------------------------

LINKS = 7
LINK = 0.13  # m per link: the arm reaches 0.91 m
DISCS = np.array([(0.45, 0.35, 0.12), (0.45, -0.35, 0.12), (-0.45, 0.30, 0.12), (0.0, 0.55, 0.1)])  # (x, y, r)
ARM_START = (0.0,) * LINKS  # reaching right, along the x axis
ARM_GOAL = (math.pi - 0.3, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05)  # reaching left


@numba.njit(cache=True)
def box_free(q: np.ndarray, boxes: np.ndarray) -> bool:
    for i in range(boxes.shape[0]):
        if boxes[i, 0] <= q[0] <= boxes[i, 2] and boxes[i, 1] <= q[1] <= boxes[i, 3]:
            return False
    return True


@numba.njit(cache=True)
def arm_free(q: np.ndarray) -> bool:
    """No link's end or middle inside a disc."""
    x = y = angle = 0.0
    for link in range(LINKS):
        angle += q[link]
        dx, dy = LINK * math.cos(angle), LINK * math.sin(angle)
        for step in (0.5, 1.0):
            px, py = x + step * dx, y + step * dy
            for disc in range(DISCS.shape[0]):
                ox, oy = px - DISCS[disc, 0], py - DISCS[disc, 1]
                if ox * ox + oy * oy <= DISCS[disc, 2] * DISCS[disc, 2]:
                    return False
        x, y = x + dx, y + dy
    return True


def numba_box_free(boxes: np.ndarray) -> Callable[[np.ndarray], bool]:
    @numba.njit
    def free(q: np.ndarray) -> bool:
        return box_free(q, boxes)

    return free


def python_box_free(boxes: tuple[tuple[float, ...], ...]) -> Callable[[ob.State], bool]:
    def is_valid(state: ob.State) -> bool:
        x, y = state[0], state[1]
        return all(not (x0 <= x <= x1 and y0 <= y <= y1) for x0, y0, x1, y1 in boxes)

    return is_valid


def python_arm_free(state: ob.State) -> bool:
    """:func:`arm_free` in plain Python on an OMPL state."""
    discs = DISCS.tolist()
    x = y = angle = 0.0
    for link in range(LINKS):
        angle += state[link]
        dx, dy = LINK * math.cos(angle), LINK * math.sin(angle)
        for step in (0.5, 1.0):
            px, py = x + step * dx, y + step * dy
            for cx, cy, r in discs:
                if (px - cx) ** 2 + (py - cy) ** 2 <= r * r:
                    return False
        x, y = x + dx, y + dy
    return True


def vectorized_box_free(boxes: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    def free(states: np.ndarray) -> np.ndarray:
        x, y = states[:, :1], states[:, 1:2]
        inside = (boxes[:, 0] <= x) & (x <= boxes[:, 2]) & (boxes[:, 1] <= y) & (y <= boxes[:, 3])
        return ~inside.any(axis=1)

    return free


def vectorized_arm_free(states: np.ndarray) -> np.ndarray:
    angles = np.cumsum(states, axis=1)
    ends = np.cumsum(LINK * np.stack([np.cos(angles), np.sin(angles)], axis=2), axis=1)  # (n, links, 2)
    starts = np.concatenate([np.zeros((len(states), 1, 2)), ends[:, :-1]], axis=1)
    points = np.concatenate([(starts + ends) / 2, ends], axis=1)  # (n, 2 links, 2)
    offsets = points[:, :, None, :] - DISCS[None, None, :, :2]
    return ~((offsets**2).sum(axis=3) <= DISCS[:, 2] ** 2).any(axis=(1, 2))


# -- problems ----------------------------------------------------------------------------------------


class Counted:
    """A plain callable that counts its calls (the count costs stock and the package alike)."""

    def __init__(self, function: Callable[[ob.State], bool]) -> None:
        self.function, self.calls = function, 0

    def __call__(self, state: ob.State) -> bool:
        self.calls += 1
        return self.function(state)


@dataclass
class World:
    name: str
    dim: int
    low: float
    high: float
    start: tuple[float, ...]
    goal: tuple[float, ...]
    callable_free: Callable[[ob.State], bool]
    numba_free: Callable[[np.ndarray], bool]
    vectorized_free: Callable[[np.ndarray], np.ndarray]
    time_limit: float


def worlds() -> dict[str, World]:
    found = {}
    for name, (boxes, start, goal) in PLANAR.items():
        array = np.array(boxes)
        found[name] = World(
            name,
            2,
            0.0,
            1.0,
            start,
            goal,
            python_box_free(boxes),
            numba_box_free(array),
            vectorized_box_free(array),
            10.0,
        )
    found["arm7"] = World(
        "arm7", LINKS, -math.pi, math.pi, ARM_START, ARM_GOAL, python_arm_free, arm_free, vectorized_arm_free, 30.0
    )
    return found


def simple_setup(world: World, checker: str) -> tuple[og.SimpleSetup, Counted | None]:
    space = ob.RealVectorStateSpace(world.dim)
    space.setBounds(world.low, world.high)
    ss = og.SimpleSetup(space)
    counted = None
    if checker == "callable":
        counted = Counted(world.callable_free)
        ss.setStateValidityChecker(counted)
    elif checker == "numba":
        setup_checker(ss, world.numba_free)
    else:
        setup_checker(ss, world.vectorized_free, vectorized=True)
    start, goal = space.allocState(), space.allocState()
    for i in range(world.dim):
        start[i], goal[i] = world.start[i], world.goal[i]
    ss.setStartAndGoalStates(start, goal)
    return ss, counted


PLANNERS = ("stock", "balanced")


def run(world: World, checker: str, planner: str, seed: int) -> dict:
    ss, counted = simple_setup(world, checker)
    si = ss.getSpaceInformation()
    made = og.RRTConnect(si) if planner == "stock" else BalancedRRTConnect(si)
    if planner == "balanced":
        made.setSeed(seed)
    ss.setPlanner(made)
    before = 0 if counted is None else counted.calls
    solve = measured_solve(ss, world.time_limit)
    checks = counted.calls - before if counted is not None else solve.work.states_checked
    stats = getattr(made, "stats", None)
    return {
        "solved": solve.solved,
        "time": solve.time,
        "checks": checks,
        "path": "" if stats is None else f"{stats.engine}/{stats.checks}",
        "exits": 0 if stats is None else stats.exits,
    }


def median(rows: list[dict], key: str) -> float:
    return statistics.median(row[key] for row in rows)


def table(world: World, checkers: list[str], runs: int) -> None:
    results: dict[tuple[str, str], list[dict]] = {}
    for checker in checkers:  # one untimed solve each: the engine's first solve in the process
        for planner in PLANNERS:
            run(world, checker, planner, 0)
    for index in range(runs):
        for checker in checkers:
            for planner in PLANNERS:
                results.setdefault((checker, planner), []).append(run(world, checker, planner, 1 + index))
    stock_callable = median(results[("callable", "stock")], "time") if "callable" in checkers else math.nan
    print(f"\n### {world.name} ({world.dim}-D), {runs} runs each\n")
    print("| checker | planner | solved | median time (ms) | median checks | time / stock, same checker |", end="")
    print(" time / stock with the callable | us per check | path (exits per solve) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for checker in checkers:
        stock_time = median(results[(checker, "stock")], "time")
        for planner in PLANNERS:
            rows = results[(checker, planner)]
            solved = sum(row["solved"] for row in rows) / len(rows)
            t = median(rows, "time")
            path = "C++" if planner == "stock" else f"{rows[0]['path']} ({median(rows, 'exits'):.0f})"
            same = "" if planner == "stock" else f"{t / stock_time:.2f}"
            callable_ratio = "" if (planner, checker) == ("stock", "callable") else f"{t / stock_callable:.2f}"
            per_check = statistics.median(row["time"] / max(row["checks"], 1) for row in rows)
            print(
                f"| {checker} | {planner} | {solved:.0%} | {t * 1e3:.2f} | {median(rows, 'checks'):.0f} | {same} |"
                f" {callable_ratio} | {per_check * 1e6:.2f} | {path} |"
            )


def profile(world: World) -> None:
    """Where a Balanced solve's time goes with the plain callable: cProfile of ten solves."""
    for seed in range(2):
        run(world, "callable", "balanced", seed)
    profiler = cProfile.Profile()
    began = time.perf_counter()
    profiler.enable()
    for seed in range(10):
        run(world, "callable", "balanced", seed)
    profiler.disable()
    print(
        f"\n### Profile: {world.name}, plain callable, BalancedRRTConnect, 10 runs ({time.perf_counter() - began:.2f} s)\n"
    )
    stats = pstats.Stats(profiler)
    stats.sort_stats("tottime").print_stats(12)


def best_of_five(run: Callable[[], int]) -> float:
    """The least seconds per unit of work over five calls of ``run`` (which returns its units)."""
    best = math.inf
    for _ in range(5):
        began = time.perf_counter()
        units = run()
        best = min(best, (time.perf_counter() - began) / units)
    return best


def exit_costs() -> None:
    """What a call out of the compiled loop costs with a plain callable: the package's exit
    (:mod:`ompl_balance.core.checks`) asked about ``count`` 2-D states from a compiled loop, each
    written into the scratch OMPL state and checked by a trivial function, against stock's call
    from C++ per state (``si.checkMotion`` over a long motion, the same function)."""
    from ompl_balance.core.checks import EXIT_ADDRESS, exit_handle
    from ompl_balance.core.function_pointers import call_exit
    from ompl_balance.engine.views import SpaceChecks

    @numba.njit
    def ask(calls: int, address: int, handle: int, count: int) -> int:  # (returns the calls made)
        for _ in range(calls):
            call_exit(address, handle, 0, count)
        return calls

    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)

    def free(state: ob.State) -> bool:
        return state[0] < 2.0

    counted = Counted(free)  # (as the benchmark's worlds: the same function both ways)
    si.setStateValidityChecker(counted)
    si.setStateValidityCheckingResolution(0.0005)
    si.setup()
    target = SpaceChecks(si, counted)
    target.take_rows(np.random.default_rng(0).random((64, 2)))
    handle = exit_handle(target)
    print("\n### A call out of compiled code (2-D, a trivial check; best of 5)\n")
    print("| states per call | us per call | us per state |\n|---|---|---|")
    for count in (1, 4, 8, 32):
        ask(10, EXIT_ADDRESS, handle, count)
        calls = 100_000 // count
        best = best_of_five(lambda calls=calls, count=count: ask(calls, EXIT_ADDRESS, handle, count))
        print(f"| {count} | {best * 1e6:.2f} | {best / count * 1e6:.3f} |")
    a, b = si.allocState(), si.allocState()
    a[0], a[1], b[0], b[1] = 0.0, 0.0, 1.0, 1.0

    def motions() -> int:
        before = counted.calls
        for _ in range(50):
            si.checkMotion(a, b)
        return counted.calls - before

    print(f"\nstock, OMPL's checkMotion calling the function from C++: {best_of_five(motions) * 1e6:.3f} us per state")
    state = si.allocState()

    def alone() -> int:
        for _ in range(100_000):
            counted(state)
        return 100_000

    best = best_of_five(alone)
    print(f"the function alone, called from Python: {best * 1e6:.3f} us")


def interleaved_medians(
    action: Callable[[str], None], runs: int, before: Callable[[str], None] | None = None
) -> dict[str, float]:
    """Median microseconds of ``action(planner)`` for each of :data:`PLANNERS`, planners
    interleaved run by run, over ``runs`` runs after ten that warm the caches; ``before(planner)``
    runs untimed ahead of each."""
    spent: dict[str, list[float]] = {planner: [] for planner in PLANNERS}
    for index in range(runs + 10):
        for planner in PLANNERS:
            if before is not None:
                before(planner)
            began = time.perf_counter()
            action(planner)
            if index >= 10:
                spent[planner].append(time.perf_counter() - began)
    return {planner: statistics.median(times) * 1e6 for planner, times in spent.items()}


def fixed_costs(solves: int = 300) -> None:
    """A solve's fixed cost: ``ss.solve`` of a 2-D problem in free space whose goal is within one
    step of its start (one iteration, two motions checked), stock and Balanced, with a trivial
    plain callable and with the same test in numba; the planner cleared before each solve
    (untimed), medians of ``solves``. Then what precedes a solve: a planner constructed and
    set up (``planner.setup()`` from Python, the problem already set up), and ``planner.clear()``."""

    def free(state: ob.State) -> bool:
        return True

    @numba.njit
    def free_q(q: np.ndarray) -> bool:
        return True

    # (no vectorized form: not timed)
    world = World("free", 2, 0.0, 1.0, (0.40, 0.40), (0.45, 0.45), free, free_q, lambda q: np.ones(len(q), bool), 10.0)
    print(f"\n### A solve's fixed cost (2-D, goal one step from the start; medians of {solves} solves)\n")
    print("| checker | stock (us) | Balanced (us) | checks per solve |\n|---|---|---|---|")
    for checker in ("callable", "numba"):
        setups: dict[str, tuple[og.SimpleSetup, ob.Planner]] = {}
        for planner in PLANNERS:
            ss, counted = simple_setup(world, checker)
            si = ss.getSpaceInformation()
            made = og.RRTConnect(si) if planner == "stock" else BalancedRRTConnect(si)
            ss.setPlanner(made)
            ss.setup()
            if planner == "balanced":
                made.wait_for_engine()
            setups[planner] = ss, made

        def cleared(planner: str, setups: dict = setups) -> None:
            ss, made = setups[planner]
            made.clear()
            ss.getProblemDefinition().clearSolutionPaths()

        def solved(planner: str, setups: dict = setups) -> None:
            setups[planner][0].solve(ob.timedPlannerTerminationCondition(10.0))

        medians = interleaved_medians(solved, solves, before=cleared)
        shown = "(in compiled code)"
        if counted is not None:  # (the last planner's: Balanced)
            before = counted.calls
            cleared("balanced")
            solved("balanced")
            shown = f"{counted.calls - before}"
        print(f"| {checker} | {medians['stock']:.0f} | {medians['balanced']:.0f} | {shown} |")
    print("\n| before a solve (plain callable) | stock (us) | Balanced (us) | Balanced / stock |\n|---|---|---|---|")
    ss, _counted = simple_setup(world, "callable")
    ss.setup()
    si, pdef = ss.getSpaceInformation(), ss.getProblemDefinition()
    BalancedRRTConnect(si).wait_for_engine()  # (the engine loaded, as for the solves above)
    made: dict[str, ob.Planner] = {}

    def construct_and_set_up(planner: str) -> None:
        made[planner] = og.RRTConnect(si) if planner == "stock" else BalancedRRTConnect(si)
        made[planner].setProblemDefinition(pdef)
        made[planner].setup()

    for label, action in (
        ("construction + setup()", construct_and_set_up),
        ("clear()", lambda planner: made[planner].clear()),
    ):
        medians = interleaved_medians(action, solves)
        print(
            f"| {label} | {medians['stock']:.0f} | {medians['balanced']:.0f} | {medians['balanced'] / medians['stock']:.1f} |"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=30, help="runs per planner and checker (default 30)")
    parser.add_argument("--worlds", default="trap,slalom,comb,arm7", help="comma-separated: trap, slalom, comb, arm7")
    parser.add_argument("--checkers", default="callable,numba,vectorized", help="comma-separated")
    parser.add_argument("--profile", action="store_true", help="profile a Balanced solve with the callable")
    parser.add_argument(
        "--exits", action="store_true", help="only time a call out of compiled code and a solve's fixed cost"
    )
    args = parser.parse_args()
    ou.setLogLevel(ou.LOG_WARN)
    available = worlds()
    chosen = [available[name] for name in args.worlds.split(",")]
    checkers = args.checkers.split(",")
    print(f"# bench_checkers: {time.strftime('%Y-%m-%d')}, numba {numba.__version__}")
    if args.exits:
        exit_costs()
        fixed_costs()
        return
    for world in chosen:
        table(world, checkers, args.runs)
        if args.profile:
            profile(world)


if __name__ == "__main__":
    main()
