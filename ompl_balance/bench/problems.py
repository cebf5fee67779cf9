"""The problems of experiments: :class:`ProblemSpec`, and the kinds of problem it can be.

Each kind is one entry of :data:`PROBLEM_KINDS`, which says everything the benchmark does
differently for it: the key that names it in an experiment file (``builtin = "narrow_gap"``,
``mbm = "box"``, ``rigid = "se3_room"``, ``factory = "module:function"``), the other keys its table takes, how a
table becomes specs, how a run builds a spec's ``og.SimpleSetup``, which modules a sweep's
forkserver imports for it, and which names ``ompl-balance compare --problems`` takes. A new
kind of problem is a new entry.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ompl import geometric as og

from ..core.counting import ensure_counting
from ..worlds.boxes import PROBLEMS
from .errors import ExperimentError
from .factories import import_function


@dataclass(frozen=True)
class ProblemSpec:
    """A problem of the experiment; :meth:`build` makes its ``og.SimpleSetup``.

    ``kind`` is a key of :data:`PROBLEM_KINDS`: ``"builtin"`` (``source`` names one of
    ``ompl_balance.worlds.boxes.PROBLEMS``), ``"mbm"`` (``source`` is a shipped
    MotionBenchMaker scenario or a JSON file, ``problem_id`` the problem's id, ``robot``
    the robot folder, empty for the shipped Panda, and ``motion`` the motion validator,
    ``"certified"`` or ``"discrete"``), ``"rigid"`` (``source`` a shipped rigid-body problem or
    an OMPL.app ``.cfg`` file, ``motion`` as for ``"mbm"``) or ``"factory"`` (``source`` is ``"module:function"``
    called with ``args``). ``name`` is unique in the experiment and names its log file.
    ``data`` is a digest of the files the problem is read from when they are not shipped
    with the package, so that an edited file makes a new problem.
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
        ss = PROBLEM_KINDS[self.kind].build(self)
        ensure_counting(ss.getSpaceInformation())
        return ss

    @property
    def description(self) -> str:
        """What the problem is, in words of its experiment file (``"mbm box id 3"``)."""
        return f"{self.kind} {self.source}" + (f" id {self.problem_id}" if self.problem_id else "")


#: ``read(table, where, base_dir)``: an experiment file's problem table -> its specs
#: (:class:`ExperimentError` with keys under ``where``; relative paths against ``base_dir``).
TableReader = Callable[[Mapping[str, Any], str, Path], list[ProblemSpec]]


@dataclass(frozen=True)
class ProblemKind:
    """How the benchmark handles one kind of problem (see the module docstring)."""

    options: frozenset[str]  # the keys a problem table of this kind takes besides the kind's own
    read: TableReader
    build: Callable[[ProblemSpec], og.SimpleSetup]
    preload: tuple[str, ...] = ()  # modules the forkserver of a sweep with such problems imports once
    by_name: Callable[[str], ProblemSpec | None] | None = None  # ompl-balance compare --problems NAME
    names: Callable[[], str] | None = None  # the names by_name takes, in words
    scenarios: bool = False  # named SCENARIO.NNN: summaries also pool each scenario's problems


def shipped_or_file(
    table: Mapping[str, Any], key: str, shipped: Sequence[str], what: str, where: str, base_dir: Path
) -> str:
    """``table[key]`` when it names one of ``shipped``, else the absolute path of the file it
    names relative to the experiment file; :class:`ExperimentError` when it is neither."""
    source = table[key]
    if not isinstance(source, str):
        raise ExperimentError(f"{where}.{key}", f"must be a shipped {what}'s name or a file", source)
    if source in shipped:
        return source
    path = (base_dir / source).resolve()
    if not path.is_file():
        raise ExperimentError(
            f"{where}.{key}",
            f"{source!r} is neither a shipped {what} ({', '.join(shipped)}) nor a file (looked for {str(path)!r})",
            source,
        )
    return str(path)


# -- built-in 2-D problems ----------------------------------------------------------------


def _builtin(name: str) -> ProblemSpec | None:
    return ProblemSpec(name, "builtin", name) if name in PROBLEMS else None


def _read_builtin(table: Mapping[str, Any], where: str, base_dir: Path) -> list[ProblemSpec]:
    spec = _builtin(table["builtin"]) if isinstance(table["builtin"], str) else None
    if spec is None:
        raise ExperimentError(
            f"{where}.builtin",
            f"unknown problem {table['builtin']!r}; built-in: {', '.join(PROBLEMS)}",
            table["builtin"],
        )
    return [spec]


def _build_builtin(spec: ProblemSpec) -> og.SimpleSetup:
    return PROBLEMS[spec.source].setup()


def _builtin_names() -> str:
    return f"built-in: {', '.join(PROBLEMS)}"


# -- MotionBenchMaker problems ------------------------------------------------------------


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


def _mbm_by_name(name: str) -> ProblemSpec | None:
    """A shipped MotionBenchMaker Panda problem ``<scenario>.<id>`` (``box.001``); ``ValueError`` for an id
    the scenario lacks."""
    from ..worlds.mbm import SCENARIOS

    scenario, _, number = name.rpartition(".")
    if scenario in SCENARIOS and number.isdigit():
        return mbm_problems(scenario, [int(number)])[0]
    return None


def _mbm_names() -> str:
    from ..worlds.mbm import SCENARIOS

    return f"MotionBenchMaker Panda problems SCENARIO.ID with SCENARIO one of {', '.join(SCENARIOS)} (e.g. box.001)"


