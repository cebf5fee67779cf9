"""Factories named in experiments: ``"module:function"`` references to the user's own code."""

from __future__ import annotations

import importlib
from collections.abc import Callable


def import_function(reference: str) -> Callable:
    """``"module:function"`` -> the function; ``ValueError`` saying what went wrong."""
    module_name, _, function_name = reference.partition(":")
    if not module_name or not function_name:
        raise ValueError(f"expected 'module:function', got {reference!r}")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise ValueError(f"cannot import module {module_name!r}: {error}") from error
    function = getattr(module, function_name, None)
    if not callable(function):
        raise ValueError(f"module {module_name!r} has no function {function_name!r}")
    return function
