"""The up axis of a take, from its feet, and the frame sampling it shares with the floor.

Conventions
-----------
* The up axis is one of the take's coordinate axes with a sign (``"Y"`` is +Y up, ``"-Y"`` is
  Y pointing down, as in MediaPipe's world landmarks and image coordinates). Heights are
  coordinates along it: ``sign × positions[..., axis]``, take units.
* Two cues choose it. **Feet**: along the up axis the foot points come back to the same level
  whenever they are still, while along a horizontal axis their still positions differ from
  step to step and between the left and the right foot; the feet cue is the axis with the
  smallest spread (10th–90th percentile) of still positions, pooled over both feet per part,
  and it is decisive when that spread is under half the next smallest. **Body**
  (gravity-free): in any upright motion the pelvis sits about a leg length above the feet, so
  the median pelvis-minus-feet vector points up. The body cue decides when it is clear (within
  about 25° of an axis and at least half a leg length long): on the corpus the feet cue alone
  picked a horizontal axis for short straight runs (too few still frames; the feet stay on
  one line, so the lateral axis varies least) and for a walk down uneven ground, and the body
  cue never erred on an upright take. Otherwise the feet cue decides (method ``"feet"``, or
  ``"weak"`` when it is not decisive either). The sign is the pelvis' side; without a clear
  pelvis, the side on which ankles and heels sit above toes. Neither cue uses gravity or
  accelerations, and neither holds for a take lying down or upside down the whole time; the
  report names the cue that decided.
* The floor is measured in :mod:`mocapqa.feet.floor`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError

__all__ = [
    "AXIS_NAMES",
    "MIN_STILL_SAMPLES",
    "SAMPLE_FRAMES",
    "UpAxis",
    "detect_up_axis",
    "sample_stride",
]

AXIS_NAMES = ("X", "Y", "Z")
"""Coordinate axis names, by index."""
_DECISIVE = 0.5
"""The feet cue decides when its smallest spread is under this share of the next smallest."""
_BODY_DOMINANCE = 0.9
"""The body cue decides when the pelvis-over-feet direction is this close to an axis (cosine,
about 25°) ..."""
_BODY_LIFT = 0.5
"""... and the pelvis sits at least this many leg lengths above the feet along it."""
MIN_STILL_SAMPLES = 5
"""Fewest still samples of a point (or a part) that its still positions are read from;
with fewer, all its samples are."""
SAMPLE_FRAMES = 4000
"""The up axis and the floor are measured on at most about this many frames, evenly spread:
percentiles and a plane over 4,000 frames of four points are as good as over all of a long
take, and the check's cost stays linear in the rest of its steps."""


