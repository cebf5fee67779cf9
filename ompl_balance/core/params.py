"""Parameters: declared once per planner or sampler, seen the ways OMPL users expect.

A planner declares its parameters in one settings dataclass, each field made with
:func:`param` (default, meaning, accepted values)::

    @dataclass
    class RRTConnectSettings(Settings):
        range: float = param(0.0, "longest motion added in one step", low=0.0, suggestion="0.:1.:10000.")

Everything else follows from that table:

* the values, as typed attributes the planner reads (``planner.settings.range``);
* :class:`ParamSet` (``planner.params()``), OMPL's ``ompl::base::ParamSet`` in Python: values
  set and read as strings (``setParam("range", "0.5")``), booleans as ``0``/``1``/``true``/
  ``false``, range suggestions (``"lo:step:hi"``, or a comma list of choices), and a bad name or
  value answered with ``False`` and an OMPL error naming what is accepted, the planner unchanged;
* the camelCase accessors (``setRange``/``getRange``), generated onto the class by
  :func:`add_accessors` with docstrings from the table, so ``help()`` and tab completion show them;
* the validation and its messages (``range must be a number >= 0, got -1.0``).

OMPL 2.0's own ``Planner.params()`` cannot be used from Python (its ``ParamSet`` is not bound),
which is why the package carries this one.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Iterator, Mapping
from dataclasses import MISSING, Field, dataclass, field, fields
from functools import partial
from typing import IO, Any, ClassVar

from ompl import util as ou

_TRUE = ("1", "true")
_FALSE = ("0", "false")


def _format(value: Any) -> str:
    """OMPL's string form of a value (booleans ``0``/``1``)."""
    if isinstance(value, bool):
        return "1" if value else "0"
    return str(value)


@dataclass(frozen=True)
class Domain:
    """The values a parameter accepts.

    ``kind`` is ``bool``, ``int``, ``float`` or ``str``. Numbers lie in ``[low, high]``
    (``low`` excluded when ``low_open``); strings are one of ``choices`` (or a former name in
    ``renamed``, taken as its name now with an OMPL warning saying so); ``words`` are strings
    accepted besides numbers (``"auto"``). ``suggestion`` is OMPL's range suggestion, derived
    for booleans and choices.
    """

    kind: type
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    choices: tuple[str, ...] | None = None
    words: tuple[str, ...] = ()
    suggestion: str = ""
    renamed: tuple[tuple[str, str], ...] = ()  # (former choice, its name now): accepted, with a message

    def describe(self) -> str:
        """What is accepted, in words: ``"a number in [0, 1]"``, ``"one of a, b"``, ..."""
        if self.kind is bool:
            return "one of 0, 1, true, false"
        if self.choices is not None:
            return f"one of {', '.join(self.choices)}"
        noun = "an integer" if self.kind is int else "a number"
        if self.low is not None and self.high is not None:
            text = f"{noun} in {'(' if self.low_open else '['}{self.low:g}, {self.high:g}]"
        elif self.low is not None:
            text = f"{noun} {'>' if self.low_open else '>='} {self.low:g}"
        else:
            text = noun
        return text + "".join(f" or {word}" for word in self.words)

    def range_suggestion(self) -> str:
        if self.kind is bool:
            return "0,1"
        if self.choices is not None:
            return ",".join(self.choices)
        return self.suggestion

    def convert(self, value: Any) -> Any:
        """``value`` (a string in OMPL's form, or a Python value) as this domain's type.

        Raises ``ValueError`` with :meth:`describe` when it is not accepted.
        """
        text = value.strip() if isinstance(value, str) else None
        if text is not None and text.lower() in self.words:
            return text.lower()
        if self.kind is bool:
            if isinstance(value, bool):
                return value
            lowered = _format(value).strip().lower()
            if lowered in _TRUE or lowered in _FALSE:
                return lowered in _TRUE
            raise ValueError
        if self.kind is str:
            now = dict(self.renamed).get(value)
            if now is not None:
                ou.OMPL_WARN(f"{value!r} is now called {now!r}; the former name will be removed in a later release")
                value = now
            if self.choices is not None and value not in self.choices:
                raise ValueError
            return str(value)
        if isinstance(value, bool):
            raise ValueError  # True is not a number here
        if self.kind is int:
            number: float = int(text) if text is not None else value
            if int(number) != number:
                raise ValueError
            number = int(number)
        else:
            number = float(value)
            if not math.isfinite(number):
                raise ValueError
        if self.low is not None and (number < self.low or (self.low_open and number == self.low)):
            raise ValueError
        if self.high is not None and number > self.high:
            raise ValueError
        return number


