"""The compiled engine against the Python engine and stock OMPL, measured in one run.

Six parts (``--part``), each printing a table of medians and ratios measured in the same
run, planners interleaved run by run so that the machine's slow phases hit all of them. Before
the timed runs of a Panda scenario or a 2-D problem each planner solves it once untimed
(:func:`warm_up`). The
two engines get the same seed in each run, so they make the same trees: their time ratio is
the engines' speed alone. Stock gets the run's seed through OMPL's RNG, so its runs too are
the same from one run of the script to the next.

``panda``
    MotionBenchMaker Panda problems (the four shipped scenarios, the first ``--problems`` of
    each, VAMP's Panda, certified motions, all of a problem's goals): stock ``og.RRTConnect``,
    ``BalancedRRTConnect`` on the Python engine and on the compiled engine, all with the
    package's checker and certified motion validator. Per scenario and planner: success,
    median time, median iterations, validity checks and motions, time per iteration and per
    motion (microseconds), calls out of compiled code, which path the checks took, the
    ratios compiled / Python and compiled / stock of the medians, and the ratio of the total
    times to stock's (where a scenario's solve times fall in groups, its median can move from
    one group to the next between runs of the script; the total does not). Every path the compiled engine returns is
    re-checked every ``--step`` rad per joint by a fresh checker without pre-filter.
``2d``
    The built-in 2-D problems with the package's box worlds (the compiled engine calls their
    kernel), and the bug trap with the same world as a plain Python callable (the compiled
    engine calls ``si.isValid``/``si.checkMotion``): stock ``og.RRTConnect`` against
    ``BalancedRRTConnect`` on both engines.
``profile``
    Where a compiled solve's time goes on the Panda problems: the certified edges and state
    checks in compiled code (the edges and states of the same runs, replayed through the
    kernels), the calls out to Python (FCL on pairs the kernels cannot decide, timed), the rest
    of the compiled slices (the loop: nearest nodes, sampling, trees; the slices' time less the
    other two, so that where the replay takes longer than the same kernels took in the loop the
    rest comes out negative, and says so), OMPL's checks of the start
    and goal states (through the checker's Python entry), the planner's other Python around the
    slices (its solve before and after the loop: start and goal states through OMPL, the
    policies, the path, the statistics), and ``SimpleSetup.solve`` around the planner.
``edges``
    What a certified Panda edge costs by how it ends: the edges of the same runs (the Python
    engine's, on the seeds of the ``profile`` part), replayed in order through the certified
    motion kernel with a fresh certifier per problem, each timed in compiled code. Edges are
    accepted or refused in the kernel, or after its call out to Python (FCL's exact distance on
    the segments of non-convex geometries the kernel could not bound); per kind: its share of the
    edges and of their time, microseconds per edge, and the configurations and distance bounds
    (GJK) the kernel evaluated per edge.
``scaling``
    The cost of an iteration as the trees grow to tens of thousands of nodes, in R^2 and SE(3)
    (a box world and a rigid body, each cut in two by a wall so that both trees grow freely
    and never meet): a solve on one seed, run three times, timed at the end of each compiled
    slice (a few milliseconds). The runs make the same trees iteration for iteration, so the
    times of a window of iterations differ by the machine only. Per run, the ratio of the most
    to the least cost per iteration over the windows from 100 to 20,000 nodes (the machine's
    speed drifts more between runs than within one), and their median.

``index``
    The nearest-node index alone: a tree of uniform SE(3) states in an 8 m cube grown to 20,000
    nodes with one query at each size (the index's builds included), and a linear scan of the
    same tree, per query.

Every solve is timed as ``ompl-balance bench`` times it, within OMPL's time limit evaluated
where the planner asks (:func:`~ompl_balance.core.counting.measured_solve`), not in the thread
of its own that ``ss.solve(seconds)`` starts for limits of a second or more, whose end costs
every planner up to a millisecond a solve.

Each part starts with the objects the script made before it set aside (``gc.freeze``), so that
Python's collector walking them is not charged to the planners of the part.

Run: ``python benchmarks/bench_engine.py [--part panda,2d,profile,edges,scaling,index] [--problems 25] [--runs 1]``
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import itertools
import platform
import time
from collections.abc import Callable, Iterator
from importlib import metadata
from typing import NamedTuple

import numpy as np
from cells import medians, ratios, success
from numba import njit
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect
from ompl_balance.bench.execution import seed_ompl
from ompl_balance.collision import certified
from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.collision.environment import Environment
from ompl_balance.collision.kernels import certified_motion_free, robot_state_free
from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.core.checks import Count
from ompl_balance.core.counting import CountingValidityChecker, measured_solve
from ompl_balance.engine import driver
from ompl_balance.engine.clock import monotonic_ns
from ompl_balance.engine.loop import Slot
from ompl_balance.worlds.boxes import BoxWorld2D, Problem, get_problem
from ompl_balance.worlds.mbm import SCENARIOS, MBMProblem, load_mbm
from ompl_balance.worlds.rigid import RigidBodyProblem, shipped_robot

ENGINES = ("python", "compiled")
KEYS = ("time", "iterations", "checks", "motions", "exits")


def stock(si, seed: int):
    # OMPL's RNG seeded for the run: stock's runs draw the same numbers from one run of the
    # script to the next, whatever ran before them in the process
    seed_ompl(seed)
    return og.RRTConnect(si)


def balanced(engine: str) -> Callable:
    def make(si, seed: int):
        planner = BalancedRRTConnect(si)
        planner.setEngine(engine)
        planner.setSeed(seed)
        return planner

    return make


PLANNERS = {"RRTConnect": stock, **{f"BalancedRRTConnect[{engine}]": balanced(engine) for engine in ENGINES}}


def measure(ss, make_planner, time_limit: float, seed: int) -> dict:
    """One solve of ``ss`` (set up outside the timing) and its work."""
    planner = make_planner(ss.getSpaceInformation(), seed)
    ss.setPlanner(planner)
    run = measured_solve(ss, time_limit)
    stats = getattr(planner, "stats", None)
    return {
        "solved": run.solved,
        "time": run.time,
        "checks": run.work.states_checked,
        "motions": run.work.motions_checked,
        "iterations": stats.iterations if stats is not None else 0,
        "exits": stats.exits if stats is not None else 0,
        "path": stats.checks if stats is not None else "python",
    }


def warm_up(make_setup: Callable, time_limit: float) -> None:
    """One untimed solve by each planner before a table's timed runs, as ``ompl-balance bench``
    warms a run up: a process's first solve on a kind of problem pays one-time costs (the
    Python engine's first pass through its code, the compiled engine's first call of a newly
    loaded loop: about 0.5-1 ms on a 2-D problem) that are not a solve's."""
    for make in PLANNERS.values():
        measure(make_setup(), make, time_limit, seed=0)


