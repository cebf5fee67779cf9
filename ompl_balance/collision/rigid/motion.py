"""Poses of rigid-body states and OMPL's interpolation between them, compiled.

A motion ``a -> b`` is what OMPL's ``interpolate(a, b, t)`` traces for ``t in [0, 1]``:

* the position moves on the straight line ``(1 - t) p_a + t p_b``;
* SE(2): the yaw turns by the shortest angle (``SO2StateSpace``: ``b - a`` if ``|b - a| <= pi``,
  else the other way round, the result brought back into ``[-pi, pi]``);
* SE(3): the orientation follows the shortest arc (``SO3StateSpace``: slerp at constant angular
  rate, ``-q_b`` when ``q_a . q_b < 0``). When ``|q_a . q_b| > 1 - 1e-9`` OMPL's arc length is 0
  and its interpolation jumps to ``q_b`` for every ``t > 0``: :func:`motion_split` says so.

Along such a motion, a point ``p`` of the body, at ``R(t) p + x(t)``, moves at speed at most
``|x_b - x_a| + phi |p|`` (``phi`` the total rotation angle, ``|p|`` its distance from the
frame origin in SE(3), from the frame's z axis in SE(2)): path length bounds displacement,
so over ``[t0, t1]`` no point travels farther than ``(t1 - t0) (|x_b - x_a| + reach phi)``.
"""

from __future__ import annotations

import math

import numpy as np

from ...core.kernel_cache import njit

#: OMPL's ``MAX_QUATERNION_NORM_ERROR``: quaternions closer than this to the same
#: orientation (``|q_a . q_b| > 1 -`` this) are one orientation for OMPL's interpolation,
#: and a quaternion whose norm is off 1 by more is not a valid SO(3) state.
QUATERNION_TOLERANCE = 1e-9


