"""A rigid-body checker's kernels as the compiled engine calls them.

:class:`RigidStates` (a :class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`'s state
check) and :class:`RigidCertifiedMotions` (its certified motions) are the views the engine
takes from the rigid-body validators (:mod:`ompl_balance.core.checks`): the screening
(:func:`~ompl_balance.collision.rigid.view.state_status`) and the certified edge
(:func:`~ompl_balance.collision.rigid.advance.edge_status`) run compiled, and what they leave
undecided leaves through one counted exit to the checker's :meth:`decide` (FCL). The counts go
to the checker's own work counter, as its Python methods count.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import objmode

from ...core.check_overloads import register_kernels
from ...core.checks import Count, exit_handle, exit_target, kernels_in
from ...core.kernel_cache import njit
from .advance import edge_status
from .motion import interpolate, motion_split
from .view import BOUNDS_COMPUTED, FREE, OVER_BUDGET, POSES_EVALUATED, UNDECIDED, RigidView, state_status


@kernels_in("ompl_balance.collision.rigid.kernels")
class RigidStates(NamedTuple):
    """A rigid-body checker's state check as compiled code sees it.

    ``rigid``: the checker's :class:`~ompl_balance.collision.rigid.view.RigidView` (geometry and
    scratch, shared with its Python methods); ``handle``: the exit to the checker
    (:func:`~ompl_balance.core.checks.exit_target`); ``counts``: its work counter's array
    (indexed by :class:`~ompl_balance.core.checks.Count`).
    """

    rigid: RigidView  # (a field named "view" would clash with numba's array method)
    handle: int
    counts: np.ndarray


@kernels_in("ompl_balance.collision.rigid.kernels")
class RigidCertifiedMotions(NamedTuple):
    """A rigid-body checker's certified motions as compiled code sees them: its :class:`RigidStates`
    and their ``counts`` (the checker's work counter, which also counts the motions)."""

    states: RigidStates
    counts: np.ndarray


def rigid_states(checker: Any) -> RigidStates:
    """The :class:`RigidStates` view of a :class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`."""
    return RigidStates(checker.view, exit_handle(checker), checker.counter.array)


def _decide_state(handle: int, state: np.ndarray) -> bool:
    return bool(exit_target(handle).decide(state)[0])


def _decide_motion(handle: int, a: np.ndarray, b: np.ndarray) -> bool:
    return bool(exit_target(handle).decide(a, b)[0])


@njit(cache=True)
def decide_state(handle: int, state: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """The exit to the checker behind ``handle``: FCL on the pairs the screening of ``state`` left."""
    with objmode(free="boolean"):
        free = _decide_state(handle, state)
    return free


@njit(cache=True)
def decide_motion(handle: int, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """The exit to the checker behind ``handle``: FCL distances on the segments of ``a -> b`` the
    certified edge left."""
    with objmode(free="boolean"):
        free = _decide_motion(handle, a, b)
    return free


@njit(cache=True)
def rigid_state_free(view: RigidStates, state: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """:meth:`RigidBodyChecker.is_valid` of ``state`` ((3,) SE(2), (7,) SE(3)); counts one state."""
    view.counts[Count.STATES] += 1
    status = state_status(view.rigid, state)
    if status != UNDECIDED:
        return status == FREE
    view.counts[Count.EXITS] += 1
    return decide_state(view.handle, state)


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
                return False
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
    counts[Count.EXITS] += 1
    return decide_motion(states.handle, a, b)


register_kernels(RigidStates, state=rigid_state_free)
register_kernels(RigidCertifiedMotions, state="states", motion=rigid_certified_motion_free)


class _AllFree:
    """An exit target answering every query "free" (for :func:`warm_exits`)."""

    def decide(self, *arguments: Any) -> tuple[bool, float]:
        return True, 1.0


def warm_exits() -> None:
    """Run the exits to Python once: numba makes a kernel's ``objmode`` code ready the first time
    it runs in a process (about a tenth of a second), which would otherwise fall in a solve (for
    the kernels compiled in the same process as these: see the robot kernels' ``warm_exits``)."""
    target = _AllFree()  # held here: the registry holds it weakly
    handle, q = exit_handle(target), np.zeros(3)
    decide_state(handle, q)
    decide_motion(handle, q, q)
