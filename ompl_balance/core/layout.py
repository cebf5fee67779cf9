"""State spaces as flat float arrays: which OMPL spaces have one, and their geometry in numpy.

OMPL's real-vector, SO(2), SO(3), SE(2) and SE(3) spaces, and compound spaces built from
them (with any subspace weights), store a state as a fixed sequence of reals, the order
of ``space.copyFromReals``: a real-vector space its coordinates, SO(2) its angle, SO(3) its
quaternion ``(x, y, z, w)``, SE(2) ``(x, y, yaw)``, SE(3) ``(x, y, z, qx, qy, qz, qw)``, a
compound space its components in turn. :class:`SpaceLayout` describes that sequence as a
list of *leaves* (a real-vector block, an SO(2) angle or an SO(3) quaternion), each with
what OMPL's space of that leaf uses: its weight in the distance (the product of the
subspace weights above it), its bounds, its longest valid segment and segment-count factor.

The geometry is OMPL's, leaf by leaf:

* distance: the weighted sum of the leaves' distances (Euclidean; ``|a - b|`` the short way
  round the circle; the arc length ``acos(|a . b|)`` between unit quaternions, 0 within
  1e-9 of the same rotation);
* interpolation: straight for real-vector leaves, the shortest arc for SO(2), slerp for
  SO(3);
* ``validSegmentCount``: the largest over the leaves of ``factor * ceil(d / segment)``;
* uniform sampling: within the bounds, ``[-pi, pi)`` for an angle, Shoemake's method for
  a quaternion (OMPL's ``RNG::quaternion``), from uniform numbers drawn by the caller.

The functions here are numpy's and the Python engine's; :mod:`ompl_balance.core.compiled_spaces`
compiles the same formulas for the compiled engine, operation for operation, so both engines
compute the same numbers (sums are taken coordinate by coordinate in order, never by a
dot product whose order a BLAS may change).
"""

from __future__ import annotations

import enum
import math
import operator
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
from ompl import base as ob

#: OMPL's tolerance for a unit quaternion (``MAX_QUATERNION_NORM_ERROR``): rotations whose
#: ``|a . b|`` is within this of 1 are at distance 0.
QUATERNION_TOLERANCE = 1e-9
_EPS = float(np.finfo(float).eps)


class Leaf(enum.IntEnum):
    """The kinds of leaf a flat state is made of."""

    REAL = 0  # real-vector coordinates
    SO2 = 1  # an angle in [-pi, pi)
    SO3 = 2  # a unit quaternion (x, y, z, w)


#: Uniform numbers one sample of a leaf takes: one per coordinate, one per angle, three per quaternion.
_DRAWS = {Leaf.SO2: 1, Leaf.SO3: 3}


class SpaceLayout(NamedTuple):
    """A state space's flat layout (arrays, so compiled kernels take it as it is).

    Leaf ``i`` has kind ``kind[i]`` (:class:`Leaf`), occupies ``values[offset[i]:offset[i] +
    size[i]]`` of a flat state and draws ``draws[i]`` uniform numbers per sample starting at
    ``draw_offset[i]``; its distance counts ``weight[i]`` times, and OMPL cuts a motion of its
    own into ``factor[i] * ceil(d / segment[i])`` segments. ``low``, ``high`` (dim,) are the
    bounds of the real-vector coordinates (``-pi``, ``pi`` for angles, ``-1``, ``1`` for
    quaternions). ``dim`` is the number of reals in a state and ``total_draws`` the uniform
    numbers one sample takes.
    """

    kind: np.ndarray
    offset: np.ndarray
    size: np.ndarray
    weight: np.ndarray
    segment: np.ndarray
    factor: np.ndarray
    draw_offset: np.ndarray
    draws: np.ndarray
    low: np.ndarray
    high: np.ndarray
    dim: int
    total_draws: int

    @property
    def euclidean(self) -> bool:
        """One real-vector leaf of weight 1: the plain Euclidean space."""
        # (as Python numbers: a numpy scalar compared with an enum costs microseconds)
        return len(self.kind) == 1 and self.kind.item(0) == Leaf.REAL and self.weight.item(0) == 1.0


def leaf_spaces(space: ob.StateSpace) -> list[ob.StateSpace]:
    """The leaves of ``space`` in layout order (``[]`` for a space without a flat layout)."""
    leaves: list[tuple[Leaf, float, ob.StateSpace]] = []
    return [leaf for _, _, leaf in leaves] if _leaves(space, 1.0, leaves) else []


