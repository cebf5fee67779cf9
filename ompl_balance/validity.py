"""OMPL adapters for robots: a state validity checker and two motion validators backed by a
:class:`~ompl_balance.collision.checker.CollisionChecker`, the joint space, :func:`setup_robot`
and :func:`certify_path`; the same for rigid bodies in SE(2) and SE(3) backed by a
:class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker` (:func:`setup_rigid_body`).

Motion validators:

* :class:`CertifiedMotionValidator` (the default of :func:`setup_robot`) proves each
  straight joint-space edge free of collision for the checker's model, with an optional
  clearance (:mod:`ompl_balance.collision.certified`), within a work budget per edge
  (``motion_budget``, :mod:`ompl_balance.collision.budget`);
* :class:`MotionValidator` checks the states OMPL's ``DiscreteMotionValidator`` checks
  (``validSegmentCount`` of them), in one batch; what lies between them is not looked at.

The checker and its validators share one work counter (see :mod:`ompl_balance.core.counting`),
so ``RunStats`` and the benchmark logs count the states, motions and distance queries a
planner made them do.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .collision.budget import MOTION_BUDGET, budget_units
from .collision.certified import MotionCertifier, PathCertificate, certify_states
from .collision.checker import CollisionChecker
from .collision.kernels import (
    CertifiedMotions,
    RobotDiscreteMotions,
    robot_discrete_motion_free,
    robot_discrete_motions,
    visiting_order,
)
from .collision.kinematics import RobotModel
from .collision.rigid.checker import RigidBodyChecker, certify_rigid_states
from .collision.rigid.kernels import RigidCertifiedMotions, RigidStates
from .collision.rigid.motion import interpolate, interpolate_many
from .core.checks import raise_kept
from .core.compiled_calls import entry_point
from .core.layout import layout_for

#: The motion validators :func:`setup_robot` installs, by name.
MOTION_VALIDATORS = ("certified", "discrete")


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
        """Collision-free, within the joint limits, and finite (``False``, not an exception, otherwise)."""
        return self.checker.is_valid(state[0 : self._dof])

    def compiled_view(self) -> Any:
        """The checker's view for compiled code (:class:`~ompl_balance.collision.kernels.RobotStates`)."""
        return self.checker.kernel_view()

    def raise_error(self) -> None:
        """Raise the error the checker met in compiled code (FCL's, for the engine to report)."""
        self.checker.raise_error()

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()


class _RobotMotionValidator(ob.MotionValidator):
    """What the package's two motion validators share: the checker, its counters, and
    ``last_valid`` as OMPL's ``checkMotion(s1, s2, lastValid)`` sets it."""

    def __init__(self, si: ob.SpaceInformation, checker: CollisionChecker):
        _check_dimension(si, checker)
        super().__init__(si)
        self.checker = checker
        self._dof = checker.robot.dof

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()

    def raise_error(self) -> None:
        """Raise the error a check met in compiled code (FCL's, for the engine to report)."""
        self.checker.raise_error()

    @staticmethod
    def _set_last_valid(last_valid: ob.State | None, a: np.ndarray, b: np.ndarray, fraction: float) -> None:
        """Set ``last_valid`` (if given) to the state at ``fraction`` of the edge ``a -> b``:
        ``a`` itself at 0, so that a non-finite ``b`` never leaks into it."""
        if last_valid is None:
            return
        values = a if fraction == 0.0 else a + fraction * (b - a)
        for i, value in enumerate(values.tolist()):
            last_valid[i] = value


