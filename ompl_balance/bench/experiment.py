"""Benchmark experiments: which problems, which planners, how many runs, how long.

An :class:`Experiment` is plain data (it pickles, so runs can be sent to other
processes and machines); each run builds its problem and planner where it executes.
Experiments come from TOML files (:func:`load_experiment`) or from Python::

    name = "narrow"            # no spaces; names the OMPL logs
    runs = 5                   # runs per (problem, planner) cell
    time_limit = 1.0           # seconds of planning per run
    memory_limit = 0           # MB a run may add to its memory (as OMPL), 0 = no limit
    seed = 1                   # decides every run's seed (see run_seed)
    warm_up = true             # an untimed short solve before each timed one (runner.warm_up)
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

Everything is checked when the experiment is made, before any run starts: unknown
keys, planners or parameters, missing files, bad ids and non-positive numbers raise
:class:`ExperimentError` naming the key (and the line, for TOML files).
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import json
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields
from importlib import metadata
from pathlib import Path
from typing import Any

from ompl import base as ob
from ompl import geometric as og

from ..core.counting import ensure_counting
from ..planners import PRESETS
from ..rrtstar import BallRadiusRRTstar
from ..worlds.boxes import PROBLEMS
from .planner_params import DECLARED_PARAMS, check_declared_param, set_planner_param

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


class ExperimentError(ValueError):
    """An experiment description that cannot be run.

    ``key`` is where the problem is (``"planners[1].params"``), ``value`` the offending
    value when there is one; the message starts with the key.
    """

    def __init__(self, key: str, message: str, value: Any = None) -> None:
        super().__init__(f"{key}: {message}")
        self.key, self.value = key, value


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message names the ``pip install`` that adds it."""


# -- planners ---------------------------------------------------------------------------


def package_planner_classes() -> dict[str, type[ob.Planner]]:
    """This package's planners by name: ``BalancedRRTConnect``, ``BallRadiusRRTstar`` and the presets."""
    return {**PRESETS, "BallRadiusRRTstar": BallRadiusRRTstar}


def stock_planner_classes() -> dict[str, type[ob.Planner]]:
    """OMPL's geometric planners bound in ``ompl.geometric`` (``RRTConnect``, ``RRT``, ``PRM``, ...)."""
    return {name: cls for name, cls in vars(og).items() if isinstance(cls, type) and issubclass(cls, ob.Planner)}


def _param_text(value: Any) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    return str(value)


def _import_function(reference: str) -> Callable:
    """``"module:function"`` -> the function; ``ValueError`` saying what went wrong."""
    module_name, _, function_name = reference.partition(":")
    if not module_name or not function_name:
        raise ValueError(f"expected 'module:function', got {reference!r}")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise ValueError(f"cannot import module {module_name!r}: {error}") from error
    function = getattr(module, function_name, None)
    if not callable(function):
        raise ValueError(f"module {module_name!r} has no function {function_name!r}")
    return function


