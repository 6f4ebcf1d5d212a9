"""Schemathesis against the running app: every check, zero failures.

The server runs in this process (uvicorn in a thread) with an analysed take; schemathesis
(pinned in the dev extras) runs as its CLI with ``--checks all``: no server errors, no answer
outside its schema, no undocumented status code, no undocumented header, valid data accepted
and invalid data rejected (with the exceptions stated in ``schemathesis.toml``). Bounded by
``--max-examples`` per operation: a few minutes on a loaded 2-core machine. The summary goes
to ``test-artifacts/schemathesis.txt``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from datetime import timedelta
from pathlib import Path

import httpx
import pytest
from tests.api.conftest import make_settings
from tests.live_server import live_server

from mocapqa.render.service import RenderService
from mocapqa.store.accounts import Accounts
from mocapqa.store.repository import Repository
from mocapqa.store.roles import Role

pytestmark = pytest.mark.schemathesis

CONFIG = Path(__file__).with_name("schemathesis.toml")
ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"
MAX_EXAMPLES = 25
"""Examples per operation and phase (41 operations)."""
RUN_BOUND_S = 900.0
"""Generous bound on the whole run (about 2 minutes on an idle machine)."""


def test_schemathesis_finds_nothing(
    tmp_path: Path, corpus_dir: Path, renderer: RenderService
) -> None:
    settings = make_settings(
        "sqlite", tmp_path, allowed_hosts=["127.0.0.1"], uploads_per_minute_per_user=120
    )
    # Signed in as an admin through a personal token (the server has users, so an anonymous
    # request would get 401).
    settings.data_dir.mkdir(parents=True)
    repository = Repository(settings.resolved_database_url)
    accounts = Accounts(repository.engine)
    admin = accounts.add_user("schemathesis-admin", Role.ADMIN)
    token = accounts.issue(admin.id, "api", timedelta(days=1)).token
    spare_user = accounts.add_user("spare", Role.VIEWER)
    spare_token = accounts.issue(spare_user.id, "api", timedelta(days=1)).id
    repository.close()
    bearer = {"Authorization": f"Bearer {token}"}
    with live_server(settings, renderer) as url:
        # 005_05 has twist intervals, so the decision routes are exercised past their 404.
        data = (corpus_dir / "bvh" / "cmu" / "iclone" / "005_05.bvh").read_bytes()
        take, spare = (
            httpx.post(f"{url}/api/v1/takes", files={"file": (name, data)}, headers=bearer).json()
            for name in ("knees.bvh", "spare.bvh")
        )
        deadline = time.monotonic() + RUN_BOUND_S
        run_url = f"{url}/api/v1/runs/{take['run_id']}"
        while httpx.get(run_url, headers=bearer).json()["status"] != "done":
            assert time.monotonic() < deadline, "the take's analysis did not finish"
            time.sleep(0.2)
        env = {
            **os.environ,
            "MOCAPQA_ST_TAKE_ID": take["id"],
            "MOCAPQA_ST_RUN_ID": take["run_id"],
            "MOCAPQA_ST_SPARE_TAKE_ID": spare["id"],
            "MOCAPQA_ST_SPARE_USER": spare_user.name,
            "MOCAPQA_ST_SPARE_TOKEN_ID": spare_token,
            "NO_COLOR": "1",
        }
        command = [
            str(Path(sys.executable).with_name("schemathesis")),
            "--config-file", str(CONFIG),
            "run", f"{url}/openapi.json",
            "--header", f"Authorization: Bearer {token}",
            "--checks", "all",
            "--max-examples", str(MAX_EXAMPLES),
            "--workers", "1",
            "--seed", "15",
            "--phases", "examples,coverage,fuzzing",
            "--no-color",
        ]  # fmt: skip
        done = subprocess.run(
            command,
            env=env,
            cwd=tmp_path,  # its example database goes there, not into the checkout
            capture_output=True,
            text=True,
            timeout=RUN_BOUND_S,
            check=False,
        )
    ARTIFACTS.mkdir(exist_ok=True)
    summary = done.stdout[done.stdout.find("WARNINGS") - 40 :]
    (ARTIFACTS / "schemathesis.txt").write_text(summary)
    assert done.returncode == 0, done.stdout[-6000:] + done.stderr[-2000:]
