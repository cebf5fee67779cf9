"""Counting the work a planner makes the collision checker do.

Time on a shared machine is noisy; the number of states and motions checked is not.
Every checker of this package exposes ``counters()`` returning a dict with at least

``states_checked``
    states whose validity was decided (each call of ``isValid``, and each state a
    batched motion validator looked at),
``motions_checked``
    motions (edges) handed to a motion validator;

and may have

``distance_queries``
    exact distance queries a certified motion validator made (0 when absent).

A plain Python callable given to ``si.setStateValidityChecker`` counts nothing, so
:func:`ensure_counting` wraps whatever checker the space information has in a
:class:`CountingValidityChecker`. Motions checked by OMPL's own
``DiscreteMotionValidator`` are read from its built-in counter, plus those the compiled engine
decided by the same rule (counted by the validity checker).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from types import FrameType
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .checks import new_counts, states_and_motions
from .exit_release import release_at_exit


class CountingValidityChecker(ob.StateValidityChecker):
    """A state validity checker that counts the states it is asked about.

    Parameters
    ----------
    si:
        The space information the checker belongs to.
    check:
        What decides validity: another ``ob.StateValidityChecker`` (its ``isValid``
        is called) or a callable ``state -> bool``. A callable with a ``compiled_view(counts)``
        (the package's box worlds) also checks states for the compiled engine, which
        counts its states, and the motions it decides with OMPL's discrete rule, here too.

    Attributes
    ----------
    check:
        The check it counts, ``state -> bool`` (code that counts for itself, such as the
        compiled engine's exits, calls it directly and adds to :attr:`counts`).
    counts:
        The counter compiled code and such callers add to, indexed by
        :class:`~ompl_balance.core.checks.Count` (states and motions).
    """

    def __init__(self, si: ob.SpaceInformation, check: ob.StateValidityChecker | Callable[[ob.State], bool]):
        super().__init__(si)
        self.check: Callable[[ob.State], bool] = check.isValid if isinstance(check, ob.StateValidityChecker) else check
        self.states_checked = 0  # by isValid; compiled code counts in self.counts
        self.counts = new_counts()
        self._view: Any = None
        release_at_exit(self)  # (it holds the user's function: see core.exit_release)

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        self.states_checked += 1
        valid = self.check(state)
        return valid if valid is True or valid is False else validity(valid, self.check)

    def compiled_view(self) -> Any:
        """The wrapped callable's compiled view (:mod:`ompl_balance.core.checks`), or ``None``."""
        if self._view is None:
            view_of = getattr(self.check, "compiled_view", None)
            self._view = False if view_of is None else view_of(self.counts)
        return self._view or None

    def counters(self) -> dict[str, int]:
        """States decided since construction or the last reset (by ``isValid`` and by compiled
        code) and the motions compiled code decided (OMPL's validator counts the others)."""
        states, motions = states_and_motions(self.counts)
        return {"states_checked": self.states_checked + states, "motions_checked": motions}

    def reset_counters(self) -> None:
        self.states_checked = 0
        self.counts[:] = 0


def validity(answer: Any, check: Callable[..., Any]) -> bool:
    """A validity check's ``answer`` as a ``bool``: ``True``/``False``, or numpy's ``bool_``; anything
    else (``None``, a number, an array) is refused with an error naming ``check`` and the answer."""
    if isinstance(answer, (bool, np.bool_)):
        return bool(answer)
    name = getattr(check, "__qualname__", None) or type(check).__name__
    raise TypeError(
        f"the state validity checker {name} returned {answer!r} ({type(answer).__name__}); "
        "a validity checker returns True or False"
    )


@dataclass(frozen=True)
class WorkCount:
    """States and motions checked, and distance queries made, read from a space information's checkers."""

    states_checked: int
    motions_checked: int
    distance_queries: int = 0

    def __sub__(self, other: WorkCount) -> WorkCount:
        return WorkCount(
            self.states_checked - other.states_checked,
            self.motions_checked - other.motions_checked,
            self.distance_queries - other.distance_queries,
        )


def ensure_counting(si: ob.SpaceInformation) -> None:
    """Make sure ``si``'s state validity checker counts what it checks.

    A checker that already has ``counters()`` (this package's, or a user's that follows
    the same protocol) is left alone; any other checker, including the wrapper OMPL
    builds around a plain callable, is wrapped in a :class:`CountingValidityChecker`.
    Every planner using ``si`` afterwards (stock OMPL planners included) goes through
    the counting checker, so their counts compare fairly. Where the wrapped checker is
    OMPL's wrapper of a Python function and the function can be told for sure
    (:func:`installed_function`), the counting checker calls the function itself: one
    call into Python per state instead of three crossings between Python and C++.
    """
    checker = si.getStateValidityChecker()
    if checker is None:
        raise ValueError("the space information has no state validity checker; call si.setStateValidityChecker first")
    if not hasattr(checker, "counters"):
        function = installed_function(si, checker)
        # The checker replaced is kept on si, as OMPL's bindings keep there the function they were
        # given: OMPL's wrapper of a Python function destroyed while the script runs leaves the
        # script's SimpleSetup alive when it exits, which nanobind then reports as leaked.
        si._ompl_balance_replaced_checker = checker
        si.setStateValidityChecker(CountingValidityChecker(si, checker if function is None else function))


def tell_validator_the_checker(si: ob.SpaceInformation) -> None:
    """Tell ``si``'s motion validator, where it checks states with a checker of its own
    (``follow_checker``: :func:`~ompl_balance.checking.setup_checker`'s), which state validity
    checker ``si`` has now, so that a checker set since decides the motions too."""
    follow_checker = getattr(si.getMotionValidator(), "follow_checker", None)
    if follow_checker is not None:
        follow_checker(si.getStateValidityChecker())


#: Frames above the caller of :func:`installed_function` in which a ``SimpleSetup`` is looked for.
_FRAMES_SEARCHED = 8


def installed_function(si: ob.SpaceInformation, checker: ob.StateValidityChecker) -> Callable[..., Any] | None:
    """The Python function ``checker`` calls, when ``checker`` is the one OMPL's bindings made
    from it (``si.setStateValidityChecker(fn)`` or ``ss.setStateValidityChecker(fn)``); ``None``
    when that cannot be told for sure.

    OMPL 2.0's bindings keep the function a ``setStateValidityChecker`` call was given on the
    object it was called on (``si`` or the ``SimpleSetup``, attribute ``_svc``), but not on the
    checker. So the function is taken when exactly one function is found there: on ``si``, or
    on a ``SimpleSetup`` of ``si`` held in a variable of one of the calling frames (a planner's
    ``setup()`` runs inside ``ss.setup()`` or ``ss.solve()``). Two different ones (two
    ``SimpleSetup`` of one ``si``, or a call on each) leave it undecided, and so does anything
    else: the checker is then called as it is, with the same answers, only slower.
    """
    if type(checker) is not ob.StateValidityChecker:  # a checker written in Python, or a bound C++ class
        return None
    found = [_given_function(si)]
    frame: FrameType | None = sys._getframe(1)
    for _ in range(_FRAMES_SEARCHED):
        if frame is None:
            break
        found += [_given_function(value) for value in frame.f_locals.values() if _is_simple_setup_of(value, si)]
        frame = frame.f_back
    functions = {id(function): function for function in found if function is not None}
    return next(iter(functions.values())) if len(functions) == 1 else None


def _given_function(owner: Any) -> Callable[..., Any] | None:
    """The plain function the last ``setStateValidityChecker`` call on ``owner`` was given, if any."""
    given = getattr(owner, "_svc", None)  # (where OMPL's bindings keep it)
    return None if given is None or isinstance(given, ob.StateValidityChecker) or not callable(given) else given


def _is_simple_setup_of(value: Any, si: ob.SpaceInformation) -> bool:
    return isinstance(value, og.SimpleSetup) and value.getSpaceInformation() is si


def read_work(si: ob.SpaceInformation) -> WorkCount:
    """The work counters of ``si``'s checkers as they stand now.

    Take the difference of two readings to count one run. States checked are ``0``
    when the checker does not count (see :func:`ensure_counting`). Motions checked
    come from the motion validator's ``counters()`` when it has them, else from
    OMPL's own motion counter.
    """
    checker_counters = getattr(si.getStateValidityChecker(), "counters", None)
    counters = {} if checker_counters is None else checker_counters()
    validator = si.getMotionValidator()
    validator_counters = getattr(validator, "counters", None)
    if validator_counters is not None:
        counters = {**counters, **validator_counters()}
        motions = counters["motions_checked"]
    else:  # OMPL's own validator, and the motions compiled code decided by its rule
        motions = counters.get("motions_checked", 0) + (0 if validator is None else validator.getCheckedMotionCount())
    return WorkCount(counters.get("states_checked", 0), motions, counters.get("distance_queries", 0))


@dataclass(frozen=True)
class MeasuredSolve:
    """One ``ss.solve``: its status, whether it found an exact path, wall time (s) and work."""

    status: ob.PlannerStatus
    solved: bool
    time: float
    work: WorkCount


def measured_solve(ss: og.SimpleSetup, time_limit: float) -> MeasuredSolve:
    """``ss.solve`` within ``time_limit`` seconds, timed as the benchmark runner times a run: its
    wall time and the work its checkers counted.

    Sets ``ss`` up first and has a planner of this package make its compiled engine ready
    (``wait_for_engine``), so that neither setup (e.g. wrapping a checker to count) nor loading
    the engine is timed, and the solve runs on the engine it will use. The limit is OMPL's
    ``timedPlannerTerminationCondition(time_limit)``, evaluated when the planner asks.
    (``ss.solve(time_limit)`` with a limit of a second or more evaluates it in a thread of its
    own, which sleeps a millisecond at a time and which the solve waits for at its end: up to a
    millisecond more on every solve, whatever the planner; a solve under a millisecond takes
    about 1.2 ms.)
    """
    ss.setup()
    wait_for_engine = getattr(ss.getPlanner(), "wait_for_engine", None)
    if wait_for_engine is not None:
        wait_for_engine()
    si = ss.getSpaceInformation()
    before = read_work(si)
    began = time.perf_counter()
    status = ss.solve(ob.timedPlannerTerminationCondition(time_limit))
    elapsed = time.perf_counter() - began
    return MeasuredSolve(status, bool(ss.haveExactSolutionPath()), elapsed, read_work(si) - before)