@dataclass(frozen=True)
class PlannerSpec:
    """A planner of the experiment.

    ``name`` is one of this package's planners or presets or a stock OMPL geometric
    planner; alternatively ``factory`` is ``"module:function"``, a function
    ``si -> ob.Planner``. ``params`` overrides parameters (OMPL string forms).
    ``label`` names the planner in logs and tables (default: ``name``).
    """

    label: str
    name: str = ""
    factory: str = ""
    params: Mapping[str, str] = field(default_factory=dict)

    def build(self, si: ob.SpaceInformation) -> ob.Planner:
        """A fresh planner on ``si``, parameters set, named ``label``."""
        if self.factory:
            planner = _import_function(self.factory)(si)
        else:
            planner = {**stock_planner_classes(), **package_planner_classes()}[self.name](si)
        for name, value in self.params.items():
            set_planner_param(planner, name, value)
        planner.setName(self.label)
        return planner

    def check(self) -> None:
        """Raise :class:`ExperimentError` (key relative to this planner) for an unknown planner,
        factory or parameter or a bad value. Named planners are built on a 2-D space to try
        the parameters; a factory is only imported (it is called where the run executes)."""
        if self.factory:
            try:
                _import_function(self.factory)
            except ValueError as error:
                raise ExperimentError("factory", str(error), self.factory) from error
            return
        known = {**stock_planner_classes(), **package_planner_classes()}
        if self.name not in known:
            raise ExperimentError(
                "name", f"unknown planner {self.name!r}; known: {', '.join(sorted(known))}", self.name
            )
        if self.name in DECLARED_PARAMS:  # a stock planner: checked against OMPL's names, not built
            for name, value in self.params.items():
                try:
                    check_declared_param(self.name, name, value)
                except ValueError as error:
                    raise ExperimentError(f"params.{name}", str(error)) from error
            return
        space = ob.RealVectorStateSpace(2)
        space.setBounds(0.0, 1.0)
        si = ob.SpaceInformation(space)
        si.setStateValidityChecker(lambda state: True)
        planner = known[self.name](si)
        for name, value in self.params.items():
            try:
                set_planner_param(planner, name, value)
            except ValueError as error:
                raise ExperimentError(f"params.{name}", str(error)) from error


# -- problems ---------------------------------------------------------------------------


@dataclass(frozen=True)
class ProblemSpec:
    """A problem of the experiment; :meth:`build` makes its ``og.SimpleSetup``.

    ``kind`` is ``"builtin"`` (``source`` names one of ``ompl_balance.worlds.boxes.PROBLEMS``),
    ``"mbm"`` (``source`` is a shipped MotionBenchMaker scenario or a JSON file,
    ``problem_id`` the problem's id, ``robot`` the robot folder, empty for the shipped
    Panda, and ``motion`` the motion validator, ``"certified"`` or ``"discrete"``) or ``"factory"`` (``source`` is ``"module:function"`` called with ``args``).
    ``name`` is unique in the experiment and names its log file. ``data`` is a digest of
    the files a MotionBenchMaker problem is read from when they are not shipped with the
    package (:func:`mbm_problems` fills it), so that an edited file makes a new problem.
    """

    name: str
    kind: str
    source: str
    problem_id: int = 0
    robot: str = ""
    args: Mapping[str, Any] = field(default_factory=dict)
    data: str = ""
    motion: str = ""

    def build(self) -> og.SimpleSetup:
        """A fresh ``SimpleSetup`` with start, goal and a counting validity checker."""
        if self.kind == "builtin":
            ss = PROBLEMS[self.source].setup()
        elif self.kind == "mbm":
            from ..worlds.mbm import problem_setup

            ss = problem_setup(self.source, self.problem_id, self.robot, self.motion or "certified")
        else:
            ss = _import_function(self.source)(**self.args)
            if not isinstance(ss, og.SimpleSetup):
                raise TypeError(f"problem factory {self.source} returned {type(ss).__name__}, not og.SimpleSetup")
        ensure_counting(ss.getSpaceInformation())
        return ss


def mbm_problems(
    scenario: str, ids: Sequence[int] | None = None, robot: str = "", motion: str = "certified"
) -> list[ProblemSpec]:
    """Specs of MotionBenchMaker problems, named ``<scenario>.NNN``: a shipped scenario by name or
    a JSON file (absolute path), ``ids`` (default: all), ``robot`` a folder with ``panda.urdf``
    and ``panda.srdf`` (default: the shipped Panda), ``motion`` the motion validator
    (``"certified"`` or ``"discrete"``). ``ValueError`` for what cannot be read."""
    from ..worlds.mbm import load_mbm

    problems = load_mbm(scenario)
    available = [problem.id for problem in problems]
    missing = sorted(set(ids or ()) - set(available))
    if missing:
        raise ValueError(f"ids {missing} not in the file (it has {min(available)}..{max(available)})")
    name = problems[0].scenario if problems else Path(scenario).stem
    return _mbm_specs(name, scenario, available if ids is None else list(ids), robot, motion)


