"""ompl_balance: tree-balancing RRT-Connect and friends for OMPL's Python bindings.

Planners subclass ``ompl.base.Planner`` and drop into ``og.SimpleSetup`` and
``ompl.tools.Benchmark``; they are configured with ``planner.params().setParam``.

The robot layer (URDF kinematics, FCL collision checking, MotionBenchMaker scenes) is
imported on first use, so ``import ompl_balance`` stays quick when it is not needed.
"""

from __future__ import annotations

import importlib
from typing import Any

from .counting import CountingValidityChecker, WorkCount, ensure_counting, read_work
from .params import ParamSet
from .planners import BalancedRRTConnect, RunStats, balance_choice, tree_size_ratio

# name -> module of the robot layer (loaded lazily by __getattr__)
_ROBOT_LAYER = {
    "RobotModel": "kinematics",
    "Environment": "validity",
    "CollisionChecker": "validity",
    "StateValidityChecker": "validity",
    "MotionValidator": "validity",
    "space_for": "validity",
    "setup_robot": "validity",
    "load_mbm": "mbm",
    "MBMProblem": "mbm",
    "load_example_robot_data_panda": "robots",
    "load_panda_vamp": "robots",
}

__all__ = [
    "BalancedRRTConnect",
    "CountingValidityChecker",
    "ParamSet",
    "RunStats",
    "WorkCount",
    "balance_choice",
    "ensure_counting",
    "read_work",
    "tree_size_ratio",
    *_ROBOT_LAYER,
]
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    if name in _ROBOT_LAYER:
        return getattr(importlib.import_module(f".{_ROBOT_LAYER[name]}", __name__), name)
    raise AttributeError(f"module 'ompl_balance' has no attribute {name!r}")