@dataclass(frozen=True)
class Param:
    """One row of a parameter table: OMPL name, default, meaning and accepted values."""

    name: str
    default: Any
    doc: str
    domain: Domain
    accessor: str = ""  # the stem of OMPL's accessors when it is not the camel-cased name

    @property
    def camel(self) -> str:
        """The accessor stem: ``max_tree_size_ratio`` -> ``MaxTreeSizeRatio``."""
        return self.accessor or "".join(part[:1].upper() + part[1:] for part in self.name.split("_"))

    def convert(self, value: Any) -> Any:
        try:
            return self.domain.convert(value)
        except (TypeError, ValueError):
            raise ValueError(f"{self.name} must be {self.domain.describe()}, got {value!r}") from None


def param(
    default: Any,
    doc: str,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    choices: tuple[str, ...] | None = None,
    words: tuple[str, ...] = (),
    suggestion: str = "",
    kind: type | None = None,
    accessor: str = "",
    renamed: Mapping[str, str] | None = None,
) -> Any:
    """A field of a :class:`Settings` dataclass that is a parameter.

    ``default`` also fixes the type (``bool``, ``int``, ``float`` or ``str``; write floats
    as ``0.0``) unless ``kind`` is given (a number parameter whose default is one of its
    ``words``); ``doc`` is the meaning, with units; the keywords are the :class:`Domain`, and
    ``accessor`` the stem of the camelCase accessors when OMPL names them otherwise
    (``"StdDev"`` for ``standard_deviation``); ``renamed`` maps former choices to their names now.
    """
    kind = type(default) if kind is None else kind
    if kind not in (bool, int, float, str):
        raise TypeError(f"a parameter's default must be a bool, int, float or str, got {default!r}")
    domain = Domain(kind, low, high, low_open, choices, words, suggestion, tuple((renamed or {}).items()))
    return field(default=default, metadata={"doc": doc, "domain": domain, "accessor": accessor})


class Settings:
    """Base of a planner's settings dataclass: the parameter table and checked assignment."""

    _table: ClassVar[dict[type, tuple[Param, ...]]] = {}

    @classmethod
    def table(cls) -> tuple[Param, ...]:
        """The parameters, in declaration order."""
        if cls not in Settings._table:
            Settings._table[cls] = tuple(_param_of(f) for f in fields(cls))  # type: ignore[arg-type]
        return Settings._table[cls]

    def set(self, name: str, value: Any) -> None:
        """Set parameter ``name`` from a string or a value; ``ValueError`` naming what is accepted."""
        self.update({name: value})

    def update(self, values: Mapping[str, Any]) -> None:
        """Set several parameters at once, all or none: each value is converted, then
        :meth:`check` runs on the result; any refusal restores every old value."""
        rows = {p.name: p for p in self.table()}
        unknown = [name for name in values if name not in rows]
        if unknown:
            raise KeyError(f"unknown parameter {unknown[0]!r}; known: {', '.join(rows)}")
        converted = {name: rows[name].convert(value) for name, value in values.items()}
        previous = {name: getattr(self, name) for name in converted}
        for name, value in converted.items():
            setattr(self, name, value)
        try:
            self.check()
        except ValueError:
            for name, value in previous.items():
                setattr(self, name, value)
            raise

    def check(self) -> None:
        """Constraints between parameters (override); raise ``ValueError`` when violated."""


def _param_of(f: Field[Any]) -> Param:
    if "domain" not in f.metadata or f.default is MISSING:
        raise TypeError(f"settings field {f.name!r} must be made with param()")
    return Param(f.name, f.default, f.metadata["doc"], f.metadata["domain"], f.metadata["accessor"])


def add_accessors(cls: type, settings: type[Settings], attribute: str = "settings") -> None:
    """Give ``cls`` OMPL's camelCase accessors ``set<Name>``/``get<Name>`` for each parameter
    of ``settings`` (read from ``instance.<attribute>``), unless ``cls`` defines them itself."""
    for row in settings.table():

        def getter(self: Any, _name: str = row.name) -> Any:
            return getattr(getattr(self, attribute), _name)

        def setter(self: Any, value: Any, _name: str = row.name) -> None:
            getattr(self, attribute).set(_name, value)

        for method, verb in ((getter, "get"), (setter, "set")):
            name = f"{verb}{row.camel}"
            if name in cls.__dict__:
                continue
            method.__name__ = method.__qualname__ = name
            method.__doc__ = (
                f"The ``{row.name}`` parameter: {row.doc}"
                if verb == "get"
                else f"Set the ``{row.name}`` parameter ({row.domain.describe()}): {row.doc}"
            )
            setattr(cls, name, method)


