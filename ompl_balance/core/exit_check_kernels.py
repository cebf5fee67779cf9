"""The compiled kernels of :class:`~ompl_balance.core.exit_checks.ExitChecks`: states and motions
checked by Python, a tree's growth (a motion, or the steps of a connect) or an iteration's (the
extension and the connect) in one exit."""

from __future__ import annotations

import numpy as np

from .array_kernels import copy_into
from .check_overloads import growth_in_turn, register_kernels, steps_one_by_one
from .checks import EXTENSION_BLOCKED, Count
from .compiled_spaces import interpolate, segment_count
from .discrete_motion_kernels import fraction_between, order_between
from .exit_checks import ExitChecks, Query
from .function_pointers import counted_exit
from .kernel_cache import njit_borrowing

_STATES, _MOTION = int(Query.STATES), int(Query.MOTION)
NO_STEP = 0  # what _ask_rows answers when every state asked about is valid (steps count from 1)


@njit_borrowing
def _ask(view: ExitChecks, kind: int, count: int) -> int:  # pragma: no cover (compiled)
    """One exit to the view's target about ``view.rows[:count]`` (counted); -1, with the view's
    RAISED flag set, when it raised."""
    return counted_exit(view.counts, view.address, view.handle, kind, count)


@njit_borrowing
def _ask_rows(view: ExitChecks, count: int) -> int:  # pragma: no cover (compiled)
    """Ask Python for the first invalid state of ``view.rows[:count]`` (tagged in ``view.row_steps``)
    and count the states tested and the motions begun; the step of the first invalid state, or
    ``NO_STEP`` when all are valid (when the check raised: the step of the first row)."""
    tags = view.row_steps
    first = _ask(view, _STATES, count)
    if first < 0:
        return tags[0] // 2
    tested = min(first + 1, count)
    view.counts[Count.STATES] += tested
    for row in range(tested):
        view.counts[Count.MOTIONS] += tags[row] & 1
    return tags[first] // 2 if first < count else NO_STEP


@njit_borrowing
def _queue_motion(
    view: ExitChecks, a: np.ndarray, b: np.ndarray, step: int, a_first: bool, filled: int
) -> tuple[int, int]:  # pragma: no cover (compiled)
    """Append to ``view.rows[filled:]`` the states step ``step`` tests by OMPL's discrete rule for
    the motion ``a -> b`` (``a`` first when ``a_first``: a goal tree's new state; then ``b``, then
    those between in the rule's order, :mod:`~ompl_balance.core.discrete_motions`), asking Python
    about the rows whenever they are full. Returns the rows filled and the blocked step found by
    an ask (``NO_STEP``: none yet)."""
    layout, rows, tags, queue, order = view.layout, view.rows, view.row_steps, view.queue, view.order
    n = max(segment_count(layout, a, b), 1)
    in_order = order_between(n, queue, order)
    for k in range(-1 if a_first else 0, n):  # -1: a, 0: b, then the states between in the rule's order
        if filled == rows.shape[0]:
            blocked = _ask_rows(view, filled)
            if blocked != NO_STEP:
                return filled, blocked
            filled = 0
        row = rows[filled]
        if k < 1:
            copy_into(a if k < 0 else b, row)
        else:
            interpolate(layout, a, b, fraction_between(k - 1, n, in_order, order), row)
        tags[filled] = 2 * step + (1 if k == 0 else 0)
        filled += 1
    return filled, NO_STEP


@njit_borrowing
def exit_state_free(view: ExitChecks, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether ``q`` is valid: one exit (a state counted here where the view is batched)."""
    copy_into(q, view.rows[0])
    if view.batched:
        view.counts[Count.STATES] += 1
    return _ask(view, _STATES, 1) == 1


@njit_borrowing
def exit_motion_free(view: ExitChecks, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """Whether the motion ``a -> b`` is valid (``a`` taken as valid).

    Batched: the states OMPL's discrete rule tests, handed to Python in one exit (in as many as
    the rows need), counting the motion and the states decided. Otherwise one exit that asks for
    the motion.
    """
    if not view.batched:
        copy_into(a, view.rows[0])
        copy_into(b, view.rows[1])
        return _ask(view, _MOTION, 2) == 1
    filled, blocked = _queue_motion(view, a, b, 1, False, 0)
    return blocked == NO_STEP and _ask_rows(view, filled) == NO_STEP


@njit_borrowing
def _queue_steps(
    view: ExitChecks, chain: np.ndarray, steps: int, outward: bool, first_step: int, filled: int
) -> tuple[int, int]:  # pragma: no cover (compiled)
    """Append to ``view.rows[filled:]`` the states the steps ``chain[0] -> ... -> chain[steps]``
    test, numbered from ``first_step``, as :func:`_queue_motion` appends one (the rows filled, and
    the blocked step an ask found, ``NO_STEP``: none)."""
    for k in range(1, steps + 1):
        if outward:
            filled, blocked = _queue_motion(view, chain[k - 1], chain[k], first_step + k - 1, False, filled)
        else:
            filled, blocked = _queue_motion(view, chain[k], chain[k - 1], first_step + k - 1, True, filled)
        if blocked != NO_STEP:
            return filled, blocked
    return filled, NO_STEP


@njit_borrowing
def exit_steps_free(view: ExitChecks, chain: np.ndarray, steps: int, outward: bool) -> int:  # pragma: no cover
    """:func:`~ompl_balance.core.checks.steps_free`: batched, every state the steps test in one
    exit (in as many as the rows need), in the order and with the counts of checking them one by
    one; otherwise a state and a motion at a time."""
    if not view.batched:
        return steps_one_by_one(view, chain, steps, outward)
    filled, blocked = _queue_steps(view, chain, steps, outward, 1, 0)
    if blocked == NO_STEP:
        blocked = _ask_rows(view, filled)
    return steps if blocked == NO_STEP else blocked - 1


@njit_borrowing
def exit_growth_free(
    view: ExitChecks, extension: np.ndarray, extension_outward: bool, chain: np.ndarray, steps: int, outward: bool
) -> int:  # pragma: no cover (compiled)
    """:func:`~ompl_balance.core.checks.growth_free`: batched, the extension's states and then the
    connect's in one exit (step 1 the extension, the connect's from 2), so an iteration makes one
    exit where it made two; otherwise in turn."""
    if not view.batched:
        return growth_in_turn(view, extension, extension_outward, chain, steps, outward)
    filled, blocked = _queue_steps(view, extension, 1, extension_outward, 1, 0)
    if blocked == NO_STEP:
        filled, blocked = _queue_steps(view, chain, steps, outward, 2, filled)
    if blocked == NO_STEP:
        blocked = _ask_rows(view, filled)
    if blocked == 1:
        return EXTENSION_BLOCKED
    return steps if blocked == NO_STEP else blocked - 2


register_kernels(
    ExitChecks, state=exit_state_free, motion=exit_motion_free, steps=exit_steps_free, growth=exit_growth_free
)
