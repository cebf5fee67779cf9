"""The first sweep after installing: numba compiles the forkserver's kernels in parallel processes.

A sweep's forkserver imports its preload modules (:func:`~ompl_balance.bench.isolation.preload_modules`)
one after another, and each compiles what its runs need the first time after installing
(tens of seconds each, numba compiling mostly in Python on one core). :func:`compile_in_parallel`
has them compiled first, each imported by a process of its own, as many at once as the machine
has cores; the forkserver then loads everything from numba's cache. A module done so is noted
(by the package's digest, so an update compiles again), and later sweeps skip the step.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Seconds between looks at the compiling processes.
_POLL = 0.1
#: What a compiling process runs before it imports its module.
_COMPILE_HERE = "from ompl_balance.engine.compiled import compile_in_this_process; compile_in_this_process()"


def _done_marker(module: str) -> Path:
    """The file that says ``module``'s kernels were compiled for this copy of the package: kept
    in numba's cache of the package (a reinstall that empties the cache removes it too), else in
    the temporary folder."""
    from ..core.kernel_cache import PACKAGE, cache_folder, package_digest

    cache = os.environ.get("NUMBA_CACHE_DIR", "")
    key = hashlib.sha256(f"{PACKAGE} {cache} {package_digest()} {module}".encode()).hexdigest()[:16]
    return (cache_folder() or Path(tempfile.gettempdir())) / f"ompl_balance-compiled-{key}"


def compile_in_parallel(modules: list[str]) -> None:
    """Import each of ``modules`` whose kernels may not be compiled yet in a process of its own,
    up to the machine's core count at once, and wait for them (their compile notices go to
    standard error, their standard output nowhere). Nothing is done for fewer than two: the
    forkserver compiles one as fast. A process that fails is left to the forkserver, which
    compiles and reports the same.

    The modules start in the order given, the next as soon as any running one ends: the
    forkserver imports the runner's own module first, whose engine compiles the planning loop's
    kernels that every engine shares, so the problem kinds' engines, compiled after their
    collision kernels, find them in numba's cache rather than compiling them alongside.
    """
    pending = [module for module in modules if module != "__main__" and not _done_marker(module).exists()]
    if len(pending) < 2:
        return
    environment = {**os.environ, "PYTHONSAFEPATH": "1"}  # the installed package (see isolation._context)
    running: list[tuple[str, subprocess.Popen[bytes]]] = []
    while pending or running:
        while pending and len(running) < (os.cpu_count() or 1):
            module = pending.pop(0)
            # (standard output: OMPL's Info lines, which must not reach the tables on the caller's)
            # (the engine compiled in the process itself: it does nothing else)
            command = [sys.executable, "-c", f"{_COMPILE_HERE}; import {module}"]
            running.append((module, subprocess.Popen(command, env=environment, stdout=subprocess.DEVNULL)))
        ended = [(module, process) for module, process in running if process.poll() is not None]
        for module, process in ended:
            running.remove((module, process))
            _finish(module, process)
        if not ended:
            time.sleep(_POLL)


def _finish(module: str, process: subprocess.Popen[bytes]) -> None:
    if process.wait() == 0:
        _done_marker(module).touch()
