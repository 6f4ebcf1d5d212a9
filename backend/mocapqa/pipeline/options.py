"""Options of one analysis run: which checks, which twist and filter methods, with parameters.

The options travel as JSON (stored with each run, sent by the UI), so they are one frozen
dataclass with a strict ``from_json`` that names the offending field, and a ``to_json`` that
round-trips. Angles are degrees only at this edge (names end in ``_deg``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Self

from mocapqa.core.rig import ROLE_KEYS
from mocapqa.errors import InputError, OptionError
from mocapqa.feet.fix_choice import RUN_APPLY_CHOICES
from mocapqa.filters.registry import FILTERS
from mocapqa.pipeline.option_checks import (
    CHECKS,
    Check,
    apply_option,
    check_checks,
    check_filter_params,
    check_mapping,
    checks_option,
    feet_apply_option,
    filter_option,
    model_option,
)
from mocapqa.pipeline.option_fields import (
    FormGroup,
    OptionField,
    OptionSpec,
    check_field,
    declare,
    declared_fields,
    describe_field,
    json_value,
    read_field,
)
from mocapqa.twist.analysis import METHODS, Method
from mocapqa.twist.choice import APPLY_CHOICES

__all__ = [
    "CHECKS",
    "DEFAULT_KEYPOINT_FILTER",
    "DEFAULT_OPTIONS",
    "FEET_APPLY_CHOICES",
    "FORM_GROUPS",
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
    "option_fields",
    "take_checks",
    "take_filter",
]

ParamValue = float | int | bool | str
"""Value of one filter parameter override."""

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


DEFAULT_KEYPOINT_FILTER = "adaptive"
"""The filter a keypoint take's run uses when none is chosen (a motion take's uses none)."""


def take_filter(kind: str) -> dict[str, str | None]:
    """The filters a take of ``kind`` ("motion" or "keypoints") can run and the one its run
    uses when none is chosen: ``target`` as the filter registry names what a filter applies to
    (``"rotations"``, a motion take's joint rotations; ``"keypoints"``), ``default`` the
    registry's name of the filter (:data:`DEFAULT_KEYPOINT_FILTER`), None for no filter."""
    if kind == "motion":
        return {"target": "rotations", "default": None}
    return {"target": "keypoints", "default": DEFAULT_KEYPOINT_FILTER}


TwistMethod = Method
"""A twist detection method."""
TWIST_METHODS = METHODS
"""Twist detection methods (those of :mod:`mocapqa.twist.analysis`)."""
TWIST_APPLY_CHOICES = APPLY_CHOICES
"""Which twist intervals a run applies (besides a list of interval ids such as ``"0,3"``)."""
FEET_APPLY_CHOICES = RUN_APPLY_CHOICES
"""Which foot locks a run applies (besides ids such as ``"skate-left-120"``); none by default."""
MAX_POINTS_RANGE = (10, 100_000)
"""Smallest and largest ``max_points`` (time samples per plotted series)."""


@dataclass(frozen=True, slots=True)
class AnalysisOptions:
    """What one analysis run does.

    Every field is declared once, here, with an :class:`~mocapqa.pipeline.option_fields.OptionSpec`:
    its default, JSON kind, choices or bounds, help and place in the re-run form. The checks,
    ``to_json``/``from_json``, :func:`describe_options`, the API's request model and the CLI
    defaults read the declaration (:func:`~mocapqa.pipeline.option_fields.declared_fields`).

    Parameters
    ----------
    checks : tuple of str
        Subset of :data:`CHECKS` to run, each named at most once.
    twist_method : str
        One of :data:`TWIST_METHODS`.
    twist_apply : str
        One of :data:`TWIST_APPLY_CHOICES` (default ``"confident"``), or comma-separated
        interval ids of the take (``"0,3"``): which detected intervals the corrected take has.
    feet_apply : str
        One of :data:`FEET_APPLY_CHOICES` (default ``"none"``: foot cleanup is off), or
        comma-separated ids of skate findings and contacts (``"skate-left-120"``): which foot
        contacts the corrected take has locked (:func:`mocapqa.feet.fix_choice.choose_locks`),
        after every other correction and the filter.
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

    checks: tuple[str, ...] = field(
        default=CHECKS,
        metadata=declare(
            OptionSpec(
                "names",
                "The checks to run, each at most once",
                choices=CHECKS,
                max_items=len(CHECKS),
                check=checks_option,
                check_in_request=True,
            )
        ),
    )
    twist_method: str = field(
        default="robust",
        metadata=declare(
            OptionSpec(
                "text",
                "Twist detection method: the robust detector, or the published rule as written "
                "(paper)",
                label="detection method",
                group="twist",
                form="choice",
                choices=TWIST_METHODS,
            )
        ),
    )
    twist_apply: str = field(
        default="confident",
        metadata=declare(
            OptionSpec(
                "text",
                "Twist intervals to remove: confident, all, none, or interval ids ('0,3'); "
                "checked by the run options (pipeline/options.py)",
                label="intervals removed in the corrected take",
                group="twist",
                form="choice",
                choices=TWIST_APPLY_CHOICES,
                open_choices=True,
                check=apply_option,
            )
        ),
    )
    feet_apply: str = field(
        default="none",
        metadata=declare(
            OptionSpec(
                "text",
                "Foot locks in the corrected take: none (cleanup off), confident (the contacts "
                "of skate findings of confidence at least 0.5), skates (of every skate "
                "finding), or ids ('skate-left-120'); each lock can be accepted or rejected",
                label="planted feet locked in the corrected take",
                group="feet",
                form="choice",
                choices=FEET_APPLY_CHOICES,
                open_choices=True,
                check=feet_apply_option,
                check_in_request=True,
            )
        ),
    )
    filter_method: str | None = field(
        default=None,
        metadata=declare(
            OptionSpec(
                "text",
                "A filter of the registry (GET /filters); none: adaptive for keypoint takes, no "
                "filtering of a BVH take",
                label="filter",
                group="filter",
                form="filter",
                nullable=True,
                check=filter_option,
            )
        ),
    )
    filter_preset: str | None = field(
        default=None,
        metadata=declare(
            OptionSpec(
                "text",
                "A preset of the filter (GET /filters); none: its default",
                label="filter preset",
                group="filter",
                form="filter_preset",
                nullable=True,
            )
        ),
    )
    filter_params: dict[str, ParamValue] = field(
        default_factory=dict,
        metadata=declare(
            OptionSpec(
                "params",
                "Parameter overrides of the filter by dotted name, in the registry's units "
                "(GET /filters)",
                max_items=64,
            )
        ),
    )
    max_points: int = field(
        default=2000,
        metadata=declare(
            OptionSpec(
                "int",
                "Most time samples per plotted series (the result is decimated to it)",
                label="samples per plotted series",
                group="advanced",
                form="int",
                bounds=MAX_POINTS_RANGE,
                unit="samples",
            )
        ),
    )
    mapping: dict[str, str] = field(
        default_factory=dict,
        metadata=declare(
            OptionSpec(
                "mapping",
                'Rig roles by hand, role key → joint name ({"left_upper_arm": "LeftArm"}); '
                "roles not named are found from the joint names and the skeleton's structure.",
                max_items=len(ROLE_KEYS),
                check=check_mapping,
                check_in_request=True,
            )
        ),
    )
    limits_model: str | None = field(
        default=None,
        metadata=declare(
            OptionSpec(
                "text",
                "The limits model by name; none: the take's shoot's model, else the default",
                nullable=True,
                requested=False,
                check=model_option,
            )
        ),
    )

    def __post_init__(self) -> None:
        for declared in declared_fields(type(self)):
            value = getattr(self, declared.name)
            checked = check_field(declared, value)
            if checked is not value:
                object.__setattr__(self, declared.name, checked)
        check_filter_params(
            self.filter_method or DEFAULT_KEYPOINT_FILTER, self.filter_preset, self.filter_params
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
        """The options as a JSON-ready dict, every declared field in its order."""
        return {f.name: json_value(getattr(self, f.name)) for f in declared_fields(type(self))}

    def request_json(self) -> dict[str, Any]:
        """The body of a run request for these options (``POST /takes/{id}/runs``): the JSON
        less ``limits_model``, which a run does not choose (its shoot's model, or the
        default, decides)."""
        body = self.to_json()
        for declared in declared_fields(type(self)):
            if not declared.spec.requested:
                del body[declared.name]
        return body

    @classmethod
    def from_json(cls, data: dict[str, Any] | None) -> Self:
        """Options from a JSON dict; missing fields take their defaults.

        Raises
        ------
        InputError
            On an unknown field or a value of the wrong type.
        """
        if not data:
            return cls()
        declared = declared_fields(cls)
        known = sorted(f.name for f in declared)
        extra = sorted(set(data) - set(known))
        if extra:
            raise OptionError(extra[0], f"Expected option fields among {known}")
        return cls(**{f.name: read_field(f, data) for f in declared})


RUN_PRESETS: dict[str, AnalysisOptions] = {
    "full check": AnalysisOptions(),
    "twist only": AnalysisOptions(checks=("twist",)),
    "full check, no twist interval applied (decide each)": AnalysisOptions(twist_apply="none"),
    "full check, every twist interval applied": AnalysisOptions(twist_apply="all"),
    "limits only": AnalysisOptions(checks=("limits",)),
    "filter only": AnalysisOptions(checks=("filter",)),
    "markers only": AnalysisOptions(checks=("markers",)),
    "feet only": AnalysisOptions(checks=("feet",)),
    "full check, confident foot locks applied": AnalysisOptions(feet_apply="confident"),
}
"""Named option sets offered by the re-run form (a preset fills the form; every field stays
editable). The filter's own presets are the filter registry's."""


FORM_GROUPS: tuple[FormGroup, ...] = (
    FormGroup("twist", "Twist", "twist"),
    FormGroup("limits", "Joint limits", "limits", note="the rig's joint-limit model; no settings"),
    FormGroup(
        "markers",
        "Markers",
        "markers",
        note="swaps repaired, then confident gap fills applied; no settings",
    ),
    FormGroup("feet", "Feet and floor", "feet"),
    FormGroup("filter", "Filter", "filter"),
    FormGroup("advanced", "Advanced", None, advanced=True),
)
"""The groups of the re-run form, in its order: one per check (its box runs it), then the
settings of no check. A declared option shows in the group its spec names."""

DEFAULT_OPTIONS = AnalysisOptions()
"""The options of a run that chooses none (the CLI's defaults read it)."""


def option_fields(cls: type[AnalysisOptions] = AnalysisOptions) -> tuple[OptionField, ...]:
    """The declared run options of ``cls`` (:class:`AnalysisOptions` or a subclass declaring
    more), in their order."""
    return declared_fields(cls)


def _form_groups(fields: Sequence[OptionField]) -> list[dict[str, Any]]:
    """:data:`FORM_GROUPS` as the form describes them, each with its declared fields."""
    known = {group.name for group in FORM_GROUPS}
    strays = [f.name for f in fields if f.spec.group is not None and f.spec.group not in known]
    if strays:
        raise ValueError(f"Expected the form group of {strays} among {sorted(known)}")
    groups = []
    for group in FORM_GROUPS:
        described: dict[str, Any] = {"name": group.name, "label": group.label}
        described["check"] = group.check
        if group.advanced:
            described["advanced"] = True
        described["note"] = group.note
        shown = [f for f in fields if f.spec.group == group.name]
        described["fields"] = [describe_field(f, group) for f in shown]
        groups.append(described)
    return groups


def _take_kinds() -> dict[str, list[str]]:
    """The checks each kind of take can run (:func:`take_checks`): ``"motion"``, ``"markers"``
    (a keypoint take read from one of :data:`MARKER_FORMATS`) and ``"keypoints"``."""
    return {
        "motion": list(take_checks("motion")),
        "markers": list(take_checks("keypoints", MARKER_FORMATS[0])),
        "keypoints": list(take_checks("keypoints")),
    }


def _take_filters() -> dict[str, dict[str, str | None]]:
    """The filters each kind of take can run and its default (:func:`take_filter`), by the
    kinds of :func:`_take_kinds`."""
    return {"motion": take_filter("motion"), "markers": take_filter("keypoints"),
            "keypoints": take_filter("keypoints")}  # fmt: skip


def describe_options(cls: type[AnalysisOptions] = AnalysisOptions) -> dict[str, Any]:
    """The run options for a form: fields grouped by check, with types, units, choices, bounds,
    defaults, help and the check each field belongs to, :data:`RUN_PRESETS` as JSON options,
    the checks each kind of take can run (:func:`take_checks`, a form offers those only) and
    the role keys a ``mapping`` may name (:data:`mocapqa.core.rig.ROLE_KEYS`).

    Derived from the fields declared by ``cls`` (:class:`AnalysisOptions`, or a subclass
    declaring more) and the constants above, so a form offers exactly what ``from_json``
    accepts. Filter parameters come from the filter registry (``GET /filters``): they depend
    on the filter chosen.
    """
    return {
        "checks": list(CHECKS),
        "take_checks": _take_kinds(),
        "take_filters": _take_filters(),
        "marker_formats": list(MARKER_FORMATS),
        "groups": _form_groups(option_fields(cls)),
        "presets": {name: options.request_json() for name, options in RUN_PRESETS.items()},
        # The rig roles a ``mapping`` may name (BVH takes), in the rig module's order.
        "role_keys": list(ROLE_KEYS),
    }
