"""The compiled engine's uniform numbers against numpy's own ``Generator.random``."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from ompl_balance.engine.uniforms import bit_generator_address, next_double


@njit
def _draw(address: int, count: int) -> np.ndarray:  # pragma: no cover (compiled)
    out = np.empty(count)
    for i in range(count):
        out[i] = next_double(address)
    return out


@pytest.mark.parametrize("bit_generator", [np.random.PCG64, np.random.PCG64DXSM, np.random.Philox, np.random.SFC64])
def test_next_double_is_the_generators_stream(bit_generator) -> None:
    drawn = np.random.Generator(bit_generator(2026))
    reference = np.random.Generator(bit_generator(2026))
    address = bit_generator_address(drawn)
    # interleaved: compiled draws advance the generator's own state, which Python then continues
    for count in (1, 255, 1000):
        assert np.array_equal(_draw(address, count), reference.random(count))
        assert drawn.random() == reference.random()
        assert np.array_equal(drawn.random((3, 2)), reference.random((3, 2)))
