"""Calling C functions by their address from compiled code: a user's compiled checker, and Python.

Two kinds of function are called this way, each with one fixed C signature, so that the
compiled engine is compiled once for every function of that kind (the address is a value
the engine is given, not part of its type):

* a **state function**, ``int8 check(const double *q, intptr_t dim)``: 1 when the state ``q``
  (``dim`` reals in the flat layout of :mod:`ompl_balance.core.layout`) is valid, 0 when it is
  not, -1 when the check raised. A user's numba function, wrapped in a numba ``cfunc``
  (:mod:`ompl_balance.checking.functions`), is one;
* an **exit**, ``int64 exit(int64 handle, int64 kind, int64 count)``: a Python callback
  (:data:`~ompl_balance.core.checks.EXIT_ADDRESS`, a ``ctypes`` callback made once per process) that calls the method
  ``answer(kind, count)`` of the object registered under ``handle``
  (:func:`~ompl_balance.core.checks.exit_handle`) and returns its answer; when ``answer``
  raises, the error goes to the object's ``error`` attribute and the exit returns -1 (the
  object reports it once the compiled code has returned). A ``ctypes`` callback costs some
  0.1 us over the Python call itself, a tenth of numba's ``objmode`` (about 1 us), and a
  ``KeyboardInterrupt`` raised inside it is kept and reported like any error.

Both are called through :func:`call_state_function` and :func:`call_exit`, numba intrinsics
that turn the address into a function pointer of the fixed signature and call it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, cast

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .checks import Count
from .kernel_cache import njit_borrowing


def _state_function_typing(typingctx: Any, address: Any, q: Any) -> Any:
    """``check(q.ctypes.data, q.size)`` for the state function at ``address`` (an integer), ``q`` a
    contiguous float64 array: 1 valid, 0 not valid, -1 raised (compiled code only)."""
    if not (isinstance(address, types.Integer) and isinstance(q, types.Array) and q.dtype == types.float64):
        return None
    signature = types.int8(address, q)

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        address_value, array_value = args
        array = context.make_array(sig.args[1])(context, builder, array_value)
        function_type = ir.FunctionType(ir.IntType(8), [ir.DoubleType().as_pointer(), cgutils.intp_t])
        function = builder.inttoptr(address_value, function_type.as_pointer())
        return builder.call(function, [array.data, array.nitems])

    return signature, codegen


def _exit_typing(typingctx: Any, address: Any, handle: Any, kind: Any, count: Any) -> Any:
    """``exit(handle, kind, count)`` for the exit at ``address`` (integers; compiled code only)."""
    arguments = (address, handle, kind, count)
    if not all(isinstance(argument, types.Integer) for argument in arguments):
        return None
    signature = types.int64(*arguments)

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        int64 = ir.IntType(64)
        function_type = ir.FunctionType(int64, [int64, int64, int64])
        function = builder.inttoptr(args[0], function_type.as_pointer())
        values = [context.cast(builder, value, ty, types.int64) for value, ty in zip(args[1:], sig.args[1:])]
        return builder.call(function, values)

    return signature, codegen


#: ``call_state_function(address, q) -> int8`` (compiled code only; see :func:`_state_function_typing`).
call_state_function = cast(Callable[[int, Any], int], intrinsic(_state_function_typing))
#: ``call_exit(address, handle, kind, count) -> int64`` (compiled code only; see :func:`_exit_typing`).
call_exit = cast(Callable[[int, int, int, int], int], intrinsic(_exit_typing))


@njit_borrowing
def counted_exit(counts: Any, address: int, handle: int, kind: int, count: int) -> int:  # pragma: no cover (compiled)
    """:func:`call_exit`, counted in ``counts[Count.EXITS]`` (a view's counts, indexed by
    :class:`~ompl_balance.core.checks.Count`): the exit's answer, -1 with ``counts[Count.RAISED]``
    set when the target raised."""
    counts[Count.EXITS] += 1
    answer = call_exit(address, handle, kind, count)
    if answer < 0:
        counts[Count.RAISED] = 1
    return answer