class GenericParam:
    """One parameter of a :class:`ParamSet`, as OMPL's ``ompl::base::GenericParam``.

    ``getName``/``setName``, ``getValue`` (the value in OMPL's string form), ``setValue``
    (from a string; ``False`` and an OMPL error when refused), ``getRangeSuggestion``/
    ``setRangeSuggestion``. A parameter of a :class:`Settings` table also knows its table
    (``settings``, ``field``), so that :meth:`ParamSet.setParams` can set several at once.
    """

    def __init__(
        self,
        name: str,
        setter: Callable[[Any], None],
        getter: Callable[[], Any],
        parse: Callable[[str], Any],
        range_suggestion: str,
        settings: Settings | None = None,
    ) -> None:
        self._name = name
        self._setter, self._getter, self.parse = setter, getter, parse
        self._range_suggestion = range_suggestion
        self.settings, self.field = settings, name

    def getName(self) -> str:  # noqa: N802 (OMPL's names)
        return self._name

    def setName(self, name: str) -> None:  # noqa: N802
        self._name = name

    def getValue(self) -> str:  # noqa: N802
        """The current value in OMPL's string form (booleans ``0``/``1``)."""
        return _format(self._getter())

    def setValue(self, value: Any) -> bool:  # noqa: N802
        """Set from the string form; ``False`` (and an OMPL error naming what is accepted) if refused."""
        text = _format(value)
        try:
            self._setter(self.parse(text))
        except ValueError as error:
            self.refused(text, error)
            return False
        return True

    def refused(self, text: str, error: Exception) -> None:
        """Log OMPL's error for a refused value ``text``."""
        accepted = f" (range suggestion '{self._range_suggestion}')" if self._range_suggestion else ""
        ou.OMPL_ERROR(f"Invalid value '{text}' for parameter '{self._name}': {error}{accepted}")

    def getRangeSuggestion(self) -> str:  # noqa: N802
        """``"lo:step:hi"`` for numbers, a comma list for choices and booleans."""
        return self._range_suggestion

    def setRangeSuggestion(self, suggestion: str) -> None:  # noqa: N802
        self._range_suggestion = suggestion

    def __repr__(self) -> str:
        return f"GenericParam({self._name}={self.getValue()})"


def _parser(value_type: type, choices: tuple[str, ...] | None) -> Callable[[str], Any]:
    if value_type not in (bool, int, float, str):
        raise TypeError(f"unsupported type {value_type.__name__}; use bool, int, float or str")
    domain = Domain(value_type, choices=choices)

    def parse(text: str) -> Any:
        try:
            return domain.convert(text)
        except (TypeError, ValueError):
            raise ValueError(f"expected {domain.describe()}") from None

    return parse


