"""A user's validity function of a state's coordinates: which kind it is, and how it is called.

:func:`check_function` takes what :func:`~ompl_balance.checking.setup_checker` is given and
returns a :class:`CheckFunction`, one of four kinds (:data:`KINDS`):

``numba``
    a ``numba.njit`` function ``fn(q) -> bool`` of a 1-D float64 array: compiled once more
    inside a C wrapper (a numba ``cfunc`` that catches what it raises), whose address the
    compiled engine calls for every state, with no Python in between;
``cfunc``
    a numba ``cfunc`` of signature ``boolean(CPointer(float64), intp)`` (the state's values and
    their number): the engine calls its address as it is (a ``cfunc`` cannot report an error);
``vectorized``
    ``fn(Q) -> (n,) bools`` of an ``(n, d)`` float64 array: called once per iteration of the
    loop (its extension step, then all the steps of the connect after it) with every state
    OMPL's discrete rule would test;
``python``
    any other callable ``fn(q) -> bool`` of a 1-D float64 array: called once per state, from
    one call into Python per growth of a tree (an extension step; all the steps of a connect).

``q`` holds the state's values in the flat layout of :mod:`ompl_balance.core.layout` (OMPL's
``copyFromReals`` order). A function's error reaches the caller as a :class:`CheckerError`
naming the function and the state, whichever engine or planner asked.
"""

from __future__ import annotations

import ctypes
import inspect
import math
from typing import Any, NoReturn

import numpy as np

from ..core.checks import Count
from ..core.exit_checks import Query, row_chunks
from .views import FunctionStates

#: The kinds of function (see the module docstring).
KINDS = ("numba", "cfunc", "vectorized", "python")

_STATES = int(Query.STATES)
_C_CHECK = ctypes.CFUNCTYPE(ctypes.c_int8, ctypes.POINTER(ctypes.c_double), ctypes.c_ssize_t)


class CheckerError(RuntimeError):
    """A user's validity function raised (the original error is the ``__cause__``)."""


def describe(function: Any) -> str:
    """A function's name as messages give it (``module.qualname``)."""
    target = getattr(function, "py_func", None) or getattr(function, "__wrapped__", None) or function  # (njit; cfunc)
    name = getattr(target, "__qualname__", None) or type(function).__name__
    module = getattr(target, "__module__", None)
    return name if module in (None, "__main__", "builtins") else f"{module}.{name}"


