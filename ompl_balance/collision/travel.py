"""How far the links of a robot can travel when its joints move: the bound behind certified motions.

Along a straight joint-space edge ``q(t) = a + t (b - a)`` a point ``p`` of a link moves
with velocity ``sum_k v_k' w_k(p)``, where joint ``k`` upstream of the link changes its
value ``v_k`` at rate ``v_k'`` and ``w_k(p)`` is ``axis_k x (p - o_k)`` for a revolute
joint (``o_k`` a point of its axis) or ``axis_k`` for a prismatic one. So
``|dp/dt| <= sum_k |v_k'| r_k`` with ``r_k`` any bound on the distance of ``p`` from
joint ``k``'s axis (``1`` for a prismatic joint), and over ``[t0, t1]`` every point of the
link travels at most ``(t1 - t0) sum_k |dv_k| r_k``: path length bounds displacement.
This is the bound of Schwarzer, Saha and Latombe, "Adaptive dynamic collision checking
for single and multiple articulated robots in complex environments" (IEEE T-RO 21(3),
2005). A mimic joint ``v_k = m q_j + c`` has ``|dv_k| = |m| |dq_j|``, so the bound is
``(t1 - t0) sum_j |b_j - a_j| W[g, j]`` with ``W[g, j]`` the sum of ``|m_k| r_k(g)`` over
the joints ``k`` upstream of geometry ``g`` driven by active joint ``j``
(:func:`travel_weights`).

``r_k(g)`` must hold in every configuration within the joint bounds (:func:`joint_reach`).
Joint ``k`` turns the body whose frame origin is on its axis (the joint's child frame). If
``g`` hangs off that body itself, ``r_k`` is the largest distance of ``g`` from the axis,
exact over the geometry's extreme points (:func:`extreme_points`). Further down,
``p - o_k = t_1 + R_1 (t_2 + R_2 (... + R_m p_g))`` with ``t_i`` the fixed offsets of the
joints ``1..m`` between joint ``k``'s body and ``g``'s (plus ``v_i`` times the slide axis
for a prismatic joint), ``R_i`` rotations, and ``p_g`` the point in its body's frame. The
first offset is in joint ``k``'s child frame, where the axis is fixed, so
``|P_k (p - o_k)| <= |P_k t_1| + |t_2| + ... + |t_m| + max |p_g|`` (``P_k`` projects
across the axis; a prismatic offset counts at the end of its range where it is longest).

Both geometries of a self-collision pair count from their lowest common ancestor body:
the joints above it move both rigidly and leave their distance alone, so a pair's weight
sums the two geometries' weights over the joints below it, bounding their relative travel.
"""

from __future__ import annotations

import numpy as np

from .convex import convex_part
from .kinematics import Chain, LinkGeometry, RobotModel


def extreme_points(geometry: LinkGeometry) -> tuple[np.ndarray, float]:
    """Points (m, 3) in the geometry's body frame and a radius ``pad`` such that every point
    of the geometry is within ``pad`` of the convex hull of the points.

    Convex functions of a point (its distance from an origin or from an axis) are at most
    their largest value at these points plus ``pad`` over the geometry: the vertices of a
    mesh's convex hull, a box's corners, a sphere's centre (pad: its radius), a cylinder's
    two end centres (pad: its radius).
    """
    shape = geometry.shape
    vertices, pad, disk, _axis = convex_part(shape.kind, shape.dims, shape.hull_vertices(), geometry.origin)
    return vertices, pad + disk


def _across(points: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Distances of ``points`` (m, 3) from the line through the origin along unit ``axis``."""
    return np.linalg.norm(points - np.outer(points @ axis, axis), axis=1)


def joint_value_ranges(robot: RobotModel) -> np.ndarray:
    """(joints, 2): the values each moving joint takes within the robot's bounds (mimic ones scaled)."""
    chain = robot.chain
    ends = chain.multiplier[:, None] * np.stack([robot.lower, robot.upper], axis=1)[chain.source]
    ends += chain.shift[:, None]
    return np.sort(ends, axis=1)


def joint_reach(robot: RobotModel) -> np.ndarray:
    """``reach`` (joints, geometries): metres a point of geometry ``g`` moves per unit of joint ``k``.

    For a revolute joint upstream of ``g``, a bound valid in every configuration on the
    distance of any point of ``g`` from the joint's axis (see the module docstring); for a
    prismatic joint upstream of ``g``, 1; 0 where joint ``k`` does not move ``g``.
    """
    chain = robot.chain
    joints = len(chain.source)
    prismatic = np.linalg.norm(chain.slide, axis=1) > 0.5
    ranges = joint_value_ranges(robot)
    # largest length of each joint's offset (translation plus slide over its range)
    offset_length = np.array(
        [max(np.linalg.norm(chain.translation[j] + v * chain.slide[j]) for v in ranges[j]) for j in range(joints)]
    ).reshape(-1)
    reach = np.zeros((joints, len(robot.geometries)))
    for g, geometry in enumerate(robot.geometries):
        points, pad = extreme_points(geometry)
        radius = float(np.max(np.linalg.norm(points, axis=1))) + pad
        below: list[int] = []  # joints between the current one and g's body, deepest first
        body = geometry.body
        while body != 0:
            k = body - 1  # joint k moves body k + 1
            if prismatic[k]:
                reach[k, g] = 1.0
            elif not below:
                reach[k, g] = float(np.max(_across(points, chain.axis[k]))) + pad
            else:
                first = below[-1]  # the joint right below k: its offset is in k's child frame
                across_first = max(
                    float(_across((chain.translation[first] + v * chain.slide[first])[None], chain.axis[k])[0])
                    for v in ranges[first]
                )
                reach[k, g] = across_first + float(offset_length[below[:-1]].sum()) + radius
            below.append(k)
            body = int(chain.parent_body[k])
    return reach


def _ancestor_joints(chain: Chain, body: int) -> set[int]:
    """The moving joints between the root and ``body`` (joint k moves body k + 1)."""
    joints = set()
    while body != 0:
        joints.add(body - 1)
        body = int(chain.parent_body[body - 1])
    return joints


def travel_weights(robot: RobotModel) -> tuple[np.ndarray, np.ndarray]:
    """Travel bound weights per active joint: ``environment`` (geometries, dof) and ``self`` (pairs, dof).

    Along an edge ``a -> b``, no point of geometry ``g`` travels farther than
    ``sum_j |b_j - a_j| environment[g, j]``, and no point of self pair ``p`` travels farther
    relative to the other geometry than ``sum_j |b_j - a_j| self[p, j]`` (metres; see the
    module docstring).
    """
    chain = robot.chain
    reach = joint_reach(robot) * np.abs(chain.multiplier)[:, None]
    dof, geometries = robot.dof, len(robot.geometries)
    environment = np.zeros((geometries, dof))
    for k in range(len(chain.source)):
        environment[:, chain.source[k]] += reach[k]
    self_weight = np.zeros((len(robot.self_collision_pairs), dof))
    for p, (a, b) in enumerate(robot.self_collision_pairs):
        body_a, body_b = robot.geometries[a].body, robot.geometries[b].body
        common = _ancestor_joints(chain, body_a) & _ancestor_joints(chain, body_b)
        for k in (_ancestor_joints(chain, body_a) | _ancestor_joints(chain, body_b)) - common:
            self_weight[p, chain.source[k]] += reach[k, a] + reach[k, b]
    return environment, self_weight