def dense_collisions(reference: CollisionChecker, states: np.ndarray, step: float) -> int:
    """Segments of the path ``states`` (n, dof) with a colliding state at most ``step`` rad apart."""
    colliding = 0
    for a, b in itertools.pairwise(states):
        count = max(1, int(np.ceil(np.abs(b - a).max() / step)))
        t = np.arange(count + 1) / count
        colliding += not reference.check(a + t[:, None] * (b - a)).all()
    return colliding


def table(rows: dict[str, list[dict]], label: str, baseline: str = "RRTConnect") -> None:
    cell = medians(rows, KEYS)
    python, stock_cell = cell.get("BalancedRRTConnect[python]"), cell[baseline]
    for name, runs in rows.items():
        m = cell[name]
        to_stock = ratios(m, stock_cell)
        to_python = ratios(m, python) if python is not None else {"time": float("nan")}
        per_iteration = m["time"] / m["iterations"] * 1e6 if m["iterations"] else float("nan")
        # a median of few solves can jump between groups of solve times; the totals do not
        total_to_stock = sum(r["time"] for r in runs) / sum(r["time"] for r in rows[baseline])
        print(
            f"| {label} | {name} | {success(runs):.0%} | {m['time'] * 1e3:.1f} | {m['iterations']:.0f} "
            f"| {m['checks']:.0f} | {m['motions']:.0f} | {per_iteration:.0f} | {m['time'] / max(m['motions'], 1) * 1e6:.0f} "
            f"| {m['exits']:.0f} | {runs[0]['path']} | {to_python['time']:.2f} | {to_stock['time']:.2f} "
            f"| {total_to_stock:.2f} | {to_stock['checks']:.2f} |",
            flush=True,
        )