class CheckFunction:
    """A user's validity function of a state's coordinates, and its calls counted in ``counts``.

    Parameters
    ----------
    function:
        What the user gave (see the module docstring for the kinds).
    dim:
        Reals in a state of the space (``q.shape == (dim,)``).
    vectorized:
        ``function`` takes an ``(n, dim)`` array and returns ``n`` booleans.

    Attributes
    ----------
    kind:
        One of :data:`KINDS`.
    address:
        The C state function the compiled engine calls (``numba`` and ``cfunc`` kinds; 0 otherwise),
        ``int8 check(const double *q, intptr_t dim)``: 1 valid, 0 not, -1 raised.
    counts:
        The work counter the checker, its motion validator and their compiled views share
        (:class:`~ompl_balance.core.checks.Count`).
    failed:
        ``(dim,)``: the state at which a compiled check last raised.
    error:
        An error raised while compiled code waited for Python (an exit's), until reported.
    """

    def __init__(self, function: Any, dim: int, vectorized: bool = False) -> None:
        if not callable(function):
            raise TypeError(
                f"setup_checker: fn must be a function of a state's coordinates (a Python function, a numba "
                f"njit function or cfunc), got {type(function).__name__}"
            )
        self.function = function
        self.name = describe(function)
        self.dim = dim
        self.kind = _kind(function, vectorized)
        self.counts = np.zeros(len(Count), dtype=np.int64)
        self.failed = np.zeros(dim)
        self.error: BaseException | None = None
        self.rows = np.empty((0, dim))  # an exit's rows (its view's, set when the view is made)
        self.address = 0
        self._c_check: Any = None  # the C state function, callable from Python (compiled kinds)
        self._keep: Any = None  # the wrapper cfunc of a numba function (owns its machine code)
        if self.kind == "cfunc":
            _check_cfunc_signature(function, self.name)
            self.address = int(function.address)
        elif self.kind == "numba":
            _check_arity(function.py_func, self.name)
            self._keep = _wrapped(function, self.name)
            self.address = int(self._keep.address)
        else:
            _check_arity(function, self.name)
        if self.address:
            self._c_check = _C_CHECK(self.address)

    def states_view(self) -> FunctionStates:
        """The function as compiled code calls it (``numba`` and ``cfunc`` kinds: ``address`` set)."""
        return FunctionStates(self.address, np.empty(self.dim), self.failed, self.counts)

    # -- from Python: one state, a motion's states ------------------------------------------------

    def check(self, q: np.ndarray) -> bool:
        """Whether state ``q`` (dim,) is valid (not counted); an error is raised as a :class:`CheckerError`."""
        try:
            if self.kind == "vectorized":
                return bool(self._vectorized(q.reshape(1, -1))[0])
            if self._c_check is not None and self.kind == "cfunc":
                return self._c_check(q.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), q.shape[0]) == 1
            return self._answer(self.function(q))
        except CheckerError:
            raise
        except Exception as error:
            raise CheckerError(
                f"the validity function {self.name} raised {_error_text(error)} at state {_text(q)}"
            ) from error

    def first_invalid(self, states: np.ndarray) -> int:
        """The index of the first invalid state of ``states`` (n, dim) in order, ``n`` when all are
        valid; counts the states tested (all up to the first invalid one, as OMPL's rule tests them)."""
        first = self._first_invalid(states)
        self.counts[Count.STATES] += min(first + 1, len(states))
        return first

    # -- from compiled code: the exit's target ------------------------------------------------------

    def answer(self, kind: int, count: int) -> int:
        """The exit's answer (:class:`~ompl_balance.core.exit_checks.ExitChecks`, kind ``STATES``): the
        first invalid of ``rows[:count]`` (the compiled caller counts the states)."""
        return self._first_invalid(self.rows[:count])

    def _first_invalid(self, states: np.ndarray) -> int:
        count = len(states)
        if self.kind != "vectorized":
            for index in range(count):
                if not self.check(states[index]):
                    return index
            return count
        for first, last in row_chunks(count):
            try:
                valid = self._vectorized(states[first:last])
            except CheckerError:
                raise
            except Exception as error:
                raise CheckerError(
                    f"the validity function {self.name} raised {_error_text(error)} on {last - first} states"
                ) from error
            invalid = np.flatnonzero(~valid)
            if len(invalid):
                return first + int(invalid[0])
        return count

    def raise_error(self) -> NoReturn:
        """Raise the error compiled code met: an exit's (``error``) or that of the compiled check at
        ``failed``, called again from Python; a ``KeyboardInterrupt`` is raised as it is."""
        error, self.error = self.error, None
        self.counts[Count.RAISED] = 0
        if error is not None:
            if not isinstance(error, Exception) or isinstance(error, CheckerError):
                raise error
            raise CheckerError(f"the validity function {self.name} raised {_error_text(error)}") from error
        state = self.failed.copy()
        if self.kind == "numba":
            self.check(state)  # raises the function's error as Python sees it
        raise CheckerError(f"the validity function {self.name} raised in compiled code at state {_text(state)}")

    # -- answers --------------------------------------------------------------------------------------

    def _answer(self, valid: Any) -> bool:
        if valid is True or valid is False:
            return valid
        if isinstance(valid, np.bool_):
            return bool(valid)
        raise CheckerError(
            f"the validity function {self.name} returned {_short(valid)} ({type(valid).__name__}); "
            "it must return True or False (a numpy bool too)"
        )

    def _vectorized(self, states: np.ndarray) -> np.ndarray:
        valid = self.function(states)
        if not isinstance(valid, np.ndarray) or valid.shape != (len(states),) or valid.dtype != np.bool_:
            got = (
                f"an array of shape {valid.shape} and dtype {valid.dtype}"
                if isinstance(valid, np.ndarray)
                else f"{type(valid).__name__}"
            )
            raise CheckerError(
                f"the vectorized validity function {self.name} returned {got} for {len(states)} states; "
                f"it must return a bool array of shape ({len(states)},)"
            )
        return valid


