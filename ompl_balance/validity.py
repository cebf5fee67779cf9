"""OMPL adapters for robots: a state validity checker and a motion validator backed by a
:class:`~ompl_balance.collision.checker.CollisionChecker`, the joint space, and :func:`setup_robot`.

The checker and its validators share one work counter (see :mod:`ompl_balance.core.counting`),
so ``RunStats`` and the benchmark logs count the states and motions a planner made them check.
"""

from __future__ import annotations

import functools

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .collision.checker import CollisionChecker
from .collision.kinematics import RobotModel


def space_for(robot: RobotModel) -> ob.RealVectorStateSpace:
    """A real-vector state space over the robot's active joints, bounded by the joint limits.

    Continuous joints are bounded to ``[-pi, pi]`` and do not wrap around.
    """
    space = ob.RealVectorStateSpace(robot.dof)
    bounds = ob.RealVectorBounds(robot.dof)
    for i, (low, high) in enumerate(zip(robot.lower, robot.upper)):
        bounds.setLow(i, float(low))
        bounds.setHigh(i, float(high))
    space.setBounds(bounds)
    return space


class StateValidityChecker(ob.StateValidityChecker):
    """OMPL state validity checker backed by a :class:`CollisionChecker` (counts each state)."""

    def __init__(self, si: ob.SpaceInformation, checker: CollisionChecker):
        super().__init__(si)
        self.checker = checker
        self._dof = checker.robot.dof

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.checker.is_valid(state[0 : self._dof])

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()


class MotionValidator(ob.MotionValidator):
    """OMPL motion validator checking a whole edge in one batch.

    The edge ``s1 -> s2`` is cut into ``space.validSegmentCount(s1, s2)`` segments as
    OMPL's ``DiscreteMotionValidator`` does; the states at ``j / nd`` for
    ``j = 1 .. nd`` (``s1`` is taken as valid) are visited in the coarse-to-fine order
    ``s2``, the midpoint, the quarter points, ...: ``s2`` alone first on the single-state
    path (it decides most colliding edges, as in OMPL's validator), then all the others in
    one batch of forward kinematics and pre-filter, FCL running on them in that order until
    the first collision. Counts one motion and the states of the batches processed.
    """

    def __init__(self, si: ob.SpaceInformation, checker: CollisionChecker):
        super().__init__(si)
        self.checker = checker
        self._space = si.getStateSpace()
        self._dof = checker.robot.dof

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.check_motion_last_valid(s1, s2)[0]

    def check_motion_last_valid(
        self, s1: ob.State, s2: ob.State, last_valid: ob.State | None = None
    ) -> tuple[bool, float]:
        """Validity of the edge and the fraction ``t`` of it known valid.

        As OMPL's ``checkMotion(s1, s2, lastValid)`` overload (which the Python
        binding does not expose): on a collision the states are examined in order from
        ``s1``, ``t = (j - 1) / nd`` for the first invalid state ``j``, and ``last_valid``
        (if given) is set to the state at ``t``. ``t = 1`` for a valid edge, and whenever
        ``last_valid`` is not given (then the states are visited coarse to fine instead).
        """
        self.checker.counter.motions_checked += 1
        b = np.array(s2[0 : self._dof])
        if last_valid is None and not self.checker.is_valid(b):
            # s2 alone on the single-state path first: it decides most colliding edges
            return False, 1.0
        a = np.array(s1[0 : self._dof])
        nd = self._space.validSegmentCount(s1, s2)
        t = np.arange(1, nd + 1) / nd
        if last_valid is None:
            states = a + t[:-1, None] * (b - a)
            return nd == 1 or self.checker.first_collision(states, coarse_to_fine(nd)[1:], first_chunk=0) < 0, 1.0
        states = a + t[:, None] * (b - a)
        first = self.checker.first_collision(states)
        if first < 0:
            return True, 1.0
        fraction = first / nd
        for i, value in enumerate(a + fraction * (b - a)):
            last_valid[i] = float(value)
        return False, fraction

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()


@functools.lru_cache(maxsize=4096)
def coarse_to_fine(nd: int) -> tuple[int, ...]:
    """Visiting order of the states ``j / nd``, ``j = 1 .. nd`` (as indices ``j - 1``).

    The end state first, then breadth-first bisection of ``(0, nd)``: the midpoint, the
    quarter points, and so on, so that an obstacle across the edge is met early. Cached:
    planners ask for the same few lengths again and again.
    """
    order = [nd - 1]
    intervals = [(0, nd)]
    while intervals:
        low, high = intervals.pop(0)
        if high - low < 2:
            continue
        mid = (low + high) // 2
        order.append(mid - 1)
        intervals += [(low, mid), (mid, high)]
    return tuple(order)


def setup_robot(ss_or_si, checker: CollisionChecker) -> tuple[StateValidityChecker, MotionValidator]:
    """Install ``checker`` as state validity checker and batched motion validator.

    ``ss_or_si`` is an ``og.SimpleSetup`` or an ``ob.SpaceInformation`` whose space is
    a real-vector space of the robot's dimension (e.g. from :func:`space_for`). Call
    before ``setup()``/``solve()``. Returns the two installed objects.
    """
    si = ss_or_si.getSpaceInformation() if isinstance(ss_or_si, og.SimpleSetup) else ss_or_si
    dimension = si.getStateDimension()
    if dimension != checker.robot.dof:
        raise ValueError(
            f"space has dimension {dimension}, robot {checker.robot.name!r} has {checker.robot.dof} joints"
        )
    validity = StateValidityChecker(si, checker)
    motion = MotionValidator(si, checker)
    si.setStateValidityChecker(validity)
    si.setMotionValidator(motion)
    return validity, motion
