"""Imported by every sweep's forkserver (see ``isolation.preload_modules``): the code a run
executes, the planners' compiled tree scans and the compiled engine for the built-in box
worlds, compiled with a notice the first time after installing, so every run's process,
forked from the forkserver, starts with them ready.

First of all it points the forkserver's standard output at its standard error, for every
process forked from it: the sweep's standard output holds its tables alone, and what the
forkserver and the runs write there (OMPL's ``Info:`` lines, which OMPL's default output
handler prints on standard output, or a planner's own prints) goes to standard error.
"""

import os
import sys

sys.stdout.flush()
os.dup2(sys.stderr.fileno(), sys.stdout.fileno())

from .compile_notice import compile_notice  # noqa: E402  (after the redirection: it may print)

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
