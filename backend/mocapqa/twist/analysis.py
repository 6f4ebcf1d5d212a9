"""Twist analysis of a whole take: chains, detection, refinement and plot-ready time series.

This is the entry point for the pipeline and the dashboard: :func:`analyze_twist` finds the
rig's limb chains, detects level-shift twist errors with the chosen method and returns the
refined take with the intervals found. :meth:`TwistAnalysis.to_json` gives the per-chain time
series (θP, offset, flagged frames) in the shape documented in ``docs/twist.md``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any, Literal, get_args

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, IntArray
from mocapqa.core.decimate import peak_frames
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles, limb_chains
from mocapqa.errors import InputError
from mocapqa.kinematics.euler import euler_from_quats
from mocapqa.limits.rig import rig_family
from mocapqa.twist.anatomy import anatomy_evidence
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
    leading_pose_frames,
    shift_detection,
)
from mocapqa.twist.natural_roll import NaturalRoll, default_natural_roll
from mocapqa.twist.refine import refine_quats
from mocapqa.twist.reviewer_prior import ReviewerPrior

__all__ = [
    "METHODS",
    "Method",
    "TwistAnalysis",
    "TwistInterval",
    "analyze_twist",
    "detect_chains",
    "interval_frames",
    "parse_apply",
    "refined_hint",
]

Method = Literal["robust", "paper"]
"""A detection method: the robust default, or the paper as written."""
METHODS: tuple[Method, ...] = get_args(Method)
"""The detection methods, the default first."""


def interval_frames(
    joint_names: Sequence[str], n_frames: int, intervals: Iterable[tuple[str, int, int]]
) -> BoolArray:
    """Frames of each joint inside a twist interval, shape (F, J).

    Parameters
    ----------
    joint_names : sequence of str
        The take's joints, in skeleton order.
    n_frames : int
    intervals : iterable of (str, int, int)
        Joint name, first and last frame (inclusive) of each interval; unknown joints are
        skipped.
    """
    index = {name: j for j, name in enumerate(joint_names)}
    mask = np.zeros((n_frames, len(joint_names)), dtype=bool)
    for joint, start, end in intervals:
        if joint in index:
            mask[max(start, 0) : end + 1, index[joint]] = True
    return mask


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

    def interval_frames(self) -> BoolArray:
        """Frames inside an interval found (applied or not), per joint: shape (F, J), True on
        the frames of each interval's joint (its chain's parent)."""
        return interval_frames(
            self.joint_names,
            self.refined.n_frames,
            [(i.joint, i.start_frame, i.end_frame) for i in self.intervals],
        )

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

    def plotted_deg(self) -> FloatArray:
        """The plotted series on every frame: θP per chain, then the removed offset per chain.

        Returns
        -------
        ndarray, shape (F, 2 C)
            Degrees; θP in (−180, 180], the offset wrapped to (−180, 180].
        """
        theta = np.rad2deg(self.parent_twist_rad)
        offsets = np.rad2deg(wrap_angle(self.offsets_rad))
        return np.concatenate([theta, offsets], axis=1)

    def step_frames(self) -> IntArray:
        """Where the intervals found start and where their offset steps, most important first.

        The detected offset (applied or not) steps where θP jumps: on each level's first frame
        and on the frame after each interval. A plot that keeps these frames shows every
        interval's first frame and every jump at its frame.

        Returns
        -------
        ndarray of int, shape (K,)
            Each interval's first frame, in order, then the other frames where the offset of
            some chain steps, by decreasing step (the largest over the chains); inside the take.
        """
        offsets = self.detected_offsets_rad
        change = np.abs(wrap_angle(np.diff(offsets, axis=0, prepend=0.0)))
        size = change.max(axis=1, initial=0.0)
        steps = np.flatnonzero(size > 1e-9)
        steps = steps[np.argsort(-size[steps], kind="stable")]
        starts = np.asarray([i.start_frame for i in self.intervals], dtype=np.intp)
        frames: IntArray = np.concatenate([starts, steps[~np.isin(steps, starts)]])
        return frames.astype(np.intp)

    def to_json(
        self, max_points: int | None = None, frames: IntArray | None = None
    ) -> dict[str, Any]:
        """Plot-ready time series per chain (shape documented in ``docs/twist.md``).

        Parameters
        ----------
        max_points : int, optional
            Most samples returned. Longer takes keep the frames of
            :func:`mocapqa.core.decimate.peak_frames`: per bucket of frames the lowest and
            highest θP and offset of every chain, and every interval's first frame and offset
            step (:meth:`step_frames`), so a one-frame flip stays visible.
        frames : ndarray of int, shape (N,), optional
            The frames to sample instead (increasing), as the pipeline's shared axis.

        Returns
        -------
        dict
            ``frame_step`` is the largest gap between consecutive samples (1 when every frame
            is kept); every series holds its value at ``frames``.
        """
        n_frames = self.offsets_rad.shape[0]
        plotted = self.plotted_deg()
        if frames is None:
            if max_points is not None and max_points < 2:
                raise InputError(f"Expected max_points ≥ 2, got {max_points}")
            limit = n_frames if max_points is None else max_points
            frames = peak_frames(plotted, limit, self.step_frames())
        n_chains = len(self.chains)
        flagged_all = np.zeros((n_frames, n_chains), dtype=bool)
        for interval in self.intervals:
            c = next(
                k for k, g in enumerate(self.chains)
                if self.joint_names[g.chain.parent] == interval.joint
            )  # fmt: skip
            flagged_all[interval.start_frame : interval.end_frame + 1, c] = True
        sampled = np.round(plotted[frames], 3)
        chains_json = []
        for c, geometry in enumerate(self.chains):
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
                    "theta_p_deg": sampled[:, c].tolist(),
                    "offset_deg": sampled[:, n_chains + c].tolist(),
                    "flagged": flagged_all[frames, c].astype(int).tolist(),
                    "intervals": [i.to_json() for i in self.intervals if i.joint == joint],
                }
            )
        return {
            "method": self.method,
            "apply": self.apply,
            "fps": self.fps,
            "n_frames": n_frames,
            "frame_step": int(np.diff(frames).max(initial=1)),
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
    # Bind-pose first frames are not motion and not a reference for the roll: the detector
    # reads the take from its first frame of motion on (that frame has no increment).
    skip = leading_pose_frames(quats)
    if skip:
        dp, dc = dp[skip:].copy(), dc[skip:].copy()
        dp[0] = dc[0] = 0.0
    return shift_detection(detect_robust(dp, dc, fps, robust), skip, n_frames)


def refined_hint(
    motion: Motion, refined_quats: FloatArray, changed: BoolArray
) -> FloatArray | None:
    """Euler hints for writing a refined take: unchanged cells keep the read angles, changed
    ones follow them.

    Parameters
    ----------
    motion : Motion
        The take as read, with the Euler angles it was read with (``euler_hint_deg``).
    refined_quats : ndarray, shape (F, J, 4)
        The take's local rotations after refinement.
    changed : ndarray of bool, shape (F, J)
        True where refinement changed the rotation.

    Returns
    -------
    ndarray, shape (F, J, 3), or None
        Hint angles in degrees for the BVH writer: the read angles where unchanged; where
        changed, the refined rotation as Euler angles nearest to the read angles interpolated
        across the change. None when the take has no read angles: the writer then makes every
        joint continuous itself.
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
    natural_roll: NaturalRoll | None = None,
    prior: ReviewerPrior | None = None,
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
        :data:`mocapqa.twist.confidence.APPLY_THRESHOLD` or that the anatomy evidence supports,
        :func:`mocapqa.twist.confidence.decide`), ``"all"``, ``"none"``, or interval
        ids (a set, or text such as ``"0,3"``). The paper's method has no calibrated
        confidence: ``"confident"`` applies all its intervals.
    natural_roll : NaturalRoll, optional
        Natural roll levels per rig family and segment (:mod:`mocapqa.twist.natural_roll`);
        ``confident`` applies no interval smaller than its rig segment's level. Default: the
        shipped levels; ``NaturalRoll()`` for none.
    prior : ReviewerPrior, optional
        A shoot's reviewer decisions (:mod:`mocapqa.twist.reviewer_prior`); None: none.

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
    # Anatomy evidence (joint limits) of each interval, for the apply choice and its record.
    anatomy = (
        anatomy_evidence(motion, geometries, found, detected, mapping)
        if method == "robust" and found
        else None
    )
    natural = default_natural_roll() if natural_roll is None else natural_roll
    family = rig_family(skeleton)
    natural_deg = [natural.level_deg(family, geometries[i.chain].chain.segment) for i in found]
    offsets, intervals = choose_intervals(
        found, detected, geometries, skeleton.names, choice, method == "robust", anatomy,
        natural_deg, prior, family,
    )  # fmt: skip
    return TwistAnalysis(
        method=method,
        refined=_refined(motion, refine_quats(motion.quats, geometries, offsets)),
        intervals=tuple(intervals),
        chains=geometries,
        joint_names=skeleton.names,
        fps=motion.fps,
        parent_twist_rad=_parent_twist(motion, geometries),
        offsets_rad=offsets,
        detected_offsets_rad=detected,
        apply="ids" if isinstance(choice, frozenset) else choice,
        found=tuple(found),
    )


def _refined(motion: Motion, refined_quats: FloatArray) -> Motion:
    """The take with the refined rotations ``(F, J, 4)`` and an Euler hint for the rows they
    change; the take itself when they change nothing."""
    changed = np.any(refined_quats != motion.quats, axis=-1)
    if not changed.any():
        return motion
    return replace(
        motion, quats=refined_quats, euler_hint_deg=refined_hint(motion, refined_quats, changed)
    )


def _parent_twist(motion: Motion, geometries: tuple[ChainGeometry, ...]) -> FloatArray:
    """Twist angle of each chain's parent about its axis per frame, radians, shape (F, C)."""
    if not geometries:
        return np.zeros((motion.n_frames, 0))
    axes = np.stack([g.axis for g in geometries])
    return parent_twist_angles(motion.quats[:, [g.chain.parent for g in geometries]], axes)
