"""Options of one analysis run: which checks, which twist and filter methods, with parameters.

The options travel as JSON (stored with each run, sent by the UI), so they are one frozen
dataclass with a strict ``from_json`` that names the offending field, and a ``to_json`` that
round-trips. Angles are degrees only at this edge (names end in ``_deg``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

from mocapqa.core.rig import ROLE_KEYS, normalise_mapping
from mocapqa.errors import InputError, OptionError
from mocapqa.filters.apply import apply_overrides
from mocapqa.filters.registry import FILTERS, DataScale
from mocapqa.limits.catalog import check_model_name
from mocapqa.twist.analysis import METHODS, Method
from mocapqa.twist.choice import APPLY_CHOICES, parse_apply

__all__ = [
    "CHECKS",
    "MARKER_FORMATS",
    "MAX_POINTS_RANGE",
    "RUN_PRESETS",
    "TWIST_APPLY_CHOICES",
    "TWIST_METHODS",
    "AnalysisOptions",
    "Check",
    "ParamValue",
    "TwistMethod",
    "check_checks",
    "check_mapping",
    "describe_options",
    "take_checks",
]

ParamValue = float | int | bool | str
"""Value of one filter parameter override."""

Check = Literal["twist", "limits", "filter", "markers", "feet"]
"""A check a run can do."""
CHECKS: tuple[Check, ...] = get_args(Check)
"""The checks a run can do."""
MARKER_FORMATS = ("c3d", "trc")
"""Formats whose points are optical markers (the ``markers`` check runs on them); the points of
every other keypoint format are detections from video."""


def take_checks(kind: str, source_format: str | None = None) -> tuple[Check, ...]:
    """The checks a take can run: joint rotations (``twist``, ``limits``) for a ``"motion"``
    take, ``markers`` for points read from one of :data:`MARKER_FORMATS`, ``feet`` and
    ``filter`` for all. A run asked for another check reports it as skipped, with the reason;
    so does the feet check on a take without usable feet (a rig without legs, keypoints without
    hips, knees and ankles, markers without foot markers)."""
    if kind == "motion":
        return ("twist", "limits", "feet", "filter")
    if source_format in MARKER_FORMATS:
        return ("markers", "feet", "filter")
    return ("feet", "filter")


TwistMethod = Method
"""A twist detection method."""
TWIST_METHODS = METHODS
"""Twist detection methods (those of :mod:`mocapqa.twist.analysis`)."""
TWIST_APPLY_CHOICES = APPLY_CHOICES
"""Which twist intervals a run applies (besides a list of interval ids such as ``"0,3"``)."""
MAX_POINTS_RANGE = (10, 100_000)
"""Smallest and largest ``max_points`` (time samples per plotted series)."""


def _same_kind(value: Any, current: Any) -> bool:
    """Whether an override ``value`` can stand in for a parameter's ``current`` value."""
    if isinstance(value, str):
        return not dataclasses.is_dataclass(current)  # converted (and checked) by the filter
    if isinstance(current, bool) or isinstance(value, bool):
        return isinstance(current, bool) and isinstance(value, bool)
    if isinstance(current, int | float) and isinstance(value, int | float):
        return math.isfinite(value) and (isinstance(current, float) or isinstance(value, int))
    return False


