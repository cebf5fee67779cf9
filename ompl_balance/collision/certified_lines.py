"""The motions a certifier proved free lately, so that a piece of one stays certified.

OMPL's path simplifier cuts a path's edges into pieces (``PathGeometric::subdivide`` in the
B-spline smoothing, the ends of ``partialShortcutPath``'s shortcuts) and asks for the pieces
again later (``checkAndRepair``). A piece of a certified edge is free, but its own proof starts
from new end configurations and may need more work than the motion budget allows: it would be
refused. ``checkAndRepair`` then overwrites path states with random samples and, when no sample
fits, returns the path with them in it, through obstacles. So before a certifier refuses a
motion it looks here: a motion with both ends on a certified edge lies on that edge, and that
edge's proof covers it.

"On the edge" allows :data:`ALONG_TOLERANCE` radians (or metres, for a prismatic joint) of
rounding: OMPL's interpolation ``a + t (b - a)`` is exact to about 1e-15. A configuration that
far off a certified edge moves no link point farther than the tolerance times the robot's
travel weights (:mod:`ompl_balance.collision.travel`, metres per radian, about 1 for an arm):
picometres, far below the precision of the distances a proof rests on (GJK's and FCL's are
iterative, to about a micrometre, and every exact distance is taken short by
:data:`~ompl_balance.collision.advancement.DISTANCE_TOLERANCE`, 10 micrometres).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..core.kernel_cache import njit_borrowing

#: How far (radians, or metres for a prismatic joint) a motion's end may lie off a certified
#: edge for the motion to count as a piece of it: rounding of OMPL's interpolation, no more.
ALONG_TOLERANCE = 1e-12
#: The certified edges a certifier keeps: the planner's solution path and the simplifier's
#: recent shortcuts are among them (the trees of the shipped Panda problems have tens to
#: hundreds of edges). A refused motion is compared with each (a few microseconds for 2,048).
LINES_REMEMBERED = 2048


class CertifiedLines(NamedTuple):
    """The last certified edges ``a -> b``, oldest overwritten first: ``starts`` (n, dof) the
    ``a``, ``directions`` (n, dof) the unit vectors ``(b - a) / |b - a|``, ``lengths`` (n,) the
    ``|b - a|``, ``axes`` (n,) the joint that moves most along each, ``next`` (1,) the row written
    next, ``filled`` (1,) how many rows hold an edge."""

    starts: np.ndarray
    directions: np.ndarray
    lengths: np.ndarray
    axes: np.ndarray
    next: np.ndarray
    filled: np.ndarray


def certified_lines(capacity: int, dof: int) -> CertifiedLines:
    """Room for ``capacity`` certified edges of ``dof`` joints, none kept yet."""
    return CertifiedLines(
        np.zeros((capacity, dof)),
        np.zeros((capacity, dof)),
        np.zeros(capacity),
        np.zeros(capacity, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
    )


@njit_borrowing
def _distance(a: np.ndarray, b: np.ndarray) -> float:  # pragma: no cover (compiled)
    """The Euclidean distance of ``a`` and ``b`` (dof,) in joint space."""
    squares = 0.0
    for j in range(a.shape[0]):
        squares += (b[j] - a[j]) ** 2
    return float(np.sqrt(squares))


@njit_borrowing
def remember_certified(lines: CertifiedLines, a: np.ndarray, b: np.ndarray) -> None:  # pragma: no cover (compiled)
    """Keep the certified edge ``a -> b`` (dof,), in place of the oldest when ``lines`` is full.
    An edge shorter than :data:`ALONG_TOLERANCE` has no direction to keep and is not kept."""
    length = _distance(a, b)
    if length <= ALONG_TOLERANCE:
        return
    row = lines.next[0]
    axis = 0
    for j in range(a.shape[0]):
        lines.starts[row, j] = a[j]
        lines.directions[row, j] = (b[j] - a[j]) / length
        if abs(b[j] - a[j]) > abs(b[axis] - a[axis]):
            axis = j
    lines.lengths[row] = length
    lines.axes[row] = axis
    lines.next[0] = (row + 1) % lines.lengths.shape[0]
    lines.filled[0] = min(lines.filled[0] + 1, lines.lengths.shape[0])


@njit_borrowing
def _on_line(lines: CertifiedLines, row: int, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether ``q`` (dof,) lies on the edge in ``row`` of ``lines`` (within :data:`ALONG_TOLERANCE`);
    never for a ``q`` with a non-finite value."""
    start, direction = lines.starts[row], lines.directions[row]
    along = 0.0
    for j in range(q.shape[0]):
        along += (q[j] - start[j]) * direction[j]
    # (every test written so that a NaN fails it: a non-finite q is on no edge)
    if not (-ALONG_TOLERANCE <= along <= lines.lengths[row] + ALONG_TOLERANCE):
        return False
    for j in range(q.shape[0]):  # noqa: SIM110 (a loop numba compiles)
        if not abs(q[j] - start[j] - along * direction[j]) <= ALONG_TOLERANCE:
            return False
    return True


@njit_borrowing
def along_certified(lines: CertifiedLines, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether the motion ``a -> b`` (dof,) lies on one edge kept in ``lines``: both its ends on
    the edge's segment, so the whole motion is (the segment is convex).

    An edge is passed over at the cost of a comparison when the joint it moves most is not one
    the motion moves most too (within 1e-6: a piece moves its joints in the same proportions, to
    rounding), and at the cost of a dot product when its direction is not the motion's (to 1e-6
    in the cosine): a few microseconds for 2,048 edges of a 7-joint arm.
    """
    length = _distance(a, b)
    most = 0.0
    for j in range(a.shape[0]):
        most = max(most, abs(b[j] - a[j]))
    for row in range(lines.filled[0]):
        if length > ALONG_TOLERANCE:  # (a motion of no length is a configuration on the edge)
            axis = lines.axes[row]
            if abs(b[axis] - a[axis]) < (1.0 - 1e-6) * most:
                continue
            cosine = 0.0
            for j in range(a.shape[0]):
                cosine += (b[j] - a[j]) * lines.directions[row, j]
            if abs(cosine) < (1.0 - 1e-6) * length:
                continue
        if _on_line(lines, row, a) and _on_line(lines, row, b):
            return True
    return False
