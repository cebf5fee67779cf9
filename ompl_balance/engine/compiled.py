"""Whether a solve runs on the compiled engine, and running it.

:class:`CompiledEngine` is what a planner asks before each solve: it keeps the solves' check
view (:mod:`ompl_balance.engine.views`), and returns the compiled engine's run when the engine
for that kind of view is loaded in this process (or, with ``engine=compiled``, after loading
it); otherwise it starts loading it in the background (:mod:`ompl_balance.engine.loading`) and
returns ``None``, and the solve runs on the Python engine. Nothing here imports numba: a process that never
plans on the compiled engine never loads it.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib
import math
import pickle
import subprocess
import sys
import tempfile
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import ModuleType
from typing import Any

from ompl import base as ob
from ompl import util as ou

from ..core.checks import load_kernels
from ..core.file_lock import file_lock
from ..core.layout import SpaceLayout
from ..core.spaces import ArrayPoints
from ..core.trees import ArrayTree, Tree
from .loading import LOADER, view_key
from .solve import Solve
from .views import EngineChecks, checks_for

#: ``run(ptc) -> (status, checks)``: a solve on the compiled engine; ``checks`` is how it checked.
CompiledRun = Callable[[ob.PlannerTerminationCondition], tuple[Any, str]]


def room_per_iteration(layout: SpaceLayout, extent: float, step: float, intermediate_states: bool) -> int:
    """Nodes one iteration can add to a tree: the extension step and a connect of at most
    ``extent / step + 1`` steps (``step``: the planner's range), each of one node (or of its
    motion's states with ``intermediate_states``), and a goal state."""
    steps = math.ceil(extent / step) + 2
    per_step = 1
    if intermediate_states:
        for factor, segment, weight in zip(layout.factor, layout.segment, layout.weight):
            reach = min(step / weight, extent) if weight > 0.0 else extent
            per_step = max(per_step, int(factor) * math.ceil(reach / segment))
    return steps * per_step + 1


class _Compiling:
    """Where this process has a missing specialization of the engine compiled (see :func:`_warm`)."""

    in_this_process = False


def compile_in_this_process() -> None:
    """Have this process compile the engine's missing specializations itself rather than in a
    worker process: for processes that only compile (the first sweep's,
    :func:`ompl_balance.bench.first_compile.compile_in_parallel`), where holding the interpreter
    costs nothing and a worker's start-up and the loading of its work after it would cost some
    seconds per specialization."""
    _Compiling.in_this_process = True


def _warm(view: Any, layout: SpaceLayout) -> None:
    """Make the engine for ``view`` and ``layout`` ready in this process: loaded from numba's cache,
    or, when it is not there, compiled into it by another process first
    (:mod:`ompl_balance.engine.compile_worker`; a compilation takes tens of seconds, mostly in
    Python, and would hold this interpreter), then loaded; compiled here in a process that only
    compiles (:func:`compile_in_this_process`)."""
    load_kernels(view)
    from ..core.compiled_calls import load_cached, signature_of  # (these import numba)
    from ..core.kernel_cache import package_digest
    from . import loop

    driver = _driver()
    arguments = driver.warm_up_arguments(view, layout)
    if not load_cached(loop.run, arguments):
        try:
            # one compilation of this specialization at a time on the machine (the next finds it
            # cached); other specializations compile alongside, on the other cores
            with _compile_lock(f"{package_digest()} {signature_of(arguments)}"):
                if _Compiling.in_this_process:
                    driver.warm_up(view, layout)  # (compiled now, unless another process just did)
                elif not load_cached(loop.run, arguments):
                    subprocess.run(
                        [sys.executable, "-m", "ompl_balance.engine.compile_worker"],
                        input=pickle.dumps((view, layout)),
                        capture_output=True,
                        check=True,
                    )
        except (OSError, subprocess.SubprocessError, pickle.PicklingError):
            pass  # compiled here instead
    driver.warm_up(view, layout)


@functools.cache
def _driver() -> ModuleType:
    """:mod:`ompl_balance.engine.driver` (it imports numba), imported at the first compiled solve
    and kept: an import statement in a solve costs a microsecond each time."""
    return importlib.import_module(".driver", __package__)


def runs_compiled(checks: EngineChecks, engine: str) -> bool:
    """Whether ``engine`` (``"auto"`` or ``"compiled"``) plans on the compiled engine with ``checks``:
    both do, whatever the checks (see ``docs/engine.md``: with a checker written in Python the
    compiled loop and its one call into Python per growth of a tree cost less than the Python engine's
    loop around the same checks)."""
    return engine in ("auto", "compiled")


def _compile_lock(what: str) -> contextlib.AbstractContextManager[None]:
    """An exclusive lock on compiling ``what``, shared by the processes of the machine."""
    name = hashlib.sha256(what.encode()).hexdigest()[:16]
    return file_lock(Path(tempfile.gettempdir()) / f"ompl_balance-compile-{name}.lock")


class CompiledEngine:
    """A planner's compiled engine, kept from its setup through its solves.

    Its solves reuse the check view of the space information's checkers (with the engine's key
    for it) and the arrays the loop works in; both are made again only when what they came
    from changes (another checker, validator or layout; other trees). Making them anew each
    solve would cost about as much as a short solve plans.
    """

    def __init__(self) -> None:
        self._checks: EngineChecks | None = None
        self._key: Any = None
        self._arrays: Any = None  # the driver's SolveArrays (made at the first compiled solve)

    def _current_checks(self, si: ob.SpaceInformation, layout: SpaceLayout) -> EngineChecks:
        checks = checks_for(si, layout, self._checks)
        if checks is not self._checks:
            self._checks, self._key = checks, view_key((checks.view, layout))
        return checks

    def load(self, si: ob.SpaceInformation, layout: SpaceLayout, engine: str, wait: bool) -> None:
        """Start loading the compiled engine for ``si``'s checks in the background, or (``wait``)
        load it now, where ``engine`` would plan on it (:func:`runs_compiled`).

        Planners call this from ``setup()``: ``SimpleSetup.solve`` sets up before the solve's
        time limit starts, so a wait here (``engine=compiled``) does not eat into the solve.
        """
        checks = self._current_checks(si, layout)
        if not runs_compiled(checks, engine):
            return
        warm = partial(_warm, checks.view, layout)
        if wait:
            LOADER.wait(self._key, warm, _describe(checks))
        else:
            LOADER.start(self._key, warm)

    def prepare(
        self,
        points: ArrayPoints,
        settings: Any,
        record: bool,
        trees: tuple[Tree, Tree],
        failures: tuple[Any, Any],
        room: int,
    ) -> None:
        """Make the arrays and the loop's settings of solves on ``trees`` (start, goal; with their
        ``failures``) now, where the engine is loaded (``settings``: the planner's
        RRTConnectSettings; ``record``: whether solves record the loop; ``room``: the nodes an
        iteration may add). Planners call this as they make their trees, at setup and clear,
        which a solve's time does not count."""
        if self._key is None or not LOADER.ready(self._key):
            return
        if self._arrays is None or self._arrays.layout is not points.layout:
            self._arrays = _driver().SolveArrays(points.layout)
        start_tree, goal_tree = trees
        assert isinstance(start_tree, ArrayTree) and isinstance(goal_tree, ArrayTree)
        self._arrays.hold(start_tree, goal_tree, failures, room)
        self._arrays.settings_for(points, settings, record)

    def run_of(self, solve: Solve, layout: SpaceLayout, room: int, engine: str, name: str) -> CompiledRun | None:
        """The compiled engine's run of ``solve`` where ``engine`` plans on it (:func:`runs_compiled`)
        and it is ready (``engine="compiled"``: made ready now), else ``None``."""
        checks = self._current_checks(solve.si, layout)
        if not runs_compiled(checks, engine):
            return None
        key = self._key
        if not LOADER.ready(key):
            if engine == "compiled":
                LOADER.wait(key, partial(_warm, checks.view, layout), _describe(checks))
            else:
                failure = LOADER.failure(key)
                if failure is not None:
                    ou.OMPL_WARN(f"{name}: the compiled engine failed to compile ({failure}); solving on Python")
                elif LOADER.start(key, partial(_warm, checks.view, layout)):
                    ou.OMPL_INFORM(
                        f"{name}: the compiled engine is loading in the background; solving on Python meanwhile"
                    )
                return None
        return partial(self._run, solve, checks, layout, key, room)

    def _run(
        self,
        solve: Solve,
        checks: EngineChecks,
        layout: SpaceLayout,
        key: Any,
        room: int,
        ptc: ob.PlannerTerminationCondition,
    ) -> tuple[Any, str]:
        driver = _driver()
        if self._arrays is None or self._arrays.layout is not layout:
            self._arrays = driver.SolveArrays(layout)
        return driver.run(solve, ptc, checks, key, room, self._arrays), checks.path


def _describe(checks: EngineChecks) -> str:
    """What the engine checks with, in the user's terms: the validity checker's and the motion
    validator's classes."""
    checker, validator = checks.source[:2]
    check = getattr(checker, "check", checker)  # what a counting checker counts
    owner = getattr(check, "__self__", check)  # a bound method's object
    name = getattr(owner, "__qualname__", None) or type(owner).__name__
    return f"{name} and {type(validator).__name__}"
