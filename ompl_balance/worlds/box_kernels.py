"""The compiled state check of a box world (:class:`~ompl_balance.worlds.boxes.BoxKernel`)."""

from __future__ import annotations

import math

import numpy as np

from ..core.check_overloads import register_kernels
from ..core.checks import Count
from ..core.kernel_cache import njit
from .boxes import BoxKernel


@njit(cache=True, inline="always")
def box_state_free(view: BoxKernel, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """:meth:`BoxWorld2D.is_free` of ``(q[0], q[1])``: finite and in no closed box; counts one state.

    (The view's arrays read once, first: numba charges an inlined function that reads them
    under a branch or in a loop some 20 ns a call, more than the test.)"""
    boxes, counts = view.boxes, view.counts
    counts[Count.STATES] += 1
    x, y = q[0], q[1]
    if not (math.isfinite(x) and math.isfinite(y)):
        return False
    for i in range(boxes.shape[0]):  # noqa: SIM110 (a loop numba compiles)
        if boxes[i, 0] <= x <= boxes[i, 2] and boxes[i, 1] <= y <= boxes[i, 3]:
            return False
    return True


register_kernels(BoxKernel, state=box_state_free)
