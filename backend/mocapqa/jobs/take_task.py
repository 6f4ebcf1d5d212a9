"""One take analysed from its path, as a Dask task (or in-process for comparison).

The task reads the take itself (the client never holds the corpus), analyses it, writes the
run's files and a copy of the take into the data folder (shared by the workers), and returns
only the small things the client stores: the take's row values and the run summary. A worker
that shares neither the client's files nor the data folder is sent the take's bytes instead
(:func:`analyse_sent`, :func:`analyse_stored_sent`) and returns the run's files
(:mod:`mocapqa.jobs.sent_files`).

The analysis stack (the pipeline, scipy, numba) is imported inside the tasks, not by this
module: the batch client imports it to name the task and hash files, and never analyses, so it
does not pay that stack's import time (about 2 CPU s, most of a finished batch's resume) or its
memory (docs/batch.md).
"""

from __future__ import annotations

import hashlib
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any

from mocapqa.errors import MocapQAError
from mocapqa.jobs.reading_record import write_reading
from mocapqa.jobs.run_folder import relative_folder
from mocapqa.jobs.run_outputs import run_summary, write_outputs
from mocapqa.jobs.sent_files import SentFiles, pack, pack_tree
from mocapqa.jobs.take_reading import CheckedTake, read_checked_take
from mocapqa.pipeline.loading import Take
from mocapqa.store.files import FileStore

__all__ = [
    "RETURNED_FILES",
    "analyse_path",
    "analyse_sent",
    "analyse_stored",
    "analyse_stored_sent",
    "content_sha256",
    "copy_take",
    "sent_models",
]

RETURNED_FILES = "files"
"""The key of a sent take's outcome that holds the run's files (a :class:`SentFiles`, paths
relative to the data folder)."""


def content_sha256(path: Path) -> str:
    """SHA-256 of a take: the file's bytes, or of a frame folder its files' names and bytes."""
    digest = hashlib.sha256()
    members = sorted(p for p in path.iterdir() if p.is_file()) if path.is_dir() else [path]
    for member in members:
        if path.is_dir():
            digest.update(member.name.encode() + b"\0")
        with member.open("rb") as handle:
            while chunk := handle.read(1 << 20):
                digest.update(chunk)
    return digest.hexdigest()


def _size_bytes(source: Path) -> int:
    """Bytes of a take file, or of a frame folder's files."""
    if source.is_dir():
        return sum(p.stat().st_size for p in source.iterdir() if p.is_file())
    return source.stat().st_size


def copy_take(source: Path, target: Path) -> None:
    """Copy a take file, or a frame folder with its files, to ``target``."""
    if source.is_dir():
        shutil.copytree(source, target, dirs_exist_ok=True)
    else:
        shutil.copyfile(source, target)


def _store_take(
    source: Path, checked: CheckedTake, take_id: str, data_dir: str, copy: bool
) -> None:
    """The take's reading record in its folder, and (``copy``) a copy of it."""
    files = FileStore(Path(data_dir))
    folder = files.take_dir(take_id)
    folder.mkdir(parents=True, exist_ok=True)
    if copy:
        copy_take(source, folder / checked.file_name)
    write_reading(files, take_id, checked.facts())


def _analyse(
    take: Take,
    options: dict[str, Any],
    data_dir: str | None,
    run_id: str,
    source: Path | None,
    prior: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Analyse a read take with the data folder's limits models (and the reviewer ``prior``
    as JSON, when the server built one), write the run's files there (with ``data_dir``;
    ``source`` is the take's file, None for a frame folder) and return the run summary."""
    from mocapqa.limits.catalog import ModelCatalog
    from mocapqa.pipeline.analyze import analyze
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.twist.reviewer_prior import ReviewerPrior

    catalog = ModelCatalog.of_data_folder(data_dir)
    used = None if prior is None else ReviewerPrior.from_json(prior)
    result = analyze(take, AnalysisOptions.from_json(options), catalog=catalog, prior=used)
    if data_dir is not None:
        write_outputs(FileStore(Path(data_dir)), run_id, result, source, used)
    return run_summary(result)


def analyse_path(
    path: str,
    options: dict[str, Any],
    take_id: str,
    run_id: str,
    data_dir: str | None,
    copy_take: bool = True,
) -> dict[str, Any]:
    """Read, check, analyse and (with ``data_dir``) store one take.

    The take is read and checked as an upload is
    (:func:`~mocapqa.jobs.take_reading.read_checked_take`: a name too long refused, a
    reader's unforeseen error a parse error naming the file) and described the same way
    (its shown name included).

    Parameters
    ----------
    path : str
        A take file or an OpenPose frame folder, readable by the worker.
    options : dict
        Run options as JSON.
    take_id, run_id : str
        Ids chosen by the client (outputs go to the run's folder, the copy to the take's).
    data_dir : str, optional
        The data folder; None analyses without writing anything.
    copy_take : bool
        Copy the take into its folder (False when the client, which holds the take, copies
        it: :func:`analyse_sent`).

    Returns
    -------
    dict
        ``{"status": "done", "take": row values, "summary": run summary, "time_s"}`` or
        ``{"status": "failed", "error": message}`` for a file the readers reject.
    """
    started = time.perf_counter()
    source = Path(path)
    try:
        checked = read_checked_take(source, source.name, label=str(source))
        file = source if source.is_file() else None
        summary = _analyse(checked.take, options, data_dir, run_id, file)
    except MocapQAError as e:
        return {"status": "failed", "error": str(e)}
    if data_dir is not None:
        _store_take(source, checked, take_id, data_dir, copy_take)
    return {
        "status": "done",
        "take": {**checked.row(), "id": take_id, "size_bytes": _size_bytes(source)},
        "summary": summary,
        "time_s": time.perf_counter() - started,
    }


