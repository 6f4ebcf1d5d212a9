"""Numbers checked at the request (issue 32, item 5): every frame rate, size and coordinate a
client sends is bounded and finite where it arrives, in an upload's form and file, in run
options and in the live stream's messages.

Before, an upload with ``fps=1e-300`` was stored (201) and its run failed with "internal
error: OverflowError"; ``checks`` of 100,000 items was stored as sent; on the stream a tiny
frame rate raised OverflowError, huge positions a ZeroDivisionError and a binary frame
``KeyError: 'text'``, each closing the socket with no close code and a traceback in the log.
Now each is a 422 naming the field, or a close code with a reason (1003 unsupported data,
1007 invalid payload, 1008 policy, 1009 too big; 1011 only for an internal error)."""

from __future__ import annotations

import json
import logging
from collections.abc import Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient
from starlette.testclient import WebSocketTestSession
from tests.api.test_hostile_pass import SMALL_BVH

from mocapqa.core.bounds import MAX_FPS, MAX_MAGNITUDE, MIN_FPS
from mocapqa.pipeline.filtering import StreamSession
from mocapqa.pipeline.options import CHECKS

KEYPOINTS_JSON = (
    b'{"keypoints": ["a", "b"], "frames": [[[0, 2, 3], [1, 2, 3]], [[0.1, 2, 3], [1, 2.2, 3]]]}'
)
"""A keypoint take without a frame rate: the upload's ``fps`` field is used."""
STREAM = "/api/v1/stream/filter"
HEADER = {"fps": 30, "n_keypoints": 2}
FRAME = {"positions": [[0.0, 1.0, 2.0], [1.0, 1.5, 2.0]]}


def no_takes(client: TestClient) -> None:
    assert client.get("/api/v1/takes").json()["total"] == 0


def refused(response: Any, field: str) -> dict[str, Any]:
    assert response.status_code == 422, response.text
    body: dict[str, Any] = response.json()
    assert body["field"] == field, body
    return body


# --- uploads ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "fps", ["1e-300", "5e-324", "0.01", "-1", "nan", "inf", "-inf", "1e400", "100001"]
)
def test_an_upload_frame_rate_outside_the_bounds_is_422_naming_fps(
    fps: str, client: TestClient
) -> None:
    """``fps=1e-300`` was stored (201) and the run failed with "internal error:
    OverflowError" (the Kalman filter's dt⁴)."""
    response = client.post(
        "/api/v1/takes", files={"file": ("k.json", KEYPOINTS_JSON)}, data={"fps": fps}
    )
    refused(response, "body.fps")
    no_takes(client)


@pytest.mark.parametrize("fps", [MIN_FPS, 25.0, MAX_FPS])
def test_an_upload_frame_rate_within_the_bounds_is_used(fps: float, client: TestClient) -> None:
    response = client.post(
        "/api/v1/takes", files={"file": ("k.json", KEYPOINTS_JSON)}, data={"fps": str(fps)}
    )
    assert response.status_code == 201, response.text
    assert response.json()["fps"] == fps


def test_the_upload_form_documents_the_frame_rate_bounds(client: TestClient) -> None:
    spec = client.get("/openapi.json").json()
    form = spec["paths"]["/api/v1/takes"]["post"]["requestBody"]["content"]
    ref = form["multipart/form-data"]["schema"]["$ref"].rsplit("/", 1)[1]
    fps = spec["components"]["schemas"][ref]["properties"]["fps"]["anyOf"][0]
    assert (fps["minimum"], fps["maximum"]) == (MIN_FPS, MAX_FPS)


@pytest.mark.parametrize("fps", ["1e-300", "0.01"])
def test_a_frame_rate_a_keypoint_file_stores_is_bounded_too(fps: str, client: TestClient) -> None:
    """The file's own ``fps`` was accepted when above 0: the run failed later."""
    content = '{"fps": ' + fps + ', "keypoints": ["a"], "frames": [[[1, 2, 3]], [[1, 2, 3]]]}'
    response = client.post("/api/v1/takes", files={"file": ("slow.json", content.encode())})
    assert response.status_code == 422, response.text
    assert response.json()["field"] == "fps"
    assert f"at least {MIN_FPS:g}" in response.json()["detail"]
    no_takes(client)


# --- run options -----------------------------------------------------------------------------


@pytest.fixture
def take_id(client: TestClient) -> str:
    response = client.post("/api/v1/takes", files={"file": ("small.bvh", SMALL_BVH)})
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


