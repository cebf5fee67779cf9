"""The compiled kernel of :class:`~ompl_balance.checking.views.FunctionStates`."""

from __future__ import annotations

import numpy as np

from ..core.array_kernels import copy_into
from ..core.check_overloads import register_kernels
from ..core.checks import Count
from ..core.function_pointers import call_state_function
from ..core.kernel_cache import njit
from .views import FunctionStates


@njit(cache=True, inline="always")
def function_state_free(view: FunctionStates, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether ``q`` is valid for the function at ``view.address``, which is given a copy of it;
    counts one state. A function that raised answers "not valid", its state kept in
    ``view.failed`` and the RAISED flag set. (The view's fields read once, first: see
    :func:`~ompl_balance.worlds.box_kernels.box_state_free`.)"""
    address, given, failed, counts = view.address, view.given, view.failed, view.counts
    counts[Count.STATES] += 1
    copy_into(q, given)
    answer = call_state_function(address, given)
    if answer == 1:
        return True
    if answer < 0:
        counts[Count.RAISED] = 1
        copy_into(q, failed)
    return False


register_kernels(FunctionStates, state=function_state_free)
