"""Gap filling with an expected error per gap.

Every gap (a run of missing samples of one marker) is filled by whichever of three methods
(cubic spline and rigid body from donor markers in :mod:`mocapqa.markers.fill_methods`, PCA
intercorrelation in :mod:`mocapqa.markers.fill_pca`) or their blend reproduced the take's own
data best: the gap's length is hidden again in stretches where the same marker is recorded (near
the gap and where the take moves as it does over the gap; :mod:`mocapqa.markers.fill_cv`), each
method and the blend fill them, and the lowest RMSE (3-D distance, root mean square over the
hidden samples) is the gap's expected error (:mod:`mocapqa.markers.fill_plan`). Gaps nothing fills
below ``FillParams.max_error_mm`` are listed as not fillable; fills below
``FillParams.confident_error_mm`` are confident.

Lengths in :class:`FillParams` are in mm and converted with ``units_per_mm``; results are in the
take's own unit. Frames are 0-based, gap ends inclusive.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, check_shape, column_runs
from mocapqa.errors import OptionError, ShapeError
from mocapqa.markers.fill_params import FillParams
from mocapqa.markers.fill_plan import FillContext, GapPlan, plan_gap

__all__ = [
    "Apply",
    "FillContext",
    "FillParams",
    "FillResult",
    "GapFill",
    "GapPlan",
    "fill_gaps",
    "plan_gap",
]

Apply = Literal["confident", "all", "none"]
"""Which fills :func:`fill_gaps` writes: the confident ones, every fillable one, or none."""


@dataclass(frozen=True, slots=True)
class GapFill:
    """One gap and what was done with it.

    Parameters
    ----------
    marker : int
        Marker index.
    start, end : int
        First and last missing frame (0-based, inclusive).
    method : str or None
        The chosen method, or ``"blend"`` (the methods' fills weighted by inverse expected
        error); None when the gap is not fillable.
    expected_error : float
        Cross-validated RMSE of the chosen method in the take's unit (of the best method when
        not fillable; NaN when no method could be tried).
    confident : bool
        Fillable with ``expected_error`` below the confidence threshold.
    applied : bool
        The fill was written into :attr:`FillResult.positions`.
    errors : dict of str to float
        Cross-validated RMSE of every method tried and of the blend (take's unit; NaN where it
        could not fill).
    """

    marker: int
    start: int
    end: int
    method: str | None
    expected_error: float
    confident: bool
    applied: bool
    errors: dict[str, float] = field(default_factory=dict)

    @property
    def fillable(self) -> bool:
        """A method filled the gap below the error limit."""
        return self.method is not None


@dataclass(frozen=True, slots=True)
class FillResult:
    """Filled positions, the filled-sample mask and every gap.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        The input with the applied fills written in; every other sample bit-identical.
    filled : ndarray of bool, shape (F, M)
        Exactly the samples written by applied fills.
    gaps : tuple of GapFill
        Every gap, by marker then start frame.
    """

    positions: FloatArray
    filled: BoolArray
    gaps: tuple[GapFill, ...]


def fill_gaps(
    positions: FloatArray,
    fps: float,
    params: FillParams | None = None,
    apply: Apply = "confident",
    *,
    units_per_mm: float = 1.0,
) -> FillResult:
    """Fill every gap of a marker take by the method (or blend) with the lowest cross-validated
    error.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Marker positions in the file's unit, NaN where missing.
    fps : float
        Frame rate (Hz).
    params : FillParams, optional
        Settings; the defaults when omitted.
    apply : {"confident", "all", "none"}
        Which fills to write: confident ones, every fillable one, or none (gaps only listed).
    units_per_mm : float
        File units per mm (1 for mm, 0.001 for m), to convert the settings' lengths.

    Returns
    -------
    FillResult
        Filled positions (the input's samples bit-identical outside applied fills), the
        ``(F, M)`` mask of filled samples and every gap.

    Raises
    ------
    ShapeError
        If ``positions`` is not ``(F, M, 3)`` or holds infinities.
    OptionError
        On a non-positive ``fps`` or ``units_per_mm`` or an unknown ``apply``.
    """
    params = params or FillParams()
    positions = np.asarray(positions, dtype=np.float64)
    check_shape(positions, "positions", ("F", "M", 3))
    if np.isinf(positions).any():
        raise ShapeError("Expected `positions` to be finite or NaN, got infinity")
    if not (np.isfinite(fps) and fps > 0):
        raise OptionError("fps", f"Expected a positive frame rate, got {fps}")
    if not (np.isfinite(units_per_mm) and units_per_mm > 0):
        raise OptionError("units_per_mm", f"Expected a positive number, got {units_per_mm}")
    if apply not in ("confident", "all", "none"):
        raise OptionError("apply", f"Expected confident, all or none, got {apply!r}")
    from threadpoolctl import threadpool_limits  # type: ignore[import-untyped]

    take = FillContext(positions, fps, params, units_per_mm)
    out = positions.copy()
    filled = np.zeros(take.visible.shape, dtype=bool)
    gaps = []
    # The fills' matrices are small (at most a few dozen columns): BLAS threads only add their
    # wake-up cost.
    with threadpool_limits(limits=1, user_api="blas"):
        runs = zip(*(run.tolist() for run in column_runs(~take.visible)), strict=True)
        plans = [(m, a, b, plan_gap(take, m, a, b)) for m, a, b in runs]
    for m, a, b, plan in plans:
        method, error = plan.best()
        if method is not None and error > params.max_error_mm * units_per_mm:
            method = None
        confident = method is not None and error < params.confident_error_mm * units_per_mm
        applied = method is not None and (apply == "all" or (apply == "confident" and confident))
        if applied and method is not None:
            out[a : b + 1, m] = plan.fills[method]
            filled[a : b + 1, m] = True
        gaps.append(GapFill(m, a, b, method, error, confident, applied, dict(plan.errors)))
    return FillResult(positions=out, filled=filled, gaps=tuple(gaps))
