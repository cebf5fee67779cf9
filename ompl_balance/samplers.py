"""Valid-state samplers that concentrate samples near obstacles (narrow passages).

Each is an ``ob.ValidStateSampler`` written in Python, so it plugs in wherever OMPL
takes one::

    si.setValidStateSamplerAllocator(BridgeTestValidStateSampler)
    sampler = si.allocValidStateSampler()     # what PRM, or our ``valid_sampler`` policy, calls

:class:`GaussianValidStateSampler`
    OMPL's ``GaussianValidStateSampler`` (``src/ompl/base/samplers/src/
    GaussianValidStateSampler.cpp``): a uniform state and a Gaussian neighbour of it;
    when exactly one of the two is valid, that one is the sample.
:class:`BridgeTestValidStateSampler`
    OMPL's ``BridgeTestValidStateSampler``: an invalid uniform state and an invalid
    Gaussian neighbour of it; their midpoint is the sample when it is valid.
:class:`PassageSampler`
    the passage sampler of the TU Berlin lab report "RRT Extensions" (2020): a valid
    uniform state is the sample when the number of its ``neighbours`` Gaussian
    neighbours that collide lies in ``[min_colliding, max_colliding]`` (default: some
    but not all collide).

OMPL's Python bindings do not expose the first two. All three:

* try ``getNrAttempts()`` times (OMPL's default, 100) and return ``False`` when no
  attempt produced a sample (the state then holds no valid sample);
* implement ``sampleNear(state, near, distance)`` as OMPL does: the first state is
  drawn uniformly within ``distance`` of ``near`` and ``distance`` is the Gaussian's
  standard deviation;
* draw every random number from an OMPL state sampler (``si.allocStateSampler()``),
  so ``ompl.util.RNG.setSeed`` makes them repeat;
* count the states they check in ``validity_checks`` (collision queries like any
  other: they go through ``si.isValid`` and so through the counting checker too);
* have a :class:`~ompl_balance.core.params.ParamSet` (``params()``) with
  ``standard_deviation`` (default 0.1 x the space's maximum extent, as OMPL; 0.05 x
  for :class:`PassageSampler`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ompl import base as ob

from .core.params import ParamSet, Settings, add_accessors, param

#: OMPL's ``magic::STD_DEV_AS_SPACE_EXTENT_FRACTION``.
STD_DEV_AS_EXTENT_FRACTION = 0.1


@dataclass
class NearObstacleSettings(Settings):
    """The parameter of the Gaussian and bridge-test samplers."""

    standard_deviation: float = param(
        math.nan,
        "standard deviation of the Gaussian neighbour (state-space distance); set at construction "
        "to a fraction of the space's maximum extent (0.1, OMPL's default; 0.05 for PassageSampler)",
        low=0.0,
        low_open=True,
        suggestion="0.:0.01:10.",
        accessor="StdDev",
    )


@dataclass
class PassageSettings(NearObstacleSettings):
    """The parameters of :class:`PassageSampler`."""

    neighbours: int = param(8, "Gaussian neighbours drawn around each candidate (k)", low=1, suggestion="1:1:64")
    min_colliding: int = param(
        1, "fewest neighbours in collision for the candidate to be a sample", low=0, suggestion="0:1:64"
    )
    max_colliding: int = param(
        7, "most neighbours in collision for the candidate to be a sample", low=0, suggestion="0:1:64"
    )

    def check(self) -> None:
        if not 0 <= self.min_colliding <= self.max_colliding <= self.neighbours:
            raise ValueError(
                "need 0 <= min_colliding <= max_colliding <= neighbours, got "
                f"{self.min_colliding}, {self.max_colliding}, {self.neighbours}"
            )


class _NearObstacleSampler(ob.ValidStateSampler):
    """What the three samplers share: OMPL's sampler and checker, counting, the parameters."""

    Settings: type[NearObstacleSettings] = NearObstacleSettings

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        add_accessors(cls, cls.Settings)

    def __init__(self, si: ob.SpaceInformation, name: str, stddev_fraction: float) -> None:
        super().__init__(si)
        self.setName(name)
        self._states = si.allocStateSampler()
        self._is_valid_in_si = si.isValid
        self._copy = si.copyState
        self._interpolate = si.getStateSpace().interpolate
        self._scratch = si.allocState()  # the second state of a pair
        self.settings = self.Settings()
        self.settings.set("standard_deviation", stddev_fraction * si.getMaximumExtent())
        self._params = ParamSet.of(self.settings)
        self.validity_checks = 0

    def params(self) -> ParamSet:
        return self._params

    def _check(self, state: ob.State) -> bool:
        self.validity_checks += 1
        return bool(self._is_valid_in_si(state))

    def _draw(self, state: ob.State, near: ob.State | None, distance: float) -> None:
        """A uniform state: anywhere when ``near`` is ``None``, else within ``distance`` of it."""
        if near is None:
            self._states.sampleUniform(state)
        else:
            self._states.sampleUniformNear(state, near, distance)

    def sample(self, state: ob.State) -> bool:
        return self._sample(state, None, self.settings.standard_deviation)

    def sampleNear(self, state: ob.State, near: ob.State, distance: float) -> bool:  # noqa: N802
        return self._sample(state, near, distance)

    def _sample(self, state: ob.State, near: ob.State | None, stddev: float) -> bool:
        raise NotImplementedError