@dataclass(frozen=True, slots=True)
class AnalysisOptions:
    """What one analysis run does.

    Parameters
    ----------
    checks : tuple of str
        Subset of :data:`CHECKS` to run, each named at most once.
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
    limits_model : str, optional
        The limits model by name (:mod:`mocapqa.limits.catalog`). None: the take's shoot's
        model, filled in when the run is recorded, else ``"default"``. Checked here for its
        form; whether it exists, when the run is recorded and when it runs.
    """

    checks: tuple[str, ...] = CHECKS
    twist_method: str = "robust"
    twist_apply: str = "confident"
    filter_method: str | None = None
    filter_preset: str | None = None
    filter_params: dict[str, ParamValue] = field(default_factory=dict)
    max_points: int = 2000
    mapping: dict[str, str] = field(default_factory=dict)
    limits_model: str | None = None

    def __post_init__(self) -> None:
        try:
            check_checks(self.checks)
        except InputError as e:
            raise OptionError("checks", str(e)) from e
        if self.twist_method not in TWIST_METHODS:
            raise OptionError(
                "twist_method",
                f"Expected one of {list(TWIST_METHODS)}, got {self.twist_method!r}",
            )
        try:
            parse_apply(self.twist_apply)
        except InputError as e:
            raise OptionError("twist_apply", str(e)) from e
        if self.filter_method is not None and self.filter_method not in FILTERS:
            raise OptionError(
                "filter_method",
                f"Expected one of {sorted(FILTERS)}, got {self.filter_method!r}",
            )
        low, high = MAX_POINTS_RANGE
        if not low <= self.max_points <= high:
            raise OptionError("max_points", f"Expected {low} to {high}, got {self.max_points}")
        object.__setattr__(self, "checks", tuple(self.checks))
        object.__setattr__(self, "mapping", check_mapping(self.mapping))
        if self.limits_model is not None:
            check_model_name(self.limits_model)
        self._check_filter(self.filter_method or "adaptive")

    def _check_filter(self, method: str) -> None:
        entry = FILTERS[method]
        if self.filter_preset is not None and self.filter_preset not in entry.presets:
            raise OptionError(
                "filter_preset",
                f"Expected a preset of {method!r} in {sorted(entry.presets)}, "
                f"got {self.filter_preset!r}",
            )
        base = entry.preset(self.filter_preset or "default", DataScale())
        for name, value in self.filter_params.items():
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
                    f"Expected a finite {type(current).__name__} (filter {method!r}), "
                    f"got {value!r}",
                )

    def check_take_kind(self, kind: str, fps: float | None = None) -> None:
        """Refuse options that do not suit a take of ``kind`` ("motion" or "keypoints") at
        ``fps`` frames per second (when known).

        Raises
        ------
        OptionError
            Naming the option: a keypoint filter on a BVH, a rotation filter on keypoints,
            a preset or parameters with no filter to apply them to, a rig mapping for
            keypoints, a cut-off frequency at or above the take's Nyquist frequency.
        """
        if fps is not None and fps > 0:
            for name, value in self.filter_params.items():
                if (
                    name.endswith("cutoff_hz")
                    and isinstance(value, int | float)
                    and value >= fps / 2
                ):
                    raise OptionError(
                        f"filter_params.{name}",
                        f"Expected a cut-off below the take's Nyquist frequency "
                        f"{fps / 2:g} Hz ({fps:g} fps), got {value:g} Hz",
                    )
        wanted = "rotations" if kind == "motion" else "keypoints"
        if kind != "motion" and self.mapping:
            raise OptionError("mapping", "Expected the mapping option only for BVH takes")
        if self.filter_method is None:
            if kind == "motion" and (self.filter_preset or self.filter_params):
                field_name = "filter_preset" if self.filter_preset else "filter_params"
                raise OptionError(
                    field_name,
                    "Expected a filter_method with it: motion takes are not filtered by default",
                )
            return
        entry = FILTERS[self.filter_method]
        if entry.kind not in (wanted, "both"):
            suits = sorted(n for n, e in FILTERS.items() if e.kind in (wanted, "both"))
            raise OptionError(
                "filter_method",
                f"Expected a filter for {wanted} on a {kind} take ({suits}), "
                f"got {self.filter_method!r}",
            )
        if kind == "motion" and self.filter_preset not in (None, "default"):
            raise OptionError(
                "filter_preset",
                f"Expected no preset or 'default' for a motion take, got {self.filter_preset!r}",
            )

    def check_joints(
        self, joints: Sequence[str] | None, parents: Sequence[int] | None = None
    ) -> None:
        """Refuse a ``mapping`` naming a joint the take does not have (``joints``: the BVH's
        joint names, None when not recorded: the run then finds out) or, given the hierarchy
        (``parents``, the parent index per joint), one that contradicts it (a mapped joint
        not below the limb's previous role, :func:`mocapqa.core.rig.find_roles`).

        Raises
        ------
        OptionError
            Naming the role, e.g. ``mapping.left_upper_arm``, or ``mapping``.
        """
        if joints is None:
            return
        known = set(joints)
        for role, joint in self.mapping.items():
            if joint not in known:
                raise OptionError(
                    f"mapping.{role}",
                    f"Expected a joint of this take ({len(known)} joints), got {joint!r}",
                )
        if not self.mapping or parents is None or len(parents) != len(joints):
            return
        import numpy as np

        from mocapqa.core.motion import Skeleton
        from mocapqa.core.rig import find_roles
        from mocapqa.errors import ShapeError

        try:  # the roles depend on names and hierarchy only, so no offsets are needed
            skeleton = Skeleton(
                tuple(joints), np.asarray(parents), np.zeros((len(joints), 3)), ((),) * len(joints)
            )
        except ShapeError:  # a record this code did not write: the run finds out
            return
        try:
            find_roles(skeleton, self.mapping)
        except InputError as e:
            raise OptionError("mapping", str(e)) from e

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
            "limits_model": self.limits_model,
        }

    def request_json(self) -> dict[str, Any]:
        """The body of a run request for these options (``POST /takes/{id}/runs``): the JSON
        less ``limits_model``, which a run does not choose (its shoot's model, or the
        default, decides)."""
        body = self.to_json()
        del body["limits_model"]
        return body

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
        known |= {"filter_params", "max_points", "mapping", "limits_model"}
        extra = sorted(set(data) - known)
        if extra:
            raise OptionError(extra[0], f"Expected option fields among {sorted(known)}")
        params = data.get("filter_params") or {}
        if not isinstance(params, dict) or not all(
            isinstance(v, int | float | str) for v in params.values()
        ):
            raise OptionError("filter_params", f"Expected names mapped to values, got {params!r}")
        checks = data.get("checks", list(CHECKS))
        if not isinstance(checks, list | tuple) or not all(isinstance(c, str) for c in checks):
            raise OptionError("checks", f"Expected a list of names, got {checks!r}")
        max_points = data.get("max_points", 2000)
        if not isinstance(max_points, int) or isinstance(max_points, bool):
            raise OptionError("max_points", f"Expected an integer, got {max_points!r}")
        strings = ("twist_method", "twist_apply", "filter_method", "filter_preset", "limits_model")
        for name in strings:
            value = data.get(name)
            if value is not None and not isinstance(value, str):
                raise OptionError(name, f"Expected a string, got {value!r}")
        return cls(
            checks=tuple(checks),
            twist_method=data.get("twist_method") or "robust",
            twist_apply=data.get("twist_apply") or "confident",
            filter_method=data.get("filter_method"),
            filter_preset=data.get("filter_preset"),
            filter_params={str(k): v for k, v in params.items()},
            max_points=max_points,
            mapping=data.get("mapping") or {},
            limits_model=data.get("limits_model"),
        )


