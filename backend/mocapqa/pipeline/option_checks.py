"""The checks of the run options that read a registry or another module: the checks a run can
do, the rig mapping, the twist choice, the filter and its parameters, the limits model. Each
returns the value kept, or raises an :class:`~mocapqa.errors.OptionError` naming the option;
:mod:`mocapqa.pipeline.options` declares which option runs which.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any, Literal, get_args

from mocapqa.core.rig import normalise_mapping
from mocapqa.errors import InputError, OptionError
from mocapqa.feet.fix_choice import check_apply
from mocapqa.filters.apply import apply_overrides
from mocapqa.filters.registry import FILTERS, DataScale
from mocapqa.limits.catalog import check_model_name
from mocapqa.twist.choice import parse_apply

__all__ = [
    "CHECKS",
    "Check",
    "apply_option",
    "check_checks",
    "check_filter_params",
    "check_mapping",
    "checks_option",
    "feet_apply_option",
    "filter_option",
    "model_option",
]

Check = Literal["twist", "limits", "filter", "markers", "feet"]
"""A check a run can do."""
CHECKS: tuple[Check, ...] = get_args(Check)
"""The checks a run can do."""


def _same_kind(value: Any, current: Any) -> bool:
    """Whether an override ``value`` can stand in for a parameter's ``current`` value."""
    if isinstance(value, str):
        return not dataclasses.is_dataclass(current)  # converted (and checked) by the filter
    if isinstance(current, bool) or isinstance(value, bool):
        return isinstance(current, bool) and isinstance(value, bool)
    if isinstance(current, int | float) and isinstance(value, int | float):
        return math.isfinite(value) and (isinstance(current, float) or isinstance(value, int))
    return False


def check_checks(checks: Sequence[str]) -> None:
    """Refuse a ``checks`` option naming a check not in :data:`CHECKS` or one more than once
    (so at most ``len(CHECKS)`` names). The one check of the option, used by
    :class:`~mocapqa.pipeline.options.AnalysisOptions` and the API's request model.

    Raises
    ------
    InputError
        E.g. ``Expected each of ['twist', 'limits', 'filter'] at most once, got 'twist'
        100000 times``.
    """
    unknown = sorted(set(checks) - set(CHECKS))
    if unknown:
        shown = [c[:40] for c in unknown[:3]] + (["…"] if len(unknown) > 3 else [])
        raise InputError(f"Expected names among {list(CHECKS)}, got {shown}")
    twice = next((c for c in CHECKS if checks.count(c) > 1), None)
    if twice is not None:
        raise InputError(
            f"Expected each of {list(CHECKS)} at most once, got {twice!r} "
            f"{checks.count(twice)} times"
        )


def check_mapping(mapping: object) -> dict[str, str]:
    """The ``mapping`` option as role key → joint name, or an InputError naming the field.

    The one check of the option, used by the run options and the API's request model.
    """
    if not isinstance(mapping, dict):
        raise InputError(f"Expected mapping to be an object of role → joint name, got {mapping!r}")
    if any(not isinstance(v, str) or not v for v in mapping.values()):
        raise InputError("Expected mapping to name a joint (a non-empty string) for each role")
    try:
        return normalise_mapping(mapping)
    except InputError as e:
        raise InputError(f"mapping: {e}") from e


def checks_option(checks: Any) -> tuple[str, ...]:
    """The ``checks`` option checked (:func:`check_checks`) as a tuple."""
    try:
        check_checks(checks)
    except InputError as e:
        raise OptionError("checks", str(e)) from e
    return tuple(checks)


def apply_option(apply: str) -> str:
    """The ``twist_apply`` option, once :func:`mocapqa.twist.choice.parse_apply` reads it."""
    try:
        parse_apply(apply)
    except InputError as e:
        raise OptionError("twist_apply", str(e)) from e
    return apply


def feet_apply_option(apply: str) -> str:
    """The ``feet_apply`` option, once :func:`mocapqa.feet.fix_choice.check_apply` reads it
    (whether the take has the ids named is the run's to find out)."""
    try:
        return check_apply(apply)
    except InputError as e:
        raise OptionError("feet_apply", str(e)) from e


def filter_option(method: str | None) -> str | None:
    """The ``filter_method`` option, a name of the filter registry or None."""
    if method is not None and method not in FILTERS:
        raise OptionError("filter_method", f"Expected one of {sorted(FILTERS)}, got {method!r}")
    return method


def model_option(name: str | None) -> str | None:
    """The ``limits_model`` option, a well-formed model name or None."""
    return None if name is None else check_model_name(name)


def check_filter_params(method: str, preset: str | None, params: dict[str, Any]) -> None:
    """Refuse a filter ``preset`` that ``method`` (a name of the filter registry) does not have,
    or a parameter override in ``params`` that its parameters do not take: unknown, out of its
    range, or of another kind.

    Raises
    ------
    OptionError
        Naming ``filter_preset`` or the parameter (``filter_params.window_s``).
    """
    entry = FILTERS[method]
    if preset is not None and preset not in entry.presets:
        raise OptionError(
            "filter_preset",
            f"Expected a preset of {method!r} in {sorted(entry.presets)}, got {preset!r}",
        )
    base = entry.preset(preset or "default", DataScale())
    for name, value in params.items():
        try:
            apply_overrides(base, {name: value})
        except OptionError as e:  # the message without the dotted name it starts with
            field_name = f"filter_params.{name}"
            raise OptionError(field_name, f"{e.message} (filter {method!r})") from e
        except (InputError, TypeError, ValueError) as e:
            raise OptionError(f"filter_params.{name}", f"{e} (filter {method!r})") from e
        current: Any = base
        for part in name.split("."):
            current = getattr(current, part)
        if not _same_kind(value, current):
            raise OptionError(
                f"filter_params.{name}",
                f"Expected a finite {type(current).__name__} (filter {method!r}), got {value!r}",
            )
