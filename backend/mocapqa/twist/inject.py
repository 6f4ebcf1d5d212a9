"""Synthetic axial twist errors: the paper's injection protocol, seeded and reproducible.

Conventions
-----------
Per take, ``n_targets`` target joints are drawn among the parents of the clavicle, upper arm,
forearm, upper leg and lower leg chains, never two on one limb (one side's arm or leg), so no
two targets lie on one continuous chain. Each target gets 2–5 level-shift intervals of 1–20
frames, separated by at least one clean frame and away from the first and last frames (every
interval has an onset and a release). The offset (uniform magnitude in
``[min_offset_deg, max_offset_deg]``, random sign) is added to the twist of the target's local
rotation, ``qP' = qP ⊗ R(a, δ)`` (equal to ``swing ⊗ (twist ⊗ R(a, δ))``), and the child is
compensated (every direct child X of the target gets ``R(a, −δ) ⊗ qX``) so the world
orientation of everything below it is unchanged.

``kind="burst"`` injects the other real error shape instead (bursts of counter-rotated flips
as described for the retargeted CMU knees): 1–4 *holds*, each held for 1 frame up to 0.05 s
with its own offset of ±20–90° and alternating sign, then a tail of up to 0.1 s that decays
linearly from 10–40 % of the last offset back to the natural level; the child counter-rotates
by (1 + ε) δ with ε uniform in ±0.2 over the burst, since a real retarget rarely does it exactly.

``ends="tail"`` makes each target's last interval end on the take's last frame (an onset with
no release), ``ends="head"`` its first start on the take's first frame of motion (frame 0, or
the first frame after a bind pose: a release with no onset); the other intervals stay between
the two, as above.

``kind="cluster"`` injects *clusters of separate errors*: inside a window of up to 0.6 s, 2–4
pieces, each a single-frame flip (half of them) or a hold of 2 frames up to 0.15 s, with its own
offset of ±20–90° (independent signs) and its own child mismatch ε in ±0.2, separated by 1 frame
up to 0.3 s of natural roll. Each piece starts and ends at the natural level, so each is an
error of its own; what the cluster adds is their crowding (the retargeted CMU knees show such
groups: flips and short holds a few frames to a quarter of a second apart).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import multiply, quats_from_axis_angle
from mocapqa.twist.angles import ChainGeometry, chain_geometry
from mocapqa.twist.detect import leading_pose_frames
from mocapqa.twist.refine import refine_quats

__all__ = [
    "ENDS",
    "KINDS",
    "InjectedInterval",
    "InjectionTruth",
    "add_mismatch",
    "choose_targets",
    "inject_twist_errors",
]

KINDS = ("level", "burst", "cluster")
"""The injected error shapes (``kind`` of :func:`inject_twist_errors`)."""
ENDS = ("", "head", "tail")
"""Where one interval per target is forced (``ends`` of :func:`inject_twist_errors`): nowhere,
starting on the take's first frame of motion, or ending on its last frame."""

TARGET_SEGMENTS = ("clavicle", "upper_arm", "forearm", "upper_leg", "lower_leg")
_LIMB = {"clavicle": "arm", "upper_arm": "arm", "forearm": "arm", "upper_leg": "leg",
         "lower_leg": "leg"}  # fmt: skip


@dataclass(frozen=True, slots=True)
class InjectedInterval:
    """One injected level shift.

    Parameters
    ----------
    joint : str
        Target (parent) joint name.
    side, segment : str
        Side and segment role of the target.
    start_frame, end_frame : int
        First and last corrupted frame (inclusive).
    offset_deg : float
        Twist offset added to the target, degrees.
    """

    joint: str
    side: str
    segment: str
    start_frame: int
    end_frame: int
    offset_deg: float


