"""Exact collision checking and certified motions of a rigid body among static obstacles.

:class:`RigidBodyChecker` answers, for a :class:`~ompl_balance.collision.rigid.body.RigidBody`
among the obstacles of an :class:`~ompl_balance.collision.environment.Environment`:

* *is this state free?* (:meth:`~RigidBodyChecker.is_valid`, batched :meth:`~RigidBodyChecker.check`):
  the compiled screening (:func:`~ompl_balance.collision.rigid.view.state_status`), then FCL's
  exact test (BVH meshes, FCL primitives) of what it could not decide: a body of meshes whole,
  against the whole world when that is meshes too (one call, as OMPL.app's checker makes it),
  else against each obstacle left. The answer is FCL's: FCL tests triangles, so a body
  entirely inside a closed obstacle mesh, without touching it, is free (for OMPL.app too);
* *is this motion free?* (:meth:`~RigidBodyChecker.certify`): the motion OMPL's
  ``interpolate`` traces is certified by conservative advancement
  (:func:`~ompl_balance.collision.rigid.advance.edge_status`), FCL's exact distances finishing
  the segments of pairs with non-convex meshes (the whole body against the whole world when
  both are meshes). "Certified" means every pair stays more than
  ``clearance`` apart at every point of the motion, for the model FCL tests (meshes that are
  convex count as their solid hulls; every exact distance is taken less
  :data:`~ompl_balance.collision.advancement.DISTANCE_TOLERANCE` times the view's scale),
  each motion within a work budget (``motion_budget``, :mod:`ompl_balance.collision.budget`:
  a proof that would need more refuses the motion, counted in ``motions_over_budget``).

The compiled view (:attr:`RigidBodyChecker.view`, a
:class:`~ompl_balance.collision.rigid.view.RigidView`) lets a compiled planning loop call the
kernels itself and hand to :meth:`RigidBodyChecker.decide` only what they leave undecided.
``prefilter=False`` skips the screening and the advancement: FCL on every pair, and motions
bisected with FCL distances only (slow; the reference).
"""

from __future__ import annotations

import math
from typing import Any

import fcl
import numpy as np
from numpy.typing import ArrayLike

from ...core.checks import ExitTarget, raise_kept
from ...core.compiled_calls import entry_point
from ..advancement import DISTANCE_TOLERANCE
from ..bisection import bisect_segments, contact_at_middles
from ..budget import MOTION_BUDGET, OverBudgetError, WorkBudget, budget_units
from ..certified import PathCertificate
from ..checker import WorkCounter
from ..contacts import OBSTACLE, Contact
from ..environment import Environment
from ..geometry import Shape, fcl_transform
from .advance import LAST_VALID_TRAVEL, MIN_TRAVEL, edge_status
from .body import RigidBody
from .kernels import Exit, RigidStates, probe_free, rigid_states
from .motion import interpolate, motion_split, state_pose, valid_state
from .pieces import soup_mesh
from .view import (
    BOUNDS_COMPUTED,
    COLLIDING,
    FREE,
    HARD_SEGMENTS,
    OVER_BUDGET,
    POSES_EVALUATED,
    UNDECIDED,
    UNDECIDED_PAIRS,
    RigidView,
    build_view,
    state_status,
    states_status,
)

_REQUEST = fcl.CollisionRequest()
#: The pair index of the whole body against the whole world (both meshes) in the FCL phase.
WHOLE = -1
_DISTANCE_REQUEST = fcl.DistanceRequest()
#: How many exact distances at motions' ends a checker keeps (oldest dropped first).
END_DISTANCES_KEPT = 1024


