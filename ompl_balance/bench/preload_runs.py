"""Imported by every sweep's forkserver (see ``isolation.preload_modules``): the code a run
executes and the planners' compiled tree scans, compiled with a notice the first time after
installing, so every run's process, forked from the forkserver, starts with them ready."""

from .compile_notice import compile_notice

with compile_notice("the planners' tree scans"):
    from ..core import scans  # noqa: F401  (compiled when imported)
    from . import execution  # noqa: F401