@dataclass(frozen=True, slots=True)
class InjectionTruth:
    """Ground truth of an injection.

    Parameters
    ----------
    clean_quats : ndarray, shape (F, J, 4)
        Local rotations before injection.
    targets : tuple of int
        Target joint indices.
    children : tuple of int
        The compensated child of each target.
    sides, segments : tuple of str
        Side and segment role of each target.
    intervals : tuple of InjectedInterval
    error_mask : ndarray of bool, shape (F, J)
        True on the corrupted frames of each target joint.
    offsets_rad : ndarray, shape (F, J)
        Offset injected into each target joint per frame, radians (0 elsewhere).
    """

    clean_quats: FloatArray
    targets: tuple[int, ...]
    children: tuple[int, ...]
    sides: tuple[str, ...]
    segments: tuple[str, ...]
    intervals: tuple[InjectedInterval, ...]
    error_mask: BoolArray
    offsets_rad: FloatArray

    @classmethod
    def of_chains(
        cls,
        clean_quats: FloatArray,
        geometries: list[ChainGeometry],
        intervals: list[InjectedInterval],
        chain_offsets: FloatArray,
        chain_mask: BoolArray,
    ) -> InjectionTruth:
        """The truth of an injection into the target chains ``geometries`` (on different
        limbs; their parent joints are the targets): ``chain_offsets`` (F, C), radians, and
        ``chain_mask`` (F, C), the corrupted frames, are each chain's parent's
        ``offsets_rad`` and ``error_mask``; the other arguments as the fields."""
        parents = [g.chain.parent for g in geometries]
        error_mask = np.zeros(clean_quats.shape[:2], dtype=bool)
        error_mask[:, parents] = chain_mask
        offsets_rad = np.zeros(clean_quats.shape[:2])
        offsets_rad[:, parents] = chain_offsets
        return cls(
            clean_quats=clean_quats,
            targets=tuple(parents),
            children=tuple(g.chain.child for g in geometries),
            sides=tuple(g.chain.side for g in geometries),
            segments=tuple(g.chain.segment for g in geometries),
            intervals=tuple(intervals),
            error_mask=error_mask,
            offsets_rad=offsets_rad,
        )


