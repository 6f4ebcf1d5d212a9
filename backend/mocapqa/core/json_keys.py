"""JSON objects whose keys are each given once.

Python's parser keeps the last of a repeated key (``{"a": 1, "a": 2}`` reads as ``{"a": 2}``),
so a document can say two things and be read as one of them without a word. Pass
:func:`unique_keys` as ``json.loads(..., object_pairs_hook=unique_keys)`` to refuse it.
"""

from __future__ import annotations

from typing import Any

__all__ = ["RepeatedKeyError", "unique_keys"]


class RepeatedKeyError(ValueError):
    """A JSON object with a key given twice; ``key`` names it (a ``ValueError``, so callers
    that catch :class:`json.JSONDecodeError`'s base see it too)."""

    def __init__(self, key: str) -> None:
        super().__init__(f"Expected each key once, got {key!r} twice")
        self.key = key


def unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """An object's members as a dict.

    Raises
    ------
    RepeatedKeyError
        When a key is given twice.
    """
    table: dict[str, Any] = {}
    for key, value in pairs:
        if key in table:
            raise RepeatedKeyError(key)
        table[key] = value
    return table