def resolution_measures(space: ob.StateSpace, leaves: list[ob.StateSpace]) -> tuple[float, ...]:
    """What a layout of ``space`` (its leaves ``leaves``, :func:`leaf_spaces`) depends on that a
    change of its bounds or validity-checking resolution changes, cheap to read: its maximum
    extent, and the longest valid segment and segment-count factor of it and of each leaf (a
    leaf's resolution can change alone: ``setLongestValidSegmentFraction`` on a subspace)."""
    measures = [space.getMaximumExtent(), space.getLongestValidSegmentLength(), space.getValidSegmentCountFactor()]
    for leaf in leaves:
        measures += (leaf.getLongestValidSegmentLength(), leaf.getValidSegmentCountFactor())
    return tuple(measures)


def _leaves(space: ob.StateSpace, weight: float, out: list[tuple[Leaf, float, ob.StateSpace]]) -> bool:
    """Append ``space``'s leaves (kind, weight, leaf space) to ``out``; ``False`` for a space without a flat layout."""
    kind = type(space)
    if kind is ob.RealVectorStateSpace:
        out.append((Leaf.REAL, weight, space))
    elif kind is ob.SO2StateSpace:
        out.append((Leaf.SO2, weight, space))
    elif kind is ob.SO3StateSpace:
        out.append((Leaf.SO3, weight, space))
    elif kind in (ob.SE2StateSpace, ob.SE3StateSpace, ob.CompoundStateSpace):
        for i in range(space.getSubspaceCount()):
            if not _leaves(space.getSubspace(i), weight * space.getSubspaceWeight(i), out):
                return False
    else:
        return False
    return True


def has_layout(space: ob.StateSpace) -> bool:
    """Whether ``space`` has a flat layout (what :func:`layout_for` asks first, without building it)."""
    return _leaves(space, 1.0, [])


def layout_for(space: ob.StateSpace) -> SpaceLayout | None:
    """The flat layout of a set-up OMPL ``space``, or ``None`` when it has none (another kind of space)."""
    leaves: list[tuple[Leaf, float, ob.StateSpace]] = []
    if not _leaves(space, 1.0, leaves):
        return None
    kinds, offsets, sizes, draw_offsets, draws, low, high = [], [], [], [], [], [], []
    offset = draw = 0
    for kind, _, leaf in leaves:
        if kind is Leaf.REAL:
            size = leaf.getDimension()
            bounds = leaf.getBounds()
            low += list(bounds.low)
            high += list(bounds.high)
        elif kind is Leaf.SO2:
            size = 1
            low.append(-math.pi)
            high.append(math.pi)
        else:
            size = 4
            low += [-1.0] * 4
            high += [1.0] * 4
        count = size if kind is Leaf.REAL else _DRAWS[kind]
        kinds.append(kind)
        offsets.append(offset)
        sizes.append(size)
        draw_offsets.append(draw)
        draws.append(count)
        offset += size
        draw += count
    return SpaceLayout(
        kind=np.array(kinds, dtype=np.int64),
        offset=np.array(offsets, dtype=np.int64),
        size=np.array(sizes, dtype=np.int64),
        weight=np.array([w for _, w, _ in leaves], dtype=float),
        segment=np.array([leaf.getLongestValidSegmentLength() for _, _, leaf in leaves], dtype=float),
        factor=np.array([leaf.getValidSegmentCountFactor() for _, _, leaf in leaves], dtype=np.int64),
        draw_offset=np.array(draw_offsets, dtype=np.int64),
        draws=np.array(draws, dtype=np.int64),
        low=np.array(low, dtype=float),
        high=np.array(high, dtype=float),
        dim=offset,
        total_draws=draw,
    )


# -- one pair of states -----------------------------------------------------------------------


def _ordered_sum(values: list[float]) -> float:
    total = values[0]
    for value in values[1:]:
        total += value
    return total