HEADER = (
    "| problem | planner | success | median time (ms) | median iterations | median checks | median motions "
    "| us / iteration | us / motion | exits to Python | checks by | time / Python engine | time / stock "
    "| total time / stock | checks / stock |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
)


def panda(args) -> None:
    robot = load_panda_vamp()
    print(
        f"Panda (VAMP model), first {args.problems} problems per scenario, {args.runs} run(s) each, certified motions\n"
    )
    print(HEADER)
    colliding = solved = 0
    for scenario in SCENARIOS:
        rows: dict[str, list[dict]] = {name: [] for name in PLANNERS}
        problems = load_mbm(scenario, robot.joint_names)[: args.problems]

        def first_setup(problem=problems[0]):
            return problem.simple_setup(robot, CollisionChecker(robot, problem.environment))

        warm_up(first_setup, args.time_limit)
        for problem in problems:
            for run in range(args.runs):
                for name, make in PLANNERS.items():
                    ss = problem.simple_setup(robot, CollisionChecker(robot, problem.environment))
                    rows[name].append(measure(ss, make, args.time_limit, seed=1 + problem.id + 1000 * run))
                    if name == "BalancedRRTConnect[compiled]" and rows[name][-1]["solved"]:
                        path = ss.getSolutionPath()
                        states = np.array([path.getState(i)[0 : robot.dof] for i in range(path.getStateCount())])
                        reference = CollisionChecker(robot, problem.environment, prefilter=False)
                        colliding += dense_collisions(reference, states, args.step) > 0
                        solved += 1
        table(rows, scenario)
    print(f"\ncompiled engine's returned paths colliding under the {args.step:g} rad re-check: {colliding} of {solved}")


def bug_trap_callable_setup():
    """The bug trap with its world as a plain Python callable (no kernel, OMPL's validator),
    counted by the same wrapper for every planner."""
    problem = get_problem("bug_trap")
    ss = problem.setup()
    si = ss.getSpaceInformation()
    world = BoxWorld2D(problem.boxes)
    si.setStateValidityChecker(CountingValidityChecker(si, lambda state: world.is_free(state[0], state[1])))
    return ss


def two_d(args) -> None:
    print(f"\n2-D problems, {args.runs_2d} runs each, {args.time_limit:g} s limit\n")
    print(HEADER)
    cases = {name: get_problem(name).setup for name in ("open", "narrow_gap", "bug_trap", "maze")}
    cases["bug_trap (Python callable)"] = bug_trap_callable_setup
    for label, make_setup in cases.items():
        rows: dict[str, list[dict]] = {name: [] for name in PLANNERS}
        warm_up(make_setup, args.time_limit)
        for run in range(args.runs_2d):
            for name, make in PLANNERS.items():
                rows[name].append(measure(make_setup(), make, args.time_limit, seed=1 + run))
        table(rows, label)


