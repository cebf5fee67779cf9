"""Collision checking for URDF robots, and its OMPL adapters.

:class:`CollisionChecker` answers "is this configuration collision-free?" for a
:class:`~ompl_balance.kinematics.RobotModel` among the obstacles of an
:class:`Environment`, for many configurations at once:

1. batched forward kinematics (one numpy pass for all configurations),
2. a conservative numpy pre-filter: spheres covering each link geometry against an
   oriented box around each obstacle, and against each other for the self-collision
   pairs; only what may touch goes on to
3. FCL's exact test, pair by pair, on FCL objects built once (only their transforms
   are updated).

The answer is FCL's: the pre-filter only skips pairs whose bounding volumes are
apart, which FCL would report free. ``prefilter=False`` skips step 2 and checks the
environment through FCL's broad phase (a dynamic AABB tree of the obstacles against
one of the robot's geometries) and every self-collision pair with FCL; it is the
straightforward reference the tests compare with.

:class:`StateValidityChecker` and :class:`MotionValidator` put one checker behind
OMPL's interfaces; they share its :class:`WorkCounter` (see :mod:`ompl_balance.counting`).
"""

from __future__ import annotations

from dataclasses import dataclass

import fcl
import numpy as np
import trimesh
from ompl import base as ob
from ompl import geometric as og

from .geometry import Shape, fcl_transform, pose_matrix
from .kinematics import RobotModel

