"""How the compiled engine checks states and motions: the check views of a solve.

Three kinds of check view (:mod:`ompl_balance.core.checks`), chosen by :func:`checks_for`:

* a motion validator's own view (the package's robot validators): its kernels decide
  states and motions;
* :class:`DiscreteMotions`: OMPL's ``DiscreteMotionValidator`` (the default of a space
  information; or a validator that says it ``checks_as_discrete``) around a validity checker's compiled view, as OMPL checks a motion: the end
  state first, then the states at ``j / n`` of the way, ``n = validSegmentCount``, in
  breadth-first bisection order;
* :class:`PythonChecks`: anything else (a user's Python callable, a C++ checker, a motion
  validator of their own): one call to ``si.isValid`` or ``si.checkMotion`` per query, on
  two scratch OMPL states.

The views are plain named tuples (this module does not import numba); their kernels are in
:mod:`ompl_balance.engine.check_kernels`.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from ompl import base as ob

from ..core.checks import exit_handle, exit_target, exits_to_python, kernels_in, new_counts
from ..core.layout import SpaceLayout


@kernels_in("ompl_balance.engine.check_kernels")
class DiscreteMotions(NamedTuple):
    """OMPL's ``DiscreteMotionValidator`` around the compiled view ``states`` of a validity checker.

    ``test`` (dim,) is scratch space and ``queue`` (rows, 2) the bisection's queue; the motions
    count in ``counts`` (the validity checker's own counter, which also counts its states).
    """

    states: Any
    layout: SpaceLayout
    test: np.ndarray
    queue: np.ndarray
    counts: np.ndarray


@kernels_in("ompl_balance.engine.check_kernels")
class PythonChecks(NamedTuple):
    """Checks by the space information: ``exit_target(handle)`` is a :class:`SpaceChecks`."""

    handle: int
    counts: np.ndarray  # calls out of compiled code (the checkers count their own work)


class SpaceChecks:
    """``si.isValid`` and ``si.checkMotion`` on flat states, through two scratch OMPL states."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        self._si = si
        self._space = si.getStateSpace()
        self._scratch = (si.allocState(), si.allocState())

    def _state(self, q: np.ndarray, slot: int) -> ob.State:
        state = self._scratch[slot]
        self._space.copyFromReals(state, q.tolist())
        return state

    def is_valid(self, q: np.ndarray) -> bool:
        return bool(self._si.isValid(self._state(q, 0)))

    def check_motion(self, a: np.ndarray, b: np.ndarray) -> bool:
        return bool(self._si.checkMotion(self._state(a, 0), self._state(b, 1)))


def call_is_valid(handle: int, q: np.ndarray) -> bool:
    """``SpaceChecks.is_valid`` of the object behind ``handle`` (called from a kernel's objmode block)."""
    return bool(exit_target(handle).is_valid(q))


def call_check_motion(handle: int, a: np.ndarray, b: np.ndarray) -> bool:
    """``SpaceChecks.check_motion`` of the object behind ``handle`` (called from a kernel's objmode block)."""
    return bool(exit_target(handle).check_motion(a, b))


class EngineChecks:
    """The check view of a solve and what it holds on to while the solve runs.

    ``path`` says how the checks are made: ``"kernel"`` (compiled kernels, leaving to Python
    only for what they cannot decide) or ``"python"`` (``si.isValid``/``si.checkMotion``).
    ``source``: the objects it was made from (validity checker, motion validator, their compiled
    view, the layout), by identity. ``exits``: whether its kernels may call Python.
    """

    def __init__(self, view: Any, path: str, source: tuple[Any, ...], keep: Any = None) -> None:
        self.view = view
        self.path = path
        self.exits = exits_to_python(view)
        self.source = source
        self.keep = keep  # the object behind the view's exit handle (held weakly by the registry)

    def made_from(self, source: tuple[Any, ...]) -> bool:
        """Whether these checks were made from the very objects ``source``."""
        return len(source) == len(self.source) and all(a is b for a, b in zip(source, self.source))


def checks_for(si: ob.SpaceInformation, layout: SpaceLayout, previous: EngineChecks | None = None) -> EngineChecks:
    """The check view the compiled engine uses for ``si``'s validity checker and motion validator:
    ``previous`` (the checks of an earlier solve) when it was made from the same checker,
    validator, compiled view and layout, else new checks."""
    checker, validator = si.getStateValidityChecker(), si.getMotionValidator()
    motions = getattr(validator, "compiled_view", lambda: None)()
    states = None if motions is not None else getattr(checker, "compiled_view", lambda: None)()
    source = (checker, validator, motions if motions is not None else states, layout)
    if previous is not None and previous.made_from(source):
        return previous
    if motions is not None:
        return EngineChecks(motions, "kernel", source)
    # OMPL's own DiscreteMotionValidator, or one that checks the same states
    discrete = type(validator) is ob.MotionValidator or getattr(validator, "checks_as_discrete", False)
    if states is not None and discrete:
        # room for OMPL's bisection queue of a motion across the whole space
        longest = max(int(f) * math.ceil(si.getMaximumExtent() / g) for f, g in zip(layout.factor, layout.segment))
        queue = np.empty((2 * longest + 4, 2), dtype=np.int64)
        view = DiscreteMotions(states, layout, np.empty(layout.dim), queue, states.counts)
        return EngineChecks(view, "kernel", source)
    space_checks = SpaceChecks(si)
    return EngineChecks(PythonChecks(exit_handle(space_checks), new_counts()), "python", source, space_checks)
