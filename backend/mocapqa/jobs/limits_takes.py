"""The takes a limits model is built from, read in one process (``mocapqa limits build``).

The fixed split (:mod:`mocapqa.limits.split`) over a corpus' BVH takes: a canonical model is
built from every take with roles, a per-rig model from the build takes of its rig family.
The Dask build picks the same takes from per-take summaries (:mod:`mocapqa.jobs.limits_build`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from pathlib import Path

from mocapqa.core.motion import Motion
from mocapqa.io.bvh import read_bvh
from mocapqa.limits.rig import rig_fingerprint
from mocapqa.limits.split import (
    check_rig_family,
    corpus_files,
    held_back_names,
    rig_positions,
    split_group,
)

__all__ = ["canonical_takes", "corpus_takes", "rig_takes", "split_takes"]


def corpus_takes(corpus_dir: Path) -> Iterator[tuple[str, Motion]]:
    """File name and motion of every BVH take under ``corpus_dir``, read one at a time in
    :func:`mocapqa.limits.split.corpus_files` order.

    Raises
    ------
    InputError
        If a file cannot be read (naming it).
    """
    for path in corpus_files(corpus_dir):
        yield path.name, read_bvh(path)


def split_takes(
    corpus_dir: Path, families: tuple[str, ...] | None
) -> list[tuple[str, tuple[object, ...], Motion]]:
    """Name, split group and motion of every take of ``families`` (all families but
    "other" when None), in :func:`corpus_takes` order.

    Raises
    ------
    InputError
        As :func:`corpus_takes`.
    """
    read = []
    for name, motion in corpus_takes(corpus_dir):
        key = split_group(motion.skeleton)
        if key is not None and (families is None or key[0] in families):
            read.append((name, key, motion))
    return read


def rig_takes(
    corpus_dir: Path, family: str, all_takes: bool = False,
    exclude: set[str] | frozenset[str] = frozenset(),
) -> tuple[tuple[str, Motion], ...]:  # fmt: skip
    """The takes (names and motions) a per-rig model of ``family`` is built from
    (:func:`mocapqa.limits.split.rig_positions`).

    Raises
    ------
    InputError
        As :func:`mocapqa.limits.split.rig_positions`, or if a file cannot be read (naming it).
    """
    check_rig_family(family)
    read = split_takes(corpus_dir, (family,))
    chosen = rig_positions([(n, key) for n, key, _ in read], family, corpus_dir, all_takes, exclude)
    return tuple((read[i][0], read[i][2]) for i in chosen)


def canonical_takes(
    corpus_dir: Path,
    all_takes: bool = False,
    exclude: set[str] | frozenset[str] = frozenset(),
    mapping: Mapping[str, str] | None = None,
) -> tuple[tuple[str, Motion], ...]:
    """The takes a canonical model is built from: every take with roles, of any rig.

    Takes of a rig family with two or more takes follow the fixed split (only the build
    takes, unless ``all_takes``); single takes of other rigs are all used. Names in
    ``exclude`` are left out. ``mapping`` gives roles to the takes whose skeleton has the
    joints it names (:func:`mocapqa.core.rig.mapped_roles`).
    """
    read = list(corpus_takes(corpus_dir))
    held = set() if all_takes else held_back_names([(n, split_group(m.skeleton)) for n, m in read])
    return tuple(
        (n, m) for n, m in read
        if rig_fingerprint(m.skeleton, mapping) and n not in held and n not in exclude
    )  # fmt: skip