@contextlib.contextmanager
def recorded_checks() -> Iterator[tuple[list[tuple[np.ndarray, np.ndarray]], list[np.ndarray]]]:
    """The certified edges and the states the package's checkers are asked about while inside."""
    edges: list[tuple[np.ndarray, np.ndarray]] = []
    states: list[np.ndarray] = []
    check, is_valid = certified.MotionCertifier.check, CollisionChecker.is_valid

    def record_edge(self, a, b, last_valid=False):
        edges.append((np.array(a), np.array(b)))
        return check(self, a, b, last_valid)

    def record_state(self, q):
        states.append(np.array(q, dtype=float).reshape(-1))
        return is_valid(self, q)

    certified.MotionCertifier.check, CollisionChecker.is_valid = record_edge, record_state
    try:
        yield edges, states
    finally:
        certified.MotionCertifier.check, CollisionChecker.is_valid = check, is_valid


@contextlib.contextmanager
def timed_exits() -> Iterator[list[float]]:
    """Seconds spent while inside in the compiled kernels' calls out to Python (FCL), in ``[0]``,
    and in the checker's Python entry for one state (``is_valid``: OMPL's checks of the start
    and goal states; the compiled loop checks states in its kernels), in ``[1]``, whose own
    calls out to Python count there only."""
    spent = [0.0, 0.0]
    inside_is_valid = [False]
    decide, is_valid = CollisionChecker.decide, CollisionChecker.is_valid
    hard_free, hard_touch = certified.MotionCertifier.hard_segments_free, certified.MotionCertifier.hard_segments_touch

    def timed(function, slot):
        def wrapper(*arguments, **keywords):
            if slot == 0 and inside_is_valid[0]:
                return function(*arguments, **keywords)
            inside_is_valid[0] = slot == 1
            began = time.perf_counter()
            try:
                return function(*arguments, **keywords)
            finally:
                spent[slot] += time.perf_counter() - began
                inside_is_valid[0] = False

        return wrapper

    CollisionChecker.decide, CollisionChecker.is_valid = timed(decide, 0), timed(is_valid, 1)
    certified.MotionCertifier.hard_segments_free = timed(hard_free, 0)
    certified.MotionCertifier.hard_segments_touch = timed(hard_touch, 0)
    try:
        yield spent
    finally:
        CollisionChecker.decide, CollisionChecker.is_valid = decide, is_valid
        certified.MotionCertifier.hard_segments_free = hard_free
        certified.MotionCertifier.hard_segments_touch = hard_touch


class SliceEnd(NamedTuple):
    """A compiled slice as it ended: when it began and ended (``time.perf_counter()``, s), and the
    solve's iterations and nodes in both trees then."""

    began: float
    ended: float
    iterations: int
    nodes: int


@contextlib.contextmanager
def traced_slices() -> Iterator[list[SliceEnd]]:
    """The compiled loop's slices (kernels and exits included) run while inside, in order."""
    trace: list[SliceEnd] = []
    runner = driver._runner

    def traced_runner(*arguments):
        run_slice = runner(*arguments)

        def traced(*slice_arguments):
            began = time.perf_counter()
            try:
                return run_slice(*slice_arguments)
            finally:
                ended, loop_arrays = time.perf_counter(), slice_arguments[4]
                trace.append(
                    SliceEnd(began, ended, int(loop_arrays.ints[Slot.ITERATIONS]), int(loop_arrays.sizes.sum()))
                )

        return traced

    driver._runner = traced_runner
    try:
        yield trace
    finally:
        driver._runner = runner


def seeded_solve(robot, problem: MBMProblem, engine: str, seed: int, time_limit: float) -> tuple[float, float]:
    """``ss.solve``'s time and the planner's own (``planner.stats.time``), in seconds."""
    ss = problem.simple_setup(robot, CollisionChecker(robot, problem.environment))
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine(engine)
    planner.setSeed(seed)
    ss.setPlanner(planner)
    return measured_solve(ss, time_limit).time, planner.stats.time


def python_engine_checks(robot, problem: MBMProblem, time_limit: float) -> tuple[np.ndarray, np.ndarray, list]:
    """The edges (their starts and ends, each (edges, dof)) and the states the Python engine's solve
    of ``problem`` on its seed (``1 + problem.id``) asks the package's checker about: on the same
    seed the compiled engine makes the same trees, so these are its edges and states too."""
    with recorded_checks() as (edges, states):
        seeded_solve(robot, problem, "python", 1 + problem.id, time_limit)
    starts = np.array([a for a, _ in edges]).reshape(-1, robot.dof)
    ends = np.array([b for _, b in edges]).reshape(-1, robot.dof)
    return starts, ends, states