def analyse_stored(
    path: str,
    format_name: str,
    name: str,
    options: dict[str, Any],
    run_id: str,
    data_dir: str,
    read: dict[str, Any] | None = None,
    prior: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """A server run on a Dask worker: read a stored take, analyse it, write the run's files.

    ``read`` is the take's read options as JSON (the server read them from the take's
    reading record, so the worker does not); ``prior`` the reviewer prior the server built
    for the run, as JSON (:class:`mocapqa.twist.reviewer_prior.ReviewerPrior`), or None.

    Returns
    -------
    dict
        The run summary (as :func:`mocapqa.jobs.run_outputs.run_summary`). Errors the readers
        or the analysis raise on purpose travel back as themselves.
    """
    from mocapqa.pipeline.loading import ReadOptions, read_take_file

    stored = Path(path)
    take = read_take_file(stored, format_name, name, ReadOptions.from_json(read))
    return _analyse(take, options, data_dir, run_id, stored, prior)


def sent_models(data_dir: Path | None, model: str | None) -> SentFiles:
    """The data folder's file of a registered limits ``model``, for workers that cannot read
    the folder (nothing for a shipped model, which every worker has, or for None)."""
    from mocapqa.limits.catalog import MODELS_FOLDER

    if data_dir is None or model is None:
        return SentFiles()
    path = data_dir / MODELS_FOLDER / f"{model}.npz"
    return pack(data_dir, [path]) if path.is_file() else SentFiles()


def analyse_sent(
    take: SentFiles,
    options: dict[str, Any],
    take_id: str,
    run_id: str,
    models: SentFiles,
) -> dict[str, Any]:
    """:func:`analyse_path` on a worker that cannot read the client's disk.

    Parameters
    ----------
    take : SentFiles
        The take: one file, or a frame folder's files under the folder's name.
    options : dict
        Run options as JSON.
    take_id, run_id : str
        Ids chosen by the client.
    models : SentFiles
        Files of the data folder the run reads (a registered limits model), relative to it.

    Returns
    -------
    dict
        As :func:`analyse_path`; a done outcome also holds, under :data:`RETURNED_FILES`, the
        run's outputs and the take's reading facts, relative to the data folder. The take
        itself is not sent back: the client has it.
    """
    with tempfile.TemporaryDirectory(prefix="mocapqa-sent-") as scratch:
        inbox, data = Path(scratch) / "take", Path(scratch) / "data"
        take.unpack(inbox)
        models.unpack(data)
        name = take.files[0][0].split("/")[0]
        outcome = analyse_path(str(inbox / name), options, take_id, run_id, str(data), False)
        if outcome["status"] == "done":
            files = FileStore(data)
            folders = [files.run_dir(run_id), files.take_dir(take_id)]
            outcome[RETURNED_FILES] = pack_tree(data, [relative_folder(files, f) for f in folders])
    return outcome


def analyse_stored_sent(
    take: SentFiles,
    file_name: str,
    format_name: str,
    name: str,
    options: dict[str, Any],
    run_id: str,
    models: SentFiles,
    read: dict[str, Any] | None = None,
    prior: dict[str, Any] | None = None,
) -> tuple[dict[str, Any], SentFiles]:
    """:func:`analyse_stored` on a worker that cannot read the server's data folder.

    Parameters
    ----------
    take : SentFiles
        The take's stored file.
    file_name : str
        The stored file's name among them.
    format_name, name : str
        The take's format and the name the user knows it by.
    options : dict
        Run options as JSON.
    run_id : str
        The run.
    models : SentFiles
        Files of the data folder the run reads, relative to it.
    read : dict, optional
        The take's read options as JSON (from its reading record, read by the server).
    prior : dict, optional
        The reviewer prior of the run as JSON, when the server built one.

    Returns
    -------
    tuple of (dict, SentFiles)
        The run summary, and the run's files relative to the data folder.
    """
    with tempfile.TemporaryDirectory(prefix="mocapqa-sent-") as scratch:
        inbox, data = Path(scratch) / "take", Path(scratch) / "data"
        take.unpack(inbox)
        models.unpack(data)
        summary = analyse_stored(
            str(inbox / file_name), format_name, name, options, run_id, str(data), read, prior
        )
        files = FileStore(data)
        return summary, pack_tree(data, [relative_folder(files, files.run_dir(run_id))])
