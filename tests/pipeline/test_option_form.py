"""The run options as the re-run form gets them: derived from AnalysisOptions, presets valid."""

from __future__ import annotations

import dataclasses

import pytest

from mocapqa.errors import InputError
from mocapqa.pipeline.options import (
    CHECKS,
    MAX_POINTS_RANGE,
    RUN_PRESETS,
    TWIST_APPLY_CHOICES,
    TWIST_METHODS,
    AnalysisOptions,
    describe_options,
)


def test_every_field_of_the_form_is_an_option_with_its_default() -> None:
    described = describe_options()
    fields = {f["name"]: f for g in described["groups"] for f in g["fields"]}
    option_names = {f.name for f in dataclasses.fields(AnalysisOptions)}
    # Every field is an option (checks are the groups' own boxes; mapping is set per take, the
    # limits model per shoot).
    assert set(fields) <= option_names
    assert option_names - set(fields) == {"checks", "filter_params", "mapping", "limits_model"}
    default = AnalysisOptions()
    for name, field in fields.items():
        assert field["default"] == getattr(default, name), name
    assert fields["twist_method"]["choices"] == list(TWIST_METHODS)
    assert fields["twist_apply"]["choices"] == list(TWIST_APPLY_CHOICES)
    assert (fields["max_points"]["minimum"], fields["max_points"]["maximum"]) == MAX_POINTS_RANGE
    assert fields["max_points"]["unit"] == "samples"
    assert described["checks"] == list(CHECKS)
    assert {g["check"] for g in described["groups"]} - {None} == set(CHECKS)


def test_presets_are_valid_options_and_the_bounds_are_enforced() -> None:
    presets = describe_options()["presets"]
    assert set(presets) == set(RUN_PRESETS)
    for name, options in presets.items():
        assert AnalysisOptions.from_json(options) == RUN_PRESETS[name]
    low, high = MAX_POINTS_RANGE
    with pytest.raises(InputError, match=rf"^max_points: Expected {low} to {high}"):
        AnalysisOptions(max_points=high + 1)
