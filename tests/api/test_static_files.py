"""The dashboard's files gzipped once per version (``mocapqa.api.static_files``)."""

from __future__ import annotations

import gzip
import os
import time
from pathlib import Path

from fastapi import FastAPI
from fastapi.testclient import TestClient

from mocapqa.api.static_files import CompressedStaticFiles

GZIP = {"Accept-Encoding": "gzip"}


def served(tmp_path: Path) -> tuple[TestClient, CompressedStaticFiles]:
    files = CompressedStaticFiles(directory=tmp_path)
    app = FastAPI()
    app.mount("/static", files)
    return TestClient(app), files


def test_a_text_file_is_gzipped_once_and_revalidates(tmp_path: Path) -> None:
    script = tmp_path / "js" / "big.js"
    script.parent.mkdir()
    script.write_text("export const x = 1;\n" * 500)
    client, files = served(tmp_path)
    first = client.get("/static/js/big.js", headers=GZIP)
    assert first.status_code == 200
    assert first.headers["content-encoding"] == "gzip"
    assert first.headers["content-type"].startswith("text/javascript")
    assert first.text == script.read_text()  # the client decodes the gzip
    assert int(first.headers["content-length"]) < script.stat().st_size / 10
    # Kept: the second answer is the same bytes, not a new compression.
    kept = list(files._compressed.values())
    assert client.get("/static/js/big.js", headers=GZIP).content == first.content
    assert list(files._compressed.values()) == kept
    # The file's own ETag: a revalidation gets 304.
    again = client.get("/static/js/big.js", headers=GZIP | {"If-None-Match": first.headers["etag"]})
    assert again.status_code == 304
    # An edited file is compressed afresh; the old version is not kept.
    script.write_text("export const y = 2;\n" * 500)
    later = time.time() + 5
    os.utime(script, (later, later))
    edited = client.get("/static/js/big.js", headers=GZIP)
    assert edited.text == script.read_text()
    assert len(files._compressed) == 1


def test_small_files_other_types_and_plain_clients_are_sent_as_they_are(tmp_path: Path) -> None:
    (tmp_path / "small.js").write_text("export const x = 1;\n")
    (tmp_path / "image.png").write_bytes(b"\x89PNG" + bytes(5000))
    (tmp_path / "big.css").write_text("body { margin: 0; }\n" * 500)
    client, files = served(tmp_path)
    for name in ("small.js", "image.png"):
        answer = client.get(f"/static/{name}", headers=GZIP)
        assert answer.status_code == 200
        assert "content-encoding" not in answer.headers, name
    plain = client.get("/static/big.css", headers={"Accept-Encoding": "identity"})
    assert "content-encoding" not in plain.headers
    assert plain.text == (tmp_path / "big.css").read_text()
    assert files._compressed == {}
    assert client.get("/static/missing.js", headers=GZIP).status_code == 404


def test_warm_compresses_the_named_files_ahead(tmp_path: Path) -> None:
    (tmp_path / "a.js").write_text("export const a = 1;\n" * 200)
    (tmp_path / "tiny.js").write_text("export const t = 1;\n")
    _, files = served(tmp_path)
    files.warm(["a.js", "tiny.js", "missing.js"])
    assert files._warming is not None
    files._warming.join(timeout=60)
    assert [Path(k[0]).name for k in files._compressed] == ["a.js"]
    body = next(iter(files._compressed.values()))
    assert gzip.decompress(body) == (tmp_path / "a.js").read_bytes()
