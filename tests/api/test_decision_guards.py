"""The guards of the decision routes: an approved take takes no decision, a note and a history
are bounded, a take deleted meanwhile is a 404, and only robust runs teach a shoot's prior."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

import mocapqa.api.routes.decisions as decision_routes
from mocapqa.store.decisions import NOTE_MAX_CHARS

API = "/api/v1"
KNEES = "bvh/cmu/iclone/005_05.bvh"

Waiter = Callable[[TestClient, str], dict[str, Any]]
Uploader = Callable[[TestClient, Path], dict[str, Any]]

DECISION_KEYS = (
    "run_id", "item", "apply", "intervals", "swaps", "history", "lock_apply", "locks",
    "lock_history", "history_total", "lock_history_total",
)  # fmt: skip
"""The keys of ``GET /runs/{id}/decisions``: every earlier key, and the two counts."""


@pytest.fixture
def feet_run(
    client: TestClient, corpus_dir: Path, upload: Uploader, wait_for_run: Waiter
) -> dict[str, Any]:
    """005_05 uploaded, then a run with the twist and feet checks."""
    take = upload(client, corpus_dir / KNEES)
    assert wait_for_run(client, take["run_id"])["status"] == "done"
    response = client.post(f"{API}/takes/{take['id']}/runs", json={"checks": ["twist", "feet"]})
    assert response.status_code == 201, response.text
    run = wait_for_run(client, response.json()["id"])
    assert run["status"] == "done", run["error"]
    return run


def decide(client: TestClient, run_id: str, path: str, decision: str, note: str = "") -> Any:
    """POST a decision on ``intervals/ID`` or ``feet/ID`` of a run; the response."""
    return client.post(
        f"{API}/runs/{run_id}/{path}/decisions", json={"decision": decision, "note": note}
    )


def review(client: TestClient, take_id: str, status: str) -> None:
    response = client.post(f"{API}/takes/{take_id}/reviews", json={"status": status})
    assert response.status_code == 201, response.text


def test_an_approved_take_takes_no_decision_until_it_is_reopened(
    client: TestClient, feet_run: dict[str, Any]
) -> None:
    run_id, take_id = feet_run["id"], feet_run["take_id"]
    body = client.get(f"{API}/runs/{run_id}/decisions").json()
    interval = body["intervals"][0]["id"]
    assert body["locks"], "005_05 has skate findings to decide on"
    lock = body["locks"][0]["id"]
    assert decide(client, run_id, f"intervals/{interval}", "accept").status_code == 201
    review(client, take_id, "approved")
    decided = client.get(f"{API}/runs/{run_id}/decisions/bvh").content

    for path in (f"intervals/{interval}", f"feet/{lock}"):
        refused = decide(client, run_id, path, "reject")
        assert refused.status_code == 409, refused.text
        assert refused.json()["error"] == "ConflictError"
        assert f"take {take_id} approved" in refused.json()["detail"]
        assert "reopen it" in refused.json()["detail"]
    # Nothing was stored: the approved take's reviewed download is as it was.
    after = client.get(f"{API}/runs/{run_id}/decisions").json()
    assert after["history_total"] == 1
    assert after["lock_history_total"] == 0
    assert client.get(f"{API}/runs/{run_id}/decisions/bvh").content == decided
    # An earlier run of the approved take is refused alike.
    first_run = client.get(f"{API}/takes/{take_id}").json()["runs"][0]["id"]
    assert first_run != run_id
    assert decide(client, first_run, f"intervals/{interval}", "accept").status_code == 409

    review(client, take_id, "needs_fix")  # reopened
    assert decide(client, run_id, f"intervals/{interval}", "reject").status_code == 201
    assert decide(client, run_id, f"feet/{lock}", "accept").status_code == 201
    assert client.get(f"{API}/runs/{run_id}/decisions/bvh").content != decided


def test_a_note_is_bounded_and_named(client: TestClient, feet_run: dict[str, Any]) -> None:
    run_id = feet_run["id"]
    lock = client.get(f"{API}/runs/{run_id}/decisions").json()["locks"][0]["id"]
    for path in ("intervals/0", f"feet/{lock}"):
        long = decide(client, run_id, path, "accept", "n" * (NOTE_MAX_CHARS + 1))
        assert long.status_code == 422, long.text
        assert long.json()["field"] == "note"
        assert str(NOTE_MAX_CHARS) in long.json()["detail"]
        kept = decide(client, run_id, path, "accept", "n" * NOTE_MAX_CHARS)
        assert kept.status_code == 201, kept.text
    body = client.get(f"{API}/runs/{run_id}/decisions").json()
    assert (body["history_total"], body["lock_history_total"]) == (1, 1)


def test_the_history_is_paged_and_each_decision_stays_the_newest(
    client: TestClient, feet_run: dict[str, Any]
) -> None:
    run_id = feet_run["id"]
    intervals = client.get(f"{API}/runs/{run_id}/decisions").json()["intervals"]
    assert len(intervals) >= 2
    first, second = intervals[0]["id"], intervals[1]["id"]
    assert decide(client, run_id, f"intervals/{first}", "reject", "early").status_code == 201
    for k in range(11):  # the second interval's decisions push the first's off the page
        decision = "accept" if k % 2 == 0 else "reject"
        assert decide(client, run_id, f"intervals/{second}", decision, str(k)).status_code == 201

    body = client.get(f"{API}/runs/{run_id}/decisions", params={"limit": 5}).json()
    assert body["history_total"] == 12
    assert [h["note"] for h in body["history"]] == ["10", "9", "8", "7", "6"]
    by_id = {i["id"]: i for i in body["intervals"]}
    assert by_id[first]["decision"] == "reject"  # off the page, still its decision
    assert by_id[second]["decision"] == "accept"
    last = client.get(f"{API}/runs/{run_id}/decisions", params={"limit": 5, "offset": 10}).json()
    assert [h["note"] for h in last["history"]] == ["0", "early"]
    whole = client.get(f"{API}/runs/{run_id}/decisions").json()  # the default page holds all
    assert len(whole["history"]) == whole["history_total"] == 12
    assert set(DECISION_KEYS) <= set(whole)
    for params in ({"limit": 0}, {"limit": decision_routes.HISTORY_MAX_LIMIT + 1}, {"offset": -1}):
        refused = client.get(f"{API}/runs/{run_id}/decisions", params=params)
        assert refused.status_code == 422, refused.text


def test_a_decision_on_a_take_deleted_meanwhile_is_a_404(
    client: TestClient, feet_run: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    run_id, take_id = feet_run["id"], feet_run["take_id"]
    services = client.app.state.services  # type: ignore[attr-defined]
    listed = decision_routes.run_intervals

    def deleted_meanwhile(files: Any, run: str) -> list[dict[str, Any]]:
        """The run's intervals, read before another user deletes its take."""
        intervals = listed(files, run)
        services.repository.delete_take(take_id)
        return intervals

    monkeypatch.setattr(decision_routes, "run_intervals", deleted_meanwhile)
    response = decide(client, run_id, "intervals/0", "accept")
    assert response.status_code == 404, response.text
    assert response.json()["error"] == "NotFoundError"
    assert client.get(f"{API}/takes/{take_id}").status_code == 404


