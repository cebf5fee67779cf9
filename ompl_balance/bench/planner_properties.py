"""What a planner reports after a run, as OMPL benchmark run properties (``"name TYPE"``).

Every planner: ``graph states`` and ``graph motions`` of its planner data; stock
``RRTConnect``: its ``start tree size`` and ``goal tree size`` (the start tree's vertices
are tagged 1 and the goal tree's 2, ``RRTConnect::getPlannerData``); this package's
planners: every numeric field of their ``stats`` as well (``iterations``, tree sizes,
``tree swaps``, sampler counters, ``best cost``, ``rewires``, ...).
"""

from __future__ import annotations

from collections.abc import Collection
from typing import Any

from ompl import base as ob
from ompl import geometric as og

#: Stock planners whose ``PlannerData`` tags the start tree's vertices 1 and the goal tree's 2.
TREE_TAGGING_STOCK_PLANNERS = (og.RRTConnect,)


def typed(name: str, value: Any) -> tuple[str, Any]:
    """An OMPL log property ``"name TYPE"`` for a Python value (bool -> BOOLEAN 0/1)."""
    if isinstance(value, bool):
        return f"{name} BOOLEAN", int(value)
    if isinstance(value, int):
        return f"{name} INTEGER", value
    return f"{name} REAL", float(value)


def graph_properties(planner: ob.Planner) -> dict[str, Any]:
    """Graph states and motions of ``planner``'s planner data (and stock RRT-Connect's tree sizes)."""
    if hasattr(planner, "plannerData"):  # this package's planners (see TreePlanner.plannerData)
        data = planner.plannerData()
    else:
        data = ob.PlannerData(planner.getSpaceInformation())
        planner.getPlannerData(data)
    properties = dict([typed("graph states", data.numVertices()), typed("graph motions", data.numEdges())])
    if isinstance(planner, TREE_TAGGING_STOCK_PLANNERS):
        tags = [data.getVertex(i).getTag() for i in range(data.numVertices())]
        properties.update([typed("start tree size", tags.count(1)), typed("goal tree size", tags.count(2))])
    return properties


def stats_properties(planner: ob.Planner, measured_elsewhere: Collection[str] = ()) -> dict[str, Any]:
    """Every numeric field of ``planner.stats`` (this package's planners; ``{}`` for others) but
    ``measured_elsewhere``, named as OMPL logs them (``tree_swaps`` -> ``"tree swaps INTEGER"``)."""
    stats = getattr(planner, "stats", None)
    if stats is None:
        return {}
    return dict(
        typed(name.replace("_", " "), value)
        for name, value in stats.as_dict().items()
        if name not in measured_elsewhere and isinstance(value, (int, float))
    )