class MotionValidator(_RobotMotionValidator):
    """OMPL motion validator checking a whole edge in one batch.

    The edge ``s1 -> s2`` is cut into ``space.validSegmentCount(s1, s2)`` segments as
    OMPL's ``DiscreteMotionValidator`` does; the states at ``j / nd`` for
    ``j = 1 .. nd`` (``s1`` is taken as valid) are visited in the coarse-to-fine order
    ``s2``, the midpoint, the quarter points, ...: ``s2`` alone first on the single-state
    path (it decides most colliding edges, as in OMPL's validator), then all the others in
    one batch of forward kinematics and pre-filter, FCL running on them in that order until
    the first collision (:func:`~ompl_balance.collision.kernels.coarse_to_fine`). Counts one
    motion and the states of the batches processed.
    """

    def __init__(self, si: ob.SpaceInformation, checker: CollisionChecker):
        super().__init__(si, checker)
        self._space = si.getStateSpace()
        self._view: RobotDiscreteMotions | None = None
        self._segments: tuple[float, int] | None = None  # the space's valid segment length and factor for _view
        self._motion_free: Any = None

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.check_motion_last_valid(s1, s2)[0]

    def compiled_view(self) -> RobotDiscreteMotions:
        """The validator as compiled code sees it (:class:`~ompl_balance.collision.kernels.RobotDiscreteMotions`),
        for the space's current validity-checking resolution."""
        space = self._space
        segments = (space.getLongestValidSegmentLength(), space.getValidSegmentCountFactor())
        if self._view is None or segments != self._segments:
            layout = layout_for(space)
            assert layout is not None  # a real-vector space (checked at construction)
            rows = int(segments[1]) * math.ceil(space.getMaximumExtent() / segments[0])
            self._view = robot_discrete_motions(self.checker, layout, rows)
            self._segments = segments
            lower = np.ascontiguousarray(self.checker.robot.lower, dtype=float)
            self._motion_free = entry_point(robot_discrete_motion_free, (self._view, lower, lower))
        return self._view

    def check_motion_last_valid(
        self, s1: ob.State, s2: ob.State, last_valid: ob.State | None = None
    ) -> tuple[bool, float]:
        """Validity of the edge and the fraction ``t`` of it known valid.

        As OMPL's ``checkMotion(s1, s2, lastValid)`` overload (which the Python
        binding does not expose): on a collision the states are examined in order from
        ``s1``, ``t = (j - 1) / nd`` for the first invalid state ``j``, and ``last_valid``
        (if given) is set to the state at ``t``. ``t = 1`` for a valid edge, and whenever
        ``last_valid`` is not given (then the states are visited coarse to fine instead,
        by the compiled kernel :func:`~ompl_balance.collision.kernels.robot_discrete_motion_free`).
        A state with a non-finite value makes the edge invalid with ``t = 0`` (``last_valid``
        is then ``s1``).
        """
        a, b = np.array(s1[0 : self._dof]), np.array(s2[0 : self._dof])
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            # invalid, not an exception through OMPL's C++ caller
            self.checker.counter.motions_checked += 1
            self._set_last_valid(last_valid, a, b, 0.0)
            return False, 0.0
        if last_valid is None:
            view = self.compiled_view()
            free = bool(self._motion_free(view, a, b))
            raise_kept(view.counts, self.checker)
            return free, 1.0
        self.checker.counter.motions_checked += 1
        nd = self._space.validSegmentCount(s1, s2)
        t = np.arange(1, nd + 1) / nd
        first = self.checker.first_collision(a + t[:, None] * (b - a))
        if first < 0:
            return True, 1.0
        fraction = first / nd
        self._set_last_valid(last_valid, a, b, fraction)
        return False, fraction


