"""The work budget of one certified motion check.

Conservative advancement proves a motion free by cutting it into segments until every pair's
distance bounds at a segment's ends exceed what the pair can travel along it. Near a grazing
contact that takes about ``travel / distance`` segments: a link sliding past an obstacle at a
fraction of a millimetre over tens of centimetres of travel needs hundreds of exact FCL
distances on a non-convex mesh, and one such check can take a second. OMPL's path simplifier
asks for many long motions between far-apart path states, whatever its time limit, so it can
only keep that limit if every motion check costs a bounded amount.

So every certified motion check has a *budget* of work, counted, not timed (a run repeats
exactly from its seed):

* one unit for each configuration placed (forward kinematics or a rigid body's pose) and for
  each distance bound computed on convex hulls (GJK), in compiled code (a few microseconds);
* :data:`FCL_QUERY_WORK` units for each FCL query, a collision test or an exact distance, made
  in Python on a pair with a non-convex mesh (a hundred microseconds and more each).

A check whose proof would need more than its budget stops before the unit that would exceed
it and refuses the motion: it is *not certified* (sound: never "free" for a motion with a
colliding configuration), and it counts in the checker's ``motions_over_budget``. With
``last_valid`` the certified fraction is then the start of the first stretch left unproved.
The two configurations at a motion's ends count as work like any other; bounds and distances
remembered from earlier motions cost nothing, so near its budget a motion's answer can depend on
the motions checked before it (as every answer does on the seed: a run still repeats). (Rigid
bodies among meshes probe at most
:data:`~ompl_balance.collision.rigid.kernels.MAX_PROBES` states before the proof; those are
bounded apart from the budget.)
"""

from __future__ import annotations

import numbers

#: Work units of one FCL query (collision test or exact distance) against the one unit of a
#: configuration placed or a distance bound on convex hulls: on the MotionBenchMaker Panda
#: problems a unit of the compiled advancement takes about 2 us and an FCL query on the Panda's
#: non-convex ``link6`` a median of 130 us (up to about 1 ms right next to a contact).
FCL_QUERY_WORK = 64
#: The default budget of one motion check, in work units: about 4 ms of compiled advancement,
#: or 32 FCL queries. While planning on the shipped Panda problems it refuses about 1 in 2,000
#: of the motions stock RRT-Connect checks (docs/robots.md), on the rigid-body problems about
#: 1 in 500,000 (docs/rigid.md).
MOTION_BUDGET = 2048
#: The budget the kernels take for "no limit" (``motion_budget=None``): more work than any check
#: can do, with room to add to it without overflowing an int64.
UNLIMITED = 2**62


def budget_units(motion_budget: object) -> int:
    """``motion_budget`` as the kernels take it: a whole number of work units >= 1 itself,
    ``None`` (no limit) as :data:`UNLIMITED`; ``ValueError`` for anything else."""
    if motion_budget is None:
        return UNLIMITED
    if isinstance(motion_budget, bool) or not isinstance(motion_budget, numbers.Integral) or motion_budget < 1:
        raise ValueError(
            f"motion_budget must be a whole number of work units >= 1 (default {MOTION_BUDGET}) or None for no "
            f"limit, got {motion_budget!r}"
        )
    return min(int(motion_budget), UNLIMITED)


class OverBudgetError(Exception):
    """Raised by :meth:`WorkBudget.spend` when a motion check's budget runs out."""


class WorkBudget:
    """The work units left to one motion check on the Python side (FCL queries).

    :meth:`spend` before each query: it raises :class:`OverBudgetError` instead of spending past
    the budget, and :attr:`exhausted` then tells the caller the motion was refused for it.
    """

    def __init__(self, left: int) -> None:
        self.left = max(0, int(left))
        self.spent = 0
        self.exhausted = False

    def spend(self, units: int | None = None) -> None:
        """Take ``units`` (default one FCL query, :data:`FCL_QUERY_WORK`) from the budget, or raise
        :class:`OverBudgetError`."""
        if units is None:
            units = FCL_QUERY_WORK
        if units > self.left:
            self.exhausted = True
            raise OverBudgetError
        self.left -= units
        self.spent += units
