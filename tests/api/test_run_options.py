"""``GET /run-options``: the re-run form's fields and presets (pipeline/options.py)."""

from __future__ import annotations

from pathlib import Path

from fastapi.testclient import TestClient
from tests.api.conftest import Uploader

from mocapqa.pipeline.options import RUN_PRESETS, describe_options


def test_the_api_serves_the_form(client: TestClient) -> None:
    served = client.get("/api/v1/run-options")
    assert served.status_code == 200
    assert served.json() == describe_options()
    assert set(served.json()["presets"]) == set(RUN_PRESETS)


def test_every_preset_is_a_run_request_as_served(
    client: TestClient, cmu_walk: Path, upload: Uploader
) -> None:
    take = upload(client, cmu_walk)
    presets = client.get("/api/v1/run-options").json()["presets"]
    for name, body in presets.items():
        sent = client.post(f"/api/v1/takes/{take['id']}/runs", json=body)
        assert sent.status_code == 201, (name, sent.text)
