"""Registering a view's compiled kernels as :func:`~ompl_balance.core.checks.state_free`,
:func:`~ompl_balance.core.checks.motion_free` and :func:`~ompl_balance.core.checks.steps_free`
(imports numba: only kernel modules use it)."""

from __future__ import annotations

from typing import Any

from numba import types
from numba.extending import overload

from .checks import motion_free, state_free, steps_free

#: view class -> its own compiled ``steps(view, chain, steps, outward)``, where it has one
_STEPS_KERNELS: dict[type, Any] = {}


def register_kernels(view_class: type, state: Any = None, motion: Any = None, steps: Any = None) -> None:
    """Make compiled ``state(view, q)``, ``motion(view, a, b)`` and ``steps(view, chain, steps,
    outward)`` (numba functions) the ``state_free``, ``motion_free`` and ``steps_free`` of views
    of ``view_class`` (a named tuple class). Without ``steps`` the view's steps are checked one by
    one with its ``state_free`` and ``motion_free``.

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
    if steps is not None:
        _STEPS_KERNELS[view_class] = steps


@overload(steps_free)
def _steps_typing(view: Any, chain: Any, steps: Any, outward: Any) -> Any:
    """``steps_free`` of any view: its own kernel (:func:`register_kernels`), else one step at a time."""
    own = _STEPS_KERNELS.get(getattr(view, "instance_class", type(None)))
    if own is not None:

        def implementation(view: Any, chain: Any, steps: Any, outward: Any) -> Any:
            return own(view, chain, steps, outward)

        return implementation

    def one_by_one(view: Any, chain: Any, steps: Any, outward: Any) -> Any:
        for k in range(1, steps + 1):
            if outward:
                free = motion_free(view, chain[k - 1], chain[k])
            else:
                free = state_free(view, chain[k]) and motion_free(view, chain[k], chain[k - 1])
            if not free:
                return k - 1
        return steps

    return one_by_one
