"""``GET /run-options`` and the run request's schema, against the one declaration of the run
options (``AnalysisOptions`` in pipeline/options.py): what is served is what is declared."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from pydantic import ValidationError
from tests.api.conftest import Uploader

from mocapqa.api.routes import filters as filter_routes
from mocapqa.api.schemas import options_request_model
from mocapqa.errors import OptionError
from mocapqa.pipeline.option_fields import OptionSpec, declare
from mocapqa.pipeline.options import AnalysisOptions, describe_options, option_fields

# What the re-run form (frontend/js/rerun.js) builds itself from, written out: the groups in
# their order with the check each belongs to, every field with its type, default, choices or
# bounds and unit, and the named presets as run requests.
FIELDS: dict[str, dict[str, Any]] = {
    "twist_method": {
        "type": "choice", "choices": ["robust", "paper"], "default": "robust", "unit": "",
        "check": "twist",
    },
    "twist_apply": {
        "type": "choice", "choices": ["confident", "all", "none"], "default": "confident",
        "unit": "", "check": "twist",
    },
    "feet_apply": {
        "type": "choice", "choices": ["none", "confident", "skates"], "default": "none",
        "unit": "", "check": "feet",
    },
    "filter_method": {"type": "filter", "default": None, "unit": "", "check": "filter"},
    "filter_preset": {"type": "filter_preset", "default": None, "unit": "", "check": "filter"},
    "max_points": {
        "type": "int", "default": 2000, "minimum": 10, "maximum": 100_000, "unit": "samples",
        "check": None,
    },
}  # fmt: skip
GROUPS = [
    ("twist", "twist", ["twist_method", "twist_apply"]),
    ("limits", "limits", []),
    ("markers", "markers", []),
    ("feet", "feet", ["feet_apply"]),
    ("filter", "filter", ["filter_method", "filter_preset"]),
    ("advanced", None, ["max_points"]),
]
"""(name, check, field names) of each group, in the form's order."""
DEFAULT_REQUEST: dict[str, Any] = {
    "checks": ["twist", "limits", "filter", "markers", "feet"],
    "twist_method": "robust",
    "twist_apply": "confident",
    "feet_apply": "none",
    "filter_method": None,
    "filter_preset": None,
    "filter_params": {},
    "max_points": 2000,
    "mapping": {},
}
"""A run request with every option at its default (a run does not choose its limits model)."""
PRESETS: dict[str, dict[str, Any]] = {
    "full check": {},
    "twist only": {"checks": ["twist"]},
    "full check, no twist interval applied (decide each)": {"twist_apply": "none"},
    "full check, every twist interval applied": {"twist_apply": "all"},
    "limits only": {"checks": ["limits"]},
    "filter only": {"checks": ["filter"]},
    "markers only": {"checks": ["markers"]},
    "feet only": {"checks": ["feet"]},
    "full check, confident foot locks applied": {"feet_apply": "confident"},
}
"""Each preset's difference from :data:`DEFAULT_REQUEST`."""
SIDES = ("left", "right")
ROLES = ("clavicle", "upper_arm", "forearm", "hand", "upper_leg", "lower_leg", "foot", "toe")


def served_fields(client: TestClient) -> dict[str, dict[str, Any]]:
    """The fields of the form ``GET /run-options`` serves, by name."""
    body = client.get("/api/v1/run-options").json()
    return {f["name"]: f for group in body["groups"] for f in group["fields"]}


def test_the_api_serves_each_take_kinds_filters_and_default(client: TestClient) -> None:
    body = client.get("/api/v1/run-options").json()
    assert body["take_filters"] == {
        "motion": {"target": "rotations", "default": None},
        "markers": {"target": "keypoints", "default": "adaptive"},
        "keypoints": {"target": "keypoints", "default": "adaptive"},
    }
    registry = {f["name"]: f for f in client.get("/api/v1/filters").json()}
    for served in body["take_filters"].values():
        default = served["default"]
        assert default is None or served["target"] in registry[default]["applies_to"]


def test_the_api_serves_the_form(client: TestClient) -> None:
    served = client.get("/api/v1/run-options")
    assert served.status_code == 200
    body = served.json()
    assert body["checks"] == ["twist", "limits", "filter", "markers", "feet"]
    groups = body["groups"]
    assert [(g["name"], g["check"], [f["name"] for f in g["fields"]]) for g in groups] == GROUPS
    assert [g.get("advanced", False) for g in groups] == [False] * 5 + [True]
    assert body["take_checks"] == {
        "motion": ["twist", "limits", "feet", "filter"],
        "markers": ["markers", "feet", "filter"],
        "keypoints": ["feet", "filter"],
    }
    assert body["marker_formats"] == ["c3d", "trc"]
    notes = {g["name"]: g["note"] for g in groups}
    assert "no settings" in notes["limits"]
    assert "no settings" in notes["markers"]
    for group in groups:
        assert group["label"], group["name"]
        for served_field in group["fields"]:
            assert served_field["label"], served_field["name"]
            assert served_field["help"], served_field["name"]
            shown = {k: v for k, v in served_field.items() if k not in ("name", "label", "help")}
            assert shown == FIELDS[served_field["name"]], served_field["name"]
    assert list(body["presets"]) == list(PRESETS)  # the form's menu, in this order
    assert body["presets"] == {
        name: {**DEFAULT_REQUEST, **changes} for name, changes in PRESETS.items()
    }
    assert body["role_keys"] == [f"{side}_{role}" for side in SIDES for role in ROLES]


