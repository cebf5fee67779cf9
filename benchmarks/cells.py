"""What the benchmark scripts print per cell: medians over runs and their ratios to stock's.

Each run is a dict of measured values (``"time"`` in seconds, counts of checks, motions,
nodes, ...) with ``"solved"``; the scripts import this module from beside them.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Iterable, Mapping, Sequence


def medians(results: Mapping[str, Sequence[Mapping]], keys: Iterable[str]) -> dict[str, dict[str, float]]:
    """Per planner (the keys of ``results``), the median of each of ``keys`` over its runs."""
    keys = tuple(keys)
    return {name: {key: statistics.median(run[key] for run in runs) for key in keys} for name, runs in results.items()}


def ratios(median: Mapping[str, float], stock: Mapping[str, float]) -> dict[str, float]:
    """``median`` over ``stock``, key by key (``nan`` where stock's median is 0)."""
    return {key: median[key] / stock[key] if stock[key] else math.nan for key in median}


def success(runs: Sequence[Mapping]) -> float:
    """The fraction of ``runs`` that solved."""
    return sum(run["solved"] for run in runs) / len(runs)
