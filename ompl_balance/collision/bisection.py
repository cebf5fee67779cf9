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

Before that, where only a yes or no is wanted, the certifiers look for a contact at the
segments' midpoints with FCL's collision test, cheaper than a distance. A refused motion
often leaves a hundred or more short segments of one pair along it, and its contact
covers a stretch of them somewhere: :func:`probe_order` tests them coarse to fine along the
motion (its middle, its quarters, ...), which meets a stretch covering a fraction ``f`` of
them after about ``1 / f`` tests instead of after every segment before it.

The FCL queries are the expensive part, and near a grazing contact a motion needs about
``travel / distance`` of them: the callers' ``distance`` and ``touching`` spend from the motion
check's :class:`~ompl_balance.collision.budget.WorkBudget` before each query, and
:func:`bisect_segments` refuses the motion when it runs out (:mod:`ompl_balance.collision.budget`).
"""

from __future__ import annotations

import functools
from collections import deque
from collections.abc import Callable, Iterable

import numpy as np

from .budget import OverBudgetError

#: ``(pair, t0, t1, d0, d1)``: a collision pair over ``[t0, t1]`` with distance lower bounds at its ends.
Segment = tuple[int, float, float, float, float]


def probe_order(middles: np.ndarray) -> np.ndarray:
    """Indices of the segments whose midpoints are ``middles`` (n,), in the order to test them
    for a contact: sorted along the motion, then taken coarse to fine, the segment at the
    motion's middle rank first, then those at a quarter and three quarters, and so on (the
    van der Corput sequence), so that every stretch of the motion is reached early."""
    along = np.argsort(middles, kind="stable")
    if len(middles) == 0:
        return along
    bits = (len(middles) - 1).bit_length()
    # 1/2, 1/4, 3/4, 1/8, ... then 0, in units of 2**-bits, as ranks among the n segments
    # (a step of n / 2**bits <= 1 rank, so every rank comes up; each is kept where it first does)
    ranks = (np.roll(_bit_reversed(bits), -1) * len(middles)) >> bits
    _, first = np.unique(ranks, return_index=True)
    return along[ranks[np.sort(first)]]


@functools.lru_cache(maxsize=32)
def _bit_reversed(bits: int) -> np.ndarray:
    """``0 .. 2**bits - 1``, each with its ``bits`` binary digits reversed."""
    ranks = np.zeros(1, dtype=np.int64)
    for _ in range(bits):
        ranks = np.concatenate((2 * ranks, 2 * ranks + 1))
    return ranks


def contact_at_middles(middles: np.ndarray, touching: Callable[[int, float], bool]) -> bool:
    """Whether ``touching(i, middles[i])`` finds a contact at the midpoint of one of the segments
    (midpoints ``middles`` (n,)), tested in :func:`probe_order` and stopping at the first."""
    return any(touching(i, float(middles[i])) for i in probe_order(middles).tolist())


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

    When ``distance`` raises :class:`~ompl_balance.collision.budget.OverBudgetError` (the motion
    check's work budget ran out) the motion is refused: ``(True, 0.0)`` without ``last_valid``,
    else ``bad`` moved back to the start of the first segment still unproved.
    """
    queue = deque(sorted(segments, key=lambda segment: segment[1] - segment[2]))  # widest first
    t0 = 1.0  # (the segment being worked on when the budget runs out)
    try:
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
    except OverBudgetError:
        if not last_valid:
            return True, 0.0
        return True, min([bad, t0, *(segment[1] for segment in queue)])
    return failed, bad