class CertifiedMotionValidator(_RobotMotionValidator):
    """OMPL motion validator that proves each edge free of collision, or rejects it.

    An edge ``s1 -> s2`` is valid when the whole straight line ``s1 + t (s2 - s1)``,
    ``t in [0, 1]``, in joint space is certified: every collision pair of ``checker``'s
    model (link collision geometry against the environment's obstacles, and the enabled
    self-collision pairs) stays more than ``clearance`` metres apart. The proof is
    conservative advancement: distance lower bounds (bounding spheres, GJK on convex hulls,
    FCL's exact distance) against a bound on how far the links travel
    (:class:`~ompl_balance.collision.certified.MotionCertifier`). It never calls an edge
    with a colliding configuration valid; it may reject one that passes within
    :data:`~ompl_balance.collision.advancement.DISTANCE_TOLERANCE` (10 micrometres) of the
    clearance. What is not certified: anything off the straight line (a controller's
    tracking error), geometry the checker does not model (visual meshes, SRDF-disabled
    pairs), obstacles that move.

    States with a non-finite value or outside the robot's joint bounds make an edge
    invalid (OMPL's C++ caller gets ``false``, not an exception). Work is counted in the
    checker's counter: one motion per edge, the configurations evaluated as states, and
    the distance queries (GJK bounds and FCL distances).

    ``motion_budget``: the most work one edge's proof may take, in work units (one per
    configuration placed or GJK bound, :data:`~ompl_balance.collision.budget.FCL_QUERY_WORK`
    per FCL query; ``None``: no limit). An edge that would need more is invalid (never "free"
    unproved) and counts in the checker's ``motions_over_budget``: it bounds the cost of every
    ``checkMotion``, which OMPL's path simplifier needs to keep its time limit
    (:mod:`ompl_balance.collision.budget`).
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        checker: CollisionChecker,
        clearance: float = 0.0,
        motion_budget: int | None = MOTION_BUDGET,
    ):
        budget_units(motion_budget)  # (its error before OMPL's constructor runs)
        super().__init__(si, checker)
        self.certifier = MotionCertifier(checker, clearance, motion_budget=motion_budget)

    def compiled_view(self) -> CertifiedMotions:
        """The validator as compiled code sees it (:class:`~ompl_balance.collision.kernels.CertifiedMotions`)."""
        return self.certifier.compiled_view()

    def raise_error(self) -> None:
        """Raise the error a check met in compiled code (FCL's, for the engine to report)."""
        self.checker.raise_error()
        self.certifier.raise_error()

    @property
    def clearance(self) -> float:
        """Metres every pair keeps clear of contact along a valid edge."""
        return self.certifier.clearance

    @property
    def motion_budget(self) -> int | None:
        """The work units one edge's proof may take (``None``: no limit)."""
        return self.certifier.motion_budget

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.certifier.check(np.array(s1[0 : self._dof]), np.array(s2[0 : self._dof]))[0]

    def check_motion_last_valid(
        self, s1: ob.State, s2: ob.State, last_valid: ob.State | None = None
    ) -> tuple[bool, float]:
        """Validity of the edge and the fraction ``t`` of it certified from ``s1``.

        As OMPL's ``checkMotion(s1, s2, lastValid)`` overload (which the Python binding
        does not expose): ``[0, t]`` is certified, ``last_valid`` (if given) is set to the
        state at ``t``, and ``t = 1`` for a valid edge. Without ``last_valid``, a rejected
        edge reports ``t = 0`` (nothing is refined beyond the first failure).
        """
        a, b = np.array(s1[0 : self._dof]), np.array(s2[0 : self._dof])
        valid, fraction = self.certifier.check(a, b, last_valid=last_valid is not None)
        if not valid:
            self._set_last_valid(last_valid, a, b, fraction)
        return valid, fraction


def _check_dimension(si: ob.SpaceInformation, checker: CollisionChecker) -> None:
    dimension = si.getStateDimension()
    if dimension != checker.robot.dof:
        raise ValueError(
            f"space has dimension {dimension}, robot {checker.robot.name!r} has {checker.robot.dof} joints"
        )


def setup_robot(
    ss_or_si: og.SimpleSetup | ob.SpaceInformation,
    checker: CollisionChecker,
    motion: str = "certified",
    clearance: float = 0.0,
    motion_budget: int | None = MOTION_BUDGET,
) -> tuple[StateValidityChecker, CertifiedMotionValidator | MotionValidator]:
    """Install ``checker`` as state validity checker, and a motion validator.

    ``ss_or_si`` is an ``og.SimpleSetup`` or an ``ob.SpaceInformation`` whose space is
    a real-vector space of the robot's dimension (e.g. from :func:`space_for`).
    ``motion`` is ``"certified"`` (:class:`CertifiedMotionValidator`, keeping
    ``clearance`` metres, each edge's proof within ``motion_budget`` work units, ``None``
    for no limit) or ``"discrete"`` (:class:`MotionValidator`, OMPL's discrete states only).
    Call before ``setup()``/``solve()``. Returns the two installed objects.
    """
    if motion not in MOTION_VALIDATORS:
        raise ValueError(f"motion must be one of {', '.join(map(repr, MOTION_VALIDATORS))}, got {motion!r}")
    budget_units(motion_budget)
    if motion == "discrete" and clearance != 0.0:
        raise ValueError(f"clearance={clearance} needs motion='certified' (the discrete validator keeps none)")
    if motion == "discrete" and motion_budget != MOTION_BUDGET:
        raise ValueError(f"motion_budget={motion_budget} needs motion='certified' (the discrete validator has none)")
    si = ss_or_si.getSpaceInformation() if isinstance(ss_or_si, og.SimpleSetup) else ss_or_si
    _check_dimension(si, checker)
    validity = StateValidityChecker(si, checker)
    validator: CertifiedMotionValidator | MotionValidator
    if motion == "certified":
        validator = CertifiedMotionValidator(si, checker, clearance, motion_budget)
    else:
        validator = MotionValidator(si, checker)
    si.setStateValidityChecker(validity)
    si.setMotionValidator(validator)
    return validity, validator


def certify_path(
    checker: CollisionChecker | RigidBodyChecker,
    states: np.ndarray | og.PathGeometric,
    clearance: float = 0.0,
    motion_budget: int | None = MOTION_BUDGET,
) -> PathCertificate:
    """Certify a path's straight joint-space segments for ``checker``'s model.

    ``states`` is an ``(n, dof)`` array or an ``og.PathGeometric`` (a stock planner's or a
    smoother's output). Returns a :class:`~ompl_balance.collision.certified.PathCertificate`:
    whether every segment is certified with ``clearance`` metres to spare, the first
    segment that is not (and how much of it is), and the smallest exact distance at the
    path's states. Counts its work in the checker's counter. A segment whose proof would take
    more than ``motion_budget`` work units is not certified (``None``: no limit), as the
    certified motion validators have it.

    With a :class:`RigidBodyChecker` the segments are rigid-body motions along OMPL's
    interpolation and ``states`` are ``(n, 3)`` (SE(2)) or ``(n, 7)`` (SE(3)) rows.
    """
    if isinstance(checker, RigidBodyChecker):
        if isinstance(states, og.PathGeometric):
            size = checker.body.state_size
            states = np.array([rigid_state_values(states.getState(i), size) for i in range(states.getStateCount())])
        return certify_rigid_states(checker, np.asarray(states, dtype=float), clearance, motion_budget)
    if isinstance(states, og.PathGeometric):
        dof = checker.robot.dof
        states = np.array([states.getState(i)[0:dof] for i in range(states.getStateCount())]).reshape(-1, dof)
    return certify_states(checker, states, clearance, motion_budget)


# -- rigid bodies -------------------------------------------------------------------------
#
# A RigidBodyChecker's body moves in SE(2) or SE(3); its states are OMPL's SE2StateSpace and
# SE3StateSpace states, read as (x, y, yaw) and (x, y, z, qx, qy, qz, qw).


def rigid_body_space(space: str, low: Sequence[float], high: Sequence[float]) -> ob.StateSpace:
    """OMPL's ``SE2StateSpace`` (``space="SE2"``) or ``SE3StateSpace`` (``"SE3"``) with position
    bounds ``low``/``high`` (2 or 3 numbers each)."""
    axes = {"SE2": 2, "SE3": 3}.get(space)
    if axes is None:
        raise ValueError(f"space must be 'SE2' or 'SE3', got {space!r}")
    if len(low) != axes or len(high) != axes:
        raise ValueError(f"{space} position bounds are {axes} numbers each, got low {list(low)}, high {list(high)}")
    state_space = ob.SE2StateSpace() if axes == 2 else ob.SE3StateSpace()
    bounds = ob.RealVectorBounds(axes)
    for i, (lo, hi) in enumerate(zip(low, high)):
        bounds.setLow(i, float(lo))
        bounds.setHigh(i, float(hi))
    state_space.setBounds(bounds)
    return state_space


def rigid_state_values(state: ob.State, size: int) -> np.ndarray:
    """An SE(2) (``size`` 3) or SE(3) (``size`` 7) OMPL state as ``(x, y, yaw)`` or ``(x, y, z, qx, qy, qz, qw)``."""
    if size == 3:
        return np.array((state.getX(), state.getY(), state.getYaw()))
    rotation = state.rotation()
    return np.array((state.getX(), state.getY(), state.getZ(), rotation.x, rotation.y, rotation.z, rotation.w))


def set_rigid_state(state: ob.State, values: np.ndarray) -> None:
    """Write ``(x, y, yaw)`` or ``(x, y, z, qx, qy, qz, qw)`` into an SE(2) or SE(3) OMPL state."""
    if len(values) == 3:
        state.setXY(float(values[0]), float(values[1]))
        state.setYaw(float(values[2]))
        return
    state.setXYZ(float(values[0]), float(values[1]), float(values[2]))
    rotation = state.rotation()
    rotation.x, rotation.y, rotation.z, rotation.w = (float(v) for v in values[3:])


class RigidBodyValidityChecker(ob.StateValidityChecker):
    """OMPL state validity checker backed by a :class:`RigidBodyChecker` (counts each state)."""

    def __init__(self, si: ob.SpaceInformation, checker: RigidBodyChecker):
        _check_rigid_space(si, checker)
        super().__init__(si)
        self.checker = checker
        self._size = checker.body.state_size

    def isValid(self, state: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.checker.is_valid(rigid_state_values(state, self._size))

    def compiled_view(self) -> RigidStates | None:
        """The checker's view for compiled code (:class:`~ompl_balance.collision.rigid.kernels.RigidStates`)."""
        return self.checker.kernel_view()

    def raise_error(self) -> None:
        """Raise the error the checker met in compiled code (FCL's, for the engine to report)."""
        self.checker.raise_error()

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()


class _RigidBodyMotionValidator(ob.MotionValidator):
    """What the two rigid-body motion validators share: the checker, its counters, reading
    states, and ``last_valid`` set along OMPL's interpolation."""

    def __init__(self, si: ob.SpaceInformation, checker: RigidBodyChecker):
        _check_rigid_space(si, checker)
        super().__init__(si)
        self.checker = checker
        self._size = checker.body.state_size

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()

    def raise_error(self) -> None:
        """Raise the error the checker met in compiled code (FCL's, for the engine to report)."""
        self.checker.raise_error()

    def _values(self, state: ob.State) -> np.ndarray:
        return rigid_state_values(state, self._size)

    @staticmethod
    def _set_last_valid(last_valid: ob.State | None, a: np.ndarray, b: np.ndarray, fraction: float) -> None:
        """Set ``last_valid`` (if given) to OMPL's ``interpolate(a, b, fraction)`` (``a`` itself at 0)."""
        if last_valid is None:
            return
        values = a.copy()
        if fraction > 0.0:
            interpolate(a, b, fraction, values)
        set_rigid_state(last_valid, values)


class RigidBodyMotionValidator(_RigidBodyMotionValidator):
    """OMPL-style discrete motion validator for a rigid body, the states checked in one batch.

    The states OMPL's ``DiscreteMotionValidator`` checks (``interpolate(s1, s2, j / nd)``,
    ``j = 1 .. nd``, ``nd = space.validSegmentCount(s1, s2)``), ``s2`` first on the single-state
    path, then the others coarse to fine (:func:`~ompl_balance.collision.kernels.visiting_order`)
    in one screening batch, FCL running until the first collision. What lies between the states
    is not looked at. The compiled engine checks these states as it checks OMPL's own
    ``DiscreteMotionValidator``'s (:attr:`checks_as_discrete`), with the checker's kernels.
    """

    checks_as_discrete = True

    def __init__(self, si: ob.SpaceInformation, checker: RigidBodyChecker):
        super().__init__(si, checker)
        self._space = si.getStateSpace()

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.check_motion_last_valid(s1, s2)[0]

    def check_motion_last_valid(
        self, s1: ob.State, s2: ob.State, last_valid: ob.State | None = None
    ) -> tuple[bool, float]:
        """Validity of the edge and the fraction ``t`` of it known valid, as
        :meth:`MotionValidator.check_motion_last_valid` (for states along OMPL's interpolation)."""
        checker = self.checker
        checker.counter.motions_checked += 1
        a, b = self._values(s1), self._values(s2)
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            self._set_last_valid(last_valid, a, b, 0.0)
            return False, 0.0
        if last_valid is None and not checker.is_valid(b):
            return False, 1.0
        nd = self._space.validSegmentCount(s1, s2)
        t = np.arange(1, nd + 1) / nd
        states = np.empty((nd, len(a)))
        interpolate_many(a, b, t, states)
        if last_valid is None:
            return nd == 1 or checker.first_collision(states[:-1], visiting_order(nd)[1:], first_chunk=0) < 0, 1.0
        first = checker.first_collision(states)
        if first < 0:
            return True, 1.0
        fraction = first / nd
        self._set_last_valid(last_valid, a, b, fraction)
        return False, fraction


class RigidBodyCertifiedMotionValidator(_RigidBodyMotionValidator):
    """OMPL motion validator that proves each rigid-body motion free of collision, or rejects it.

    The motion ``s1 -> s2`` is what OMPL's ``interpolate`` traces (translation on a straight
    line, rotation along the shortest arc); it is valid when every pair (obstacle, body part)
    of ``checker``'s model stays more than ``checker.clearance`` apart along all of it
    (:meth:`RigidBodyChecker.certify`: conservative advancement with distance lower bounds
    against the body's travel), within the checker's work budget per motion
    (``checker.motion_budget``: a motion whose proof would need more is invalid and counts in
    ``motions_over_budget``). States that are not valid (outside the bounds, not finite)
    make a motion invalid. Counts in the checker's counter: one motion per edge, the poses
    evaluated as states, the distance queries.
    """

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.checker.certify(self._values(s1), self._values(s2))[0]

    def compiled_view(self) -> RigidCertifiedMotions | None:
        """The validator as compiled code sees it (:class:`~ompl_balance.collision.rigid.kernels.RigidCertifiedMotions`)."""
        states = self.checker.kernel_view()
        return None if states is None else RigidCertifiedMotions(states, states.counts)

    def check_motion_last_valid(
        self, s1: ob.State, s2: ob.State, last_valid: ob.State | None = None
    ) -> tuple[bool, float]:
        """Validity of the edge and the fraction ``t`` of it certified from ``s1`` (as
        :meth:`CertifiedMotionValidator.check_motion_last_valid`)."""
        a, b = self._values(s1), self._values(s2)
        valid, fraction = self.checker.certify(a, b, last_valid=last_valid is not None)
        if not valid:
            self._set_last_valid(last_valid, a, b, fraction)
        return valid, fraction


def _check_rigid_space(si: ob.SpaceInformation, checker: RigidBodyChecker) -> None:
    space = si.getStateSpace()
    expected = ob.SE2StateSpace if checker.body.space == "SE2" else ob.SE3StateSpace
    if not isinstance(space, expected):
        raise ValueError(
            f"rigid body {checker.body.name!r} moves in {checker.body.space}; the space information's state space "
            f"is {type(space).__name__}, expected {expected.__name__}"
        )


def setup_rigid_body(
    ss_or_si: og.SimpleSetup | ob.SpaceInformation, checker: RigidBodyChecker, motion: str = "certified"
) -> tuple[RigidBodyValidityChecker, RigidBodyCertifiedMotionValidator | RigidBodyMotionValidator]:
    """Install ``checker`` as state validity checker, and a motion validator, for a rigid body.

    ``ss_or_si``: an ``og.SimpleSetup`` or ``ob.SpaceInformation`` over an ``SE2StateSpace`` or
    ``SE3StateSpace`` (e.g. from :func:`rigid_body_space`), as the body moves. ``motion``:
    ``"certified"`` (:class:`RigidBodyCertifiedMotionValidator`, keeping ``checker.clearance``,
    each motion's proof within ``checker.motion_budget``) or ``"discrete"``
    (:class:`RigidBodyMotionValidator`, OMPL's discrete states only). Call
    before ``setup()``/``solve()``. Returns the two installed objects.
    """
    if motion not in MOTION_VALIDATORS:
        raise ValueError(f"motion must be one of {', '.join(map(repr, MOTION_VALIDATORS))}, got {motion!r}")
    si = ss_or_si.getSpaceInformation() if isinstance(ss_or_si, og.SimpleSetup) else ss_or_si
    validity = RigidBodyValidityChecker(si, checker)
    validator: RigidBodyCertifiedMotionValidator | RigidBodyMotionValidator
    if motion == "certified":
        validator = RigidBodyCertifiedMotionValidator(si, checker)
    else:
        validator = RigidBodyMotionValidator(si, checker)
    si.setStateValidityChecker(validity)
    si.setMotionValidator(validator)
    return validity, validator
