"""Checks every command that writes files makes before it reads or computes anything.

* :func:`check_outputs` refuses an output that is the same file as an input (by path after
  resolving links, or by device and inode for hard links), a file the command will read
  from an input folder, or another output of the same command; an output that exists and is
  not a regular file (a directory, a FIFO, a device) is refused too
  (:func:`mocapqa.io.atomic.output_target`). An input ``.csv`` counts with its
  ``.meta.json`` sidecar, and so does a keypoint CSV output (``sidecars=True``).
* :func:`require_suffix` refuses an output whose extension does not match what will be
  written, naming the extensions expected.

Both raise :class:`~mocapqa.errors.InputError` (exit code 3), naming the option and the paths.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from mocapqa.errors import InputError, UnsupportedFormatError

__all__ = ["FolderReads", "check_outputs", "require_suffix", "take_input"]


@dataclass(frozen=True)
class FolderReads:
    """The files a command reads from a folder: those ending in one of ``suffixes``.

    Parameters
    ----------
    folder : Path
        The input folder.
    suffixes : tuple of str
        Lower-case extensions with their dot (``(".bvh",)``).
    recursive : bool, default False
        Whether files in sub-folders are read too.
    """

    folder: Path
    suffixes: tuple[str, ...]
    recursive: bool = False

    def reads(self, path: Path) -> bool:
        """Whether ``path`` (resolved) is a file this command would read from the folder."""
        folder = self.folder.resolve()
        if path.suffix.lower() not in self.suffixes:
            return False
        return path.parent == folder or (self.recursive and path.is_relative_to(folder))


def take_input(path: Path) -> Path | FolderReads:
    """What reading a take argument reads: the file, or an OpenPose folder's ``*.json``."""
    return FolderReads(path, (".json",)) if path.is_dir() else path


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # one does not exist (yet): compare where they lead
        return a.resolve() == b.resolve()


def _with_sidecars(label: str, path: Path, existing_only: bool) -> list[tuple[str, Path]]:
    """``path``, and for a ``.csv`` its ``.meta.json`` sidecar (when it exists, for inputs)."""
    from mocapqa.io.keypoint_csv import csv_sidecar_path

    paths = [(label, path)]
    if path.suffix.lower() == ".csv":
        sidecar = csv_sidecar_path(path)
        if not existing_only or sidecar.exists():
            paths.append((f"{label} (its .meta.json sidecar)", sidecar))
    return paths


def check_outputs(
    outputs: Mapping[str, Path | None],
    inputs: Iterable[Path | FolderReads | None],
    sidecars: bool = False,
) -> None:
    """Refuse outputs that would destroy an input or each other, before any work is done.

    Parameters
    ----------
    outputs : mapping of str to Path or None
        Option name (``"-o"``, ``"--report"``) → output path; None for an output not asked
        for.
    inputs : iterable of Path, FolderReads or None
        Files the command reads (None ignored), and folders it reads files from.
    sidecars : bool, default False
        Whether a ``.csv`` output is a keypoint CSV, written with its ``.meta.json`` sidecar.

    Raises
    ------
    InputError
        Naming the option and both paths, when an output is the same file as an input, is a
        file read from an input folder, or is the same file as another output; or when an
        output exists and is not a regular file.
    """
    from mocapqa.io.atomic import output_target

    written = [
        item
        for label, path in outputs.items()
        if path is not None
        for item in (_with_sidecars(label, path, False) if sidecars else [(label, path)])
    ]
    files: list[Path] = []
    folders: list[FolderReads] = []
    for source in inputs:
        if isinstance(source, FolderReads):
            folders.append(source)
        elif source is not None:
            files.extend(p for _, p in _with_sidecars("input", source, existing_only=True))
    for k, (label, path) in enumerate(written):
        output_target(path)
        for source in files:
            if _same_file(path, source):
                raise InputError(
                    f"Expected {label} to name a file other than the input, got {path}, "
                    f"the same file as the input {source}"
                )
        resolved = path.resolve()
        for folder in folders:
            if folder.reads(resolved):
                raise InputError(
                    f"Expected {label} outside the files read from the input folder "
                    f"{folder.folder}, got {path}, a {resolved.suffix} file there"
                )
        for other_label, other in written[:k]:
            if _same_file(path, other):
                raise InputError(
                    f"Expected {other_label} and {label} to name different files, got {other} "
                    f"and {path}, the same file"
                )


def require_suffix(label: str, path: Path, suffixes: Sequence[str], what: str) -> str:
    """The output's lower-case extension, when it is one of ``suffixes``.

    Parameters
    ----------
    label : str
        The option (``"-o"``).
    path : Path
        The output.
    suffixes : sequence of str
        Extensions allowed, with their dot (``(".png",)``).
    what : str
        What will be written (``"a PNG image"``), for the message.

    Returns
    -------
    str
        The extension, lower case, with its dot.

    Raises
    ------
    UnsupportedFormatError
        Naming the output and the extensions expected.
    """
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        raise UnsupportedFormatError(
            f"Expected {label} ending in {' or '.join(suffixes)} for {what}, got {path.name!r}"
        )
    return suffix
