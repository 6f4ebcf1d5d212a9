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
compensated with ``qC' = M⁻¹ ⊗ R(a, −δ) ⊗ M ⊗ qC`` so its global orientation is unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.twist.angles import ChainGeometry, chain_geometry
from mocapqa.twist.refine import refine_quats

__all__ = ["InjectedInterval", "InjectionTruth", "inject_twist_errors"]

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
    n_frames, n_joints = motion.quats.shape[:2]
    chain_offsets = np.zeros((n_frames, len(geometries)))
    error_mask = np.zeros((n_frames, n_joints), dtype=bool)
    offsets_rad = np.zeros((n_frames, n_joints))
    intervals: list[InjectedInterval] = []
    for c, geometry in enumerate(geometries):
        count = int(rng.integers(min_intervals, max_intervals + 1))
        for start, end in _place_intervals(rng, n_frames, count, max_interval_frames):
            magnitude = rng.uniform(min_offset_deg, max_offset_deg)
            offset_deg = float(magnitude * rng.choice((-1.0, 1.0)))
            chain_offsets[start : end + 1, c] = np.deg2rad(offset_deg)
            parent = geometry.chain.parent
            error_mask[start : end + 1, parent] = True
            offsets_rad[start : end + 1, parent] = np.deg2rad(offset_deg)
            intervals.append(
                InjectedInterval(
                    skeleton.names[parent],
                    geometry.chain.side,
                    geometry.chain.segment,
                    start,
                    end,
                    offset_deg,
                )
            )
    # Injecting +δ is refining by −δ.
    corrupted_quats = refine_quats(motion.quats, geometries, -chain_offsets)
    truth = InjectionTruth(
        clean_quats=motion.quats.copy(),
        targets=tuple(g.chain.parent for g in geometries),
        children=tuple(g.chain.child for g in geometries),
        sides=tuple(g.chain.side for g in geometries),
        segments=tuple(g.chain.segment for g in geometries),
        intervals=tuple(intervals),
        error_mask=error_mask,
        offsets_rad=offsets_rad,
    )
    return replace(motion, quats=corrupted_quats), truth