def sample_stride(n_frames: int) -> int:
    """Every how many frames the up axis and the floor take a sample (1 up to
    :data:`SAMPLE_FRAMES` frames)."""
    return max(1, -(-n_frames // SAMPLE_FRAMES))


@dataclass(frozen=True, slots=True)
class UpAxis:
    """The up direction of a take.

    Parameters
    ----------
    axis : int
        0, 1 or 2 (X, Y, Z).
    sign : int
        +1 when up is the positive direction of the axis, −1 when it is the negative one.
    method : str
        Which cue decided: ``"feet and body"`` (both agree), ``"feet"``, ``"body"`` or
        ``"weak"`` (neither was decisive; the smallest feet spread was taken).
    feet_spreads : tuple of float
        Spread of the still foot positions along X, Y and Z, leg lengths (inf for an axis
        the points do not use, such as Z of 2D keypoints).
    body_axis : int or None
        The axis closest to the pelvis-over-feet direction, None without a pelvis.
    """

    axis: int
    sign: int
    method: str
    feet_spreads: tuple[float, float, float]
    body_axis: int | None = None

    @property
    def label(self) -> str:
        """``"Y"`` for +Y up, ``"-Z"`` for −Z up, and so on."""
        return ("" if self.sign > 0 else "-") + AXIS_NAMES[self.axis]

    def heights(self, positions: FloatArray) -> FloatArray:
        """Heights along the up direction, shape ``positions.shape[:-1]``, take units."""
        heights: FloatArray = self.sign * np.asarray(positions, dtype=np.float64)[..., self.axis]
        return heights


def _feet_spreads(
    positions: FloatArray,
    parts: tuple[str, ...],
    static: BoolArray,
    used: BoolArray,
    leg_length: float,
) -> list[float]:
    """Spread (10th–90th percentile) of the still foot positions along X, Y and Z, averaged
    over the parts, leg lengths; inf along an axis the points do not use."""
    groups = [[p for p, q in enumerate(parts) if q == part] for part in dict.fromkeys(parts)]
    per_group = []
    for members in groups:
        values = positions[:, members].reshape(-1, 3)
        still = static[:, members].ravel()
        samples = values[still] if still.sum() >= MIN_STILL_SAMPLES else values
        samples = samples[np.isfinite(samples).all(axis=-1)]
        if samples.shape[0] < 2:
            per_group.append(np.full(3, np.inf))
            continue
        low, high = np.percentile(samples, [10.0, 90.0], axis=0)
        per_group.append(high - low)
    spread = np.where(used, np.mean(per_group, axis=0) / leg_length, np.inf)
    return [float(v) for v in spread]


def _body_direction(
    pelvis: FloatArray, positions: FloatArray, used: BoolArray
) -> FloatArray | None:
    """The median pelvis-minus-feet vector ``(3,)``, zero along unused axes; None when it is
    not finite."""
    with warnings.catch_warnings():
        # Frames without any foot point (a keypoint take's gaps) are NaN, not a warning.
        warnings.simplefilter("ignore", RuntimeWarning)
        body = np.nanmedian(pelvis - np.nanmean(positions, axis=1), axis=0)
    if not np.all(np.isfinite(body)):
        return None
    direction: FloatArray = np.where(used, body, 0.0)
    return direction


def detect_up_axis(
    positions: FloatArray,
    parts: tuple[str, ...],
    static: BoolArray,
    leg_length: float,
    pelvis: FloatArray | None = None,
) -> UpAxis:
    """Find the up axis from where the feet rest and where the body is.

    Parameters
    ----------
    positions : ndarray, shape (F, P, 3)
        Foot point positions, take units; NaN where missing.
    parts : tuple of str
        The part of each point (``"heel"``, ``"ankle"``, ``"toe"``).
    static : ndarray of bool, shape (F, P)
        Where each point is still.
    leg_length : float
        Take units.
    pelvis : ndarray, shape (F, 3), optional
        A body point above the feet.

    Returns
    -------
    UpAxis

    Raises
    ------
    InputError
        If the foot points have no usable coordinates.
    """
    stride = sample_stride(positions.shape[0])
    positions, static = positions[::stride], static[::stride]
    pelvis = None if pelvis is None else pelvis[::stride]
    if np.sum(np.isfinite(positions).all(axis=-1).any(axis=-1)) < 2:
        raise InputError("Expected foot points with positions in at least 2 frames, got fewer")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        extent = np.nanmax(positions, axis=(0, 1)) - np.nanmin(positions, axis=(0, 1))
    used = extent > 1e-9 * leg_length
    spreads = _feet_spreads(positions, parts, static, used, leg_length)
    order = np.argsort(spreads)
    feet_axis = int(order[0])
    decisive = spreads[order[0]] < _DECISIVE * spreads[order[1]]
    body = None if pelvis is None else _body_direction(pelvis, positions, used)
    body_axis = None if body is None else int(np.argmax(np.abs(body)))
    upright = (
        body is not None
        and body_axis is not None
        and abs(body[body_axis]) >= _BODY_DOMINANCE * np.linalg.norm(body)
        and abs(body[body_axis]) >= _BODY_LIFT * leg_length
    )
    if upright and body_axis is not None:
        axis = body_axis
        method = "feet and body" if decisive and feet_axis == axis else "body"
    elif decisive:
        axis, method = feet_axis, "feet"
    else:
        axis, method = feet_axis, "weak"
    sign = _sign(positions, parts, axis, body, leg_length)
    return UpAxis(axis, sign, method, (spreads[0], spreads[1], spreads[2]), body_axis)


def _sign(
    positions: FloatArray,
    parts: tuple[str, ...],
    axis: int,
    body: FloatArray | None,
    leg_length: float,
) -> int:
    """+1 or −1: the pelvis is above the feet, else ankles and heels are above toes."""
    if body is not None and abs(body[axis]) > 0.25 * leg_length:
        return 1 if body[axis] > 0 else -1
    toes = [p for p, part in enumerate(parts) if part == "toe"]
    rears = [p for p, part in enumerate(parts) if part != "toe"]
    if toes and rears:
        lift = np.nanmedian(
            np.nanmean(positions[:, rears, axis], axis=1)
            - np.nanmean(positions[:, toes, axis], axis=1)
        )
        if np.isfinite(lift) and lift != 0:
            return 1 if lift > 0 else -1
    return 1
