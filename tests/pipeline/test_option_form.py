"""The run options' one declaration (``AnalysisOptions`` in pipeline/options.py), written out
here: the JSON form and the re-run form's description follow it, presets are valid."""

from __future__ import annotations

import re
from typing import Any

import pytest

from mocapqa.errors import InputError, OptionError
from mocapqa.filters.apply import resolve_params
from mocapqa.filters.registry import DataScale
from mocapqa.pipeline.options import (
    CHECKS,
    DEFAULT_OPTIONS,
    RUN_PRESETS,
    AnalysisOptions,
    describe_options,
    option_fields,
)

DECLARED: dict[str, tuple[str, Any, str | None, tuple[str, ...], tuple[int, int] | None]] = {
    "checks": ("names", ("twist", "limits", "filter", "markers", "feet"), None,
               ("twist", "limits", "filter", "markers", "feet"), None),
    "twist_method": ("text", "robust", "twist", ("robust", "paper"), None),
    "twist_apply": ("text", "confident", "twist", ("confident", "all", "none"), None),
    "feet_apply": ("text", "none", "feet", ("none", "confident", "skates"), None),
    "filter_method": ("text", None, "filter", (), None),
    "filter_preset": ("text", None, "filter", (), None),
    "filter_params": ("params", {}, None, (), None),
    "max_points": ("int", 2000, "advanced", (), (10, 100_000)),
    "mapping": ("mapping", {}, None, (), None),
    "limits_model": ("text", None, None, (), None),
}  # fmt: skip
"""Each option written out: (JSON kind, default, form group, choices, bounds), in order."""
CHANGED: dict[str, Any] = {
    "checks": ["feet", "twist"],
    "twist_method": "paper",
    "twist_apply": "0,3",
    "feet_apply": "skate-left-120,skate-right-348",
    "filter_method": "butterworth",
    "filter_preset": "default",
    "filter_params": {"cutoff_hz": 4.0, "order": 2},
    "max_points": 10,
    "mapping": {"left_upper_arm": "LeftArm"},
    "limits_model": "walks",
}
"""A value other than the default for every option, as JSON."""


def test_the_declaration_is_the_options_written_out() -> None:
    declared = {
        f.name: (f.spec.kind, f.default, f.spec.group, f.spec.choices, f.spec.bounds)
        for f in option_fields()
    }
    assert list(declared) == list(DECLARED)
    assert declared == DECLARED
    assert [f.name for f in option_fields() if not f.spec.requested] == ["limits_model"]
    assert all(f.spec.help for f in option_fields())
    assert AnalysisOptions() == DEFAULT_OPTIONS
    assert DEFAULT_OPTIONS.to_json() == {
        name: list(default) if isinstance(default, tuple) else default
        for name, (_, default, *_) in DECLARED.items()
    }


def test_every_option_goes_through_the_json_form_and_back() -> None:
    options = AnalysisOptions.from_json(CHANGED)
    assert options.to_json() == CHANGED
    assert AnalysisOptions.from_json(options.to_json()) == options
    assert options.request_json() == {k: v for k, v in CHANGED.items() if k != "limits_model"}
    for name, value in CHANGED.items():  # each alone (with its filter), the others default
        sent = {"filter_method": "butterworth", name: value} if "filter" in name else {name: value}
        alone = AnalysisOptions.from_json(sent)
        assert alone.to_json() == {**DEFAULT_OPTIONS.to_json(), **sent}, name
    wrong = {"checks": "twist", "max_points": 2000.0, "twist_method": 1, "filter_params": ["x"]}
    for name, value in wrong.items():
        with pytest.raises(OptionError, match="^" + name + ": Expected") as raised:
            AnalysisOptions.from_json({name: value})
        assert raised.value.field == name


def test_the_form_shows_the_declared_fields_with_their_defaults() -> None:
    described = describe_options()
    fields = {f["name"]: f for g in described["groups"] for f in g["fields"]}
    # Checks are the groups' own boxes; filter parameters come from the filter registry,
    # mapping is set per take, the limits model per shoot.
    shown = {name for name, (_, _, group, _, _) in DECLARED.items() if group is not None}
    assert set(fields) == shown
    for name, (_, default, group, choices, bounds) in DECLARED.items():
        if group is None:
            continue
        assert fields[name]["default"] == default, name
        assert fields[name].get("choices", []) == list(choices), name
        assert (fields[name].get("minimum"), fields[name].get("maximum")) == (bounds or (None,) * 2)
        assert (
            next(g for g in described["groups"] if name in [f["name"] for f in g["fields"]])["name"]
            == group
        )
    assert fields["max_points"]["unit"] == "samples"
    assert described["checks"] == list(CHECKS)
    assert {g["check"] for g in described["groups"]} - {None} == set(CHECKS)


def test_presets_are_valid_options_and_the_bounds_are_enforced() -> None:
    presets = describe_options()["presets"]
    assert set(presets) == set(RUN_PRESETS)
    for name, options in presets.items():
        assert AnalysisOptions.from_json(options) == RUN_PRESETS[name]
    with pytest.raises(InputError, match=r"^max_points: Expected 10 to 100000"):
        AnalysisOptions(max_points=100_001)
    with pytest.raises(InputError, match=r"^twist_method: Expected one of \['robust', 'paper'\]"):
        AnalysisOptions(twist_method="spin")


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