@njit(cache=True)
def valid_state(state: np.ndarray, low: np.ndarray, high: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether ``state`` (3,) or (7,) is finite, inside the position bounds ``low``/``high`` (3,)
    and (SE(3)) has a unit quaternion."""
    for value in state:
        if not math.isfinite(value):
            return False
    axes = 2 if len(state) == 3 else 3
    for axis in range(axes):
        if not (low[axis] <= state[axis] <= high[axis]):
            return False
    if len(state) == 7:
        norm = math.sqrt(state[3] ** 2 + state[4] ** 2 + state[5] ** 2 + state[6] ** 2)
        if abs(norm - 1.0) > QUATERNION_TOLERANCE:
            return False
    return True


@njit(cache=True)
def state_pose(state: np.ndarray, pose: np.ndarray) -> None:  # pragma: no cover (compiled)
    """The body frame pose (4, 4) of ``state`` (3,) or (7,) into ``pose`` (the quaternion is normalised)."""
    pose[3, 0], pose[3, 1], pose[3, 2], pose[3, 3] = 0.0, 0.0, 0.0, 1.0
    if len(state) == 3:
        c, s = math.cos(state[2]), math.sin(state[2])
        pose[0, 0], pose[0, 1], pose[0, 2], pose[0, 3] = c, -s, 0.0, state[0]
        pose[1, 0], pose[1, 1], pose[1, 2], pose[1, 3] = s, c, 0.0, state[1]
        pose[2, 0], pose[2, 1], pose[2, 2], pose[2, 3] = 0.0, 0.0, 1.0, 0.0
        return
    x, y, z, w = state[3], state[4], state[5], state[6]
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    pose[0, 0], pose[0, 1], pose[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    pose[1, 0], pose[1, 1], pose[1, 2] = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    pose[2, 0], pose[2, 1], pose[2, 2] = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    pose[0, 3], pose[1, 3], pose[2, 3] = state[0], state[1], state[2]


@njit(cache=True)
def _yaw_step(a: float, b: float) -> float:  # pragma: no cover (compiled)
    """The signed shortest turn from yaw ``a`` to ``b``, as OMPL's ``SO2StateSpace::interpolate`` takes it."""
    diff = b - a
    if abs(diff) <= math.pi:
        return diff
    return diff - 2.0 * math.pi if diff > 0.0 else diff + 2.0 * math.pi


@njit(cache=True)
def motion_split(a: np.ndarray, b: np.ndarray) -> tuple[float, float, bool]:  # pragma: no cover (compiled)
    """``(translation, angle, jump)`` of the motion ``a -> b``.

    ``translation``: length of the position change; ``angle``: the total rotation angle (rad,
    computed robustly from the quaternions' half-angle ``atan2(|v|, |s|)`` of ``q_a^-1 q_b``);
    ``jump``: OMPL's interpolation turns at once to ``b``'s orientation (SE(3) orientations
    within its quaternion tolerance but not equal), so that the motion is a pure translation
    in ``b``'s orientation after ``t = 0``.
    """
    axes = 2 if len(a) == 3 else 3
    translation = 0.0
    for axis in range(axes):
        translation += (b[axis] - a[axis]) ** 2
    translation = math.sqrt(translation)
    if len(a) == 3:
        return translation, abs(_yaw_step(a[2], b[2])), False
    na = math.sqrt(a[3] ** 2 + a[4] ** 2 + a[5] ** 2 + a[6] ** 2)
    nb = math.sqrt(b[3] ** 2 + b[4] ** 2 + b[5] ** 2 + b[6] ** 2)
    ax, ay, az, aw = a[3] / na, a[4] / na, a[5] / na, a[6] / na
    bx, by, bz, bw = b[3] / nb, b[4] / nb, b[5] / nb, b[6] / nb
    # q_a^-1 q_b: scalar part and the norm of its vector part
    scalar = aw * bw + ax * bx + ay * by + az * bz
    vx = aw * bx - bw * ax - (ay * bz - az * by)
    vy = aw * by - bw * ay - (az * bx - ax * bz)
    vz = aw * bz - bw * az - (ax * by - ay * bx)
    angle = 2.0 * math.atan2(math.sqrt(vx * vx + vy * vy + vz * vz), abs(scalar))
    dot = abs(a[3] * b[3] + a[4] * b[4] + a[5] * b[5] + a[6] * b[6])
    return translation, angle, dot > 1.0 - QUATERNION_TOLERANCE and angle > 0.0


@njit(cache=True)
def interpolate(a: np.ndarray, b: np.ndarray, t: float, out: np.ndarray) -> None:  # pragma: no cover (compiled)
    """OMPL's ``interpolate(a, b, t)`` of SE(2) or SE(3) states into ``out``."""
    axes = 2 if len(a) == 3 else 3
    for axis in range(axes):
        out[axis] = a[axis] + t * (b[axis] - a[axis])
    if len(a) == 3:
        yaw = a[2] + t * _yaw_step(a[2], b[2])
        if abs(b[2] - a[2]) > math.pi:  # the way round: back into [-pi, pi] as OMPL does
            if yaw > math.pi:
                yaw -= 2.0 * math.pi
            elif yaw < -math.pi:
                yaw += 2.0 * math.pi
        out[2] = yaw
        return
    dot = a[3] * b[3] + a[4] * b[4] + a[5] * b[5] + a[6] * b[6]
    half = 0.0 if abs(dot) > 1.0 - QUATERNION_TOLERANCE else math.acos(abs(dot))  # OMPL's arc length
    if half > 2.220446049250313e-16:
        d = 1.0 / math.sin(half)
        s0 = math.sin((1.0 - t) * half)
        s1 = math.sin(t * half)
        if dot < 0.0:
            s1 = -s1
        for k in range(3, 7):
            out[k] = (a[k] * s0 + b[k] * s1) * d
    else:
        for k in range(3, 7):
            out[k] = b[k]


@njit(cache=True)
def interpolate_many(a: np.ndarray, b: np.ndarray, t: np.ndarray, out: np.ndarray) -> None:  # pragma: no cover
    """:func:`interpolate` at each of ``t`` (m,) into the rows of ``out`` (m, 3) or (m, 7)."""
    for i in range(len(t)):
        interpolate(a, b, t[i], out[i])