def _import(client: TestClient, shoot_id: str, name: str, data: bytes) -> dict[str, Any]:
    response = client.post(f"{API}/shoots/{shoot_id}/takes", files=[("files", (name, data))])
    assert response.status_code == 201, response.text
    created: dict[str, Any] = response.json()["created"][0]
    return created


def _accept_all(client: TestClient, run_id: str) -> int:
    """Accept every twist interval of a run; how many."""
    intervals = client.get(f"{API}/runs/{run_id}/decisions").json()["intervals"]
    for interval in intervals:
        assert decide(client, run_id, f"intervals/{interval['id']}", "accept").status_code == 201
    return len(intervals)


def test_decisions_on_paper_runs_are_no_labels_of_the_shoots_prior(
    client: TestClient, corpus_dir: Path, wait_for_run: Waiter
) -> None:
    data = (corpus_dir / KNEES).read_bytes()
    shoot = client.post(f"{API}/shoots", json={"name": "methods"}).json()["id"]
    robust = _import(client, shoot, "robust.bvh", data)
    paper = _import(client, shoot, "paper.bvh", data)
    for created in (robust, paper):
        assert wait_for_run(client, created["run_id"])["status"] == "done"
    rerun = client.post(
        f"{API}/takes/{paper['take_id']}/runs", json={"twist_method": "paper", "checks": ["twist"]}
    )
    assert rerun.status_code == 201, rerun.text
    paper_run = wait_for_run(client, rerun.json()["id"])
    assert paper_run["status"] == "done", paper_run["error"]
    assert paper_run["options"]["twist_method"] == "paper"
    assert _accept_all(client, paper_run["id"]) > 0  # the paper's rule finds intervals here

    only_paper = _import(client, shoot, "only_paper.bvh", data)
    report = client.get(f"{API}/runs/{wait_for_run(client, only_paper['run_id'])['id']}/result")
    assert "reviewer_prior" not in report.json()  # the paper run's decisions taught nothing

    accepted = _accept_all(client, robust["run_id"])
    later = _import(client, shoot, "later.bvh", data)
    report = client.get(f"{API}/runs/{wait_for_run(client, later['run_id'])['id']}/result")
    prior = report.json()["reviewer_prior"]
    assert prior["runs"] == 1  # the robust run only
    assert (prior["accepted"], prior["rejected"]) == (accepted, 0)
