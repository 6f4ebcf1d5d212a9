"""``GET /run-options``: the re-run form's fields and presets (pipeline/options.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient
from tests.api.conftest import Uploader

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
    ("feet", "feet", []),
    ("filter", "filter", ["filter_method", "filter_preset"]),
    ("advanced", None, ["max_points"]),
]
"""(name, check, field names) of each group, in the form's order."""
DEFAULT_REQUEST: dict[str, Any] = {
    "checks": ["twist", "limits", "filter", "markers", "feet"],
    "twist_method": "robust",
    "twist_apply": "confident",
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
}
"""Each preset's difference from :data:`DEFAULT_REQUEST`."""
SIDES = ("left", "right")
ROLES = ("clavicle", "upper_arm", "forearm", "hand", "upper_leg", "lower_leg", "foot", "toe")


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
    for group in groups:
        assert group["label"], group["name"]
        for field in group["fields"]:
            assert field["label"], field["name"]
            shown = {key: value for key, value in field.items() if key not in ("name", "label")}
            assert shown == FIELDS[field["name"]], field["name"]
    assert list(body["presets"]) == list(PRESETS)  # the form's menu, in this order
    assert body["presets"] == {
        name: {**DEFAULT_REQUEST, **changes} for name, changes in PRESETS.items()
    }
    assert body["role_keys"] == [f"{side}_{role}" for side in SIDES for role in ROLES]


def test_every_preset_is_a_run_request_as_served(
    client: TestClient, cmu_walk: Path, upload: Uploader
) -> None:
    take = upload(client, cmu_walk)
    presets = client.get("/api/v1/run-options").json()["presets"]
    for name, body in presets.items():
        sent = client.post(f"/api/v1/takes/{take['id']}/runs", json=body)
        assert sent.status_code == 201, (name, sent.text)
