"""Validity checks as compiled kernels: the protocol between the compiled engine and the checkers.

A checker that can be called from compiled code offers a *view*: a ``NamedTuple`` of
arrays (its obstacles, its robot, its scratch space, ...) whose type has compiled
implementations of the two functions below, registered with ``numba.extending.overload``
by the module that defines the view. The compiled planning engine
(:mod:`ompl_balance.engine`) calls them on flat states (:mod:`ompl_balance.core.layout`)
without knowing which checker is behind the view; numba compiles the engine once per
type of view and caches it on disk.

Every view has a ``counts`` field, an int64 array indexed by :class:`Count`, that its
kernels increment in place: it *is* the checker's work counter (what ``counters()``
reports), so the counts stay exact whichever engine, or a stock planner, did the work.

A view's class names the module of its kernels (:func:`kernels_in`), so that the engine
imports them, and numba, only when it compiles for such a view.

A query a kernel cannot decide in compiled code (FCL on a non-convex pair, a user's
Python callable) leaves through one exit: the kernel's ``objmode`` block looks the Python
object up by the integer handle the view carries (:func:`exit_handle`) and calls it;
each such call counts in ``counts[Count.EXITS]``.
"""

from __future__ import annotations

import enum
import itertools
import weakref
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np


class Count(enum.IntEnum):
    """The entries of a view's ``counts`` array."""

    STATES = 0  # states whose validity was decided
    MOTIONS = 1  # motions (edges) decided
    DISTANCE_QUERIES = 2  # exact distance queries of a certified motion validator
    EXITS = 3  # calls from compiled code to Python
    OVER_BUDGET = 4  # motions refused because their proof would exceed the check's work budget


def new_counts() -> np.ndarray:
    """A zeroed work counter for a view, indexed by :class:`Count`."""
    return np.zeros(len(Count), dtype=np.int64)


def state_free(view: Any, q: np.ndarray) -> bool:
    """Whether flat state ``q`` (dim,) is valid for the checker behind ``view`` (compiled code only).

    Counts the states it decides in ``view.counts``.
    """
    raise TypeError("state_free is a compiled kernel: call it from numba-compiled code with a checker's view")


def motion_free(view: Any, a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the motion ``a -> b`` (flat states, dim,) is valid, ``a`` taken as valid (compiled code only).

    As OMPL's ``MotionValidator::checkMotion(s1, s2)``; counts one motion and the states it
    decides in ``view.counts``.
    """
    raise TypeError("motion_free is a compiled kernel: call it from numba-compiled code with a checker's view")


_TARGETS: weakref.WeakValueDictionary[int, Any] = weakref.WeakValueDictionary()  # handle -> object
_HANDLE_OF: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()  # object -> handle
_HANDLES = itertools.count(1)


def exit_handle(target: Any) -> int:
    """The handle by which compiled code reaches ``target`` (see :func:`exit_target`): one per
    object, held weakly, so registering keeps nothing alive."""
    handle = _HANDLE_OF.get(target)
    if handle is None:
        handle = next(_HANDLES)
        _TARGETS[handle] = target
        _HANDLE_OF[target] = handle
    return handle


def exit_target(handle: int) -> Any:
    """The object registered under ``handle``, for a kernel's ``objmode`` block."""
    return _TARGETS[handle]


def exits_to_python(view: Any) -> bool:
    """Whether the kernels of ``view`` may call Python: it, or a view inside it, carries an exit
    handle (a field ``handle``, by the convention of :func:`exit_handle`'s callers)."""
    if not (isinstance(view, tuple) and hasattr(view, "_fields")):
        return False
    return "handle" in view._fields or any(exits_to_python(field) for field in view)


_KERNEL_MODULES: dict[type, str] = {}

View = TypeVar("View", bound=type)


def kernels_in(module: str) -> Callable[[View], View]:
    """Class decorator of a view: its kernels are registered by importing ``module`` (which
    imports numba; the view's own module need not)."""

    def register(view: View) -> View:
        _KERNEL_MODULES[view] = module
        return view

    return register


def kernel_modules(view: Any) -> list[str]:
    """The modules holding the kernels of ``view`` and of the views inside it (:func:`kernels_in`),
    innermost first: importing them registers the kernels before the engine is compiled."""
    modules: list[str] = []
    if isinstance(view, tuple) and hasattr(view, "_fields"):
        for field in view:
            modules += [module for module in kernel_modules(field) if module not in modules]
        own = _KERNEL_MODULES.get(type(view))
        if own is not None and own not in modules:
            modules.append(own)
    return modules
