"""Rendered take thumbnails (PNG, SVG fallback), missing keypoints kept missing, HTML report."""

from __future__ import annotations

import io
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from PIL import Image

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.errors import RenderUnavailableError
from mocapqa.jobs.demo import demo_paths
from mocapqa.render.scene import SkeletonTrack
from mocapqa.render.service import RenderService

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]

TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
HEADER_LINES = 5
BLANKED = {(5, 0), (6, 0), (7, 0), (30, 4)}
"""(frame, keypoint) cells left empty in the uploaded TRC."""


class NoRendering(RenderService):
    """A render service on a machine where rendering cannot start."""

    def thumbnail(
        self,
        track: SkeletonTrack,
        frame: int | None = None,
        width_px: int = 192,
        height_px: int = 144,
    ) -> bytes:
        raise RenderUnavailableError("Expected an off-screen OpenGL window, got none")


@pytest.fixture
def trc_with_gaps(corpus_dir: Path, tmp_path: Path) -> Path:
    """The Pose2Sim TRC with a few keypoints' cells left empty (not detected)."""
    lines = (corpus_dir / TRC).read_text().split("\n")
    for frame, keypoint in BLANKED:
        row = lines[HEADER_LINES + frame].split("\t")
        row[2 + 3 * keypoint : 5 + 3 * keypoint] = ["", "", ""]
        lines[HEADER_LINES + frame] = "\t".join(row)
    path = tmp_path / "gaps.trc"
    path.write_text("\n".join(lines))
    return path


def test_missing_keypoints_stay_missing_in_frames_and_thumbnails(
    client: TestClient, trc_with_gaps: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, trc_with_gaps)
    run = wait_for_run(client, created["run_id"])
    assert run["status"] == "done", run["error"]
    frames = client.get(f"/api/v1/runs/{created['run_id']}/frames?max_frames=20000").json()
    assert frames["frames"] == list(range(created["n_frames"]))
    raw = frames["raw"]
    missing = {(f, k) for f, frame in enumerate(raw) for k, p in enumerate(frame) if p[0] is None}
    assert missing == BLANKED
    for f, k in BLANKED:
        assert raw[f][k] == [None, None, None]
    present = np.asarray(
        [raw[f][k] for f in range(len(raw)) for k in range(5) if (f, k) not in BLANKED]
    )
    assert np.all(np.abs(present).sum(axis=1) > 0)  # nothing else at the origin
    # The filter bridges the gaps: corrected points exist where the raw ones are missing.
    assert all(frames["corrected"][f][k][0] is not None for f, k in BLANKED)
    thumbnail = client.get(f"/api/v1/takes/{created['id']}/thumbnail")
    assert thumbnail.headers["content-type"] == "image/png"


def test_thumbnail_is_rendered_after_analysis(
    client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, cmu_walk)
    assert wait_for_run(client, created["run_id"])["status"] == "done"
    response = client.get(f"/api/v1/takes/{created['id']}/thumbnail")
    assert response.status_code == 200
    assert response.headers["content-type"] == "image/png"
    image = np.asarray(Image.open(io.BytesIO(response.content)).convert("RGB"))
    assert image.shape == (144, 192, 3)
    rgb = image.astype(int)
    # Skeleton pixels: dark or saturated, unlike the white background and the grey floor.
    skeleton = (rgb.max(axis=-1) < 150) | (rgb.max(axis=-1) - rgb.min(axis=-1) > 80)
    assert 15 < skeleton.sum() < 0.5 * skeleton.size


@pytest.fixture
def unrendered_client(settings: Settings) -> Iterator[TestClient]:
    """A client of an app whose render service cannot draw."""
    with NoRendering() as service, TestClient(create_app(settings, renderer=service)) as client:
        yield client


def test_thumbnail_falls_back_to_svg_without_rendering(
    unrendered_client: TestClient, cmu_walk: Path, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(unrendered_client, cmu_walk)
    assert wait_for_run(unrendered_client, created["run_id"])["status"] == "done"
    response = unrendered_client.get(f"/api/v1/takes/{created['id']}/thumbnail")
    assert response.headers["content-type"].startswith("image/svg+xml")
    assert b"<line" in response.content


def test_html_report_downloads_with_findings_and_contact_sheet(
    client: TestClient, upload: Uploader, wait_for_run: Waiter
) -> None:
    created = upload(client, demo_paths()[0])  # the CMU walk with injected twist errors
    run_id = created["run_id"]
    assert wait_for_run(client, run_id)["status"] == "done"
    result = client.get(f"/api/v1/runs/{run_id}/result").json()
    assert result["summary"]["n_findings"] > 0
    response = client.get(f"/api/v1/runs/{run_id}/download/report.html")
    assert response.status_code == 200
    assert response.headers["content-type"].startswith("text/html")
    assert "attachment" in response.headers["content-disposition"]
    page = response.text
    assert page.lstrip().lower().startswith("<!doctype html")
    assert created["sha256"] in page
    assert "LeftArm" in page  # an injected interval's joint, in the findings table
    assert "data:image/png;base64," in page  # the contact sheet
    again = client.get(f"/api/v1/runs/{run_id}/download/report.html")
    assert again.content == response.content
    assert client.get("/api/v1/runs/0123/download/report.html").status_code == 404
