"""The fixed split of a corpus' BVH takes into build takes and held-back takes, by rig.

Every BVH take is grouped by rig fingerprint (:func:`mocapqa.limits.rig.rig_fingerprint`);
groups of fewer than two takes are left out. In each group the takes are sorted by file name and
every take at a position ``i`` with ``i % 4 == 1`` is held back (never used to build a model or
choose a parameter); the rest build. The limits-model builds of the product and the benchmarks
both use this one rule.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from mocapqa.core.motion import Skeleton
from mocapqa.errors import InputError
from mocapqa.limits.rig import RIG_FAMILIES, rig_family, rig_fingerprint

__all__ = [
    "check_rig_family",
    "corpus_files",
    "held_back",
    "held_back_names",
    "rig_positions",
    "split_group",
    "split_positions",
]


def held_back(index: int) -> bool:
    """The fixed split rule: the take at sorted position ``index`` is held back."""
    return index % 4 == 1


def corpus_files(corpus_dir: Path) -> list[Path]:
    """The BVH files of a corpus in the order every split and build reads them: under its
    ``bvh`` subfolder when it has one, sorted by file name."""
    root = corpus_dir / "bvh" if (corpus_dir / "bvh").is_dir() else corpus_dir
    return sorted(root.rglob("*.bvh"), key=lambda p: p.name)


def split_group(skeleton: Skeleton) -> tuple[object, ...] | None:
    """The group a take is split in (family label and rig fingerprint), None for a rig of
    the family "other" (never split)."""
    family = rig_family(skeleton)
    if family == "other":
        return None
    return (family, *sorted(rig_fingerprint(skeleton).items()))


def split_positions(
    groups: Sequence[tuple[object, ...] | None],
) -> dict[tuple[object, ...], tuple[list[int], list[int]]]:
    """The fixed split over takes in :func:`corpus_files` order, from the :func:`split_group`
    of each: per group of two or more takes, the positions (in ``groups``) of its build takes
    and of its held-back takes."""
    members: dict[tuple[object, ...], list[int]] = {}
    for i, key in enumerate(groups):
        if key is not None:
            members.setdefault(key, []).append(i)
    return {
        key: ([i for n, i in enumerate(m) if not held_back(n)],
              [i for n, i in enumerate(m) if held_back(n)])
        for key, m in members.items() if len(m) >= 2
    }  # fmt: skip


def held_back_names(groups: Sequence[tuple[str, tuple[object, ...] | None]]) -> set[str]:
    """Names of the takes the fixed split holds back, from ``(name, split_group)`` of every
    take in :func:`corpus_files` order (:func:`corpus_rigs` without reading the takes)."""
    positions = split_positions([key for _, key in groups])
    return {groups[i][0] for _, back in positions.values() for i in back}


def check_rig_family(family: str) -> None:
    """An InputError unless ``family`` is one of :data:`mocapqa.limits.rig.RIG_FAMILIES`."""
    if family not in RIG_FAMILIES:
        raise InputError(f"Expected a rig family among {', '.join(RIG_FAMILIES)}, got {family!r}")


def rig_positions(
    groups: Sequence[tuple[str, tuple[object, ...] | None]], family: str, corpus_dir: Path,
    all_takes: bool = False, exclude: set[str] | frozenset[str] = frozenset(),
) -> list[int]:  # fmt: skip
    """The takes a per-rig model of ``family`` is built from: the build takes of the one rig
    of that family (then its held-back takes, with ``all_takes``), less the names in
    ``exclude``.

    Parameters
    ----------
    groups : sequence of (str, tuple or None)
        Name and :func:`split_group` of every take, in :func:`corpus_files` order.
    family : str
    corpus_dir : Path
        For messages.
    all_takes : bool
    exclude : set of str

    Returns
    -------
    list of int
        Positions in ``groups``.

    Raises
    ------
    InputError
        If ``family`` is not a rig family, the folder has no rig of that family with two or
        more takes or more than one such rig, or no take is left.
    """
    check_rig_family(family)
    rigs = [
        split for key, split in split_positions([key for _, key in groups]).items()
        if key[0] == family
    ]  # fmt: skip
    if len(rigs) != 1:
        raise InputError(
            f"Expected one {family} rig with two or more takes in {corpus_dir}, got {len(rigs)}"
        )
    build, back = rigs[0]
    chosen = [i for i in build + (back if all_takes else []) if groups[i][0] not in exclude]
    if not chosen:
        raise InputError(f"Expected takes of the {family} rig left to build from, got none")
    return chosen
