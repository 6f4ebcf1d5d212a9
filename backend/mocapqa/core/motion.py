"""Skeletons and motions: the in-memory form of a BVH take.

Conventions
-----------
* Joints are stored in file (depth-first) order, so ``parents[j] < j`` and a root has parent -1.
* Local rotations are unit quaternions ``(F, J, 4)``, scalar-last ``(x, y, z, w)``, active,
  parent-from-child: ``world[j] = world[parent[j]] ⊗ local[j]``.
* ``translations`` holds the values of each joint's position channels ``(F, J, 3)`` in file
  units (zero where a joint has none). Forward kinematics uses them in place of the OFFSET
  (BVH's rule) or, for rigs that store the root as a delta from its rest OFFSET (Character
  Creator exports), added to it: :attr:`Skeleton.root_translation` records which.
* Lengths stay in file units; :attr:`Skeleton.length_unit` records them when known.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray, as_float_array, check_shape
from mocapqa.errors import ShapeError

__all__ = ["POSITION_CHANNELS", "ROTATION_CHANNELS", "EndSite", "Motion", "Skeleton"]

POSITION_CHANNELS = ("Xposition", "Yposition", "Zposition")
"""BVH position channel names, in x, y, z order."""
ROTATION_CHANNELS = ("Xrotation", "Yrotation", "Zrotation")
"""BVH rotation channel names, in x, y, z order."""

RootTranslation = Literal["replace", "add"]


@dataclass(frozen=True, slots=True)
class EndSite:
    """A BVH ``End Site``: a leaf offset below joint ``parent``.

    Parameters
    ----------
    parent : int
        Index of the joint the End Site belongs to.
    offset : tuple of float
        Offset from the parent in the parent's frame, file units.
    """

    parent: int
    offset: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Skeleton:
    """The hierarchy, rest offsets and channel layout of a take.

    Parameters
    ----------
    names : tuple of str
        Joint names, unique, in depth-first file order.
    parents : ndarray, shape (J,)
        Parent index per joint, -1 for a root.
    offsets : ndarray, shape (J, 3)
        OFFSET of each joint from its parent, in the parent's frame, file units.
    channels : tuple of tuple of str
        Each joint's channel names in file order (e.g. ``("Zrotation", "Yrotation", "Xrotation")``).
    end_sites : tuple of EndSite
        The End Sites in file order.
    length_unit : str
        Unit of the offsets and translations ("cm", "m", "in", or "unknown").
    root_translation : {"replace", "add"}
        Whether root position channels replace the root OFFSET or are added to it.
    """

    names: tuple[str, ...]
    parents: IntArray
    offsets: FloatArray
    channels: tuple[tuple[str, ...], ...]
    end_sites: tuple[EndSite, ...] = ()
    length_unit: str = "unknown"
    root_translation: RootTranslation = "replace"
    _index: dict[str, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = len(self.names)
        parents = np.asarray(self.parents, dtype=np.intp)
        check_shape(parents, "parents", (n,))
        offsets = as_float_array(self.offsets, "offsets", (n, 3))
        if len(self.channels) != n:
            raise ShapeError(f"Expected {n} channel lists, got {len(self.channels)}")
        if len(set(self.names)) != n:
            raise ShapeError("Expected unique joint names, got duplicates")
        if n and np.any(parents >= np.arange(n)):
            raise ShapeError("Expected every parent to precede its child (depth-first order)")
        for j, chans in enumerate(self.channels):
            rot = [c for c in chans if c in ROTATION_CHANNELS]
            pos = [c for c in chans if c in POSITION_CHANNELS]
            if len(rot) not in (0, 3) or len(set(rot)) != len(rot) or len(set(pos)) != len(pos):
                raise ShapeError(
                    f"Expected joint {self.names[j]!r} to have 0 or 3 distinct rotation "
                    f"channels, got {chans}"
                )
            if len(rot) + len(pos) != len(chans):
                raise ShapeError(f"Expected known channel names on {self.names[j]!r}, got {chans}")
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "_index", {name: i for i, name in enumerate(self.names)})

    @property
    def n_joints(self) -> int:
        """Number of joints (End Sites not counted)."""
        return len(self.names)

    def index(self, name: str) -> int:
        """Return the index of joint ``name``.

        Raises
        ------
        KeyError
            If no joint has that name.
        """
        return self._index[name]

    def children(self, joint: int) -> list[int]:
        """Indices of the direct child joints of ``joint``."""
        return [int(c) for c in np.flatnonzero(self.parents == joint)]

    def rotation_order(self, joint: int) -> str:
        """Rotation axes of ``joint`` in channel order, e.g. ``"ZYX"`` ('' if none)."""
        return "".join(c[0] for c in self.channels[joint] if c in ROTATION_CHANNELS)

    def has_position_channels(self, joint: int) -> bool:
        """Whether ``joint`` has any position channel."""
        return any(c in POSITION_CHANNELS for c in self.channels[joint])

    def end_site_offsets(self, joint: int) -> list[tuple[float, float, float]]:
        """Offsets of the End Sites attached to ``joint``."""
        return [e.offset for e in self.end_sites if e.parent == joint]

    @property
    def depths(self) -> IntArray:
        """Tree depth per joint, shape (J,); roots are 0."""
        depth = np.zeros(self.n_joints, dtype=np.intp)
        for j, p in enumerate(self.parents):
            if p >= 0:
                depth[j] = depth[p] + 1
        return depth


@dataclass(frozen=True, slots=True)
class Motion:
    """An animated take: a skeleton plus per-frame local rotations and translations.

    Parameters
    ----------
    skeleton : Skeleton
        Hierarchy and channel layout.
    quats : ndarray, shape (F, J, 4)
        Local unit quaternions, scalar-last.
    translations : ndarray, shape (F, J, 3)
        Position-channel values per joint, file units (zeros where a joint has none).
    fps : float
        Frames per second (> 0).
    euler_hint_deg : ndarray, shape (F, J, 3), optional
        Euler angles the take was read with, in each joint's channel order. Only used to choose
        among equivalent Euler triples (2π shifts and the second solution) when writing, so that
        an unchanged take writes back its own numbers.
    """

    skeleton: Skeleton
    quats: FloatArray
    translations: FloatArray
    fps: float
    euler_hint_deg: FloatArray | None = None

    def __post_init__(self) -> None:
        j = self.skeleton.n_joints
        quats = as_float_array(self.quats, "quats", ("F", j, 4))
        n = quats.shape[0]
        translations = as_float_array(self.translations, "translations", (n, j, 3))
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise ShapeError(f"Expected `fps` > 0, got {self.fps}")
        norms = np.linalg.norm(quats, axis=-1)
        if n and not np.allclose(norms, 1.0, atol=1e-6):
            raise ShapeError("Expected `quats` to be unit quaternions, got norms away from 1")
        if self.euler_hint_deg is not None:
            hint = as_float_array(self.euler_hint_deg, "euler_hint_deg", (n, j, 3))
            object.__setattr__(self, "euler_hint_deg", hint)
        object.__setattr__(self, "quats", quats)
        object.__setattr__(self, "translations", translations)
        object.__setattr__(self, "fps", float(self.fps))

    @classmethod
    def _from_valid_arrays(
        cls,
        skeleton: Skeleton,
        quats: FloatArray,
        translations: FloatArray,
        fps: float,
        euler_hint_deg: FloatArray | None,
    ) -> Motion:
        """Build a motion without :meth:`__post_init__`'s conversions and checks.

        For readers that built the arrays themselves: float64, finite, shaped
        ``(F, J, 4)``, ``(F, J, 3)`` and ``(F, J, 3)`` for ``skeleton``, unit quaternions
        (e.g. from sines and cosines of finite angles), ``fps`` a finite float > 0. The
        arrays are kept, not copied, so the caller must not keep a reference it mutates.
        Any other caller uses the checked constructor.
        """
        motion = object.__new__(cls)
        object.__setattr__(motion, "skeleton", skeleton)
        object.__setattr__(motion, "quats", quats)
        object.__setattr__(motion, "translations", translations)
        object.__setattr__(motion, "fps", float(fps))
        object.__setattr__(motion, "euler_hint_deg", euler_hint_deg)
        return motion

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.quats.shape[0])

    @property
    def frame_time_s(self) -> float:
        """Seconds per frame."""
        return 1.0 / self.fps

    @property
    def duration_s(self) -> float:
        """Duration in seconds (frames × frame time)."""
        return self.n_frames / self.fps

    def translation_channels(self) -> list[tuple[int, int, bool]]:
        """Where the position channels go in the local translations.

        Returns
        -------
        list of (joint, axis, add)
            One entry per position channel: the joint, the axis (0, 1, 2 for X, Y, Z) and
            whether the value adds to the OFFSET (a root with ``root_translation == "add"``)
            rather than replacing it.
        """
        sk = self.skeleton
        return [
            (j, axis, bool(sk.parents[j] < 0 and sk.root_translation == "add"))
            for j in range(sk.n_joints)
            for axis, name in enumerate("XYZ")
            if f"{name}position" in sk.channels[j]
        ]

    def local_translations(self) -> FloatArray:
        """Translation of each joint from its parent, per frame, shape (F, J, 3), file units.

        The OFFSET, replaced by the position channels where a joint has them (or, for a root
        with ``root_translation == "add"``, the OFFSET plus the channels).
        """
        out = np.broadcast_to(self.skeleton.offsets, self.translations.shape).copy()
        for j, axis, add in self.translation_channels():
            if add:
                out[:, j, axis] += self.translations[:, j, axis]
            else:
                out[:, j, axis] = self.translations[:, j, axis]
        return out