class ParamSet:
    """A planner's parameters, set and read as strings, as OMPL's ``ompl::base::ParamSet``.

    The C++ class's methods, with Python returning what C++ writes into its output
    arguments: ``setParam``, ``setParams``, ``getParam(name)`` (the value; C++'s
    ``getParam(name, value)``), ``getParams()`` (name -> value), ``getParamNames()``,
    ``getParamValues()``, ``hasParam``, ``params[name]`` (the :class:`GenericParam`),
    ``size()``, ``print``, ``declareParam``, ``add``, ``remove``, ``include``, ``clear``.
    As in C++ (a ``std::map``), parameters are listed in the order of their names.

    ``ParamSet.of(settings)`` makes the set of a :class:`Settings` table.
    """

    def __init__(self) -> None:
        self._params: dict[str, GenericParam] = {}

    @classmethod
    def of(cls, settings: Settings) -> ParamSet:
        """The parameters of ``settings``' table, set through :meth:`Settings.update`."""
        params = cls()
        for row in settings.table():
            params.add(
                GenericParam(
                    row.name,
                    partial(settings.set, row.name),
                    partial(getattr, settings, row.name),
                    row.convert,
                    row.domain.range_suggestion(),
                    settings,
                )
            )
        return params

    def declareParam(  # noqa: N802 (OMPL's names)
        self,
        name: str,
        setter: Callable[[Any], None],
        getter: Callable[[], Any],
        range_suggestion: str = "",
        value_type: type | None = None,
        choices: tuple[str, ...] | None = None,
    ) -> None:
        """Declare parameter ``name`` from a ``setter`` and a ``getter``.

        ``value_type`` (``bool``, ``int``, ``float`` or ``str``) decides how strings are
        parsed; by default the type of ``getter()``'s current value. With ``choices``, only
        those strings are accepted and the range suggestion is their comma list. A setter
        refuses a value by raising ``ValueError``; its text goes into the error logged.
        """
        kind = type(getter()) if value_type is None else value_type
        parse = _parser(kind, choices)
        if choices is not None:
            range_suggestion = ",".join(choices)
        elif kind is bool and not range_suggestion:
            range_suggestion = "0,1"
        self.add(GenericParam(name, setter, getter, parse, range_suggestion))

    def add(self, param: GenericParam) -> None:
        """Add ``param`` under its name (replacing a parameter of that name)."""
        self._params[param.getName()] = param

    def remove(self, name: str) -> None:
        """Remove parameter ``name`` (nothing if there is none)."""
        self._params.pop(name, None)

    def include(self, other: ParamSet, prefix: str = "") -> None:
        """Add ``other``'s parameters, named ``prefix.name`` when ``prefix`` is given (as C++)."""
        for name, param in other._params.items():
            self._params[f"{prefix}.{name}" if prefix else name] = param

    def clear(self) -> None:
        self._params.clear()

    def _unknown(self, name: str) -> str:
        return f"Unknown parameter '{name}'. Known parameters: {', '.join(sorted(self._params))}"

    def setParam(self, name: str, value: Any) -> bool:  # noqa: N802
        """Set ``name`` from its string form; ``False`` (and an OMPL error) if refused."""
        if name not in self._params:
            ou.OMPL_ERROR(self._unknown(name))
            return False
        return self._params[name].setValue(value)

    def setParams(self, values: Mapping[str, Any], ignore_unknown: bool = False) -> bool:  # noqa: N802
        """Set several parameters; ``True`` only if all were set.

        As in OMPL, an entry refused on its own (an unknown name, a value its parameter
        does not accept) does not stop the others; with ``ignore_unknown``, names this set
        does not have are skipped silently. Entries of one :class:`Settings` table are set
        together, so the constraints between its parameters are checked on the resulting
        combination: the order of ``values`` never matters.
        """
        all_set = True
        tables: dict[int, tuple[Settings, dict[str, Any], list[GenericParam]]] = {}
        for name, value in values.items():
            if name not in self._params:
                if not ignore_unknown:
                    ou.OMPL_ERROR(self._unknown(name))
                    all_set = False
                continue
            param = self._params[name]
            if param.settings is None:
                all_set = param.setValue(value) and all_set
                continue
            try:
                converted = param.parse(_format(value))
            except ValueError as error:
                param.refused(_format(value), error)
                all_set = False
                continue
            _, table, members = tables.setdefault(id(param.settings), (param.settings, {}, []))
            table[param.field] = converted
            members.append(param)
        for settings, table, members in tables.values():
            try:
                settings.update(table)
            except ValueError as error:
                names = ", ".join(param.getName() for param in members)
                ou.OMPL_ERROR(f"Invalid combination of values for parameters {names}: {error}")
                all_set = False
        return all_set

    def getParam(self, name: str) -> str:  # noqa: N802
        """The current value of ``name`` as a string; ``KeyError`` if unknown."""
        return self[name].getValue()

    def getParams(self) -> dict[str, str]:  # noqa: N802
        """Every parameter's current value, as strings, by name."""
        return {name: self._params[name].getValue() for name in self.getParamNames()}

    def getParamNames(self) -> list[str]:  # noqa: N802
        """The parameters' names, sorted (as C++'s ``std::map``)."""
        return sorted(self._params)

    def getParamValues(self) -> list[str]:  # noqa: N802
        """The values, as strings, in the order of :meth:`getParamNames`."""
        return [self._params[name].getValue() for name in self.getParamNames()]

    def hasParam(self, name: str) -> bool:  # noqa: N802
        return name in self._params

    def getRangeSuggestion(self, name: str) -> str:  # noqa: N802
        """OMPL's range suggestion of ``name`` (``"lo:step:hi"`` or a comma list)."""
        return self[name].getRangeSuggestion()

    def size(self) -> int:
        return len(self._params)

    def print(self, out: IO[str] | None = None) -> None:
        """Write ``name = value`` per parameter, as OMPL's ``ParamSet::print`` (standard output by default)."""
        (out or sys.stdout).write("".join(f"{name} = {value}\n" for name, value in self.getParams().items()))

    def __getitem__(self, name: str) -> GenericParam:
        if name not in self._params:
            raise KeyError(f"unknown parameter {name!r}; known: {', '.join(sorted(self._params))}")
        return self._params[name]

    def __contains__(self, name: object) -> bool:
        return name in self._params

    def __iter__(self) -> Iterator[str]:
        return iter(self.getParamNames())

    def __len__(self) -> int:
        return len(self._params)

    def __repr__(self) -> str:
        return "ParamSet(" + ", ".join(f"{k}={v}" for k, v in self.getParams().items()) + ")"
