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
import json
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any

from mocapqa.errors import MocapQAError, ParseError
from mocapqa.jobs.sent_files import SentFiles, pack, pack_tree

__all__ = [
    "RETURNED_FILES",
    "analyse_path",
    "analyse_sent",
    "analyse_stored",
    "analyse_stored_sent",
    "content_sha256",
    "sent_models",
    "stored_name",
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


def stored_name(path: Path) -> str:
    """The name a take is stored under (its file or folder name, made safe)."""
    from mocapqa.jobs.intake import safe_file_name

    return safe_file_name(path.name)


def analyse_path(
    path: str,
    options: dict[str, Any],
    take_id: str,
    run_id: str,
    data_dir: str | None,
    copy_take: bool = True,
) -> dict[str, Any]:
    """Read, analyse and (with ``data_dir``) store one take.

    Parameters
    ----------
    path : str
        A take file or an OpenPose frame folder, readable by the worker.
    options : dict
        Run options as JSON.
    take_id, run_id : str
        Ids chosen by the client (outputs go to ``runs/<run_id>``, the copy to
        ``takes/<take_id>``).
    data_dir : str, optional
        The data folder; None analyses without writing anything.
    copy_take : bool
        Copy the take into ``takes/<take_id>`` (False when the client, which holds the take,
        copies it: :func:`analyse_sent`).

    Returns
    -------
    dict
        ``{"status": "done", "take": row values, "summary": run summary, "time_s"}`` or
        ``{"status": "failed", "error": message}`` for a file the readers reject.
    """
    from mocapqa.core.motion import Motion
    from mocapqa.io.formats import require_frames
    from mocapqa.jobs.runner import run_summary, write_outputs
    from mocapqa.limits.catalog import ModelCatalog
    from mocapqa.pipeline.analyze import analyze
    from mocapqa.pipeline.loading import (
        READING_FILE,
        ReadOptions,
        detect_take_format,
        read_take_file,
        reading_facts,
    )
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.store.files import FileStore

    started = time.perf_counter()
    source = Path(path)
    try:
        format_name = detect_take_format(source)
        try:
            take = read_take_file(source, format_name, str(source))
        except MocapQAError:
            raise
        except (ValueError, LookupError, TypeError, OverflowError, EOFError, OSError) as e:
            raise ParseError(
                f"Expected a readable {format_name} file, got {type(e).__name__}: {e}", source
            ) from e
        require_frames(take, source)
        catalog = ModelCatalog.of_data_folder(data_dir)
        result = analyze(take, AnalysisOptions.from_json(options), catalog=catalog)
    except MocapQAError as e:
        return {"status": "failed", "error": str(e)}
    if isinstance(take, Motion):
        kind, n_points, fps = "motion", take.skeleton.n_joints, take.fps
    else:
        kind, n_points, fps = "keypoints", take.n_keypoints, take.fps
    name = stored_name(source)
    if data_dir is not None:
        files = FileStore(Path(data_dir))
        folder = files.take_dir(take_id)
        folder.mkdir(parents=True, exist_ok=True)
        if copy_take and source.is_dir():
            shutil.copytree(source, folder / name, dirs_exist_ok=True)
        elif copy_take:
            shutil.copyfile(source, folder / name)
        facts = reading_facts(take, ReadOptions())
        files.write_bytes(folder / READING_FILE, json.dumps(facts).encode())
        write_outputs(files, run_id, result, source if source.is_file() else None)
    size = (
        sum(p.stat().st_size for p in source.iterdir() if p.is_file())
        if source.is_dir()
        else source.stat().st_size
    )
    return {
        "status": "done",
        "take": {
            "id": take_id,
            "name": source.name[:255],
            "format": format_name,
            "kind": kind,
            "size_bytes": size,
            "n_frames": take.n_frames,
            "fps": fps,
            "n_joints": n_points,
            "file_name": name,
        },
        "summary": run_summary(result),
        "time_s": time.perf_counter() - started,
    }


def analyse_stored(
    path: str, format_name: str, name: str, options: dict[str, Any], run_id: str, data_dir: str
) -> dict[str, Any]:
    """A server run on a Dask worker: read a stored take, analyse it, write the run's files.

    Returns
    -------
    dict
        The run summary (as :func:`mocapqa.jobs.runner.run_summary`). Errors the readers or
        the analysis raise on purpose travel back as themselves.
    """
    from mocapqa.jobs.runner import read_options, run_summary, write_outputs
    from mocapqa.limits.catalog import ModelCatalog
    from mocapqa.pipeline.analyze import analyze
    from mocapqa.pipeline.loading import read_take_file
    from mocapqa.pipeline.options import AnalysisOptions
    from mocapqa.store.files import FileStore

    stored = Path(path)
    take = read_take_file(stored, format_name, name, read_options(stored.parent))
    catalog = ModelCatalog.of_data_folder(data_dir)
    result = analyze(take, AnalysisOptions.from_json(options), catalog=catalog)
    write_outputs(FileStore(Path(data_dir)), run_id, result, stored)
    return run_summary(result)


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
            outcome[RETURNED_FILES] = pack_tree(data, [f"runs/{run_id}", f"takes/{take_id}"])
    return outcome


def analyse_stored_sent(
    take: SentFiles,
    file_name: str,
    format_name: str,
    name: str,
    options: dict[str, Any],
    run_id: str,
    models: SentFiles,
) -> tuple[dict[str, Any], SentFiles]:
    """:func:`analyse_stored` on a worker that cannot read the server's data folder.

    Parameters
    ----------
    take : SentFiles
        The take's stored file and its reading facts (the files of its take folder).
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
            str(inbox / file_name), format_name, name, options, run_id, str(data)
        )
        return summary, pack_tree(data, [f"runs/{run_id}"])
