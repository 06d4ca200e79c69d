"""One declaration per parameter: name, type, default, unit, range or choices, doc (no ROS here).

A node's settings are a frozen dataclass whose fields are declared with :func:`param`; :func:`schema_of`
collects them into a :class:`Schema`. From that one declaration come

* the defaults (the dataclass field defaults),
* start-up validation (:meth:`Schema.load`: type and range per key, errors naming the key and what is
  allowed; unknown keys refused naming the closest valid key, "did you mean global_max_force?"),
* the parameter table of the package README (:meth:`Schema.table`, spliced between
  ``<!-- params:begin module:ATTR -->`` markers by :mod:`compliant_common.schema_docs`).

Relations between parameters (a hard stop above a slow-down threshold, a cutoff below Nyquist) stay in each
package's own check, which runs on the built settings.

Example::

    @dataclass(frozen=True)
    class Settings:
        rate: float = param(50.0, unit="Hz", gt=0.0, doc="publish rate")
        topic: str = param("wrench", nonempty=True, doc="input topic")

    SCHEMA = schema_of(Settings)
    settings = SCHEMA.build(Settings, SCHEMA.load(params, prefix="~"))
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Literal, TypeGuard, TypeVar, cast

from compliant_common.errors import StackError
from compliant_common.keys import unknown_key_message
from compliant_common.typedefs import ParamMap

__all__ = ["Param", "ParamType", "Schema", "SchemaError", "param", "schema_of"]

#: What a value must be. "float" accepts ints (given as float), never bools, never NaN or inf; "sign" is 1 or
#: -1 (1.0 and -1.0 accepted, given as int); "floats" a list of finite numbers (a tuple of float; `length`
#: fixes the count); "strings" a list of non-empty strings (a tuple); "mapping" a dict; "any" is left to the
#: package's own check.
ParamType = Literal["str", "bool", "int", "float", "sign", "floats", "strings", "mapping", "any"]

_TYPES: tuple[str, ...] = ("str", "bool", "int", "float", "sign", "floats", "strings", "mapping", "any")
_META = "compliant_common.schema.param"
_T = TypeVar("_T")
_S = TypeVar("_S")


class SchemaError(StackError):
    """A value does not fit its declaration, or a key is not declared.

    Attributes:
        key: The parameter's name (without prefix).
        message: What is wrong, without the key (the unknown-key message names it with its prefix).
    """

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"{key}: {message}")
        self.key = key
        self.message = message

    def named(self, prefix: str) -> str:
        """The error with the key as the user writes it: "~rate: must be > 0, got 0" (an unknown-key
        message already names it: "~rtae is not a parameter: ...")."""
        return self.message if self.message.startswith(f"{prefix}{self.key} ") else f"{prefix}{self}"


def _is_number(value: object) -> TypeGuard[int | float]:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _number_text(value: float) -> str:
    text = repr(value)
    return f"{value:.4g}" if len(text) > 10 else text


@dataclasses.dataclass(frozen=True)
class Param:
    """One parameter's declaration.

    Attributes:
        name: The key (a nested key is written with "/": ``scale/linear``).
        type: See :data:`ParamType`.
        default: The value when the key is absent (lists are given as tuples).
        unit: Unit of the value ("" for none); shown in the README.
        doc: What it does; shown in the README.
        gt, ge, lt, le: Bounds (> gt, >= ge, < lt, <= le) of a number, or of each number of "floats".
        choices: The allowed values ("str" or numbers), when only a few are.
        length: "floats": the exact count.
        nonempty: "str": "" is refused.
        optional: None is accepted (and is the default's usual meaning: "see doc").
        shown_default: README text of the default when the code computes it (e.g. "= `max_velocity`").
        shown_range: README text of the range when a relation to another key bounds it.
        attr: The settings attribute holding the value ("" for a key the node reads by itself).
    """

    name: str
    type: ParamType
    default: object
    unit: str = ""
    doc: str = ""
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    choices: tuple[object, ...] = ()
    length: int | None = None
    nonempty: bool = False
    optional: bool = False
    shown_default: str = ""
    shown_range: str = ""
    attr: str = ""

    def __post_init__(self) -> None:
        if self.type not in _TYPES:
            raise TypeError(f"parameter {self.name!r}: unknown type {self.type!r}, expected one of {_TYPES}")
        try:
            self.convert(self.default)
        except SchemaError as exc:
            raise TypeError(f"parameter {self.name!r}: the default {self.default!r} is invalid: "
                            f"{exc.message}") from None

    def convert(self, value: object) -> object:
        """The value as the settings hold it (int to float, list to tuple), after checking it.

        Raises:
            SchemaError: Wrong type, out of range, not one of the choices; the message says what is allowed.
        """
        if value is None and self.optional:
            return None
        converted = self._typed(value)
        if self.choices and converted not in self.choices:
            raise SchemaError(self.name, f"must be one of {self.choices}, got {value!r}")
        if self.type in ("int", "float", "floats"):
            numbers = converted if isinstance(converted, tuple) else (converted,)  # "floats": a tuple
            if not all(_is_number(n) and self._in_range(n) for n in numbers):
                raise SchemaError(self.name, f"must be {self.range_text(markdown=False)}, got {value!r}")
        if self.nonempty and not converted:
            raise SchemaError(self.name, "must not be empty")
        return converted

    def _typed(self, value: object) -> object:
        kind = self.type
        if kind == "any":
            return value
        if kind == "str":
            if not isinstance(value, str):
                raise SchemaError(self.name, f"expected a string, got {value!r}")
            return value
        if kind == "bool":
            if not isinstance(value, bool):
                raise SchemaError(self.name, f"expected true or false, got {value!r}")
            return value
        if kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                raise SchemaError(self.name, f"expected an integer, got {value!r}")
            return value
        if kind == "mapping":
            if not isinstance(value, Mapping):
                raise SchemaError(self.name, f"expected a mapping, got {value!r}")
            return value
        if kind == "strings":
            if not isinstance(value, list | tuple) or not all(isinstance(v, str) and v for v in value):
                raise SchemaError(self.name, f"expected a list of non-empty strings, got {value!r}")
            return tuple(value)
        if kind == "floats":
            count = f"{self.length} " if self.length is not None else ""
            if not isinstance(value, list | tuple) or (self.length is not None and len(value) != self.length):
                raise SchemaError(self.name, f"expected a list of {count}numbers, got {value!r}")
            return tuple(self._float(v) for v in value)
        number = self._float(value)
        if kind == "sign":
            if number not in (1.0, -1.0):
                raise SchemaError(self.name, f"must be 1 or -1, got {value!r}")
            return int(number)
        return number

    def _float(self, value: object) -> float:
        if not _is_number(value):
            raise SchemaError(self.name, f"expected a number, got {value!r}")
        number = float(value)
        if not math.isfinite(number):
            raise SchemaError(self.name, f"must be finite, got {value!r}")
        return number

    def _in_range(self, number: float) -> bool:
        return not (
            (self.gt is not None and not number > self.gt)
            or (self.ge is not None and not number >= self.ge)
            or (self.lt is not None and not number < self.lt)
            or (self.le is not None and not number <= self.le)
        )

    def range_text(self, markdown: bool = True) -> str:
        """The allowed values in words: "> 0", "in [0, 1)", "`a` / `b`" ("" when anything of the type goes).

        With `markdown`, `shown_range` (a relation to another key) is used when set.
        """
        if markdown and self.shown_range:
            return self.shown_range
        if self.choices:
            return " / ".join(self._value_text(c) if markdown else repr(c) for c in self.choices)
        if self.type == "sign":
            return "1 / -1"
        low = ("[", self.ge) if self.ge is not None else ("(", self.gt) if self.gt is not None else None
        high = ("]", self.le) if self.le is not None else (")", self.lt) if self.lt is not None else None
        if low is not None and high is not None:
            return f"in {low[0]}{low[1]:g}, {high[1]:g}{high[0]}"
        if low is not None:
            return f"{'>=' if low[0] == '[' else '>'} {low[1]:g}"
        if high is not None:
            return f"{'<=' if high[0] == ']' else '<'} {high[1]:g}"
        if self.nonempty:
            return "not empty"
        return ""

    def default_text(self) -> str:
        """The default as the README shows it (YAML spelling: true, `""`, [0.0, 0.0, -9.81])."""
        return self.shown_default or self._value_text(self.default)

    def _value_text(self, value: object, quote: bool = True) -> str:
        if value is None:
            return "none"
        if isinstance(value, bool):
            return "true" if value else "false"
        if isinstance(value, float):
            return _number_text(value)
        if isinstance(value, str):
            text = value if value else '""'
            return f"`{text}`" if quote else text
        if isinstance(value, list | tuple):
            return "[" + ", ".join(self._value_text(v, quote=False) for v in value) + "]"
        if isinstance(value, Mapping):
            return "{}" if not value else str(dict(value))
        return str(value)


class Schema(Mapping[str, Param]):
    """The parameters of one node, in declaration order: a read-only mapping key -> :class:`Param`."""

    def __init__(self, params: Iterable[Param]) -> None:
        self._params: dict[str, Param] = {}
        for p in params:
            if p.name in self._params:
                raise ValueError(f"parameter {p.name!r} is declared twice")
            self._params[p.name] = p

    def __len__(self) -> int:
        return len(self._params)

    def __iter__(self) -> Iterator[str]:
        return iter(self._params)

    def __getitem__(self, name: str) -> Param:
        return self._params[name]

    @property
    def names(self) -> tuple[str, ...]:
        """The keys, in declaration order."""
        return tuple(self._params)

    def defaults(self) -> dict[str, object]:
        """Key -> default."""
        return {p.name: p.default for p in self.values()}

    def unknown(self, keys: Iterable[str], also_known: Iterable[str] = ()) -> list[str]:
        """The keys that are not declared (nor in `also_known`), sorted."""
        known = set(self._params) | set(also_known)
        return sorted(k for k in keys if k not in known)

    def refuse_unknown(self, keys: Iterable[str], prefix: str = "", also_known: Iterable[str] = ()) -> None:
        """Refuses the first unknown key (sorted), naming the closest known one.

        Args:
            keys: The keys given.
            prefix: Shown before key names ("~", "jog_arm_server/").
            also_known: Keys accepted although not declared here (read elsewhere).

        Raises:
            SchemaError: "<prefix><key> is not a parameter: did you mean <prefix><closest>?".
        """
        unknown = self.unknown(keys, also_known)
        if unknown:
            known = [*self._params, *also_known]
            raise SchemaError(unknown[0], unknown_key_message(unknown[0], known, prefix))

    def convert(self, params: ParamMap) -> dict[str, object]:
        """The declared keys present in `params`, converted and checked (other keys are ignored).

        Raises:
            SchemaError: Naming the first bad key (declaration order).
        """
        return {p.name: p.convert(params[p.name]) for p in self.values() if p.name in params}

    def load(
        self, params: ParamMap, prefix: str = "", also_known: Iterable[str] = ()
    ) -> dict[str, object]:
        """Start-up validation: unknown keys refused, then the given values converted (absent keys are left
        out: the settings' defaults apply).

        Raises:
            SchemaError: The first unknown key, else the first bad value.
        """
        self.refuse_unknown(params, prefix, also_known)
        return self.convert(params)

    def check(self, values: ParamMap) -> None:
        """Checks values already in settings form (e.g. a settings object's fields by key).

        Raises:
            SchemaError: Naming the first bad key.
        """
        for p in self.values():
            if p.name in values:
                p.convert(values[p.name])

    def attrs(self, values: ParamMap) -> dict[str, object]:
        """Key -> value turned into settings attribute -> value (keys without an attribute dropped)."""
        return {self._params[k].attr: v for k, v in values.items() if self._params[k].attr}

    def build(self, settings_class: type[_S], values: ParamMap) -> _S:
        """The settings object of checked values (key -> value, as `load` returns them): the class called
        with `attrs(values)` as keyword arguments (the class's own checks run as usual)."""
        return settings_class(**self.attrs(values))

    def values_of(self, settings: object) -> dict[str, object]:
        """Key -> the value a settings object holds."""
        return {p.name: getattr(settings, p.attr) for p in self.values() if p.attr}

    def table(self, prefix: str = "") -> str:
        """The README table: parameter, default, unit, range, meaning (Markdown, one row per key)."""
        rows = ["| parameter | default | unit | range | meaning |", "|---|---|---|---|---|"]
        for p in self.values():
            cells = [f"`{prefix}{p.name}`", p.default_text(), p.unit, p.range_text(), p.doc]
            escaped = [c.replace("|", "\\|") for c in cells]
            rows.append("|" + "|".join(f" {c} " if c else " " for c in escaped) + "|")
        return "\n".join(rows) + "\n"


def _infer_type(default: object) -> ParamType:
    for kind, cls in (("bool", bool), ("int", int), ("float", float), ("str", str)):
        if isinstance(default, cls):
            return cast(ParamType, kind)
    raise TypeError(f"cannot infer a parameter type from the default {default!r}: give type=")


def param(
    default: _T,
    *,
    type: ParamType | None = None,
    unit: str = "",
    doc: str = "",
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    choices: tuple[object, ...] = (),
    length: int | None = None,
    nonempty: bool = False,
    optional: bool = False,
    shown_default: str = "",
    shown_range: str = "",
    key: str = "",
) -> _T:
    """A settings dataclass field declaring its parameter (the field's name is the key unless `key` is
    given); the arguments are :class:`Param`'s. The type is inferred from a bool, int, float or str default.

    Returns the dataclass field (typed as the default, so the field's annotation is checked against it).
    """
    spec = Param(
        key, type or _infer_type(default), default, unit, doc, gt, ge, lt, le, choices, length, nonempty,
        optional, shown_default, shown_range,
    )
    metadata = {_META: spec}
    if isinstance(default, list | dict | set):  # mutable: each settings object gets its own copy
        factory: Callable[[], _T] = functools.partial(copy.copy, default)
        return dataclasses.field(default_factory=factory, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def schema_of(settings_class: type, extra: Iterable[Param] = ()) -> Schema:
    """The schema of a settings dataclass whose fields were declared with :func:`param`, in field order,
    followed by `extra` (keys the node reads itself, not settings attributes)."""
    declared = [
        dataclasses.replace(f.metadata[_META], name=f.metadata[_META].name or f.name, attr=f.name)
        for f in dataclasses.fields(settings_class)
        if _META in f.metadata
    ]
    return Schema([*declared, *extra])