def test_the_served_form_and_request_schema_are_the_declaration(client: TestClient) -> None:
    """Every declared option with a place in the form is served with its declared default,
    choices, bounds and help, and nothing else is; every option a run request carries is in
    the request's schema with the same default and bounds."""
    declared = option_fields()
    served = served_fields(client)
    assert list(served) == [f.name for f in declared if f.spec.group is not None]
    for option in declared:
        if option.name not in served:
            continue
        shown = served[option.name]
        assert shown["default"] == option.default, option.name
        assert shown.get("choices", []) == list(option.spec.choices), option.name
        bounds = (shown["minimum"], shown["maximum"]) if "minimum" in shown else None
        assert bounds == option.spec.bounds, option.name
        assert (shown["label"], shown["help"]) == (option.spec.label, option.spec.help)
    schema = client.get("/openapi.json").json()["components"]["schemas"]["AnalysisOptionsIn"]
    properties = schema["properties"]
    assert list(properties) == list(DEFAULT_REQUEST)
    assert [f.name for f in declared if f.spec.requested] == list(DEFAULT_REQUEST)
    for name, default in DEFAULT_REQUEST.items():  # the schema leaves out None and {}
        assert properties[name].get("default") == (default or None), name
    assert (properties["max_points"]["minimum"], properties["max_points"]["maximum"]) == (
        10,
        100_000,
    )
    assert properties["twist_method"]["enum"] == ["robust", "paper"]
    assert properties["checks"]["items"]["enum"] == DEFAULT_REQUEST["checks"]
    assert properties["checks"]["maxItems"] == 5
    assert properties["mapping"]["maxProperties"] == len(SIDES) * len(ROLES)
    assert properties["filter_params"]["maxProperties"] == 64


@dataclass(frozen=True, slots=True)
class WithSmoothing(AnalysisOptions):
    """The run options and one more, declared as every option is."""

    smoothing_frames: int = field(
        default=3,
        metadata=declare(
            OptionSpec(
                "int",
                "Frames of a moving average before the filter",
                label="smoothing",
                group="filter",
                form="int",
                bounds=(1, 9),
                unit="frames",
            )
        ),
    )


def test_a_declared_field_reaches_the_form_the_request_and_the_json(
    client: TestClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(filter_routes, "describe_options", partial(describe_options, WithSmoothing))
    filter_group = next(
        g for g in client.get("/api/v1/run-options").json()["groups"] if g["name"] == "filter"
    )
    assert [f["name"] for f in filter_group["fields"]][-1] == "smoothing_frames"
    assert filter_group["fields"][-1] == {
        "name": "smoothing_frames", "label": "smoothing", "type": "int", "default": 3,
        "minimum": 1, "maximum": 9, "unit": "frames", "check": "filter",
        "help": "Frames of a moving average before the filter",
    }  # fmt: skip
    # The request model takes it, with its default and bounds.
    model = options_request_model(WithSmoothing)
    schema = model.model_json_schema()["properties"]["smoothing_frames"]
    assert (schema["default"], schema["minimum"], schema["maximum"]) == (3, 1, 9)
    assert model().model_dump()["smoothing_frames"] == 3
    with pytest.raises(ValidationError, match="smoothing_frames"):
        model.model_validate({"smoothing_frames": 10})
    # The JSON form round-trips it, and refuses it out of its bounds or of the wrong type.
    sent = model.model_validate({"smoothing_frames": 5}).model_dump()
    options = WithSmoothing.from_json(sent)
    assert options.smoothing_frames == 5
    assert options.to_json()["smoothing_frames"] == 5
    assert WithSmoothing.from_json(options.to_json()) == options
    assert WithSmoothing.from_json({}).smoothing_frames == 3
    for bad, message in ((10, "Expected 1 to 9, got 10"), ("5", "Expected an integer")):
        with pytest.raises(OptionError, match=message) as raised:
            WithSmoothing.from_json({"smoothing_frames": bad})
        assert raised.value.field == "smoothing_frames"
    # The options without it know nothing of it.
    with pytest.raises(OptionError, match="Expected option fields among") as raised:
        AnalysisOptions.from_json({"smoothing_frames": 5})
    assert raised.value.field == "smoothing_frames"


def test_every_preset_is_a_run_request_as_served(
    client: TestClient, cmu_walk: Path, upload: Uploader
) -> None:
    take = upload(client, cmu_walk)
    presets = client.get("/api/v1/run-options").json()["presets"]
    for name, body in presets.items():
        sent = client.post(f"/api/v1/takes/{take['id']}/runs", json=body)
        assert sent.status_code == 201, (name, sent.text)
