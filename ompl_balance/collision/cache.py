"""A disk cache for arrays derived from robot geometry.

Building a collision checker derives arrays from the robot's meshes that take a second
or two to compute (covering spheres, certified-free tables) and never change for the
same geometry. Benchmarks build a checker in every run's fresh process, so these arrays
are kept on disk, keyed by a hash of everything they are computed from and of
:data:`FORMAT`. The cached arrays are the computed ones, bit for bit; a missing,
unreadable or unwritable cache only costs the computation.

Location: ``$OMPL_BALANCE_CACHE`` if set (an empty value turns the cache off), else
``$XDG_CACHE_HOME/ompl_balance`` (``~/.cache/ompl_balance``).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

#: Part of every key: bump it when what a cached computation returns changes.
FORMAT = "1"


def cache_dir() -> Path | None:
    """The cache directory, or ``None`` when caching is off."""
    configured = os.environ.get("OMPL_BALANCE_CACHE")
    if configured is not None:
        return Path(configured) if configured else None
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "ompl_balance"


def digest(parts: Iterable[object]) -> str:
    """A hex key over ``parts``: arrays by dtype, shape and bytes, anything else by ``repr``."""
    h = hashlib.blake2b(FORMAT.encode(), digest_size=20)
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(f"{part.dtype}{part.shape}".encode())
            h.update(np.ascontiguousarray(part).tobytes())
        else:
            h.update(repr(part).encode())
        h.update(b"\0")
    return h.hexdigest()


def cached_arrays(
    kind: str, key_parts: Iterable[object], compute: Callable[[], dict[str, np.ndarray]]
) -> dict[str, np.ndarray]:
    """``compute()``, or what an earlier call with the same ``kind`` and ``key_parts`` stored."""
    directory = cache_dir()
    if directory is None:
        return compute()
    path = directory / f"{kind}-{digest(key_parts)}.npz"
    try:
        with np.load(path, allow_pickle=False) as stored:
            return {name: stored[name] for name in stored.files}
    except (OSError, ValueError, EOFError):
        pass  # not there yet, or damaged: compute it again
    arrays = compute()
    temporary = None
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=directory, suffix=".npz", delete=False) as temporary:
            named: dict[str, Any] = dict(arrays)
            np.savez(temporary, **named)
        os.replace(temporary.name, path)  # atomic: concurrent runs never read half a file
    except OSError:  # read-only home, full disk: work without the cache
        if temporary is not None:
            Path(temporary.name).unlink(missing_ok=True)
    return arrays
