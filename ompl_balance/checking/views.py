"""How compiled code calls a user's compiled validity function: the :class:`FunctionStates` view.

The view carries the address of the function's C form (:class:`~ompl_balance.checking.functions.CheckFunction`),
so the compiled engine is compiled once for every such function: a new function costs its own
compilation only. Its kernel (:mod:`ompl_balance.checking.kernels`) calls the address for a
state, counts it, and when the function raised, keeps the state in ``failed`` and sets the
RAISED flag (:mod:`ompl_balance.core.checks`) for the engine to report the error from Python.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..core.checks import kernels_in


@kernels_in("ompl_balance.checking.kernels")
class FunctionStates(NamedTuple):
    """A compiled validity function at ``address`` (``int8 check(const double *q, intptr_t dim)``),
    ``given`` (dim,) the copy of a state the function is given (a function that writes into its
    ``q`` changes the copy, not the planner's state), ``failed`` (dim,) the state at which it
    raised, ``counts`` the work counter."""

    address: int
    given: np.ndarray
    failed: np.ndarray
    counts: np.ndarray
