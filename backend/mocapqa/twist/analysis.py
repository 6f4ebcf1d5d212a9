"""Twist analysis of a whole take: chains, detection, refinement and plot-ready time series.

This is the entry point for the pipeline and the dashboard: :func:`analyze_twist` finds the
rig's limb chains, detects level-shift twist errors with the chosen method and returns the
refined take with the intervals found. :meth:`TwistAnalysis.to_json` gives the per-chain time
series (θP, offset, flagged frames) in the shape documented in ``docs/twist.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Literal, get_args

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.kinematics.euler import euler_from_quats
from mocapqa.twist.angles import (
    ChainGeometry,
    chain_geometry,
    child_azimuth_increments,
    child_increment_twists,
    child_relative_quats,
    parent_increment_twists,
    parent_twist_angles,
    wrap_angle,
)
from mocapqa.twist.choice import TwistInterval, choose_intervals, parse_apply
from mocapqa.twist.detect import (
    DetectedInterval,
    Detection,
    PaperParams,
    RobustParams,
    detect_paper,
    detect_robust,
)
from mocapqa.twist.refine import refine_quats

__all__ = [
    "METHODS",
    "Method",
    "TwistAnalysis",
    "TwistInterval",
    "analyze_twist",
    "detect_chains",
    "parse_apply",
]

Method = Literal["robust", "paper"]
"""A detection method: the robust default, or the paper as written."""
METHODS: tuple[Method, ...] = get_args(Method)
"""The detection methods, the default first."""


@dataclass(frozen=True, slots=True)
class TwistAnalysis:
    """Result of :func:`analyze_twist`.

    Parameters
    ----------
    method : str
        "robust" or "paper".
    refined : Motion
        The take with the detected offsets removed.
    intervals : tuple of TwistInterval
        Every interval found, ordered by chain then frame.
    chains : tuple of ChainGeometry
        The chains checked (parent, child, grandchild, axis).
    joint_names : tuple of str
        The skeleton's joint names (to name chain joints).
    fps : float
        Frame rate of the take.
    parent_twist_rad : ndarray, shape (F, C)
        θP per chain (swing–twist angle of the parent about the axis), radians.
    offsets_rad : ndarray, shape (F, C)
        Offset removed per chain and frame, radians (the applied intervals only).
    detected_offsets_rad : ndarray, shape (F, C)
        Offset of every interval found, applied or not, radians.
    apply : str
        The apply choice: one of :data:`mocapqa.twist.choice.APPLY_CHOICES` or ``"ids"``.
    found : tuple of DetectedInterval
        The detector's intervals (chain index, confidence features), in ``intervals`` order.
    """

    method: str
    refined: Motion
    intervals: tuple[TwistInterval, ...]
    chains: tuple[ChainGeometry, ...]
    joint_names: tuple[str, ...]
    fps: float
    parent_twist_rad: FloatArray
    offsets_rad: FloatArray
    detected_offsets_rad: FloatArray
    apply: str = "confident"
    found: tuple[DetectedInterval, ...] = ()

    def summaries(self) -> list[dict[str, Any]]:
        """Per chain: joint, side, segment, interval count, flagged frames, largest offset."""
        out = []
        for c, geometry in enumerate(self.chains):
            joint = self.joint_names[geometry.chain.parent]
            mine = [i for i in self.intervals if i.joint == joint]
            offsets_deg = np.rad2deg(np.abs(wrap_angle(self.offsets_rad[:, c])))
            out.append(
                {
                    "joint": joint,
                    "child": self.joint_names[geometry.chain.child],
                    "side": geometry.chain.side,
                    "segment": geometry.chain.segment,
                    "n_intervals": len(mine),
                    "n_applied": sum(i.applied for i in mine),
                    "n_frames_flagged": int(sum(i.end_frame - i.start_frame + 1 for i in mine)),
                    "max_abs_offset_deg": round(float(offsets_deg.max(initial=0.0)), 4),
                }
            )
        return out

    def to_json(self, max_points: int | None = None) -> dict[str, Any]:
        """Plot-ready time series per chain (shape documented in ``docs/twist.md``).

        Parameters
        ----------
        max_points : int, optional
            Longest series returned. Longer takes are decimated in blocks of ``frame_step``
            frames: θP takes the block's first value, the offset the value of largest magnitude
            in the block and ``flagged`` whether any frame of the block is flagged, so that
            one-frame intervals stay visible.

        Returns
        -------
        dict
        """
        n_frames = self.offsets_rad.shape[0]
        step = 1
        if max_points is not None:
            if max_points < 1:
                raise InputError(f"Expected max_points ≥ 1, got {max_points}")
            step = max(1, math.ceil(n_frames / max_points))
        frames = np.arange(0, n_frames, step)
        pad = (-n_frames) % step
        chains_json = []
        flagged_all = np.zeros((n_frames, len(self.chains)), dtype=bool)
        for interval in self.intervals:
            c = next(
                k for k, g in enumerate(self.chains)
                if self.joint_names[g.chain.parent] == interval.joint
            )  # fmt: skip
            flagged_all[interval.start_frame : interval.end_frame + 1, c] = True
        for c, geometry in enumerate(self.chains):
            offsets = np.rad2deg(wrap_angle(self.offsets_rad[:, c]))
            blocks = np.pad(offsets, (0, pad)).reshape(-1, step)
            picked = blocks[np.arange(len(blocks)), np.argmax(np.abs(blocks), axis=1)]
            flags = np.pad(flagged_all[:, c], (0, pad)).reshape(-1, step).any(axis=1)
            theta = np.rad2deg(self.parent_twist_rad[frames, c])
            joint = self.joint_names[geometry.chain.parent]
            grand = geometry.chain.grandchild
            chains_json.append(
                {
                    "joint": joint,
                    "child": self.joint_names[geometry.chain.child],
                    "grandchild": None if grand is None else self.joint_names[grand],
                    "side": geometry.chain.side,
                    "segment": geometry.chain.segment,
                    "axis": [round(float(v), 6) for v in geometry.axis],
                    "theta_p_deg": np.round(theta, 3).tolist(),
                    "offset_deg": np.round(picked, 3).tolist(),
                    "flagged": flags.astype(int).tolist(),
                    "intervals": [i.to_json() for i in self.intervals if i.joint == joint],
                }
            )
        return {
            "method": self.method,
            "apply": self.apply,
            "fps": self.fps,
            "n_frames": n_frames,
            "frame_step": step,
            "frames": frames.tolist(),
            "chains": chains_json,
            "intervals": [i.to_json() for i in self.intervals],
            "summaries": self.summaries(),
        }


def detect_chains(
    quats: FloatArray,
    geometries: tuple[ChainGeometry, ...],
    fps: float,
    method: str = "robust",
    params: RobustParams | PaperParams | None = None,
) -> Detection:
    """Twist increments and detection for a set of chains.

    Parameters
    ----------
    quats : ndarray, shape (F, J, 4)
        Local rotations.
    geometries : tuple of ChainGeometry, length C
    fps : float
        Frames per second.
    method : {"robust", "paper"}
    params : RobustParams or PaperParams, optional
        Defaults of the method when omitted.

    Returns
    -------
    Detection
        Arrays of shape (F, C).

    Raises
    ------
    InputError
        For an unknown method or parameters of the other method.
    """
    if method not in METHODS:
        raise InputError(f"Expected method in {METHODS}, got {method!r}")
    n_frames = quats.shape[0]
    if not geometries:
        empty = np.zeros((n_frames, 0))
        return Detection(empty, empty, empty.astype(bool), empty, ())
    axes = np.stack([g.axis for g in geometries])
    grand = np.stack([g.grandchild_vector for g in geometries])
    parent_quats = quats[:, [g.chain.parent for g in geometries]]
    child_quats = np.stack([child_relative_quats(quats, g) for g in geometries], axis=1)
    if method == "paper":
        paper = params if params is not None else PaperParams()
        if not isinstance(paper, PaperParams):
            raise InputError(f"Expected PaperParams for method 'paper', got {type(paper).__name__}")
        theta = parent_twist_angles(parent_quats, axes)
        dp = np.zeros_like(theta)
        dp[1:] = wrap_angle(np.diff(theta, axis=0))
        dc, _ = child_azimuth_increments(child_quats, axes, grand)
        return detect_paper(dp, dc, paper)
    robust = params if params is not None else RobustParams()
    if not isinstance(robust, RobustParams):
        raise InputError(f"Expected RobustParams for method 'robust', got {type(robust).__name__}")
    if robust.parent_source == "increment":
        dp = parent_increment_twists(parent_quats, axes)
    else:
        theta = parent_twist_angles(parent_quats, axes)
        dp = np.zeros_like(theta)
        dp[1:] = wrap_angle(np.diff(theta, axis=0))
    if robust.child_source == "increment":
        dc = child_increment_twists(child_quats, axes)
    else:
        azimuth, conditioning = child_azimuth_increments(child_quats, axes, grand)
        if robust.child_source == "azimuth":
            dc = azimuth
        else:
            good = np.minimum(conditioning, np.roll(conditioning, 1, axis=0))
            has_grandchild = np.array([g.chain.grandchild is not None for g in geometries])
            good = np.where(has_grandchild[None], good, 0.0)
            dc = np.where(
                good >= robust.min_conditioning, azimuth, child_increment_twists(child_quats, axes)
            )
    return detect_robust(dp, dc, fps, robust)


def _refined_hint(
    motion: Motion, refined_quats: FloatArray, changed: BoolArray
) -> FloatArray | None:
    """Euler hints for writing: unchanged cells keep the read angles, changed ones follow them.

    Without read angles there is no hint: the writer then makes every joint continuous itself.
    """
    read_hint = motion.euler_hint_deg
    if read_hint is None:
        return None
    hint = read_hint.copy()
    frames = np.arange(motion.n_frames)
    for j in np.flatnonzero(changed.any(axis=0)):
        rows = changed[:, j]
        keep = ~rows
        if not keep.any():
            continue
        for k in range(3):
            hint[rows, j, k] = np.interp(frames[rows], frames[keep], hint[keep, j, k])
        order = motion.skeleton.rotation_order(int(j))
        if order:
            angles = euler_from_quats(refined_quats[rows, j], order, np.deg2rad(hint[rows, j]))
            hint[rows, j] = np.rad2deg(angles)
    return hint


def analyze_twist(
    motion: Motion,
    method: str = "robust",
    mapping: dict[str, str] | None = None,
    params: RobustParams | PaperParams | None = None,
    apply: str | frozenset[int] = "confident",
) -> TwistAnalysis:
    """Detect axial twist errors in a take and remove those chosen by ``apply``.

    Parameters
    ----------
    motion : Motion
        The take (not modified).
    method : {"robust", "paper"}
        The robust detector (default) or the paper's rule as written.
    mapping : dict, optional
        Role key → joint name overrides (see :func:`mocapqa.core.rig.find_roles`).
    params : RobustParams or PaperParams, optional
        Detector parameters; the method's defaults when omitted.
    apply : str or frozenset of int
        ``"confident"`` (default: intervals whose calibrated probability is at least
        :data:`mocapqa.twist.confidence.APPLY_THRESHOLD`), ``"all"``, ``"none"``, or interval
        ids (a set, or text such as ``"0,3"``). The paper's method has no calibrated
        confidence: ``"confident"`` applies all its intervals.

    Returns
    -------
    TwistAnalysis
        Every interval found, each marked applied or not.

    Raises
    ------
    InputError
        For an unknown method or apply choice, wrong parameters, a bad mapping or an interval
        id the take does not have.
    """
    choice = parse_apply(apply)
    skeleton = motion.skeleton
    geometries = tuple(
        chain_geometry(skeleton, c) for c in limb_chains(find_roles(skeleton, mapping))
    )
    detection = detect_chains(motion.quats, geometries, motion.fps, method, params)
    n_frames = motion.n_frames
    detected = detection.offsets.reshape(n_frames, len(geometries))
    found = sorted(detection.intervals, key=lambda i: (i.chain, i.start_frame))
    offsets, intervals = choose_intervals(
        found, detected, geometries, skeleton.names, choice, method == "robust"
    )
    refined_quats = refine_quats(motion.quats, geometries, offsets)
    changed = np.any(refined_quats != motion.quats, axis=-1)
    if changed.any():
        refined = replace(
            motion,
            quats=refined_quats,
            euler_hint_deg=_refined_hint(motion, refined_quats, changed),
        )
    else:
        refined = motion
    if geometries:
        axes = np.stack([g.axis for g in geometries])
        theta = parent_twist_angles(motion.quats[:, [g.chain.parent for g in geometries]], axes)
    else:
        theta = np.zeros((n_frames, 0))
    return TwistAnalysis(
        method=method,
        refined=refined,
        intervals=tuple(intervals),
        chains=geometries,
        joint_names=skeleton.names,
        fps=motion.fps,
        parent_twist_rad=theta,
        offsets_rad=offsets,
        detected_offsets_rad=detected,
        apply="ids" if isinstance(choice, frozenset) else choice,
        found=tuple(found),
    )
