"""Accuracy of twist refinement against injected ground truth (the paper's metrics).

Conventions
-----------
The rotation error of a target joint on a frame is the geodesic angle, in degrees, between its
clean local rotation and the corrupted (before) or refined (after) one. MAE and RMSE are taken
over the injected error frames; FSR is the share of those frames whose error fell by at least
80 %; RER is the residual error ratio, the sum of errors after over the sum before. The clean-data
figure is the share of frame × joint rotations that a refinement changes by more than a
tolerance on an uncorrupted take.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import ShapeError
from mocapqa.kinematics.quaternion import geodesic_angle

__all__ = ["CleanChange", "TwistAccuracy", "clean_change", "rotation_errors_deg", "twist_accuracy"]


@dataclass(frozen=True, slots=True)
class TwistAccuracy:
    """Paper metrics over a set of error frames.

    Parameters
    ----------
    n_frames : int
        Error frames counted.
    mae_before_deg, mae_after_deg, rmse_before_deg, rmse_after_deg : float
        Mean absolute and root-mean-square rotation errors, degrees.
    fsr : float
        Frame success rate in [0, 1].
    rer : float
        Residual error ratio (after / before).
    n_success : int
        Frames whose error fell by at least 80 %.
    """

    n_frames: int
    mae_before_deg: float
    mae_after_deg: float
    rmse_before_deg: float
    rmse_after_deg: float
    fsr: float
    rer: float
    n_success: int


@dataclass(frozen=True, slots=True)
class CleanChange:
    """How much a refinement changed an uncorrupted take.

    Parameters
    ----------
    n_cells : int
        Frame × joint rotations compared.
    n_changed : int
        Rotations changed by more than the tolerance.
    max_change_deg : float
        Largest change, degrees.
    """

    n_cells: int
    n_changed: int
    max_change_deg: float

    @property
    def share(self) -> float:
        """``n_changed / n_cells`` (0 for no cells)."""
        return self.n_changed / self.n_cells if self.n_cells else 0.0


def rotation_errors_deg(reference: FloatArray, quats: FloatArray) -> FloatArray:
    """Geodesic angle between two rotation arrays of the same shape ``(..., 4)``, degrees."""
    if reference.shape != quats.shape:
        raise ShapeError(f"Expected equal shapes, got {reference.shape} and {quats.shape}")
    return np.rad2deg(geodesic_angle(reference, quats))


def twist_accuracy(before_deg: FloatArray, after_deg: FloatArray) -> TwistAccuracy:
    """MAE, RMSE, FSR and RER from per-frame errors of the error frames.

    Parameters
    ----------
    before_deg, after_deg : ndarray, shape (N,)
        Rotation errors of the N error frames before and after refinement, degrees.

    Returns
    -------
    TwistAccuracy
    """
    before = np.asarray(before_deg, dtype=np.float64).ravel()
    after = np.asarray(after_deg, dtype=np.float64).ravel()
    if before.shape != after.shape:
        raise ShapeError(f"Expected equal shapes, got {before.shape} and {after.shape}")
    n = before.size
    if n == 0:
        return TwistAccuracy(0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
    success = int(np.sum(after <= 0.2 * before))
    total_before = float(before.sum())
    return TwistAccuracy(
        n_frames=n,
        mae_before_deg=float(before.mean()),
        mae_after_deg=float(after.mean()),
        rmse_before_deg=float(np.sqrt(np.mean(before**2))),
        rmse_after_deg=float(np.sqrt(np.mean(after**2))),
        fsr=success / n,
        rer=float(after.sum()) / total_before if total_before > 0 else 0.0,
        n_success=success,
    )


def clean_change(
    clean: FloatArray,
    refined: FloatArray,
    tolerance_deg: float = 1.0,
    mask: BoolArray | None = None,
) -> CleanChange:
    """Count rotations of an uncorrupted take changed by more than ``tolerance_deg``.

    Parameters
    ----------
    clean, refined : ndarray, shape (F, J, 4)
    tolerance_deg : float
    mask : ndarray of bool, shape (F, J), optional
        Cells to count (e.g. joints with rotation channels); all when omitted.

    Returns
    -------
    CleanChange
    """
    change = rotation_errors_deg(clean, refined)
    if mask is not None:
        change = change[mask]
    return CleanChange(
        n_cells=int(change.size),
        n_changed=int(np.sum(change > tolerance_deg)),
        max_change_deg=float(change.max(initial=0.0)),
    )
