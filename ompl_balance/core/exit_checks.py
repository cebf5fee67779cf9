"""Checks made in Python for compiled code, a motion's states in one call: the exit check view.

A checker written in Python (a user's function of OMPL states or of coordinates, a vectorized
numpy function) cannot be called from compiled code directly. :class:`ExitChecks` is the
view the compiled engine calls it through (:mod:`ompl_balance.core.checks`): its kernels
write the states a query is about into :attr:`ExitChecks.rows` and make one exit to Python
(:data:`~ompl_balance.core.checks.EXIT_ADDRESS`), where the object registered as its
``target`` answers. With ``batched`` a motion checked by OMPL's discrete rule goes to Python
once, with all the states ``DiscreteMotionValidator::checkMotion`` would test, in its order
(:mod:`ompl_balance.core.discrete_motions`); the target tests them in that order until the
first invalid one, so the answer, and the states tested, are OMPL's. The steps a tree takes
in one growth (a goal tree's new state and its motion; the steps of a connect) go to Python
together in the same way (:func:`~ompl_balance.core.checks.steps_free`): one exit where one
step at a time would make one or two per step; with ``per_iteration``, an iteration's extension
and the connect after it in one exit (:func:`~ompl_balance.core.checks.growth_free`). Without ``batched``
each query is its own exit (``si.isValid`` or ``si.checkMotion``, for a motion validator of
the user's own).

A target answers ``answer(kind, count)`` (:class:`Query`); an error it raises is kept in its
``error`` and raised again by its ``raise_error()`` once the compiled code has returned.

The view is a plain named tuple (this module does not import numba); its kernels are in
:mod:`ompl_balance.core.exit_check_kernels`.
"""

from __future__ import annotations

import enum
import threading
from collections.abc import Iterator
from typing import Any, NamedTuple

import numpy as np

from .checks import EXIT_ADDRESS, exit_handle, kernels_in
from .discrete_motions import bisection_scratch
from .layout import SpaceLayout

#: Rows a target checks first: in OMPL's order a blocked motion's first invalid state is most
#: often among its first few (its end, its middle, its quarters), and checking them alone spares
#: converting, or checking in a vectorized call, the rows behind them.
FIRST_ROWS = 8


def row_chunks(count: int) -> Iterator[tuple[int, int]]:
    """The ranges ``(first, last)`` of ``rows[:count]`` a target checks together, in order until it
    meets an invalid state: :data:`FIRST_ROWS` rows, then twice as many as the chunk before."""
    first, size = 0, FIRST_ROWS
    while first < count:
        last = min(count, first + size)
        yield first, last
        first, size = last, 2 * size


#: ``tuple(row_chunks(n))`` at index ``n`` (see :func:`chunks_up_to`), and the lock that extends it.
_CHUNK_TABLE: list[tuple[tuple[int, int], ...]] = []
_CHUNK_TABLE_LOCK = threading.Lock()


def chunks_up_to(count: int) -> list[tuple[tuple[int, int], ...]]:
    """``tuple(row_chunks(n))`` at index ``n``, for every ``n`` up to ``count`` at least: one table
    shared by every target and extended as needed (exits are hot, so a target looks its chunks up;
    working the table out for each target cost a planner's setup some 0.2 ms)."""
    with _CHUNK_TABLE_LOCK:
        table = _CHUNK_TABLE
        table.extend([tuple(row_chunks(n)) for n in range(len(table), count + 1)])
    return table


class Query(enum.IntEnum):
    """What an exit of :class:`ExitChecks` asks its target (its ``kind``)."""

    STATES = 0  # the index of the first invalid state of rows[:count] in order (count: all valid)
    MOTION = 1  # whether the motion rows[0] -> rows[1] is valid: 1 valid, 0 not


@kernels_in("ompl_balance.core.exit_check_kernels")
class ExitChecks(NamedTuple):
    """Checks by the Python object registered under ``handle``, through the exit at ``address`` (see
    the module docstring). (A view with a ``handle`` calls Python: while the engine runs it,
    SIGINT only sets a flag, acted on between slices: ``engine.driver.interrupts_between_slices``.)

    ``rows`` (capacity, dim) holds the states a query is about, written by compiled code and
    read by the target; ``row_steps`` (capacity,) says what each row of a query about a tree's
    steps is: twice the step (from 1) its state belongs to, plus one for the first state the step's
    motion tests (the others: the states between, and a goal tree's new state, tested before its
    motion); ``queue`` (longest, 2) and ``order`` (longest,) are the
    bisection's scratch; ``counts`` the work counter (batched: states and motions; always: exits).
    ``per_iteration`` (batched only): an iteration's extension and the connect after it go to the
    target in one exit (:func:`~ompl_balance.core.checks.growth_free`), the connect's states laid
    out before the extension is known to be free; for a target whose call costs far more than
    laying them out in vain (a vectorized numpy function: tens of microseconds a call).
    """

    address: int
    handle: int
    layout: SpaceLayout
    rows: np.ndarray
    row_steps: np.ndarray
    queue: np.ndarray
    order: np.ndarray
    counts: np.ndarray
    batched: bool
    per_iteration: bool


#: Rows of a batched view per state of the space's longest motion: room for a connect across the
#: space, whose steps' motions add up to about one longest motion, plus their new states.
ROWS_PER_LONGEST = 2


def exit_checks(
    target: Any, layout: SpaceLayout, extent: float, counts: np.ndarray, batched: bool, per_iteration: bool = False
) -> ExitChecks:
    """The :class:`ExitChecks` of ``target`` (an object with ``answer`` and ``error``) in a space of
    ``layout`` and maximum extent ``extent``, counting in ``counts``; rows for the states of
    :data:`ROWS_PER_LONGEST` longest motions when ``batched`` (more go to Python in parts),
    else for two states; ``per_iteration``: see :class:`ExitChecks`."""
    queue, order = bisection_scratch(extent, layout)
    rows = np.empty((ROWS_PER_LONGEST * len(order) if batched else 2, layout.dim))
    row_steps = np.empty(len(rows), dtype=np.int64)
    return ExitChecks(
        EXIT_ADDRESS,
        exit_handle(target),
        layout,
        rows,
        row_steps,
        queue,
        order,
        counts,
        batched,
        batched and per_iteration,
    )