def _place_intervals(
    rng: np.random.Generator, n_frames: int, count: int, max_length: int
) -> list[tuple[int, int]]:
    """Disjoint inclusive intervals inside frames 1 … F−2 with a clean frame between them."""
    usable = n_frames - 2
    count = max(0, min(count, (usable + 1) // 2))
    if count == 0:
        return []
    lengths = rng.integers(1, max_length + 1, size=count)
    while lengths.sum() + count - 1 > usable:
        lengths = np.maximum(1, lengths - 1)
    free = usable - int(lengths.sum()) - (count - 1)
    gaps = rng.multinomial(free, np.full(count + 1, 1.0 / (count + 1)))
    out: list[tuple[int, int]] = []
    start = 1 + int(gaps[0])
    for k in range(count):
        end = start + int(lengths[k]) - 1
        out.append((start, end))
        start = end + 2 + int(gaps[k + 1])
    return out


def _place_with_end(
    rng: np.random.Generator, n_frames: int, count: int, max_length: int, ends: str, first: int
) -> list[tuple[int, int]]:
    """As :func:`_place_intervals`, with one interval ending on frame F − 1 (``ends="tail"``) or
    starting on frame ``first`` (``"head"``) and the others inside, a clean frame apart."""
    if not ends:
        return _place_intervals(rng, n_frames, count, max_length)
    span = n_frames - first
    length = int(rng.integers(1, max_length + 1))
    length = max(1, min(length, (span - 1) // 2))
    inner = _place_intervals(rng, span - length, count - 1, max_length)
    if ends == "tail":
        return [(first + a, first + b) for a, b in inner] + [(n_frames - length, n_frames - 1)]
    return [(first, first + length - 1)] + [(first + length + a, first + length + b)
                                              for a, b in inner]  # fmt: skip


def _burst_parts(
    rng: np.random.Generator, start: int, end: int, hold: int, tail_max: int
) -> list[tuple[int, int, float]]:
    """Holds of alternating ±20–90° offsets, then a decaying tail, inside ``[start, end]``."""
    tail = int(rng.integers(0, min(tail_max, end - start) + 1))
    last = end - tail
    cuts = np.cumsum(rng.integers(1, hold + 1, size=4))
    edges = [start, *(start + int(x) for x in cuts if start + x <= last), last + 1]
    parts: list[tuple[int, int, float]] = []
    sign = float(rng.choice((-1.0, 1.0)))
    for a, b in pairwise(edges):
        if b > a:
            sign = -sign
            parts.append((a, b - 1, float(sign * rng.uniform(20.0, 90.0))))
    if tail:
        residue = parts[-1][2] * rng.uniform(0.1, 0.4)
        for k, value in enumerate(np.linspace(residue, 0.0, tail + 2)[1:-1]):
            parts.append((last + 1 + k, last + 1 + k, float(value)))
    return parts


def _cluster_parts(
    rng: np.random.Generator, start: int, end: int, fps: float
) -> list[tuple[int, int, float]]:
    """Separate flips and short holds of ±20–90° inside ``[start, end]``, 1 frame to 0.3 s
    apart."""
    longest_hold = max(2, round(0.15 * fps))
    widest_gap = max(1, round(0.3 * fps))
    parts: list[tuple[int, int, float]] = []
    first = start
    for _ in range(int(rng.integers(2, 5))):
        if first > end:
            break
        length = 1 if rng.random() < 0.5 else int(rng.integers(2, longest_hold + 1))
        last = min(end, first + length - 1)
        sign = float(rng.choice((-1.0, 1.0)))
        parts.append((first, last, sign * float(rng.uniform(20.0, 90.0))))
        first = last + 1 + int(rng.integers(1, widest_gap + 1))
    return parts


def choose_targets(
    motion: Motion, rng: np.random.Generator, n_targets: int, mapping: dict[str, str] | None
) -> list[ChainGeometry]:
    """Target chains of an injection: ``n_targets`` limbs drawn at random, one chain on each.

    Raises
    ------
    InputError
        If the rig has fewer limbs with twist chains than ``n_targets``.
    """
    skeleton = motion.skeleton
    chains = [c for c in limb_chains(find_roles(skeleton, mapping)) if c.segment in TARGET_SEGMENTS]
    limbs = sorted({(c.side, _LIMB[c.segment]) for c in chains})
    if len(limbs) < n_targets:
        raise InputError(f"Expected at least {n_targets} limbs with twist chains, got {len(limbs)}")
    chosen_limbs = rng.choice(len(limbs), size=n_targets, replace=False)
    geometries: list[ChainGeometry] = []
    for index in sorted(int(i) for i in chosen_limbs):
        options = [c for c in chains if (c.side, _LIMB[c.segment]) == limbs[index]]
        geometries.append(chain_geometry(skeleton, options[int(rng.integers(len(options)))]))
    return geometries


def inject_twist_errors(
    motion: Motion,
    rng: np.random.Generator,
    n_targets: int = 2,
    min_intervals: int = 2,
    max_intervals: int = 5,
    max_interval_frames: int = 20,
    min_offset_deg: float = 5.0,
    max_offset_deg: float = 180.0,
    mapping: dict[str, str] | None = None,
    kind: str = "level",
    ends: str = "",
) -> tuple[Motion, InjectionTruth]:
    """Corrupt a take with level-shift twist errors.

    Parameters
    ----------
    motion : Motion
        The clean take (not modified).
    rng : numpy.random.Generator
        Source of randomness (``np.random.default_rng(seed)``).
    n_targets : int
        Target joints per take (the paper uses 2).
    min_intervals, max_intervals : int
        Level shifts per target (inclusive range).
    max_interval_frames : int
        Longest interval, frames (shortest is 1).
    min_offset_deg, max_offset_deg : float
        Range of the offset magnitude, degrees; the sign is random.
    mapping : dict, optional
        Role key → joint name overrides for :func:`mocapqa.core.rig.find_roles`.
    kind : {"level", "burst", "cluster"}
        The paper's level shifts, bursts of alternating flips, or clusters of separate flips
        and holds (see the module notes; for the last two the interval count is per burst or
        cluster and the offsets and lengths are their own).
    ends : {"", "head", "tail"}
        Force one interval per target to start on the first frame of motion (after a bind
        pose, :func:`mocapqa.twist.detect.leading_pose_frames`) or to end on the last frame
        (level shifts only).

    Returns
    -------
    corrupted : Motion
        The take with errors (translations and layout unchanged).
    truth : InjectionTruth

    Raises
    ------
    InputError
        If the parameters are inconsistent or the rig has too few separate limbs.
    """
    _check_injection(kind, ends, (min_offset_deg, max_offset_deg),
                     (min_intervals, max_intervals, max_interval_frames))  # fmt: skip
    names = motion.skeleton.names
    geometries = choose_targets(motion, rng, n_targets, mapping)
    n_frames = motion.n_frames
    first = leading_pose_frames(motion.quats) if ends == "head" else 0
    chain_offsets = np.zeros((n_frames, len(geometries)))
    intervals: list[InjectedInterval] = []
    mismatch = np.zeros((n_frames, len(geometries)))
    shape = _Shape(kind, motion.fps, (min_offset_deg, max_offset_deg), max_interval_frames)
    for c, geometry in enumerate(geometries):
        count = int(rng.integers(min_intervals, max_intervals + 1))
        parent = geometry.chain.parent
        for start, end in _place_with_end(rng, n_frames, count, shape.longest, ends, first):
            for a, b, value in shape.parts(rng, start, end, mismatch[:, c]):
                chain_offsets[a : b + 1, c] = np.deg2rad(value)
                intervals.append(
                    InjectedInterval(names[parent], geometry.chain.side,
                                     geometry.chain.segment, a, b, value)
                )  # fmt: skip
    # Injecting +δ is refining by −δ.
    corrupted_quats = refine_quats(motion.quats, geometries, -chain_offsets)
    add_mismatch(corrupted_quats, geometries, mismatch, chain_offsets)
    # No part is injected at 0°: the corrupted frames are those with an offset.
    truth = InjectionTruth.of_chains(
        motion.quats.copy(), geometries, intervals, chain_offsets, chain_offsets != 0.0
    )
    return replace(motion, quats=corrupted_quats), truth


@dataclass(frozen=True, slots=True)
class _Shape:
    """The error shape of an injection: its ``kind``, the take's frame rate, the range of a
    level shift's magnitude (degrees) and its longest length (frames)."""

    kind: str
    fps: float
    offsets_deg: tuple[float, float]
    max_interval_frames: int

    @property
    def hold(self) -> int:
        """Longest hold of a burst, frames."""
        return max(1, round(0.05 * self.fps))

    @property
    def tail_max(self) -> int:
        """Longest decaying tail of a burst, frames."""
        return round(0.1 * self.fps)

    @property
    def longest(self) -> int:
        """Longest interval, frames."""
        return {"level": self.max_interval_frames, "burst": 4 * self.hold + self.tail_max,
                "cluster": max(3, round(0.6 * self.fps))}[self.kind]  # fmt: skip

    def parts(
        self, rng: np.random.Generator, start: int, end: int, mismatch: FloatArray
    ) -> list[tuple[int, int, float]]:
        """The parts of the interval ``[start, end]`` (first and last frame, offset in
        degrees), the child's mismatch ratio of bursts and clusters written into the chain's
        ``mismatch`` column (F,)."""
        if self.kind == "burst":
            parts = _burst_parts(rng, start, end, self.hold, self.tail_max)
            mismatch[start : end + 1] = rng.uniform(-0.2, 0.2)
            return parts
        if self.kind == "cluster":
            parts = _cluster_parts(rng, start, end, self.fps)
            for a, b, _ in parts:
                mismatch[a : b + 1] = rng.uniform(-0.2, 0.2)
            return parts
        magnitude = rng.uniform(*self.offsets_deg)
        return [(start, end, float(magnitude * rng.choice((-1.0, 1.0))))]


def _check_injection(
    kind: str, ends: str, offsets_deg: tuple[float, float], counts: tuple[int, int, int]
) -> None:
    """Refuse inconsistent parameters of :func:`inject_twist_errors`: the kind, the ends, the
    offset range (degrees) and the interval counts and longest interval (frames).

    Raises
    ------
    InputError
        If they are inconsistent.
    """
    min_offset_deg, max_offset_deg = offsets_deg
    min_intervals, max_intervals, max_interval_frames = counts
    if kind not in KINDS:
        raise InputError(f"Expected kind 'level', 'burst' or 'cluster', got {kind!r}")
    if ends not in ENDS or (ends and kind != "level"):
        raise InputError(f"Expected ends '', 'head' or 'tail' with kind 'level', got {ends!r}")
    if not (0 < min_offset_deg <= max_offset_deg <= 180.0):
        raise InputError(
            "Expected 0 < min_offset_deg ≤ max_offset_deg ≤ 180, got "
            f"{min_offset_deg}, {max_offset_deg}"
        )
    if not (1 <= min_intervals <= max_intervals) or max_interval_frames < 1:
        raise InputError(
            "Expected 1 ≤ min_intervals ≤ max_intervals and max_interval_frames ≥ 1, got "
            f"{min_intervals}, {max_intervals}, {max_interval_frames}"
        )


def add_mismatch(
    quats: FloatArray,
    geometries: list[ChainGeometry],
    mismatch: FloatArray,
    chain_offsets: FloatArray,
) -> None:
    """Make each chain's first child counter-rotate by (1 + ε) δ where ``mismatch`` (F, C) holds ε
    and ``chain_offsets`` (F, C) δ, radians, as a real retarget rarely does it exactly (its
    world orientation moves by ε δ); ``quats`` (F, J, 4) is changed in place."""
    for c, geometry in enumerate(geometries):
        rows = np.flatnonzero(mismatch[:, c] != 0.0)
        if len(rows):
            first = geometry.intermediates[0] if geometry.intermediates else geometry.chain.child
            extra = quats_from_axis_angle(
                geometry.axis, -mismatch[rows, c] * chain_offsets[rows, c]
            )
            quats[rows, first] = multiply(extra, quats[rows, first])
