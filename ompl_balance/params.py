"""OMPL's parameter introspection (``ompl::base::ParamSet``) for Python planners.

OMPL 2.0's ``Planner.params()`` cannot be used from Python (its ``ParamSet`` is not
bound), so the planners of this package carry this one. It keeps OMPL's semantics:

* every value is set and read as a string (``setParam("range", "0.5")``);
* booleans are written ``"0"``, ``"1"``, ``"true"`` or ``"false"`` and read ``"0"``/``"1"``;
* each parameter has a range suggestion, ``"lo:step:hi"`` for numbers and a comma list
  (``"0,1"``, ``"alternate,balance_nodes"``) for choices;
* a bad name or value makes ``setParam`` return ``False`` and log an OMPL error that
  names the parameter and what it accepts; the planner is left unchanged.

Setters given to :meth:`ParamSet.declareParam` validate their own domain by raising
``ValueError`` (a negative ratio, say); that error text goes into the log message.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ompl import util as ou

_TRUE = ("1", "true")
_FALSE = ("0", "false")


def _parse_bool(text: str) -> bool:
    lowered = text.strip().lower()
    if lowered in _TRUE:
        return True
    if lowered in _FALSE:
        return False
    raise ValueError("expected one of 0, 1, true, false")


def _parse_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError("expected a finite number")
    return value


def _parse_int(text: str) -> int:
    return int(text.strip())


def _format(value: Any) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    return str(value)


@dataclass
class _Param:
    name: str
    setter: Callable[[Any], None]
    getter: Callable[[], Any]
    parse: Callable[[str], Any]
    range_suggestion: str
    choices: tuple[str, ...] | None


_PARSERS: dict[type, Callable[[str], Any]] = {bool: _parse_bool, int: _parse_int, float: _parse_float, str: str}


class ParamSet:
    """A named set of planner parameters, set and read as strings as in OMPL."""

    def __init__(self) -> None:
        self._params: dict[str, _Param] = {}

    def declareParam(  # noqa: N802 (OMPL's name)
        self,
        name: str,
        setter: Callable[[Any], None],
        getter: Callable[[], Any],
        range_suggestion: str = "",
        value_type: type | None = None,
        choices: tuple[str, ...] | None = None,
    ) -> None:
        """Declare parameter ``name``.

        ``value_type`` (``bool``, ``int``, ``float`` or ``str``) decides how strings
        are parsed; by default it is the type of ``getter()``'s current value. With
        ``choices``, only those strings are accepted and the range suggestion is
        their comma list.
        """
        if value_type is None:
            value_type = type(getter())
        if value_type not in _PARSERS:
            raise TypeError(f"parameter {name!r}: unsupported type {value_type.__name__}; use bool, int, float or str")
        if choices is not None:
            range_suggestion = ",".join(choices)
        elif value_type is bool and not range_suggestion:
            range_suggestion = "0,1"
        self._params[name] = _Param(name, setter, getter, _PARSERS[value_type], range_suggestion, choices)

    def setParam(self, name: str, value: Any) -> bool:  # noqa: N802
        """Set ``name`` from its string form; ``False`` (and an OMPL error) if refused."""
        param = self._params.get(name)
        if param is None:
            known = ", ".join(sorted(self._params))
            ou.OMPL_ERROR(f"Unknown parameter '{name}'. Known parameters: {known}")
            return False
        text = _format(value)
        try:
            if param.choices is not None and text not in param.choices:
                raise ValueError(f"expected one of {', '.join(param.choices)}")
            param.setter(param.parse(text))
        except ValueError as error:
            accepted = f" (range suggestion '{param.range_suggestion}')" if param.range_suggestion else ""
            ou.OMPL_ERROR(f"Invalid value '{text}' for parameter '{name}': {error}{accepted}")
            return False
        return True

    def setParams(self, values: Mapping[str, Any], ignore_unknown: bool = False) -> bool:  # noqa: N802
        """Set several parameters; ``True`` only if all were set.

        As in OMPL, each entry is tried on its own: a refused entry does not stop the
        others. With ``ignore_unknown``, names this set does not have are skipped.
        """
        all_set = True
        for name, value in values.items():
            if ignore_unknown and name not in self._params:
                continue
            all_set = self.setParam(name, value) and all_set
        return all_set

    def getParam(self, name: str) -> str:  # noqa: N802
        """The current value of ``name`` as a string; ``KeyError`` if unknown."""
        if name not in self._params:
            raise KeyError(f"unknown parameter {name!r}; known: {', '.join(sorted(self._params))}")
        return _format(self._params[name].getter())

    def getParams(self) -> dict[str, str]:  # noqa: N802
        """Every parameter's current value, as strings."""
        return {name: _format(param.getter()) for name, param in self._params.items()}

    def hasParam(self, name: str) -> bool:  # noqa: N802
        return name in self._params

    def getParamNames(self) -> list[str]:  # noqa: N802
        return list(self._params)

    def getRangeSuggestion(self, name: str) -> str:  # noqa: N802
        """OMPL's range suggestion of ``name`` (``"lo:step:hi"`` or a comma list)."""
        if name not in self._params:
            raise KeyError(f"unknown parameter {name!r}; known: {', '.join(sorted(self._params))}")
        return self._params[name].range_suggestion

    def __contains__(self, name: str) -> bool:
        return name in self._params

    def __len__(self) -> int:
        return len(self._params)

    def __repr__(self) -> str:
        return "ParamSet(" + ", ".join(f"{k}={v}" for k, v in self.getParams().items()) + ")"
