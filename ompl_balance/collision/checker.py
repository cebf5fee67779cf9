"""Exact collision checking of a URDF robot among static obstacles, batched over configurations.

:class:`CollisionChecker` answers "is this configuration collision-free?" for a
:class:`~ompl_balance.collision.kinematics.RobotModel` among the obstacles of an
:class:`Environment`, for many configurations at once:

1. forward kinematics and a conservative screening, compiled, for all configurations
   in one call (:mod:`ompl_balance.collision.screening`): spheres covering each link
   geometry against an oriented box around each obstacle, and against each other for the
   self-collision pairs; only the pairs it cannot clear go on to
2. FCL's exact test, pair by pair, on FCL objects built once (only their transforms
   are updated).

The answer is FCL's: the screening only skips pairs whose bounding volumes are
apart, which FCL would report free. ``prefilter=False`` skips the screening and checks the
environment through FCL's broad phase (a dynamic AABB tree of the obstacles against
one of the robot's geometries) and every self-collision pair with FCL; it is the
straightforward reference the tests compare with.

The checker counts what it checks in its :class:`WorkCounter`, which the OMPL adapters
(:mod:`ompl_balance.validity`) share (see :mod:`ompl_balance.core.counting`).
"""

from __future__ import annotations

from typing import Any

import fcl
import numpy as np
from numpy.typing import ArrayLike

from ..core.checks import Count, ExitTarget, new_counts, raise_kept
from ..core.compiled_calls import entry_point
from .contacts import OBSTACLE, SELF, Contact, geometry_names
from .environment import Environment
from .geometry import fcl_transform
from .kernels import Exit, RobotStates, robot_state_free, robot_states
from .kinematics import RobotModel
from .screening import Volumes, build_volumes, screen


class _Count:
    """An entry of a :class:`WorkCounter`'s array, read and written as an ``int``."""

    def __init__(self, index: Count) -> None:
        self.index = index

    def __get__(self, counter: Any, owner: type | None = None) -> Any:
        return self if counter is None else int(counter.array[self.index])

    def __set__(self, counter: Any, value: int) -> None:
        counter.array[self.index] = value


class WorkCounter:
    """Work done for a planner; one instance is shared by a checker and its motion validator.

    ``states_checked``: configurations evaluated (a state check, a state of a discrete
    edge, a configuration a certified edge was bounded at); ``motions_checked``: edges;
    ``distance_queries``: distance bounds computed by GJK on convex hulls and FCL exact
    distances (certified motions only); ``motions_over_budget``: certified motions refused
    because their proof would exceed the check's work budget
    (:mod:`ompl_balance.collision.budget`). The counts live in :attr:`array` (indexed by
    :class:`~ompl_balance.core.checks.Count`), which compiled kernels increment in place.
    """

    def __init__(self) -> None:
        self.array = new_counts()

    states_checked = _Count(Count.STATES)
    motions_checked = _Count(Count.MOTIONS)
    distance_queries = _Count(Count.DISTANCE_QUERIES)
    exits = _Count(Count.EXITS)  # calls from compiled code to Python (FCL)
    motions_over_budget = _Count(Count.OVER_BUDGET)

    def counters(self) -> dict[str, int]:
        return {
            "states_checked": self.states_checked,
            "motions_checked": self.motions_checked,
            "distance_queries": self.distance_queries,
            "motions_over_budget": self.motions_over_budget,
        }

    def reset(self) -> None:
        self.array[:] = 0


