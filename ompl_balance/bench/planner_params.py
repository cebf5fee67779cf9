"""Planner parameters by the names and in the form ``ompl.tools.Benchmark`` logs them.

A benchmark log lists as a planner's *common properties* its declared parameters
(``planner.params().getParams()``) and the space information's
(``longest_valid_segment_fraction``, ``valid_segment_count_factor``). This package's
planners give their ``ParamSet`` to Python; OMPL 2.0's bindings cannot return a stock
planner's (``Planner.params()`` raises ``TypeError``), so stock planners are read and set
through their bound ``get<X>``/``set<X>`` methods under the names their C++ constructors
declare: :data:`DECLARED_PARAMS`, transcribed from the ``declareParam`` calls (and the
``params_.remove`` calls of derived planners) in OMPL 2.0.1's
``src/ompl/geometric/planners/**/*.cpp``, for every planner ``ompl.geometric`` binds.

A stock planner outside that table (a newer OMPL, or a factory's class deriving from
``ob.Planner``) falls back to names derived from its getters (``getDelayCC`` ->
``delay_c_c``); :func:`named_by_getters` tells which, and the log says so in its setup text.
Values are OMPL's strings: booleans ``0``/``1``, integers in decimal, reals as C++'s
``operator<<`` prints them (6 significant digits, ``%g``).
"""

from __future__ import annotations

import re
from typing import Any

from ompl import base as ob
from ompl import geometric as og

# Parameters the KPIECE family and the FMT family share.
_KPIECE = {
    "border_fraction": ("double", "setBorderFraction", "getBorderFraction"),
    "min_valid_path_fraction": ("double", "setMinValidPathFraction", "getMinValidPathFraction"),
    "range": ("double", "setRange", "getRange"),
}
_FAILED_EXPANSION = {
    "failed_expansion_score_factor": (
        "double",
        "setFailedExpansionCellScoreFactor",
        "getFailedExpansionCellScoreFactor",
    ),
}
_FMT = {
    "cache_cc": ("bool", "setCacheCC", "getCacheCC"),
    "extended_fmt": ("bool", "setExtendedFMT", "getExtendedFMT"),
    "heuristics": ("bool", "setHeuristics", "getHeuristics"),
    "num_samples": ("unsigned", "setNumSamples", "getNumSamples"),
    "radius_multiplier": ("double", "setRadiusMultiplier", "getRadiusMultiplier"),
}

#: Stock planner class -> declared parameter name -> (C++ type, setter, getter). A value is logged
#: empty where the bindings lack the getter (BFMT's ``balanced`` and ``optimality``).
DECLARED_PARAMS: dict[str, dict[str, tuple[str, str, str]]] = {
    "RRT": {
        "goal_bias": ("double", "setGoalBias", "getGoalBias"),
        "intermediate_states": ("bool", "setIntermediateStates", "getIntermediateStates"),
        "range": ("double", "setRange", "getRange"),
    },
    "RRTConnect": {
        "intermediate_states": ("bool", "setIntermediateStates", "getIntermediateStates"),
        "range": ("double", "setRange", "getRange"),
    },
    "PRM": {"max_nearest_neighbors": ("unsigned", "setMaxNearestNeighbors", "getMaxNearestNeighbors")},
    "PRMstar": {},  # PRMstar removes PRM's max_nearest_neighbors
    "KPIECE1": {**_KPIECE, **_FAILED_EXPANSION, "goal_bias": ("double", "setGoalBias", "getGoalBias")},
    "BKPIECE1": {**_KPIECE, **_FAILED_EXPANSION},
    "LBKPIECE1": _KPIECE,
    "BITstar": {
        "delay_rewiring_to_first_solution": (
            "bool",
            "setDelayRewiringUntilInitialSolution",
            "getDelayRewiringUntilInitialSolution",
        ),
        "drop_unconnected_samples_on_prune": ("bool", "setDropSamplesOnPrune", "getDropSamplesOnPrune"),
        "find_approximate_solutions": (
            "bool",
            "setConsiderApproximateSolutions",
            "getConsiderApproximateSolutions",
        ),
        "prune_threshold_as_fractional_cost_change": (
            "double",
            "setPruneThresholdFraction",
            "getPruneThresholdFraction",
        ),
        "rewire_factor": ("double", "setRewireFactor", "getRewireFactor"),
        "samples_per_batch": ("unsigned", "setSamplesPerBatch", "getSamplesPerBatch"),
        "stop_on_each_solution_improvement": ("bool", "setStopOnSolnImprovement", "getStopOnSolnImprovement"),
        "use_graph_pruning": ("bool", "setPruning", "getPruning"),
        "use_just_in_time_sampling": ("bool", "setJustInTimeSampling", "getJustInTimeSampling"),
        "use_k_nearest": ("bool", "setUseKNearest", "getUseKNearest"),
        "use_strict_queue_ordering": ("bool", "setStrictQueueOrdering", "getStrictQueueOrdering"),
    },
    "FMT": {**_FMT, "use_k_nearest": ("bool", "setNearestK", "getNearestK")},
    "BFMT": {
        **_FMT,
        "balanced": ("bool", "setExploration", "getExploration"),
        "nearest_k": ("bool", "setNearestK", "getNearestK"),
        "optimality": ("bool", "setTermination", "getTermination"),
    },
    "AORRTC": {},
}