def _mbm_specs(name: str, source: str, ids: Sequence[int], robot: str, motion: str) -> list[ProblemSpec]:
    """Specs of the problems ``ids`` of a scenario, with the digest of its files unless shipped."""
    from ..validity import MOTION_VALIDATORS
    from ..worlds.mbm import SCENARIOS, files_digest

    files = [] if source in SCENARIOS else [Path(source)]
    if robot:
        files += [Path(robot) / "panda.urdf", Path(robot) / "panda.srdf"]
    data = files_digest(files) if files else ""
    if motion not in MOTION_VALIDATORS:
        raise ValueError(f"motion must be one of {', '.join(MOTION_VALIDATORS)}, got {motion!r}")
    return [
        ProblemSpec(f"{name}.{i:03d}", "mbm", source, problem_id=i, robot=robot, data=data, motion=motion) for i in ids
    ]


# -- the experiment ---------------------------------------------------------------------


def run_seed(experiment_seed: int, problem: str, planner: str, run: int) -> int:
    """The seed of one run, in ``[1, 2**31 - 2]``: a hash of the experiment seed and the run's coordinates.

    The same run gets the same seed whatever else the experiment holds and wherever it
    executes, so it can be re-executed alone.
    """
    digest = hashlib.blake2b(f"{experiment_seed}\0{problem}\0{planner}\0{run}".encode(), digest_size=8).digest()
    return 1 + int.from_bytes(digest, "little") % (2**31 - 2)


@functools.cache
def versions() -> dict[str, str]:
    """The versions of this package and of OMPL's Python package that runs execute with (read
    once per process: every cell's definition carries them)."""
    return {"ompl-balance": metadata.version("ompl-balance"), "ompl": metadata.version("ompl")}


def digest(definition: Mapping[str, Any]) -> str:
    """A short stable hash of a JSON-able definition."""
    text = json.dumps(definition, sort_keys=True, default=str)
    return hashlib.blake2b(text.encode(), digest_size=8).hexdigest()


@dataclass(frozen=True)
class RunTask:
    """One run: everything a worker process needs to execute it."""

    problem: ProblemSpec
    planner: PlannerSpec
    run: int  # 0-based index within its cell
    seed: int
    time_limit: float  # s of planning (and again at most as much for simplification)
    memory_limit: float  # MB the run may add to its process's memory (runner.MemoryLimit), 0 = no limit
    hard_limit: float  # s of wall clock after which the run's process is killed
    definition: str = ""  # digest of the cell's definition (Experiment.cell_definition)
    warm_up: bool = True  # an untimed short solve before the timed one (runner.warm_up)

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.problem.name, self.planner.label, self.run)


HARD_LIMIT_MARGIN = 5.0  # s added to 2 x the time limit before a run is killed

#: The experiment's fields that define every run's result (besides its problem and planner).
RUN_DEFINING_FIELDS = ("seed", "time_limit", "memory_limit", "hard_limit_margin", "warm_up")