class RigidBodyChecker(ExitTarget):
    """Collision checks and certified motions of a rigid body among static obstacles.

    Parameters
    ----------
    body:
        The body and the space it moves in (SE(2) or SE(3)).
    environment:
        The obstacles (none if omitted), world frame.
    bounds:
        ``(low, high)``: position bounds, 2 (SE(2)) or 3 (SE(3)) numbers each; a state outside
        is invalid, as OMPL.app's checker has it. ``None``: unbounded.
    spheres_per_part:
        Small spheres covering each body part in the screening.
    clearance:
        Distance certified motions keep from every obstacle (0: touching is contact).
    prefilter:
        ``False``: FCL on every pair, motions by FCL distances only (the reference).
    motion_budget:
        The most work one certified motion may take, in work units (one per pose evaluated or
        GJK bound, :data:`~ompl_balance.collision.budget.FCL_QUERY_WORK` per FCL query;
        :mod:`ompl_balance.collision.budget`): a motion whose proof would need more is not
        certified. ``None``: no limit.
    """

    def __init__(
        self,
        body: RigidBody,
        environment: Environment | None = None,
        bounds: tuple[ArrayLike, ArrayLike] | None = None,
        spheres_per_part: int = 8,
        clearance: float = 0.0,
        prefilter: bool = True,
        motion_budget: int | None = MOTION_BUDGET,
    ) -> None:
        if not (math.isfinite(clearance) and clearance >= 0.0):
            raise ValueError(f"clearance must be a finite distance >= 0, got {clearance}")
        budget = budget_units(motion_budget)
        self.motion_budget = motion_budget
        self.body = body
        self.environment = environment or Environment()
        self.prefilter = prefilter
        self.spheres_per_part = spheres_per_part
        self.clearance = float(clearance)
        self.counter = WorkCounter()
        self.bounds = self._position_bounds(bounds)
        # FCL's exact distances at motions' ends, by (pair, state): a planner's motions start
        # from tree states again and again, and a connection's next motion starts where its
        # last one ended
        self._end_distances: dict[tuple[int, bytes], float] = {}
        obstacles = self.environment.obstacles
        self._parts = [fcl.CollisionObject(p.shape.fcl_geometry(), fcl.Transform()) for p in body.parts]
        self._part_pose = [None if np.array_equal(p.pose, np.eye(4)) else p.pose for p in body.parts]
        self._obstacles = [fcl.CollisionObject(o.shape.fcl_geometry(), fcl_transform(o.pose)) for o in obstacles]
        # a body of meshes is also one FCL model: one placement per state, one test per obstacle
        self._whole_body: fcl.CollisionObject | None = None
        if all(p.shape.mesh is not None for p in body.parts):
            triangles = np.concatenate(
                [np.asarray(p.shape.trimesh().triangles) @ p.pose[:3, :3].T + p.pose[:3, 3] for p in body.parts]
            )
            self._whole_body = fcl.CollisionObject(soup_mesh_geometry(triangles), fcl.Transform())
        self._whole_world: fcl.CollisionObject | None = None
        if obstacles and all(o.shape.mesh is not None for o in obstacles):
            triangles = np.concatenate(
                [np.asarray(o.shape.trimesh().triangles) @ o.pose[:3, :3].T + o.pose[:3, 3] for o in obstacles]
            )
            self._whole_world = fcl.CollisionObject(soup_mesh_geometry(triangles), fcl.Transform())
        low3, high3 = np.full(3, -np.inf), np.full(3, np.inf)
        low3[: len(self.bounds[0])], high3[: len(self.bounds[1])] = self.bounds
        self.view: RigidView = build_view(body, obstacles, low3, high3, spheres_per_part, clearance, budget)
        """The compiled view: geometry and work arrays for the kernels (see :mod:`~ompl_balance.collision.rigid.view`)."""
        # the kernels are called without numba's type dispatch; argument types are fixed here
        state = np.zeros(body.state_size)
        if body.space == "SE3":
            state[6] = 1.0
        self._state_kernel = entry_point(state_status, (self.view, state))
        self._edge_kernel = entry_point(edge_status, (self.view, state, state, False))
        self._states_view = rigid_states(self)
        self._probe_kernel = entry_point(probe_free, (self._states_view, state, state))
        pairs = len(self._obstacles) * len(self._parts)
        states = np.zeros((1, body.state_size))
        self._batch_kernel = entry_point(
            states_status, (self.view, states, np.zeros((1, 4, 4)), np.zeros((1, pairs), dtype=bool))
        )

    def _position_bounds(self, bounds: tuple[ArrayLike, ArrayLike] | None) -> tuple[np.ndarray, np.ndarray]:
        axes = 2 if self.body.space == "SE2" else 3
        if bounds is None:
            return np.full(axes, -np.inf), np.full(axes, np.inf)
        low, high = (np.asarray(b, dtype=float).reshape(-1) for b in bounds)
        if low.shape != (axes,) or high.shape != (axes,) or np.isnan(low).any() or np.isnan(high).any():
            raise ValueError(f"{self.body.space} position bounds are (low, high) of {axes} numbers each, got {bounds}")
        if (low > high).any():
            raise ValueError(f"position bounds have low > high: low {low.tolist()}, high {high.tolist()}")
        return low, high

    # ------------------------------------------------------------------ states

    def is_valid(self, state: ArrayLike) -> bool:
        """Whether ``state`` ((3,) SE(2), (7,) SE(3)) is inside the bounds and free of collision.

        ``ValueError`` for a wrong shape; a non-finite state or a non-unit quaternion is invalid.
        """
        row = state if isinstance(state, np.ndarray) and _is_row(state, self.body.state_size) else self._row(state)
        self.counter.states_checked += 1
        if not self.prefilter:
            return self._valid_reference(row)
        status = self._state_kernel(self.view, row)
        return status == FREE or (status == UNDECIDED and self._free_pairs(self.view.pose[0], self._undecided()))

    def check(self, states: ArrayLike) -> np.ndarray:
        """Validity of each of ``states`` (n, 3) or (n, 7) -> bool (n,)."""
        rows = self._rows(states)
        self.counter.states_checked += len(rows)
        if not self.prefilter:
            return np.array([self._valid_reference(r) for r in rows], dtype=bool)
        poses = np.empty((len(rows), 4, 4))
        undecided = np.empty((len(rows), len(self._obstacles) * len(self._parts)), dtype=bool)
        status = self._batch_kernel(self.view, rows, poses, undecided)
        valid = status == FREE
        for i in np.flatnonzero(status == UNDECIDED):
            valid[i] = self._free_pairs(poses[i], np.flatnonzero(undecided[i]))
        return valid

    def first_collision(self, states: ArrayLike, order: ArrayLike | None = None, first_chunk: int = 1) -> int:
        """Index of the first invalid state of ``states`` (n, k), visiting them in ``order``, or -1.

        The first ``first_chunk`` states of ``order`` (default: row order) are screened together,
        then the rest together; FCL runs state by state in ``order`` and stops at the first
        collision. States of a chunk that was screened count as checked.
        """
        rows = self._rows(states)
        order = np.arange(len(rows)) if order is None else np.asarray(order, dtype=int)
        for chunk in (order[:first_chunk], order[first_chunk:]):
            if len(chunk) == 0:
                continue
            self.counter.states_checked += len(chunk)
            if not self.prefilter:
                hit = next((k for k, row in enumerate(rows[chunk]) if not self._valid_reference(row)), -1)
            else:
                poses = np.empty((len(chunk), 4, 4))
                undecided = np.empty((len(chunk), len(self._obstacles) * len(self._parts)), dtype=bool)
                status = self._batch_kernel(self.view, np.ascontiguousarray(rows[chunk]), poses, undecided)
                hit = next(
                    (
                        k
                        for k in np.flatnonzero(status != FREE).tolist()
                        if status[k] == COLLIDING or not self._free_pairs(poses[k], np.flatnonzero(undecided[k]))
                    ),
                    -1,
                )
            if hit >= 0:
                return int(chunk[hit])
        return -1

    # ------------------------------------------------------------------ motions

    def certify(self, a: ArrayLike, b: ArrayLike, last_valid: bool = False) -> tuple[bool, float]:
        """Whether the motion ``a -> b`` (OMPL's interpolation) is certified, and the fraction certified.

        Counts one motion, the poses evaluated and the distance queries (GJK bounds, FCL
        distances). An end that is not a valid state: not certified, fraction 0. Without
        ``last_valid`` a refused motion reports fraction 0; with it the motion is refined around
        its first failure and ``interpolate(a, b, s)`` is certified for every ``s`` up to the
        fraction returned. Where ``view.probe`` says so (body and world all meshes), a motion
        without ``last_valid`` is first probed at a few states
        (:func:`~ompl_balance.collision.rigid.kernels.probe_free`), which count as checked.
        A proof that would exceed :attr:`motion_budget` stops: not certified (with
        ``last_valid``, certified up to the first stretch left unproved), counted in
        ``motions_over_budget``.
        """
        a, b = self._row(a), self._row(b)
        self.counter.motions_checked += 1
        if not self.prefilter:
            return self._finish_edge(a, b, self._whole_edge(), 1.0, False, last_valid, WorkBudget(self.view.budget))
        if self.view.probe and not last_valid:
            probed_free = self._probe_kernel(self._states_view, a, b)
            raise_kept(self.counter.array, self)
            if not probed_free:
                return False, 0.0
        status, fraction = self._edge_kernel(self.view, a, b, last_valid)
        self._count_kernel_work()
        if status == FREE:
            return True, 1.0
        if status == COLLIDING:
            return False, fraction
        return self.decide(a, b, last_valid)

    def decide(self, a: ArrayLike, b: ArrayLike | None = None, last_valid: bool = False) -> tuple[bool, float]:
        """FCL's answer to what the last kernel call left ``UNDECIDED``.

        ``decide(a)`` after :func:`~ompl_balance.collision.rigid.view.state_status` ``(view, a)``:
        FCL's collision test of the pairs it left (``view.undecided``), with the body at
        ``view.pose[0]``; returns ``(free, 1.0 if free else 0.0)``. ``decide(a, b, last_valid)``
        after :func:`~ompl_balance.collision.rigid.advance.edge_status` ``(view, a, b,
        last_valid)``: FCL's exact distances finish the segments it left (``view.hard``) with what
        is left of the motion's work budget; returns ``(certified, fraction)`` as :meth:`certify`
        does. Counts the FCL work (distance queries and poses evaluated), not the state or motion
        itself, and the motion in ``motions_over_budget`` when the budget runs out.
        """
        if b is None:
            free = self._free_pairs(self.view.pose[0], self._undecided())
            return free, 1.0 if free else 0.0
        a, b = self._row(a), self._row(b)
        counts = self.view.counts
        hard, bad = int(counts[HARD_SEGMENTS]), float(self.view.reached[0])
        budget = WorkBudget(self.view.budget - int(counts[POSES_EVALUATED]) - int(counts[BOUNDS_COMPUTED]))
        if hard < 0:  # more than the view holds: every pair over the whole motion
            return self._finish_edge(a, b, self._whole_edge(), 1.0, False, last_valid, budget)
        segments = [tuple(row) for row in self.view.hard[:hard].tolist()]
        return self._finish_edge(a, b, segments, bad, bad < 1.0, last_valid, budget)

    def closest(self, state: ArrayLike) -> float:
        """The smallest FCL distance between the body and an obstacle at ``state`` (at most 0 in
        contact; ``inf`` without obstacles)."""
        row = self._row(state)
        pose = np.empty((4, 4))
        state_pose(row, pose)
        self._place_all(pose)
        best = np.inf
        for pair in range(len(self._obstacles) * len(self._parts)):
            part, obstacle = self._pair_objects(pair)
            if fcl.collide(part, obstacle, _REQUEST, fcl.CollisionResult()):
                return 0.0
            best = min(best, fcl.distance(part, obstacle, _DISTANCE_REQUEST, fcl.DistanceResult()))
        return float(best)

    def collisions(self, state: ArrayLike, nearest: int = 0) -> list[Contact]:
        """What collides at ``state`` ((3,) SE(2), (7,) SE(3)): every pair of a body part and an
        obstacle in contact, by FCL's collision test, in pair order (obstacles, then parts).

        When no pair is in contact and ``nearest > 0``, the ``nearest`` closest pairs instead,
        with FCL's distances (m), closest first. The position bounds are not looked at (see
        :meth:`inside_bounds`), and nothing is counted in :attr:`counter`. ``ValueError`` for a
        wrong shape, a non-finite value, a non-unit quaternion or ``nearest < 0``.
        """
        row = self.body.as_states(self._row(state))[0]
        if nearest < 0:
            raise ValueError(f"nearest must be a number of pairs >= 0, got {nearest}")
        pose = np.empty((4, 4))
        state_pose(row, pose)
        self._place_all(pose)
        touching: list[int] = []
        apart: list[tuple[float, int]] = []
        for pair in range(len(self._obstacles) * len(self._parts)):
            part, obstacle = self._pair_objects(pair)
            if fcl.collide(part, obstacle, _REQUEST, fcl.CollisionResult()):
                touching.append(pair)
            elif nearest:
                apart.append((float(fcl.distance(part, obstacle, _DISTANCE_REQUEST, fcl.DistanceResult())), pair))
        if touching or not nearest:
            return [self._contact(pair, True, 0.0) for pair in touching]
        return [self._contact(pair, False, distance) for distance, pair in sorted(apart)[:nearest]]

    def inside_bounds(self, state: ArrayLike) -> bool:
        """Whether ``state`` is a valid state within the position bounds (collisions aside)."""
        return bool(valid_state(self._row(state), self.view.low, self.view.high))

    def answer(self, kind: int, count: int) -> int:
        """The exit's answer (:class:`~ompl_balance.collision.rigid.kernels.Exit`): :meth:`decide`
        of the state or motion the kernel staged in its view, 1 free, 0 not."""
        staged = self._states_view.staged
        if kind == Exit.DECIDE_STATE:
            return int(self.decide(staged[0])[0])
        if kind == Exit.DECIDE_MOTION:
            return int(self.decide(staged[0].copy(), staged[1].copy())[0])
        raise ValueError(f"a rigid-body checker answers the queries of Exit, not query {kind}")

    def kernel_view(self) -> RigidStates | None:
        """The checker as compiled code sees it (:class:`~ompl_balance.collision.rigid.kernels.RigidStates`),
        or ``None`` without ``prefilter`` (the reference path is Python's)."""
        return self._states_view if self.prefilter else None

    def counters(self) -> dict[str, int]:
        return self.counter.counters()

    def reset_counters(self) -> None:
        self.counter.reset()

    # ------------------------------------------------------------------ internals

    def _row(self, state: ArrayLike) -> np.ndarray:
        array = np.asarray(state, dtype=float)
        if array.shape != (self.body.state_size,):
            raise ValueError(
                f"a {self.body.space} state of rigid body {self.body.name!r} has {self.body.state_size} values, "
                f"got shape {array.shape}"
            )
        return np.ascontiguousarray(array)

    def _rows(self, states: ArrayLike) -> np.ndarray:
        array = np.asarray(states, dtype=float)
        rows = array.reshape(1, -1) if array.ndim == 1 else array
        if rows.ndim != 2 or rows.shape[1] != self.body.state_size:
            raise ValueError(
                f"{self.body.space} states of rigid body {self.body.name!r} must have shape "
                f"(n, {self.body.state_size}), got {array.shape}"
            )
        return np.ascontiguousarray(rows)

    def _undecided(self) -> np.ndarray:
        return self.view.undecided[: self.view.counts[UNDECIDED_PAIRS]]

    def _contact(self, pair: int, touching: bool, distance: float) -> Contact:
        """Pair ``pair`` (obstacle * parts + part) as a :class:`~ompl_balance.collision.contacts.Contact`."""
        obstacle, part = divmod(pair, len(self._parts))
        name = self.environment.obstacles[obstacle].name
        return Contact(self.body.parts[part].name, name, OBSTACLE, touching, distance, part, obstacle)

    def _count_kernel_work(self) -> None:
        counts = self.view.counts
        self.counter.states_checked += int(counts[POSES_EVALUATED])
        self.counter.distance_queries += int(counts[BOUNDS_COMPUTED])
        if counts[OVER_BUDGET]:
            self.counter.motions_over_budget += 1

    def _pair_objects(self, pair: int) -> tuple[fcl.CollisionObject, fcl.CollisionObject]:
        obstacle, part = divmod(pair, len(self._parts))
        return self._parts[part], self._obstacles[obstacle]

    def _place(self, pose: np.ndarray, part: int) -> None:
        """Move part ``part``'s FCL object to the body at ``pose`` (4, 4)."""
        offset = self._part_pose[part]
        placed = pose if offset is None else pose @ offset
        self._parts[part].setRotation(placed[:3, :3])
        self._parts[part].setTranslation(placed[:3, 3])

    def _place_all(self, pose: np.ndarray) -> None:
        for part in range(len(self._parts)):
            self._place(pose, part)

    def _free_pairs(self, pose: np.ndarray, pairs: np.ndarray) -> bool:
        """FCL's collision test of ``pairs`` with the body at ``pose``: True if none collides.

        A body of meshes is tested whole (one placement): against the whole world when the
        world is meshes too (one call, as OMPL.app does), else against each obstacle of the
        pairs, the first pair's (the likeliest contact) first. Otherwise part by part. The same
        triangles, so the same answer.
        """
        parts = len(self._parts)
        if not len(pairs):
            return True
        if self._whole_body is not None:
            body = self._whole_body
            body.setRotation(pose[:3, :3])
            body.setTranslation(pose[:3, 3])
            if self._whole_world is not None:
                return not fcl.collide(body, self._whole_world, _REQUEST, fcl.CollisionResult())
            obstacles = dict.fromkeys((pairs // parts).tolist())  # in order, once each
            return not any(fcl.collide(body, self._obstacles[o], _REQUEST, fcl.CollisionResult()) for o in obstacles)
        placed: set[int] = set()
        for pair in pairs.tolist():
            obstacle, part = divmod(pair, parts)
            if part not in placed:
                self._place(pose, part)
                placed.add(part)
            if fcl.collide(self._parts[part], self._obstacles[obstacle], _REQUEST, fcl.CollisionResult()):
                return False
        return True

    def _valid_reference(self, row: np.ndarray) -> bool:
        if not valid_state(row, self.view.low, self.view.high):
            return False
        pose = np.empty((4, 4))
        state_pose(row, pose)
        return self._free_pairs(pose, np.arange(len(self._obstacles) * len(self._parts)))

    def _whole_edge(self) -> list[tuple[float, ...]]:
        """Every pair over the whole motion, without bounds: what FCL alone must certify."""
        return [(pair, 0.0, 1.0, -np.inf, -np.inf) for pair in range(len(self._obstacles) * len(self._parts))]

    def _finish_edge(
        self,
        a: np.ndarray,
        b: np.ndarray,
        segments: list[tuple[Any, ...]],
        bad: float,
        failed: bool,
        last_valid: bool,
        budget: WorkBudget,
    ) -> tuple[bool, float]:
        """Certify ``segments`` ``(pair, t0, t1, d0, d1)`` of the motion ``a -> b`` with FCL.

        ``bad``/``failed``: what the kernel found (certified on ``[0, bad]`` but for the
        segments). Conservative advancement as the kernel does it, with FCL's exact distances
        (contact: ``-inf``) as the bounds; returns ``(certified, fraction)``. When body and world
        are both meshes, the segments' spans are certified for the whole body against the whole
        world instead (pair :data:`WHOLE`: one distance per pose bounds every pair, travelling at
        the body's reach). Each pose evaluated and FCL query is spent from ``budget``; when it
        runs out the motion is not certified (with ``last_valid``, up to the first segment left
        unproved) and counts in ``motions_over_budget``.
        """
        view, counter = self.view, self.counter
        low, high = view.low, view.high
        if not (valid_state(a, low, high) and valid_state(b, low, high)):
            return False, 0.0
        translation, angle, jump = motion_split(a, b)
        reach = np.append(view.part_reach, self.body.reach)  # index WHOLE (-1): the whole body
        speed = translation + (0.0 if jump else angle) * reach
        margin = angle * reach if jump else np.zeros(len(reach))
        clearance, scale = self.clearance, view.scale
        settle = (LAST_VALID_TRAVEL if last_valid else MIN_TRAVEL) * scale
        poses: dict[float, np.ndarray] = {}
        exact: dict[tuple[int, float], float] = {}
        touches: dict[tuple[int, float], bool] = {}
        state = np.empty(len(a))
        ends = self._end_distances
        whole_body, whole_world = self._whole_body, self._whole_world
        if whole_body is not None and whole_world is not None and segments:
            segments = [(WHOLE, t0, t1, -np.inf, -np.inf) for t0, t1 in _spans(segments)]

        def pose_at(t: float) -> np.ndarray:
            if t not in poses:
                budget.spend(1)
                interpolate(a, b, t, state)
                poses[t] = np.empty((4, 4))
                state_pose(state, poses[t])
                counter.states_checked += 1
            return poses[t]

        def placed(pair: int, t: float) -> tuple[fcl.CollisionObject, fcl.CollisionObject]:
            """The pair's FCL objects with the body at ``t``."""
            if pair == WHOLE and whole_body is not None and whole_world is not None:
                pose = pose_at(t)
                whole_body.setRotation(pose[:3, :3])
                whole_body.setTranslation(pose[:3, 3])
                return whole_body, whole_world
            self._place(pose_at(t), pair % len(self._parts))
            return self._pair_objects(pair)

        def touching(pair: int, t: float) -> bool:
            if (pair, t) not in touches:
                objects = placed(pair, t)
                budget.spend()
                touches[pair, t] = fcl.collide(*objects, _REQUEST, fcl.CollisionResult())
            return touches[pair, t]

        def distance(pair: int, t: float) -> float:
            if (pair, t) not in exact:
                end = (pair, (a if t == 0.0 else b).tobytes()) if t in (0.0, 1.0) else None
                if end is not None and end in ends:
                    exact[pair, t] = ends.pop(end)  # (kept again below, as the newest)
                elif touching(pair, t):
                    exact[pair, t] = -np.inf
                else:
                    objects = placed(pair, t)
                    budget.spend()
                    counter.distance_queries += 1
                    found = fcl.distance(*objects, _DISTANCE_REQUEST, fcl.DistanceResult())
                    exact[pair, t] = found - DISTANCE_TOLERANCE * scale
                if end is not None:
                    ends[end] = exact[pair, t]
                    if len(ends) > END_DISTANCES_KEPT:
                        del ends[next(iter(ends))]
            return exact[pair, t]

        # contacts first: a collision test is cheaper than a distance, which a segment its ends
        # certify never needs at its middle
        try:
            if not last_valid and contact_at_middles(
                np.array([0.5 * (t0 + t1) for _, t0, t1, _, _ in segments]),
                lambda i, t: touching(int(segments[i][0]), t),
            ):
                return False, 0.0
        except OverBudgetError:
            counter.motions_over_budget += 1
            return False, 0.0
        parts = len(self._parts)

        def group(pair: int) -> int:  # the body part of a pair (WHOLE: the whole body)
            return pair if pair == WHOLE else pair % parts

        failed, bad = bisect_segments(
            ((int(pair), t0, t1, d0, d1) for pair, t0, t1, d0, d1 in segments),
            distance,
            lambda pair: speed[group(pair)],
            lambda pair: clearance + margin[group(pair)],
            MIN_TRAVEL * scale,
            settle,
            last_valid,
            failed,
            bad,
        )
        if budget.exhausted:
            counter.motions_over_budget += 1
        if failed:
            return False, bad if last_valid else 0.0
        return True, 1.0


def _is_row(state: object, size: int) -> bool:
    """Whether ``state`` is already what the kernels take: a contiguous float64 array (size,)."""
    return (
        type(state) is np.ndarray and state.dtype == np.float64 and state.shape == (size,) and state.flags.c_contiguous
    )


def soup_mesh_geometry(triangles: np.ndarray) -> fcl.BVHModel:
    """FCL's BVH model of a triangle soup (t, 3, 3)."""
    return Shape.from_mesh(soup_mesh(triangles)).fcl_geometry()


def _spans(segments: list[tuple[Any, ...]]) -> list[tuple[float, float]]:
    """The union of the segments' ``[t0, t1]`` as disjoint spans, in order."""
    spans: list[tuple[float, float]] = []
    for _pair, t0, t1, _d0, _d1 in sorted(segments, key=lambda s: s[1]):
        if spans and t0 <= spans[-1][1]:
            spans[-1] = (spans[-1][0], max(spans[-1][1], t1))
        else:
            spans.append((t0, t1))
    return spans


def certify_rigid_states(
    checker: RigidBodyChecker,
    states: np.ndarray,
    clearance: float = 0.0,
    motion_budget: int | None = MOTION_BUDGET,
) -> PathCertificate:
    """Certify the motions between consecutive ``states`` (n, 3) or (n, 7) for ``checker``'s model.

    As :func:`~ompl_balance.collision.certified.certify_states` does for robots: every motion
    (OMPL's interpolation) certified with ``clearance`` to spare, each within ``motion_budget``
    work units (a motion whose proof would need more is not certified), the first that is not
    and how much of it is, and the smallest FCL distance at the states. Work is counted in
    ``checker``'s counter. ``ValueError`` for a wrong shape, non-finite values or non-unit
    quaternions; a state outside the position bounds leaves its motions uncertified.
    """
    rows = checker.body.as_states(states)
    if len(rows) == 0:
        raise ValueError("a path needs at least one state")
    certifier = checker
    if clearance != checker.clearance or motion_budget != checker.motion_budget:
        certifier = RigidBodyChecker(
            checker.body,
            checker.environment,
            checker.bounds,
            checker.spheres_per_part,
            clearance,
            checker.prefilter,
            motion_budget,
        )
        certifier.counter = checker.counter
    first_bad, fraction = None, 1.0
    for i in range(len(rows) - 1):
        ok, fraction = certifier.certify(rows[i], rows[i + 1], last_valid=True)
        if not ok:
            first_bad = i
            break
    inside = [certifier.inside_bounds(row) for row in rows]
    smallest = min(certifier.closest(row) if ok else -np.inf for row, ok in zip(rows, inside))
    tolerance = DISTANCE_TOLERANCE * certifier.view.scale
    certified = first_bad is None and all(inside) and smallest > clearance + tolerance
    return PathCertificate(
        certified=certified,
        segments=len(rows) - 1,
        first_bad_segment=first_bad,
        certified_fraction=fraction if first_bad is not None else 1.0,
        smallest_clearance=smallest,
        clearance=clearance,
    )


def warm_up() -> None:
    """Compile the rigid-body kernels, or load them from numba's cache, for the argument types
    every checker passes (a small body and box stand in), as
    :func:`~ompl_balance.collision.screening.warm_up` does for robots: spent here instead of in a
    problem's first check (a process that imports this and calls it, e.g. a benchmark runner's
    forkserver, starts its runs warm)."""
    environment = Environment()
    environment.add_box("box", (0.1, 0.1, 0.1), (1.0, 0.0, 0.0))
    body = RigidBody("SE3", [("sphere", Shape.sphere(0.1), None)], name="warm-up")
    checker = RigidBodyChecker(body, environment)
    start, end = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]), np.array([2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    checker.check(np.stack([start, end]))
    checker.certify(start, end)
