"""Imported by every sweep's forkserver (see ``isolation.preload_modules``): the code a run
executes, the planners' compiled tree scans and the compiled engine for the built-in box
worlds, compiled with a notice the first time after installing, so every run's process,
forked from the forkserver, starts with them ready."""

from .compile_notice import compile_notice

with compile_notice("the planners' tree scans"):
    from ..core import compiled_spaces  # noqa: F401  (compiled when imported)
    from . import execution  # noqa: F401


def _load_engine() -> None:
    from ..planners import BalancedRRTConnect
    from ..worlds.boxes import PROBLEMS

    ss = PROBLEMS["open"].setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    ss.setPlanner(planner)
    ss.setup()
    planner.wait_for_engine()


_load_engine()