def leaf_distance(layout: SpaceLayout, leaf: int, a: np.ndarray, b: np.ndarray) -> float:
    """OMPL's distance between ``a`` and ``b`` (flat states) in leaf ``leaf``'s own space (unweighted)."""
    start, stop = layout.offset[leaf], layout.offset[leaf] + layout.size[leaf]
    kind = layout.kind[leaf]
    if kind == Leaf.REAL:
        return math.sqrt(_ordered_sum(((b[start:stop] - a[start:stop]) ** 2).tolist()))
    if kind == Leaf.SO2:
        d = abs(float(a[start]) - float(b[start]))
        return 2.0 * math.pi - d if d > math.pi else d
    dot = abs(_ordered_sum((a[start:stop] * b[start:stop]).tolist()))
    return 0.0 if dot > 1.0 - QUATERNION_TOLERANCE else math.acos(dot)


def distance(layout: SpaceLayout, a: np.ndarray, b: np.ndarray) -> float:
    """OMPL's distance between flat states ``a`` and ``b``: the weighted sum over the leaves."""
    total = 0.0
    for leaf in range(len(layout.kind)):
        total += layout.weight[leaf] * leaf_distance(layout, leaf, a, b)
    return total


def segment_count(layout: SpaceLayout, a: np.ndarray, b: np.ndarray) -> int:
    """OMPL's ``validSegmentCount(a, b)``: the largest over the leaves of ``factor * ceil(d / segment)``."""
    count = 0
    for leaf in range(len(layout.kind)):
        d = leaf_distance(layout, leaf, a, b)
        count = max(count, int(layout.factor[leaf]) * math.ceil(d / layout.segment[leaf]))
    return count


