"""Writing an output file whole or not at all.

Every writer of a file a user names (BVH, TRC, keypoint CSV/JSON/NPY/NPZ, the report's HTML and
PDF, rendered PNG/GIF/MP4, a limits model, the batch results table) goes through this module:

* The data go to a temporary file in the target's folder (``.<name>.<random>.tmp``, created
  with the permissions a new file gets, or the target's when it exists). On success it is
  renamed over the target in one step; on any failure (an exception, a full disk, ``ulimit
  -f``) it is removed, so an existing target is left as it was and nothing half-written stays.
* A target that exists and is not a regular file (a directory, a FIFO, a device such as
  ``/dev/full``, a socket) is refused with :class:`~mocapqa.errors.InputError`: a rename would
  replace it with a regular file.
* A symbolic link is written through: the file it points to is replaced (after the same check)
  and the link itself is kept. A dangling link creates the file it names.
* An :class:`OSError` while writing or renaming is raised again with the target's path as its
  ``filename``, so the message names the output the user gave, not the temporary file.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from mocapqa.errors import InputError

__all__ = [
    "PendingFile",
    "atomic_path",
    "output_target",
    "with_output_path",
    "write_bytes",
    "write_text",
]

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def output_target(path: str | Path) -> Path:
    """The file a write to ``path`` replaces: ``path``, or the file a symbolic link points to.

    Parameters
    ----------
    path : str or Path
        The output as the user gave it.

    Returns
    -------
    Path
        ``path`` itself, or for a symbolic link its fully resolved target.

    Raises
    ------
    InputError
        When the target exists and is not a regular file (directory, FIFO, device, socket).
    """
    path = Path(path)
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    try:
        mode = target.stat().st_mode
    except (FileNotFoundError, NotADirectoryError):
        return target
    except OSError:
        return target  # unreadable metadata: the write itself reports the error, naming path
    if not stat.S_ISREG(mode):
        kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
        via = f" (through the link {path})" if target != path else ""
        raise InputError(
            f"Expected a regular file or a new file name as output, got {kind}: {target}{via}"
        )
    return target


def with_output_path(error: OSError, path: str | Path) -> OSError:
    """``error`` raised again naming ``path``: same errno (so the same subclass), ``path`` as
    its ``filename``.

    Parameters
    ----------
    error : OSError
        An error of writing a temporary file (or of a library writing it).
    path : Path
        The output the user named.

    Returns
    -------
    OSError
        The error to raise (``from error``).
    """
    if error.errno is None:
        renamed = OSError(error.strerror or str(error) or type(error).__name__)
        renamed.filename = str(path)
        return renamed
    return OSError(error.errno, error.strerror or os.strerror(error.errno), str(path))


class PendingFile:
    """A temporary file that becomes ``path`` on :meth:`commit`, or disappears on :meth:`discard`.

    For writers that stream (the batch table); others use :func:`atomic_path`.

    Parameters
    ----------
    path : str or Path
        The output (checked with :func:`output_target`).

    Attributes
    ----------
    path : Path
        The output as given.
    target : Path
        The file replaced on commit (``path``, or a symbolic link's target).
    temporary : Path
        Where to write: an empty file in the target's folder.

    Raises
    ------
    InputError
        When the target is not a regular file.
    OSError
        When the temporary file cannot be created (its ``filename`` is ``path``).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.target = output_target(self.path)
        name = f".{self.target.name[:100]}.{secrets.token_hex(4)}.tmp"  # within NAME_MAX
        self.temporary = self.target.with_name(name)
        try:
            handle = os.open(self.temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except OSError as e:
            raise with_output_path(e, self.path) from e
        try:
            if self.target.is_file():  # keep the permissions of the file being replaced
                os.fchmod(handle, stat.S_IMODE(self.target.stat().st_mode))
        except OSError:
            pass  # the new file keeps the default permissions
        finally:
            os.close(handle)
        self._open = True

    def commit(self) -> None:
        """Rename the temporary over the target (removing the temporary if that fails).

        Raises
        ------
        InputError
            When the target became something other than a regular file meanwhile.
        OSError
            When the rename fails (its ``filename`` is the output's path).
        """
        if not self._open:
            return
        with self.discarding():
            output_target(self.path)
            os.replace(self.temporary, self.target)
        self._open = False

    @contextmanager
    def discarding(self) -> Iterator[None]:
        """Discard the temporary file when the block fails, and re-raise: an ``OSError``
        with the output's path as its ``filename``, anything else as it is."""
        try:
            yield
        except OSError as e:
            self.discard()
            raise with_output_path(e, self.path) from e
        except BaseException:
            self.discard()
            raise

    def discard(self) -> None:
        """Remove the temporary file; the target is left as it was."""
        self._open = False
        # Nothing more can be done if this fails; the caller's error is the one to report.
        with contextlib.suppress(OSError):
            self.temporary.unlink(missing_ok=True)


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write; renamed over ``path`` when the block ends without error.

    The temporary name ends in ``.tmp``: a writer that picks its format from the extension
    (matplotlib, Pillow) must be told the format.

    Parameters
    ----------
    path : str or Path
        The output.

    Yields
    ------
    Path
        An empty file in the output's folder to write (or overwrite) in the block.

    Raises
    ------
    InputError
        When the output exists and is not a regular file.
    OSError
        When creating, writing or renaming fails, with the output's path as ``filename``;
        the temporary file is removed and an existing output is left unchanged.
    """
    pending = PendingFile(path)
    with pending.discarding():
        yield pending.temporary
    pending.commit()


def write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` whole or not at all (see :func:`atomic_path`).

    Parameters
    ----------
    path : str or Path
        The output.
    data : bytes
        Its content.
    """
    with atomic_path(path) as temporary:
        temporary.write_bytes(data)


def write_text(path: str | Path, text: str, encoding: str = "utf-8", newline: str = "\n") -> None:
    """Write ``text`` to ``path`` whole or not at all (see :func:`atomic_path`).

    Parameters
    ----------
    path : str or Path
        The output.
    text : str
        Its content.
    encoding : str, default "utf-8"
        Text encoding.
    newline : str, default "\\n"
        What each ``"\\n"`` of ``text`` is written as.
    """
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding=encoding, newline=newline)
