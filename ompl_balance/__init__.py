"""ompl_balance: tree-balancing RRT-Connect and friends for OMPL's Python bindings.

Planners subclass ``ompl.base.Planner`` and drop into ``og.SimpleSetup`` and
``ompl.tools.Benchmark``; they are configured with ``planner.params().setParam``.

The robot layer (URDF kinematics, FCL collision checking, MotionBenchMaker scenes) and
the benchmark runner are imported on first use, so ``import ompl_balance`` stays quick
when they are not needed.
"""

from __future__ import annotations

import importlib
from typing import Any

from .counting import CountingValidityChecker, WorkCount, ensure_counting, read_work
from .gamma import (
    FreeMeasure,
    ball_radius_constant,
    estimate_ball_radius_constant,
    estimate_free_measure,
    ompl_rewire_factor,
    rewire_radius,
    unit_ball_volume,
)
from .occupancy import OCCUPANCY_PROBLEMS, GridValidityChecker, OccupancyGrid, OccupancyProblem, rooms_grid, rooms_problem
from .params import ParamSet
from .planners import (
    NEAREST_POLICIES,
    PRESETS,
    SAMPLE_POLICIES,
    SWAP_CAUSES,
    SWAP_POLICIES,
    BallRadiusRRTstar,
    BalancedRRTConnect,
    CollisionSwapRRTConnect,
    ControlChosenRRTConnect,
    ExhaustedNodesRRTConnect,
    ExhaustionRRTConnect,
    GaussianPassageRRTConnect,
    GoalBiasRRTConnect,
    NeighbourCostRRTConnect,
    RRTstarStats,
    RunStats,
    SwapLimitRRTConnect,
    balance_choice,
    exhaustion_scale,
    nearest_by_exhaustion,
    nearest_not_exhausted,
    node_quality,
    path_length_objective,
    tree_chooser,
    tree_size_ratio,
)
from .problems import PROBLEMS, BoxWorld2D, Problem, get_problem
from .samplers import BridgeTestValidStateSampler, GaussianValidStateSampler, PassageSampler

# name -> module, for the robot layer (trimesh, FCL) and the benchmark runner, loaded
# lazily by __getattr__
_LAZY = {
    "Experiment": "experiment",
    "ProblemSpec": "experiment",
    "PlannerSpec": "experiment",
    "RunTask": "experiment",
    "ExperimentError": "experiment",
    "load_experiment": "experiment",
    "run_seed": "experiment",
    "bench": "benchmark",
    "compare_experiment": "benchmark",
    "run_isolated": "runner",
    "ResultStore": "runner",
    "sweep": "runner",
    "write_logs": "ompl_log",
    "to_database": "ompl_log",
    "summarize": "summary",
    "plot_folder": "plots",
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
    "BallRadiusRRTstar",
    "BalancedRRTConnect",
    "BoxWorld2D",
    "BridgeTestValidStateSampler",
    "CollisionSwapRRTConnect",
    "ControlChosenRRTConnect",
    "CountingValidityChecker",
    "ExhaustedNodesRRTConnect",
    "ExhaustionRRTConnect",
    "FreeMeasure",
    "GaussianPassageRRTConnect",
    "GaussianValidStateSampler",
    "GoalBiasRRTConnect",
    "GridValidityChecker",
    "NEAREST_POLICIES",
    "NeighbourCostRRTConnect",
    "OCCUPANCY_PROBLEMS",
    "OccupancyGrid",
    "OccupancyProblem",
    "PRESETS",
    "PROBLEMS",
    "ParamSet",
    "PassageSampler",
    "Problem",
    "RRTstarStats",
    "RunStats",
    "SAMPLE_POLICIES",
    "SWAP_CAUSES",
    "SWAP_POLICIES",
    "SwapLimitRRTConnect",
    "WorkCount",
    "balance_choice",
    "ball_radius_constant",
    "ensure_counting",
    "estimate_ball_radius_constant",
    "estimate_free_measure",
    "exhaustion_scale",
    "get_problem",
    "nearest_by_exhaustion",
    "nearest_not_exhausted",
    "node_quality",
    "ompl_rewire_factor",
    "path_length_objective",
    "read_work",
    "rewire_radius",
    "rooms_grid",
    "rooms_problem",
    "tree_chooser",
    "tree_size_ratio",
    "unit_ball_volume",
    *_LAZY,
]
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'ompl_balance' has no attribute {name!r}")
