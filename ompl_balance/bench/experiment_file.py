"""Experiment files (TOML) -> :class:`~ompl_balance.bench.experiment.Experiment`::

    name = "narrow"            # no spaces; names the OMPL logs
    runs = 5                   # runs per (problem, planner) cell
    time_limit = 1.0           # seconds of planning per run
    memory_limit = 0           # MB a run may add to its memory (as OMPL), 0 = no limit
    seed = 1                   # decides every run's seed (see experiment.run_seed)
    warm_up = true             # an untimed short solve before each timed one (execution.warm_up)
    baseline = "RRTConnect"    # planner label the summary's ratios refer to

    [[problems]]
    builtin = "narrow_gap"                     # ompl_balance.worlds.boxes.PROBLEMS

    [[problems]]
    mbm = "table_pick"                         # a shipped MotionBenchMaker scenario, or a JSON file
                                               # (relative to this file)
    ids = [1, 2, "10-19"]                      # problem ids; default: all
    # robot = "my/panda_vamp"                  # another folder with panda.urdf + panda.srdf
                                               # (default: the Panda shipped with the package)
    # motion = "discrete"                      # the motion validator: "certified" (default)
                                               # or "discrete" (OMPL-style states only)

    [[problems]]
    factory = "mypackage.worlds:make_setup"    # function(**args) -> og.SimpleSetup
    name = "corridor"
    args = { width = 0.1 }

    [[planners]]
    name = "RRTConnect"                        # a stock OMPL planner, or one of this package's

    [[planners]]
    name = "BalancedRRTConnect"
    label = "Balanced r=0.5"                   # display name (default: name)
    params = { max_tree_size_ratio = 0.5 }

    [[planners]]
    factory = "mypackage.planners:make"        # function(si) -> ob.Planner
    label = "Mine"

The problem tables are read by their kind (:data:`~ompl_balance.bench.problems.PROBLEM_KINDS`).
Everything is checked before any run starts: unknown keys, planners or parameters, missing
files, bad ids and non-positive numbers raise
:class:`~ompl_balance.bench.errors.ExperimentError` naming the key and the line.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .errors import ExperimentError
from .experiment import HARD_LIMIT_MARGIN, Experiment, PlannerSpec
from .problems import read_problem_table

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

_TOP_KEYS = {
    "name",
    "runs",
    "time_limit",
    "memory_limit",
    "seed",
    "baseline",
    "hard_limit_margin",
    "warm_up",
    "problems",
    "planners",
}
_PLANNER_KEYS = {"name", "factory", "label", "params"}


def _param_text(value: Any) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    return str(value)


def _line_of(text: str, key: str, value: Any = None) -> str:
    """`` line N`` of the TOML line holding ``value`` (or assigning ``key``'s last part), else ``""``."""
    leaf = re.sub(r"\[\d+\]", "", key.rpartition(".")[2])
    patterns = [rf"[\"']{re.escape(str(value))}[\"']"] if isinstance(value, str) else []
    patterns.append(rf"(^|[\s{{,]){re.escape(leaf)}\s*=")
    for pattern in patterns:
        for number, line in enumerate(text.splitlines(), 1):
            if re.search(pattern, line.split("#")[0]):
                return f" line {number}"
    return ""


def load_experiment(path: str | Path) -> Experiment:
    """Read and check an experiment TOML file; :class:`ExperimentError` naming the key and line."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as error:
        raise ExperimentError(str(path), f"cannot read the experiment file: {error}") from error
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ExperimentError(str(path), f"not valid TOML: {error}") from error
    try:
        return experiment_from_dict(data, base_dir=path.parent, default_name=path.stem)
    except ExperimentError as error:
        raise ExperimentError(f"{path}{_line_of(text, error.key, error.value)}", str(error), error.value) from error


def experiment_from_dict(
    data: Mapping[str, Any], base_dir: Path = Path("."), default_name: str = "experiment"
) -> Experiment:
    """An :class:`Experiment` from the TOML layout (relative paths resolved against ``base_dir``)."""
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        raise ExperimentError(unknown[0], f"unknown key; accepted: {', '.join(sorted(_TOP_KEYS))}")
    problems = [
        spec
        for index, table in enumerate(_tables(data, "problems"))
        for spec in read_problem_table(table, f"problems[{index}]", base_dir)
    ]
    planners = [_planner(table, index) for index, table in enumerate(_tables(data, "planners"))]
    return Experiment(
        name=data.get("name", default_name),
        problems=tuple(problems),
        planners=tuple(planners),
        runs=data.get("runs", 10),
        time_limit=data.get("time_limit", 10.0),
        memory_limit=data.get("memory_limit", 0.0),
        seed=data.get("seed", 1),
        baseline=data.get("baseline", ""),
        hard_limit_margin=data.get("hard_limit_margin", HARD_LIMIT_MARGIN),
        warm_up=data.get("warm_up", True),
    )


def _tables(data: Mapping[str, Any], key: str) -> list[Mapping[str, Any]]:
    tables = data.get(key, [])
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise ExperimentError(key, f"must be an array of tables ([[{key}]])")
    return tables


def _planner(table: Mapping[str, Any], index: int) -> PlannerSpec:
    where = f"planners[{index}]"
    unknown = sorted(set(table) - _PLANNER_KEYS)
    if unknown:
        raise ExperimentError(f"{where}.{unknown[0]}", f"unknown key; accepted: {', '.join(sorted(_PLANNER_KEYS))}")
    if ("name" in table) == ("factory" in table):
        raise ExperimentError(where, "needs exactly one of name (a planner or preset) and factory ('module:function')")
    params = table.get("params", {})
    if not isinstance(params, dict):
        raise ExperimentError(f"{where}.params", "must be a table of parameter = value")
    label = table.get("label", table.get("name", ""))
    if not label:
        raise ExperimentError(f"{where}.label", "a factory planner needs a label")
    return PlannerSpec(
        label=str(label),
        name=table.get("name", ""),
        factory=table.get("factory", ""),
        params={name: _param_text(value) for name, value in params.items()},
    )