def profile_problem(
    robot, problem: MBMProblem, time_limit: float, replay: Callable
) -> tuple[float, float, float, float, float, float, int]:
    """A compiled solve's time (``ss.solve``'s and the planner's own), its time in calls out to
    Python, its edges' and states' time in the kernels, its time inside the compiled slices, its
    time in OMPL's checks of the start and goal states, and its edges. The Python engine on the
    same seed makes the same trees, so its validator's calls are the compiled engine's edges and
    states."""
    starts, ends, states = python_engine_checks(robot, problem, time_limit)
    with timed_exits() as spent, traced_slices() as trace:
        solve_time, planner_time = seeded_solve(robot, problem, "compiled", 1 + problem.id, time_limit)
    exit_time, endpoint_time, slice_time = spent[0], spent[1], sum(end.ended - end.began for end in trace)
    if not len(starts):
        return solve_time, planner_time, exit_time, 0.0, slice_time, endpoint_time, 0
    certifier = certified.MotionCertifier(CollisionChecker(robot, problem.environment))  # (the view's exits)
    view = certifier.compiled_view()
    replay(view, starts[:0], ends[:0], np.empty((0, robot.dof)))  # compiled before the timing
    with timed_exits() as spent:
        began = time.perf_counter()
        replay(view, starts, ends, np.array(states).reshape(-1, robot.dof))
        kernel_time = time.perf_counter() - began - spent[0]
    return solve_time, planner_time, exit_time, kernel_time, slice_time, endpoint_time, len(starts)


def profile(args) -> None:
    """Where the compiled engine's time goes (see the module docstring)."""

    @njit
    def replay(view, starts, ends, states):  # the edges and states of a run, through the kernels
        free = 0
        for i in range(starts.shape[0]):
            free += certified_motion_free(view, starts[i], ends[i])
        for i in range(states.shape[0]):
            free += robot_state_free(view.states, states[i])
        return free

    robot = load_panda_vamp()
    print(f"\nWhere a compiled solve's time goes: first {args.problems} problems per scenario, certified motions\n")
    print(
        "| scenario | solve time (ms, total) | edges and states in compiled code | calls out to Python (FCL) "
        "| the compiled loop (nearest nodes, samples, trees) | OMPL's checks of the start and goal states "
        "(ms per solve) | the planner's other Python around the slices (ms per solve) "
        "| SimpleSetup around the planner (ms per solve) | us / edge (kernel) |"
        "\n|---|---|---|---|---|---|---|---|---|"
    )
    for scenario in SCENARIOS:
        totals = np.zeros(7)
        problems = load_mbm(scenario, robot.joint_names)[: args.problems]
        for problem in problems:
            totals += profile_problem(robot, problem, args.time_limit, replay)
        solve_time, planner_time, exit_time, kernel_time, slice_time, endpoint_time, edges = totals
        loop_time = slice_time - exit_time - kernel_time
        around, outside = planner_time - slice_time - endpoint_time, solve_time - planner_time
        shares = [f"{seconds / solve_time:.0%}" for seconds in (kernel_time, exit_time, loop_time)]
        if loop_time < 0:  # (the replay is timed apart from the solve: an estimate of the kernels' share)
            shares[2] += " (the replay took longer than the loop's kernels: the loop's share is within its error)"
        shares += [
            f"{seconds / solve_time:.0%} ({seconds / len(problems) * 1e3:.2f})"
            for seconds in (endpoint_time, around, outside)
        ]
        print(
            f"| {scenario} | {solve_time * 1e3:.0f} | {' | '.join(shares)} | {kernel_time / max(edges, 1) * 1e6:.0f} |",
            flush=True,
        )


