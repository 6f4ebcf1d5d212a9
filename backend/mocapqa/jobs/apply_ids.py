"""Interval ids a new run's ``twist_apply`` names, checked against the take's finished runs
before the run is queued.

Ids are positions in a run's twist findings (:class:`mocapqa.twist.choice.TwistInterval`), so
they only mean something on a take that has a finished run listing them; the newest such run is
the one a reviewer picked them from. A run that then finds fewer intervals (other options)
still fails naming ``twist_apply`` (:func:`mocapqa.pipeline.steps.run_twist`).
"""

from __future__ import annotations

from mocapqa.errors import OptionError
from mocapqa.jobs.twist_items import twist_items_of
from mocapqa.store.files import FileStore
from mocapqa.store.repository import Repository
from mocapqa.twist.choice import parse_apply

__all__ = ["check_apply_ids"]


def check_apply_ids(repository: Repository, files: FileStore, take_id: str, apply: str) -> None:
    """Refuse ``twist_apply`` ids that the take's newest finished run with twist intervals
    does not list (any named choice passes).

    Raises
    ------
    OptionError
        Naming ``twist_apply``: ids on a take with no finished run that lists twist intervals,
        or ids that run does not have (the message gives its id and its intervals' ids).
    """
    choice = parse_apply(apply)
    if not isinstance(choice, frozenset):
        return
    for run in reversed(repository.list_runs(take_id)):
        if run["status"] != "done":
            continue
        listed = set(twist_items_of(files, str(run["id"])))
        if not listed:
            continue
        unknown = sorted(choice - listed)
        if unknown:
            shown = f"{unknown[:20]}{' and more' if len(unknown) > 20 else ''}"
            raise OptionError(
                "twist_apply",
                f"Expected interval ids of run {run['id']} (the take's newest run with twist "
                f"intervals: {min(listed)} to {max(listed)}), got {shown}",
            )
        return
    raise OptionError(
        "twist_apply",
        "Expected interval ids from an earlier run's twist findings, but this take has no "
        "finished run with twist intervals; use confident, all or none",
    )
