"""How the planners see a state space: sampling, distance, interpolation, conversion.

A planner works on "points" and asks this layer everything it needs to know about
them. Two implementations share one interface:

:class:`ArrayPoints`
    for the spaces with a flat layout (:mod:`ompl_balance.core.layout`: real-vector spaces,
    SO(2), SO(3), SE(2), SE(3) and compounds of them): points are numpy arrays of shape
    ``(dim,)``, sampled uniformly from a numpy generator, with OMPL's metric and
    interpolation computed on the arrays; trees are :class:`~ompl_balance.core.trees.ArrayTree`.
:class:`StatePoints`
    for every other OMPL space: points are OMPL states, and every question goes to OMPL
    (``si.distance``, ``space.interpolate``, the space's default sampler); trees are
    :class:`~ompl_balance.core.trees.StateTree`.

Collision checking is never done here: planners pass ``ompl_state(point)`` to
``si.isValid`` / ``si.checkMotion`` so that stock OMPL planners and ours use exactly the
same checker and motion validator.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np
from ompl import base as ob

from . import layout as flat
from .layout import SpaceLayout, layout_for, leaf_spaces, resolution_measures, state_reader
from .trees import ArrayTree, StateTree, Tree

#: Uniform samples drawn from numpy at a time (the compiled engine draws the same blocks).
SAMPLE_BLOCK = 256
_EQUAL_TOLERANCE = 2.0 * float(np.finfo(float).eps)


class Points(Protocol):
    """How a planner sees the points of a state space (both classes below implement it)."""

    def new_tree(self) -> Tree: ...
    def sample(self) -> Any: ...
    def distance(self, a: Any, b: Any) -> float: ...
    def interpolate(self, a: Any, b: Any, t: float) -> Any: ...
    def equal(self, a: Any, b: Any) -> bool: ...
    def may_stall(self, step: float) -> bool: ...
    def is_finite(self, state: ob.State) -> bool: ...
    def from_state(self, state: ob.State) -> Any: ...
    def ompl_state(self, point: Any, slot: int = 0) -> ob.State: ...
    def new_state(self, point: Any) -> ob.State: ...
    def segment_points(self, a: Any, b: Any) -> list[Any]: ...
    def restarted(self, rng: np.random.Generator) -> Points: ...


class ArrayPoints:
    """Points of a space with a flat layout as ``(dim,)`` float64 arrays."""

    def __init__(self, si: ob.SpaceInformation, layout: SpaceLayout, rng: np.random.Generator | None = None) -> None:
        self.layout = layout
        self.dim = layout.dim
        self._euclidean = layout.euclidean
        self._rng = rng  # None: set by restarted() before the first sample
        self._block = np.empty((0, self.dim))
        self._next = 0
        self._space = si.getStateSpace()
        self._si = si
        self._read = state_reader(self._space)
        # Two scratch OMPL states: checks take a pair (nearest, new) at a time.
        self._scratch = (si.allocState(), si.allocState())
        self._leaves = leaf_spaces(self._space)
        self._space_measures = resolution_measures(self._space, self._leaves)
        self._largest = max(map(abs, layout.low.tolist() + layout.high.tolist()), default=0.0)  # (numpy: slower here)

    def restarted(self, rng: np.random.Generator) -> Points:
        """These points, drawing from ``rng`` from now on (a fresh block of samples), for the next
        solve; new points when the space's extent or validity-checking resolution changed since
        these were made (a ``si.setup()`` after a change), so that the layout is the space's own."""
        if resolution_measures(self._space, self._leaves) != self._space_measures:
            return points_for(self._si, rng)
        self._rng = rng
        self._block = self._block[:0]
        self._next = 0
        return self

    def new_tree(self) -> ArrayTree:
        return ArrayTree(self.dim, layout=self.layout)

    def sample(self) -> np.ndarray:
        """A uniform sample of the space, ``(dim,)`` (a view into the current block of samples)."""
        if self._next == len(self._block):
            assert self._rng is not None, "restarted(rng) before sampling"
            uniforms = self._rng.random((SAMPLE_BLOCK, self.layout.total_draws))
            self._block = flat.samples_from_uniforms(self.layout, uniforms)
            self._next = 0
        point = self._block[self._next]
        self._next += 1
        return point

    def block(self) -> tuple[np.ndarray, int]:
        """The current block of uniform samples, ``(SAMPLE_BLOCK, dim)`` (``(0, dim)`` before the
        first), and the row the next sample is taken from: where a compiled loop taking over a
        solve goes on drawing."""
        return self._block, self._next

    def distance(self, a: np.ndarray, b: np.ndarray) -> float:
        """OMPL's distance (the squares of a real-vector space summed over the coordinates in
        order, as the tree scans and the compiled engine sum them, to the last bit)."""
        if self._euclidean:
            squares = ((b - a) ** 2).tolist()
            total = squares[0]
            for square in squares[1:]:
                total += square
            return math.sqrt(total)
        return flat.distance(self.layout, a, b)

    def interpolate(self, a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
        """The point a fraction ``t`` of the way from ``a`` to ``b`` (OMPL's interpolation)."""
        if self._euclidean:
            return a + t * (b - a)
        return flat.interpolate(self.layout, a, b, t)

    def equal(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Equal within OMPL's ``equalStates`` tolerance."""
        if self._euclidean:
            return float(np.abs(a - b).max()) <= _EQUAL_TOLERANCE
        return flat.equal(self.layout, a, b)

    def may_stall(self, step: float) -> bool:
        """Whether a move of length ``step`` can round back onto its start point.

        In a real-vector space only when ``step`` is within rounding of the coordinates'
        magnitude (planners skip the no-progress test otherwise); always where a leaf turns.
        """
        if not self._euclidean:
            return True
        return step <= 4.0 * _EQUAL_TOLERANCE * self._largest * math.sqrt(self.dim)

    def is_finite(self, state: ob.State) -> bool:
        """``False`` when an OMPL state has a NaN or infinite value (bounds checks miss NaN)."""
        return all(map(math.isfinite, self._read(state)))

    def from_state(self, state: ob.State) -> np.ndarray:
        """A copy of an OMPL state's values, ``(dim,)``."""
        return np.array(self._read(state), dtype=float)

    def ompl_state(self, point: np.ndarray, slot: int = 0) -> ob.State:
        """``point`` written into scratch OMPL state ``slot`` (0 or 1); valid until reused."""
        state = self._scratch[slot]
        self._space.copyFromReals(state, point.tolist())
        return state

    def new_state(self, point: np.ndarray) -> ob.State:
        """A freshly allocated OMPL state holding ``point`` (for output)."""
        state = self._si.allocState()
        self._space.copyFromReals(state, point.tolist())
        return state

    def segment_points(self, a: np.ndarray, b: np.ndarray) -> list[np.ndarray]:
        """Points after ``a`` up to and including ``b``: the states a motion check of ``(a, b)`` decided.

        ``interpolate(a, b, j / n)`` for ``j = 1..n``, ``n = validSegmentCount(a, b)``:
        the states OMPL's ``DiscreteMotionValidator`` checks, so every state added is
        known valid. (OMPL's ``getMotionStates`` would place them at ``j / (n + 1)``,
        between the checked ones.)
        """
        count = flat.segment_count(self.layout, a, b)
        return [self.interpolate(a, b, step / count) for step in range(1, count)] + [b]


class StatePoints:
    """Points of any OMPL state space, as OMPL states owned by the caller."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        self._si = si
        self._space = si.getStateSpace()
        self._sampler: ob.StateSampler | None = None  # allocated at the first sample
        self.distance = si.distance
        self.equal = si.equalStates

    def restarted(self, rng: np.random.Generator) -> Points:
        """Points with a sampler of their own for the next solve (allocated from OMPL, which
        seeds it from its RNG, as each solve's sampler always was; ``rng`` is not used)."""
        return StatePoints(self._si)

    def new_tree(self) -> StateTree:
        return StateTree(self._si)

    def sample(self) -> ob.State:
        if self._sampler is None:
            self._sampler = self._si.allocStateSampler()
        state = self._si.allocState()
        self._sampler.sampleUniform(state)
        return state

    def interpolate(self, a: ob.State, b: ob.State, t: float) -> ob.State:
        state = self._si.allocState()
        self._space.interpolate(a, b, t, state)
        return state

    @staticmethod
    def may_stall(step: float) -> bool:
        """Always: an arbitrary space's ``interpolate`` may make no progress (see RRTConnect.cpp)."""
        return True

    def is_finite(self, state: ob.State) -> bool:
        """``False`` when an OMPL state has a NaN or infinite value.

        Any such value makes the state's distance to itself NaN (or infinite), in every
        OMPL space, which bounds checks alone miss.
        """
        return math.isfinite(self.distance(state, state))

    def from_state(self, state: ob.State) -> ob.State:
        return self.new_state(state)

    def new_state(self, point: ob.State) -> ob.State:
        state = self._si.allocState()
        self._si.copyState(state, point)
        return state

    @staticmethod
    def ompl_state(point: ob.State, slot: int = 0) -> ob.State:
        return point

    def segment_points(self, a: ob.State, b: ob.State) -> list[ob.State]:
        """As :meth:`RealVectorPoints.segment_points`: the states a motion check of ``(a, b)`` decided."""
        count = self._space.validSegmentCount(a, b)
        return [self.interpolate(a, b, step / count) for step in range(1, count)] + [self.new_state(b)]


def points_for(si: ob.SpaceInformation, rng: np.random.Generator | None = None) -> Points:
    """Flat arrays for the spaces with a layout (:mod:`ompl_balance.core.layout`), OMPL states otherwise;
    samples come from ``rng`` (flat arrays; ``None``: from the generator given to ``restarted``)."""
    layout = layout_for(si.getStateSpace())
    return StatePoints(si) if layout is None else ArrayPoints(si, layout, rng)