#: How a certified edge ends: (accepted, after a call out to Python).
EDGE_OUTCOMES = {
    (False, False): "refused in the kernel",
    (False, True): "refused after FCL",
    (True, False): "accepted in the kernel",
    (True, True): "accepted after FCL",
}


@njit
def timed_edges(view, starts, ends, free, work, nanoseconds):
    """Each edge ``starts[i] -> ends[i]`` in order through the certified motion kernel of ``view``:
    whether it is free, the work it counted and its time (ns, in compiled code). (At module
    level: compiled as a closure inside its part, it had nanobind report OMPL's objects as
    leaked when the interpreter exits.)"""
    for i in range(starts.shape[0]):
        before = view.counts.copy()
        began = monotonic_ns()
        free[i] = certified_motion_free(view, starts[i], ends[i])
        nanoseconds[i] = monotonic_ns() - began
        work[i] = view.counts - before


def edge_costs(args) -> None:
    """What a certified edge costs by how it ends (see the module docstring)."""
    robot = load_panda_vamp()
    print(
        f"\nWhat a certified edge costs by how it ends: first {args.problems} problems per scenario, the edges "
        "of the Python engine's runs replayed through the kernel\n"
    )
    print(
        "| scenario | edges | how they end | share of the edges | share of their time | us / edge "
        "| configurations / edge | distance bounds / edge |\n|---|---|---|---|---|---|---|---|"
    )
    for scenario in SCENARIOS:
        free_parts, work_parts, time_parts = [], [], []
        for problem in load_mbm(scenario, robot.joint_names)[: args.problems]:
            starts, ends, _states = python_engine_checks(robot, problem, args.time_limit)
            if not len(starts):
                continue
            certifier = certified.MotionCertifier(CollisionChecker(robot, problem.environment))
            view = certifier.compiled_view()  # (its calls out to Python find the certifier while it lives)
            free, work = np.zeros(len(starts), dtype=np.bool_), np.zeros((len(starts), len(Count)), dtype=np.int64)
            nanoseconds = np.zeros(len(starts), dtype=np.int64)
            timed_edges(view, starts[:0], ends[:0], free, work, nanoseconds)  # compiled before the timing
            timed_edges(view, starts, ends, free, work, nanoseconds)
            free_parts.append(free)
            work_parts.append(work)
            time_parts.append(nanoseconds)
        free, work, nanoseconds = np.concatenate(free_parts), np.concatenate(work_parts), np.concatenate(time_parts)
        exited = work[:, Count.EXITS] > 0
        for (accepted, after_fcl), label in EDGE_OUTCOMES.items():
            kind = (free == accepted) & (exited == after_fcl)
            if not kind.any():
                continue
            print(
                f"| {scenario} | {len(free)} | {label} | {kind.mean():.0%} | {nanoseconds[kind].sum() / nanoseconds.sum():.0%} "
                f"| {nanoseconds[kind].mean() / 1e3:.0f} | {work[kind, Count.STATES].mean():.1f} "
                f"| {work[kind, Count.DISTANCE_QUERIES].mean():.1f} |",
                flush=True,
            )


def split_box_world() -> Callable[[], og.SimpleSetup]:
    """The unit square cut in two by a wall: start and goal on either side, both trees grow freely."""
    return Problem("split", "a wall between start and goal", ((0.48, 0.0, 0.52, 1.0),), (0.1, 0.5), (0.9, 0.5)).setup


def split_room() -> Callable[[], og.SimpleSetup]:
    """An SE(3) room cut in two by a wall, the L-shaped robot on either side (certified motions)."""
    environment = Environment()
    environment.add_box("wall", (0.1, 4.0, 4.0), (0.0, 0.0, 0.0))
    identity = (0.0, 0.0, 0.0, 1.0)
    problem = RigidBodyProblem(
        "split_room", shipped_robot("ell"), environment, np.array([-2.0, 0.0, 0.0, *identity]),
        np.array([2.0, 0.0, 0.0, *identity]), np.full(3, -4.0), np.full(3, 4.0),
    )  # fmt: skip
    return problem.simple_setup


