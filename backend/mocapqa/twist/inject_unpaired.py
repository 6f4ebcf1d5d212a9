"""Synthetic unpaired bursts after a natural roll step: a real bracket-matching failure.

Conventions
-----------
A real knee of a Character Creator retarget (docs/twist.md, "Why the right knee's 272–301 is
moved") shows a failure the level-shift and burst injections never produce: a *natural*
counter-rotated roll step of 12–14°, taken while both rolls jitter, and 0.5 s later a burst of
counter-rotated flips whose jumps do not cancel by themselves. Bracket matching pairs the
burst's unbalanced part with the natural step and shifts the clean frames between them.
:func:`inject_unpaired_bursts` builds that shape on any take, per target chain (axis ``a``):

*Natural* motion (part of the clean reference, ``truth.clean_quats``):

* **jitter** over ``jitter_s`` = 0.1 s up to and one frame past the step: the parent's roll
  and the child's own roll each get an independent level of ±``jitter_deg`` (2–5°) per frame;
* **the step** at frame ``t0``: the parent's roll rises by ``s`` (8–15°, either sign) and
  stays there; the child counter-rotates by ``−s`` on that frame only and then keeps only
  ``−μ s`` (μ uniform in 0–0.5: the child follows part of the step, as the real foot does);
* **the return** on the first frame after the burst: the parent's roll goes to ``η s``
  (|η| uniform in 0.1–0.4, either sign: near, but not exactly at, the level before the step);
  the child does not counter-rotate it and keeps its ``−μ s`` (the real foot does not
  counter-rotate the burst's net either).

*Error* (``truth.error_mask``, ``truth.offsets_rad``): the **burst**, ``gap_s`` (0.35–0.6 s)
after the step, 1–3 frames of holds of alternating sign, each 25–90°, counter-rotated by the
child by ``(1 + ε)`` with ε uniform in ±0.2 (the child keeps its world orientation up to ε).
Since the return coincides with the burst's release, the parent's jumps in the burst add up to
about ``−s (1 + η)`` and can close with the natural step (when the release, read against the
child's counter-rotation of the last hold alone, still counts as counter-rotated).

The parent's natural roll turns the whole limb below it (no compensation); the child's own
roll is applied to its local rotation in the parent's frame, ``R(a, c) ⊗ qC``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mocapqa.core.arrays import FloatArray, IntArray
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.kinematics.quaternion import multiply, quats_from_axis_angle
from mocapqa.twist.angles import ChainGeometry
from mocapqa.twist.inject import InjectedInterval, InjectionTruth, add_mismatch, choose_targets
from mocapqa.twist.refine import refine_quats

__all__ = ["UnpairedShape", "inject_unpaired_bursts"]


@dataclass(frozen=True, slots=True)
class UnpairedShape:
    """The ranges the shape is drawn from (uniform; see the module notes).

    Parameters
    ----------
    jitter_s : float
        Jitter before the step, seconds.
    jitter_deg : tuple of float
        Range of the jitter amplitude of each roll, degrees.
    step_deg : tuple of float
        Range of the natural step's size, degrees (the sign is random).
    child_follow : tuple of float
        Range of μ, the part of the step the child keeps after its one counter-rotated frame.
    gap_s : tuple of float
        Range of the time from the step to the burst, seconds.
    max_burst_frames : int
        The burst lasts 1 to this many frames.
    flip_deg : tuple of float
        Range of each hold's size, degrees (alternating sign).
    mismatch : float
        The child counter-rotates the burst by (1 + ε), |ε| ≤ this.
    return_fraction : tuple of float
        Range of |η|: after the burst the parent's roll sits at η × the step.
    """

    jitter_s: float = 0.1
    jitter_deg: tuple[float, float] = (2.0, 5.0)
    step_deg: tuple[float, float] = (8.0, 15.0)
    child_follow: tuple[float, float] = (0.0, 0.5)
    gap_s: tuple[float, float] = (0.35, 0.6)
    max_burst_frames: int = 3
    flip_deg: tuple[float, float] = (25.0, 90.0)
    mismatch: float = 0.2
    return_fraction: tuple[float, float] = (0.1, 0.4)

    def __post_init__(self) -> None:
        ranges = {
            "jitter_deg": self.jitter_deg, "step_deg": self.step_deg,
            "child_follow": self.child_follow, "gap_s": self.gap_s,
            "flip_deg": self.flip_deg, "return_fraction": self.return_fraction,
        }  # fmt: skip
        for name, (low, high) in ranges.items():
            if not 0 <= low <= high:
                raise InputError(f"Expected 0 ≤ low ≤ high for {name}, got ({low}, {high})")
        if self.jitter_s <= 0 or self.max_burst_frames < 1 or not 0 <= self.mismatch < 1:
            raise InputError(
                "Expected jitter_s > 0, max_burst_frames ≥ 1 and 0 ≤ mismatch < 1, got "
                f"{self.jitter_s}, {self.max_burst_frames}, {self.mismatch}"
            )
        if self.gap_s[0] <= 0.25:
            raise InputError(
                f"Expected gap_s to start above 0.25 s (the far-frame distance), got {self.gap_s}"
            )


def _first_child(geometry: ChainGeometry) -> int:
    return geometry.intermediates[0] if geometry.intermediates else geometry.chain.child


def inject_unpaired_bursts(
    motion: Motion,
    rng: np.random.Generator,
    n_targets: int = 2,
    mapping: dict[str, str] | None = None,
    shape: UnpairedShape | None = None,
) -> tuple[Motion, InjectionTruth]:
    """A natural roll step and, shortly after, a burst that does not cancel, per target chain.

    Parameters
    ----------
    motion : Motion
        The take (not modified).
    rng : numpy.random.Generator
        Source of randomness.
    n_targets : int
        Target chains, on different limbs (as :func:`mocapqa.twist.inject.inject_twist_errors`).
    mapping : dict, optional
        Role key → joint name overrides.
    shape : UnpairedShape, optional
        The ranges drawn from; defaults when omitted.

    Returns
    -------
    corrupted : Motion
        The take with the natural step and the burst.
    truth : InjectionTruth
        ``clean_quats`` holds the natural step, jitter and return (no error); the burst's
        holds are the intervals, ``error_mask`` and ``offsets_rad``.

    Raises
    ------
    InputError
        If the take is too short for the shape (about 1 s) or has too few limbs.
    """
    shape = shape if shape is not None else UnpairedShape()
    fps = motion.fps
    jitter = max(1, round(shape.jitter_s * fps))
    longest = jitter + round(shape.gap_s[1] * fps) + shape.max_burst_frames + 2
    n_frames = motion.n_frames
    if n_frames < longest + 4:
        raise InputError(f"Expected a take of at least {longest + 4} frames, got {n_frames}")
    geometries = choose_targets(motion, rng, n_targets, mapping)
    parent_roll = np.zeros((n_frames, len(geometries)))
    child_roll = np.zeros((n_frames, len(geometries)))
    offsets = np.zeros((n_frames, len(geometries)))
    mismatch = np.zeros((n_frames, len(geometries)))
    error_mask = np.zeros((n_frames, len(geometries)), dtype=bool)
    intervals: list[InjectedInterval] = []
    for c, geometry in enumerate(geometries):
        burst = _natural_step(rng, shape, fps, jitter, parent_roll[:, c], child_roll[:, c])
        sign = float(rng.choice((-1.0, 1.0)))
        parent = geometry.chain.parent
        for frame in burst:
            sign = -sign
            value = float(sign * rng.uniform(*shape.flip_deg))
            offsets[frame, c] = np.deg2rad(value)
            error_mask[frame, c] = True
            intervals.append(
                InjectedInterval(motion.skeleton.names[parent], geometry.chain.side,
                                 geometry.chain.segment, int(frame), int(frame), value)
            )  # fmt: skip
        mismatch[burst, c] = rng.uniform(-shape.mismatch, shape.mismatch)
    clean = motion.quats.copy()
    for c, geometry in enumerate(geometries):
        parent, first = geometry.chain.parent, _first_child(geometry)
        rows = np.flatnonzero(parent_roll[:, c] != 0.0)
        turn = quats_from_axis_angle(geometry.axis, parent_roll[rows, c])
        clean[rows, parent] = multiply(clean[rows, parent], turn)
        rows = np.flatnonzero(child_roll[:, c] != 0.0)
        turn = quats_from_axis_angle(geometry.axis, child_roll[rows, c])
        clean[rows, first] = multiply(turn, clean[rows, first])
    # Injecting +δ is refining by −δ; then the child's counter-rotation is off by ε δ.
    corrupted = refine_quats(clean, geometries, -offsets)
    add_mismatch(corrupted, geometries, mismatch, offsets)
    truth = InjectionTruth.of_chains(clean, geometries, intervals, offsets, error_mask)
    return replace(motion, quats=corrupted), truth


def _natural_step(
    rng: np.random.Generator,
    shape: UnpairedShape,
    fps: float,
    jitter: int,
    parent_roll: FloatArray,
    child_roll: FloatArray,
) -> IntArray:
    """Draw one chain's natural roll step, with its jitter before it and its partial return
    after the burst, into its ``parent_roll`` and ``child_roll`` columns (F,), radians, and
    return the burst's frames after it."""
    n_frames = len(parent_roll)
    gap = round(rng.uniform(*shape.gap_s) * fps)
    length = int(rng.integers(1, shape.max_burst_frames + 1))
    t0 = int(rng.integers(jitter + 1, n_frames - gap - length - 2))
    burst = np.arange(t0 + gap, t0 + gap + length)
    back = int(burst[-1]) + 1
    step = np.deg2rad(rng.uniform(*shape.step_deg) * rng.choice((-1.0, 1.0)))
    follow = rng.uniform(*shape.child_follow)
    after = step * rng.uniform(*shape.return_fraction) * rng.choice((-1.0, 1.0))
    window = np.arange(t0 - jitter, t0 + 2)
    amplitude = np.deg2rad(rng.uniform(*shape.jitter_deg, size=2))
    parent_roll[window] = rng.uniform(-1.0, 1.0, size=len(window)) * amplitude[0]
    child_roll[window] = rng.uniform(-1.0, 1.0, size=len(window)) * amplitude[1]
    parent_roll[t0:back] += step
    parent_roll[back:] += after
    child_roll[t0] -= step
    child_roll[t0 + 1 :] -= follow * step
    return burst
