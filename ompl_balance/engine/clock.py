"""A monotonic clock that compiled code reads: how the compiled loop knows its slice is over.

:func:`monotonic_ns` is a numba intrinsic that calls the C library's ``clock_gettime`` with
``CLOCK_MONOTONIC`` (POSIX: Linux and macOS; some 25 ns a call), so the loop can run for a
stated time rather than a stated number of iterations. Its values are only compared with each
other, never with Python's clocks (which need not read the same clock).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, cast

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

#: POSIX's id of the monotonic clock on this system (``time.CLOCK_MONOTONIC``: 1 on Linux, 6 on macOS).
_CLOCK_MONOTONIC = getattr(time, "CLOCK_MONOTONIC", 1)


@intrinsic
def _monotonic_ns(typingctx: Any) -> Any:
    """numba's typing and code of :data:`monotonic_ns`: ``() -> int64``, one ``clock_gettime`` call."""

    def codegen(context: Any, builder: Any, signature: Any, arguments: Any) -> Any:
        i32, i64 = ir.IntType(32), ir.IntType(64)
        timespec = ir.LiteralStructType([i64, i64])  # (tv_sec, tv_nsec): time_t and long, 64-bit
        clock_gettime = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(i32, [i32, timespec.as_pointer()]), "clock_gettime"
        )
        now = cgutils.alloca_once(builder, timespec)
        builder.call(clock_gettime, [ir.Constant(i32, _CLOCK_MONOTONIC), now])
        zero = ir.Constant(i32, 0)
        seconds = builder.load(builder.gep(now, [zero, zero]))
        nanoseconds = builder.load(builder.gep(now, [zero, ir.Constant(i32, 1)]))
        return builder.add(builder.mul(seconds, ir.Constant(i64, 1_000_000_000)), nanoseconds)

    return types.int64(), codegen


#: ``monotonic_ns()``: nanoseconds of the system's monotonic clock, as ``int64`` (compiled code only).
monotonic_ns = cast(Callable[[], int], _monotonic_ns)