def interpolate(layout: SpaceLayout, a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """The state a fraction ``t`` of the way from ``a`` to ``b`` along OMPL's interpolation, ``(dim,)``."""
    if layout.euclidean:
        return a + t * (b - a)
    out = np.empty(layout.dim)
    for leaf in range(len(layout.kind)):
        start, stop = layout.offset[leaf], layout.offset[leaf] + layout.size[leaf]
        kind = layout.kind[leaf]
        if kind == Leaf.REAL:
            out[start:stop] = a[start:stop] + t * (b[start:stop] - a[start:stop])
        elif kind == Leaf.SO2:
            out[start] = _angle_between(float(a[start]), float(b[start]), t)
        else:
            out[start:stop] = _slerp(a[start:stop].tolist(), b[start:stop].tolist(), t)
    return out


def _angle_between(a: float, b: float, t: float) -> float:
    """SO(2): the angle a fraction ``t`` of the way from ``a`` to ``b`` the short way round."""
    diff = b - a
    if abs(diff) <= math.pi:
        return a + diff * t
    diff = 2.0 * math.pi - diff if diff > 0.0 else -2.0 * math.pi - diff
    value = a - diff * t
    if value > math.pi:
        value -= 2.0 * math.pi
    elif value < -math.pi:
        value += 2.0 * math.pi
    return value


def _slerp(a: list[float], b: list[float], t: float) -> list[float]:
    """SO(3): spherical linear interpolation of unit quaternions, the short way (OMPL's)."""
    dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    theta = 0.0 if abs(dot) > 1.0 - QUATERNION_TOLERANCE else math.acos(abs(dot))
    if theta <= _EPS:
        return list(a)
    d = 1.0 / math.sin(theta)
    s0 = math.sin((1.0 - t) * theta)
    s1 = math.sin(t * theta)
    if dot < 0.0:
        s1 = -s1
    return [(a[k] * s0 + b[k] * s1) * d for k in range(4)]


def equal(layout: SpaceLayout, a: np.ndarray, b: np.ndarray) -> bool:
    """OMPL's ``equalStates``: every leaf equal within its space's tolerance."""
    for leaf in range(len(layout.kind)):
        start, stop = layout.offset[leaf], layout.offset[leaf] + layout.size[leaf]
        kind = layout.kind[leaf]
        if kind == Leaf.REAL:
            if float(np.abs(a[start:stop] - b[start:stop]).max()) > 2.0 * _EPS:
                return False
        elif kind == Leaf.SO2:
            if not abs(float(a[start]) - float(b[start])) < 2.0 * _EPS:
                return False
        elif not leaf_distance(layout, leaf, a, b) < _EPS:
            return False
    return True


def samples_from_uniforms(layout: SpaceLayout, uniforms: np.ndarray) -> np.ndarray:
    """Uniform samples of the space, ``(n, dim)``, from uniform numbers in [0, 1), ``(n, total_draws)``."""
    if layout.euclidean:
        return layout.low + (layout.high - layout.low) * uniforms
    samples = np.empty((len(uniforms), layout.dim))
    for leaf in range(len(layout.kind)):
        start, size = layout.offset[leaf], layout.size[leaf]
        first = layout.draw_offset[leaf]
        kind = layout.kind[leaf]
        if kind == Leaf.REAL:
            low, high = layout.low[start : start + size], layout.high[start : start + size]
            samples[:, start : start + size] = low + (high - low) * uniforms[:, first : first + size]
        elif kind == Leaf.SO2:
            samples[:, start] = -math.pi + (2.0 * math.pi) * uniforms[:, first]
        else:
            for row in range(len(uniforms)):
                samples[row, start : start + 4] = _quaternion(*uniforms[row, first : first + 3].tolist())
    return samples


def _quaternion(u0: float, u1: float, u2: float) -> tuple[float, float, float, float]:
    """A uniform unit quaternion (x, y, z, w) from three uniform numbers (Shoemake; OMPL's ``RNG::quaternion``)."""
    r1, r2 = math.sqrt(1.0 - u0), math.sqrt(u0)
    t1, t2 = 2.0 * math.pi * u1, 2.0 * math.pi * u2
    return math.sin(t1) * r1, math.cos(t1) * r1, math.sin(t2) * r2, math.cos(t2) * r2


# -- a state against many -----------------------------------------------------------------------


def squared_distances(states: np.ndarray, query: np.ndarray) -> np.ndarray:
    """Squared Euclidean distance of each row of ``states`` to ``query``, ``(len(states),)``.

    Summed over the coordinates in order, exactly as the compiled kernels do, so both
    give the same numbers to the last bit.
    """
    offsets = states - query
    squared = offsets[:, 0] * offsets[:, 0]
    for k in range(1, offsets.shape[1]):
        squared += offsets[:, k] * offsets[:, k]
    return squared


def distances(layout: SpaceLayout, states: np.ndarray, query: np.ndarray) -> np.ndarray:
    """OMPL's distance from each row of ``states`` (n, dim) to ``query`` (dim,), ``(n,)``."""
    total = np.zeros(len(states))
    for leaf in range(len(layout.kind)):
        start, stop = layout.offset[leaf], layout.offset[leaf] + layout.size[leaf]
        kind = layout.kind[leaf]
        block = states[:, start:stop]
        if kind == Leaf.REAL:
            d = np.sqrt(squared_distances(block, query[start:stop]))
        elif kind == Leaf.SO2:
            d = np.abs(block[:, 0] - query[start])
            d = np.where(d > math.pi, 2.0 * math.pi - d, d)
        else:
            dot = block[:, 0] * query[start]
            for k in range(1, 4):
                dot += block[:, k] * query[start + k]
            dot = np.abs(dot)
            d = np.where(dot > 1.0 - QUATERNION_TOLERANCE, 0.0, np.arccos(np.minimum(dot, 1.0)))
        total += layout.weight[leaf] * d
    return total


# -- OMPL states ----------------------------------------------------------------------------------


def state_reader(space: ob.StateSpace) -> Callable[[Any], list[float]]:
    """``read(state) -> [reals]``: an OMPL state of ``space`` (one with a layout) as its flat values."""
    kind = type(space)
    if kind is ob.RealVectorStateSpace:
        n = space.getDimension()
        if n < 2:
            return lambda state: [state[i] for i in range(n)]
        # (itemgetter indexes the state n times from C: up to 30 dimensions faster than the
        # bindings' slice, which costs some 0.7 us a call)
        values = operator.itemgetter(*range(n))
        return lambda state: list(values(state))
    if kind is ob.SO2StateSpace:
        return lambda state: [state.value]
    if kind is ob.SO3StateSpace:
        return lambda state: [state.x, state.y, state.z, state.w]
    if kind is ob.SE2StateSpace:
        return lambda state: [state.getX(), state.getY(), state.getYaw()]
    if kind is ob.SE3StateSpace:

        def read_se3(state: Any) -> list[float]:
            rotation = state.rotation()
            return [state.getX(), state.getY(), state.getZ(), rotation.x, rotation.y, rotation.z, rotation.w]

        return read_se3
    readers = [state_reader(space.getSubspace(i)) for i in range(space.getSubspaceCount())]

    def read_compound(state: Any) -> list[float]:
        values: list[float] = []
        for i, read in enumerate(readers):
            values += read(state[i])
        return values

    return read_compound
