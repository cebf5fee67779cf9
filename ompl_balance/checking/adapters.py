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

from collections.abc import Callable
from typing import Any

import numpy as np
from ompl import base as ob

from ..core.checks import Count, load_kernels, states_and_motions
from ..core.compiled_calls import entry_point
from ..core.discrete_motion_kernels import bisection_order
from ..core.discrete_motions import DiscreteMotions, discrete_motions
from ..core.exit_checks import ExitChecks, exit_checks
from ..core.exit_release import release_at_exit
from ..core.layout import SpaceLayout, interpolate, layout_for, leaf_spaces, resolution_measures, state_reader
from .functions import CheckFunction
from .views import FunctionStates


class FunctionValidityChecker(ob.StateValidityChecker):
    """An OMPL state validity checker calling ``function`` on the state's coordinates (counted)."""

    def __init__(self, si: ob.SpaceInformation, function: CheckFunction) -> None:
        super().__init__(si)
        self.function = function
        self._read = state_reader(si.getStateSpace())
        release_at_exit(self)  # (it holds the user's function: see core.exit_release)

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        self.function.counts[Count.STATES] += 1
        return self.function.check(np.array(self._read(state)))

    def compiled_view(self) -> FunctionStates | None:
        """The function as compiled code calls it (numba functions and cfuncs; ``None`` for others,
        whose states reach them from compiled code through the motion validator's view)."""
        function = self.function
        if not function.address:
            return None
        return function.states_view()

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

    Told that the space information's state validity checker is no longer ``checker`` (a later
    ``ss.setStateValidityChecker``; the package's planners tell it at each solve,
    :meth:`follow_checker`), it checks motions as OMPL's ``DiscreteMotionValidator`` does, with
    the checker the space information has: OMPL 2.0's bindings offer no way to put OMPL's own
    validator back. (It cannot ask the space information itself: an object OMPL holds from C++
    that holds its space information is never freed.)
    """

    #: Once it no longer follows the function (see above), the compiled engine checks its motions
    #: with the space information's checker by OMPL's discrete rule.
    checks_as_discrete = True

    def __init__(self, si: ob.SpaceInformation, function: CheckFunction, checker: FunctionValidityChecker) -> None:
        super().__init__(si)
        self.function = function
        self._checker = checker
        self._current: ob.StateValidityChecker | None = None  # the space's checker, once not ``checker``
        self._rule_motions = 0  # motions checked with ``_current`` from Python
        self._space = si.getStateSpace()
        # (scratch: a state between a motion's ends; the space's, as one of si's would hold si)
        self._between = self._space.allocState()
        release_at_exit(self)  # (it holds the user's function: see core.exit_release)
        self._read = state_reader(self._space)
        self._view: DiscreteMotions | ExitChecks | None = None
        self._leaves = leaf_spaces(self._space)
        self._made_for: tuple[float, ...] | None = None  # the space's resolution_measures _view is for
        self._layout: SpaceLayout | None = None
        # the motion kernel compiled (or loaded from numba's cache) now, not in a planner's first check
        self._motion_free: Callable[..., bool] = self._kernel(self._make_view(1.0))

    def follow_checker(self, checker: ob.StateValidityChecker) -> None:
        """Check motions with ``checker``, the space information's state validity checker now: with
        the function while it is the function's checker, else by OMPL's discrete rule with it."""
        self._current = None if checker is self._checker else checker

    def follows_function(self) -> bool:
        """Whether motions are checked with the function (see :meth:`follow_checker`)."""
        return self._current is None

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        if not self.follows_function():
            return self._by_rule(s1, s2, from_start=False)[0]
        view = self._function_view()
        a, b = np.array(self._read(s1)), np.array(self._read(s2))
        free = self._motion_free(view, a, b)
        if self.function.counts[Count.RAISED]:
            self.function.raise_error()
        return bool(free)

    def check_motion_last_valid(self, s1: ob.State, s2: ob.State) -> tuple[bool, float]:
        """``(valid, fraction)``: whether the motion ``s1 -> s2`` is valid, and where its last valid
        state lies (OMPL's ``lastValid.second``: ``(j - 1) / n`` when the state ``j / n`` is the
        first invalid one from ``s1``, ``(n - 1) / n`` when only ``s2`` is; 1.0 for a valid motion)."""
        if not self.follows_function():
            return self._by_rule(s1, s2, from_start=True)
        self._function_view()  # (the layout for the space's current resolution)
        layout = self._layout
        assert layout is not None
        a, b = np.array(self._read(s1)), np.array(self._read(s2))
        n = max(self._space.validSegmentCount(s1, s2), 1)
        states = np.array([interpolate(layout, a, b, j / n) for j in range(1, n)] + [b]).reshape(-1, len(a))
        self.function.counts[Count.MOTIONS] += 1
        first = self.function.first_invalid(states)
        return (True, 1.0) if first == len(states) else (False, first / n)

    def compiled_view(self) -> DiscreteMotions | ExitChecks | None:
        """The validator as compiled code calls it, for the space's current resolution: OMPL's
        discrete rule around the function's compiled form, or around one call into Python per
        motion (:class:`~ompl_balance.core.exit_checks.ExitChecks`); ``None`` once it no longer
        follows the function (the engine then checks by the rule with the current checker)."""
        return self._function_view() if self.follows_function() else None

    def _by_rule(self, s1: ob.State, s2: ob.State, from_start: bool) -> tuple[bool, float]:
        """OMPL's ``DiscreteMotionValidator`` with the space information's current checker:
        ``(valid, fraction of the last valid state)``. ``from_start`` (its ``lastValid`` overload):
        the states ``j / n`` from ``s1`` outwards; otherwise ``s2``, then those between in the
        rule's bisection order."""
        checker, space = self._current, self._space
        assert checker is not None  # (not following the function)
        self._rule_motions += 1
        n = max(space.validSegmentCount(s1, s2), 1)
        if from_start:
            fractions = [j / n for j in range(1, n + 1)]
        else:
            if not checker.isValid(s2):
                return False, 1.0
            queue, order = np.empty((n, 2), dtype=np.int64), np.empty(n, dtype=np.int64)
            bisection_order(n, queue, order)
            fractions = [j / n for j in order[: n - 1].tolist()]
        state = self._between
        for fraction in fractions:
            space.interpolate(s1, s2, fraction, state)
            if not checker.isValid(state):
                return False, fraction - 1.0 / n
        return True, 1.0

    def _function_view(self) -> DiscreteMotions | ExitChecks:
        """The function's view for the space's current resolution (see :meth:`compiled_view`)."""
        measures = resolution_measures(self._space, self._leaves)
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
            states = function.states_view()
            return discrete_motions(states, layout, extent)
        # (a vectorized function's call costs tens of microseconds: one call an iteration pays even
        # when the connect's states are laid out for an extension that turns out blocked)
        per_iteration = function.kind == "vectorized"
        view = exit_checks(function, layout, extent, function.counts, batched=True, per_iteration=per_iteration)
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
        """States and motions checked (shared with the validity checker); once it no longer
        follows the function, the motions only (its own and those compiled code checked with the
        current checker, which counts its states)."""
        checker = self._current
        if checker is None:  # (following the function)
            return _counters(self.function)
        counted = checker.counters().get("motions_checked", 0) if hasattr(checker, "counters") else 0
        return {"motions_checked": self._rule_motions + counted}

    def reset_counters(self) -> None:
        self.function.counts[:] = 0
        self._rule_motions = 0

    def raise_error(self) -> None:
        """Raise the error the function met in compiled code."""
        self.function.raise_error()


def _counters(function: CheckFunction) -> dict[str, int]:
    states, motions = states_and_motions(function.counts)
    return {"states_checked": states, "motions_checked": motions}


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
    """Reals in a state of ``si``'s space (its flat layout); a one-line error for a space without
    one or with a real-vector part whose bounds are not set."""
    from ..core.layout import has_layout

    space = si.getStateSpace()
    if not has_layout(space):
        raise ValueError(
            f"setup_checker: a {type(space).__name__} has no flat layout; setup_checker takes real-vector, SO(2), "
            "SO(3), SE(2), SE(3) spaces and compounds of them"
        )
    layout = layout_for(space)
    assert layout is not None  # (has_layout)
    low, high = layout.low, layout.high
    if not (np.isfinite(low).all() and np.isfinite(high).all() and (low < high).all()):
        raise ValueError(
            f"setup_checker: the {type(space).__name__}'s bounds are not set (call setBounds on its real-vector "
            "part first)"
        )
    return int(layout.dim)
