"""The compiled state check of an occupancy grid (:class:`~ompl_balance.worlds.occupancy.GridKernel`)."""

from __future__ import annotations

import math

import numpy as np

from ..core.check_overloads import register_kernels
from ..core.checks import Count
from ..core.kernel_cache import njit
from .occupancy import GridKernel


@njit(cache=True, inline="always")
def grid_state_free(view: GridKernel, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """:meth:`OccupancyGrid.is_free` of ``(q[0], q[1])``: finite and in a free cell; counts one state.
    (The view's fields read once, first, as :func:`~ompl_balance.worlds.box_kernels.box_state_free` does.)"""
    free, origin, resolution, counts = view.free, view.origin, view.resolution, view.counts
    counts[Count.STATES] += 1
    x, y = q[0], q[1]
    if not (math.isfinite(x) and math.isfinite(y)):
        return False
    col = math.floor((x - origin[0]) / resolution)
    row = math.floor((y - origin[1]) / resolution)
    return 0 <= row < free.shape[0] and 0 <= col < free.shape[1] and free[row, col]


register_kernels(GridKernel, state=grid_state_free)
