"""Whether a solve runs on the compiled engine, and running it.

:func:`prepared` is what the planner asks before each solve: it builds the solve's check view
(:mod:`ompl_balance.engine.views`), and returns the compiled engine's run when the engine for
that kind of view is loaded in this process (or, with ``wait``, after loading it); otherwise it
starts loading it in the background (:mod:`ompl_balance.engine.loading`) and returns ``None``,
and the solve runs on the Python engine. Nothing here imports numba: a process that never
plans on the compiled engine never loads it.
"""

from __future__ import annotations

import contextlib
import importlib
import math
import pickle
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

from ompl import base as ob
from ompl import util as ou

from ..core.checks import kernel_modules
from ..core.layout import SpaceLayout
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


def _warm(view: Any, layout: SpaceLayout) -> None:
    """Make the engine for ``view`` and ``layout`` ready in this process: compiled into numba's
    cache by another process (:mod:`ompl_balance.engine.compile_worker`; a compilation takes tens
    of seconds, mostly in Python, and would hold this interpreter), then loaded from it here."""
    try:
        with _compile_lock():  # one compilation at a time on the machine: the next one finds it cached
            subprocess.run(
                [sys.executable, "-m", "ompl_balance.engine.compile_worker"],
                input=pickle.dumps((view, layout)),
                capture_output=True,
                check=True,
            )
    except (OSError, subprocess.SubprocessError, pickle.PicklingError):
        pass  # compiled here instead
    modules = [importlib.import_module(module) for module in kernel_modules(view)]
    from .driver import warm_up

    warm_up(view, layout)
    for module in modules:  # the exits to Python, run once (see their warm_exits)
        warm_exits = getattr(module, "warm_exits", None)
        if warm_exits is not None:
            warm_exits()


def runs_compiled(checks: EngineChecks, engine: str) -> bool:
    """Whether ``engine`` (``"auto"`` or ``"compiled"``) plans on the compiled engine with ``checks``.

    ``auto`` keeps the Python engine where every check is a call to Python (``checks.path ==
    "python"``: a user's callable, a C++ checker): such a call made from compiled code costs
    more than the compiled loop saves around it.
    """
    return engine == "compiled" or checks.path == "kernel"


def load(si: ob.SpaceInformation, layout: SpaceLayout, engine: str, wait: bool) -> None:
    """Start loading the compiled engine for ``si``'s checks in the background, or (``wait``) load
    it now, where ``engine`` would plan on it (:func:`runs_compiled`).

    Planners call this from ``setup()``: ``SimpleSetup.solve`` sets up before the solve's
    time limit starts, so a wait here (``engine=compiled``) does not eat into the solve.
    """
    checks = checks_for(si, layout)
    if not runs_compiled(checks, engine):
        return
    key = view_key((checks.view, layout))
    warm = partial(_warm, checks.view, layout)
    if wait:
        LOADER.wait(key, warm, _describe(checks))
    else:
        LOADER.start(key, warm)


@contextlib.contextmanager
def _compile_lock() -> Iterator[None]:
    """An exclusive lock shared by the processes of the machine (where the system has ``flock``)."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    with open(Path(tempfile.gettempdir()) / "ompl_balance-compile.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def prepared(solve: Solve, layout: SpaceLayout, room: int, engine: str, name: str) -> CompiledRun | None:
    """The compiled engine's run of ``solve`` where ``engine`` plans on it (:func:`runs_compiled`)
    and it is ready (``engine="compiled"``: made ready now), else ``None``."""
    checks = checks_for(solve.si, layout)
    if not runs_compiled(checks, engine):
        return None
    key = view_key((checks.view, layout))
    ready = LOADER.ready(key)
    if engine == "compiled" and not ready:
        LOADER.wait(key, partial(_warm, checks.view, layout), _describe(checks))
    elif not ready:
        failure = LOADER.failure(key)
        if failure is None:
            if LOADER.start(key, partial(_warm, checks.view, layout)):
                ou.OMPL_INFORM(f"{name}: the compiled engine is loading in the background; solving on Python meanwhile")
        else:
            ou.OMPL_WARN(f"{name}: the compiled engine failed to compile ({failure}); solving on Python")
        return None
    return partial(_run, solve, checks, layout, key, room)


def _run(
    solve: Solve, checks: EngineChecks, layout: SpaceLayout, key: Any, room: int, ptc: ob.PlannerTerminationCondition
) -> tuple[Any, str]:
    from .driver import run

    return run(solve, ptc, checks, layout, key, room), checks.path


def _describe(checks: EngineChecks) -> str:
    """The kind of checks, in words, for the compiling message."""
    view = checks.view
    inner = getattr(view, "states", None)
    return type(view).__name__ if inner is None else f"{type(view).__name__} of {type(inner).__name__}"