@pytest.mark.parametrize(
    ("checks", "words"),
    [
        (["twist"] * 100_000, "at most 5"),
        (["twist", "limits", "twist"], "at most once"),
        (["limits", "limits"], "at most once"),
    ],
)
def test_a_checks_list_longer_than_the_checks_or_repeating_one_is_422(
    checks: list[str], words: str, client: TestClient, take_id: str
) -> None:
    """100,000 items were stored with the run as sent."""
    response = client.post(f"/api/v1/takes/{take_id}/runs", json={"checks": checks})
    body = refused(response, "body.checks")
    assert words in body["detail"], body
    assert len(client.get(f"/api/v1/takes/{take_id}").json()["runs"]) == 1


def test_the_run_options_document_their_list_bounds(client: TestClient) -> None:
    spec = client.get("/openapi.json").json()
    checks = spec["components"]["schemas"]["AnalysisOptionsIn"]["properties"]["checks"]
    assert checks["maxItems"] == len(CHECKS)
    assert checks["uniqueItems"] is True


@pytest.mark.parametrize(
    ("options", "field"),
    [
        # Numbers beyond a float, infinite or of no range: each option's range refuses them.
        (b'{"max_points": 1e400}', "body.max_points"),
        (b'{"max_points": 100000000000000000000000}', "body.max_points"),
        (
            b'{"filter_method": "quat-pd", "filter_params": {"natural_frequency_hz": 1e400}}',
            "filter_params.natural_frequency_hz",
        ),
        (
            b'{"filter_method": "quat-pd", "filter_params": {"natural_frequency_hz": '
            + b"1" * 400
            + b"}}",
            "filter_params.natural_frequency_hz",
        ),
    ],
)
def test_numeric_run_options_out_of_any_range_are_422(
    options: bytes, field: str, client: TestClient, take_id: str
) -> None:
    response = client.post(
        f"/api/v1/takes/{take_id}/runs",
        content=options,
        headers={"Content-Type": "application/json"},
    )
    refused(response, field)


# --- the live stream -------------------------------------------------------------------------


@pytest.fixture
def quiet(caplog: pytest.LogCaptureFixture) -> Iterator[pytest.LogCaptureFixture]:
    """The log of a test, which must hold no error and no traceback."""
    caplog.set_level(logging.INFO)
    yield caplog
    loud = [r for r in caplog.records if r.levelno >= logging.ERROR or r.exc_info]
    assert not loud, [r.getMessage() for r in loud]


def closed(socket: WebSocketTestSession) -> tuple[str, int, str]:
    """The error message the server sent ("" when it sent none) and its close code and
    reason."""
    message = socket.receive()
    error = ""
    if message["type"] == "websocket.send":
        error = json.loads(message["text"])["error"]
        message = socket.receive()
    assert message["type"] == "websocket.close", message
    return error, int(message["code"]), str(message.get("reason") or "")


@pytest.mark.parametrize(
    ("header", "words"),
    [
        ('{"fps": 1e-300, "n_keypoints": 2}', f"at least {MIN_FPS:g}"),
        ('{"fps": 5e-324, "n_keypoints": 2}', f"at least {MIN_FPS:g}"),
        ('{"fps": 1e308, "n_keypoints": 2}', f"at most {MAX_FPS:g}"),
        ('{"fps": 1e999, "n_keypoints": 2}', "finite"),
        ('{"fps": NaN, "n_keypoints": 2}', "NaN"),
        ('{"fps": ' + "9" * 400 + ', "n_keypoints": 2}', "fps finite"),
        ('{"fps": true, "n_keypoints": 2}', "a number for 'fps'"),
        ('{"fps": 30, "n_keypoints": 2.5}', "whole number"),
        ('{"fps": 30, "n_keypoints": 2, "length_unit": 7}', "a string for 'length_unit'"),
        ("[30, 2]", "JSON object"),
        ('{"fps": 30', "JSON"),
        ("[" * 200_000 + "]" * 200_000, "nested"),
        ("\x00", "JSON"),
        ('{"fps": ' + "9" * 5000 + ', "n_keypoints": 2}', "JSON"),  # past int()'s 4300 digits
    ],
)
def test_a_stream_header_the_server_cannot_use_closes_1007(
    header: str, words: str, client: TestClient, quiet: pytest.LogCaptureFixture
) -> None:
    with client.websocket_connect(STREAM) as socket:
        socket.send_text(header)
        error, code, reason = closed(socket)
    assert code == 1007, (error, reason)
    assert words in error, error
    assert 0 < len(reason.encode()) <= 123


def test_a_stream_header_over_the_keypoint_limit_closes_1009(
    client: TestClient, quiet: pytest.LogCaptureFixture
) -> None:
    with client.websocket_connect(STREAM) as socket:
        socket.send_text('{"fps": 30, "n_keypoints": ' + "9" * 400 + "}")
        error, code, _ = closed(socket)
    assert code == 1009
    assert "stream_max_keypoints" in error