_RRTSTAR = {
    "delay_collision_checking": ("bool", "setDelayCC", "getDelayCC"),
    "focus_search": ("bool", "setFocusSearch", "getFocusSearch"),
    "goal_bias": ("double", "setGoalBias", "getGoalBias"),
    "informed_sampling": ("bool", "setInformedSampling", "getInformedSampling"),
    "new_state_rejection": ("bool", "setNewStateRejection", "getNewStateRejection"),
    "number_sampling_attempts": ("unsigned", "setNumSamplingAttempts", "getNumSamplingAttempts"),
    "ordered_sampling": ("bool", "setOrderedSampling", "getOrderedSampling"),
    "ordering_batch_size": ("unsigned", "setBatchSize", "getBatchSize"),
    "prune_threshold": ("double", "setPruneThreshold", "getPruneThreshold"),
    "pruned_measure": ("bool", "setPrunedMeasure", "getPrunedMeasure"),
    "range": ("double", "setRange", "getRange"),
    "rewire_factor": ("double", "setRewireFactor", "getRewireFactor"),
    "sample_rejection": ("bool", "setSampleRejection", "getSampleRejection"),
    "tree_pruning": ("bool", "setTreePruning", "getTreePruning"),
    "use_admissible_heuristic": ("bool", "setAdmissibleCostToCome", "getAdmissibleCostToCome"),
    "use_k_nearest": ("bool", "setKNearest", "getKNearest"),
}
#: InformedRRTstar (and SORRTstar, derived from it) removes these of RRTstar's parameters.
_INFORMED_REMOVES = {
    "use_admissible_heuristic",
    "informed_sampling",
    "pruned_measure",
    "tree_pruning",
    "sample_rejection",
    "new_state_rejection",
    "focus_search",
}
DECLARED_PARAMS["RRTstar"] = _RRTSTAR
DECLARED_PARAMS["InformedRRTstar"] = {k: v for k, v in _RRTSTAR.items() if k not in _INFORMED_REMOVES}
DECLARED_PARAMS["SORRTstar"] = DECLARED_PARAMS["InformedRRTstar"]

#: The space information's parameters (``StateSpace``'s declared ones), logged for every planner.
SPACE_PARAMS = {
    "longest_valid_segment_fraction": ("double", "setLongestValidSegmentFraction", "getLongestValidSegmentFraction"),
    "valid_segment_count_factor": ("unsigned", "setValidSegmentCountFactor", "getValidSegmentCountFactor"),
}


def ompl_text(value: Any) -> str:
    """``value`` as OMPL writes a parameter: ``0``/``1`` for booleans, ``%g`` for reals."""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _from_text(kind: str, text: str) -> bool | int | float:
    """OMPL's string form of a ``kind`` (``bool``, ``unsigned``, ``double``) parameter as a Python value."""
    if kind == "bool":
        lowered = text.strip().lower()
        if lowered not in ("0", "1", "true", "false"):
            raise ValueError("expected one of 0, 1, true, false")
        return lowered in ("1", "true")
    if kind == "unsigned":
        value = int(text)
        if value < 0:
            raise ValueError("expected a whole number >= 0")
        return value
    return float(text)


def _param_set(planner: ob.Planner) -> Any:
    """The planner's ``ParamSet`` when Python can have it (this package's planners), else ``None``."""
    try:
        return planner.params()
    except TypeError:  # OMPL 2.0's bindings: a stock planner's ParamSet cannot be returned
        return None


