"""Registering a view's compiled kernels as :func:`~ompl_balance.core.checks.state_free`,
:func:`~ompl_balance.core.checks.motion_free`, :func:`~ompl_balance.core.checks.steps_free` and
:func:`~ompl_balance.core.checks.growth_free` (imports numba: only kernel modules use it)."""

from __future__ import annotations

import functools
from typing import Any

from numba import types
from numba.core.imputils import lower_builtin
from numba.core.typing import signature
from numba.extending import type_callable

from .checks import EXTENSION_BLOCKED, growth_free, motion_free, state_free, steps_free
from .kernel_cache import njit_borrowing

#: ``(state_free, motion_free, steps_free or growth_free; a view class)`` -> the view's compiled kernel for it
_KERNELS: dict[tuple[Any, type | None], Any] = {}


def register_kernels(
    view_class: type, state: Any = None, motion: Any = None, steps: Any = None, growth: Any = None
) -> None:
    """Make compiled ``state(view, q)``, ``motion(view, a, b)``, ``steps(view, chain, steps,
    outward)`` and ``growth(view, extension, extension_outward, chain, steps, outward)`` (numba
    functions) the ``state_free``, ``motion_free``, ``steps_free`` and ``growth_free`` of views of
    ``view_class`` (a named tuple class). ``state`` may instead name a field of the view that
    holds the view whose ``state_free`` checks its states (a motion view's ``"states"``). Without
    ``steps`` the view's steps are checked one by one with its ``state_free`` and ``motion_free``;
    without ``growth``, the extension and then the connect with its ``steps_free``.

    A call of ``state_free(view, q)`` in compiled code is compiled as a call of ``state(view, q)``
    itself (of the named field's kernel with the field). Not through a function of numba's
    ``overload`` that calls it: numba compiles such a function on its own, and optimizes and
    emits the machine code of everything it calls again (a robot's certified kernels: 3.5 s of the
    first compilation). Nor inlined in numba's IR: the loop calls them in many places, and numba
    types every inlined copy again (the box world's engine compiled in 46 s inlined, 28 s not).
    LLVM still inlines the calls where it pays.
    """
    for function, kernel in ((state_free, state), (motion_free, motion), (steps_free, steps), (growth_free, growth)):
        if kernel is not None:
            _KERNELS[function, view_class] = kernel


def _kernel(function: Any, view: Any) -> Any:
    """What a call of ``function`` with a view of numba type ``view`` calls: its compiled kernel, the
    name of the view's field to call it with, or ``None``."""
    view_class = getattr(view, "instance_class", None) if isinstance(view, types.BaseNamedTuple) else None
    kernel = _KERNELS.get((function, view_class))
    if kernel is None and (state_free, view_class) in _KERNELS:
        if function is steps_free:
            return steps_one_by_one
        if function is growth_free:
            return growth_in_turn
    return kernel


@njit_borrowing
def steps_one_by_one(view: Any, chain: Any, steps: int, outward: bool) -> int:  # pragma: no cover (compiled)
    """``steps_free`` of a view without a kernel of its own: one step at a time."""
    for k in range(1, steps + 1):
        if outward:
            free = motion_free(view, chain[k - 1], chain[k])
        else:
            free = state_free(view, chain[k]) and motion_free(view, chain[k], chain[k - 1])
        if not free:
            return k - 1
    return steps


@njit_borrowing
def growth_in_turn(
    view: Any, extension: Any, extension_outward: bool, chain: Any, steps: int, outward: bool
) -> int:  # pragma: no cover (compiled)
    """``growth_free`` of a view without a kernel of its own: the extension, then the connect's steps."""
    if steps_free(view, extension, 1, extension_outward) == 0:
        return EXTENSION_BLOCKED
    return steps_free(view, chain, steps, outward) if steps > 0 else 0


def _typed(function: Any, context: Any, arguments: tuple[Any, ...]) -> Any:
    """The signature of ``function(*arguments)``: its view's kernel's (compiled now if need be)."""
    view, kernel = arguments[0], _kernel(function, arguments[0])
    if isinstance(kernel, str):  # (the kernel of the view in that field)
        field = _typed(function, context, (view[view.fields.index(kernel)], *arguments[1:]))
        return None if field is None else signature(field.return_type, view, *field.args[1:])
    if kernel is None:
        return None
    return context.resolve_function_type(types.Dispatcher(kernel), arguments, {})


@type_callable(state_free)
def _state_typing(context: Any) -> Any:
    return lambda view, q: _typed(state_free, context, (view, q))


@type_callable(motion_free)
def _motion_typing(context: Any) -> Any:
    return lambda view, a, b: _typed(motion_free, context, (view, a, b))


@type_callable(steps_free)
def _steps_typing(context: Any) -> Any:
    return lambda view, chain, steps, outward: _typed(steps_free, context, (view, chain, steps, outward))


def _call_kernel(function: Any, context: Any, builder: Any, called: Any, arguments: Any) -> Any:
    """A call of ``function`` (``state_free``, ...) lowered as a call of its view's kernel."""
    view, kernel = called.args[0], _kernel(function, called.args[0])
    if isinstance(kernel, str):
        index = view.fields.index(kernel)
        field = signature(called.return_type, view[index], *called.args[1:])
        return _call_kernel(
            function, context, builder, field, (builder.extract_value(arguments[0], index), *arguments[1:])
        )
    return context.get_function(types.Dispatcher(kernel), called)(builder, arguments)


@type_callable(growth_free)
def _growth_typing(context: Any) -> Any:
    return lambda view, extension, extension_outward, chain, steps, outward: _typed(
        growth_free, context, (view, extension, extension_outward, chain, steps, outward)
    )


for _function, _arity in ((state_free, 2), (motion_free, 3), (steps_free, 4), (growth_free, 6)):
    lower_builtin(_function, *(types.Any,) * _arity)(functools.partial(_call_kernel, _function))