#: The scaling part's solves: per problem a time limit (s) that grows the trees past 20,000
#: nodes, run this many times on one seed (the same iterations each run, only their times differ).
SCALING_RUNS = 3
#: The tree sizes (nodes in both trees) between which the scaling part reports the cost of an iteration.
SCALING_WINDOWS = (100, 200, 500, 1_000, 2_000, 5_000, 10_000, 20_000)


def scaling(args) -> None:
    """The cost of an iteration as the trees grow (see the module docstring)."""
    print(
        f"\nCost of an iteration as the trees grow (BalancedRRTConnect, compiled engine, one seed, "
        f"{SCALING_RUNS} runs)\n\n| problem | nodes (both trees) | iterations | us / iteration, median of the runs "
        "| us / iteration, each run |\n|---|---|---|---|---|"
    )
    cases = (("R^2, a wall across", split_box_world(), 1.0), ("SE(3), a wall across", split_room(), 4.0))
    for label, make_setup, time_limit in cases:
        traces, checks = [], []
        for _ in range(SCALING_RUNS):
            ss = make_setup()
            planner = BalancedRRTConnect(ss.getSpaceInformation())
            planner.setEngine("compiled")
            planner.setSeed(7)
            ss.setPlanner(planner)
            with traced_slices() as trace:
                run = measured_solve(ss, time_limit)
            traces.append(trace)
            checks.append(run.work.states_checked / max(planner.stats.iterations, 1))
        reached = traces[0][-1].nodes
        if reached < SCALING_WINDOWS[-1]:
            print(f"| {label} | {reached:,} nodes in {time_limit:g} s: fewer than {SCALING_WINDOWS[-1]:,} | | | |")
            continue
        # Each run makes the same trees: the iteration at which they hold a window's end is found on
        # the first run's slice ends, and each run's time at it, between its own slice ends.
        first = traces[0]
        at = np.interp(SCALING_WINDOWS, [0] + [end.nodes for end in first], [0] + [end.iterations for end in first])
        costs = np.empty((len(SCALING_WINDOWS) - 1, SCALING_RUNS))  # us per iteration, by window and run
        for r, trace in enumerate(traces):
            times = np.interp(
                at, [0] + [end.iterations for end in trace], [trace[0].began] + [end.ended for end in trace]
            )
            costs[:, r] = np.diff(times) / np.diff(at) * 1e6
        for j, each in enumerate(costs):
            print(
                f"| {label} | {SCALING_WINDOWS[j]:,} to {SCALING_WINDOWS[j + 1]:,} | {at[j + 1] - at[j]:.0f} "
                f"| {np.median(each):.1f} | {', '.join(f'{c:.1f}' for c in each)} |",
                flush=True,
            )
        spread = costs.max(axis=0) / costs.min(axis=0)  # each run's own: the machine's speed drifts between runs
        print(
            f"| {label} | {SCALING_WINDOWS[0]:,} to {SCALING_WINDOWS[-1]:,}: most / least cost per iteration "
            f"| | median {np.median(spread):.2f} | {', '.join(f'{x:.2f}' for x in spread)} "
            f"(states checked per iteration: {np.mean(checks):.1f}) |"
        )


#: Tree sizes at which the index part times its queries (each over the next INDEX_WINDOW sizes).
INDEX_SIZES = (300, 1_000, 5_000, 20_000)
INDEX_WINDOW = 512


