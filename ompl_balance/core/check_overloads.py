"""Registering a view's compiled kernels as :func:`~ompl_balance.core.checks.state_free` and
:func:`~ompl_balance.core.checks.motion_free` (imports numba: only kernel modules use it)."""

from __future__ import annotations

from typing import Any

from numba import types
from numba.extending import overload

from .checks import motion_free, state_free


def register_kernels(view_class: type, state: Any = None, motion: Any = None) -> None:
    """Make compiled ``state(view, q)`` and ``motion(view, a, b)`` (numba functions) the
    ``state_free`` and ``motion_free`` of views of ``view_class`` (a named tuple class).

    Not inlined in numba's IR (``inline="always"``): the loop calls them in many places, and numba
    types every inlined copy again (the box world's engine compiled in 46 s inlined, 28 s not);
    LLVM still inlines the calls where it pays (the 2-D solves' times are the same either way).
    """

    def is_view(view: Any) -> bool:
        return isinstance(view, types.BaseNamedTuple) and getattr(view, "instance_class", None) is view_class

    if state is not None:

        def state_typing(view: Any, q: Any) -> Any:
            if not is_view(view):
                return None

            def implementation(view: Any, q: Any) -> Any:
                return state(view, q)

            return implementation

        overload(state_free)(state_typing)
    if motion is not None:

        def motion_typing(view: Any, a: Any, b: Any) -> Any:
            if not is_view(view):
                return None

            def implementation(view: Any, a: Any, b: Any) -> Any:
                return motion(view, a, b)

            return implementation

        overload(motion_free)(motion_typing)
