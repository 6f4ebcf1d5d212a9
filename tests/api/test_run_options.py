"""``GET /run-options``: the re-run form's fields and presets (pipeline/options.py)."""

from __future__ import annotations

from fastapi.testclient import TestClient

from mocapqa.pipeline.options import RUN_PRESETS, describe_options


def test_the_api_serves_the_form(client: TestClient) -> None:
    served = client.get("/api/v1/run-options")
    assert served.status_code == 200
    assert served.json() == describe_options()
    assert set(served.json()["presets"]) == set(RUN_PRESETS)