class GaussianValidStateSampler(_NearObstacleSampler):
    """OMPL's Gaussian sampler: of a uniform state and its Gaussian neighbour, the one valid
    when the other is not (Boor, Overmars, van der Stappen, 1999)."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        super().__init__(si, "gaussian", STD_DEV_AS_EXTENT_FRACTION)

    def _sample(self, state: ob.State, near: ob.State | None, stddev: float) -> bool:
        neighbour = self._scratch
        for _ in range(self.getNrAttempts()):
            self._draw(state, near, stddev)
            first_valid = self._check(state)
            self._states.sampleGaussian(neighbour, state, stddev)
            if first_valid != self._check(neighbour):
                if not first_valid:
                    self._copy(state, neighbour)
                return True
        return False


class BridgeTestValidStateSampler(_NearObstacleSampler):
    """OMPL's bridge test: the valid midpoint of an invalid state and an invalid Gaussian
    neighbour of it (Hsu et al., 2003)."""

    def __init__(self, si: ob.SpaceInformation) -> None:
        super().__init__(si, "bridge_test", STD_DEV_AS_EXTENT_FRACTION)

    def _sample(self, state: ob.State, near: ob.State | None, stddev: float) -> bool:
        endpoint = self._scratch
        for _ in range(self.getNrAttempts()):
            self._draw(state, near, stddev)
            if self._check(state):
                continue
            self._states.sampleGaussian(endpoint, state, stddev)
            if self._check(endpoint):
                continue
            self._interpolate(endpoint, state, 0.5, state)
            if self._check(state):
                return True
        return False


class PassageSampler(_NearObstacleSampler):
    """The passage sampler of the lab report "RRT Extensions" (2020): a valid uniform state with
    some, not all, neighbours colliding.

    Parameters
    ----------
    si: the space information.
    neighbours: Gaussian neighbours drawn around each candidate (``k``, >= 1).
    min_colliding, max_colliding: the candidate is the sample when the number of its
        neighbours in collision lies in this closed range; defaults 1 and ``k - 1``
        ("some but not all"). Neighbours stop being checked once the count can no
        longer end in the range.
    stddev_fraction: the neighbours' standard deviation as a fraction of the space's
        maximum extent (the report's 0.05).
    """

    Settings = PassageSettings
    settings: PassageSettings

    def __init__(
        self,
        si: ob.SpaceInformation,
        neighbours: int = 8,
        min_colliding: int = 1,
        max_colliding: int | None = None,
        stddev_fraction: float = 0.05,
    ) -> None:
        super().__init__(si, "passage", stddev_fraction)
        self.settings.update(
            {
                "neighbours": neighbours,
                "min_colliding": min_colliding,
                "max_colliding": neighbours - 1 if max_colliding is None else max_colliding,
            }
        )

    def _sample(self, state: ob.State, near: ob.State | None, stddev: float) -> bool:
        neighbour, k = self._scratch, self.settings.neighbours
        low, high = self.settings.min_colliding, self.settings.max_colliding
        for _ in range(self.getNrAttempts()):
            self._draw(state, near, stddev)
            if not self._check(state):
                continue
            colliding = 0
            for checked in range(1, k + 1):
                self._states.sampleGaussian(neighbour, state, stddev)
                colliding += not self._check(neighbour)
                if colliding > high or colliding + (k - checked) < low:
                    break
            else:
                return True
        return False
