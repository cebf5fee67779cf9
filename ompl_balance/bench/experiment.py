"""Benchmark experiments as data: which problems, which planners, how many runs, how long.

An :class:`Experiment` is plain data (it pickles, so runs can be sent to other processes
and machines); each run builds its problem and planner where it executes. Experiments come
from TOML files (:mod:`ompl_balance.bench.experiment_file`) or from Python::

    Experiment(
        name="narrow",
        problems=(ProblemSpec("narrow_gap", "builtin", "narrow_gap"),),
        planners=(PlannerSpec("RRTConnect", "RRTConnect"), PlannerSpec("Balanced", "BalancedRRTConnect")),
        runs=5,
        time_limit=1.0,
    )

Everything is checked when the experiment is made, before any run starts: unknown
planners or parameters, repeated names and non-positive numbers raise
:class:`~ompl_balance.bench.errors.ExperimentError` naming the field.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import re
from collections.abc import Iterator, Mapping
from dataclasses import asdict, dataclass, field, fields
from importlib import metadata
from typing import Any

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..planners import PRESETS
from ..rrtstar import BallRadiusRRTstar
from .errors import ExperimentError
from .factories import import_function
from .planner_params import DECLARED_PARAMS, check_declared_param, set_planner_param
from .problems import ProblemSpec

# -- planners ---------------------------------------------------------------------------


def package_planner_classes() -> dict[str, type[ob.Planner]]:
    """This package's planners by name: ``BalancedRRTConnect``, ``BallRadiusRRTstar`` and the presets."""
    return {**PRESETS, "BallRadiusRRTstar": BallRadiusRRTstar}


def stock_planner_classes() -> dict[str, type[ob.Planner]]:
    """OMPL's geometric planners bound in ``ompl.geometric`` (``RRTConnect``, ``RRT``, ``PRM``, ...)."""
    return {name: cls for name, cls in vars(og).items() if isinstance(cls, type) and issubclass(cls, ob.Planner)}


@contextlib.contextmanager
def _ompl_silent() -> Iterator[None]:
    """OMPL's log off for the block: a refused parameter value is reported once, by the error raised."""
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    try:
        yield
    finally:
        ou.setLogLevel(level)


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
            planner = import_function(self.factory)(si)
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
                import_function(self.factory)
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
                with _ompl_silent():
                    set_planner_param(planner, name, value)
            except ValueError as error:
                raise ExperimentError(f"params.{name}", str(error)) from error


# -- runs -------------------------------------------------------------------------------


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
    memory_limit: float  # MB the run may add to its process's memory (execution.MemoryLimit), 0 = no limit
    hard_limit: float  # s of wall clock after which the run's process is killed
    definition: str = ""  # digest of the cell's definition (Experiment.cell_definition)
    warm_up: bool = True  # an untimed short solve before the timed one (execution.warm_up)

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.problem.name, self.planner.label, self.run)


HARD_LIMIT_MARGIN = 5.0  # s added to 2 x the time limit before a run is killed

#: The experiment's fields that define every run's result (besides its problem and planner).
RUN_DEFINING_FIELDS = ("seed", "time_limit", "memory_limit", "hard_limit_margin", "warm_up")


@dataclass(frozen=True)
class Experiment:
    """Problems x planners x runs, with the limits and the seed every run is derived from.

    ``warm_up``: each run's process first solves a fresh copy of the problem briefly,
    neither timed nor counted (:func:`~ompl_balance.bench.execution.warm_up`).
    ``baseline``: the planner label the summary's ratios refer to (default: the first).
    """

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
    if not isinstance(experiment.name, str) or not re.fullmatch(r"[A-Za-z0-9_.\-]+", experiment.name):
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
            raise ExperimentError(f"planners[{index}].{error.key}", error.reason, error.value) from error
