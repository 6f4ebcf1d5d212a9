"""Options of one analysis run: which checks, which twist and filter methods, with parameters.

The options travel as JSON (stored with each run, sent by the UI), so they are one frozen
dataclass with a strict ``from_json`` that names the offending field, and a ``to_json`` that
round-trips. Angles are degrees only at this edge (names end in ``_deg``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from mocapqa.core.rig import normalise_mapping
from mocapqa.errors import InputError
from mocapqa.filters.registry import FILTERS
from mocapqa.twist.analysis import METHODS
from mocapqa.twist.choice import APPLY_CHOICES, parse_apply

__all__ = [
    "CHECKS",
    "TWIST_APPLY_CHOICES",
    "TWIST_METHODS",
    "AnalysisOptions",
    "ParamValue",
    "check_mapping",
]

ParamValue = float | int | bool | str
"""Value of one filter parameter override."""

CHECKS = ("twist", "limits", "filter")
"""The checks a run can do."""
TWIST_METHODS = METHODS
"""Twist detection methods (those of :mod:`mocapqa.twist.analysis`)."""
TWIST_APPLY_CHOICES = APPLY_CHOICES
"""Which twist intervals a run applies (besides a list of interval ids such as ``"0,3"``)."""


@dataclass(frozen=True, slots=True)
class AnalysisOptions:
    """What one analysis run does.

    Parameters
    ----------
    checks : tuple of str
        Subset of :data:`CHECKS` to run.
    twist_method : str
        One of :data:`TWIST_METHODS`.
    twist_apply : str
        One of :data:`TWIST_APPLY_CHOICES` (default ``"confident"``), or comma-separated
        interval ids of the take (``"0,3"``): which detected intervals the corrected take has.
    filter_method : str, optional
        A name from the filter registry; ``None`` means "adaptive" for keypoint takes and no
        filtering of the corrected BVH.
    filter_preset : str, optional
        A preset name of the filter registry, for keypoint filters.
    filter_params : dict of str to float, int, bool or str
        Parameter overrides for the filter by dotted name, in the registry's units.
    max_points : int
        Largest number of time samples per plotted series (the result is decimated to it).
    mapping : dict of str to str
        Rig roles named by hand, role key → joint name (``{"left_upper_arm": "LeftShoulder"}``),
        overriding the roles found from names and structure (:func:`mocapqa.core.rig.find_roles`).
        Checked here for its role keys; its joint names are checked against the take when the
        run reads it.
    """

    checks: tuple[str, ...] = CHECKS
    twist_method: str = "robust"
    twist_apply: str = "confident"
    filter_method: str | None = None
    filter_preset: str | None = None
    filter_params: dict[str, ParamValue] = field(default_factory=dict)
    max_points: int = 2000
    mapping: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = [c for c in self.checks if c not in CHECKS]
        if unknown:
            raise InputError(f"Expected checks among {list(CHECKS)}, got {unknown}")
        if self.twist_method not in TWIST_METHODS:
            raise InputError(
                f"Expected twist_method in {list(TWIST_METHODS)}, got {self.twist_method!r}"
            )
        parse_apply(self.twist_apply)
        if self.filter_method is not None and self.filter_method not in FILTERS:
            raise InputError(
                f"Expected filter_method in {sorted(FILTERS)}, got {self.filter_method!r}"
            )
        if not 10 <= self.max_points <= 100_000:
            raise InputError(f"Expected max_points in [10, 100000], got {self.max_points}")
        object.__setattr__(self, "checks", tuple(self.checks))
        object.__setattr__(self, "mapping", check_mapping(self.mapping))

    def to_json(self) -> dict[str, Any]:
        """The options as a JSON-ready dict."""
        return {
            "checks": list(self.checks),
            "twist_method": self.twist_method,
            "twist_apply": self.twist_apply,
            "filter_method": self.filter_method,
            "filter_preset": self.filter_preset,
            "filter_params": dict(self.filter_params),
            "max_points": self.max_points,
            "mapping": dict(self.mapping),
        }

    @classmethod
    def from_json(cls, data: dict[str, Any] | None) -> AnalysisOptions:
        """Options from a JSON dict; missing fields take their defaults.

        Raises
        ------
        InputError
            On an unknown field or a value of the wrong type.
        """
        if not data:
            return cls()
        known = {"checks", "twist_method", "twist_apply", "filter_method", "filter_preset"}
        known |= {"filter_params", "max_points", "mapping"}
        extra = sorted(set(data) - known)
        if extra:
            raise InputError(f"Expected option fields among {sorted(known)}, got {extra}")
        params = data.get("filter_params") or {}
        if not isinstance(params, dict) or not all(
            isinstance(v, int | float | str) for v in params.values()
        ):
            raise InputError(f"Expected filter_params to map names to values, got {params!r}")
        checks = data.get("checks", list(CHECKS))
        if not isinstance(checks, list | tuple) or not all(isinstance(c, str) for c in checks):
            raise InputError(f"Expected checks to be a list of names, got {checks!r}")
        max_points = data.get("max_points", 2000)
        if not isinstance(max_points, int) or isinstance(max_points, bool):
            raise InputError(f"Expected max_points to be an integer, got {max_points!r}")
        for name in ("twist_method", "twist_apply", "filter_method", "filter_preset"):
            value = data.get(name)
            if value is not None and not isinstance(value, str):
                raise InputError(f"Expected {name} to be a string, got {value!r}")
        return cls(
            checks=tuple(checks),
            twist_method=data.get("twist_method") or "robust",
            twist_apply=data.get("twist_apply") or "confident",
            filter_method=data.get("filter_method"),
            filter_preset=data.get("filter_preset"),
            filter_params={str(k): v for k, v in params.items()},
            max_points=max_points,
            mapping=data.get("mapping") or {},
        )


def check_mapping(mapping: object) -> dict[str, str]:
    """The ``mapping`` option as role key → joint name, or an InputError naming the field.

    The one check of the option, used by :class:`AnalysisOptions` and the API's request model.
    """
    if not isinstance(mapping, dict):
        raise InputError(f"Expected mapping to be an object of role → joint name, got {mapping!r}")
    if any(not isinstance(v, str) or not v for v in mapping.values()):
        raise InputError("Expected mapping to name a joint (a non-empty string) for each role")
    try:
        return normalise_mapping(mapping)
    except InputError as e:
        raise InputError(f"mapping: {e}") from e
