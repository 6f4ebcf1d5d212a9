"""BVH takes users bring, uploaded and run: built from real corpus takes in the test.

A malformed, huge or hostile BVH is refused at upload with a 4xx whose body names the file and
the line (or the field or limit), and nothing is stored; an unusual but valid one is stored,
its run finishes, and it is drawn in the same place as the plain take it was made from.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import make_settings, poll_run
from tests.io.bvh_variants import (
    WALK,
    Take,
    chain,
    fan,
    garbage,
    mixed_case,
    positions_everywhere,
    reordered,
    tabs,
    z_up,
)

from mocapqa.api.app import create_app


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[TestClient]:
    """One app for the module, its upload rate raised for the many uploads."""
    settings = make_settings(
        "sqlite", tmp_path_factory.mktemp("hostile-bvh"), uploads_per_minute_per_user=1000
    )
    with TestClient(create_app(settings)) as test_client:
        yield test_client


@pytest.fixture(scope="module")
def walk(corpus_dir: Path) -> Take:
    """Eight frames of the CMU walk, from its frame 100."""
    return Take.load(corpus_dir / WALK, 8, start=100)


def first_value(take: Take, row: int, text: str) -> bytes:
    rows = list(take.rows)
    rows[row] = f"{text} {rows[row].split(' ', 1)[1]}"
    return take.with_rows(rows).data()


def lower_case_joints(n_joints: int) -> bytes:
    """A chain of ``n_joints`` written with lower-case keywords (``joint``), as the reader
    takes them, so the joint count before parsing must count them too."""
    return chain(n_joints).replace(b"JOINT ", b"joint ").replace(b"ROOT ", b"root ")


# Each case, from the walk's 8 frames and its H hierarchy lines (MOTION on H + 1, Frames: on
# H + 2, Frame Time: on H + 3, frame k on H + 4 + k): the bytes, the status, the error class,
# what the detail must say and the line it must name (None: no line, a field or a limit).
REFUSED: dict[str, Callable[[Take, int], tuple[bytes, int, str, str, int | None]]] = {
    "1e308 in a frame": lambda t, h: (
        first_value(t, 2, "1e308"),
        422,
        "ParseError",
        "Expected values within ±1,000,000,000, got '1e308'",
        h + 6,
    ),
    "Frames: 0": lambda t, h: (
        t.with_rows([]).data(),
        422,
        "ParseError",
        "field 'Frames': Expected at least one frame, got 0",
        None,
    ),
    "Frame Time: 120 (a frame rate)": lambda t, h: (
        t.text().replace(f"Frame Time: {t.frame_time}", "Frame Time: 120").encode(),
        422,
        "ParseError",
        "(a frame rate? Frame Time is seconds per frame, 0.008333333 for 120 fps)",
        h + 3,
    ),
    "cut in a frame line": lambda t, h: (
        t.text()[: len(t.text()) - 40].encode(),
        422,
        "ParseError",
        "values on a frame line, got",
        h + 11,
    ),
    "no MOTION section": lambda t, h: (
        "\n".join(t.hierarchy).encode(),
        422,
        "ParseError",
        "Expected a 'MOTION' section, got end of file",
        h,
    ),
    "duplicate joint names": lambda t, h: (
        t.renamed({"LeftArm": "RightArm"}).data(),
        422,
        "ParseError",
        "Expected unique joint names, got 'RightArm' twice",
        None,
    ),
    "random bytes": lambda t, h: (
        garbage(4096, seed=11),
        422,
        "ParseError",
        "Expected a text file, got binary data",
        1,
    ),
    "a JSON file named .bvh": lambda t, h: (
        b'{"fps": 30, "frames": []}\n',
        422,
        "ParseError",
        "Expected 'HIERARCHY', got",
        1,
    ),
    "an empty file": lambda t, h: (
        b"",
        422,
        "ParseError",
        "Expected a non-empty file, got 0 bytes",
        None,
    ),
    "Frames: 10000000000 over a few rows": lambda t, h: (
        t.data(frames=10_000_000_000),
        413,
        "TooLargeError",
        "frames × joints (setting max_frame_points), got 10000000000 × 31",
        None,
    ),
    "5,000 joints deep": lambda t, h: (
        chain(5000),
        413,
        "TooLargeError",
        "joints (setting max_joints), got 5000",
        None,
    ),
    "20,000 joints wide": lambda t, h: (
        fan(20_000),
        413,
        "TooLargeError",
        "joints (setting max_joints), got 20000",
        None,
    ),
    "600 joints in UTF-16": lambda t, h: (
        chain(600).decode().encode("utf-16"),
        413,
        "TooLargeError",
        "joints (setting max_joints), got 600",
        None,
    ),
    "600 joints in lower case": lambda t, h: (
        lower_case_joints(600),
        413,
        "TooLargeError",
        "joints (setting max_joints), got 600",
        None,
    ),
}


def stored_takes(client: TestClient) -> int:
    total: int = client.get("/api/v1/takes").json()["total"]
    return total


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_a_bad_take_is_refused_naming_the_file_and_line(
    client: TestClient, walk: Take, case: str
) -> None:
    data, status, error, message, line = REFUSED[case](walk, len(walk.hierarchy))
    before = stored_takes(client)
    response = client.post("/api/v1/takes", files={"file": ("hostile.bvh", data)})
    assert response.status_code == status, response.text
    body = response.json()
    assert body["error"] == error
    assert body["detail"].startswith("hostile.bvh")
    assert message in body["detail"], body["detail"]
    if line is not None:
        assert body["line"] == line, body
    assert stored_takes(client) == before


def upload_and_run(client: TestClient, name: str, data: bytes) -> dict[str, Any]:
    """Upload, wait for the run, and return the take's reading and the run's frames."""
    response = client.post("/api/v1/takes", files={"file": (name, data)})
    assert response.status_code == 201, response.text
    take = response.json()
    run = poll_run(client, take["run_id"])
    assert run["status"] == "done", run.get("error")
    assert client.get(f"/api/v1/runs/{take['run_id']}/result").status_code == 200
    frames = client.get(f"/api/v1/runs/{take['run_id']}/frames")
    assert frames.status_code == 200, frames.text
    return {"take": take, "frames": frames.json()}


BIPED_ARMS = {
    "LeftArm": "Bip01 L UpperArm",
    "LeftForeArm": "Bip01 L Forearm",
    "RightArm": "Bip01 R UpperArm",
    "RightForeArm": "Bip01 R Forearm",
}
TURN_BACK = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
"""Z-up points back to Y-up ones (the inverse of ``bvh_variants.Z_UP_TURN``)."""

ACCEPTED: dict[str, tuple[Callable[[Take], bytes], np.ndarray | None]] = {
    "an odd exporter's take": (
        lambda t: mixed_case(
            Take.parse(tabs(positions_everywhere(reordered(t.renamed(BIPED_ARMS), "XYZ"))).decode())
        ).replace(b"\n", b"\r\n"),
        None,
    ),
    "UTF-16 with byte order mark": (lambda t: t.text().encode("utf-16"), None),
    "Z-up": (lambda t: z_up(t).data(), TURN_BACK),
}


@pytest.mark.parametrize("case", sorted(ACCEPTED))
def test_an_unusual_take_runs_and_is_drawn_where_its_source_is(
    client: TestClient, walk: Take, case: str
) -> None:
    source = upload_and_run(client, "source.bvh", walk.data())
    build, turn = ACCEPTED[case]
    variant = upload_and_run(client, "variant.bvh", build(walk))
    assert variant["take"]["n_frames"] == source["take"]["n_frames"] == 8
    assert variant["take"]["n_joints"] == 31
    raw = np.array(variant["frames"]["raw"], dtype=float)
    expected = np.array(source["frames"]["raw"], dtype=float)
    if turn is not None:
        raw = raw @ turn.T
    np.testing.assert_allclose(raw, expected, rtol=0, atol=1e-4 * np.abs(expected).max())


def test_a_take_of_one_frame_runs(client: TestClient, walk: Take) -> None:
    result = upload_and_run(client, "one.bvh", walk.with_rows(list(walk.rows[:1])).data())
    assert result["frames"]["n_frames"] == 1


def test_joint_names_with_spaces_are_kept_in_the_reading(client: TestClient, walk: Take) -> None:
    result = upload_and_run(client, "biped.bvh", walk.renamed(BIPED_ARMS).data())
    reading = client.get(f"/api/v1/takes/{result['take']['id']}").json()["reading"]
    assert set(BIPED_ARMS.values()) <= set(reading["joints"])
