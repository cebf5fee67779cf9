"""ompl_balance: tree-balancing RRT-Connect and friends for OMPL's Python bindings.

Planners subclass ``ompl.base.Planner`` and drop into ``og.SimpleSetup`` and
``ompl.tools.Benchmark``; they are configured with ``planner.params().setParam``.

The package is built in layers (``docs/architecture.md``): :mod:`ompl_balance.core`
(parameters, state points, trees, work counting, the planner base), the planners and
their policies at the top level (:mod:`~ompl_balance.planners`,
:mod:`~ompl_balance.policies`, :mod:`~ompl_balance.rrtstar`, :mod:`~ompl_balance.samplers`),
the robot layer (:mod:`ompl_balance.collision` and its OMPL adapters,
:mod:`~ompl_balance.validity`), problems (:mod:`ompl_balance.worlds`) and the benchmark
runner (:mod:`ompl_balance.bench`).

The robot layer (trimesh, FCL, numba), the benchmark runner and the viewer (``show``, the
``viz`` extra) are imported on first use, so ``import ompl_balance`` stays quick when they are
not needed: their names (``CollisionChecker``, ``setup_robot``, ``load_mbm``,
``RigidBodyChecker``, ``load_omplapp``, ``rigid_problem``, ``bench``, ``show``, ...) are attributes of
this package but not in ``__all__``, so ``from ompl_balance import *`` does not load them.
"""

from __future__ import annotations

import importlib
from importlib import metadata
from typing import Any

from .core.counting import CountingValidityChecker, WorkCount, ensure_counting, read_work
from .core.params import ParamSet
from .gamma import (
    FreeMeasure,
    ball_radius_constant,
    estimate_ball_radius_constant,
    estimate_free_measure,
    ompl_rewire_factor,
    rewire_radius,
    unit_ball_volume,
)
from .planners import (
    PRESETS,
    BalancedRRTConnect,
    CollisionSwapRRTConnect,
    ControlChosenRRTConnect,
    ExhaustedNodesRRTConnect,
    ExhaustionRRTConnect,
    GaussianPassageRRTConnect,
    GoalBiasRRTConnect,
    NeighbourCostRRTConnect,
    RunStats,
    SwapLimitRRTConnect,
)
from .policies import (
    NEAREST_POLICIES,
    SAMPLE_POLICIES,
    SWAP_POLICIES,
    SwapCause,
    balance_choice,
    choose_tree,
    tree_size_ratio,
)
from .rrtstar import BallRadiusRRTstar, RRTstarStats
from .samplers import BridgeTestValidStateSampler, GaussianValidStateSampler, PassageSampler
from .worlds.boxes import PROBLEMS, BoxWorld2D, Problem, get_problem
from .worlds.occupancy import (
    OCCUPANCY_PROBLEMS,
    GridValidityChecker,
    OccupancyGrid,
    OccupancyProblem,
    rooms_grid,
    rooms_problem,
)

try:
    __version__ = metadata.version("ompl-balance")
except metadata.PackageNotFoundError:  # run from a source tree that was not installed
    __version__ = "0+unknown"

#: name -> module of names loaded on first use (the robot layer, the benchmark runner, and
#: helpers whose home is a module of their own)
_LAZY = {
    "RobotModel": "collision.kinematics",
    "Environment": "collision.environment",
    "CollisionChecker": "collision.checker",
    "Contact": "collision.contacts",
    "load_example_robot_data_panda": "collision.robots",
    "load_panda_vamp": "collision.robots",
    "StateValidityChecker": "validity",
    "MotionValidator": "validity",
    "CertifiedMotionValidator": "validity",
    "certify_path": "validity",
    "space_for": "validity",
    "setup_robot": "validity",
    "load_mbm": "worlds.mbm",
    "MBMProblem": "worlds.mbm",
    "RigidBody": "collision.rigid.body",
    "RigidBodyChecker": "collision.rigid.checker",
    "RigidView": "collision.rigid.view",
    "RigidBodyValidityChecker": "validity",
    "RigidBodyMotionValidator": "validity",
    "RigidBodyCertifiedMotionValidator": "validity",
    "rigid_body_space": "validity",
    "setup_rigid_body": "validity",
    "RigidBodyProblem": "worlds.rigid",
    "RIGID_PROBLEMS": "worlds.rigid",
    "rigid_problem": "worlds.rigid",
    "load_omplapp": "worlds.omplapp",
    "read_omplapp_path": "worlds.omplapp",
    "Experiment": "bench.experiment",
    "ProblemSpec": "bench.problems",
    "PlannerSpec": "bench.experiment",
    "RunTask": "bench.experiment",
    "ExperimentError": "bench.errors",
    "load_experiment": "bench.experiment_file",
    "run_seed": "bench.experiment",
    "bench": "bench.compare",
    "compare_experiment": "bench.compare",
    "run_isolated": "bench.isolation",
    "ResultStore": "bench.results",
    "sweep": "bench.scheduling",
    "run_ompl_benchmark": "bench.ompl_benchmark",
    "write_logs": "bench.logs",
    "to_database": "bench.logs",
    "summarize": "bench.summary",
    "plot_folder": "bench.plots",
    "SWAP_CAUSES": "policies",
    "tree_chooser": "policies",
    "exhaustion_scale": "policies",
    "nearest_not_exhausted": "policies",
    "nearest_by_exhaustion": "policies",
    "node_quality": "policies",
    "path_length_objective": "rrtstar",
    "setup_checker": "checking",
    "CheckerError": "checking",
    "show": "viz",
}

__all__ = [
    "NEAREST_POLICIES",
    "OCCUPANCY_PROBLEMS",
    "PRESETS",
    "PROBLEMS",
    "SAMPLE_POLICIES",
    "SWAP_POLICIES",
    "BalancedRRTConnect",
    "BallRadiusRRTstar",
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
    "NeighbourCostRRTConnect",
    "OccupancyGrid",
    "OccupancyProblem",
    "ParamSet",
    "PassageSampler",
    "Problem",
    "RRTstarStats",
    "RunStats",
    "SwapCause",
    "SwapLimitRRTConnect",
    "WorkCount",
    "__version__",
    "balance_choice",
    "ball_radius_constant",
    "choose_tree",
    "ensure_counting",
    "estimate_ball_radius_constant",
    "estimate_free_measure",
    "get_problem",
    "ompl_rewire_factor",
    "read_work",
    "rewire_radius",
    "rooms_grid",
    "rooms_problem",
    "tree_size_ratio",
    "unit_ball_volume",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'ompl_balance' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})
