"""The ``ompl-balance`` command line.

``ompl-balance compare``
    stock ``og.RRTConnect`` against ``BalancedRRTConnect`` (balancing on and off), or
    the planners given with ``--planners``, on the built-in 2-D problems, problem 1 of
    each MotionBenchMaker Panda scenario and two shipped rigid-body problems; prints per problem the success rate and
    the median time, validity checks and nodes of the solved runs, each with its 95 % interval and its
    ratio to stock RRT-Connect's solved runs. With ``-o OUT`` the runs are kept, and the same command resumes.
``ompl-balance bench EXPERIMENT.toml -o OUT/``
    runs an experiment file (docs/benchmark.md) into ``OUT/``: results, OMPL logs, the
    SQLite database and the summary; running it again resumes.
``ompl-balance plot OUT/``
    per problem how each planner's runs ended and the times to a solution and validity
    checks of its solved runs, success-vs-time curves, the median best cost against time
    of planners that keep improving it (RRT*), the summary table and, for 2-D problems, the
    two trees of balanced and alternating growth (needs matplotlib: the ``plot`` extra).
``ompl-balance gamma``
    RRT*'s ball-radius constant for a built-in problem or an occupancy grid, and the
    ``rewire_factor`` that gives OMPL's ``RRTstar`` the same radius schedule.
``ompl-balance show PROBLEM [-o FILE.html]``
    plans a problem and shows it in the browser: live, or written to one self-contained HTML
    file (the ``viz`` extra; :mod:`ompl_balance.viz`).

Every run executes in its own process, after an untimed short solve that warms the
planner's code up (``--no-warm-up`` to time the cold first solve); ``--jobs N`` runs N at a
time, ``--dask tcp://HOST:PORT`` or ``--dask local:N`` on a Dask cluster (the
``distributed`` extra).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from ompl import util as ou

from .bench.compare import (
    COMPARE_MBM_PROBLEMS,
    COMPARE_RIGID_PROBLEMS,
    COMPARE_SEED,
    bench,
    compare_experiment,
    parse_planners,
)
from .bench.errors import ClusterError, ExperimentError, MissingExtraError
from .bench.execution import TIME_INCLUDES_COMPILING, TIMED_AGAIN
from .bench.experiment import Experiment, PlannerSpec
from .bench.experiment_file import load_experiment
from .bench.problems import problem_by_name
from .bench.scheduling import require_dask
from .gamma import ball_radius_constant, estimate_free_measure, ompl_rewire_factor, rewire_radius
from .worlds.boxes import PROBLEMS
from .worlds.occupancy import OCCUPANCY_PROBLEMS, OccupancyGrid, OccupancyProblem
from .worlds.rigid import RIGID_PROBLEMS


def _problem_names(text: str) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise argparse.ArgumentTypeError("no problem given")
    for name in names:
        try:
            problem_by_name(name)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from error
    return names


def _planners(text: str) -> list[PlannerSpec]:
    try:
        return parse_planners(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from error


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}")
    return value


def _whole_number(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 0, got {text!r}")
    return value


def _positive(unit: str) -> Callable[[str], float]:
    """An argument type: a positive finite number of ``unit``."""

    def positive(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not 0 < value < math.inf:
            raise argparse.ArgumentTypeError(f"must be a positive number of {unit}, got {text!r}")
        return value

    return positive


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 < value < 1:
        raise argparse.ArgumentTypeError(f"must be a number between 0 and 1 (exclusive), got {text!r}")
    return value


def _dask_address(text: str) -> str:
    if text.startswith("tcp://") or (text.startswith("local:") and text[6:].isdigit() and int(text[6:]) >= 1):
        return text
    raise argparse.ArgumentTypeError(f"expected tcp://HOST:PORT or local:N (N >= 1 workers), got {text!r}")


def _add_execution_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--jobs",
        type=_positive_int,
        default=1,
        help="runs at a time on this machine (default 1; more than the free cores distorts times)",
    )
    parser.add_argument(
        "--dask",
        type=_dask_address,
        default=None,
        metavar="ADDRESS",
        help="run on a Dask cluster: tcp://HOST:PORT, or local:N for N local workers",
    )
    parser.add_argument("--no-progress", action="store_true", help="do not show a progress bar")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ompl-balance", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)

    compare = commands.add_parser(
        "compare",
        help="compare planners with stock RRTConnect on 2-D and Panda problems",
        description=__doc__.split("\n\n", 1)[1],
    )
    compare.add_argument("--runs", type=_positive_int, default=20, help="runs per planner and problem (default 20)")
    compare.add_argument(
        "--time-limit", type=_positive("seconds"), default=5.0, help="seconds each run may plan (default 5)"
    )
    compare.add_argument(
        "--problems",
        type=_problem_names,
        default=[*PROBLEMS, *COMPARE_MBM_PROBLEMS, *COMPARE_RIGID_PROBLEMS],
        help=f"comma-separated problems: built-in 2-D ({', '.join(PROBLEMS)}), MotionBenchMaker Panda "
        f"problems SCENARIO.ID and shipped rigid-body problems ({', '.join(RIGID_PROBLEMS)}) (default: all "
        f"2-D ones, {', '.join(COMPARE_MBM_PROBLEMS)}, {', '.join(COMPARE_RIGID_PROBLEMS)})",
    )
    compare.add_argument(
        "--planners",
        type=_planners,
        default=None,
        help="comma-separated planners: stock OMPL names (RRTConnect, RRT, PRM, ...), this package's "
        "planners and presets, each optionally NAME[param=value;...] (default: RRTConnect, "
        "BalancedRRTConnect, BalancedRRTConnect[balance_tree_sizes=0])",
    )
    compare.add_argument(
        "--warm-up",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="before each timed solve, an untimed short solve of a copy of the problem, so the first "
        "execution of the planner's code in the run's process is not what is timed (default: on)",
    )
    compare.add_argument(
        "--seed",
        type=_positive_int,
        default=COMPARE_SEED,
        help=f"experiment seed; every run's seed derives from it (default {COMPARE_SEED})",
    )
    compare.add_argument(
        "-o",
        "--out",
        type=Path,
        default=None,
        help="keep results, logs and database in this folder (the same command then resumes); "
        "default: a temporary folder, deleted at the end",
    )
    _add_execution_options(compare)

    bench_parser = commands.add_parser("bench", help="run an experiment file into an output folder (resumes)")
    bench_parser.add_argument("experiment", type=Path, help="experiment TOML file (see docs/benchmark.md)")
    bench_parser.add_argument("-o", "--out", type=Path, required=True, help="output folder")
    _add_execution_options(bench_parser)

    plot = commands.add_parser("plot", help="plots and summary tables of an output folder (matplotlib)")
    plot.add_argument("out", type=Path, help="output folder of bench or compare -o")
    plot.add_argument("--baseline", default=None, help="planner label the ratios refer to (default: the experiment's)")
    plot.add_argument(
        "--tree-iterations",
        type=_positive_int,
        default=300,
        help="iterations at which the 2-D tree pictures are drawn (default 300)",
    )

    gamma = commands.add_parser(
        "gamma",
        help="estimate RRT*'s ball-radius constant for a problem",
        description="Estimate RRT*'s ball-radius constant gamma* = 2^d (1 + 1/d) mu(X_free) / zeta_d "
        "(Karaman & Frazzoli 2011) for a built-in problem or an occupancy grid you give, "
        "and the rewire_factor that makes OMPL's RRTstar use the same radius schedule.",
    )
    source = gamma.add_mutually_exclusive_group()
    source.add_argument(
        "--problem",
        default="rooms",
        help="built-in problem: rooms, rooms_se2 (occupancy grid, counted exactly) or a box world of "
        "'ompl-balance compare' (open, narrow_gap, bug_trap, maze; Monte Carlo). Default: rooms",
    )
    source.add_argument(
        "--grid", metavar="FILE.npy", help="a 2-D boolean occupancy array (True = occupied) saved with numpy.save"
    )
    gamma.add_argument(
        "--resolution", type=_positive("metres"), default=0.2, help="cell side of --grid in metres (default 0.2)"
    )
    gamma.add_argument(
        "--samples",
        type=_positive_int,
        default=20000,
        help="Monte Carlo samples when the measure is estimated (default 20000)",
    )
    gamma.add_argument(
        "--confidence", type=_fraction, default=0.95, help="confidence level of the interval (default 0.95)"
    )
    gamma.add_argument(
        "--monte-carlo", action="store_true", help="estimate by sampling even when a grid allows exact counting"
    )
    gamma.add_argument("--seed", type=_whole_number, default=None, help="seed of the Monte Carlo samples")
    gamma.add_argument(
        "--eta",
        type=_positive("metres"),
        default=None,
        help="maximum connection distance for the radius table, in the space's units (default 0.2 x extent)",
    )
    _add_show(commands)
    return parser


def _add_show(commands: argparse._SubParsersAction) -> None:
    """The ``show`` subcommand's arguments."""
    show = commands.add_parser(
        "show",
        help="plan a problem and show it in the browser: live, or one offline HTML file (the viz extra)",
        description="Plan a problem and show it: the robot or body, the obstacles, start and goal, the path "
        "animated (slider and play button) and, with --trees, both trees. Without -o a live viewer in the browser "
        "(this machine only unless --host says otherwise; Ctrl-C ends it); with -o one self-contained HTML file "
        "that opens offline. Exits 1 when no path was found (the problem is shown all the same, what makes its "
        "start or goal invalid named and painted red).",
    )
    show.add_argument(
        "problem",
        help="a 2-D world (open, narrow_gap, bug_trap, maze, twin_pockets, rooms, rooms_se2, env1, env2, circles), "
        f"a MotionBenchMaker Panda problem SCENARIO.ID (e.g. table_pick.001), a rigid body ({', '.join(RIGID_PROBLEMS)}) "
        "or an OMPL.app .cfg file",
    )
    show.add_argument(
        "-o", "--out", type=_html_file, default=None, metavar="FILE.html", help="write one HTML file instead"
    )
    show.add_argument(
        "--planner",
        default="BalancedRRTConnect",
        metavar="NAME[param=value;...]",
        help="a stock OMPL planner or one of the package's, with parameters (default BalancedRRTConnect)",
    )
    show.add_argument("--seed", type=_positive_int, default=None, help="seed of OMPL's random numbers")
    show.add_argument(
        "--time-limit",
        type=_positive("seconds"),
        default=None,
        help="seconds to plan (default: the problem's suggestion, else 10)",
    )
    show.add_argument("--trees", action="store_true", help="draw the planner's trees (nodes at the end effector)")
    show.add_argument("--end-effector", default=None, metavar="LINK", help="the link a robot's path traces")
    show.add_argument(
        "--host", default="127.0.0.1", help="where the live viewer listens (default 127.0.0.1; 0.0.0.0 shares it)"
    )
    show.add_argument("--port", type=_whole_number, default=8080, help="its port (default 8080; 0: any free port)")
    show.add_argument("--no-browser", action="store_true", help="do not open a browser (print the address only)")


