"""The batch results table, streamed to disk row by row (CSV, JSON lines or Parquet).

One row per file: ``source``, ``status`` (done | failed | skipped), ``error``, ``take_id`` and
the QA summary columns (``docs/qa-summary.md``). Parquet is written in row groups of
:data:`ROW_GROUP` rows, so memory stays bounded whatever the corpus size. Rows stream to a
temporary file beside the output, renamed into place on :meth:`ResultWriter.close`
(:mod:`mocapqa.io.atomic`): a table that cannot be finished (a full disk) leaves an existing
file as it was, and a device, FIFO or folder is refused up front.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any, TextIO

from mocapqa.errors import InputError
from mocapqa.io.atomic import PendingFile, output_target, with_output_path

__all__ = ["COLUMNS", "OUTPUT_FORMATS", "ROW_GROUP", "ResultWriter"]

COLUMNS: tuple[tuple[str, str], ...] = (
    ("source", "string"),
    ("status", "string"),
    ("error", "string"),
    ("take_id", "string"),
    ("n_frames", "int64"),
    ("duration_s", "float64"),
    ("rig", "string"),
    ("twist_intervals", "int64"),
    ("corrected_joint_frames", "int64"),
    ("limb_spins", "int64"),
    ("violation_share", "float64"),
    ("worst_joint", "string"),
    ("filter_residual_mm", "float64"),
    ("missing_share", "float64"),
    ("score", "float64"),
    ("review_status", "string"),
)
"""Column names and types of the results table, in order."""
OUTPUT_FORMATS = {".csv": "csv", ".jsonl": "jsonl", ".parquet": "parquet"}
"""Output formats by file suffix."""
ROW_GROUP = 500
"""Rows per Parquet row group (and per flush of the other formats)."""


class ResultWriter:
    """Writes result rows to ``path`` in the format its suffix names.

    Raises
    ------
    InputError
        For a suffix other than ``.csv``, ``.jsonl`` or ``.parquet``, or an output that
        exists and is not a regular file.
    """

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.format = OUTPUT_FORMATS.get(self.path.suffix.lower(), "")
        if not self.format:
            raise InputError(
                f"Expected an output ending in {', '.join(OUTPUT_FORMATS)}, got {self.path.name!r}"
            )
        self.path.parent.mkdir(parents=True, exist_ok=True)
        output_target(self.path)  # refused before the batch starts, not at its end
        self._file: PendingFile | None = None  # created on the first flush
        self._closed = False
        self._pending: list[dict[str, Any]] = []
        self._text: TextIO | None = None
        self._csv: Any = None
        self._parquet: Any = None
        self.rows = 0

    def write(self, row: dict[str, Any]) -> None:
        """Queue one row (missing columns are empty); flushed every :data:`ROW_GROUP` rows."""
        self._pending.append({name: row.get(name) for name, _ in COLUMNS})
        self.rows += 1
        if len(self._pending) >= ROW_GROUP:
            self.flush()

    def flush(self) -> None:
        """Write the queued rows.

        Raises
        ------
        OSError
            When they cannot be written (its ``filename`` is the output, not the temporary).
        """
        try:
            if self.format == "parquet":
                self._flush_parquet()
            else:
                self._flush_text()
        except OSError as e:
            raise with_output_path(e, self.path) from e
        self._pending = []

    def _temporary(self) -> Path:
        if self._file is None:
            self._file = PendingFile(self.path)
        return self._file.temporary

    def _flush_text(self) -> None:
        if self._text is None:
            self._text = self._temporary().open("w", newline="", encoding="utf-8")
            if self.format == "csv":
                self._csv = csv.DictWriter(self._text, [name for name, _ in COLUMNS])
                self._csv.writeheader()
        for row in self._pending:
            if self._csv is not None:
                self._csv.writerow(row)
            else:
                self._text.write(json.dumps(row, allow_nan=False) + "\n")
        self._text.flush()

    def _flush_parquet(self) -> None:
        import pyarrow as pa  # type: ignore[import-untyped]
        import pyarrow.parquet as pq  # type: ignore[import-untyped]

        schema = pa.schema([(name, pa.type_for_alias(kind)) for name, kind in COLUMNS])
        if self._parquet is None:
            self._parquet = pq.ParquetWriter(self._temporary(), schema)
        if self._pending:
            table = pa.Table.from_pylist(self._pending, schema=schema)
            self._parquet.write_table(table)

    def close(self) -> None:
        """Flush, close and rename the file into place (an empty table still gets its header
        or schema).

        Raises
        ------
        OSError
            When the table cannot be finished (its ``filename`` is the output); the
            temporary file is removed and an existing output is left as it was.
        """
        if self._closed:
            return
        self._closed = True
        error: BaseException | None = None
        try:
            self.flush()
        except BaseException as e:
            error = e
        for handle in (self._text, self._parquet):
            try:
                if handle is not None:
                    handle.close()
            except BaseException as e:
                error = error or e
        self._text = self._parquet = None
        if error is not None:
            if self._file is not None:
                self._file.discard()
            if isinstance(error, OSError):
                raise with_output_path(error, self.path) from error
            raise error
        if self._file is not None:
            self._file.commit()

    def __enter__(self) -> ResultWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
