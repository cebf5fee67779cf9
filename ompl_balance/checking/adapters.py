"""OMPL's checker classes around a user's validity function of a state's coordinates.

:class:`FunctionValidityChecker` and :class:`FunctionMotionValidator` are what
:func:`~ompl_balance.checking.setup_checker` installs. Stock planners call them as any OMPL
checker (a state or a motion at a time, from C++); the package's compiled engine calls the
function through their compiled views instead, with no Python per state for a numba function
and one call into Python per motion for the others. Both paths run the same kernels for a
motion (OMPL's discrete rule: :mod:`ompl_balance.core.discrete_motions`), so a stock planner
gets the answers OMPL's ``DiscreteMotionValidator`` would give, and the work counted is the same.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from ompl import base as ob

from ..core.checks import Count, load_kernels
from ..core.compiled_calls import entry_point
from ..core.discrete_motions import DiscreteMotions, discrete_motions
from ..core.exit_checks import ExitChecks, exit_checks
from ..core.layout import SpaceLayout, interpolate, layout_for, state_reader
from .functions import CheckFunction
from .views import FunctionStates


class FunctionValidityChecker(ob.StateValidityChecker):
    """An OMPL state validity checker calling ``function`` on the state's coordinates (counted)."""

    def __init__(self, si: ob.SpaceInformation, function: CheckFunction) -> None:
        super().__init__(si)
        self.function = function
        self._read = state_reader(si.getStateSpace())

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        self.function.counts[Count.STATES] += 1
        return self.function.check(np.array(self._read(state)))

    def compiled_view(self) -> FunctionStates | None:
        """The function as compiled code calls it (numba functions and cfuncs; ``None`` for others,
        whose states reach them from compiled code through the motion validator's view)."""
        function = self.function
        if not function.address:
            return None
        return FunctionStates(function.address, function.failed, function.counts)

    def counters(self) -> dict[str, int]:
        """States and motions checked (shared with the motion validator)."""
        return _counters(self.function)

    def reset_counters(self) -> None:
        self.function.counts[:] = 0

    def raise_error(self) -> None:
        """Raise the error the function met in compiled code."""
        self.function.raise_error()


