"""The exact end of conservative advancement: a motion's hard segments bisected with FCL.

Both certifiers (the arm's :class:`~ompl_balance.collision.certified.MotionCertifier` and the
rigid body's :class:`~ompl_balance.collision.rigid.checker.RigidBodyChecker`) leave their
compiled kernels with *segments* ``(pair, t0, t1, d0, d1)``: a collision pair over the part
``[t0, t1]`` of the motion (``t`` from 0 to 1) with lower bounds ``d0``, ``d1`` (m) of its
distance at the two ends, which the kernels could not make prove the segment free. This
module finishes them with exact distances: a segment along which the pair's points travel at
most ``travel`` is free when ``d0 + d1 > travel + 2 * allowance`` (neither end can close the
gap before meeting the other half way), is sharpened with an exact distance at an end where
the bounds do not suffice, and is halved otherwise, widest segments first (coarse to fine).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable

import numpy as np

#: ``(pair, t0, t1, d0, d1)``: a collision pair over ``[t0, t1]`` with distance lower bounds at its ends.
Segment = tuple[int, float, float, float, float]


def sharper(bound: float, exact: float) -> float:
    """The better of a lower bound and an exact distance (``-inf``: contact, which stands)."""
    return exact if exact == -np.inf else max(bound, exact)


def bisect_segments(
    segments: Iterable[Segment],
    distance: Callable[[int, float], float],
    speed: Callable[[int], float],
    allowance: Callable[[int], float],
    min_travel: float,
    settle: float,
    last_valid: bool,
    failed: bool = False,
    bad: float = 1.0,
) -> tuple[bool, float]:
    """Certify ``segments`` with exact distances; returns ``(failed, bad)``: whether some part
    of the motion is not certified, and from which ``t`` on (the motion is certified on
    ``[0, bad]``).

    ``distance(pair, t)``: the pair's exact distance (m) at ``t`` less any tolerance, ``-inf``
    in contact; ``speed(pair)``: how far (m) its points travel per unit of ``t`` at most;
    ``allowance(pair)``: the distance (m) it must keep (the clearance, and a margin where the
    travel bound leaves one out). A segment travelling less than ``min_travel`` (m) whose ends
    do not certify it fails, as does one reaching a failure found earlier once it travels less
    than ``settle``. ``failed``, ``bad``: what is already known (from the kernels); without
    ``last_valid`` the answer comes at the first failure, ``(True, 0.0)``.
    """
    queue = deque(sorted(segments, key=lambda segment: segment[1] - segment[2]))  # widest first
    while queue:
        pair, t0, t1, d0, d1 = queue.popleft()
        if t0 >= bad:
            continue
        travel = speed(pair) * (t1 - t0)
        need = travel + 2.0 * allowance(pair)
        for t in (t0, t1) if d0 <= d1 else (t1, t0):  # the smaller bound first
            if d0 + d1 > need:
                break
            # both are lower bounds; an exact -inf (contact) is a fact
            if t == t0:
                d0 = sharper(d0, distance(pair, t))
            else:
                d1 = sharper(d1, distance(pair, t))
        if d0 + d1 > need:
            continue
        for t, d in ((t0, d0), (t1, d1)):
            if d <= allowance(pair):  # (exact: the sharpening reached it)
                failed = True
                if not last_valid:
                    return True, 0.0
                bad = min(bad, t)
        if travel < min_travel or t0 >= bad or (failed and t1 >= bad and travel < settle):
            failed = True
            if not last_valid:
                return True, 0.0
            bad = min(bad, t0)
            continue
        middle = 0.5 * (t0 + t1)
        dm = distance(pair, middle)
        queue.append((pair, t0, middle, d0, dm))
        queue.append((pair, middle, t1, dm, d1))
    return failed, bad
