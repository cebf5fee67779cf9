"""Certified collision-free motions of a robot along straight joint-space edges.

What is certified
-----------------
For an edge ``q(t) = a + t (b - a)``, ``t in [0, 1]``, with ``a`` and ``b`` inside the
robot's joint bounds, :class:`MotionCertifier` proves that at every ``t`` every collision
pair of a :class:`~ompl_balance.collision.checker.CollisionChecker`'s model is more than
``clearance`` metres apart, or rejects the edge. The pairs are the checker's: each link
collision geometry against each environment obstacle, and the enabled self-collision
geometry pairs (:attr:`~ompl_balance.collision.kinematics.RobotModel.self_collision_pairs`).
Distances are FCL's, with two conservative changes: a mesh that is (nearly) convex counts
as its solid convex hull, and every exact distance is taken less
:data:`~ompl_balance.collision.advancement.DISTANCE_TOLERANCE` (10 micrometres), so a pair
that close to the clearance counts as in contact. The certificate never accepts an edge
with a configuration FCL finds in collision. It is about the model and the straight line
only: not the robot's visual geometry, not pairs the SRDF disables, not obstacles that
move, not a controller's tracking error.

Method
------
Conservative advancement (Schwarzer, Saha and Latombe, "Adaptive dynamic collision
checking for single and multiple articulated robots in complex environments", IEEE T-RO
21(3), 2005) with three ingredients, each in a module of its own:

* a **travel bound** (:mod:`ompl_balance.collision.travel`). Along the edge a point ``p``
  of a link moves with velocity ``sum_k v_k' w_k(p)``: joint ``k`` upstream of the link
  changes its value at rate ``v_k'``, and ``w_k(p)`` is ``axis_k x (p - o_k)`` (``o_k`` on
  the axis) for a revolute joint, ``axis_k`` for a prismatic one. So ``|dp/dt| <=
  sum_k |v_k'| r_k`` where ``r_k`` bounds the distance of ``p`` from joint ``k``'s axis
  in *every* configuration (1 for a prismatic joint), and over ``[t0, t1]`` no point
  travels farther than ``(t1 - t0) sum_j |b_j - a_j| W[g, j]``, with ``W[g, j]`` the sum of
  ``|m_k| r_k`` over the joints ``k`` of geometry ``g``'s chain driven by active joint
  ``j`` (a mimic joint ``v_k = m_k q_j + c_k``). ``r_k`` is the largest distance of the
  geometry from the axis when it hangs off joint ``k``'s own body, and otherwise the
  component across the axis of the first link offset below the joint, plus the lengths
  of the further offsets (prismatic ones at the end of their range), plus the geometry's
  radius about its body frame origin. A self pair counts the joints below the two
  geometries' lowest common ancestor body only, both geometries' weights summed: the
  joints above move both rigidly and leave their distance alone;
* **distance lower bounds** at a configuration (:mod:`ompl_balance.collision.convex`):
  bounding spheres first (a link geometry's sphere against an obstacle's box or sphere,
  two links' spheres), then GJK on the convex parts (a mesh's convex hull, which contains
  the mesh), whose separating-plane value ``v . w / |v|`` is a lower bound at every
  iteration, and last FCL's exact distance;
* **advancement** (:mod:`ompl_balance.collision.advancement`): with lower bounds ``d0``,
  ``d1`` at ``t0``, ``t1`` and travel bound ``V`` per unit ``t``, a pair stays
  ``max(d0 - V (t - t0), d1 - V (t1 - t)) >= (d0 + d1 - V (t1 - t0)) / 2`` apart on the
  segment, so it is certified there when ``d0 + d1 - 2 clearance > V (t1 - t0)``;
  otherwise the segment is halved and the midpoint bounded. Pairs are independent, so a
  pair far from contact needs a bound or two for the whole edge while a close one is cut
  finely, and configurations at the ends of an edge keep their bounds for the next edge.

A pair whose convex parts are its FCL model (primitives, convex meshes) is decided by
GJK: an upper bound within the tolerance of the clearance is a contact. Pairs with a
non-convex mesh (whose hull may touch where the mesh does not) are finished with FCL
(:meth:`MotionCertifier._exact_phase`): when a segment of theirs with at most ``handover``
metres of travel is still uncertified, a collision test at its midpoint, then FCL's exact
distances, halving again. Self pairs with a certified-free table are certified wherever
their straight line in the table's two joint values crosses free cells.

Termination: a segment with a travel bound under :data:`MIN_TRAVEL` metres that is still
not certified makes the edge uncertified, and contacts are decided with the tolerance
above, so grazing edges end (rejected) after a bounded number of halvings.

Cost: near a grazing contact the proof needs about ``travel / distance`` segments (hundreds of
FCL distances for a link sliding past an obstacle a fraction of a millimetre away), so every
check has a work budget (``motion_budget``, :mod:`ompl_balance.collision.budget`): a proof that
would exceed it stops and the edge is not certified, counted in the checker's
``motions_over_budget``.

A motion that lies on an edge certified lately is certified by that edge's proof, whether or not
its own proof would fit the budget (:mod:`~ompl_balance.collision.certified_lines`): OMPL's path
simplifier cuts a path's edges into pieces and checks them again, and a refused piece of a free
edge makes it put random states into the path.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..core.checks import ExitTarget, raise_kept
from ..core.compiled_calls import entry_point
from .advancement import (
    DISTANCE_TOLERANCE,
    MIN_TRAVEL,
    EdgeModel,
    EdgeScratch,
    Model,
    advance,
    end_memory,
    hull_bounds,
    memory_row,
    sphere_bounds,
)
from .bisection import bisect_segments, contact_at_middles
from .budget import MOTION_BUDGET, UNLIMITED, OverBudgetError, WorkBudget, budget_units
from .certified_lines import LINES_REMEMBERED, along_certified, certified_lines, remember_certified
from .checker import CollisionChecker
from .convex import convex_part, pack_parts
from .kernels import (
    EXIT_NO,
    EXIT_OVER_BUDGET,
    EXIT_YES,
    CertifiedMotions,
    Exit,
    Staged,
    certified_edge_free,
    segment_exits,
)
from .travel import travel_weights

#: Travel (m) to which ``check(..., last_valid=True)`` refines the edge around its first
#: failure before it reports the last certified fraction.
LAST_VALID_TRAVEL = 1e-3


class MotionCertifier(ExitTarget):
    """Proves straight joint-space edges free of collision for a checker's model, or rejects them.

    Parameters
    ----------
    checker:
        The collision model: its robot, environment and self-collision pairs. With
        ``checker.prefilter`` false, every pair is bisected with FCL distances only (no
        spheres, hulls or tables): slow; the reference.
    clearance:
        Metres: pairs closer than this count as in contact (0: touching is contact).
    handover:
        Travel (m) of a segment below which pairs with a non-convex mesh go to FCL.
    remembered:
        How many edge end configurations keep their bounds (planners extend from the
        same states again and again).
    motion_budget:
        The most work one check may do, in work units (:mod:`ompl_balance.collision.budget`:
        one per configuration placed or GJK bound,
        :data:`~ompl_balance.collision.budget.FCL_QUERY_WORK` per FCL query); an edge whose
        proof would need more is not certified. ``None``: no limit.

    See the module docstring for what is certified and how.
    """

    def __init__(
        self,
        checker: CollisionChecker,
        clearance: float = 0.0,
        handover: float = 0.01,
        remembered: int = 512,
        motion_budget: int | None = MOTION_BUDGET,
    ):
        if not (math.isfinite(clearance) and clearance >= 0.0):
            raise ValueError(f"clearance must be a finite number of metres >= 0, got {clearance}")
        if not (math.isfinite(handover) and handover > 0.0):
            raise ValueError(f"handover must be a positive number of metres, got {handover}")
        self._budget = budget_units(motion_budget)
        self.motion_budget = motion_budget
        self.checker = checker
        self.clearance = float(clearance)
        self.handover = float(handover)
        self.remembered = remembered
        self._robot = robot = checker.robot
        self._geometries = len(robot.geometries)
        self._obstacles = len(checker.environment.obstacles)
        self.pair_count = checker.pair_count
        self._model = self._build_model()
        self._identity = np.eye(4).reshape(1, 4, 4)
        self._edge = EdgeModel(
            robot.chain, checker.volumes, self._model, self.clearance, self.handover, MIN_TRAVEL, self._budget
        )
        capacity = 4 * self.pair_count + 16  # hard segments before the arrays grow
        self._scratch = EdgeScratch(
            np.zeros((self.pair_count, 3)),
            np.empty((4, 3)),
            np.empty(self.pair_count),
            np.empty(capacity, dtype=np.int64),
            np.empty((capacity, 4)),
        )
        self._memory = end_memory(max(2, remembered), robot.dof, self.pair_count)
        # FCL distances at remembered rows (pair -> distance), valid for the row's generation
        self._exact: list[tuple[int, dict[int, float]]] = [(-1, {}) for _ in range(len(self._memory.used))]
        # the compiled kernels are called without numba's type dispatch (several microseconds
        # of an edge's few tens): the argument types are fixed here
        lower = np.ascontiguousarray(robot.lower, dtype=float)
        self._lines = certified_lines(LINES_REMEMBERED, robot.dof)
        self._view = CertifiedMotions(
            checker.kernel_view(),
            self._edge,
            self._memory,
            self._lines,
            self._scratch,
            segment_exits(self, robot.dof, capacity),
            checker.counter.array,
        )
        # the parts of a query about more segments than the exit stages at once (see answer)
        self._staged: list[tuple[np.ndarray, np.ndarray]] = []
        self._row = entry_point(memory_row, (self._memory, lower))
        self._advance = entry_point(
            advance,
            (lower, lower, self._edge, self._memory.bounds, 0, 1, MIN_TRAVEL, True, False, self._scratch, self._budget),
        )
        self._edge_free = entry_point(
            certified_edge_free,
            (
                self._edge,
                self._memory,
                self._lines,
                self._scratch,
                checker.counter.array,
                self._view.exits,
                lower,
                lower,
            ),
        )
        self._remember = entry_point(remember_certified, (self._lines, lower, lower))
        self._along = entry_point(along_certified, (self._lines, lower, lower))

    def _build_model(self) -> Model:
        robot, obstacles = self._robot, self.checker.environment.obstacles
        environment_weight, self_weight = travel_weights(robot)
        shapes = [(g.shape, g.origin) for g in robot.geometries] + [(o.shape, o.pose) for o in obstacles]
        parts = pack_parts([convex_part(s.kind, s.dims, s.hull_vertices(), pose) for s, pose in shapes])
        around = []
        for obstacle in obstacles:
            centre, radius = obstacle.shape.bounding_spheres(1)
            around.append((obstacle.pose[:3, :3] @ centre[0] + obstacle.pose[:3, 3], radius[0]))
        convex = [s.convex for s, _ in shapes]
        solid = np.array(
            [
                convex[g] and convex[self._geometries + o]
                for o in range(self._obstacles)
                for g in range(self._geometries)
            ]
            + [convex[a] and convex[b] for a, b in robot.self_collision_pairs],
            dtype=bool,
        )
        fixed = np.full(self.pair_count, np.nan)
        still = ~environment_weight.any(axis=1)  # geometries no joint moves
        if still.any():
            poses = robot.body_poses(np.zeros(robot.dof))[0]
            for o in range(self._obstacles):
                for g in np.flatnonzero(still):
                    fixed[o * self._geometries + g] = max(self._distance(o * self._geometries + g, poses), -1.0)
        return Model(
            parts=parts,
            obstacle_centre=np.array([c for c, _ in around], dtype=float).reshape(-1, 3),
            obstacle_radius=np.array([r for _, r in around], dtype=float),
            environment_weight=environment_weight,
            self_weight=self_weight.reshape(-1, robot.dof),
            fixed=fixed,
            solid=solid,
            joint_lower=np.ascontiguousarray(robot.lower, dtype=float),
            joint_upper=np.ascontiguousarray(robot.upper, dtype=float),
        )

    # ------------------------------------------------------------------ public API

    def check(self, a: np.ndarray, b: np.ndarray, last_valid: bool = False) -> tuple[bool, float]:
        """Whether the edge ``a -> b`` (dof,) is certified, and the fraction of it certified.

        Counts one motion, the configurations evaluated and the distance queries in the
        checker's counter. Non-finite or out-of-bounds ends: not certified, fraction 0.
        Without ``last_valid`` the work stops at the first failure and a rejected edge
        reports fraction 0 (the compiled engine's kernel, :func:`~ompl_balance.collision.kernels.certified_edge_free`).
        With ``last_valid`` the edge is refined around its first failure to
        :data:`LAST_VALID_TRAVEL` of travel, and ``a + s (b - a)`` is certified for every ``s``
        up to the fraction returned. A check whose proof would exceed :attr:`motion_budget`
        stops there: not certified (with ``last_valid``, certified up to the first stretch left
        unproved), counted in the checker's ``motions_over_budget``. An edge whose proof fails but
        that lies on an edge certified lately is certified by that edge
        (:mod:`~ompl_balance.collision.certified_lines`); every certified edge is kept for that.
        """
        a = np.ascontiguousarray(a, dtype=float)
        b = np.ascontiguousarray(b, dtype=float)
        counter = self.checker.counter
        if a.shape != (self._robot.dof,) or b.shape != a.shape:
            counter.motions_checked += 1
            return False, 0.0
        if self.checker.prefilter and not last_valid:
            view = self._view
            free = bool(
                self._edge_free(view.edge, view.memory, view.lines, view.scratch, view.counts, view.exits, a, b)
            )
            raise_kept(view.counts, self)
            return free, 1.0 if free else 0.0
        counter.motions_checked += 1
        free, fraction, over_budget = self._prove(a, b, last_valid)
        if free:
            self._remember(self._lines, a, b)
            return True, 1.0
        if self._along(self._lines, a, b):
            return True, 1.0
        if over_budget:
            counter.motions_over_budget += 1
        return False, fraction if last_valid else 0.0

    def _prove(self, a: np.ndarray, b: np.ndarray, last_valid: bool) -> tuple[bool, float, bool]:
        """The proof of ``a -> b`` in Python's hands (``last_valid``, or no prefilter): whether it
        certifies the edge, the fraction certified from ``a``, and whether the budget ran out."""
        counter = self.checker.counter
        start, end = self._row(self._memory, a), self._row(self._memory, b)
        settle = max(MIN_TRAVEL, LAST_VALID_TRAVEL) if last_valid else MIN_TRAVEL
        budget = WorkBudget(self._budget)
        if self.checker.prefilter:
            failed, bad, hard, evaluated, bounded, hard_pair, hard_span, exhausted = self._advance(
                a, b, self._edge, self._memory.bounds, start, end, settle, False, False, self._scratch, self._budget
            )
            counter.states_checked += evaluated
            counter.distance_queries += bounded
            budget = WorkBudget(self._budget - evaluated - bounded)  # (what the FCL phase may spend)
            if exhausted:  # (the hard segments' starts are in bad: they are not finished)
                return False, bad, True
            if failed and bad == 0.0:
                return False, 0.0, False
            if hard == 0:
                return (False, bad, False) if failed else (True, 1.0, False)
            pairs, spans = hard_pair[:hard], hard_span[:hard]
        else:  # the reference: every pair over the whole edge with FCL only
            inside = self._robot.within_limits(np.stack([a, b]))
            if not inside.all():
                return False, 0.0, False
            delta = np.abs(b - a)
            per_geometry = self._model.environment_weight @ delta
            self._scratch.speed[:] = np.concatenate(
                [np.tile(per_geometry, self._obstacles), self._model.self_weight @ delta]
            )
            failed, bad = False, 1.0
            pairs = np.arange(self.pair_count)
            spans = np.tile([0.0, 1.0, -np.inf, -np.inf], (self.pair_count, 1))
        failed, bad = self._exact_phase(a, b, pairs, spans, start, end, settle, last_valid, failed, bad, budget)
        return (False, bad, budget.exhausted) if failed else (True, 1.0, budget.exhausted)

    def compiled_view(self) -> CertifiedMotions:
        """The certifier as compiled code sees it (:class:`~ompl_balance.collision.kernels.CertifiedMotions`)."""
        return self._view

    def answer(self, kind: int, count: int) -> int:
        """The exit's answer (:class:`~ompl_balance.collision.kernels.Exit`) about the segments the
        kernel staged in :attr:`~ompl_balance.collision.kernels.CertifiedMotions.exits` (the first
        ``count`` rows; those of earlier ``STAGE_SEGMENTS`` queries before them):
        :meth:`hard_segments_free` or :meth:`hard_segments_touch` as ``EXIT_YES``, ``EXIT_NO`` or
        ``EXIT_OVER_BUDGET``, the work units spent written back."""
        exits = self._view.exits
        pairs, spans = exits.pairs[:count].copy(), exits.spans[:count].copy()
        if kind == Exit.STAGE_SEGMENTS:
            self._staged.append((pairs, spans))
            return 0
        if self._staged:  # (the query's own parts are the last ``total`` rows)
            total = int(exits.numbers[Staged.SEGMENTS])
            pairs = np.concatenate([part for part, _ in self._staged] + [pairs])[-total:]
            spans = np.concatenate([part for _, part in self._staged] + [spans])[-total:]
            self._staged.clear()
        a, b = exits.ends[0].copy(), exits.ends[1].copy()
        budget = WorkBudget(int(exits.numbers[Staged.WORK_LEFT]))
        try:
            if kind == Exit.SEGMENTS_FREE:
                start, end = int(exits.numbers[Staged.START_ROW]), int(exits.numbers[Staged.END_ROW])
                free = self.hard_segments_free(a, b, pairs, spans, start, end, budget)
                return EXIT_YES if free else EXIT_OVER_BUDGET if budget.exhausted else EXIT_NO
            if kind == Exit.SEGMENTS_TOUCH:
                return EXIT_YES if self.hard_segments_touch(a, b, pairs, spans, budget) else EXIT_NO
        except OverBudgetError:
            return EXIT_OVER_BUDGET
        finally:
            exits.numbers[Staged.WORK_SPENT] = budget.spent
        raise ValueError(f"a motion certifier answers the segment queries of Exit, not query {kind}")

    def hard_segments_free(
        self,
        a: np.ndarray,
        b: np.ndarray,
        pairs: np.ndarray,
        spans: np.ndarray,
        start: int,
        end: int,
        budget: WorkBudget | None = None,
    ) -> bool:
        """Whether FCL certifies the hard segments ``(pair, (t0, t1, d0, d1))`` that the compiled
        phase of the edge ``a -> b`` left (rows ``start``, ``end`` of the end memory); the compiled
        kernel's exit. Spends from ``budget`` (``None``: no limit); not certified when it runs out
        (``budget.exhausted``)."""
        budget = budget or WorkBudget(UNLIMITED)
        failed, _ = self._exact_phase(a, b, pairs, spans, start, end, MIN_TRAVEL, False, False, 1.0, budget)
        return not failed

    def hard_segments_touch(
        self, a: np.ndarray, b: np.ndarray, pairs: np.ndarray, spans: np.ndarray, budget: WorkBudget | None = None
    ) -> bool:
        """Whether FCL finds a contact in the hard segments ``(pair, (t0, t1, d0, d1))`` of the edge
        ``a -> b``: a collision test at each end whose bound is within the clearance (where the
        pair's convex parts touch), then at each middle; the compiled kernel's exit before it
        certifies the rest of the edge. Spends from ``budget`` (``None``: no limit) and raises
        :class:`~ompl_balance.collision.budget.OverBudgetError` when it runs out."""
        budget = budget or WorkBudget(UNLIMITED)
        poses = self._poses_along(a, b, budget)
        for pair, (t0, t1, d0, d1) in zip(pairs.tolist(), spans.tolist()):
            for t, bound in ((t0, d0), (t1, d1), (0.5 * (t0 + t1), -np.inf)):
                if bound <= self.clearance and self._touching(pair, poses(t), budget):
                    return True
        return False

    def closest(self, q: np.ndarray) -> float:
        """The smallest FCL distance (m) between the collision pairs at configuration ``q`` (dof,).

        At most 0 in contact. Pairs whose lower bound exceeds the best so far are skipped.
        """
        q = np.ascontiguousarray(q, dtype=float)
        poses = self._robot.body_poses(q)[0]
        warm, simplex = np.zeros((self.pair_count, 3)), self._scratch.simplex
        volumes = self.checker.volumes
        pairs = np.arange(self.pair_count)
        lower = np.empty(self.pair_count)
        sphere_bounds(poses, volumes, self._model, pairs, lower)
        for pair in range(self.pair_count):
            lower[pair] = max(
                lower[pair], hull_bounds(pair, poses, volumes, self._model, warm, self._identity, simplex, 0.0)[0]
            )
        best = np.inf
        for pair in np.argsort(lower):
            if lower[pair] >= best:
                break
            best = min(best, self._distance(pair, poses) + DISTANCE_TOLERANCE)
            if best <= 0.0:
                return 0.0
        return float(best)

    # ------------------------------------------------------------------ internals

    def _touching(self, pair: int, poses: np.ndarray, budget: WorkBudget | None = None) -> bool:
        """FCL's collision test of ``pair`` at body ``poses``, spent from ``budget`` if given."""
        if budget is not None:
            budget.spend()
        return self.checker.pair_touching(pair, poses)

    def _distance(self, pair: int, poses: np.ndarray, budget: WorkBudget | None = None) -> float:
        """FCL's distance of ``pair`` at body ``poses`` less the tolerance; ``-inf`` in contact.
        Both FCL queries (a collision test, then the distance) are spent from ``budget`` if given."""
        if self._touching(pair, poses, budget):
            return -np.inf
        if budget is not None:
            budget.spend()
        return self.checker.pair_distance(pair, poses) - DISTANCE_TOLERANCE

    def _poses_along(self, a: np.ndarray, b: np.ndarray, budget: WorkBudget) -> Callable[[float], np.ndarray]:
        """The body poses at fraction ``t`` of the edge ``a -> b``: ``poses(t)``, each worked out
        (counted as a state checked, and one unit of ``budget``) once."""
        delta, poses_at = b - a, {}

        def poses(t: float) -> np.ndarray:
            if t not in poses_at:
                budget.spend(1)
                poses_at[t] = self._robot.body_poses(a + t * delta)[0]
                self.checker.counter.states_checked += 1
            return poses_at[t]

        return poses

    def _known(self, row: int) -> dict[int, float]:
        """The FCL distances remembered at end-memory ``row`` (forgotten when the row is reused)."""
        generation = int(self._memory.generation[row])
        if self._exact[row][0] != generation:
            self._exact[row] = (generation, {})
        return self._exact[row][1]

    def _exact_phase(
        self,
        a: np.ndarray,
        b: np.ndarray,
        pairs: np.ndarray,
        spans: np.ndarray,
        start: int,
        end: int,
        settle: float,
        last_valid: bool,
        failed: bool,
        bad: float,
        budget: WorkBudget,
    ) -> tuple[bool, float]:
        """Certify the hard segments (pair, (t0, t1, d0, d1)) with FCL.

        ``failed`` and ``bad``: what the compiled phase found (the edge certified on
        ``[0, bad]`` but for the hard segments). Returns them updated; without
        ``last_valid`` it returns at the first failure. Segments reaching a failure are
        refined to ``settle`` metres of travel only. Every configuration placed and FCL query
        is spent from ``budget``; when it runs out the edge fails (``budget.exhausted``), with
        ``last_valid`` certified up to the first segment left unproved.
        """
        clearance, speed, poses = self.clearance, self._scratch.speed, self._poses_along(a, b, budget)
        exact: dict[tuple[int, float], float] = {}

        def distance(pair: int, t: float) -> float:
            known = self._known(start) if t == 0.0 else self._known(end) if t == 1.0 else None
            if known is not None and pair in known:
                return known[pair]
            if (pair, t) not in exact:
                exact[pair, t] = self._distance(pair, poses(t), budget)
                if known is not None:
                    known[pair] = exact[pair, t]
            return exact[pair, t]

        # contacts first: an FCL collision test costs less than a distance
        try:
            if not last_valid and contact_at_middles(
                0.5 * (spans[:, 0] + spans[:, 1]), lambda i, t: self._touching(int(pairs[i]), poses(t), budget)
            ):
                return True, 0.0
        except OverBudgetError:
            return True, 0.0
        segments = [(pair, t0, t1, d0, d1) for pair, (t0, t1, d0, d1) in zip(pairs.tolist(), spans.tolist())]
        return bisect_segments(
            segments,
            distance,
            lambda pair: speed[pair],
            lambda pair: clearance,
            MIN_TRAVEL,
            settle,
            last_valid,
            failed,
            bad,
        )


@dataclass(frozen=True)
class PathCertificate:
    """The answer of :func:`certify_states` (and :func:`ompl_balance.validity.certify_path`).

    ``certified``: every segment is certified free with ``clearance`` (m) to spare.
    ``segments``: how many segments the path has. ``first_bad_segment``: index ``i`` of the
    first segment ``states[i] -> states[i + 1]`` not certified (``None`` if all are), and
    ``certified_fraction`` how much of it is certified from ``states[i]`` on (1 if all are).
    ``smallest_clearance``: the smallest FCL distance (m) between any collision pair at the
    path's states (at most 0: a state in contact); the path's true smallest clearance is at
    most this, and more than ``clearance`` when ``certified``.
    """

    certified: bool
    segments: int
    first_bad_segment: int | None
    certified_fraction: float
    smallest_clearance: float
    clearance: float


def certify_states(
    checker: CollisionChecker, states: np.ndarray, clearance: float = 0.0, motion_budget: int | None = MOTION_BUDGET
) -> PathCertificate:
    """Certify the straight joint-space segments between consecutive ``states`` (n, dof), each
    within ``motion_budget`` (see :class:`MotionCertifier`: a segment whose proof would exceed it
    is not certified).

    Raises ``ValueError`` for a wrong shape or non-finite values; a state outside the joint
    bounds leaves its segments uncertified.
    """
    states = checker.robot.as_array(states)
    if len(states) == 0:
        raise ValueError("a path needs at least one state")
    certifier = MotionCertifier(checker, clearance, motion_budget=motion_budget)
    first_bad, fraction = None, 1.0
    for i in range(len(states) - 1):
        ok, fraction = certifier.check(states[i], states[i + 1], last_valid=True)
        if not ok:
            first_bad = i
            break
    inside = checker.robot.within_limits(states).tolist()
    smallest = min(certifier.closest(q) if ok else -np.inf for q, ok in zip(states, inside))
    certified = first_bad is None and all(inside) and smallest > clearance + DISTANCE_TOLERANCE
    return PathCertificate(
        certified=certified,
        segments=len(states) - 1,
        first_bad_segment=first_bad,
        certified_fraction=fraction if first_bad is not None else 1.0,
        smallest_clearance=smallest,
        clearance=clearance,
    )
