"""A hostile client's pass over the upload endpoints (``POST /takes``, ``POST
/shoots/{id}/takes``): an import larger than the queued-run quota, repeated and unknown
multipart parts, file names longer than any file system keeps, and form fields a route does
not read. Each answer must be a 4xx naming the field (never a bare 400 or a part silently
dropped), and nothing already stored may be lost. Runs on SQLite and (``scripts/
with-postgres.sh``) on PostgreSQL."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient
from tests.api.conftest import poll_run
from tests.api.test_hostile_pass import SMALL_BVH, bearer, deflated_zip

from mocapqa.api.app import create_app
from mocapqa.config import Settings
from mocapqa.render.service import RenderService
from mocapqa.store.roles import Role

QUOTA = 2
"""``max_queued_runs_per_user`` of these tests: fewer than an imported archive's members."""
MEMBERS = 5


@pytest.fixture
def quota_settings(settings: Settings) -> Settings:
    """Settings with a small queued-run quota and one worker."""
    return settings.model_copy(update={"max_queued_runs_per_user": QUOTA, "job_workers": 1})


def reviewer_client(settings: Settings, renderer: RenderService) -> Iterator[TestClient]:
    """A client of a fresh app whose requests carry a reviewer's token."""
    with TestClient(create_app(settings, renderer=renderer)) as client:
        _, headers = bearer(client, "alice", Role.REVIEWER)
        client.headers.update(headers)
        yield client


@pytest.fixture
def over_quota(quota_settings: Settings, renderer: RenderService) -> Iterator[TestClient]:
    """A reviewer's client on a server whose quota an import of :data:`MEMBERS` exceeds."""
    yield from reviewer_client(quota_settings, renderer)


@pytest.fixture
def signed_in(settings: Settings, renderer: RenderService) -> Iterator[TestClient]:
    """A reviewer's client on a server with the default settings."""
    yield from reviewer_client(settings, renderer)


def new_shoot(client: TestClient) -> str:
    response = client.post("/api/v1/shoots", json={"name": "day one"})
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


def import_archive(client: TestClient, shoot_id: str, members: int = MEMBERS) -> dict[str, Any]:
    archive = deflated_zip({f"take{i}.bvh": SMALL_BVH for i in range(members)})
    response = client.post(
        f"/api/v1/shoots/{shoot_id}/takes", files=[("files", ("day.zip", archive))]
    )
    assert response.status_code == 201, response.text
    body: dict[str, Any] = response.json()
    assert len(body["created"]) == members, body
    return body


def runner_of(client: TestClient) -> Any:
    return client.app.state.services.runner  # type: ignore[attr-defined]


def user_key(client: TestClient) -> str:
    me = client.get("/api/v1/me").json()
    return f"user:{me['user_id']}"


def test_an_archive_import_puts_no_more_runs_in_line_than_the_quota(
    quota_settings: Settings, renderer: RenderService
) -> None:
    """An archive of 5 takes from a user allowed 2 queued runs: all 5 takes are stored and
    their runs recorded, but at most 2 are handed to the workers (queued there or running);
    the others wait in the database, in import order, and are not held in memory as parsed
    takes. The import used to queue all 5. A server stopped before they ran finishes every
    one of them after its restart: nothing stored is lost."""
    with TestClient(create_app(quota_settings, renderer=renderer)) as client:
        _, headers = bearer(client, "alice", Role.REVIEWER)
        client.headers.update(headers)
        key = user_key(client)
        runner = runner_of(client)
        runner.shutdown()  # no worker takes a run: the line stays as the import left it
        shoot_id = new_shoot(client)
        body = import_archive(client, shoot_id)
        assert runner.in_line(key) <= QUOTA
        assert runner.pending(key) == MEMBERS
        refused = client.post("/api/v1/takes", files={"file": ("one.bvh", SMALL_BVH)})
        assert refused.status_code == 429, refused.text
        assert "max_queued_runs_per_user" in refused.json()["detail"]
    with TestClient(create_app(quota_settings, renderer=renderer)) as client:
        client.headers.update(headers)
        for take in body["created"]:
            assert poll_run(client, take["run_id"])["status"] == "done"


def test_the_runs_an_import_holds_back_all_finish(over_quota: TestClient) -> None:
    """Held runs enter the line as the user's earlier runs finish: every take of an import
    larger than the quota is analysed, and the user may upload again afterwards."""
    runner = runner_of(over_quota)
    key = user_key(over_quota)
    body = import_archive(over_quota, new_shoot(over_quota))
    for take in body["created"]:
        assert poll_run(over_quota, take["run_id"])["status"] == "done"
    assert runner.pending(key) == 0
    again = over_quota.post("/api/v1/takes", files={"file": ("one.bvh", SMALL_BVH)})
    assert again.status_code == 201, again.text


