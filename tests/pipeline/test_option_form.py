"""The run options as the re-run form gets them: derived from AnalysisOptions, presets valid."""

from __future__ import annotations

import dataclasses
import re

import pytest

from mocapqa.errors import InputError, OptionError
from mocapqa.filters.apply import resolve_params
from mocapqa.filters.registry import DataScale
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


@pytest.mark.parametrize(
    ("method", "params", "field", "message"),
    [
        # Strings are converted by the filter: "inf" and "nan" got through the JSON check.
        ("adaptive", {"window_s": "inf"}, "filter_params.window_s", "0.0001 to 60 s"),
        (
            "adaptive",
            {"confidence_threshold": "nan"},
            "filter_params.confidence_threshold",
            "0 to 1",
        ),
        (
            "adaptive",
            {"kalman.process_noise": "1e400"},
            "filter_params.kalman.process_noise",
            "1e+24",
        ),
        ("kalman", {"measurement_noise": 1e30}, "filter_params.measurement_noise", "1e+24"),
        ("one-euro", {"beta": "inf"}, "filter_params.beta", "0 to 1e+20"),
        ("adaptive", {"innovation_power": 50}, "filter_params.innovation_power", "at most 10"),
        # An int past a float's range overflowed math.isfinite: a 500 from the API.
        ("ema", {"time_constant_s": 10**400}, "filter_params.time_constant_s", "0.0001 to 60 s"),
        ("butterworth", {"order": -(10**400)}, "filter_params.order", "order"),
    ],
)
def test_run_options_refuse_filter_parameters_out_of_their_range(
    method: str, params: dict[str, object], field: str, message: str
) -> None:
    with pytest.raises(OptionError, match=re.escape(message)) as raised:
        AnalysisOptions.from_json({"filter_method": method, "filter_params": params})
    assert raised.value.field == field
    assert str(raised.value).count(field) == 1


def test_run_options_take_the_bounds_of_the_ranges() -> None:
    """A value at either end of its range is accepted, kept as sent and reaches the filter;
    a step past it is refused, naming the parameter and its range."""
    params = {"window_s": 60.0, "lead_s": 0, "kalman.bridge_decay_s": 0.0, "innovation_power": 10}
    options = AnalysisOptions.from_json({"filter_method": "adaptive", "filter_params": params})
    assert options.filter_params == params
    assert AnalysisOptions.from_json(options.to_json()) == options
    used = resolve_params("adaptive", "default", DataScale(), options.filter_params)
    assert used.window_s == 60.0
    assert used.lead_s == 0
    assert used.kalman.bridge_decay_s == 0.0
    assert used.innovation_power == 10
    past = {
        "window_s": (60.001, "0.0001 to 60 s"),
        "lead_s": (-0.001, "0 to 60 s"),
        "kalman.bridge_decay_s": (-0.001, "0 to 60 s"),
        "innovation_power": (10.001, "> 0 and at most 10"),
    }
    for name, (value, described) in past.items():
        with pytest.raises(OptionError, match=re.escape(described)) as raised:
            AnalysisOptions.from_json({"filter_method": "adaptive", "filter_params": {name: value}})
        assert raised.value.field == f"filter_params.{name}"


def test_an_apply_list_past_its_cap_is_refused_when_asked_for() -> None:
    # 100,000 ids (a 590 KB string) were stored and queued, and failed when the run started.
    with pytest.raises(OptionError, match="at most 10,000 interval ids") as raised:
        AnalysisOptions.from_json({"twist_apply": ",".join(str(i) for i in range(100_000))})
    assert raised.value.field == "twist_apply"
    with pytest.raises(OptionError, match="at most 10,000 interval ids"):
        AnalysisOptions.from_json({"twist_apply": ",".join(["0"] * 40_001)})  # 80,001 characters
    AnalysisOptions.from_json({"twist_apply": ",".join(str(i) for i in range(10_000))})


@pytest.mark.parametrize(
    ("checks", "message"),
    [
        (["twist"] * 100_000, f"Expected each of {list(CHECKS)} at most once"),
        (["limits", "filter", "limits"], "got 'limits' 2 times"),
        (["spin"] * 100_000 + ["twist"], "got ['spin']"),
    ],
)
def test_checks_are_known_names_each_at_most_once(checks: list[str], message: str) -> None:
    """A list of 100,000 checks was stored with the run as sent (a batch options file or a
    stored run's options read back alike)."""
    with pytest.raises(OptionError, match=re.escape(message)) as raised:
        AnalysisOptions.from_json({"checks": checks})
    assert raised.value.field == "checks"
    assert len(str(raised.value)) < 200
    assert AnalysisOptions.from_json({"checks": ["filter", "twist"]}).checks == ("filter", "twist")