@dataclass(frozen=True)
class Experiment:
    """Problems x planners x runs, with the limits and the seed every run is derived from."""

    name: str
    problems: tuple[ProblemSpec, ...]
    planners: tuple[PlannerSpec, ...]
    runs: int
    time_limit: float
    memory_limit: float = 0.0
    seed: int = 1
    baseline: str = ""
    hard_limit_margin: float = HARD_LIMIT_MARGIN
    warm_up: bool = True

    def __post_init__(self) -> None:
        check_experiment(self)

    def cell_definition(self, problem: ProblemSpec, planner: PlannerSpec) -> dict[str, Any]:
        """Everything that defines the results of a (problem, planner) cell: both specs, the
        seed and limits, and the versions of this package and OMPL. A finished run counts
        for this experiment only when it was recorded under the same definition."""
        return {
            "problem": asdict(problem),
            "planner": asdict(planner),
            **{key: getattr(self, key) for key in RUN_DEFINING_FIELDS},
            "versions": versions(),
        }

    def tasks(self) -> list[RunTask]:
        """All runs, interleaved (run 0 of every cell, then run 1, ...) so slow phases of the machine hit all alike."""
        definitions = {
            (problem.name, planner.label): digest(self.cell_definition(problem, planner))
            for problem in self.problems
            for planner in self.planners
        }
        return [
            RunTask(
                problem,
                planner,
                run,
                run_seed(self.seed, problem.name, planner.label, run),
                self.time_limit,
                self.memory_limit,
                2 * self.time_limit + self.hard_limit_margin,
                definitions[problem.name, planner.label],
                self.warm_up,
            )
            for run in range(self.runs)
            for problem in self.problems
            for planner in self.planners
        ]

    @property
    def baseline_label(self) -> str:
        return self.baseline or self.planners[0].label

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Experiment:
        """Inverse of :meth:`as_dict` (e.g. from ``experiment.json`` in an output folder; other keys are ignored)."""
        values = {key: data[key] for key in (f.name for f in fields(cls)) if key in data}
        values["problems"] = tuple(ProblemSpec(**p) for p in data["problems"])
        values["planners"] = tuple(PlannerSpec(**p) for p in data["planners"])
        return cls(**values)


def check_experiment(experiment: Experiment) -> None:
    """Raise :class:`ExperimentError` naming the offending key for anything that cannot run."""
    if not re.fullmatch(r"[A-Za-z0-9_.\-]+", experiment.name):
        raise ExperimentError(
            "name", f"{experiment.name!r} must be letters, digits, '_', '.', '-' (it names the OMPL logs)"
        )
    if isinstance(experiment.runs, bool) or not isinstance(experiment.runs, int) or experiment.runs < 1:
        raise ExperimentError("runs", f"must be a whole number >= 1, got {experiment.runs!r}")
    for key in ("time_limit", "memory_limit", "hard_limit_margin"):
        value = getattr(experiment, key)
        positive = key == "time_limit"
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not (value > 0 if positive else value >= 0)
            or value == float("inf")
        ):
            raise ExperimentError(
                key, f"must be a {'positive' if positive else 'non-negative'} finite number, got {value!r}"
            )
    if not isinstance(experiment.warm_up, bool):
        raise ExperimentError("warm_up", f"must be true or false, got {experiment.warm_up!r}")
    if isinstance(experiment.seed, bool) or not isinstance(experiment.seed, int) or experiment.seed < 0:
        raise ExperimentError("seed", f"must be a whole number >= 0, got {experiment.seed!r}")
    if not experiment.problems:
        raise ExperimentError("problems", "the experiment has none")
    if not experiment.planners:
        raise ExperimentError("planners", "the experiment has none")
    for key, names in (
        ("problems", [p.name for p in experiment.problems]),
        ("planners", [p.label for p in experiment.planners]),
    ):
        duplicates = sorted({n for n in names if names.count(n) > 1})
        if duplicates:
            raise ExperimentError(key, f"names and labels must be unique, repeated: {', '.join(duplicates)}")
    labels = [p.label for p in experiment.planners]
    if experiment.baseline and experiment.baseline not in labels:
        raise ExperimentError(
            "baseline", f"{experiment.baseline!r} is not a planner label; labels: {', '.join(labels)}"
        )
    for index, planner in enumerate(experiment.planners):
        try:
            planner.check()
        except ExperimentError as error:
            raise ExperimentError(
                f"planners[{index}].{error.key}", str(error).partition(": ")[2], error.value
            ) from error


# -- TOML -------------------------------------------------------------------------------

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
_PROBLEM_KEYS = {"builtin": set(), "mbm": {"robot", "ids", "motion"}, "factory": {"name", "args"}}
_PLANNER_KEYS = {"name", "factory", "label", "params"}


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
    except OSError as error:
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
    problems = [p for index, table in enumerate(_tables(data, "problems")) for p in _problems(table, index, base_dir)]
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


