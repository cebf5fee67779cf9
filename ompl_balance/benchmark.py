"""Side-by-side comparison of planners on the same problems, in one process.

Each run builds a fresh ``SimpleSetup`` for its problem (with a counting validity
checker), so stock OMPL planners and this package's planners use the same checker and
motion validator. Runs of the different planners are interleaved (run 1 of every
planner, then run 2, ...) so that slow phases of a shared machine hit them alike.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from ompl import base as ob
from ompl import geometric as og
from tqdm import tqdm

from .counting import read_work
from .planners import BalancedRRTConnect
from .problems import Problem

PlannerFactory = Callable[[ob.SpaceInformation], ob.Planner]


@dataclass(frozen=True)
class PlannerSpec:
    """A planner to compare: a display label and a factory ``si -> planner``."""

    label: str
    factory: PlannerFactory


def _balanced(balance: bool) -> PlannerFactory:
    def make(si: ob.SpaceInformation) -> BalancedRRTConnect:
        planner = BalancedRRTConnect(si)
        planner.setBalanceTreeSizes(balance)
        return planner

    return make


STOCK_LABEL = "RRTConnect"


def default_planners() -> list[PlannerSpec]:
    """Stock ``og.RRTConnect`` (the baseline) and ``BalancedRRTConnect`` with balancing on and off."""
    return [
        PlannerSpec(STOCK_LABEL, og.RRTConnect),
        PlannerSpec("BalancedRRTConnect", _balanced(True)),
        PlannerSpec("BalancedRRTConnect[balance=0]", _balanced(False)),
    ]


@dataclass(frozen=True)
class RunResult:
    """One planner run: whether it solved and the work it took."""

    problem: str
    planner: str
    solved: bool
    time: float  # wall-clock seconds in ss.solve
    states_checked: int
    motions_checked: int
    nodes: int  # states in the planner's graph (both trees for RRT-Connect)


def graph_size(ss: og.SimpleSetup, planner: ob.Planner) -> int:
    """Vertices in the planner's graph: ``plannerData()`` for ours, ``getPlannerData`` for stock."""
    if hasattr(planner, "plannerData"):
        return planner.plannerData().numVertices()
    data = ob.PlannerData(ss.getSpaceInformation())
    ss.getPlannerData(data)
    return data.numVertices()


def run_once(problem: Problem, spec: PlannerSpec, time_limit: float) -> RunResult:
    """Solve ``problem`` once with a fresh planner from ``spec``."""
    ss = problem.setup()
    si = ss.getSpaceInformation()
    planner = spec.factory(si)
    ss.setPlanner(planner)
    ss.setup()
    before = read_work(si)
    began = time.perf_counter()
    ss.solve(time_limit)
    elapsed = time.perf_counter() - began
    work = read_work(si) - before
    return RunResult(
        problem=problem.name,
        planner=spec.label,
        solved=bool(ss.haveExactSolutionPath()),
        time=elapsed,
        states_checked=work.states_checked,
        motions_checked=work.motions_checked,
        nodes=graph_size(ss, planner),
    )


def compare(
    problems: Sequence[Problem],
    planners: Sequence[PlannerSpec],
    runs: int,
    time_limit: float,
    progress: bool = True,
) -> list[RunResult]:
    """Run every planner ``runs`` times on every problem, interleaving planners."""
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if not time_limit > 0:
        raise ValueError(f"time limit must be a positive number of seconds, got {time_limit}")
    jobs = [(problem, spec) for problem in problems for _ in range(runs) for spec in planners]
    return [run_once(problem, spec, time_limit) for problem, spec in tqdm(jobs, disable=not progress, unit="run")]


@dataclass(frozen=True)
class Summary:
    """Medians over one (problem, planner) cell, and ratios to the baseline's medians."""

    problem: str
    planner: str
    runs: int
    success: float
    time: float
    states_checked: float
    nodes: float
    time_ratio: float
    checks_ratio: float
    nodes_ratio: float


def _ratio(value: float, baseline: float) -> float:
    return value / baseline if baseline > 0 else float("nan")


def summarize(results: Iterable[RunResult], baseline: str = STOCK_LABEL) -> list[Summary]:
    """One :class:`Summary` per (problem, planner), in first-seen order.

    Medians are over all runs of a cell, solved or not (an unsolved run counts with
    the time and work it spent until the limit).
    """
    cells: dict[tuple[str, str], list[RunResult]] = {}
    for result in results:
        cells.setdefault((result.problem, result.planner), []).append(result)
    medians = {
        key: (
            statistics.median(r.time for r in runs),
            statistics.median(r.states_checked for r in runs),
            statistics.median(r.nodes for r in runs),
        )
        for key, runs in cells.items()
    }
    summaries = []
    for (problem, planner), runs in cells.items():
        time_median, checks_median, nodes_median = medians[problem, planner]
        base = medians.get((problem, baseline), (float("nan"),) * 3)
        summaries.append(
            Summary(
                problem=problem,
                planner=planner,
                runs=len(runs),
                success=sum(r.solved for r in runs) / len(runs),
                time=time_median,
                states_checked=checks_median,
                nodes=nodes_median,
                time_ratio=_ratio(time_median, base[0]),
                checks_ratio=_ratio(checks_median, base[1]),
                nodes_ratio=_ratio(nodes_median, base[2]),
            )
        )
    return summaries


def format_table(summaries: Sequence[Summary]) -> str:
    """A markdown table per problem: success, medians, and ratios to the baseline."""
    header = (
        "| planner | runs | success | median time (ms) | median validity checks | median nodes "
        "| time ratio | checks ratio | nodes ratio |\n|---|---|---|---|---|---|---|---|---|"
    )
    blocks = []
    for problem in dict.fromkeys(s.problem for s in summaries):
        rows = [
            f"| {s.planner} | {s.runs} | {s.success:.0%} | {s.time * 1e3:.1f} | {s.states_checked:.0f} | {s.nodes:.0f} "
            f"| {s.time_ratio:.2f} | {s.checks_ratio:.2f} | {s.nodes_ratio:.2f} |"
            for s in summaries
            if s.problem == problem
        ]
        blocks.append(f"### {problem}\n\n{header}\n" + "\n".join(rows))
    return "\n\n".join(blocks)
