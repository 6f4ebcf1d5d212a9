"""How a run option is declared: one :class:`OptionSpec` per field of the options dataclass.

A field of :class:`mocapqa.pipeline.options.AnalysisOptions` is declared with its default and,
in its metadata (:func:`declare`), a spec giving its JSON kind, choices or bounds, help text
and its place in the re-run form. Everything else reads the declaration: the options' own
checks and JSON form (:func:`read_field`, :func:`check_field`, :func:`json_value`), the form
served by ``GET /run-options`` (:func:`describe_field`), the API's request model and the CLI
defaults. A new option is one more declared field.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

from mocapqa.errors import OptionError

__all__ = [
    "FormGroup",
    "OptionField",
    "OptionKind",
    "OptionSpec",
    "check_field",
    "declare",
    "declared_fields",
    "describe_field",
    "json_value",
    "read_field",
]

OptionKind = Literal["names", "text", "int", "params", "mapping"]
"""The JSON form of an option: a list of names, a string, an integer, filter parameters by
dotted name (numbers, booleans or strings), or a mapping of names to names."""


@dataclass(frozen=True, slots=True)
class OptionSpec:
    """What one run option is, besides its name and default.

    Parameters
    ----------
    kind : str
        Its JSON form, one of :data:`OptionKind`.
    help : str
        What it does, for the API's schema and the form.
    label : str
        Its name in the form.
    group : str, optional
        The :class:`FormGroup` showing it; None: not a field of the form (the checks are the
        groups' own boxes, the filter parameters come from the filter registry, the mapping
        from the rig roles).
    form : str
        The form's input: ``"choice"``, ``"int"``, ``"filter"`` (the filter registry's names)
        or ``"filter_preset"`` (the chosen filter's presets).
    choices : tuple of str
        The values offered; unless ``open_choices``, the only ones accepted.
    open_choices : bool
        Other values are accepted too (checked by ``check``), e.g. interval ids.
    bounds : tuple of int, optional
        Smallest and largest value of an ``"int"`` option.
    unit : str
        The unit of a number, for the form.
    max_items : int, optional
        Most entries a request may send (a list or an object).
    nullable : bool
        None is a value (the default decides later).
    requested : bool
        Whether a run request carries it (``limits_model`` is the shoot's, not the run's).
    check : callable, optional
        The option's own check past its kind, choices and bounds: returns the value kept
        (normalised), raises an :class:`~mocapqa.errors.InputError` naming the field.
    check_in_request : bool
        The request model runs ``check`` too (a check that needs no registry nor take).
    """

    kind: OptionKind
    help: str
    label: str = ""
    group: str | None = None
    form: str = ""
    choices: tuple[str, ...] = ()
    open_choices: bool = False
    bounds: tuple[int, int] | None = None
    unit: str = ""
    max_items: int | None = None
    nullable: bool = False
    requested: bool = True
    check: Callable[[Any], Any] | None = None
    check_in_request: bool = False


@dataclass(frozen=True, slots=True)
class FormGroup:
    """One group of the re-run form: its name, label, the check its box runs (None: a group
    of settings without a check) and a note shown when it has no fields."""

    name: str
    label: str
    check: str | None
    note: str = ""
    advanced: bool = False


@dataclass(frozen=True, slots=True)
class OptionField:
    """One declared option: its name, default and :class:`OptionSpec`."""

    name: str
    default: Any
    spec: OptionSpec


def declare(spec: OptionSpec) -> dict[str, OptionSpec]:
    """The metadata of a dataclass field declaring a run option (``field(default=…,
    metadata=declare(OptionSpec(…)))``)."""
    return {"option": spec}


def declared_fields(cls: type) -> tuple[OptionField, ...]:
    """The options declared (with :func:`declare`) by the dataclass ``cls``, in its order."""
    found = []
    for f in dataclasses.fields(cls):
        spec = f.metadata.get("option")
        if isinstance(spec, OptionSpec):
            factory: Any = f.default_factory
            default = f.default if factory is dataclasses.MISSING else factory()
            found.append(OptionField(f.name, default, spec))
    return tuple(found)


def check_field(field: OptionField, value: Any) -> Any:
    """``value`` of ``field`` checked against its choices (those of a ``"text"`` option
    without ``open_choices``), its bounds and its own check; returns the value to keep.

    Raises
    ------
    InputError
        An :class:`~mocapqa.errors.OptionError` naming the field for a choice or bound, else
        what the field's own check raises.
    """
    spec = field.spec
    closed = spec.kind == "text" and spec.choices and not spec.open_choices
    if closed and value not in spec.choices and (value is not None or not spec.nullable):
        raise OptionError(field.name, f"Expected one of {list(spec.choices)}, got {value!r}")
    if spec.bounds is not None:
        low, high = spec.bounds
        if not low <= value <= high:
            raise OptionError(field.name, f"Expected {low} to {high}, got {value}")
    return value if spec.check is None else spec.check(value)


def read_field(field: OptionField, data: dict[str, Any]) -> Any:
    """The value of ``field`` in the JSON ``data`` (its default when missing), of its kind.

    Raises
    ------
    OptionError
        Naming the field, on a value of the wrong type.
    """
    name, kind = field.name, field.spec.kind
    if name not in data:
        return copy.copy(field.default)
    value = data[name]
    if kind == "names":
        if not isinstance(value, list | tuple) or not all(isinstance(v, str) for v in value):
            raise OptionError(name, f"Expected a list of names, got {value!r}")
        return tuple(value)
    if kind == "int":
        if not isinstance(value, int) or isinstance(value, bool):
            raise OptionError(name, f"Expected an integer, got {value!r}")
        return value
    if kind == "text":
        if value is not None and not isinstance(value, str):
            raise OptionError(name, f"Expected a string, got {value!r}")
        return value if field.spec.nullable else value or field.default
    value = value or {}
    scalars = isinstance(value, dict) and all(
        isinstance(v, int | float | str) for v in value.values()
    )
    if kind == "params" and not scalars:
        raise OptionError(name, f"Expected names mapped to values, got {value!r}")
    return {str(k): v for k, v in value.items()} if kind == "params" else value


def json_value(value: Any) -> Any:
    """An option's value as JSON: a tuple as a list, a dict copied."""
    if isinstance(value, tuple):
        return list(value)
    if isinstance(value, dict):
        return dict(value)
    return value


def describe_field(field: OptionField, group: FormGroup) -> dict[str, Any]:
    """``field`` as a field of the re-run form in ``group``: name, label, type, choices or
    bounds, default, unit, the check it belongs to and its help."""
    spec = field.spec
    described: dict[str, Any] = {"name": field.name, "label": spec.label, "type": spec.form}
    if spec.choices:
        described["choices"] = list(spec.choices)
    described["default"] = json_value(field.default)
    if spec.bounds is not None:
        described["minimum"], described["maximum"] = spec.bounds
    described |= {"unit": spec.unit, "check": group.check, "help": spec.help}
    return described