def _html_file(text: str) -> Path:
    path = Path(text)
    if path.suffix.lower() not in (".html", ".htm"):
        raise argparse.ArgumentTypeError(f"must name an .html file, got {text!r}")
    if not path.parent.is_dir():
        raise argparse.ArgumentTypeError(f"folder {str(path.parent)!r} does not exist")
    return path


def _show(args: argparse.Namespace) -> int:
    """``ompl-balance show``: plan the problem, then show it (:mod:`ompl_balance.viz`)."""
    from .viz.command import run_show

    try:
        return run_show(
            args.problem,
            args.out,
            planner=args.planner,
            seed=args.seed,
            time_limit=args.time_limit,
            trees=args.trees,
            host=args.host,
            port=args.port,
            open_browser=not args.no_browser,
            end_effector=args.end_effector,
        )
    except ValueError as error:
        print(f"ompl-balance show: {error}", file=sys.stderr)
        return 2


def _run(experiment: Experiment, out: Path, args: argparse.Namespace, temporary: bool = False) -> int:
    records = bench(experiment, out, jobs=args.jobs, dask=args.dask, progress=not args.no_progress)
    print((out / "summary.md").read_text(), end="")
    crashed = sum(bool(r["error"]) for r in records)
    timed_again = sum(TIMED_AGAIN in r.get("note", "") for r in records)
    compiling = sum(TIME_INCLUDES_COMPILING in r.get("note", "") for r in records)
    where = "in a temporary folder, now deleted (-o OUT keeps results, logs and database)" if temporary else f"in {out}"
    print(
        f"\n{len(records)} runs {where}"
        + (f"; {crashed} crashed or killed (see results.jsonl)" if crashed else "")
        + (f"; {timed_again} timed again, numba having compiled during their first solve" if timed_again else "")
        + (f"; {compiling} with numba compiling in their time (see their notes)" if compiling else "")
    )
    return 0


