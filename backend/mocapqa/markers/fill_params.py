"""Settings of the gap fill (:func:`mocapqa.markers.fill.fill_gaps`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mocapqa.errors import OptionError

__all__ = ["CHOICES", "METHODS", "PCA_FAMILY", "FillParams"]

METHODS = ("spline", "rigid", "pca", "relative")
"""The gap-fill methods: cubic spline, rigid-body from donor markers, PCA intercorrelation of
the markers' positions (Gløersen & Federolf 2016), and the same PCA of their positions relative
to their neighbours (each frame's weighted centre of the model markers taken out first)."""

PCA_FAMILY = {"pca": False, "relative": True}
"""The PCA methods, each with whether it takes the neighbours' centre out first
(:func:`mocapqa.markers.fill_pca.pca_model`)."""

CHOICES = (*METHODS, "blend")
"""What a gap's fill may be: one method or their blend, in the order used to break ties."""

MATCHES = ("spread", "motion")


@dataclass(frozen=True, slots=True)
class FillParams:
    """Settings of :func:`fill_gaps` (lengths in mm, times in seconds).

    Parameters
    ----------
    confident_error_mm : float
        Expected error below which a fill is confident (applied by ``apply="confident"``).
    max_error_mm : float
        Expected error above which a gap is not fillable.
    spline_window_s : float
        Time either side of a gap whose samples the spline passes through.
    spline_max_gap_s : float
        Longest gap the spline fills.
    rigid_donors : int
        Donor markers used by the rigid fill (at least 3).
    rigid_max_std_mm : float
        Largest standard deviation of a donor's distance to the target.
    rigid_min_spread_mm : float
        Least distance between the first two donors and of the third from their line.
    rigid_window_s : float
        Time either side of a gap used to fit the target in the donors' frame.
    pca_markers : int
        Model markers (nearest first) of the PCA fill.
    pca_weight_mm : float
        Fall-off distance of the PCA fill's marker weights.
    pca_variance : float
        Share of variance kept by the PCA fill, in (0, 1].
    pca_max_train : int
        Most training frames of the PCA fill.
    cv_trials : int
        Artificial gaps per real gap in the cross-validation.
    cv_local : bool
        Hide half of the artificial gaps nearest to the real one (at most one per gap length of
        frames) rather than none: markers go missing in the hardest moments (fast motion,
        occlusion), which the neighbouring frames resemble most.
    cv_match : {"spread", "motion"}
        Where the other artificial gaps go: spread evenly over the take, or where the
        ``cv_motion_markers`` markers nearest to the target move at the speed they move at
        over the gap (nearest in log ratio).
    cv_motion_markers : int
        Markers (nearest to the target first) whose mean speed is the motion matched.
    blend_power : float
        The blend of the methods' fills weighs each by its expected error to the power
        ``-blend_power``; 0 leaves the blend out.
    smooth_anchor : bool
        Interpolate the rigid and PCA fills' errors either side of a gap with a cubic spline
        instead of blending the boundary errors linearly.
    methods : tuple of str
        The methods tried, a subset of ``METHODS``.
    """

    confident_error_mm: float = 5.0
    max_error_mm: float = 50.0
    spline_window_s: float = 0.25
    spline_max_gap_s: float = 0.5
    rigid_donors: int = 4
    rigid_max_std_mm: float = 10.0
    rigid_min_spread_mm: float = 30.0
    rigid_window_s: float = 0.1
    pca_markers: int = 20
    pca_weight_mm: float = 400.0
    pca_variance: float = 0.9999
    pca_max_train: int = 2000
    cv_trials: int = 8
    cv_local: bool = True
    cv_match: str = "motion"
    cv_motion_markers: int = 4
    blend_power: float = 2.0
    smooth_anchor: bool = False
    methods: tuple[str, ...] = METHODS

    def __post_init__(self) -> None:
        positive = {
            "confident_error_mm": self.confident_error_mm,
            "max_error_mm": self.max_error_mm,
            "spline_window_s": self.spline_window_s,
            "spline_max_gap_s": self.spline_max_gap_s,
            "rigid_max_std_mm": self.rigid_max_std_mm,
            "rigid_min_spread_mm": self.rigid_min_spread_mm,
            "rigid_window_s": self.rigid_window_s,
            "pca_weight_mm": self.pca_weight_mm,
        }
        for name, value in positive.items():
            if not (np.isfinite(value) and value > 0):
                raise OptionError(f"fill_params.{name}", f"Expected a positive number, got {value}")
        if not 0 < self.pca_variance <= 1:
            raise OptionError(
                "fill_params.pca_variance", f"Expected a share in (0, 1], got {self.pca_variance}"
            )
        counts = {
            "rigid_donors": (self.rigid_donors, 3),
            "pca_markers": (self.pca_markers, 1),
            "pca_max_train": (self.pca_max_train, 10),
            "cv_trials": (self.cv_trials, 1),
            "cv_motion_markers": (self.cv_motion_markers, 1),
        }
        for name, (value, low) in counts.items():
            if value < low:
                raise OptionError(f"fill_params.{name}", f"Expected at least {low}, got {value}")
        if self.cv_match not in MATCHES:
            raise OptionError(
                "fill_params.cv_match", f"Expected one of {list(MATCHES)}, got {self.cv_match!r}"
            )
        if not (np.isfinite(self.blend_power) and self.blend_power >= 0):
            raise OptionError(
                "fill_params.blend_power", f"Expected a number ≥ 0, got {self.blend_power}"
            )
        unknown = [x for x in self.methods if x not in METHODS]
        if unknown or not self.methods:
            raise OptionError(
                "fill_params.methods", f"Expected some of {list(METHODS)}, got {self.methods}"
            )
