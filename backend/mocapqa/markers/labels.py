"""Label and presence checks: unlabelled and duplicate labels, static and absent markers.

* **Unlabelled**: an empty label, or one a capture system gives a trajectory it could not name
  (:data:`AUTO_LABEL`: ``*12`` in Vicon, ``C_1`` in Cortex, ``Unlabeled 1000`` in Motive,
  ``New 0001`` in QTM, bare numbers).
* **Duplicate**: the same label on two or more trajectories once the subject prefix
  (everything up to the last ``:``, as in ``TakeoMonday:RBWT``), surrounding spaces and the
  ``#<n>`` a reader appends to a repeated label (:func:`mocapqa.io.c3d.read_c3d`) are removed;
  compared case-sensitively. Two trajectories of different subjects (``A:LANK``, ``B:LANK``)
  are two performers' markers, not a duplicate; one with a prefix and one without are.
* **Static**: a marker whose positions vary by less than ``static_std`` (root of the summed
  per-axis variances over its visible frames) while the take's median marker varies by more
  than ``moving_std``: a marker left on the floor or a reflection, not on the performer.
* **Absent**: a marker missing in every frame.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.markers.params import MarkerParams, unit_scale

__all__ = [
    "AUTO_LABEL",
    "LabelFinding",
    "StaticMarker",
    "base_label",
    "find_label_problems",
    "find_static",
    "subject",
]

AUTO_LABEL = re.compile(
    r"^(\*\s*\d+|C_\d+|unlabell?ed[\s_-]*\d*|new[\s_-]*\d+|\d+)$", flags=re.IGNORECASE
)
"""Labels capture systems give trajectories they could not name."""


@dataclass(frozen=True, slots=True)
class LabelFinding:
    """An unlabelled or duplicate-labelled trajectory.

    Parameters
    ----------
    kind : {"unlabelled", "duplicate"}
    label : str
        The label without its subject prefix (``""`` for an empty label).
    markers : tuple of int
        Indices of the trajectories concerned (all those sharing the label, for a duplicate).
    names : tuple of str
        Their full labels as the file writes them.
    severity : {"warning", "error"}
        Duplicates are errors (a reader or a solver picks one of them); unlabelled
        trajectories are warnings.
    """

    kind: str
    label: str
    markers: tuple[int, ...]
    names: tuple[str, ...]
    severity: str


@dataclass(frozen=True, slots=True)
class StaticMarker:
    """A marker that never moves, or is never seen.

    Parameters
    ----------
    marker : str
    kind : {"static", "absent"}
    std : float or None
        Root of the summed per-axis variances, take units (None when absent).
    severity : {"warning"}
    """

    marker: str
    kind: str
    std: float | None
    severity: str = "warning"


_REPEAT = re.compile(r"#\d+$")


def subject(name: str) -> str:
    """The subject prefix of a label (``"Bob:LANK"`` → ``"Bob"``; ``""`` without one)."""
    return name.rsplit(":", 1)[0].strip() if ":" in name else ""


def base_label(name: str) -> str:
    """The label without its subject prefix, surrounding spaces and a reader's ``#<n>``
    repeat suffix (``"Bob:LANK#2"`` → ``"LANK"``)."""
    return _REPEAT.sub("", name.rsplit(":", 1)[-1].strip()).strip()


def find_label_problems(names: Sequence[str]) -> list[LabelFinding]:
    """Unlabelled and duplicate-labelled trajectories.

    Parameters
    ----------
    names : sequence of str
        The M labels as the file writes them.

    Returns
    -------
    list of LabelFinding
        Unlabelled ones first (in marker order), then duplicates (by first marker).
    """
    bases = [base_label(n) for n in names]
    found = [
        LabelFinding("unlabelled", b, (i,), (names[i],), "warning")
        for i, b in enumerate(bases)
        if not b or AUTO_LABEL.match(b)
    ]
    groups: dict[str, list[int]] = {}
    for i, b in enumerate(bases):
        if b and not AUTO_LABEL.match(b):
            groups.setdefault(b, []).append(i)
    for b, ix in groups.items():
        subjects = [subject(names[i]) for i in ix]
        named = {s for s in subjects if s}
        # Duplicates: within one subject, or against a trajectory without a subject.
        dup = [i for i, s in zip(ix, subjects, strict=True)
               if not s or len(named) <= 1 or subjects.count(s) > 1]  # fmt: skip
        if len(dup) > 1:
            found.append(
                LabelFinding("duplicate", b, tuple(dup), tuple(names[i] for i in dup), "error")
            )
    return found


def find_static(
    positions: FloatArray,
    present: BoolArray,
    names: Sequence[str],
    length_unit: str,
    params: MarkerParams | None = None,
) -> list[StaticMarker]:
    """Markers that never move while the others do, and markers never seen.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Take units, NaN where missing.
    present : ndarray of bool, shape (F, M)
    names : sequence of str
    length_unit : str
    params : MarkerParams, optional

    Returns
    -------
    list of StaticMarker
        In marker order.
    """
    p = params or MarkerParams()
    scale = unit_scale(length_unit)
    counts = present.sum(axis=0)
    seen = counts > 0
    filled = np.where(present[..., None], positions, 0.0)
    mean = filled.sum(axis=0) / np.maximum(counts, 1)[:, None]
    deviations = np.where(present[..., None], positions - mean, 0.0)
    std = np.sqrt(np.einsum("fmk,fmk->m", deviations, deviations) / np.maximum(counts, 1))
    moving = bool(seen.any()) and float(np.median(std[seen])) > p.moving_std * scale
    found: list[StaticMarker] = []
    for m, name in enumerate(names):
        if not seen[m]:
            found.append(StaticMarker(name, "absent", None))
        elif moving and counts[m] > 1 and std[m] < p.static_std * scale:
            found.append(StaticMarker(name, "static", float(std[m])))
    return found
