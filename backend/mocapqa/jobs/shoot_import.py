"""Importing many files into a shoot: plain takes and archives of takes, each member alone.

Every file or archive member becomes a take of the shoot when it reads; members that are not
motion files are listed as skipped, members that fail (unsafe names, links, unreadable or
malformed content) are listed with their error, and the rest are kept. Limits on the archive
as a whole (size, member count, unpacked size) reject it entirely, before extracting; a member
larger than the upload limit is cut while it is unpacked and listed as failed. An archive's
declared unpacked size is added to the request's hold of the user's staging allowance
(:mod:`mocapqa.jobs.staging`) before it is unpacked, and given back once its members are
stored.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any, BinaryIO

from mocapqa.errors import InputError, MocapQAError, NotFoundError, TooLargeError
from mocapqa.jobs.archive import Member, archive_kind, unpack
from mocapqa.jobs.batch import SIDECAR_REASON, skip_reason
from mocapqa.jobs.intake import ingest_take, receive
from mocapqa.jobs.runner import JobRunner
from mocapqa.jobs.staging import StagingHold
from mocapqa.jobs.take_reading import MAX_NAME_CHARS
from mocapqa.pipeline.loading import ReadLimits
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository

__all__ = ["ImportLimits", "ImportReport", "import_uploads"]


@dataclass(frozen=True, slots=True)
class ImportLimits:
    """Size limits of one import.

    Parameters
    ----------
    max_upload_bytes : int
        Largest file or archive received, and archive member unpacked.
    max_members : int
        Most members of an archive.
    max_unpacked_bytes : int
        Most bytes an archive may unpack to.
    read : ReadLimits, optional
        Each take's read limits (frames × points, joints, ...), as for a single upload.
    """

    max_upload_bytes: int
    max_members: int
    max_unpacked_bytes: int
    read: ReadLimits | None = None


@dataclass
class ImportReport:
    """What an import did: created takes, skipped and failed files (or members)."""

    created: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[dict[str, str]] = field(default_factory=list)
    failed: list[dict[str, str]] = field(default_factory=list)


def _label(archive: str, member: str) -> str:
    """How a member is named in the report: ``archive:member``, a name longer than any file
    system keeps cut (a zip member's name may hold 65,535 bytes, echoed per member)."""
    label = f"{archive}:{member}"
    limit = 2 * MAX_NAME_CHARS
    return label if len(label) <= limit else f"{label[: limit - 1]}…"


def _holder(staging: StagingHold | None, name: str, held: list[int]) -> Callable[[int], None]:
    """An archive's ``before_extract``: its declared unpacked size held in ``staging`` (which
    may refuse it), and noted in ``held`` to be given back."""

    def hold(declared: int) -> None:
        if staging is not None:
            staging.reserve(declared, f" ({declared} unpacked from {name!r})")
            held[0] = declared

    return hold


IMPORT_SIDECAR_REASON = (
    "a keypoint CSV's .meta.json sidecar: not read by an import (the CSV's rate comes from its "
    "time column, its unit is 'unknown'); upload the CSV alone with fps and length_unit"
)
"""The skip reason of a sidecar in an import: unlike a batch of local files, an import stores
each file as a take of its own, so the sidecar never reaches its CSV's reader."""


def _skip_reason(name: str) -> str | None:
    """Why an uploaded file or archive member is not a take (the batch's rule), or None."""
    reason = skip_reason(PurePosixPath(name.replace("\\", "/")).name)
    return IMPORT_SIDECAR_REASON if reason == SIDECAR_REASON else reason


@dataclass
class _Import:
    """One import's places and limits, and its report so far."""

    shoot_id: str
    repository: Repository
    files: FileStore
    runner: JobRunner
    limits: ImportLimits
    client: str
    owner_id: int | None
    staging: StagingHold | None
    report: ImportReport = field(default_factory=ImportReport)

    def ingest(self, source: BinaryIO, name: str, label: str | None = None) -> None:
        """Store one take (as an upload) and list it as created, or as failed."""
        try:
            take_id, run_id = ingest_take(
                source,
                name,
                self.repository,
                self.files,
                self.runner,
                self.limits.max_upload_bytes,
                limits=self.limits.read,
                client=self.client,
                shoot_id=self.shoot_id,
                owner_id=self.owner_id,
            )
        except NotFoundError:
            raise  # the shoot itself is gone: the import stops (404)
        except MocapQAError as e:
            self.report.failed.append({"name": label or name, "error": str(e)})
        else:
            created = {"name": name, "take_id": take_id, "run_id": run_id}
            same = self.repository.same_content(take_id)
            if same is not None:  # kept (a reviewer may want both), but said
                created["duplicate_of"] = same
            self.report.created.append(created)

    def file(self, source: BinaryIO, name: str) -> None:
        """A file sent alone: a take, or skipped by the rule of an archive's members (a
        notes.txt beside the takes of a folder chosen in the browser is not a failed take)."""
        reason = _skip_reason(name)
        if reason is None:
            self.ingest(source, name)
        else:
            self.report.skipped.append({"name": name, "reason": reason})

    def archive(self, source: BinaryIO, name: str) -> None:
        """An archive: received, unpacked in a scratch folder (its declared size held in the
        staging allowance meanwhile) and each member taken as a file."""
        scratch = Path(tempfile.mkdtemp(prefix="archive-", dir=self.files.root / "incoming"))
        held = [0]
        try:
            received = scratch / "archive"
            receive(source, received, name, self.limits.max_upload_bytes)
            members = scratch / "members"
            members.mkdir()
            try:
                unpacked = unpack(
                    received,
                    name,
                    members,
                    self.limits.max_members,
                    self.limits.max_unpacked_bytes,
                    max_member_bytes=self.limits.max_upload_bytes,
                    before_extract=_holder(self.staging, name, held),
                )
            except TooLargeError:
                raise
            except InputError as e:  # unreadable: listed as failed, the other uploads go on
                self.report.failed.append({"name": name, "error": str(e)})
                return
            for member in unpacked:
                self.member(name, member)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
            if self.staging is not None:
                self.staging.release(held[0])

    def member(self, archive: str, member: Member) -> None:
        """One unpacked member of ``archive``: failed, skipped or ingested (then removed)."""
        label = _label(archive, member.name)
        if member.path is None:
            self.report.failed.append({"name": label, "error": str(member.problem)})
        elif (reason := _skip_reason(member.name)) is not None:
            self.report.skipped.append({"name": label, "reason": reason})
        else:
            with member.path.open("rb") as handle:
                base = PurePosixPath(member.name.replace("\\", "/")).name
                self.ingest(handle, base, label)
            member.path.unlink(missing_ok=True)


def import_uploads(
    uploads: list[tuple[BinaryIO, str]],
    shoot_id: str,
    repository: Repository,
    files: FileStore,
    runner: JobRunner,
    limits: ImportLimits,
    client: str = "local",
    owner_id: int | None = None,
    staging: StagingHold | None = None,
) -> ImportReport:
    """Import uploaded files (takes or archives of takes) into a shoot; analyses start, in
    ``client``'s line of the runner's fair queue (and counted in its queued runs). Each take
    is stored owned by ``owner_id``, so takes made before a limit stops the import keep theirs.
    Each archive's declared unpacked size is held in ``staging`` (the request's hold of its
    user's allowance in ``incoming/``) while it is unpacked and stored.

    Raises
    ------
    TooLargeError
        When an archive passes a limit (earlier uploads of the same request are kept), or
        would take the request past the staging allowance alone.
    RateLimitError
        When an archive would take the user's requests past the staging allowance.
    NotFoundError
        When the shoot is deleted while the import runs (the take being stored is removed).
    """
    run = _Import(shoot_id, repository, files, runner, limits, client, owner_id, staging)
    for source, name in uploads:
        if archive_kind(name) is None:
            run.file(source, name)
        else:
            run.archive(source, name)
    return run.report