def index(args) -> None:
    """Nearest-node queries as a tree of uniform SE(3) states grows (see the module docstring)."""
    from numba import njit
    from ompl import base as ob

    from ompl_balance.core.compiled_spaces import nearest
    from ompl_balance.core.layout import layout_for
    from ompl_balance.engine.index import BLOCK, indexed_nearest, new_index

    @njit
    def grow_and_query(index, layout, states, first, last, queries):  # pragma: no cover (compiled)
        """One query (of ``queries``, in turn) at each tree size ``first .. last - 1``."""
        found = 0
        for size in range(first, last):
            found += indexed_nearest(index, layout, states, size, queries[size % queries.shape[0]])[0]
        return found

    @njit
    def scan(layout, states, size, queries):  # pragma: no cover (compiled)
        found = 0
        for q in range(queries.shape[0]):
            found += nearest(layout, states, size, queries[q])[0]
        return found

    space = ob.SE3StateSpace()
    bounds = ob.RealVectorBounds(3)
    bounds.setLow(-4.0)
    bounds.setHigh(4.0)
    space.setBounds(bounds)
    ob.SpaceInformation(space).setup()
    layout = layout_for(space)
    rng = np.random.default_rng(1)

    def uniform(count: int) -> np.ndarray:
        quaternions = rng.normal(size=(count, 4))
        return np.hstack(
            [rng.uniform(-4.0, 4.0, (count, 3)), quaternions / np.linalg.norm(quaternions, axis=1)[:, None]]
        )

    total = INDEX_SIZES[-1] + INDEX_WINDOW
    states, queries = uniform(total), uniform(4096)
    tree_index = new_index(layout, total)
    grow_and_query(tree_index, layout, states, 1, 2, queries)  # compiled before the timing
    scan(layout, states, 1, queries[:1])
    print(
        f"\nNearest-node queries as a tree of uniform SE(3) states grows (an 8 m cube, all rotations; "
        f"index blocks of {BLOCK} nodes a unit)\n\n| nodes | us / query, index (one query at each size, "
        f"builds included) | us / query, linear scan |\n|---|---|---|"
    )
    grown = 1
    for size in INDEX_SIZES:
        grow_and_query(tree_index, layout, states, grown, size, queries)
        began = time.perf_counter()
        grow_and_query(tree_index, layout, states, size, size + INDEX_WINDOW, queries)
        indexed = (time.perf_counter() - began) / INDEX_WINDOW
        began = time.perf_counter()
        scan(layout, states, size, queries[:200])
        scanned = (time.perf_counter() - began) / 200
        print(f"| {size:,} | {indexed * 1e6:.1f} | {scanned * 1e6:.1f} |", flush=True)
        grown = size + INDEX_WINDOW


#: The script's parts, by the names ``--part`` takes.
PARTS = {"panda": panda, "2d": two_d, "profile": profile, "edges": edge_costs, "scaling": scaling, "index": index}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--part",
        default=",".join(PARTS),
        help=f"comma-separated parts: {', '.join(PARTS)}",
    )
    parser.add_argument("--problems", type=int, default=25, help="Panda problems per scenario (default 25)")
    parser.add_argument("--runs", type=int, default=1, help="Panda runs per problem and planner (default 1)")
    parser.add_argument("--runs-2d", type=int, default=30, help="2-D runs per problem and planner (default 30)")
    parser.add_argument("--time-limit", type=float, default=10.0, help="seconds per run (default 10)")
    parser.add_argument("--step", type=float, default=0.005, help="Panda re-check resolution, rad (default 0.005)")
    args = parser.parse_args()
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_ERROR)
    began = time.perf_counter()
    print(
        f"{time.strftime('%Y-%m-%d')}, {platform.machine()} {platform.processor() or ''}, Python "
        f"{platform.python_version()}, ompl {metadata.version('ompl')}; compiled engine loaded before timing\n"
    )
    for part in args.part.split(","):
        # Each part starts with the script's objects so far set aside: Python's collector walking
        # them during a part's solves would charge the script's heap to the planners that make
        # Python objects (the Python engine; calls out to Python), by up to 1.5-2x in a full run.
        gc.collect()
        gc.freeze()
        PARTS[part](args)
    gc.unfreeze()
    print(f"\nwhole script: {time.perf_counter() - began:.0f} s; median of runs, ratios of medians")


if __name__ == "__main__":
    main()