def _kind(function: Any, vectorized: bool) -> str:
    from numba.core.ccallback import CFunc
    from numba.core.dispatcher import Dispatcher

    if isinstance(function, CFunc):
        if vectorized:
            raise TypeError("setup_checker: a cfunc checks one state; vectorized=True takes a numpy function of (n, d)")
        return "cfunc"
    if isinstance(function, Dispatcher):
        if vectorized:
            raise TypeError(
                "setup_checker: vectorized=True takes a numpy function of an (n, d) array, not a numba function "
                "(whose per-state calls the compiled engine makes without Python)"
            )
        return "numba"
    return "vectorized" if vectorized else "python"


def _check_arity(function: Any, name: str) -> None:
    """A one-line error unless ``function`` can be called with one positional argument."""
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):  # a builtin or an object without one: its call will tell
        return
    try:
        signature.bind(None)
    except TypeError:
        raise TypeError(
            f"setup_checker: {name}{signature} must take one argument, the state's coordinates "
            "(or, with vectorized=True, an (n, d) array of states)"
        ) from None


def _check_cfunc_signature(function: Any, name: str) -> None:
    from numba import types

    signature = function._sig  # (numba's record of a cfunc's signature)
    expected = (types.CPointer(types.float64), types.intp)
    if tuple(signature.args) != expected or signature.return_type not in (types.boolean, types.int8):
        raise TypeError(
            f"setup_checker: the cfunc {name} has signature {signature}; a cfunc checker has "
            "boolean(CPointer(float64), intp): the state's values and their number"
        )


#: The attribute of a numba function holding its C wrapper (:func:`_wrapped`), made once per function.
_WRAPPER = "_ompl_balance_state_function"


def _wrapped(function: Any, name: str) -> Any:
    """A C wrapper of numba function ``function`` (see :class:`CheckFunction`'s ``address``): its
    error is caught (-1) rather than lost in C, and its return type must be a boolean. Compiled
    once per function (it takes about as long as the function's own compilation) and kept on the
    function, so that a checker set up again with the same function costs nothing."""
    made = getattr(function, _WRAPPER, None)
    if made is None:
        made = _compile_wrapper(function, name)
        setattr(function, _WRAPPER, made)  # (a reference cycle through the wrapper: collected with it)
    return made


def _compile_wrapper(function: Any, name: str) -> Any:
    from numba import carray, cfunc, types
    from numba.core.errors import NumbaError

    array = types.Array(types.float64, 1, "C")
    try:
        function.compile((array,))
        return_type = function.overloads[(array,)].signature.return_type
    except NumbaError as error:
        first_line = str(error).strip().splitlines()[0]
        raise TypeError(f"setup_checker: numba cannot compile {name} for a float64 array: {first_line}") from None
    except RuntimeError:  # numba compiles it for the signatures it was given only (njit with a signature)
        return_type = _given_signature(function, name, array).return_type
    if not isinstance(return_type, types.Boolean):
        raise TypeError(f"setup_checker: {name} returns {return_type}; a validity function returns a bool")

    @cfunc(types.int8(types.CPointer(types.float64), types.intp))
    def check(values: Any, dim: int) -> int:  # pragma: no cover (compiled)
        q = carray(values, (dim,))
        try:
            return 1 if function(q) else 0
        except Exception:
            return -1

    return check


def _given_signature(function: Any, name: str, array: Any) -> Any:
    """The signature, among those ``function`` was compiled for (``njit`` given signatures), that a
    C-contiguous 1-D float64 ``array`` can be passed to; a one-line error when there is none."""
    from numba import types

    for args, compiled in function.overloads.items():
        if len(args) == 1 and isinstance(args[0], types.Array):
            given = args[0]
            if given.dtype == array.dtype and given.ndim == 1 and given.layout in ("C", "A"):
                return compiled.signature
    signatures = ", ".join(str(compiled.signature) for compiled in function.overloads.values()) or "none"
    raise TypeError(
        f"setup_checker: {name} is compiled for its own signatures only ({signatures}); a validity function "
        "takes a 1-D float64 array (float64[::1] or float64[:])"
    )


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _text(q: np.ndarray) -> str:
    return "[" + ", ".join(f"{value:.6g}" if math.isfinite(value) else str(value) for value in q.tolist()) + "]"


def _error_text(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}" if str(error) else type(error).__name__