def _bound_class(planner: ob.Planner) -> str:
    """Name of the first class in ``planner``'s MRO that OMPL's bindings define."""
    return next(c.__name__ for c in type(planner).__mro__ if c.__module__.startswith("ompl."))


def named_by_getters(planner: ob.Planner) -> bool:
    """True when ``planner``'s parameters are named after its getters (a stock planner not in
    :data:`DECLARED_PARAMS`), not after OMPL's declared names."""
    return _param_set(planner) is None and _bound_class(planner) not in DECLARED_PARAMS


def _snake(camel: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", camel).lower()


def _getter_params(planner: ob.Planner) -> dict[str, tuple[str, str, str]]:
    """The ``get<X>``/``set<X>`` pairs with scalar values, named ``x`` in snake case (the fallback)."""
    params = {}
    for attribute in dir(planner):
        if attribute.startswith("get") and attribute != "getName" and hasattr(planner, "set" + attribute[3:]):
            try:
                value = getattr(planner, attribute)()
            except TypeError:  # a getter that needs arguments is not a parameter
                continue
            if isinstance(value, (bool, int, float)):
                kind = "bool" if isinstance(value, bool) else "unsigned" if isinstance(value, int) else "double"
                params[_snake(attribute[3:])] = (kind, "set" + attribute[3:], attribute)
    return params


def _stock_params(planner: ob.Planner) -> dict[str, tuple[str, str, str]]:
    declared = DECLARED_PARAMS.get(_bound_class(planner))
    return _getter_params(planner) if declared is None else declared


def set_planner_param(planner: ob.Planner, name: str, value: str) -> None:
    """Set parameter ``name`` to ``value`` (OMPL string form); ``ValueError`` naming what is accepted."""
    params = _param_set(planner)
    if params is not None:
        if not params.hasParam(name):
            raise ValueError(f"unknown parameter {name!r}; {planner.getName()} has {', '.join(params.getParamNames())}")
        if not params.setParam(name, value):
            raise ValueError(f"bad value {value!r} for {name!r}; accepted: {params.getRangeSuggestion(name)}")
        return
    setter, converted = _stock_value(type(planner), _stock_params(planner), name, value)
    try:
        getattr(planner, setter)(converted)
    except (TypeError, ValueError) as error:
        raise ValueError(f"bad value {value!r} for {name!r}: {error}") from error


def check_declared_param(planner_class: str, name: str, value: str) -> None:
    """:func:`set_planner_param`'s checks for a stock planner of :data:`DECLARED_PARAMS`, without
    building one (some stock planners crash the process when destroyed: OMPL 2.0.1's AORRTC)."""
    _stock_value(getattr(og, planner_class), DECLARED_PARAMS[planner_class], name, value)


def _stock_value(
    planner_class: type, params: dict[str, tuple[str, str, str]], name: str, value: str
) -> tuple[str, bool | int | float]:
    """The setter of stock parameter ``name`` (bound on ``planner_class``) and ``value`` converted
    to its type; ``ValueError``."""
    if name not in params:
        raise ValueError(
            f"unknown parameter {name!r}; {planner_class.__name__} has {', '.join(sorted(params)) or 'none'}"
        )
    kind, setter, _getter = params[name]
    if not hasattr(planner_class, setter):
        raise ValueError(f"{name!r} cannot be set from Python: OMPL's bindings do not bind {setter}")
    try:
        return setter, _from_text(kind, value)
    except ValueError as error:
        raise ValueError(f"bad value {value!r} for {name!r} ({kind}): {error}") from error


def planner_params(planner: ob.Planner) -> dict[str, str]:
    """The planner's common properties as ``ompl.tools.Benchmark`` logs them: its parameters and
    its space information's, as OMPL strings."""
    params = _param_set(planner)
    if params is not None:
        values = dict(params.getParams())
    else:
        values = {
            name: ompl_text(getattr(planner, getter)()) if getter and hasattr(planner, getter) else ""
            for name, (_kind, _setter, getter) in _stock_params(planner).items()
        }
    space = planner.getSpaceInformation().getStateSpace()
    values.update((name, ompl_text(getattr(space, getter)())) for name, (_, _, getter) in SPACE_PARAMS.items())
    return values
