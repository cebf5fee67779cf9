"""Objects that OMPL holds from C++ let go of what they reference when the interpreter exits.

A planner, state validity checker or motion validator written in Python is kept alive by OMPL's
C++ side (a ``SimpleSetup`` holds its planner, a space information its checker), a reference
Python's garbage collector cannot see. Where such an object references a script's globals (a
validity function defined in the script does, through its ``__globals__``), and the globals
hold the ``SimpleSetup``, the objects form a cycle that only the interpreter's last collection
breaks, after nanobind has looked for objects still alive: it reports them as leaks, tens of
lines after the script's own output. :func:`release_at_exit` registers such an object; when the
interpreter exits (before it takes the modules down), each one still alive drops its attributes,
so that the script's globals free everything in order. An exit handler that another part of the
program registered before importing the package runs after this one and finds them emptied.
"""

from __future__ import annotations

import atexit
import weakref
from typing import Any

_HELD: weakref.WeakSet[Any] = weakref.WeakSet()


def release_at_exit(held: Any) -> None:
    """Have ``held`` (an object OMPL holds from C++) drop its attributes when the interpreter exits."""
    _HELD.add(held)


def _release() -> None:
    for held in list(_HELD):
        vars(held).clear()


atexit.register(_release)
