"""Repair a marker take: swaps first, then gaps, by the same accept rule.

Swaps are repaired before any gap is filled (a fill uses the samples either side of its gap,
which a swap has put on the wrong label), then gaps are filled by the method with the lowest
cross-validated error (:func:`mocapqa.markers.fill.fill_gaps`). ``apply`` decides both: the
confident swaps and fills ("confident", the default), all, or none (everything is listed, as
found, and nothing changes). A reviewer's choice of swaps (``swaps``: their ids, the positions
in the check's list, which the check finds again in the same order from the same take) replaces
the rule for the swaps; the fills still follow ``apply``, on the take those swaps repair.
Every filled sample gets residual 0 (the C3D convention for an interpolated sample); a
repaired swap exchanges the residuals with the positions. Samples that neither touches are
bit-identical to the input.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import InputError
from mocapqa.markers.check import check_markers
from mocapqa.markers.fill import FillParams, FillResult, fill_gaps
from mocapqa.markers.params import MarkerParams, unit_scale
from mocapqa.markers.swap_repair import repair_swaps, select_swaps, swapped_mask
from mocapqa.markers.swaps import Swap

__all__ = ["MarkerRepair", "repair_markers"]


@dataclass(frozen=True, slots=True)
class MarkerRepair:
    """A repaired marker take and what was done.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Swaps repaired and gaps filled, take units; NaN where a gap stays.
    residuals : ndarray, shape (F, M)
        The input's residuals, exchanged with the swaps, 0 on filled samples.
    swaps : tuple of Swap
        Every swap found.
    repaired : tuple of Swap
        The swaps applied.
    fills : FillResult
        Every gap of the swap-repaired take, with what was filled (``fills.filled``).
    """

    positions: FloatArray
    residuals: FloatArray
    swaps: tuple[Swap, ...]
    repaired: tuple[Swap, ...]
    fills: FillResult

    @property
    def filled(self) -> BoolArray:
        """``(F, M)``: the samples a fill wrote."""
        return self.fills.filled

    def carry(self, samples: np.ndarray, on_filled: float) -> np.ndarray:
        """Another per-sample array of the take (residuals, camera masks), ``(F, M)``, as the
        repair leaves it: exchanged with the repaired swaps, ``on_filled`` on filled samples;
        its dtype kept."""
        exchanged = repair_swaps(np.asarray(samples), self.repaired)
        return np.where(self.filled, on_filled, exchanged).astype(exchanged.dtype)

    def to_json(self, names: Sequence[str], length_unit: str) -> dict[str, Any]:
        """A JSON-ready account: ``swaps`` (each with ``applied``), ``gaps`` (marker name,
        frames 0-based inclusive, method, expected error in ``length_unit``, confident,
        applied) and the number of ``filled_samples``."""
        applied = {(s.indices, s.start, s.end) for s in self.repaired}
        return {
            "length_unit": length_unit,
            "swaps": [
                {"markers": list(s.markers), "start": s.start, "end": s.end,
                 "confidence": s.confidence, "applied": (s.indices, s.start, s.end) in applied}
                for s in self.swaps
            ],
            "gaps": [
                {"marker": names[g.marker], "start": g.start, "end": g.end, "method": g.method,
                 "expected_error": None if not np.isfinite(g.expected_error)
                 else round(float(g.expected_error), 6),
                 "confident": g.confident, "applied": g.applied}
                for g in self.fills.gaps
            ],
            "filled_samples": int(self.filled.sum()),
            "swapped_samples": int(swapped_mask(self.filled.shape, self.repaired).sum()),
        }  # fmt: skip


def repair_markers(
    positions: FloatArray,
    residuals: FloatArray,
    names: Sequence[str],
    fps: float,
    length_unit: str,
    apply: Literal["confident", "all", "none"] = "confident",
    params: MarkerParams | None = None,
    fill_params: FillParams | None = None,
    swaps: Collection[int] | None = None,
) -> MarkerRepair:
    """Repair the swaps, then fill the gaps, of a marker take.

    Parameters
    ----------
    positions : ndarray, shape (F, M, 3)
        Marker positions in ``length_unit``, NaN where missing.
    residuals : ndarray, shape (F, M)
        Their residuals (−1 where missing); a take without any passes zeros.
    names : sequence of str
        The M labels.
    fps : float
        Frames per second.
    length_unit : str
        The positions' unit ("mm", "m", ...).
    apply : {"confident", "all", "none"}
        Which swaps and fills change the take.
    params, fill_params : optional
        Check and fill settings (defaults when None).
    swaps : collection of int, optional
        The ids of the swaps to repair (positions in the check's list of swaps, ``swaps`` of
        the result), instead of those ``apply`` selects; ``apply`` still decides the fills.

    Returns
    -------
    MarkerRepair

    Raises
    ------
    OptionError
        If ``apply`` is not one of the three.
    InputError
        If ``swaps`` names an id the check did not find.
    """
    report = check_markers(positions, names, fps, length_unit, params)
    ruled = select_swaps(report.swaps, apply, params)  # also checks ``apply``
    if swaps is None:
        chosen = tuple(ruled)
    else:
        unknown = sorted(set(swaps) - set(range(len(report.swaps))))
        if unknown:
            raise InputError(
                f"Expected swap ids in 0..{len(report.swaps) - 1}, got {unknown[:5]} "
                f"({len(report.swaps)} swap(s) found)"
            )
        chosen = tuple(s for k, s in enumerate(report.swaps) if k in swaps)
    swapped = repair_swaps(positions, chosen)
    fills = fill_gaps(swapped, fps, fill_params, apply, units_per_mm=unit_scale(length_unit))
    repair = MarkerRepair(
        fills.positions, np.asarray(residuals), tuple(report.swaps), chosen, fills
    )
    return replace(repair, residuals=repair.carry(np.asarray(residuals, dtype=np.float64), 0.0))
