"""C3D parameter values read the same way from either reader (ezc3d or py-c3d)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["C3DParameters", "ezc3d_parameters", "pyc3d_parameters"]


class C3DParameters:
    """Parameter values from either reader: ``GROUP:NAME`` → list of values.

    Parameters
    ----------
    get : callable
        ``get(group, name)`` → the parameter's values as a flat list, empty when absent.
    """

    def __init__(self, get: Callable[[str, str], list[Any]]) -> None:
        self._get = get

    def strings(self, group: str, name: str) -> list[str]:
        """A parameter's values as stripped strings (empty when absent)."""
        values = self._get(group, name)
        return [str(v).strip() for v in values]

    def numbers(self, group: str, name: str) -> list[float]:
        """A parameter's values as floats (empty when absent or not numbers)."""
        try:
            return [float(v) for v in self._get(group, name)]
        except (TypeError, ValueError):
            return []

    def labels(self, group: str, count: int) -> list[str]:
        """``LABELS``, then ``LABELS2``, ``LABELS3``… up to ``count``."""
        out = self.strings(group, "LABELS")
        extra = 2
        while len(out) < count:
            more = self.strings(group, f"LABELS{extra}")
            if not more:
                break
            out += more
            extra += 1
        return out[:count]


def ezc3d_parameters(parameters: Any) -> C3DParameters:
    """The parameters of an ezc3d object.

    Parameters
    ----------
    parameters : ezc3d parameters
        ``c3d["parameters"]``: group → name → ``{"value": ...}``.

    Returns
    -------
    C3DParameters
    """

    def get(group: str, name: str) -> list[Any]:
        if group not in parameters or name not in parameters[group]:
            return []
        value = parameters[group][name]["value"]
        return list(np.ravel(value)) if isinstance(value, np.ndarray) else list(value)

    return C3DParameters(get)


def pyc3d_parameters(reader: Any) -> C3DParameters:
    """The parameters of a py-c3d reader; a value py-c3d cannot convert reads as absent.

    Parameters
    ----------
    reader : c3d.Reader
        An open py-c3d reader.

    Returns
    -------
    C3DParameters
    """

    def get(group: str, name: str) -> list[Any]:
        try:
            return values(group, name)
        except Exception:  # py-c3d raises on a value it cannot convert: read as absent
            return []

    def values(group: str, name: str) -> list[Any]:
        param = reader.get(f"{group}:{name}")
        if param is None:
            return []
        if param.bytes_per_element == -1:
            if len(param.dimensions) <= 1:
                return [param.string_value]
            return list(param.string_array.ravel())
        if not param.dimensions:
            if param.bytes_per_element == 4:
                return [param.float_value]
            return [param.int16_value if param.bytes_per_element == 2 else param.int8_value]
        if param.bytes_per_element == 4:
            return list(np.ravel(param.float_array))
        return list(np.ravel(param.int_array))

    return C3DParameters(get)
