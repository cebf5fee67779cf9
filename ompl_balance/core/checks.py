"""Validity checks as compiled kernels: the protocol between the compiled engine and the checkers.

A checker that can be called from compiled code offers a *view*: a ``NamedTuple`` of
arrays (its obstacles, its robot, its scratch space, ...) whose type has compiled
implementations of :func:`state_free` and :func:`motion_free`, registered with
``numba.extending.overload`` by the module that defines the view (and, where checking a
tree's steps together pays, of :func:`steps_free` and :func:`growth_free`; other views check
them one by one). The
compiled planning engine (:mod:`ompl_balance.engine`) calls them on flat states
(:mod:`ompl_balance.core.layout`) without knowing which checker is behind the view; numba
compiles the engine once per type of view and caches it on disk.

Every view has a ``counts`` field, an int64 array indexed by :class:`Count`, that its
kernels increment in place: it *is* the checker's work counter (what ``counters()``
reports), so the counts stay exact whichever engine, or a stock planner, did the work.

A view's class names the module of its kernels (:func:`kernels_in`), so that the engine
imports them, and numba, only when it compiles for such a view.

A query a kernel cannot decide in compiled code leaves through one exit, counted in
``counts[Count.EXITS]``: a C callback (:data:`EXIT_ADDRESS`, :mod:`ompl_balance.core.function_pointers`)
that calls ``answer(kind, count)`` of the Python object registered under the integer handle
the view carries (:func:`exit_handle`). The kernel first writes what the query is about into
arrays the object owns (an :class:`ExitTarget`'s staging arrays, also fields of the view), so
the exit carries integers only. FCL on a non-convex pair goes out this way, and a checker
written in Python is called this way once per growth of a tree (an extension step, or all the
steps of a connect; a vectorized function once per iteration, both together) rather than once
per state. Nothing of an exit is compiled when it is
first taken: it costs the same in every process.

A check that raises (a user's function, FCL, a Ctrl-C in an exit) cannot raise through compiled
code: its kernel sets ``counts[Count.RAISED]`` and answers "not valid"; the engine stops at
once and has the object that kept the error raise it in Python (:func:`raise_kept`, for the
Python callers of the kernels).
"""

from __future__ import annotations

import ctypes
import enum
import functools
import importlib
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
    RAISED = 5  # 1 while a check has raised and the error is not yet reported (the engine raises it)


def new_counts() -> np.ndarray:
    """A zeroed work counter for a view, indexed by :class:`Count`."""
    return np.zeros(len(Count), dtype=np.int64)


def states_and_motions(counts: np.ndarray) -> tuple[int, int]:
    """The states and motions decided, read from a view's ``counts`` (:class:`Count`) at once: the
    work counters are read twice a solve, and one slice costs less than two numpy scalars."""
    states, motions = counts[Count.STATES : Count.MOTIONS + 1].tolist()
    return states, motions


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


def steps_free(view: Any, chain: np.ndarray, steps: int, outward: bool) -> int:
    """How many of the steps ``chain[0] -> chain[1] -> ... -> chain[steps]`` (flat states, rows of
    ``chain``) a tree can take before the first blocked one: ``steps`` when none is (compiled code only).

    Step ``k`` is checked as RRT-Connect grows a tree: ``outward`` (the start tree) as
    ``motion_free(chain[k - 1], chain[k])``; otherwise (the goal tree, whose motions run towards
    its root) as ``state_free(chain[k])`` then ``motion_free(chain[k], chain[k - 1])``. The steps
    are checked in order and the checks stop at the first blocked step, so the states tested and
    counted are those of checking the steps one by one. A view may check them all at once (one
    exit to Python for the lot: :mod:`ompl_balance.core.exit_check_kernels`); any other view checks
    them one by one with its ``state_free`` and ``motion_free``.
    """
    raise TypeError("steps_free is a compiled kernel: call it from numba-compiled code with a checker's view")


#: What :func:`growth_free` answers when the extension itself is blocked.
EXTENSION_BLOCKED = -1


