"""Certified rigid-body motions, compiled: conservative advancement along OMPL's interpolation.

:func:`edge_status` proves that along the motion ``a -> b`` that OMPL's ``interpolate`` traces
(:mod:`~ompl_balance.collision.rigid.motion`) every pair (obstacle, body part) stays more than
the view's ``clearance`` apart, or refuses the motion. Pair by pair: with distance lower bounds
``d0``, ``d1`` at ``t0``, ``t1`` and the part's travel rate ``V = |x_b - x_a| + reach * phi``
(no point moves faster), the pair stays at least ``(d0 + d1 - V (t1 - t0)) / 2`` apart on the
segment, so the segment is certified when ``d0 + d1 - 2 clearance > V (t1 - t0)``. First, an
obstacle that the whole body clears over the whole motion (every point of the body stays within
its radius of the straight line its frame origin follows; :func:`~ompl_balance.collision.rigid.view.swept_bound`)
is certified with one bound for all parts: in a world cut into many pieces most of them are
far from any one motion. Otherwise the
end bounds are sharpened (part sphere first, then GJK on the convex hulls, warm-started), and if
that does not do it the segment is halved and its midpoint bounded. Segments are processed
coarse to fine across all pairs (first in, first out), so a collision anywhere is met early.

When OMPL's interpolation turns at once to ``b``'s orientation (SE(3) orientations within its
quaternion tolerance, a rotation of at most 1e-4 rad), the motion is a translation in ``b``'s
orientation and ``a`` itself is within ``reach * phi`` of its start: certified with that much
more clearance.

A pair whose hulls are its FCL models (convex shapes: ``view.solid``) is decided here: a GJK
upper bound within :data:`~ompl_balance.collision.advancement.DISTANCE_TOLERANCE` (times the
view's scale) of the clearance is a contact. Segments of other pairs (a non-convex mesh, whose
hull may touch where the mesh does not) with at most ``view.handover`` of travel still
uncertified, or whose hulls overlap at an end (the hulls cannot certify them), are left to FCL's
exact distance in ``view.hard`` (``UNDECIDED``). A segment still
uncertified with less than :data:`MIN_TRAVEL` (times the scale) of travel refuses the motion, so
the kernel always terminates. Its cost is bounded too: each pose evaluated and each GJK bound
spends one unit of the view's ``budget`` (:mod:`ompl_balance.collision.budget`), and a proof that
would need more refuses the motion (``view.counts[OVER_BUDGET]``).
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.typed import Dict

from ...core.kernel_cache import njit
from ..advancement import DISTANCE_TOLERANCE, grown
from .motion import interpolate, motion_split, state_pose, valid_state
from .view import (
    BOUNDS_COMPUTED,
    COLLIDING,
    FREE,
    HARD_SEGMENTS,
    OVER_BUDGET,
    POSES_EVALUATED,
    UNDECIDED,
    RigidView,
    hull_bound,
    sphere_bound,
    swept_bound,
)

#: Travel (times the view's scale) below which an uncertified segment refuses the motion.
MIN_TRAVEL = 1e-7
#: Travel (times the view's scale) to which ``last_valid`` refines around the first failure
#: before it reports the certified fraction.
LAST_VALID_TRAVEL = 1e-3


@njit(cache=True, inline="always")
def _exhausted(
    view: RigidView,
    last_valid: bool,
    bad: float,
    seg_t: np.ndarray,
    first: int,
    tail: int,
    hard: int,
    overflow: bool,
    poses: int,
    bounded: int,
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """What :func:`edge_status` returns when its budget runs out: ``COLLIDING``, flagged in
    ``view.counts[OVER_BUDGET]``; with ``last_valid`` certified up to the least of ``bad`` and
    the starts of the segments still unproved (``seg_t[first:tail]`` and the hard segments;
    hard segments that did not fit leave nothing certified)."""
    counts = view.counts
    counts[OVER_BUDGET], counts[HARD_SEGMENTS] = 1, 0
    counts[POSES_EVALUATED], counts[BOUNDS_COMPUTED] = poses, bounded
    if not last_valid or overflow:
        bad = 0.0
    for i in range(first, tail):
        bad = min(bad, seg_t[i, 0])
    for i in range(hard):
        bad = min(bad, view.hard[i, 1])
    view.reached[0] = bad
    return COLLIDING, bad


@njit(cache=True)
def edge_status(
    view: RigidView, a: np.ndarray, b: np.ndarray, last_valid: bool
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """Certify the motion ``a -> b`` (states (3,) or (7,)): ``(status, fraction)``.

    ``FREE``: certified (fraction 1). ``COLLIDING``: refused; without ``last_valid`` the work
    stops at the first failure and the fraction is 0, with it the motion is refined around its
    first failure to :data:`LAST_VALID_TRAVEL` and ``[0, fraction]`` is certified. An end that is
    not a valid state refuses the motion with fraction 0. ``UNDECIDED``: certified but for the
    segments left in ``view.hard[:view.counts[1]]`` (``(pair, t0, t1, d0, d1)``; ``counts[1]`` is
    -1 when they did not fit, and then every pair needs FCL), certified on ``[0, fraction]`` up
    to them (``fraction`` is also left in ``view.reached[0]``). ``view.counts[2]`` and ``[3]``: poses evaluated and GJK bounds computed.

    The bound: poses evaluated plus GJK bounds computed <= ``view.budget``. A proof that would
    need more stops before the unit that would exceed it: ``COLLIDING`` with
    ``view.counts[OVER_BUDGET]`` set, with ``last_valid`` certified up to the first segment
    left unproved (:func:`_exhausted`).
    """
    counts = view.counts
    counts[HARD_SEGMENTS], counts[POSES_EVALUATED], counts[BOUNDS_COMPUTED], counts[OVER_BUDGET] = 0, 0, 0, 0
    if len(a) != len(b) or not (valid_state(a, view.low, view.high) and valid_state(b, view.low, view.high)):
        return COLLIDING, 0.0
    budget = view.budget
    if budget < 2:  # (not even the two ends can be placed)
        return _exhausted(view, last_valid, 0.0, np.empty((0, 2)), 0, 0, 0, False, 0, 0)
    translation, angle, jump = motion_split(a, b)
    parts = len(view.part_radius)
    clearance, solid = view.clearance, view.solid
    contact = clearance + DISTANCE_TOLERANCE * view.scale
    floor = MIN_TRAVEL * view.scale
    settle = LAST_VALID_TRAVEL * view.scale if last_valid else floor
    speed, margin = np.empty(parts), np.zeros(parts)
    for g in range(parts):
        if jump:
            speed[g], margin[g] = translation, angle * view.part_reach[g]
        else:
            speed[g] = translation + angle * view.part_reach[g]

    # evaluated poses: parameter t, pose (4, 4), by t
    point_t = np.empty(16)
    point_pose = np.empty((16, 4, 4))
    known = Dict.empty(key_type=types.float64, value_type=types.int64)
    state = np.empty(len(a))
    for t in (0.0, 1.0):
        interpolate(a, b, t, state)
        state_pose(state, point_pose[len(known)])
        point_t[len(known)] = t
        known[t] = len(known)

    # the obstacles the whole body clears over the whole motion, one bound each, need no pairs
    near = np.empty(len(view.box_half), dtype=np.int64)
    candidates = 0
    for o in range(len(near)):
        if not swept_bound(view, point_pose[0], point_pose[1], o) > clearance:
            near[candidates] = o
            candidates += 1

    # segments: pair, (t0, t1), lower bounds at both ends, whether they are final, their points
    seg_pair = np.empty(max(16, 2 * candidates * parts), dtype=np.int64)
    seg_t = np.empty((len(seg_pair), 2))
    seg_d = np.empty((len(seg_pair), 2))
    seg_final = np.zeros((len(seg_pair), 2), dtype=np.bool_)
    seg_point = np.empty((len(seg_pair), 2), dtype=np.int64)
    tail = 0
    for k in range(candidates):
        for g in range(parts):
            pair = near[k] * parts + g
            seg_pair[tail] = pair
            seg_t[tail, 0], seg_t[tail, 1] = 0.0, 1.0
            seg_d[tail, 0], seg_d[tail, 1] = (
                sphere_bound(view, point_pose[0], pair),
                sphere_bound(view, point_pose[1], pair),
            )
            seg_final[tail, 0], seg_final[tail, 1] = False, False
            seg_point[tail, 0], seg_point[tail, 1] = 0, 1
            tail += 1
    head = 0
    failed, bad, hard, overflow, bounded = False, 1.0, 0, False, 0
    while head < tail:
        e = head
        head += 1
        pair, t0, t1 = seg_pair[e], seg_t[e, 0], seg_t[e, 1]
        if t0 >= bad:
            continue
        g = pair % parts
        travel = speed[g] * (t1 - t0)
        need = travel + 2.0 * (clearance + margin[g])
        if seg_d[e, 0] + seg_d[e, 1] > need:
            continue
        first = 0 if seg_d[e, 0] <= seg_d[e, 1] else 1
        for side in (first, 1 - first):
            if seg_final[e, side]:
                continue
            if len(known) + bounded >= budget:  # (one more bound would exceed the budget)
                return _exhausted(view, last_valid, bad, seg_t, e, tail, hard, overflow, len(known), bounded)
            point = seg_point[e, side]
            target = need - seg_d[e, 1 - side]
            lower, upper = hull_bound(view, point_pose[point : point + 1], pair, target)
            bounded += 1
            seg_d[e, side] = max(seg_d[e, side], lower)
            seg_final[e, side] = lower < target
            if solid[pair] and upper <= contact + margin[g]:
                failed = True
                if not last_valid:
                    counts[POSES_EVALUATED], counts[BOUNDS_COMPUTED] = len(known), bounded
                    return COLLIDING, 0.0
                bad = min(bad, point_t[point])
            if seg_d[e, 0] + seg_d[e, 1] > need:
                break
        if seg_d[e, 0] + seg_d[e, 1] > need or t0 >= bad:
            continue
        # a hull that overlaps at an end will overlap on every piece cut from that end: FCL now
        overlapping = (seg_final[e, 0] and seg_d[e, 0] <= 0.0) or (seg_final[e, 1] and seg_d[e, 1] <= 0.0)
        if not solid[pair] and (travel <= view.handover or overlapping):
            if hard < len(view.hard):
                row = view.hard[hard]
                row[0], row[1], row[2], row[3], row[4] = pair, t0, t1, seg_d[e, 0], seg_d[e, 1]
                hard += 1
            else:
                overflow = True
            continue
        if travel < floor or (failed and t1 >= bad and travel < settle):
            failed = True
            if not last_valid:
                counts[POSES_EVALUATED], counts[BOUNDS_COMPUTED] = len(known), bounded
                return COLLIDING, 0.0
            bad = min(bad, t0)
            continue
        middle = 0.5 * (t0 + t1)
        if middle not in known:
            if len(known) + bounded >= budget:  # (placing the midpoint would exceed the budget)
                return _exhausted(view, last_valid, bad, seg_t, e, tail, hard, overflow, len(known), bounded)
            index = len(known)
            point_t = grown(point_t, index + 1)
            point_pose = grown(point_pose, index + 1)
            interpolate(a, b, middle, state)
            state_pose(state, point_pose[index])
            point_t[index] = middle
            known[middle] = index
        m = known[middle]
        dm = sphere_bound(view, point_pose[m], pair)
        seg_pair = grown(seg_pair, tail + 2)
        seg_t, seg_d = grown(seg_t, tail + 2), grown(seg_d, tail + 2)
        seg_final, seg_point = grown(seg_final, tail + 2), grown(seg_point, tail + 2)
        for side in range(2):
            child = tail + side
            seg_pair[child] = pair
            seg_t[child, side], seg_t[child, 1 - side] = seg_t[e, side], middle
            seg_d[child, side], seg_d[child, 1 - side] = seg_d[e, side], dm
            seg_final[child, side], seg_final[child, 1 - side] = seg_final[e, side], False
            seg_point[child, side], seg_point[child, 1 - side] = seg_point[e, side], m
        tail += 2
    counts[HARD_SEGMENTS] = -1 if overflow else hard
    counts[POSES_EVALUATED], counts[BOUNDS_COMPUTED] = len(known), bounded
    view.reached[0] = bad
    if overflow or hard > 0:
        return UNDECIDED, bad
    if failed:
        return COLLIDING, bad
    return FREE, 1.0