def _problems(table: Mapping[str, Any], index: int, base_dir: Path) -> list[ProblemSpec]:
    where = f"problems[{index}]"
    kinds = [kind for kind in _PROBLEM_KEYS if kind in table]
    if len(kinds) != 1:
        raise ExperimentError(where, f"needs exactly one of builtin, mbm, factory; got {', '.join(kinds) or 'none'}")
    kind = kinds[0]
    unknown = sorted(set(table) - {kind} - _PROBLEM_KEYS[kind])
    if unknown:
        raise ExperimentError(
            f"{where}.{unknown[0]}",
            f"unknown key for a {kind} problem; accepted: {', '.join(sorted(_PROBLEM_KEYS[kind]))}",
        )
    if kind == "builtin":
        if table["builtin"] not in PROBLEMS:
            raise ExperimentError(
                f"{where}.builtin",
                f"unknown problem {table['builtin']!r}; built-in: {', '.join(PROBLEMS)}",
                table["builtin"],
            )
        return [ProblemSpec(table["builtin"], "builtin", table["builtin"])]
    if kind == "factory":
        try:
            _import_function(table["factory"])
        except ValueError as error:
            raise ExperimentError(f"{where}.factory", str(error), table["factory"]) from error
        if "name" not in table:
            raise ExperimentError(f"{where}.name", "a factory problem needs a name")
        return [ProblemSpec(str(table["name"]), "factory", table["factory"], args=dict(table.get("args", {})))]
    return _mbm_problems(table, where, base_dir)


def _mbm_problems(table: Mapping[str, Any], where: str, base_dir: Path) -> list[ProblemSpec]:
    from ..validity import MOTION_VALIDATORS
    from ..worlds.mbm import SCENARIOS, load_mbm

    source = str(table["mbm"])
    if source not in SCENARIOS:  # a file, relative to the experiment file
        path = (base_dir / source).resolve()
        if not path.is_file():
            raise ExperimentError(
                f"{where}.mbm",
                f"{source!r} is neither a shipped scenario ({', '.join(SCENARIOS)}) "
                f"nor a file (looked for {str(path)!r})",
                table["mbm"],
            )
        source = str(path)
    robot = ""  # the Panda shipped with the package
    if "robot" in table:
        robot = str((base_dir / table["robot"]).resolve())
        missing = [name for name in ("panda.urdf", "panda.srdf") if not (Path(robot) / name).is_file()]
        if missing:
            raise ExperimentError(f"{where}.robot", f"no {' or '.join(missing)} in {robot!r}", table["robot"])
    try:
        scenario = load_mbm(source)
    except ValueError as error:
        raise ExperimentError(f"{where}.mbm", str(error), table["mbm"]) from error
    ids = _ids(table.get("ids", "all"), [problem.id for problem in scenario], f"{where}.ids")
    motion = table.get("motion", "certified")
    if motion not in MOTION_VALIDATORS:
        raise ExperimentError(
            f"{where}.motion", f"must be one of {', '.join(MOTION_VALIDATORS)}, got {motion!r}", motion
        )
    name = scenario[0].scenario if scenario else Path(source).stem
    return _mbm_specs(name, source, ids, robot, motion)


def _ids(selection: Any, available: list[int], where: str) -> list[int]:
    """Problem ids from ``"all"`` or a list of ids and ``"first-last"`` ranges (inclusive)."""
    if selection == "all":
        return available
    if not isinstance(selection, list) or not selection:
        raise ExperimentError(where, f'must be "all" or a list of ids and "first-last" ranges, got {selection!r}')
    ids: list[int] = []
    for item in selection:
        if isinstance(item, int) and not isinstance(item, bool):
            ids.append(item)
        elif isinstance(item, str) and re.fullmatch(r"\d+-\d+", item):
            first, last = map(int, item.split("-"))
            ids.extend(range(first, last + 1))
        else:
            raise ExperimentError(where, f'{item!r} is neither an id nor a "first-last" range')
    missing = sorted(set(ids) - set(available))
    if missing:
        raise ExperimentError(where, f"ids {missing} not in the file (it has {min(available)}..{max(available)})")
    return list(dict.fromkeys(ids))


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