def _interrupted(args: argparse.Namespace) -> str:
    """What Ctrl-C leaves behind, for the command that was interrupted."""
    out = getattr(args, "out", None)
    if args.command in ("compare", "bench") and out is not None:
        return f"interrupted: the finished runs are kept in {out}; run the same command again to resume"
    if args.command == "compare":
        return "interrupted: without -o the runs were made in a temporary folder, now deleted; give -o OUT to keep them and resume"
    return "interrupted"


def _plot(args: argparse.Namespace) -> int:
    """``ompl-balance plot``: the plots and tables of an output folder."""
    from .bench.plots import plot_folder, require_matplotlib

    if not (args.out / "experiment.json").is_file():
        raise ExperimentError(
            str(args.out),
            "is not an output folder (no experiment.json): make one with 'ompl-balance bench EXPERIMENT.toml "
            f"-o {args.out}' or 'ompl-balance compare -o {args.out}'",
        )
    require_matplotlib()
    for path in plot_folder(args.out, baseline=args.baseline, tree_iterations=args.tree_iterations):
        print(path)
    return 0


def _gamma(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """``ompl-balance gamma``: print the ball-radius constant of a problem."""
    if args.grid is not None:
        try:
            grid = OccupancyGrid(np.load(args.grid), args.resolution)
        except (OSError, ValueError) as error:
            parser.error(f"--grid {args.grid}: {error}")
        problem_name = args.grid
        ss = OccupancyProblem(args.grid, grid, grid.low, grid.high).setup()
    elif args.problem in OCCUPANCY_PROBLEMS:
        problem_name, problem = args.problem, OCCUPANCY_PROBLEMS[args.problem]()
        grid, ss = problem.grid, problem.setup()
    elif args.problem in PROBLEMS:  # the box worlds have no grid: Monte Carlo only
        problem_name, grid, ss = args.problem, None, PROBLEMS[args.problem].setup()
    else:
        parser.error(
            f"unknown problem {args.problem!r}; built-in problems: {', '.join([*OCCUPANCY_PROBLEMS, *PROBLEMS])}"
        )

    si = ss.getSpaceInformation()
    try:
        free = estimate_free_measure(
            si, samples=args.samples, confidence=args.confidence, grid=None if args.monte_carlo else grid, rng=args.seed
        )
    except ValueError as error:
        parser.error(str(error))
    if not free.high > 0:
        parser.error(f"{problem_name}: no state is free (every cell occupied), so there is no ball radius to estimate")
    d = si.getStateDimension()
    gamma = ball_radius_constant(d, free.high)
    eta = args.eta if args.eta is not None else 0.2 * si.getMaximumExtent()
    print(f"problem            {problem_name} ({si.getStateSpace().getName()}, d = {d})")
    print(f"space measure      {free.space_measure:.6g}")
    if free.exact:
        print(
            f"free measure       {free.measure:.6g} (exact, {free.free_fraction:.2%} of the space, from the grid cells)"
        )
    else:
        print(
            f"free measure       {free.measure:.6g}, {free.confidence:.0%} interval [{free.low:.6g}, {free.high:.6g}] "
            f"({free.samples} samples, {free.free_fraction:.2%} free)"
        )
    print(f"gamma*             {gamma:.6g}  (from the {'exact' if free.exact else 'upper'} free measure)")
    print(f"OMPL rewire_factor {ompl_rewire_factor(si, gamma):.6g}  (RRTstar, setKNearest(False), range = eta)")
    for n in (100, 1000, 10000):
        print(
            f"radius at N={n:<6} {rewire_radius(n, d, gamma, eta):.4g}  "
            f"(gamma = 100: {rewire_radius(n, d, 100.0, eta):.4g}; eta = {eta:.4g})"
        )
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
    ou.setLogLevel(ou.LOG_WARN)
    try:
        if getattr(args, "dask", None):
            require_dask()
        if args.command == "compare":
            experiment = compare_experiment(
                args.problems, args.planners, args.runs, args.time_limit, args.seed, args.warm_up
            )
            print(f"experiment seed {experiment.seed}")
            if args.out is not None:
                return _run(experiment, args.out, args)
            with tempfile.TemporaryDirectory(prefix="ompl-balance-compare-") as out:
                return _run(experiment, Path(out), args, temporary=True)
        if args.command == "bench":
            return _run(load_experiment(args.experiment), args.out, args)
        if args.command == "plot":
            return _plot(args)
        if args.command == "gamma":
            return _gamma(args, parser)
        if args.command == "show":
            return _show(args)
    except (ExperimentError, MissingExtraError, ClusterError) as error:
        print(f"ompl-balance {args.command}: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"\n{_interrupted(args)}", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