def _read_mbm(table: Mapping[str, Any], where: str, base_dir: Path) -> list[ProblemSpec]:
    from ..validity import MOTION_VALIDATORS
    from ..worlds.mbm import SCENARIOS, load_mbm

    source = shipped_or_file(table, "mbm", SCENARIOS, "scenario", where, base_dir)
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


def _build_mbm(spec: ProblemSpec) -> og.SimpleSetup:
    from ..worlds.mbm import problem_setup

    return problem_setup(spec.source, spec.problem_id, spec.robot, spec.motion or "certified")


# -- rigid bodies ---------------------------------------------------------------------------


def _rigid_by_name(name: str) -> ProblemSpec | None:
    from ..worlds.rigid import RIGID_PROBLEMS

    return ProblemSpec(name, "rigid", name, motion="certified") if name in RIGID_PROBLEMS else None


def _rigid_names() -> str:
    from ..worlds.rigid import RIGID_PROBLEMS

    return f"rigid bodies: {', '.join(RIGID_PROBLEMS)}"


def _read_rigid(table: Mapping[str, Any], where: str, base_dir: Path) -> list[ProblemSpec]:
    from ..validity import MOTION_VALIDATORS
    from ..worlds.mbm import files_digest
    from ..worlds.omplapp import load_omplapp
    from ..worlds.rigid import RIGID_PROBLEMS

    source, data = shipped_or_file(table, "rigid", RIGID_PROBLEMS, "problem", where, base_dir), ""
    if source not in RIGID_PROBLEMS:  # an OMPL.app problem file
        try:
            load_omplapp(source, validate=False)
        except ValueError as error:
            raise ExperimentError(f"{where}.rigid", str(error), table["rigid"]) from error
        data = files_digest([Path(source)])
    motion = table.get("motion", "certified")
    if motion not in MOTION_VALIDATORS:
        raise ExperimentError(
            f"{where}.motion", f"must be one of {', '.join(MOTION_VALIDATORS)}, got {motion!r}", motion
        )
    name = str(table.get("name", Path(source).stem))
    return [ProblemSpec(name, "rigid", source, data=data, motion=motion)]


def _build_rigid(spec: ProblemSpec) -> og.SimpleSetup:
    from ..worlds.rigid import rigid_problem

    return rigid_problem(spec.source).simple_setup(motion=spec.motion or "certified")


# -- the user's own problems --------------------------------------------------------------


def _read_factory(table: Mapping[str, Any], where: str, base_dir: Path) -> list[ProblemSpec]:
    try:
        import_function(table["factory"])
    except ValueError as error:
        raise ExperimentError(f"{where}.factory", str(error), table["factory"]) from error
    if "name" not in table:
        raise ExperimentError(f"{where}.name", "a factory problem needs a name")
    args = table.get("args", {})
    if not isinstance(args, dict):
        raise ExperimentError(f"{where}.args", "must be a table of argument = value")
    return [ProblemSpec(str(table["name"]), "factory", table["factory"], args=dict(args))]


def _build_factory(spec: ProblemSpec) -> og.SimpleSetup:
    ss = import_function(spec.source)(**spec.args)
    if not isinstance(ss, og.SimpleSetup):
        raise TypeError(f"problem factory {spec.source} returned {type(ss).__name__}, not og.SimpleSetup")
    return ss


#: The kinds of problem, by the experiment file's key that names them.
PROBLEM_KINDS: dict[str, ProblemKind] = {
    "builtin": ProblemKind(frozenset(), _read_builtin, _build_builtin, by_name=_builtin, names=_builtin_names),
    "mbm": ProblemKind(
        frozenset({"robot", "ids", "motion"}),
        _read_mbm,
        _build_mbm,
        preload=("ompl_balance.bench.preload_robots",),
        by_name=_mbm_by_name,
        names=_mbm_names,
        scenarios=True,
    ),
    "rigid": ProblemKind(
        frozenset({"name", "motion"}),
        _read_rigid,
        _build_rigid,
        preload=("ompl_balance.bench.preload_rigid",),
        by_name=_rigid_by_name,
        names=_rigid_names,
    ),
    "factory": ProblemKind(frozenset({"name", "args"}), _read_factory, _build_factory),
}


def problem_by_name(name: str) -> ProblemSpec:
    """The problem ``ompl-balance compare --problems`` calls ``name``; ``ValueError`` naming what is accepted."""
    for kind in PROBLEM_KINDS.values():
        spec = kind.by_name(name) if kind.by_name is not None else None
        if spec is not None:
            return spec
    accepted = "; ".join(kind.names() for kind in PROBLEM_KINDS.values() if kind.names is not None)
    raise ValueError(f"unknown problem {name!r}; {accepted}")


def read_problem_table(table: Mapping[str, Any], where: str, base_dir: Path) -> list[ProblemSpec]:
    """The specs of an experiment file's ``[[problems]]`` table (exactly one kind's key, that kind's options)."""
    kinds = [kind for kind in PROBLEM_KINDS if kind in table]
    if len(kinds) != 1:
        raise ExperimentError(
            where, f"needs exactly one of {', '.join(PROBLEM_KINDS)}; got {', '.join(kinds) or 'none'}"
        )
    kind = PROBLEM_KINDS[kinds[0]]
    unknown = sorted(set(table) - {kinds[0]} - kind.options)
    if unknown:
        raise ExperimentError(
            f"{where}.{unknown[0]}",
            f"unknown key for a {kinds[0]} problem; accepted: {', '.join(sorted(kind.options)) or 'none'}",
        )
    return kind.read(table, where, base_dir)