def growth_free(
    view: Any, extension: np.ndarray, extension_outward: bool, chain: np.ndarray, steps: int, outward: bool
) -> int:
    """An iteration's growth checked at once (compiled code only): one tree's extension step
    ``extension[0] -> extension[1]`` (``extension_outward``: the start tree's), then, when it is
    free, the other tree's connect steps ``chain[0] -> ... -> chain[steps]`` towards
    ``extension[1]`` (``outward``), each checked as :func:`steps_free` checks a step. Returns how
    many of the connect's steps are free, or :data:`EXTENSION_BLOCKED`.

    The checks stop at the first blocked step, so the states tested and counted are those of
    checking the extension and then the connect step by step. A view may check them all in one
    exit to Python (:mod:`ompl_balance.core.exit_check_kernels`); any other view checks the
    extension, then the connect's steps, with its :func:`steps_free`.
    """
    raise TypeError("growth_free is a compiled kernel: call it from numba-compiled code with a checker's view")


_TARGETS: dict[int, weakref.ref[Any]] = {}  # handle -> object, held weakly (its entry leaves with it)
_HANDLE_OF: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()  # object -> handle
_HANDLES = itertools.count(1)


def exit_handle(target: Any) -> int:
    """The handle by which compiled code reaches ``target`` through the exit (:data:`EXIT_ADDRESS`):
    one per object, held weakly, so registering keeps nothing alive."""
    handle = _HANDLE_OF.get(target)
    if handle is None:
        handle = next(_HANDLES)
        _TARGETS[handle] = weakref.ref(target, functools.partial(_forget, handle))
        _HANDLE_OF[target] = handle
    return handle


def _forget(handle: int, reference: weakref.ref[Any]) -> None:
    _TARGETS.pop(handle, None)


#: C signature of an exit: ``int64 exit(int64 handle, int64 kind, int64 count)``.
EXIT_SIGNATURE = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_int64, ctypes.c_int64, ctypes.c_int64)


def _exit(handle: int, kind: int, count: int) -> int:
    """The exit's Python side: ``answer(kind, count)`` of the object behind ``handle``, or -1 with
    the error kept in the object's ``error`` when it raised (an error cannot cross compiled code).
    (Hot: a solve with a Python checker makes one exit per tree growth, so the lookup is inline.)"""
    target = _TARGETS[handle]()
    if target is None:
        raise KeyError(handle)
    try:
        return target.answer(kind, count)
    except BaseException as error:
        target.error = error
        return -1


class ExitTarget:
    """An object compiled code asks through the exit: its ``answer(kind, count)`` reads the query
    from arrays it owns, which the kernel filled; an error it raises is kept in :attr:`error`
    (the exit returns -1, the kernel sets ``counts[Count.RAISED]``) and raised by
    :meth:`raise_error` once the compiled code has returned."""

    error: BaseException | None = None

    def answer(self, kind: int, count: int) -> int:
        raise NotImplementedError

    def raise_error(self) -> None:
        """Raise the error an exit kept, forgetting it (nothing when none was kept)."""
        error, self.error = self.error, None
        if error is not None:
            raise error


def raise_kept(counts: np.ndarray, *targets: ExitTarget) -> None:
    """After a Python call of compiled kernels that exit to ``targets`` and count in ``counts``:
    when a kernel met an error (``counts[Count.RAISED]``), clear the flag and raise the error the
    target kept."""
    if counts[Count.RAISED]:
        counts[Count.RAISED] = 0
        for target in targets:
            target.raise_error()
        raise RuntimeError("a check failed in compiled code and left no error to report")


_EXIT = EXIT_SIGNATURE(_exit)  # kept for the life of the process
#: Address of the exit (a C function pointer), for views to carry.
EXIT_ADDRESS: int = ctypes.cast(_EXIT, ctypes.c_void_p).value or 0


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


def load_kernels(view: Any) -> None:
    """Import the modules of the kernels of ``view`` and of the views inside it (registering them
    with numba), as compiled code that takes ``view`` needs before it is compiled."""
    for module in kernel_modules(view):
        importlib.import_module(module)