def test_deleting_a_shoot_whose_runs_are_held_back_settles_them(over_quota: TestClient) -> None:
    """A queued or held run of a deleted shoot must not count against its user for ever (the
    shoot's delete did not cancel its runs: queued ones later ran against deleted takes)."""
    runner = runner_of(over_quota)
    runner.shutdown()
    key = user_key(over_quota)
    shoot_id = new_shoot(over_quota)
    import_archive(over_quota, shoot_id)
    deleted = over_quota.delete(f"/api/v1/shoots/{shoot_id}?confirm=day one")
    assert deleted.status_code == 204, deleted.text
    assert runner.pending(key) == 0


def assert_names(response: Any, field: str, *words: str, status: int = 422) -> None:
    assert response.status_code == status, response.text
    body = response.json()
    assert body["error"] == "ValidationError", body
    assert body["field"] == field, body
    for word in words:
        assert word in body["detail"], body


def no_takes(client: TestClient) -> None:
    assert client.get("/api/v1/takes").json()["total"] == 0


def test_a_second_file_part_is_422_naming_it(signed_in: TestClient) -> None:
    """``POST /takes`` reads one file: a second ``file`` part used to be dropped in silence
    (the last one was stored)."""
    response = signed_in.post(
        "/api/v1/takes",
        files=[("file", ("a.bvh", SMALL_BVH)), ("file", ("b.bvh", SMALL_BVH))],
    )
    assert_names(response, "body.file", "one 'file' part", "2")
    no_takes(signed_in)


@pytest.mark.parametrize("name", ["options", "mapping", "files"])
def test_a_form_field_the_upload_does_not_read_is_422_naming_it(
    name: str, signed_in: TestClient
) -> None:
    """Run options or a mapping sent with an upload were ignored: the take was analysed with
    the defaults, and nothing said so."""
    response = signed_in.post(
        "/api/v1/takes",
        files=[("file", ("a.bvh", SMALL_BVH)), (name, (None, '{"checks": ["limits"]}'))],
    )
    assert_names(response, f"body.{name}", "fps", "length_unit")
    no_takes(signed_in)


def test_an_import_uses_every_files_part_and_refuses_a_file_part(signed_in: TestClient) -> None:
    """The import reads many ``files`` parts (each is used); a ``file`` part beside them was
    dropped in silence."""
    shoot_id = new_shoot(signed_in)
    both = [("files", ("a.bvh", SMALL_BVH)), ("files", ("b.bvh", SMALL_BVH))]
    response = signed_in.post(f"/api/v1/shoots/{shoot_id}/takes", files=both)
    assert response.status_code == 201, response.text
    assert sorted(t["name"] for t in response.json()["created"]) == ["a.bvh", "b.bvh"]
    extra = [("files", ("c.bvh", SMALL_BVH)), ("file", ("d.bvh", SMALL_BVH))]
    refused = signed_in.post(f"/api/v1/shoots/{shoot_id}/takes", files=extra)
    assert_names(refused, "body.file", "files")
    assert signed_in.get("/api/v1/takes").json()["total"] == 2


@pytest.mark.parametrize("length", [256, 5000])
def test_a_file_name_over_the_limit_is_422_naming_the_file(
    length: int, signed_in: TestClient
) -> None:
    """A 5,000-character name was a bare 400 ("Invalid multipart data.", the multipart
    parser's header limit) and a 256-character one was stored cut to 255."""
    name = "x" * (length - 4) + ".bvh"
    response = signed_in.post("/api/v1/takes", files={"file": (name, SMALL_BVH)})
    assert_names(response, "body.file", "255")
    no_takes(signed_in)
    shoot_id = new_shoot(signed_in)
    response = signed_in.post(
        f"/api/v1/shoots/{shoot_id}/takes", files=[("files", (name, SMALL_BVH))]
    )
    assert_names(response, "body.files", "255")
    no_takes(signed_in)


@pytest.mark.parametrize("stem", ["x" * 251, "é" * 251])
def test_a_file_name_at_the_limit_is_stored_whole(stem: str, signed_in: TestClient) -> None:
    """255 characters (ASCII, or 2-byte ones in UTF-8) is the limit: such a name is kept
    whole, and the stored file keeps its extension (it was cut to 200 characters, extension
    and all)."""
    name = stem + ".bvh"
    response = signed_in.post("/api/v1/takes", files={"file": (name, SMALL_BVH)})
    assert response.status_code == 201, response.text
    assert response.json()["name"] == name
    repository = signed_in.app.state.services.repository  # type: ignore[attr-defined]
    assert repository.get_take(response.json()["id"])["file_name"].endswith(".bvh")