@pytest.mark.parametrize("first", [True, False])
def test_a_binary_frame_closes_1003(
    first: bool, client: TestClient, quiet: pytest.LogCaptureFixture
) -> None:
    """A binary frame was ``KeyError: 'text'``: no close code, a traceback in the log."""
    with client.websocket_connect(STREAM) as socket:
        if not first:
            socket.send_json(HEADER)
            assert socket.receive_json()["ready"] is True
        socket.send_bytes(b'{"fps": 30, "n_keypoints": 2}')
        error, code, reason = closed(socket)
    assert code == 1003
    assert "binary" in error
    assert "binary" in reason


@pytest.mark.parametrize(
    ("frame", "words"),
    [
        # Huge positions were a ZeroDivisionError (the body size of a first frame) or
        # turned into infinity by the filter.
        ('{"positions": [[1e308, 1e308, 1e308], [1e308, 1e308, 1e308]]}', "±1,000,000,000"),
        ('{"positions": [[1e10, 0, 0], [1, 1, 1]]}', "±1,000,000,000"),
        ('{"positions": [[1e999, 0, 0], [1, 1, 1]]}', "±1,000,000,000"),
        ('{"positions": [[-Infinity, 0, 0], [1, 1, 1]]}', "Infinity"),
        ('{"positions": [[NaN, 0, 0], [1, 1, 1]]}', "NaN"),
        ('{"positions": [[' + "9" * 400 + ", 0, 0], [1, 1, 1]]}", "±1,000,000,000"),
        ('{"positions": [[true, 0, 0], [1, 1, 1]]}', "numbers or null"),
        ('{"positions": [["1", 0, 0], [1, 1, 1]]}', "numbers or null"),
        ('{"positions": [[1, 0, 0]]}', "2 rows"),
        ('{"positions": [[1, 0], [1, 1]]}', "[x, y, z]"),
        ('{"positions": "here"}', "2 rows"),
        ("{}", "2 rows"),
        ('{"positions": [[1, 0, 0], [1, 1, 1]], "confidence": [2, 1]}', "0 to 1"),
        ('{"positions": [[1, 0, 0], [1, 1, 1]], "confidence": [1e999, 1]}', "0 to 1"),
        ('{"positions": [[1, 0, 0], [1, 1, 1]], "confidence": [1]}', "2 values"),
        ('{"positions": [[1, 0, 0], [1, 1, 1]], "confidence": [false, 1]}', "numbers or null"),
        ("[1, 2]", "JSON object"),
        ('{"positions": ', "JSON"),
    ],
)
@pytest.mark.parametrize("unit", ["unknown", "m"])
def test_a_stream_frame_the_server_cannot_use_closes_1007(
    frame: str, words: str, unit: str, client: TestClient, quiet: pytest.LogCaptureFixture
) -> None:
    for after_a_good_frame in (False, True):
        with client.websocket_connect(STREAM) as socket:
            socket.send_json({**HEADER, "length_unit": unit})
            assert socket.receive_json()["ready"] is True
            if after_a_good_frame:
                socket.send_json(FRAME)
                assert socket.receive_json()["frame"] == 0
            socket.send_text(frame)
            error, code, reason = closed(socket)
        assert code == 1007, (error, reason)
        assert words in error, error


def test_a_stream_takes_the_largest_coordinates_and_missing_ones(
    client: TestClient, quiet: pytest.LogCaptureFixture
) -> None:
    big = MAX_MAGNITUDE
    with client.websocket_connect(STREAM) as socket:
        socket.send_json({**HEADER, "fps": MIN_FPS})
        assert socket.receive_json()["ready"] is True
        for frame in (
            {"positions": [[big, -big, 0.0], [-big, big, 1.0]]},
            {"positions": [[None, None, None], [1, 2, 3]], "confidence": [None, 1]},
            {"positions": [[-big, big, 0.0], [big, -big, 1.0]], "confidence": [0, 0.5]},
        ):
            socket.send_json(frame)
            answer = socket.receive_json()
            assert "error" not in answer, answer
            values = [v for row in answer["positions"] for v in row if v is not None]
            assert all(abs(v) <= 2 * big for v in values), answer


def test_a_stream_error_inside_the_filter_closes_1011_without_details(
    client: TestClient, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Only a genuine internal error is 1011; its traceback goes to the log, not the client."""

    def broken(self: StreamSession, positions: Any, confidence: Any) -> Any:
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(StreamSession, "filter", broken)
    with client.websocket_connect(STREAM) as socket:
        socket.send_json(HEADER)
        assert socket.receive_json()["ready"] is True
        socket.send_json(FRAME)
        error, code, reason = closed(socket)
    assert code == 1011
    assert error == reason == "internal error"
    assert any(r.exc_info and r.levelno == logging.ERROR for r in caplog.records)
