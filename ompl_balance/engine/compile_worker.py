"""Compiling the engine in another process: ``python -m ompl_balance.engine.compile_worker``.

Reads a pickled ``(view, layout)`` from standard input and compiles
:func:`ompl_balance.engine.loop.run` for their types into numba's disk cache
(:func:`ompl_balance.engine.driver.warm_up`). :mod:`ompl_balance.engine.loading` runs it so that a
long first compilation does not hold the planning process's interpreter (numba compiles mostly
in Python); the planning process then loads the cached code.
"""

from __future__ import annotations

import importlib
import pickle
import sys

from ..core.checks import kernel_modules


def main() -> None:
    view, layout = pickle.loads(sys.stdin.buffer.read())
    for module in kernel_modules(view):
        importlib.import_module(module)
    from .driver import warm_up

    warm_up(view, layout)


if __name__ == "__main__":
    main()