class CollisionChecker(ExitTarget):
    """Exact collision checks of a robot among static obstacles, batched over configurations.

    Parameters
    ----------
    robot:
        The robot; its ``self_collision_pairs`` are checked for self-collision.
    environment:
        The obstacles (none if omitted).
    spheres_per_geometry:
        How many small spheres cover each link geometry in the screening (tighter with
        more; see :mod:`ompl_balance.collision.screening`).
    prefilter:
        ``False`` checks every pair with FCL (through FCL's broad phase for the environment).
    """

    def __init__(
        self,
        robot: RobotModel,
        environment: Environment | None = None,
        spheres_per_geometry: int = 8,
        prefilter: bool = True,
    ):
        self.robot = robot
        self.environment = environment or Environment()
        self.prefilter = prefilter
        self.counter = WorkCounter()
        geometries, obstacles = robot.geometries, self.environment.obstacles
        self._request = fcl.CollisionRequest()
        self._distance_request = fcl.DistanceRequest()

        self._geometry_origin = np.array([g.origin for g in geometries]).reshape(-1, 4, 4)
        self._origin_is_identity = [bool(np.array_equal(g.origin, np.eye(4))) for g in geometries]
        self._links = [fcl.CollisionObject(g.shape.fcl_geometry(), fcl.Transform()) for g in geometries]
        self._obstacles = [fcl.CollisionObject(o.shape.fcl_geometry(), fcl_transform(o.pose)) for o in obstacles]
        self._pairs = robot.self_collision_pairs  # (a, b) geometry indices
        self._environment_manager = fcl.DynamicAABBTreeCollisionManager()
        self._environment_manager.registerObjects(self._obstacles)
        self._environment_manager.setup()

        self._volumes = build_volumes(robot, obstacles, spheres_per_geometry)
        # The screening kernel is called without numba's type dispatch (about 4 us of a
        # 30 us state check): the argument types are fixed here, and _screen passes
        # C-contiguous float rows and fresh output arrays. The single-state path (OMPL's
        # isValid) reuses its output arrays.
        arguments = (np.zeros((1, robot.dof)), robot.chain, self._volumes, *self._screen_outputs(1))
        self._kernel = entry_point(screen, arguments)  # compiled or loaded now, not in a solve
        self._view = robot_states(self)
        self._state_free = entry_point(robot_state_free, (self._view, np.zeros(robot.dof)))

    # ------------------------------------------------------------------ public API

    def check(self, q: ArrayLike) -> np.ndarray:
        """Validity of each configuration: ``q`` (n, dof) or (dof,) -> bool (n,).

        A configuration with a non-finite value or outside the joint limits is not valid.
        """
        q = self.robot.as_array(q, finite=False)
        self.counter.states_checked += len(q)
        inside = self.robot.within_limits(q)
        valid = np.zeros(len(q), dtype=bool)
        rows = np.flatnonzero(inside)
        if len(rows) == 0:
            return valid
        if not self.prefilter:
            valid[rows] = [self._free_reference(p) for p in self.robot.body_poses(q[rows])]
            return valid
        outputs = self._screen_outputs(len(rows))
        maybe = self._screen(q[rows], outputs)
        poses, obstacle_hits, self_hits = outputs
        for k in range(len(rows)):
            valid[rows[k]] = not maybe[k] or self.decide(poses[k], obstacle_hits[k], self_hits[k])
        return valid

    def is_valid(self, q: ArrayLike) -> bool:
        """Validity of one configuration ``q`` (dof,); ``False`` for non-finite values or outside the joint limits."""
        q = self.robot.as_array(q, finite=False)
        if len(q) != 1:
            raise ValueError(f"is_valid takes one configuration of {self.robot.dof} joint values, got shape {q.shape}")
        if self.prefilter:  # the compiled engine's own state check (limits, screening, FCL)
            free = bool(self._state_free(self._view, np.ascontiguousarray(q[0])))
            raise_kept(self.counter.array, self)
            return free
        self.counter.states_checked += 1
        return bool(self.robot.within_limits(q)[0]) and self._free_reference(self.robot.body_poses(q)[0])

    def first_collision(self, q: ArrayLike, order: ArrayLike | None = None, first_chunk: int = 1) -> int:
        """Index of the first configuration in collision, visiting ``q`` (n, dof) in ``order``, or -1.

        The first ``first_chunk`` rows of ``order`` (default: row order) go through
        forward kinematics and the screening together, then the rest together; the exact
        tests run row by row in ``order`` and stop at the first collision. Rows of a chunk
        that was processed count as states checked. A configuration outside the joint
        limits counts as in collision.
        """
        q = self.robot.as_array(q)
        order = np.arange(len(q)) if order is None else np.asarray(order, dtype=int)
        inside = self.robot.within_limits(q)
        for chunk in (order[:first_chunk], order[first_chunk:]):
            if len(chunk) == 0:
                continue
            self.counter.states_checked += len(chunk)
            if not self.prefilter:
                poses = self.robot.body_poses(q[chunk])
                hit = next(
                    (k for k in range(len(chunk)) if not inside[chunk[k]] or not self._free_reference(poses[k])), -1
                )
            else:
                outputs = self._screen_outputs(len(chunk))
                maybe = self._screen(q[chunk], outputs)
                poses, obstacle_hits, self_hits = outputs
                hit = next(
                    (
                        k
                        for k in range(len(chunk))
                        if not inside[chunk[k]]
                        or (maybe[k] and not self.decide(poses[k], obstacle_hits[k], self_hits[k]))
                    ),
                    -1,
                )
            if hit >= 0:
                return int(chunk[hit])
        return -1

    def counters(self) -> dict[str, int]:
        return self.counter.counters()

    def reset_counters(self) -> None:
        self.counter.reset()

    @property
    def volumes(self) -> Volumes:
        """The bounding volumes of the screening (:class:`~ompl_balance.collision.screening.Volumes`)."""
        return self._volumes

    @property
    def pair_count(self) -> int:
        """Collision pairs: pair ``o * geometries + g`` is link geometry ``g`` against obstacle
        ``o``; pair ``obstacles * geometries + s`` is self-collision pair ``s``."""
        return len(self._obstacles) * len(self._links) + len(self._pairs)

    def decide(self, body_poses: np.ndarray, obstacle_hits: np.ndarray, self_hits: np.ndarray) -> bool:
        """FCL on the pairs the screening did not clear in one configuration; True if none collides.

        ``body_poses`` (bodies, 4, 4), ``obstacle_hits`` (obstacles, geometries) and
        ``self_hits`` (pairs) as the screening (:func:`~ompl_balance.collision.screening.screen`)
        filled them for that configuration.
        """
        placed: set[int] = set()

        def place(geometry: int) -> None:
            if geometry not in placed:
                self._place(body_poses, geometry)
                placed.add(geometry)

        for o, g in zip(*np.nonzero(obstacle_hits)):
            place(g)
            if self._collide(self._links[g], self._obstacles[o]):
                return False
        for p in np.flatnonzero(self_hits):
            a, b = self._pairs[p]
            place(a)
            place(b)
            if self._collide(self._links[a], self._links[b]):
                return False
        return True

    def pair_touching(self, pair: int, body_poses: np.ndarray) -> bool:
        """FCL's collision test of ``pair`` (see :attr:`pair_count`) at body poses (bodies, 4, 4)."""
        first, second = self._pair_objects(pair, body_poses)
        return self._collide(first, second)

    def pair_distance(self, pair: int, body_poses: np.ndarray) -> float:
        """FCL's distance (m) of ``pair`` at body poses (bodies, 4, 4), for a pair not in contact;
        counts one distance query."""
        first, second = self._pair_objects(pair, body_poses)
        self.counter.distance_queries += 1
        return float(fcl.distance(first, second, self._distance_request, fcl.DistanceResult()))

    def collisions(self, q: ArrayLike, nearest: int = 0) -> list[Contact]:
        """What collides at configuration ``q`` (dof,) (radians, metres): every pair of the model
        in contact, by FCL's collision test, in pair order (see :attr:`pair_count`): link
        geometries against obstacles, then the self-collision pairs.

        When no pair is in contact and ``nearest > 0``, the ``nearest`` closest pairs instead,
        with FCL's distances (m), closest first. Joint limits are not looked at (a configuration
        outside them collides with nothing here, yet is not valid), and nothing is counted in
        :attr:`counter`. ``ValueError`` for a wrong shape, a non-finite value or ``nearest < 0``.
        """
        rows = self.robot.as_array(q)
        if len(rows) != 1:
            raise ValueError(
                f"collisions takes one configuration of {self.robot.dof} joint values, got shape {rows.shape}"
            )
        if nearest < 0:
            raise ValueError(f"nearest must be a number of pairs >= 0, got {nearest}")
        poses = self.robot.body_poses(rows)[0]
        touching: list[int] = []
        apart: list[tuple[float, int]] = []
        for pair in range(self.pair_count):
            first, second = self._pair_objects(pair, poses)
            if self._collide(first, second):
                touching.append(pair)
            elif nearest:
                apart.append((float(fcl.distance(first, second, self._distance_request, fcl.DistanceResult())), pair))
        if touching or not nearest:
            return [self._contact(pair, True, 0.0) for pair in touching]
        return [self._contact(pair, False, distance) for distance, pair in sorted(apart)[:nearest]]

    def kernel_view(self) -> RobotStates:
        """The checker as compiled code sees it (:class:`~ompl_balance.collision.kernels.RobotStates`):
        its arrays, and the exit to :meth:`decide` for the pairs the screening leaves to FCL."""
        return self._view

    def answer(self, kind: int, count: int) -> int:
        """The exit's answer (:class:`~ompl_balance.collision.kernels.Exit`): :meth:`decide` on the
        configuration the kernel screened into the view's one-row arrays, 1 free, 0 not."""
        if kind != Exit.DECIDE:
            raise ValueError(f"a collision checker answers Exit.DECIDE, not query {kind}")
        view = self._view
        return int(self.decide(view.poses[0], view.obstacle_hits[0], view.self_hits[0]))

    # ------------------------------------------------------------------ internals

    def _pair_objects(self, pair: int, body_poses: np.ndarray) -> tuple[fcl.CollisionObject, fcl.CollisionObject]:
        """The FCL objects of ``pair``, the link geometries among them placed at ``body_poses``."""
        environment = len(self._obstacles) * len(self._links)
        if pair < environment:
            o, g = divmod(pair, len(self._links))
            self._place(body_poses, g)
            return self._links[g], self._obstacles[o]
        a, b = self._pairs[pair - environment]
        self._place(body_poses, a)
        self._place(body_poses, b)
        return self._links[a], self._links[b]

    def _contact(self, pair: int, touching: bool, distance: float) -> Contact:
        """Pair ``pair`` (see :attr:`pair_count`) as a :class:`~ompl_balance.collision.contacts.Contact`."""
        names = geometry_names([g.link for g in self.robot.geometries])
        environment = len(self._obstacles) * len(self._links)
        if pair < environment:
            o, g = divmod(pair, len(self._links))
            return Contact(names[g], self.environment.obstacles[o].name, OBSTACLE, touching, distance, g, o)
        a, b = self._pairs[pair - environment]
        return Contact(names[a], names[b], SELF, touching, distance, a, b)

    def _screen_outputs(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Arrays :func:`~ompl_balance.collision.screening.screen` fills for ``n`` configurations:
        body poses, obstacle-geometry hits and self-pair hits."""
        return (
            np.empty((n, self.robot.body_count, 4, 4)),
            np.empty((n, len(self._obstacles), len(self._links)), dtype=bool),
            np.empty((n, len(self._pairs)), dtype=bool),
        )

    def _screen(self, q: np.ndarray, outputs: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
        """Screen ``q`` (n, dof) into ``outputs`` (from :meth:`_screen_outputs`); True where FCL must decide."""
        return self._kernel(np.ascontiguousarray(q), self.robot.chain, self._volumes, *outputs)

    def _place(self, body_poses: np.ndarray, geometry: int) -> None:
        """Move the FCL object of ``geometry`` to its pose for one configuration."""
        pose = body_poses[self._volumes.geometry_body[geometry]]
        if not self._origin_is_identity[geometry]:
            pose = pose.dot(self._geometry_origin[geometry])
        self._links[geometry].setRotation(pose[:3, :3])
        self._links[geometry].setTranslation(pose[:3, 3])

    def _collide(self, a: fcl.CollisionObject, b: fcl.CollisionObject) -> bool:
        return fcl.collide(a, b, self._request, fcl.CollisionResult()) > 0

    def _free_reference(self, body_poses: np.ndarray) -> bool:
        """FCL without pre-filter: broad phase against the environment, then every self pair."""
        for g in range(len(self._links)):
            self._place(body_poses, g)
        for link in self._links:
            data = fcl.CollisionData(self._request, fcl.CollisionResult())
            self._environment_manager.collide(link, data, fcl.defaultCollisionCallback)
            if data.result.is_collision:
                return False
        return not any(self._collide(self._links[a], self._links[b]) for a, b in self._pairs)
