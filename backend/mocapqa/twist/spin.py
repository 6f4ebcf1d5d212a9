"""Limb spins: a limb rolling about its own axis faster than a body can, reported, not corrected.

The twist chains (:mod:`mocapqa.twist.detect`) pair a joint with its direct child: a roll of
the joint that the child undoes. Retargets also make a second shape, with the *two* upper
segments of a limb turning together (the elbow or knee does not move) about the limb's axis,
from its root (shoulder, hip) to its end joint (wrist, ankle):

* **spin** — the end segment (hand, foot) stays: it counter-rotates against the limb in its
  parent's frame. On a nearly straight arm or leg the roll hardly moves a joint position, so it
  shows only in the segments' orientations and in the skinning. Subject 005's Character
  Creator dance takes hold runs of 15–45° per frame at 60 fps (900–2,700°/s), summing to up to
  184° in five frames (``005_03`` frames 26–30, the hand turning 7° meanwhile);
* **flip** — the end segment turns with the limb by 90° or more in one frame (a knee or elbow
  pole flip: the middle joint jumps to the mirror side of the limb's axis while the root and
  end joints stay). ``005_05``'s right leg flips by 105–176° ten times in frames 161–194.

A step between two frames is an event when the upper segment's world rotation about the limb
axis is faster than :data:`SPIN_RATE_DEG_S`, the middle segment turns with it (its roll about
the axis within a quarter of the upper segment's), and the end segment either stays (roll
within half of it: *spin*) or follows by at least :data:`FLIP_DEG` (*flip*). Consecutive
events of one shape on one limb form one finding. Rates are per second, so a take resampled
from 60 to 30 or 120 fps gets the same findings. The step into frame 1 of a take whose first
frame is a bind pose (:func:`mocapqa.kinematics.bindpose.leading_bind_pose`) is not an event.

These are reported, never applied: which side of a spin is the natural roll is not known
without a model of the limb's natural range (the limits check flags the side that is out of
range), and a wrong choice would roll a clean stretch. :data:`SPIN_RATE_DEG_S` is above every
roll of the kind on the corpus takes of other subjects (the largest is 870°/s, on a Character
Creator basketball take; Bandai stays under 520°/s, CMU under 320°/s): a figure about that
corpus.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from mocapqa.core.arrays import FloatArray, true_runs
from mocapqa.core.motion import Motion
from mocapqa.core.rig import RigMap, find_roles
from mocapqa.kinematics.bindpose import leading_bind_pose
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import conjugate, multiply
from mocapqa.kinematics.swing_twist import twist_angle

__all__ = ["FLIP_DEG", "LIMBS", "SPIN_RATE_DEG_S", "LimbSpin", "axial_rolls", "find_limb_spins"]

SPIN_RATE_DEG_S = 900.0
"""Slowest roll of a limb's upper segment about the limb axis that is an event, degrees/s."""

FLIP_DEG = 90.0
"""Smallest one-frame turn of a whole limb (end segment included) that is a flip, degrees."""

FOLLOW_SHARE = 0.25
"""The middle segment turns with the upper one: their rolls differ by at most this share."""

STAY_SHARE = 0.5
"""The end segment stays (spin) when its roll is at most this share of the upper one's."""

LIMBS: tuple[tuple[str, tuple[str, str, str]], ...] = (
    ("arm", ("upper_arm", "forearm", "hand")),
    ("leg", ("upper_leg", "lower_leg", "foot")),
)
"""Each limb's name and the roles of its upper, middle and end segments."""

Shape = Literal["spin", "flip"]


@dataclass(frozen=True, slots=True)
class LimbSpin:
    """One run of consecutive spin (or flip) events on one limb.

    Parameters
    ----------
    side : {"left", "right"}
    limb : {"arm", "leg"}
    joint : str
        Name of the limb's upper segment (upper arm, thigh).
    start_frame, end_frame : int
        First and last frame reached by a spinning step (inclusive).
    roll_deg : float
        The upper segment's roll about the limb axis summed over the run, degrees (signed).
    end_roll_deg : float
        The end segment's roll over the run, degrees.
    peak_roll_deg : float
        The largest single step's roll, degrees (signed; a flip and its flip back sum to
        about 0 but each is this large).
    peak_rate_deg_s : float
        The fastest step's roll rate, degrees per second.
    shape : {"spin", "flip"}
    """

    side: str
    limb: str
    joint: str
    start_frame: int
    end_frame: int
    roll_deg: float
    end_roll_deg: float
    peak_roll_deg: float
    peak_rate_deg_s: float
    shape: Shape

    def to_json(self) -> dict[str, object]:
        """The fields, rounded, and the read-out."""
        return {
            "side": self.side, "limb": self.limb, "joint": self.joint, "shape": self.shape,
            "start_frame": self.start_frame, "end_frame": self.end_frame,
            "roll_deg": round(self.roll_deg, 2), "end_roll_deg": round(self.end_roll_deg, 2),
            "peak_roll_deg": round(self.peak_roll_deg, 2),
            "peak_rate_deg_s": round(self.peak_rate_deg_s, 1), "readout": self.readout(),
        }  # fmt: skip

    @property
    def value_deg(self) -> float:
        """The finding's size: the summed roll of a spin, the largest step of a flip."""
        return self.roll_deg if self.shape == "spin" else self.peak_roll_deg

    def readout(self) -> str:
        """A sentence for a reviewer, e.g. "right arm spun 184° about its axis in 5 frames
        (2,602°/s) while the hand stayed (turned 7°); not corrected"."""
        frames = self.end_frame - self.start_frame + 1
        end = "hand" if self.limb == "arm" else "foot"
        middle = "elbow" if self.limb == "arm" else "knee"
        when = "in 1 frame" if frames == 1 else f"in {frames} frames"
        if self.shape == "spin":
            return (
                f"{self.side} {self.limb} spun {abs(self.roll_deg):.0f}° about its axis {when} "
                f"({self.peak_rate_deg_s:,.0f}°/s) while the {end} stayed (turned "
                f"{abs(self.end_roll_deg):.0f}°); not corrected"
            )
        return (
            f"{self.side} {self.limb} flipped {abs(self.peak_roll_deg):.0f}° about its axis "
            f"with the {end}, the {middle} to the other side, {when}; not corrected"
        )