def check_checks(checks: Sequence[str]) -> None:
    """Refuse a ``checks`` option naming a check not in :data:`CHECKS` or one more than once
    (so at most ``len(CHECKS)`` names). The one check of the option, used by
    :class:`AnalysisOptions` and the API's request model.

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


RUN_PRESETS: dict[str, AnalysisOptions] = {
    "full check": AnalysisOptions(),
    "twist only": AnalysisOptions(checks=("twist",)),
    "full check, no twist interval applied (decide each)": AnalysisOptions(twist_apply="none"),
    "full check, every twist interval applied": AnalysisOptions(twist_apply="all"),
    "limits only": AnalysisOptions(checks=("limits",)),
    "filter only": AnalysisOptions(checks=("filter",)),
    "markers only": AnalysisOptions(checks=("markers",)),
    "feet only": AnalysisOptions(checks=("feet",)),
}
"""Named option sets offered by the re-run form (a preset fills the form; every field stays
editable). The filter's own presets are the filter registry's."""


def describe_options() -> dict[str, Any]:
    """The run options for a form: fields grouped by check, with types, units, choices, bounds,
    defaults and the check each field belongs to, :data:`RUN_PRESETS` as JSON options, the
    checks each kind of take can run (:func:`take_checks`) and the role keys a ``mapping`` may
    name (:data:`mocapqa.core.rig.ROLE_KEYS`).

    Derived from :class:`AnalysisOptions` and the constants above, so a form offers exactly
    what ``from_json`` accepts. Filter parameters come from the filter registry
    (``GET /filters``): they depend on the filter chosen.
    """
    default = AnalysisOptions()
    low, high = MAX_POINTS_RANGE

    def choice(name: str, label: str, choices: tuple[str, ...], check: str) -> dict[str, Any]:
        value = getattr(default, name)
        return {
            "name": name,
            "label": label,
            "type": "choice",
            "choices": list(choices),
            "default": value,
            "unit": "",
            "check": check,
        }

    groups = [
        {
            "name": "twist",
            "label": "Twist",
            "check": "twist",
            "fields": [
                choice("twist_method", "detection method", TWIST_METHODS, "twist"),
                choice(
                    "twist_apply",
                    "intervals removed in the corrected take",
                    TWIST_APPLY_CHOICES,
                    "twist",
                ),
            ],
        },
        {"name": "limits", "label": "Joint limits", "check": "limits", "fields": []},
        {"name": "markers", "label": "Markers", "check": "markers", "fields": []},
        {"name": "feet", "label": "Feet and floor", "check": "feet", "fields": []},
        {
            "name": "filter",
            "label": "Filter",
            "check": "filter",
            "fields": [
                {
                    "name": "filter_method",
                    "label": "filter",
                    "type": "filter",
                    "default": None,
                    "unit": "",
                    "check": "filter",
                },
                {
                    "name": "filter_preset",
                    "label": "filter preset",
                    "type": "filter_preset",
                    "default": None,
                    "unit": "",
                    "check": "filter",
                },
            ],
        },
        {
            "name": "advanced",
            "label": "Advanced",
            "check": None,
            "advanced": True,
            "fields": [
                {
                    "name": "max_points",
                    "label": "samples per plotted series",
                    "type": "int",
                    "default": default.max_points,
                    "minimum": low,
                    "maximum": high,
                    "unit": "samples",
                    "check": None,
                },
            ],
        },
    ]
    return {
        "checks": list(CHECKS),
        # Which checks a take can run, by the take's kind ("markers": a keypoint take read from
        # one of ``marker_formats``): the form offers those only.
        "take_checks": {
            "motion": list(take_checks("motion")),
            "markers": list(take_checks("keypoints", MARKER_FORMATS[0])),
            "keypoints": list(take_checks("keypoints")),
        },
        "marker_formats": list(MARKER_FORMATS),
        "groups": groups,
        "presets": {name: options.request_json() for name, options in RUN_PRESETS.items()},
        # The rig roles a ``mapping`` may name (BVH takes), in the rig module's order.
        "role_keys": list(ROLE_KEYS),
    }
