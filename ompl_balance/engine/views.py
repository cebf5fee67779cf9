"""How the compiled engine checks states and motions: the check views of a solve.

Three kinds of check view (:mod:`ompl_balance.core.checks`), chosen by :func:`checks_for`:

* a motion validator's own view (the package's robot and rigid-body validators, and
  :func:`~ompl_balance.checking.setup_checker`'s): its kernels decide states and motions;
* :class:`~ompl_balance.core.discrete_motions.DiscreteMotions`: OMPL's ``DiscreteMotionValidator``
  (the default of a space information; or a validator that says it ``checks_as_discrete``)
  around a validity checker's compiled view, as OMPL checks a motion;
* :class:`~ompl_balance.core.exit_checks.ExitChecks` answered by :class:`SpaceChecks`: anything
  else (a user's Python callable, a C++ checker, a motion validator of their own), called from
  compiled code through one exit: with OMPL's discrete validator and a checker the package
  counts (a plain callable), all the states a motion tests in one call to Python, which checks
  them in OMPL's order on a scratch OMPL state; otherwise one ``si.isValid`` or
  ``si.checkMotion`` per query.

This module does not import numba.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from typing import Any

import numpy as np
from ompl import base as ob

from ..core.checks import Count, ExitTarget, exits_to_python, new_counts
from ..core.counting import CountingValidityChecker, validity
from ..core.discrete_motions import discrete_motions
from ..core.exit_checks import ExitChecks, Query, chunks_up_to, exit_checks
from ..core.layout import SpaceLayout


class SpaceChecks(ExitTarget):
    """The target of the exits of a space information's checks: its checkers on flat states
    (:class:`~ompl_balance.core.exit_checks.ExitChecks`; an error it raises is kept in :attr:`error`).

    ``is_valid`` is the check called state by state (a counting checker's own check, or
    ``si.isValid``); a state is written into the scratch OMPL state with one call of the
    space's ``copyFromReals``.
    """

    def __init__(self, si: ob.SpaceInformation, is_valid: Callable[[ob.State], Any]) -> None:
        self.error: BaseException | None = None
        self.rows = np.empty((0, 0))  # the view's rows (set by take_rows once the view is made)
        self._chunks: list[tuple[tuple[int, int], ...]] = []  # row_chunks(count) at index count
        self._si = si
        self._scratch = (si.allocState(), si.allocState())
        self._is_valid = is_valid
        self._copy = si.getStateSpace().copyFromReals

    def take_rows(self, rows: np.ndarray) -> None:
        """Answer about ``rows`` (the view's, (capacity, dim))."""
        self.rows = rows
        self._chunks = chunks_up_to(len(rows))

    def answer(self, kind: int, count: int) -> int:
        """The answer to query ``kind`` about ``rows[:count]`` (see :class:`~ompl_balance.core.exit_checks.Query`)."""
        copy, rows = self._copy, self.rows
        if kind == _STATES:
            state, is_valid = self._scratch[0], self._is_valid
            for first, last in self._chunks[count]:
                index = first  # (counted by hand: enumerate costs a tenth of a microsecond per exit)
                for values in rows[first:last].tolist():
                    copy(state, values)
                    valid = is_valid(state)
                    if valid is not True and (valid is False or not validity(valid, is_valid)):
                        return index
                    index += 1
            return count
        start, end = self._scratch
        copy(start, rows[0].tolist())
        copy(end, rows[1].tolist())
        return int(self._si.checkMotion(start, end))


_STATES = int(Query.STATES)


class EngineChecks:
    """The check view of a solve and what it holds on to while the solve runs.

    ``path`` says how the checks are made: ``"kernel"`` (compiled kernels, leaving to Python
    only for what they cannot decide) or ``"python"`` (the space information's checkers, called
    through an exit). ``source``: the objects it was made from (validity checker, motion
    validator, their compiled view, the layout), by identity. ``exits``: whether its kernels may
    call Python (see :func:`~ompl_balance.core.checks.exits_to_python`).
    ``reporter``: the object that raises an error a check kept (its ``raise_error()``), if any.
    ``steps_together``: whether its kernels check a tree's steps in one call to Python (a
    batched :class:`~ompl_balance.core.exit_checks.ExitChecks`), so the loop lays a whole
    connect out for them at once; ``per_iteration``: whether they check an iteration's extension
    and connect in one call (the view's ``per_iteration``).
    """

    def __init__(self, view: Any, path: str, source: tuple[Any, ...], reporter: Any = None) -> None:
        self.view = view
        self.path = path
        self.exits = exits_to_python(view)
        self.steps_together = isinstance(view, ExitChecks) and view.batched
        self.per_iteration = isinstance(view, ExitChecks) and view.per_iteration  # (batched: exit_checks)
        self.source = source
        self.reporter = reporter  # also keeps an exit's target alive (the registry holds it weakly)

    def made_from(self, source: tuple[Any, ...]) -> bool:
        """Whether these checks were made from the very objects ``source``."""
        return len(source) == len(self.source) and all(map(operator.is_, source, self.source))

    def raise_error(self) -> None:
        """Raise the error a check kept while compiled code ran, if any (clearing its flag)."""
        self.view.counts[Count.RAISED] = 0
        raise_error = getattr(self.reporter, "raise_error", None)
        if raise_error is not None:
            raise_error()
        raise RuntimeError("a validity check failed in compiled code and left no error to report")


def _compiled_view(checker: Any) -> Any:
    """A checker's or validator's ``compiled_view()``; ``None`` for one without."""
    compiled_view = getattr(checker, "compiled_view", None)
    return None if compiled_view is None else compiled_view()


def checks_for(si: ob.SpaceInformation, layout: SpaceLayout, previous: EngineChecks | None = None) -> EngineChecks:
    """The check view the compiled engine uses for ``si``'s validity checker and motion validator:
    ``previous`` (the checks of an earlier solve) when it was made from the same checker,
    validator, compiled view and layout, else new checks."""
    checker, validator = si.getStateValidityChecker(), si.getMotionValidator()
    motions = _compiled_view(validator)
    states = None if motions is not None else _compiled_view(checker)
    source = (checker, validator, motions if motions is not None else states, layout)
    if previous is not None and previous.made_from(source):
        return previous
    if motions is not None:
        return EngineChecks(motions, "kernel", source, validator)
    # OMPL's own DiscreteMotionValidator, or one that checks the same states
    discrete = type(validator) is ob.MotionValidator or getattr(validator, "checks_as_discrete", False)
    extent = si.getMaximumExtent()
    if states is not None and discrete:
        return EngineChecks(discrete_motions(states, layout, extent), "kernel", source, checker)
    # A checker the package counts (a plain callable): a motion's states in one exit, counted here.
    batched = discrete and isinstance(checker, CountingValidityChecker)
    space_checks = SpaceChecks(si, checker.check if batched else si.isValid)
    exits = exit_checks(space_checks, layout, extent, checker.counts if batched else new_counts(), batched)
    space_checks.take_rows(exits.rows)
    return EngineChecks(exits, "python", source, space_checks)
