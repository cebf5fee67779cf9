"""Calling compiled (numba) functions from Python without numba's type dispatch.

A call to a numba function from Python first works out the numba type of every argument;
for named tuples of arrays (the package's views, trees and layouts) that is done in Python
and costs tens of microseconds per call. :func:`entry_point` compiles a function for fixed
argument types once and returns the compiled function itself, so later calls skip it (and
must pass arguments of exactly those types).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numba
from numba.core.errors import NumbaIRAssumptionWarning


def signature_of(arguments: tuple[Any, ...]) -> tuple[Any, ...]:
    """The numba types of ``arguments``: what numba compiles a function for."""
    return tuple(numba.typeof(a) for a in arguments)


def entry_point(kernel: Any, arguments: tuple[Any, ...]) -> Callable[..., Any]:
    """The compiled function of numba ``kernel`` for the types of ``arguments``, compiled (or
    loaded from numba's cache) now, without calling it. (numba's internal pedantic check of
    the views' inlined kernels, a warning meant for numba's developers, is not shown.)"""
    signature = signature_of(arguments)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NumbaIRAssumptionWarning)
        kernel.compile(signature)
    compiled: Any = kernel.overloads[signature]
    return compiled.entry_point


def load_cached(kernel: Any, arguments: tuple[Any, ...]) -> bool:
    """Load numba ``kernel``'s machine code for the types of ``arguments`` from numba's disk cache,
    if it is there, as numba's dispatcher does before it compiles (``Dispatcher.compile``);
    whether it was. Nothing is compiled: a caller that finds the cache empty can compile elsewhere
    (another process) rather than hold this interpreter."""
    from numba.core.compiler_lock import global_compiler_lock

    signature = signature_of(arguments)
    with global_compiler_lock:
        if signature in kernel.overloads:
            return True
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NumbaIRAssumptionWarning)
                loaded = kernel._cache.load_overload(signature, kernel.targetctx)  # (numba's disk cache)
        except Exception:
            return False
        if loaded is None:
            return False
        if not loaded.objectmode:
            kernel.targetctx.insert_user_function(loaded.entry_point, loaded.fndesc, [loaded.library])
        kernel.add_overload(loaded)
    return True
