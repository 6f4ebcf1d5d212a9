"""Array type aliases and shape guards.

Conventions: time is axis 0; local unit quaternions are ``(F, J, 4)`` float64 in scalar-last
``(x, y, z, w)`` order (scipy's default); positions are ``(F, J, 3)``; keypoints are
``(F, K, 3)`` with a confidence array ``(F, K)``. Guards raise :class:`~mocapqa.errors.ShapeError`
in scipy's style: ``Expected `quats` to have shape (F, J, 4), got (120, 4)``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from mocapqa.errors import ShapeError

__all__ = [
    "BoolArray",
    "FloatArray",
    "IntArray",
    "as_float_array",
    "check_shape",
    "column_runs",
    "true_runs",
]

FloatArray = NDArray[np.float64]
"""float64 array of any shape (positions, quaternions, angles)."""
IntArray = NDArray[np.intp]
"""Platform-integer array (indices such as ``parents``)."""
BoolArray = NDArray[np.bool_]
"""Boolean mask array."""


def check_shape(array: NDArray[Any], name: str, pattern: tuple[int | str, ...]) -> None:
    """Raise ShapeError unless ``array`` matches ``pattern``.

    Parameters
    ----------
    array : ndarray
        The array to check.
    name : str
        The argument's name, used in the message.
    pattern : tuple of int or str
        One entry per axis: an int fixes that axis' length, a str (``"F"``, ``"J"``) is free.

    Raises
    ------
    ShapeError
        If the number of axes or a fixed length differs.
    """
    ok = array.ndim == len(pattern) and all(
        isinstance(p, str) or array.shape[i] == p for i, p in enumerate(pattern)
    )
    if not ok:
        expected = (
            "(" + ", ".join(str(p) for p in pattern) + ("," if len(pattern) == 1 else "") + ")"
        )
        raise ShapeError(f"Expected `{name}` to have shape {expected}, got {tuple(array.shape)}")


def as_float_array(
    values: Any, name: str, pattern: tuple[int | str, ...], *, finite: bool = True
) -> FloatArray:
    """Convert ``values`` to a float64 array, check its shape and (optionally) finiteness.

    Parameters
    ----------
    values : array_like
        Input values.
    name : str
        The argument's name, used in messages.
    pattern : tuple of int or str
        Expected shape, as in :func:`check_shape`.
    finite : bool, default True
        Reject NaN and infinity.

    Returns
    -------
    ndarray
        A float64 array (a copy only when a conversion was needed).

    Raises
    ------
    ShapeError
        On a wrong shape, a non-numeric dtype or non-finite values.
    """
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ShapeError(f"Expected `{name}` to be numeric, got {type(values).__name__}") from e
    check_shape(array, name, pattern)
    if finite and not np.all(np.isfinite(array)):
        raise ShapeError(f"Expected `{name}` to be finite, got NaN or infinity")
    return array


def true_runs(flags: BoolArray) -> IntArray:
    """Runs of consecutive true values.

    Parameters
    ----------
    flags : ndarray of bool, shape (F,)

    Returns
    -------
    ndarray of int, shape (R, 2)
        First and last index (both inside the run) of each run, in order.
    """
    edges = np.diff(np.concatenate(([0], flags.astype(np.int8), [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    return np.stack([starts, stops - 1], axis=1).astype(np.intp)


def column_runs(mask: BoolArray) -> tuple[IntArray, IntArray, IntArray]:
    """The runs of true frames in each column of a mask.

    Parameters
    ----------
    mask : ndarray of bool, shape (F, N)

    Returns
    -------
    columns, starts, ends : ndarray of int, shape (R,)
        Column, first and last frame (both inside the run) of each run, by column then start.

    Raises
    ------
    ShapeError
        If ``mask`` is not two-dimensional.
    """
    mask = np.asarray(mask, dtype=bool)
    if mask.ndim != 2:
        raise ShapeError(f"Expected `mask` to have shape (F, N), got {mask.shape}")
    n_frames, n_columns = mask.shape
    padded = np.zeros((n_columns, n_frames + 2), dtype=np.int8)
    padded[:, 1:-1] = mask.T
    edges = np.diff(padded, axis=1)
    columns, starts = np.nonzero(edges == 1)
    _, stops = np.nonzero(edges == -1)
    return columns.astype(np.intp), starts.astype(np.intp), (stops - 1).astype(np.intp)
