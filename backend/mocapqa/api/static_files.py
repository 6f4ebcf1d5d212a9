"""The dashboard's files (``/static``), each text file gzipped once per version, not per request.

Starlette's :class:`~starlette.staticfiles.StaticFiles` streams a file and the app's gzip
middleware compresses it on every request, on the event loop: opening a take compresses
three.js's 735 kB again (about 45 ms of CPU on this machine, more under load), while the take's
own data waits behind it. Here a text file's compressed bytes are kept, keyed by its path, size
and modification time (an edited file is compressed afresh); the answer carries the file's own
``ETag`` and ``Last-Modified``, so revalidation works as before.
"""

from __future__ import annotations

import gzip
import os
import threading
from collections.abc import Iterable
from pathlib import Path

from starlette.datastructures import Headers
from starlette.responses import FileResponse, Response
from starlette.staticfiles import StaticFiles
from starlette.types import Scope

__all__ = ["COMPRESSED_SUFFIXES", "MIN_COMPRESSED_BYTES", "CompressedStaticFiles"]

COMPRESSED_SUFFIXES = frozenset({".js", ".css", ".html", ".json", ".svg", ".txt"})
"""Text files worth compressing (images and fonts are compressed already)."""
MIN_COMPRESSED_BYTES = 2048
"""Smaller files are sent as they are (the app's gzip middleware's own threshold)."""
_MAX_KEPT_BYTES = 8 * 1024 * 1024
"""A file larger than this is left to the middleware (the dashboard's largest is 0.4 MB)."""
_KEPT_HEADERS = ("etag", "last-modified", "content-type")


class CompressedStaticFiles(StaticFiles):
    """:class:`StaticFiles` answering a client that accepts gzip with bytes compressed once."""

    def __init__(self, *, directory: Path, compresslevel: int = 6) -> None:
        super().__init__(directory=directory)
        self._compresslevel = compresslevel
        self._compressed: dict[tuple[str, int, int], bytes] = {}
        self._warming: threading.Thread | None = None

    def file_response(
        self,
        full_path: str | os.PathLike[str],
        stat_result: os.stat_result,
        scope: Scope,
        status_code: int = 200,
    ) -> Response:
        response = super().file_response(full_path, stat_result, scope, status_code)
        if (
            not isinstance(response, FileResponse)  # 304 Not Modified
            or status_code != 200
            or "gzip" not in Headers(scope=scope).get("accept-encoding", "")
            or Path(full_path).suffix not in COMPRESSED_SUFFIXES
            or not MIN_COMPRESSED_BYTES <= stat_result.st_size <= _MAX_KEPT_BYTES
        ):
            return response
        body = self._compress(os.fspath(full_path), stat_result)
        headers = {name: response.headers[name] for name in _KEPT_HEADERS}
        headers |= {"Content-Encoding": "gzip", "Vary": "Accept-Encoding"}
        return Response(body, status_code, headers=headers)

    def _compress(self, path: str, stat_result: os.stat_result) -> bytes:
        """The file's gzipped bytes, compressed on first use of this version of it."""
        key = (path, stat_result.st_size, stat_result.st_mtime_ns)
        body = self._compressed.get(key)
        if body is None:
            body = gzip.compress(Path(path).read_bytes(), self._compresslevel, mtime=0)
            kept = {k: v for k, v in self._compressed.items() if k[0] != path}
            self._compressed = kept | {key: body}  # one assignment: readers see old or new
        return body

    def warm(self, addresses: Iterable[str]) -> None:
        """Compress these files (URL paths below the mount, ``js/app.js``) on a thread now,
        once: a page's modules are then ready before its requests come (zlib lets the event
        loop run meanwhile). Files that are missing or not compressed are passed over."""
        if self._warming is not None:
            return

        def compress_all() -> None:
            for address in addresses:
                found, stat_result = self.lookup_path(address)
                if (
                    stat_result is not None
                    and Path(found).suffix in COMPRESSED_SUFFIXES
                    and MIN_COMPRESSED_BYTES <= stat_result.st_size <= _MAX_KEPT_BYTES
                ):
                    self._compress(found, stat_result)

        self._warming = threading.Thread(target=compress_all, name="static-gzip", daemon=True)
        self._warming.start()
