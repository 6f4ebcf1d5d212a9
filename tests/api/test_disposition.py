"""Download names: the user's own name, in any script, sent as RFC 6266 asks."""

from __future__ import annotations

from urllib.parse import unquote

from fastapi.testclient import TestClient

from mocapqa.api.disposition import attachment, download_stem


def test_a_name_in_any_script_is_kept_and_nothing_breaks_the_header() -> None:
    header = attachment('ünïcödé 日本 "x"\r\n.bvh')["Content-Disposition"]
    assert "\r" not in header
    assert "\n" not in header
    fallback, encoded = header.split("; filename*=UTF-8''")
    assert fallback == 'attachment; filename="_n_c_d_ __ _x___.bvh"'
    assert unquote(encoded) == 'ünïcödé 日本 "x"\r\n.bvh'
    assert download_stem({"name": "ünïcödé.bvh", "file_name": "_n_c_d_.bvh"}) == "ünïcödé"
    assert download_stem({"name": "", "file_name": "walk.bvh"}) == "walk"


def test_a_shoot_summary_downloads_under_the_shoot_name(client: TestClient) -> None:
    shoot = client.post("/api/v1/shoots", json={"name": "Prise 日本"}).json()
    response = client.get(f"/api/v1/shoots/{shoot['id']}/summary.csv")
    assert response.status_code == 200
    encoded = response.headers["content-disposition"].split("filename*=UTF-8''")[1]
    assert unquote(encoded) == "Prise 日本.summary.csv"
