"""Make a database with an older commit's own code, through its own API (README.md here).

Run with that commit's ``backend`` first on ``PYTHONPATH``::

    python tests/data/legacy/make_legacy.py OUT_DIR

Two takes with runs, a second run and two reviews of the first take; where the commit has
shoots, a shoot with one imported take; where it has accounts, a reviewer ``ana`` (password
``correct horse battery``) does all of it. The database is ``OUT_DIR/data/mocapqa.sqlite3``, or
the one ``MOCAPQA_DATABASE_URL`` names. Not a test: pytest does not collect it.
"""

from __future__ import annotations

import math
import sqlite3
import sys
import time
from datetime import timedelta
from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient

from mocapqa.api.app import create_app
from mocapqa.config import Settings

SIDES = (("Left", 1), ("Right", -1))


def humanoid_bvh(n_frames: int, phase: float) -> str:
    """A small humanoid BVH (hips, spine, neck, head, arms, legs) swinging its limbs."""
    children: dict[str, list[tuple[str, tuple[float, float, float]]]] = {
        "Hips": [("Spine", (0, 10, 0))],
        "Spine": [("Neck", (0, 15, 0))],
        "Neck": [("Head", (0, 5, 0))],
    }
    for side, x in SIDES:
        children["Spine"].append((f"{side}Shoulder", (x * 3, 14, 0)))
        children[f"{side}Shoulder"] = [(f"{side}Arm", (x * 5, 0, 0))]
        children[f"{side}Arm"] = [(f"{side}ForeArm", (x * 12, 0, 0))]
        children[f"{side}ForeArm"] = [(f"{side}Hand", (x * 10, 0, 0))]
        children["Hips"].append((f"{side}UpLeg", (x * 5, 0, 0)))
        children[f"{side}UpLeg"] = [(f"{side}Leg", (0, -20, 0))]
        children[f"{side}Leg"] = [(f"{side}Foot", (0, -20, 0))]
    lines = ["HIERARCHY"]
    order: list[str] = []

    def emit(name: str, offset: tuple[float, float, float], depth: int) -> None:
        pad = "  " * depth
        order.append(name)
        lines.extend([pad + ("ROOT " if depth == 0 else "JOINT ") + name, pad + "{"])
        lines.append(pad + "  OFFSET {:g} {:g} {:g}".format(*offset))
        position = "6 Xposition Yposition Zposition" if depth == 0 else "3"
        lines.append(pad + f"  CHANNELS {position} Zrotation Xrotation Yrotation")
        for child, child_offset in children.get(name, []):
            emit(child, child_offset, depth + 1)
        if name not in children:
            lines.extend([pad + "  End Site", pad + "  {", pad + "    OFFSET 0 3 0", pad + "  }"])
        lines.append(pad + "}")

    emit("Hips", (0, 0, 0), 0)
    lines += ["MOTION", f"Frames: {n_frames}", "Frame Time: 0.0333333"]
    for i in range(n_frames):
        swing = 20 * math.sin(phase + i / 5)
        values = [i * 0.5, 90.0, 0.0]
        for j, name in enumerate(order):
            limb = "Leg" in name or "Arm" in name
            values += [swing / 8 * ((j % 3) - 1), swing / 2 if limb else 0.0, 0.0]
        lines.append(" ".join(f"{v:.4f}" for v in values))
    return "\n".join(lines) + "\n"


def fill(client: TestClient, headers: dict[str, str]) -> None:
    """Takes, runs, reviews and (where there are shoots) a shoot, through the API."""

    def finished(run_id: str) -> dict[str, Any]:
        for _ in range(6000):
            run: dict[str, Any] = client.get(f"/api/v1/runs/{run_id}", headers=headers).json()
            if run["status"] in ("done", "failed"):
                return run
            time.sleep(0.05)
        raise TimeoutError(run_id)

    made = []
    for k, name in enumerate(["walk_a.bvh", "walk_b.bvh"]):
        upload = {"file": (name, humanoid_bvh(24 + k, k).encode())}
        answer = client.post("/api/v1/takes", files=upload, headers=headers)
        assert answer.status_code == 201, answer.text
        made.append(answer.json())
        finished(made[-1]["run_id"])
    first = made[0]["id"]
    again = client.post(f"/api/v1/takes/{first}/runs", json={"checks": ["limits"]}, headers=headers)
    finished(again.json()["id"])
    for status, notes, who in [("needs_fix", "left leg pops", "ann"), ("approved", "fixed", "bo")]:
        review = {"status": status, "notes": notes, "reviewer": who}
        answer = client.post(f"/api/v1/takes/{first}/reviews", json=review, headers=headers)
        assert answer.status_code == 201, answer.text
    shoot = client.post("/api/v1/shoots", json={"name": "day 1"}, headers=headers)
    if shoot.status_code == 201:
        part = ("files", ("shoot_c.bvh", humanoid_bvh(30, 2).encode()))
        path = f"/api/v1/shoots/{shoot.json()['id']}/takes"
        imported = client.post(path, files=[part], headers=headers)
        for take in imported.json()["created"]:
            finished(take["run_id"])


def main(out: Path) -> None:
    settings = Settings(data_dir=out / "data", job_workers=1)
    if "allowed_hosts" in Settings.model_fields:
        settings = settings.model_copy(update={"allowed_hosts": ["testserver"]})
    app = create_app(settings)
    with TestClient(app) as client:
        headers = {}
        accounts = getattr(app.state, "accounts", None)
        if accounts is not None:
            from mocapqa.store.roles import Role

            user = accounts.add_user("ana", Role.REVIEWER, "correct horse battery")
            token = accounts.issue(user.id, "api", timedelta(days=365)).token
            headers = {"Authorization": f"Bearer {token}"}
        fill(client, headers)
    if settings.database_url is None:
        # one self-contained file: no write-ahead log beside it, no free pages
        database = sqlite3.connect(out / "data" / "mocapqa.sqlite3")
        database.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        database.execute("PRAGMA journal_mode=DELETE")
        database.execute("VACUUM")
        database.close()


if __name__ == "__main__":
    main(Path(sys.argv[1]))
