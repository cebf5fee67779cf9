"""A rigid-body checker's kernels as the compiled engine calls them.

:class:`RigidStates` (a :class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`'s state
check) and :class:`RigidCertifiedMotions` (its certified motions) are the views the engine
takes from the rigid-body validators (:mod:`ompl_balance.core.checks`): the screening
(:func:`~ompl_balance.collision.rigid.view.state_status`) and the certified edge
(:func:`~ompl_balance.collision.rigid.advance.edge_status`) run compiled, and what they leave
undecided leaves through one counted exit to the checker's :meth:`decide` (FCL), a C callback
(:mod:`ompl_balance.core.checks`) whose states are staged in the view's ``staged`` array (an error
in it sets ``counts[Count.RAISED]``). The counts go to the checker's own work counter, as its
Python methods count.
"""

from __future__ import annotations

import enum
from typing import Any, NamedTuple

import numpy as np

from ...core.array_kernels import copy_into
from ...core.check_overloads import register_kernels
from ...core.checks import EXIT_ADDRESS, Count, exit_handle, kernels_in
from ...core.function_pointers import counted_exit
from ...core.kernel_cache import njit
from .advance import edge_status
from .motion import interpolate, motion_split
from .view import BOUNDS_COMPUTED, FREE, OVER_BUDGET, POSES_EVALUATED, UNDECIDED, RigidView, state_status


@kernels_in("ompl_balance.collision.rigid.kernels")
class RigidStates(NamedTuple):
    """A rigid-body checker's state check as compiled code sees it.

    ``rigid``: the checker's :class:`~ompl_balance.collision.rigid.view.RigidView` (geometry and
    scratch, shared with its Python methods); ``staged`` (2, state size): the states of a query
    to the checker, which it reads; ``address`` and ``handle``: the exit to the checker
    (:class:`Exit`); ``counts``: its work counter's array (indexed by
    :class:`~ompl_balance.core.checks.Count`).
    """

    rigid: RigidView  # (a field named "view" would clash with numba's array method)
    staged: np.ndarray
    address: int
    handle: int
    counts: np.ndarray


class Exit(enum.IntEnum):
    """What the rigid-body kernels' exits ask the checker: FCL on what the last kernel call left of
    the state ``staged[0]`` (``DECIDE_STATE``), or of the motion ``staged[0] -> staged[1]``
    (``DECIDE_MOTION``): 1 free, 0 not."""

    DECIDE_STATE = 0
    DECIDE_MOTION = 1


_DECIDE_STATE, _DECIDE_MOTION = int(Exit.DECIDE_STATE), int(Exit.DECIDE_MOTION)  # (for compiled code)


@kernels_in("ompl_balance.collision.rigid.kernels")
class RigidCertifiedMotions(NamedTuple):
    """A rigid-body checker's certified motions as compiled code sees them: its :class:`RigidStates`
    and their ``counts`` (the checker's work counter, which also counts the motions)."""

    states: RigidStates
    counts: np.ndarray


def rigid_states(checker: Any) -> RigidStates:
    """The :class:`RigidStates` view of a :class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`
    (the checker makes it once: its exit reads this view's ``staged`` states)."""
    staged = np.zeros((2, checker.body.state_size))
    return RigidStates(checker.view, staged, EXIT_ADDRESS, exit_handle(checker), checker.counter.array)


@njit(cache=True)
def decide(view: RigidStates, kind: int, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """The exit to the checker: FCL on what the last kernel call left of the state ``a``
    (``Exit.DECIDE_STATE``; ``b`` unused) or of the motion ``a -> b`` (``Exit.DECIDE_MOTION``);
    counts the exit. ``False`` with ``counts[Count.RAISED]`` set when the checker raised."""
    copy_into(a, view.staged[0])
    copy_into(b, view.staged[1])
    return counted_exit(view.counts, view.address, view.handle, kind, 0) == 1


@njit(cache=True)
def rigid_state_free(view: RigidStates, state: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """:meth:`RigidBodyChecker.is_valid` of ``state`` ((3,) SE(2), (7,) SE(3)); counts one state."""
    view.counts[Count.STATES] += 1
    status = state_status(view.rigid, state)
    if status != UNDECIDED:
        return status == FREE
    return decide(view, _DECIDE_STATE, state, state)


#: At most this many states probe a motion (:func:`probe_free`).
MAX_PROBES = 31


@njit(cache=True)
def probe_free(view: RigidStates, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether the states at ``t = j / n`` along ``a -> b`` (OMPL's interpolation) are free,
    visited coarse to fine (1/2, then 1/4 and 3/4, ...) up to the first that is not; ``n`` is
    the least power of two that puts them at most the body's radius of travel apart (at most
    :data:`MAX_PROBES` states). Counts the states it checks.

    Certified motions run it first where the screening decides no state (``view.rigid.probe``:
    body and world all meshes). There a certified motion costs tens of FCL distances, a state
    one FCL collision test, and most of the motions a planner tries collide: a colliding state
    refuses such a motion at once. (A body overlapping an obstacle at some point of a motion
    overlaps it for about its own size of travel, so most collisions are met.) The ends are
    not probed: a planner checks a motion's ends as states.
    """
    rigid = view.rigid
    translation, angle, _jump = motion_split(a, b)
    travel = translation + angle * rigid.body_radius
    segments = 1
    while 2 * segments - 1 <= MAX_PROBES and travel > segments * rigid.body_radius:
        segments *= 2
    state = np.empty(len(a))
    denominator = 2
    while denominator <= segments:
        for j in range(1, denominator, 2):
            interpolate(a, b, j / denominator, state)
            if not rigid_state_free(view, state):
                return False  # (also when the exit raised: the caller looks at counts)
        denominator *= 2
    return True


@njit(cache=True)
def rigid_certified_motion_free(
    view: RigidCertifiedMotions, a: np.ndarray, b: np.ndarray
) -> bool:  # pragma: no cover (compiled)
    """:meth:`RigidBodyChecker.certify` of ``a -> b`` without ``last_valid`` (probed first where
    ``probe`` says so); counts one motion, the probed states, the poses the edge was bounded at
    (as states) and the distance bounds, and the motion in ``counts[Count.OVER_BUDGET]`` when
    the edge kernel ran out of its work budget (the FCL exit counts its own)."""
    states = view.states
    counts, rigid = view.counts, states.rigid
    counts[Count.MOTIONS] += 1
    if rigid.probe and not probe_free(states, a, b):
        return False
    status, _fraction = edge_status(rigid, a, b, False)
    counts[Count.STATES] += rigid.counts[POSES_EVALUATED]
    counts[Count.DISTANCE_QUERIES] += rigid.counts[BOUNDS_COMPUTED]
    counts[Count.OVER_BUDGET] += rigid.counts[OVER_BUDGET]
    if status != UNDECIDED:
        return status == FREE
    return decide(states, _DECIDE_MOTION, a, b)


register_kernels(RigidStates, state=rigid_state_free)
register_kernels(RigidCertifiedMotions, state="states", motion=rigid_certified_motion_free)
