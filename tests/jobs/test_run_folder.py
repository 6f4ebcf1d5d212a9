"""The run folder's one owner (names, writers, readers) and the one reading of a take that
uploads, shoot imports and batches share."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

import mocapqa.jobs.take_reading as take_reading
from mocapqa.errors import InputError, NotFoundError, ParseError
from mocapqa.jobs.intake import ingest_take
from mocapqa.jobs.reading_record import read_options_of, reading_of, write_reading
from mocapqa.jobs.run_folder import DOWNLOAD_FILES, POINT_ARRAYS, RunFolder
from mocapqa.jobs.run_outputs import write_outputs
from mocapqa.jobs.runner import JobRunner
from mocapqa.jobs.stored_run import load_points, load_report, read_run
from mocapqa.jobs.take_reading import MAX_NAME_CHARS, read_checked_take, take_name
from mocapqa.jobs.take_task import analyse_path
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.loading import ReadOptions, read_take_file
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository

RUN_ID = "0123456789abcdef0123456789abcdef"
TAKE_ID = "fedcba9876543210fedcba9876543210"
WALK = Path("bvh") / "cmu" / "cmu_12_01_walk.bvh"


def test_written_run_reads_back_through_the_folder(corpus_dir: Path, tmp_path: Path) -> None:
    files = FileStore(tmp_path)
    result = analyze(read_take_file(corpus_dir / WALK, "bvh"), AnalysisOptions())
    kinds = write_outputs(files, RUN_ID, result)
    folder = RunFolder.of(files, RUN_ID)
    assert kinds == ["report", "bvh"]
    assert all(folder.download(kind).is_file() for kind in kinds)
    assert set(DOWNLOAD_FILES) == {"bvh", "csv", "trc", "c3d", "report"}
    stored = read_run(folder.path)
    assert stored.report["downloads"] == kinds
    np.testing.assert_allclose(stored.raw, result.raw_points.astype(np.float32), equal_nan=True)
    with np.load(folder.points) as data:
        assert [name for name in POINT_ARRAYS if name in data] == list(data.keys())
    # The same report and points from the bytes a worker sends back.
    assert load_report(folder.report.read_bytes()) == stored.report
    raw = load_points(folder.points.read_bytes(), ("raw",))["raw"]
    np.testing.assert_array_equal(raw.astype(np.float64), stored.raw)


def test_a_missing_or_broken_run_folder_says_which(tmp_path: Path) -> None:
    files = FileStore(tmp_path)
    folder = RunFolder.of(files, RUN_ID)
    with pytest.raises(NotFoundError, match=r"report\.json"):
        read_run(folder.path)
    files.write_bytes(folder.report, b"{not json")
    files.write_bytes(folder.points, b"")
    with pytest.raises(InputError, match="Expected a readable run report and points"):
        read_run(folder.path)


def test_the_reading_record_is_written_and_read_in_one_place(tmp_path: Path) -> None:
    files = FileStore(tmp_path)
    assert reading_of(files, TAKE_ID) is None
    assert read_options_of(files.take_dir(TAKE_ID)) == ReadOptions()
    chosen = ReadOptions(fps=25.0, root_translation="replace")
    write_reading(files, TAKE_ID, {"read_options": chosen.to_json(), "joints": ["Hips"]})
    assert reading_of(files, TAKE_ID) == {"read_options": chosen.to_json(), "joints": ["Hips"]}
    assert read_options_of(files.take_dir(TAKE_ID)) == chosen
    write_reading(files, TAKE_ID, {"read_options": {"fps": -1}})  # not a rate: the defaults
    assert read_options_of(files.take_dir(TAKE_ID)) == ReadOptions()


def test_a_reader_recursing_too_deep_is_a_parse_error_naming_the_file(
    corpus_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Upload and batch alike (it used to escape a batch as an internal error)."""

    def recurses(*args: object, **kwargs: object) -> None:
        raise RecursionError("maximum recursion depth exceeded")

    monkeypatch.setattr(take_reading, "read_take_file", recurses)
    take = tmp_path / "walk.bvh"
    take.write_bytes((corpus_dir / WALK).read_bytes())
    with pytest.raises(ParseError, match=r"walk\.bvh.*RecursionError"):
        read_checked_take(take, "walk.bvh")
    outcome = analyse_path(str(take), AnalysisOptions().to_json(), TAKE_ID, RUN_ID, None)
    assert outcome["status"] == "failed"
    assert "RecursionError" in outcome["error"]
    assert str(take) in outcome["error"]


def test_a_name_too_long_is_refused_not_cut(tmp_path: Path) -> None:
    take = tmp_path / "take.bvh"
    take.write_bytes(b"")
    long_name = "a" * (MAX_NAME_CHARS - 3) + ".bvh"
    with pytest.raises(InputError, match=f"at most {MAX_NAME_CHARS} characters, got 256"):
        read_checked_take(take, long_name)


def test_upload_and_batch_describe_a_take_alike(corpus_dir: Path, tmp_path: Path) -> None:
    """The same file gives the same row from an upload and from a batch, its shown name
    without the bidirectional override the batch used to keep."""
    name = "walk\u202e.bvh"
    take = tmp_path / name
    take.write_bytes((corpus_dir / WALK).read_bytes())
    files = FileStore(tmp_path / "data")
    repository = Repository(f"sqlite:///{tmp_path / 'db.sqlite3'}")
    runner = JobRunner(repository, files, workers=1)  # never started: the run stays queued
    with take.open("rb") as handle:
        take_id, _ = ingest_take(handle, name, repository, files, runner, 1 << 30)
    uploaded = repository.get_take(take_id)
    outcome = analyse_path(str(take), AnalysisOptions().to_json(), TAKE_ID, RUN_ID, None)
    batched = outcome["take"]
    repository.close()
    assert batched["name"] == uploaded["name"] == take_name(name) == "walk.bvh"
    for column in ("format", "kind", "n_frames", "fps", "n_joints", "file_name", "size_bytes"):
        assert batched[column] == uploaded[column], column


def test_an_empty_upload_is_refused_before_reading(tmp_path: Path) -> None:
    files = FileStore(tmp_path / "data")
    repository = Repository(f"sqlite:///{tmp_path / 'db.sqlite3'}")
    runner = JobRunner(repository, files, workers=1)
    with pytest.raises(ParseError, match="non-empty"):
        ingest_take(io.BytesIO(b""), "empty.bvh", repository, files, runner, 100)
    assert repository.list_takes()[1] == 0
    repository.close()