class FunctionMotionValidator(ob.MotionValidator):
    """An OMPL motion validator calling ``function`` by the rule of OMPL's ``DiscreteMotionValidator``.

    ``checkMotion(s1, s2)`` tests the states OMPL would (``s2``, then those ``j / n`` of the way
    in bisection order, ``n = validSegmentCount``) until the first invalid one, in one compiled
    call: a numba function is called for each state from compiled code; any other function
    gets the motion's states in one call (a vectorized one all at once). Counts one motion and
    the states tested.

    ``check_motion_last_valid(s1, s2)`` is ``checkMotion(s1, s2, lastValid)``: OMPL's rule for it
    tests the states from ``s1`` outwards and reports the fraction of the last valid one. (OMPL
    2.0's bindings hand C++ callers of that overload the plain ``checkMotion`` of a Python
    validator, without ``lastValid``; Python callers have this method.)
    """

    def __init__(self, si: ob.SpaceInformation, function: CheckFunction) -> None:
        super().__init__(si)
        self.function = function
        self._space = si.getStateSpace()
        self._read = state_reader(self._space)
        self._view: DiscreteMotions | ExitChecks | None = None
        self._made_for: tuple[float, float, int] | None = None  # the space measures _view is for
        self._layout: SpaceLayout | None = None
        # the motion kernel compiled (or loaded from numba's cache) now, not in a planner's first check
        self._motion_free: Callable[..., bool] = self._kernel(self._make_view(1.0))

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        view = self.compiled_view()
        a, b = np.array(self._read(s1)), np.array(self._read(s2))
        free = self._motion_free(view, a, b)
        if self.function.counts[Count.RAISED]:
            self.function.raise_error()
        return bool(free)

    def check_motion_last_valid(self, s1: ob.State, s2: ob.State) -> tuple[bool, float]:
        """``(valid, fraction)``: whether the motion ``s1 -> s2`` is valid, and where its last valid
        state lies (OMPL's ``lastValid.second``: ``(j - 1) / n`` when the state ``j / n`` is the
        first invalid one from ``s1``, ``(n - 1) / n`` when only ``s2`` is; 1.0 for a valid motion)."""
        self.compiled_view()  # (the layout for the space's current resolution)
        layout = self._layout
        assert layout is not None
        a, b = np.array(self._read(s1)), np.array(self._read(s2))
        n = max(self._space.validSegmentCount(s1, s2), 1)
        states = np.array([interpolate(layout, a, b, j / n) for j in range(1, n)] + [b]).reshape(-1, len(a))
        self.function.counts[Count.MOTIONS] += 1
        first = self.function.first_invalid(states)
        return (True, 1.0) if first == len(states) else (False, first / n)

    def compiled_view(self) -> DiscreteMotions | ExitChecks:
        """The validator as compiled code calls it, for the space's current resolution: OMPL's
        discrete rule around the function's compiled form, or around one call into Python per
        motion (:class:`~ompl_balance.core.exit_checks.ExitChecks`)."""
        space = self._space
        measures = (space.getMaximumExtent(), space.getLongestValidSegmentLength(), space.getValidSegmentCountFactor())
        if self._view is None or measures != self._made_for:
            self._view, self._made_for = self._make_view(measures[0]), measures
        return self._view

    def _make_view(self, extent: float) -> DiscreteMotions | ExitChecks:
        """The motions view for the space's current layout and maximum extent ``extent``."""
        layout = layout_for(self._space)
        assert layout is not None  # (setup_checker takes only spaces with a layout)
        self._layout = layout
        function = self.function
        if function.address:
            states = FunctionStates(function.address, function.failed, function.counts)
            return discrete_motions(states, layout, extent)
        view = exit_checks(function, layout, extent, function.counts, batched=True)
        function.rows = view.rows
        return view

    @staticmethod
    def _kernel(view: DiscreteMotions | ExitChecks) -> Callable[..., bool]:
        """The compiled ``motion_free`` of ``view``'s kind, called without numba's type dispatch."""
        load_kernels(view)
        kernel: Any
        if isinstance(view, DiscreteMotions):
            from ..core.discrete_motion_kernels import discrete_motion_free as kernel
        else:
            from ..core.exit_check_kernels import exit_motion_free as kernel
        a = np.zeros(view.layout.dim)
        return entry_point(kernel, (view, a, a))

    def counters(self) -> dict[str, int]:
        """States and motions checked (shared with the validity checker)."""
        return _counters(self.function)

    def reset_counters(self) -> None:
        self.function.counts[:] = 0

    def raise_error(self) -> None:
        """Raise the error the function met in compiled code."""
        self.function.raise_error()


def _counters(function: CheckFunction) -> dict[str, int]:
    counts = function.counts
    return {"states_checked": int(counts[Count.STATES]), "motions_checked": int(counts[Count.MOTIONS])}


def space_information(target: Any) -> ob.SpaceInformation:
    """The space information of ``target`` (a ``SpaceInformation`` or a geometric ``SimpleSetup``)."""
    from ompl import geometric as og

    if isinstance(target, og.SimpleSetup):
        return target.getSpaceInformation()
    if isinstance(target, ob.SpaceInformation):
        return target
    raise TypeError(
        f"setup_checker: the first argument must be an ompl.base.SpaceInformation or an "
        f"ompl.geometric.SimpleSetup, got {type(target).__name__}"
    )


def layout_dimension(si: ob.SpaceInformation) -> int:
    """Reals in a state of ``si``'s space (its flat layout); a one-line error for a space without one."""
    space = si.getStateSpace()
    layout = layout_for(space) if _has_bounds(space) else None
    if layout is None:
        from ..core.layout import has_layout

        if has_layout(space):
            raise ValueError(f"setup_checker: the {type(space).__name__}'s bounds are not set (call setBounds first)")
        raise ValueError(
            f"setup_checker: a {type(space).__name__} has no flat layout; setup_checker takes real-vector, SO(2), "
            "SO(3), SE(2), SE(3) spaces and compounds of them"
        )
    return int(layout.dim)


def _has_bounds(space: ob.StateSpace) -> bool:
    try:
        return math.isfinite(space.getMaximumExtent()) and space.getMaximumExtent() > 0.0
    except RuntimeError:
        return False
