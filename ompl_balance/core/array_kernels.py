"""Array work the package's compiled kernels share."""

from __future__ import annotations

import numpy as np

from .kernel_cache import njit_borrowing


@njit_borrowing
def copy_into(source: np.ndarray, destination: np.ndarray) -> None:  # pragma: no cover (compiled)
    """``destination[:n] = source`` for 1-D arrays, ``source`` of ``n`` elements, one element at a
    time: an array assigned to a slice has numba compile its shape-mismatch error, seconds of
    compiling at first use for every kernel that does it."""
    for k in range(source.shape[0]):
        destination[k] = source[k]