def axial_rolls(world_quats: FloatArray, axes: FloatArray) -> FloatArray:
    """Each frame-to-frame world step's rotation about a world axis, degrees in (−180, 180].

    Parameters
    ----------
    world_quats : ndarray, shape (F, 4)
        World rotations of one segment, scalar-last.
    axes : ndarray, shape (F − 1, 3)
        Unit axis of each step (world frame).

    Returns
    -------
    ndarray, shape (F − 1,)
    """
    steps = multiply(world_quats[1:], conjugate(world_quats[:-1]))
    return np.rad2deg(twist_angle(steps, axes))


def _wrap(degrees: FloatArray) -> FloatArray:
    return (degrees + 180.0) % 360.0 - 180.0


def find_limb_spins(
    motion: Motion,
    rig: RigMap | None = None,
    *,
    mapping: dict[str, str] | None = None,
    min_rate_deg_s: float = SPIN_RATE_DEG_S,
    flip_deg: float = FLIP_DEG,
    world: tuple[FloatArray, FloatArray] | None = None,
) -> list[LimbSpin]:
    """Spins and flips of every limb whose three roles are found, in frame order.

    Parameters
    ----------
    motion : Motion
    rig : RigMap, optional
        Roles of the skeleton (found with ``mapping`` when not given).
    mapping : dict, optional
        Role key → joint name overrides for :func:`mocapqa.core.rig.find_roles`.
    min_rate_deg_s : float
        :data:`SPIN_RATE_DEG_S`.
    flip_deg : float
        :data:`FLIP_DEG`.
    world : tuple of ndarray, optional
        ``forward_kinematics(motion)`` when already computed.

    Returns
    -------
    list of LimbSpin
    """
    if motion.n_frames < 2:
        return []
    if rig is None:
        rig = find_roles(motion.skeleton, mapping)
    world_quats, positions = forward_kinematics(motion) if world is None else world
    skip = leading_bind_pose(motion.quats)
    found: list[LimbSpin] = []
    for side in ("left", "right"):
        for limb, roles in LIMBS:
            joints = [rig.joint(side, role) for role in roles]  # type: ignore[arg-type]
            if any(j is None for j in joints):
                continue
            upper, middle, end = (int(j) for j in joints)  # type: ignore[arg-type]
            axes = positions[1:, end] - positions[1:, upper]
            length = np.linalg.norm(axes, axis=1, keepdims=True)
            axes = axes / np.where(length > 0, length, 1.0)
            roll_u = axial_rolls(world_quats[:, upper], axes)
            roll_m = axial_rolls(world_quats[:, middle], axes)
            roll_e = axial_rolls(world_quats[:, end], axes)
            size = np.abs(roll_u)
            fast = (size * motion.fps >= min_rate_deg_s) & (length[:, 0] > 0)
            follows = np.abs(_wrap(roll_m - roll_u)) <= FOLLOW_SHARE * size
            spin = fast & follows & (np.abs(roll_e) <= STAY_SHARE * size)
            flip = (
                fast & follows & (size >= flip_deg)
                & (np.abs(_wrap(roll_e - roll_u)) <= STAY_SHARE * size)
            )  # fmt: skip
            spin[:skip] = False
            flip[:skip] = False
            for shape, flags in (("spin", spin), ("flip", flip)):
                for first, last in true_runs(flags).tolist():
                    steps = slice(first, last + 1)
                    found.append(
                        LimbSpin(
                            side=side,
                            limb=limb,
                            joint=motion.skeleton.names[upper],
                            start_frame=first + 1,
                            end_frame=last + 1,
                            roll_deg=float(roll_u[steps].sum()),
                            end_roll_deg=float(roll_e[steps].sum()),
                            peak_roll_deg=float(roll_u[first + np.argmax(size[steps])]),
                            peak_rate_deg_s=float(size[steps].max() * motion.fps),
                            shape=shape,  # type: ignore[arg-type]
                        )
                    )
    return sorted(found, key=lambda s: (s.start_frame, s.side, s.limb))
