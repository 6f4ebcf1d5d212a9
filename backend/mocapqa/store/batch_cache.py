"""What a batch looks up before it analyses and stores after: source-file hashes by path, the
contents already analysed with its options, their summary rows, and the takes it finished."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any, TypeVar

from sqlalchemy import delete, insert, select

from mocapqa import __version__
from mocapqa.store.rows import read_rows
from mocapqa.store.shoot_base import ShootTables
from mocapqa.store.stamps import utc_now
from mocapqa.store.tables import runs, source_hashes, take_qa
from mocapqa.store.take_writer import DoneTake, done_run, write_takes

__all__ = ["CHUNK", "BatchCache"]

CHUNK = 500
"""Values in one ``IN (...)`` list (well below SQLite's limit of bound parameters)."""

T = TypeVar("T")


def _chunks(values: Sequence[T]) -> Iterator[Sequence[T]]:
    """``values`` :data:`CHUNK` at a time."""
    for start in range(0, len(values), CHUNK):
        yield values[start : start + CHUNK]


class BatchCache(ShootTables):
    """A batch's reads and writes (a part of :class:`~mocapqa.store.shoots.ShootStore`)."""

    def finished(self, sha256s: list[str], options: dict[str, Any]) -> dict[str, str]:
        """Of these contents, those with a done run of these options and this version.

        Returns
        -------
        dict
            sha256 → take id of the finished run.
        """
        found: dict[str, str] = {}
        with self.engine.connect() as conn:
            for chunk in _chunks(sha256s):
                query = select(runs.c.input_sha256, runs.c.take_id, runs.c.options).where(
                    runs.c.input_sha256.in_(chunk),
                    runs.c.status == "done",
                    runs.c.version == __version__,
                )
                for row in conn.execute(query).mappings():
                    if row["options"] == options:
                        found[str(row["input_sha256"])] = str(row["take_id"])
        return found

    def record_done(self, done: list[DoneTake]) -> None:
        """Store takes analysed elsewhere, each with its one done run, in one transaction
        (:func:`~mocapqa.store.take_writer.write_takes`)."""
        if not done:
            return
        now = utc_now()
        with self.engine.begin() as conn:
            write_takes(conn, [(item.take, done_run(item, now)) for item in done], now)

    def known_hashes(self, paths: list[str]) -> dict[str, tuple[int, int, str]]:
        """Cached ``(size, mtime_ns, sha256)`` of these source paths."""
        found: dict[str, tuple[int, int, str]] = {}
        with self.engine.connect() as conn:
            for chunk in _chunks(paths):
                query = select(source_hashes).where(source_hashes.c.path.in_(chunk))
                for row in conn.execute(query).mappings():
                    found[str(row["path"])] = (
                        int(row["size_bytes"]),
                        int(row["mtime_ns"]),
                        str(row["sha256"]),
                    )
        return found

    def remember_hashes(self, rows: list[dict[str, Any]]) -> None:
        """Store ``{"path", "size_bytes", "mtime_ns", "sha256"}`` rows, replacing older ones."""
        if not rows:
            return
        with self.engine.begin() as conn:
            for chunk in _chunks(rows):
                conn.execute(
                    delete(source_hashes).where(
                        source_hashes.c.path.in_([r["path"] for r in chunk])
                    )
                )
                conn.execute(insert(source_hashes), list(chunk))

    def qa_rows(self, take_ids: list[str]) -> dict[str, dict[str, Any]]:
        """The summary rows of these takes, by take id."""
        found: dict[str, dict[str, Any]] = {}
        with self.engine.connect() as conn:
            for chunk in _chunks(take_ids):
                rows = read_rows(conn, select(take_qa).where(take_qa.c.take_id.in_(chunk)))
                found.update((str(row["take_id"]), row) for row in rows)
        return found
