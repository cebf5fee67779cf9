"""A numpy ``Generator``'s uniform numbers drawn from compiled code, without passing the generator.

numba accepts a ``np.random.Generator`` as an argument, but converting one from Python costs
some 10 microseconds a call and several times that the first time a generator is passed (numba
rebuilds the bit generator's ctypes interface), which a solve of a few iterations would pay
in full. The engine passes the address of the generator's ``bitgen_t`` instead (numpy's C
interface to its bit generator, read once a solve from the generator's ``capsule``), and
:func:`next_double` calls the bit generator's ``next_double``: the numbers, in their order,
that ``Generator.random()`` gives, from the same state, which it advances.

The address is valid while the generator lives: whoever passes it keeps the generator.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from typing import Any, cast

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

_capsule_pointer = ctypes.pythonapi.PyCapsule_GetPointer
_capsule_pointer.restype = ctypes.c_void_p
_capsule_pointer.argtypes = [ctypes.py_object, ctypes.c_char_p]

#: Where ``next_double`` is in numpy's ``bitgen_t`` (``state``, ``next_uint64``, ``next_uint32``,
#: ``next_double``, ``next_raw``: a pointer each), in pointers from its start.
_NEXT_DOUBLE = 3


def bit_generator_address(rng: np.random.Generator) -> int:
    """The address of ``rng``'s ``bitgen_t`` (valid while ``rng`` lives), for :func:`next_double`."""
    address = _capsule_pointer(rng.bit_generator.capsule, b"BitGenerator")
    if not address:
        raise ValueError("the generator's bit generator has no C interface (a numpy BitGenerator is needed)")
    return int(address)


@intrinsic
def _next_double(typingctx: Any, address: Any) -> Any:
    """numba's typing and code of :data:`next_double`: ``(int64) -> float64``, one call of the
    bit generator's ``next_double(state)``."""

    def codegen(context: Any, builder: Any, signature: Any, arguments: Any) -> Any:
        pointer = ir.IntType(8).as_pointer()
        generator = builder.inttoptr(arguments[0], pointer.as_pointer())  # bitgen_t as void *[5]
        state = builder.load(generator)
        function_type = ir.FunctionType(ir.DoubleType(), [pointer])
        slot = builder.gep(generator, [ir.Constant(ir.IntType(32), _NEXT_DOUBLE)])
        function = builder.bitcast(builder.load(slot), function_type.as_pointer())
        return builder.call(function, [state])

    return types.float64(types.int64), codegen


#: ``next_double(address)``: the next uniform number in [0, 1) of the bit generator at
#: ``address`` (:func:`bit_generator_address`), as ``Generator.random()`` (compiled code only).
next_double = cast(Callable[[int], float], _next_double)