def test_an_archive_member_named_over_the_limit_is_listed_as_failed(
    signed_in: TestClient,
) -> None:
    """A member's name comes from the archive, not a file system: one over the limit is a
    failed member with its reason; the other members are kept."""
    archive = deflated_zip({"y" * 300 + ".bvh": SMALL_BVH, "ok.bvh": SMALL_BVH})
    response = signed_in.post(
        f"/api/v1/shoots/{new_shoot(signed_in)}/takes", files=[("files", ("d.zip", archive))]
    )
    assert response.status_code == 201, response.text
    body = response.json()
    assert [t["name"] for t in body["created"]] == ["ok.bvh"]
    assert len(body["failed"]) == 1
    assert "255" in body["failed"][0]["error"]


def test_an_unknown_length_unit_is_422_naming_the_form_field(signed_in: TestClient) -> None:
    """Was a 422 whose body named no field (``InputError`` from the reader's options)."""
    response = signed_in.post(
        "/api/v1/takes",
        files={"file": ("a.bvh", SMALL_BVH)},
        data={"length_unit": "furlong"},
    )
    assert_names(response, "body.length_unit", "'normalized'")
    no_takes(signed_in)


@pytest.mark.parametrize("name", ["mapping", "options"])
def test_run_options_sent_as_form_fields_name_the_field(name: str, signed_in: TestClient) -> None:
    """Run options are a JSON body: sent as form fields, the 422 named only ``body``."""
    take = signed_in.post("/api/v1/takes", files={"file": ("a.bvh", SMALL_BVH)}).json()
    poll_run(signed_in, take["run_id"])
    for kind in ("multipart", "urlencoded"):
        if kind == "multipart":
            response = signed_in.post(
                f"/api/v1/takes/{take['id']}/runs", files={name: (None, '{"Hips": "x"}')}
            )
        else:
            response = signed_in.post(
                f"/api/v1/takes/{take['id']}/runs", data={name: '{"Hips": "x"}'}
            )
        assert_names(response, f"body.{name}", "JSON")
    runs = signed_in.get(f"/api/v1/takes/{take['id']}").json()["runs"]
    assert len(runs) == 1


@pytest.mark.parametrize(
    ("content_type", "words"),
    [
        ("multipart/form-data; boundary=x", "Invalid multipart data"),
        ("multipart/form-data", "boundary"),
    ],
)
@pytest.mark.parametrize("path", ["/api/v1/takes", "/api/v1/shoots"])
def test_a_multipart_body_the_parser_refuses_is_422_naming_the_body(
    content_type: str, words: str, path: str, signed_in: TestClient
) -> None:
    """Was Starlette's bare 400 ("Invalid multipart data."), on an upload route and on a
    route that reads JSON alike."""
    response = signed_in.post(path, content=b"garbage", headers={"Content-Type": content_type})
    assert_names(response, "body", words)


HUGE_JSON = (
    '{"fps": 30, "keypoints": ["a", "b"], "frames": ' + str([[[1e300, 2, 3], [1, 2, 3]]] * 3) + "}"
)


@pytest.mark.parametrize(
    ("name", "content", "field"),
    [
        # A coordinate no take holds: the filter squared it into infinity inside the run.
        ("huge.json", HUGE_JSON, "positions"),
        ("fast.json", '{"fps": 1e300, "keypoints": ["a"], "frames": [[[1, 2, 3]]]}', "fps"),
        ("none.json", '{"fps": 30, "keypoints": [], "frames": [[], []]}', "keypoints"),
    ],
)
def test_keypoints_no_take_holds_are_refused_at_the_upload(
    name: str, content: str, field: str, signed_in: TestClient
) -> None:
    response = signed_in.post("/api/v1/takes", files={"file": (name, content.encode())})
    assert response.status_code == 422, response.text
    assert field in (response.json().get("field") or response.json()["detail"])
    no_takes(signed_in)


def test_a_zip_of_takes_sent_as_one_take_says_where_archives_go(signed_in: TestClient) -> None:
    """An .npz is a zip file, so a .zip of takes was read as one and refused for a missing
    'positions' array."""
    response = signed_in.post(
        "/api/v1/takes", files={"file": ("takes.zip", deflated_zip({"a.bvh": SMALL_BVH}))}
    )
    assert response.status_code == 422
    assert "import archives of takes into a shoot" in response.json()["detail"]
    no_takes(signed_in)