#: Slack (m) added to bounding-volume tests so that rounding never makes the pre-filter miss a contact.
PREFILTER_SLACK = 1e-6


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A static obstacle: ``shape`` at world ``pose`` (4, 4)."""

    name: str
    shape: Shape
    pose: np.ndarray


class Environment:
    """The static obstacles around a robot, in the robot's base (world) frame, metres.

    Poses are given as ``position`` (3,) of the shape's centre and a unit quaternion
    ``orientation_xyzw`` (scalar last), rotating shape axes into the world.
    """

    def __init__(self):
        self.obstacles: list[Obstacle] = []

    def add(self, name: str, shape: Shape, position=(0.0, 0.0, 0.0), orientation_xyzw=(0.0, 0.0, 0.0, 1.0)) -> None:
        if any(o.name == name for o in self.obstacles):
            raise ValueError(f"environment already has an obstacle named {name!r}")
        try:
            pose = pose_matrix(position, orientation_xyzw)
        except ValueError as error:
            raise ValueError(f"obstacle {name!r}: {error}") from error
        self.obstacles.append(Obstacle(name, shape, pose))

    def add_box(self, name: str, half_extents, position=(0.0, 0.0, 0.0), orientation_xyzw=(0.0, 0.0, 0.0, 1.0)) -> None:
        """A box with ``half_extents`` (hx, hy, hz), half the edge lengths."""
        self.add(name, Shape.box(half_extents), position, orientation_xyzw)

    def add_sphere(self, name: str, radius: float, position=(0.0, 0.0, 0.0)) -> None:
        self.add(name, Shape.sphere(radius), position)

    def add_cylinder(self, name: str, radius: float, length: float, position=(0.0, 0.0, 0.0),
                     orientation_xyzw=(0.0, 0.0, 0.0, 1.0)) -> None:
        """A cylinder along its local z, ``length`` the full height, centred on ``position``."""
        self.add(name, Shape.cylinder(radius, length), position, orientation_xyzw)

    def add_mesh(self, name: str, mesh, position=(0.0, 0.0, 0.0), orientation_xyzw=(0.0, 0.0, 0.0, 1.0)) -> None:
        """A triangle mesh: a ``trimesh.Trimesh`` or a file trimesh can read."""
        if not isinstance(mesh, trimesh.Trimesh):
            try:
                mesh = trimesh.load(str(mesh), force="mesh")
            except Exception as error:
                raise ValueError(f"obstacle {name!r}: cannot read mesh {mesh}: {error}") from error
        self.add(name, Shape.from_mesh(mesh), position, orientation_xyzw)


class WorkCounter:
    """States and motions checked; one instance is shared by a checker and its motion validator."""

    def __init__(self):
        self.states_checked = 0
        self.motions_checked = 0

    def counters(self) -> dict[str, int]:
        return {"states_checked": self.states_checked, "motions_checked": self.motions_checked}

    def reset(self) -> None:
        self.states_checked = 0
        self.motions_checked = 0


class CollisionChecker:
    """Exact collision checks of a robot among static obstacles, batched over configurations.

    Parameters
    ----------
    robot:
        The robot; its ``self_collision_pairs`` are checked for self-collision.
    environment:
        The obstacles (none if omitted).
    spheres_per_geometry:
        How many spheres cover each link geometry in the pre-filter (tighter with more).
    prefilter:
        ``False`` checks every pair with FCL (through FCL's broad phase for the environment).
    """

    def __init__(self, robot: RobotModel, environment: Environment | None = None,
                 spheres_per_geometry: int = 4, prefilter: bool = True):
        self.robot = robot
        self.environment = environment or Environment()
        self.prefilter = prefilter
        self.counter = WorkCounter()
        geometries, obstacles = robot.geometries, self.environment.obstacles
        self._request = fcl.CollisionRequest()

        self._geometry_body = np.array([g.body for g in geometries], dtype=int)
        self._geometry_origin = np.array([g.origin for g in geometries]).reshape(-1, 4, 4)
        self._links = [fcl.CollisionObject(g.shape.fcl_geometry(), fcl.Transform()) for g in geometries]
        self._obstacles = [fcl.CollisionObject(o.shape.fcl_geometry(), fcl_transform(o.pose)) for o in obstacles]
        self._pairs = np.array(robot.self_collision_pairs, dtype=int).reshape(-1, 2)
        self._environment_manager = fcl.DynamicAABBTreeCollisionManager()
        self._environment_manager.registerObjects(self._obstacles)
        self._environment_manager.setup()

        # pre-filter: link spheres (in body frames) grouped by geometry, obstacle boxes
        centres, radii, owner = [], [], []
        for index, g in enumerate(geometries):
            c, r = g.shape.bounding_spheres(spheres_per_geometry)
            centres.append(c @ g.origin[:3, :3].T + g.origin[:3, 3])
            radii.append(r)
            owner.append(np.full(len(r), index))
        centres = np.concatenate(centres).reshape(-1, 3)
        self._sphere_centre = np.hstack([centres, np.ones((len(centres), 1))])[:, :, None]  # (spheres, 4, 1)
        self._sphere_radius = np.concatenate(radii) if radii else np.zeros(0)
        owner = np.concatenate(owner) if owner else np.zeros(0, dtype=int)
        self._sphere_body = self._geometry_body[owner]
        self._sphere_starts = np.searchsorted(owner, np.arange(len(geometries)))  # spheres are sorted by owner
        # a point p is in box o's frame at p @ R_o - c_o @ R_o; all boxes in one product
        boxes = [o.shape.bounding_box() for o in obstacles]
        box_pose = np.array([o.pose @ pose for o, (pose, _) in zip(obstacles, boxes)]).reshape(-1, 4, 4)
        self._box_axes = np.concatenate(list(box_pose[:, :3, :3]), axis=1) if boxes else np.zeros((3, 0))
        self._box_offset = np.einsum("oi,oij->oj", box_pose[:, :3, 3], box_pose[:, :3, :3]).ravel()
        self._box_half = np.array([half for _, half in boxes]).reshape(-1, 3)
        # every sphere pair of every self-collision geometry pair, sorted by pair
        ia, ib, pair_of = [], [], []
        for p, (a, b) in enumerate(self._pairs):
            sa, sb = np.flatnonzero(owner == a), np.flatnonzero(owner == b)
            ia.append(np.repeat(sa, len(sb)))
            ib.append(np.tile(sb, len(sa)))
            pair_of.append(np.full(len(sa) * len(sb), p))
        self._pair_sphere_a = np.concatenate(ia).astype(int) if ia else np.zeros(0, dtype=int)
        self._pair_sphere_b = np.concatenate(ib).astype(int) if ib else np.zeros(0, dtype=int)
        pair_of = np.concatenate(pair_of) if pair_of else np.zeros(0, dtype=int)
        self._pair_starts = np.searchsorted(pair_of, np.arange(len(self._pairs)))
        self._pair_reach = (self._sphere_radius[self._pair_sphere_a] + self._sphere_radius[self._pair_sphere_b]
                            + PREFILTER_SLACK) ** 2

    # ------------------------------------------------------------------ public API

    def check(self, q) -> np.ndarray:
        """Validity (collision-free) of each configuration: ``q`` (n, dof) or (dof,) -> bool (n,)."""
        q = self.robot.as_array(q)
        self.counter.states_checked += len(q)
        poses = self.robot.body_poses(q)
        if not self.prefilter:
            return np.array([self._free_reference(p) for p in poses], dtype=bool)
        env_candidates, self_candidates = self._candidates(poses)
        valid = np.ones(len(q), dtype=bool)
        for i in np.flatnonzero(env_candidates.any(axis=(1, 2)) | self_candidates.any(axis=1)):
            valid[i] = self._free_exact(poses[i], env_candidates[i], self_candidates[i])
        return valid

    def is_valid(self, q) -> bool:
        """Validity of one configuration ``q`` (dof,)."""
        return bool(self.check(q)[0])

    def first_collision(self, q, order=None, first_chunk: int = 4) -> int:
        """Index of the first configuration in collision, visiting ``q`` (n, dof) in ``order``, or -1.

        The first ``first_chunk`` rows of ``order`` (default: row order) go through
        forward kinematics and the pre-filter together, then the rest together; the exact
        tests run row by row in ``order`` and stop at the first collision. Rows of a chunk
        that was processed count as states checked.
        """
        q = self.robot.as_array(q)
        order = np.arange(len(q)) if order is None else np.asarray(order, dtype=int)
        for chunk in (order[:first_chunk], order[first_chunk:]):
            if len(chunk) == 0:
                continue
            self.counter.states_checked += len(chunk)
            poses = self.robot.body_poses(q[chunk])
            if not self.prefilter:
                hit = next((k for k in range(len(chunk)) if not self._free_reference(poses[k])), -1)
            else:
                env, own = self._candidates(poses)
                maybe = np.flatnonzero(env.any(axis=(1, 2)) | own.any(axis=1))
                hit = next((k for k in maybe if not self._free_exact(poses[k], env[k], own[k])), -1)
            if hit >= 0:
                return int(chunk[hit])
        return -1

    def counters(self) -> dict[str, int]:
        return self.counter.counters()

    def reset_counters(self) -> None:
        self.counter.reset()

    # ------------------------------------------------------------------ internals

    def _candidates(self, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pairs whose bounding volumes touch: ``(env (n, geometries, obstacles), self (n, pairs))`` bool."""
        n, geometry_count, obstacle_count = len(poses), len(self._links), len(self._obstacles)
        centres = (poses[:, self._sphere_body, :3, :] @ self._sphere_centre)[..., 0]  # (n, spheres, 3)
        if obstacle_count and geometry_count:
            local = (centres @ self._box_axes - self._box_offset).reshape(n, -1, obstacle_count, 3)
            outside = np.maximum(np.abs(local) - self._box_half, 0.0)
            near = (outside**2).sum(axis=-1) <= (self._sphere_radius[:, None] + PREFILTER_SLACK) ** 2
            env = np.logical_or.reduceat(near, self._sphere_starts, axis=1)
        else:
            env = np.zeros((n, geometry_count, obstacle_count), dtype=bool)
        if len(self._pairs):
            gap = centres[:, self._pair_sphere_a] - centres[:, self._pair_sphere_b]
            near = (gap**2).sum(axis=-1) <= self._pair_reach
            own = np.logical_or.reduceat(near, self._pair_starts, axis=1)
        else:
            own = np.zeros((n, 0), dtype=bool)
        return env, own

    def _place(self, body_poses: np.ndarray, geometries) -> None:
        """Move the FCL objects of ``geometries`` to their poses for one configuration."""
        poses = body_poses[self._geometry_body[geometries]] @ self._geometry_origin[geometries]
        for g, pose in zip(geometries, poses):
            self._links[g].setRotation(pose[:3, :3])
            self._links[g].setTranslation(pose[:3, 3])

    def _collide(self, a: fcl.CollisionObject, b: fcl.CollisionObject) -> bool:
        return fcl.collide(a, b, self._request, fcl.CollisionResult()) > 0

    def _free_exact(self, body_poses: np.ndarray, env: np.ndarray, own: np.ndarray) -> bool:
        """FCL on the candidate pairs of one configuration; True if none collides."""
        env_pairs = np.argwhere(env)
        self_pairs = self._pairs[own]
        self._place(body_poses, np.unique(np.concatenate([env_pairs[:, 0], self_pairs.ravel()])))
        if any(self._collide(self._links[g], self._obstacles[o]) for g, o in env_pairs):
            return False
        return not any(self._collide(self._links[a], self._links[b]) for a, b in self_pairs)

    def _free_reference(self, body_poses: np.ndarray) -> bool:
        """FCL without pre-filter: broad phase against the environment, then every self pair."""
        self._place(body_poses, np.arange(len(self._links)))
        for link in self._links:
            data = fcl.CollisionData(self._request, fcl.CollisionResult())
            self._environment_manager.collide(link, data, fcl.defaultCollisionCallback)
            if data.result.is_collision:
                return False
        return not any(self._collide(self._links[a], self._links[b]) for a, b in self._pairs)


# ---------------------------------------------------------------------- OMPL adapters

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
        return self.checker.is_valid(state[0:self._dof])

    def counters(self) -> dict[str, int]:
        return self.checker.counters()

    def reset_counters(self) -> None:
        self.checker.reset_counters()


class MotionValidator(ob.MotionValidator):
    """OMPL motion validator checking a whole edge in one batch.

    The edge ``s1 -> s2`` is cut into ``space.validSegmentCount(s1, s2)`` segments as
    OMPL's ``DiscreteMotionValidator`` does; the states at ``j / nd`` for
    ``j = 1 .. nd`` (``s1`` is taken as valid) go through forward kinematics and the
    pre-filter in two batches (the first few of the coarse-to-fine order, ``s2``, the
    midpoint, the quarter points, ..., then the rest), and FCL runs on them in that order
    until the first collision. Counts one motion and the states of the batches processed.
    """

    def __init__(self, si: ob.SpaceInformation, checker: CollisionChecker):
        super().__init__(si)
        self.checker = checker
        self._space = si.getStateSpace()
        self._dof = checker.robot.dof

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        return self.check_motion_last_valid(s1, s2)[0]

    def check_motion_last_valid(self, s1: ob.State, s2: ob.State, last_valid: ob.State | None = None) -> tuple[bool, float]:
        """Validity of the edge and the fraction ``t`` of it known valid.

        As OMPL's ``checkMotion(s1, s2, lastValid)`` overload (which the Python
        binding does not expose): on a collision the states are examined in order from
        ``s1``, ``t = (j - 1) / nd`` for the first invalid state ``j``, and ``last_valid``
        (if given) is set to the state at ``t``. ``t = 1`` for a valid edge.
        """
        a, b = np.array(s1[0:self._dof]), np.array(s2[0:self._dof])
        nd = self._space.validSegmentCount(s1, s2)
        self.checker.counter.motions_checked += 1
        t = np.arange(1, nd + 1) / nd
        states = a + t[:, None] * (b - a)
        if last_valid is None:
            return self.checker.first_collision(states, coarse_to_fine(nd)) < 0, 1.0
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


def coarse_to_fine(nd: int) -> list[int]:
    """Visiting order of the states ``j / nd``, ``j = 1 .. nd`` (as indices ``j - 1``).

    The end state first, then breadth-first bisection of ``(0, nd)``: the midpoint, the
    quarter points, and so on, so that an obstacle across the edge is met early.
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
    return order


def setup_robot(ss_or_si, checker: CollisionChecker) -> tuple[StateValidityChecker, MotionValidator]:
    """Install ``checker`` as state validity checker and batched motion validator.

    ``ss_or_si`` is an ``og.SimpleSetup`` or an ``ob.SpaceInformation`` whose space is
    a real-vector space of the robot's dimension (e.g. from :func:`space_for`). Call
    before ``setup()``/``solve()``. Returns the two installed objects.
    """
    si = ss_or_si.getSpaceInformation() if isinstance(ss_or_si, og.SimpleSetup) else ss_or_si
    dimension = si.getStateDimension()
    if dimension != checker.robot.dof:
        raise ValueError(f"space has dimension {dimension}, robot {checker.robot.name!r} has {checker.robot.dof} joints")
    validity = StateValidityChecker(si, checker)
    motion = MotionValidator(si, checker)
    si.setStateValidityChecker(validity)
    si.setMotionValidator(motion)
    return validity, motion
