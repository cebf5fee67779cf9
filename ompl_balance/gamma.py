"""The RRT* ball-radius constant: its formula, an estimate of it, and OMPL's equivalent.

RRT* connects each new state to, and rewires, the tree nodes within

    r(N) = min((gamma * log(N) / N) ** (1 / d), eta)

of it, ``N`` the number of tree nodes (counting the new one), ``d`` the state
dimension, ``eta`` the maximum connection distance and ``gamma`` the *ball-radius
constant* (units: distance**d, ``log`` natural). Karaman & Frazzoli (IJRR 2011,
Theorem 38) prove asymptotic optimality for

    gamma > gamma* = 2**d * (1 + 1/d) * mu(X_free) / zeta_d

with ``mu(X_free)`` the measure (d-volume) of the free space and ``zeta_d`` the volume of
the unit d-ball. A constant far below ``gamma*`` (MATLAB's default is 100, whatever the
map) leaves the ball nearly empty and RRT* behaves like RRT: the cost stops improving
after the first solution. A constant far above it rewires against many nodes per
iteration.

OMPL's ``RRTstar`` (``src/ompl/geometric/planners/rrt/src/RRTstar.cpp``, radius mode,
``setKNearest(false)``) uses instead

    r_OMPL(N) = min(eta, rewire_factor * (2 * (1 + 1/d) * mu(X) / zeta_d) ** (1/d)
                         * (log(N) / N) ** (1/d))

(``calculateRewiringLowerBounds`` and ``getNeighbors``; ``N = nn_->size() + 1``, the
tree with the new state). It differs from the formula above in two ways:

1. ``mu(X)`` is the measure of the *whole* space (``si->getSpaceMeasure()``), not of
   the free space, so OMPL overestimates the constant by ``mu(X) / mu(X_free)``;
2. its constant lacks a factor ``2**(d - 1)``: raised to the power ``d`` and with
   ``rewire_factor = 1``, OMPL's radius constant is ``2 * (1 + 1/d) * mu(X) / zeta_d``
   where the theorem asks for ``2**d * (1 + 1/d) * mu(X_free) / zeta_d`` (the
   theorem's ``2 * (1 + 1/d)**(1/d)`` radius factor taken as ``(2 * (1 + 1/d))**(1/d)``).

Both schedules have the form ``c * (log(N) / N) ** (1/d)`` capped at ``eta``, so they are
equal for every ``N`` when the factors ``c`` agree:

    rewire_factor * (2 * (1 + 1/d) * mu(X) / zeta_d) ** (1/d) = gamma ** (1/d)
    rewire_factor = (gamma * zeta_d / (2 * (1 + 1/d) * mu(X))) ** (1/d)

which is what :func:`ompl_rewire_factor` computes (with OMPL's ``range`` set to ``eta``);
:func:`ompl_ball_radius_constant` is the converse, the ``gamma`` of OMPL's schedule for a
given ``rewire_factor``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, overload

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from .core.spaces import points_for

#: Samples :func:`estimate_free_measure` draws between two calls of its ``stop`` condition.
STOP_CHECK_EVERY = 100


class EstimateInterruptedError(Exception):
    """:func:`estimate_free_measure` was stopped (its ``stop`` condition said so) before its first sample."""


def unit_ball_volume(d: int) -> float:
    """Volume of the unit ball in ``d`` dimensions, ``pi**(d/2) / Gamma(d/2 + 1)``.

    ``d = 1`` gives 2 (the interval [-1, 1]), ``d = 2`` gives pi, ``d = 3`` 4/3 pi.
    """
    _check_dimension(d)
    return math.pi ** (d / 2) / math.gamma(d / 2 + 1)


def ball_radius_constant(d: int, free_measure: float) -> float:
    """Karaman & Frazzoli's lower bound ``2**d * (1 + 1/d) * free_measure / unit_ball_volume(d)``.

    ``free_measure`` is the d-volume of the free space (distance units**d, e.g. m**2
    for a planar map); the result has the same units. RRT* is asymptotically optimal
    for any ``gamma`` strictly above it.
    """
    _check_dimension(d)
    if not math.isfinite(free_measure) or free_measure <= 0:
        raise ValueError(f"free_measure must be a positive finite volume, got {free_measure!r}")
    return 2.0**d * (1.0 + 1.0 / d) * free_measure / unit_ball_volume(d)


@overload
def rewire_radius(n: int, d: int, gamma: float, eta: float = math.inf) -> float: ...
@overload
def rewire_radius(n: np.ndarray | list[int], d: int, gamma: float, eta: float = math.inf) -> np.ndarray | float: ...
def rewire_radius(n: Any, d: int, gamma: float, eta: float = math.inf) -> Any:
    """RRT*'s rewiring radius ``min((gamma * log(n) / n) ** (1/d), eta)`` (distance units).

    ``n``: number of tree nodes including the new one, an int >= 1 or an array of them
    (the result then has its shape); ``gamma``: ball-radius constant (distance**d);
    ``eta``: maximum connection distance, where the radius saturates (``inf`` for the
    unsaturated schedule). ``n = 1`` gives 0. Past ``n = e`` the radius decays like
    ``(log(n) / n) ** (1/d)``.
    """
    _check_dimension(d)
    if not math.isfinite(gamma) or gamma <= 0:
        raise ValueError(f"gamma must be a positive finite number, got {gamma!r}")
    if math.isnan(eta) or eta <= 0:
        raise ValueError(f"eta must be a positive distance (or inf), got {eta!r}")
    if isinstance(n, int):  # the planner's per-iteration call: plain floats
        if n < 1:
            raise ValueError(f"n counts tree nodes and must be >= 1, got {n}")
        return min((gamma * math.log(n) / n) ** (1.0 / d), eta)
    count = np.asarray(n, dtype=float)
    if np.any(count < 1):
        raise ValueError("n counts tree nodes and must be >= 1")
    radius = np.minimum((gamma * np.log(count) / count) ** (1.0 / d), eta)
    return float(radius) if radius.ndim == 0 else radius


@dataclass(frozen=True)
class FreeMeasure:
    """An estimate of the measure of the free space.

    ``measure`` (distance**d) with the interval ``[low, high]`` holding the true value
    with probability ``confidence`` (``low == measure == high`` when ``exact``);
    ``free_fraction`` of the space's measure ``space_measure``; ``samples`` drawn
    (0 when exact).
    """

    measure: float
    low: float
    high: float
    free_fraction: float
    space_measure: float
    samples: int
    confidence: float
    exact: bool


def estimate_free_measure(
    si: ob.SpaceInformation,
    samples: int = 5000,
    confidence: float = 0.95,
    grid: Any = None,
    rng: np.random.Generator | int | None = None,
    stop: Callable[[], Any] | None = None,
) -> FreeMeasure:
    """The measure of ``si``'s free space: Monte Carlo with a confidence interval, or exact.

    Without ``grid``: ``samples`` uniform states of the space are checked with
    ``si.isValid``; the free fraction ``k / samples`` times ``si.getSpaceMeasure()`` is
    the estimate, and the interval is the Clopper-Pearson ("exact") binomial interval
    at level ``confidence``, which covers the true fraction with probability at least
    ``confidence`` whatever the fraction and the sample size. Real-vector spaces are sampled from ``rng`` (a
    numpy generator or seed), other spaces with OMPL's sampler (seeded by
    ``ompl.util.RNG.setSeed``).

    With ``grid`` (a boolean occupancy array, ``True`` = occupied, or an object with
    such an ``occupied`` attribute, e.g. :class:`~ompl_balance.worlds.occupancy.OccupancyGrid`)
    the free fraction is counted exactly over the cells. This assumes the grid covers
    exactly the position bounds of the space and validity depends on position alone
    (other components, such as SE2's heading, then contribute their whole measure).

    ``stop`` (e.g. a ``PlannerTerminationCondition``) is asked every
    :data:`STOP_CHECK_EVERY` samples; when it returns true, sampling ends and the estimate
    is made from the samples drawn so far (``samples`` says how many; the interval is wider
    and still holds the true measure with probability ``confidence``), or, before the
    first sample, :class:`EstimateInterruptedError` is raised.
    """
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    space_measure = si.getSpaceMeasure()
    if not math.isfinite(space_measure) or space_measure <= 0:
        raise ValueError(f"the space's measure must be positive and finite (bounded space), got {space_measure!r}")
    if grid is not None:
        occupied = np.asarray(getattr(grid, "occupied", grid))
        if occupied.dtype != bool or occupied.size == 0:
            raise ValueError(
                "grid must be a non-empty boolean occupancy array (True = occupied) or have one as .occupied"
            )
        fraction = 1.0 - float(occupied.mean())
        measure = fraction * space_measure
        return FreeMeasure(measure, measure, measure, fraction, space_measure, 0, confidence, True)

    if isinstance(samples, bool) or int(samples) != samples or samples < 1:
        raise ValueError(f"samples must be a positive integer, got {samples!r}")
    if not si.isSetup():
        si.setup()
    points = points_for(si, rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng))
    free = drawn = 0
    while drawn < samples:
        if stop is not None and drawn % STOP_CHECK_EVERY == 0 and stop():
            if drawn == 0:
                raise EstimateInterruptedError("stopped before the first sample")
            break
        free += bool(si.isValid(points.ompl_state(points.sample())))
        drawn += 1
    fraction = free / drawn
    low, high = clopper_pearson(free, drawn, confidence)
    return FreeMeasure(
        fraction * space_measure,
        low * space_measure,
        high * space_measure,
        fraction,
        space_measure,
        drawn,
        confidence,
        False,
    )


def beta_quantile_function() -> Callable[..., Any]:
    """scipy's ``betaincinv``, imported on first use (a quarter of a second, more under load):
    planners that estimate ``gamma`` call this when they are made, so no solve pays it."""
    from scipy.special import betaincinv

    return betaincinv


def clopper_pearson(successes: int, trials: int, confidence: float) -> tuple[float, float]:
    """The Clopper-Pearson ("exact") interval of a binomial proportion at level ``confidence``.

    Its ends are quantiles of beta distributions: ``B(a/2; k, n - k + 1)`` and
    ``B(1 - a/2; k + 1, n - k)``, ``a = 1 - confidence`` (0 and 1 when ``k`` is 0 or ``n``);
    scipy's ``binomtest(...).proportion_ci(method="exact")`` finds the same ends by root finding.
    """
    betaincinv = beta_quantile_function()
    alpha = (1.0 - confidence) / 2.0
    low = 0.0 if successes == 0 else float(betaincinv(successes, trials - successes + 1, alpha))
    high = 1.0 if successes == trials else float(betaincinv(successes + 1, trials - successes, 1.0 - alpha))
    return low, high


def estimate_ball_radius_constant(
    si: ob.SpaceInformation,
    samples: int = 5000,
    confidence: float = 0.95,
    grid: Any = None,
    rng: np.random.Generator | int | None = None,
    stop: Callable[[], Any] | None = None,
) -> float:
    """``gamma*`` for ``si``'s free space (distance**d), erring on the large side.

    :func:`ball_radius_constant` of the state dimension and the *upper* end of
    :func:`estimate_free_measure`'s confidence interval (the exact measure when
    ``grid`` is given), so the result is at least the theorem's bound with probability
    ``confidence``. Arguments as for :func:`estimate_free_measure`.
    """
    free = estimate_free_measure(si, samples=samples, confidence=confidence, grid=grid, rng=rng, stop=stop)
    if free.high <= 0:
        raise ValueError("no valid state was sampled: the free space looks empty (check the validity checker)")
    return ball_radius_constant(si.getStateDimension(), free.high)


def ompl_rewire_factor(si: ob.SpaceInformation, gamma: float, planner: og.RRTstar | None = None) -> float:
    """The ``rewire_factor`` that gives OMPL's ``RRTstar`` the schedule ``rewire_radius(N, d, gamma, eta)``.

    ``(gamma * zeta_d / (2 * (1 + 1/d) * si.getSpaceMeasure())) ** (1/d)`` (see the
    module docstring for the derivation). With ``planner`` (an ``og.RRTstar`` on
    ``si``), also switch it to radius mode (``setKNearest(False)``) and set the factor;
    set its ``range`` to the same ``eta`` for the saturation to agree. The factor may
    be below 1, outside OMPL's range suggestion ``1.0:0.01:2.0``; OMPL accepts it.
    """
    if not math.isfinite(gamma) or gamma <= 0:
        raise ValueError(f"gamma must be a positive finite number, got {gamma!r}")
    d = si.getStateDimension()
    ompl_constant = 2.0 * (1.0 + 1.0 / d) * si.getSpaceMeasure() / unit_ball_volume(d)
    factor = (gamma / ompl_constant) ** (1.0 / d)
    if planner is not None:
        planner.setKNearest(False)
        planner.setRewireFactor(factor)
    return factor


def ompl_ball_radius_constant(si: ob.SpaceInformation, rewire_factor: float = 1.1) -> float:
    """The ``gamma`` of OMPL's ``RRTstar`` radius schedule for ``rewire_factor`` (radius mode).

    ``rewire_factor**d * 2 * (1 + 1/d) * si.getSpaceMeasure() / unit_ball_volume(d)``, the
    converse of :func:`ompl_rewire_factor`: ``BallRadiusRRTstar`` with this
    ``ball_radius_constant``, ``rewire_factor`` 1 and og.RRTstar's ``range`` rewires against
    the same ball as ``og.RRTstar`` with ``setKNearest(False)`` and this ``rewire_factor``
    (og.RRTstar's default is 1.1).
    """
    if not math.isfinite(rewire_factor) or rewire_factor <= 0:
        raise ValueError(f"rewire_factor must be a positive finite number, got {rewire_factor!r}")
    d = si.getStateDimension()
    return float(rewire_factor**d * 2.0 * (1.0 + 1.0 / d) * si.getSpaceMeasure() / unit_ball_volume(d))


def _check_dimension(d: int) -> None:
    if isinstance(d, bool) or int(d) != d or d < 1:
        raise ValueError(f"the dimension d must be an integer >= 1, got {d!r}")
