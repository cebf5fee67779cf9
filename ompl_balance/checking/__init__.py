"""Your own validity checker, at compiled speed: :func:`setup_checker`.

Most OMPL users write their validity checker themselves. :func:`setup_checker` installs one
written as a function of a state's coordinates, ``fn(q) -> bool`` with ``q`` a 1-D float64
array in OMPL's ``copyFromReals`` order (the flat layout of :mod:`ompl_balance.core.layout`):

==========================  ======================================================
space                       ``q``
==========================  ======================================================
``RealVectorStateSpace(n)``  the ``n`` coordinates
``SO2StateSpace``            ``(angle,)``, in ``[-pi, pi)``
``SO3StateSpace``            ``(x, y, z, w)``, a unit quaternion
``SE2StateSpace``            ``(x, y, yaw)``
``SE3StateSpace``            ``(x, y, z, qx, qy, qz, qw)``
``CompoundStateSpace``       its subspaces' values, one after the other
==========================  ======================================================

It installs a state validity checker and a motion validator (OMPL's discrete rule: the same
states in the same order as ``DiscreteMotionValidator``). The kinds of function, and what the
package's planners do with each (:mod:`ompl_balance.checking.functions`):

* a numba function (``@numba.njit``) or ``cfunc``: the compiled engine calls it for every
  state with no Python in between, and is not compiled again for a new function;
* ``vectorized=True``, a numpy function of an ``(n, d)`` array returning ``n`` booleans: called
  once per iteration of the loop (its extension step, then all the steps of the connect after
  it) with all the states OMPL's rule would test;
* any other Python function of ``q``: called for each state, from one call into Python per
  growth of a tree (an extension step; all the steps of a connect).

Stock planners call the same checker and validator (one call into Python per state, or per
motion for the validator). ``docs/checkers.md`` measures each kind.
"""

from __future__ import annotations

from typing import Any

from .adapters import FunctionMotionValidator, FunctionValidityChecker, layout_dimension, space_information
from .functions import KINDS, CheckerError, CheckFunction

__all__ = [
    "KINDS",
    "CheckFunction",
    "CheckerError",
    "FunctionMotionValidator",
    "FunctionValidityChecker",
    "setup_checker",
]


def setup_checker(
    target: Any, fn: Any, *, vectorized: bool = False
) -> tuple[FunctionValidityChecker, FunctionMotionValidator]:
    """Install ``fn``, a validity function of a state's coordinates, as the state validity checker
    and motion validator of ``target`` (a ``SpaceInformation`` or a geometric ``SimpleSetup``).

    Parameters
    ----------
    target:
        ``ob.SpaceInformation`` or ``og.SimpleSetup`` whose space has a flat layout (real-vector,
        SO(2), SO(3), SE(2), SE(3) and compounds of them) with its bounds set.
    fn:
        ``fn(q) -> bool``, ``q`` of shape ``(d,)`` (see the module docstring for its layout): a
        Python function, a ``numba.njit`` function, or a numba ``cfunc`` of signature
        ``boolean(CPointer(float64), intp)``; with ``vectorized=True``, ``fn(Q) -> (n,) bool``,
        ``Q`` of shape ``(n, d)``.
    vectorized:
        ``fn`` checks an ``(n, d)`` array of states at once.

    Returns
    -------
    The installed checker and validator (``counters()`` tells the states and motions checked).

    Raises
    ------
    TypeError, ValueError:
        ``fn`` is not a function of one argument, numba cannot compile it for a float64 array
        or it does not return a bool; the space has no flat layout or no bounds.
    """
    si = space_information(target)
    function = CheckFunction(fn, layout_dimension(si), vectorized)
    checker = FunctionValidityChecker(si, function)
    validator = FunctionMotionValidator(si, function, checker)
    si.setStateValidityChecker(checker)
    si.setMotionValidator(validator)
    return checker, validator
