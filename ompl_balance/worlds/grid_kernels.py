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
    """:meth:`OccupancyGrid.is_free` of ``(q[0], q[1])``: finite and in a free cell; counts one state."""
    view.counts[Count.STATES] += 1
    x, y = q[0], q[1]
    if not (math.isfinite(x) and math.isfinite(y)):
        return False
    col = math.floor((x - view.origin[0]) / view.resolution)
    row = math.floor((y - view.origin[1]) / view.resolution)
    return 0 <= row < view.free.shape[0] and 0 <= col < view.free.shape[1] and view.free[row, col]


register_kernels(GridKernel, state=grid_state_free)
