"""The ``ompl-balance`` command line.

``ompl-balance compare`` runs stock ``og.RRTConnect`` and ``BalancedRRTConnect`` (with
balancing on and off) on the built-in 2-D problems and prints, per problem, success
rate, median time, median validity checks, median nodes and each planner's ratios to
stock RRT-Connect.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ompl import util as ou

from .benchmark import compare, default_planners, format_table, summarize
from .problems import PROBLEMS, get_problem


def _problem_names(text: str) -> list[str]:
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in PROBLEMS]
    if unknown or not names:
        raise argparse.ArgumentTypeError(
            f"unknown problem(s) {', '.join(unknown) or '(none given)'}; choose from {', '.join(PROBLEMS)}"
        )
    return names


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text}")
    return value


def _positive_float(text: str) -> float:
    value = float(text)
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, got {text}")
    return value


def _seed(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ompl-balance", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    compare_parser = commands.add_parser(
        "compare",
        help="compare BalancedRRTConnect with stock RRTConnect on the built-in problems",
        description=__doc__.split("\n\n", 1)[1],
    )
    compare_parser.add_argument("--runs", type=_positive_int, default=20, help="runs per planner and problem (default 20)")
    compare_parser.add_argument(
        "--time-limit", type=_positive_float, default=5.0, help="seconds each run may plan (default 5)"
    )
    compare_parser.add_argument(
        "--problems",
        type=_problem_names,
        default=list(PROBLEMS),
        help=f"comma-separated problem names (default: all of {', '.join(PROBLEMS)})",
    )
    compare_parser.add_argument(
        "--seed", type=_seed, default=None, help="OMPL's global random seed, for a reproducible comparison"
    )
    compare_parser.add_argument("--no-progress", action="store_true", help="do not show a progress bar")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.seed is not None:
        ou.RNG.setSeed(args.seed)  # must happen before OMPL draws its first random number
    ou.setLogLevel(ou.LOG_WARN)
    if args.command == "compare":
        problems = [get_problem(name) for name in args.problems]
        results = compare(problems, default_planners(), args.runs, args.time_limit, progress=not args.no_progress)
        print(format_table(summarize(results)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
