"""The errors a benchmark reports to its user: an experiment that cannot run, an extra not installed, a
cluster that does not answer."""

from __future__ import annotations

from typing import Any


class ExperimentError(ValueError):
    """An experiment description (or output folder) that cannot be used.

    ``key`` is where the problem is (``"planners[1].params"``, a file or folder), ``reason``
    what is wrong with it and ``value`` the offending value when there is one; the message
    is ``"key: reason"``.
    """

    def __init__(self, key: str, message: str, value: Any = None) -> None:
        super().__init__(f"{key}: {message}")
        self.key, self.reason, self.value = key, message, value


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message names the ``pip install`` that adds it."""


class ClusterError(ConnectionError):
    """A Dask cluster that could not be reached; the message names its address and what was tried."""
