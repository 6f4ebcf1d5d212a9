"""``RequestModel``: the base of every JSON request body, refusing text no store can keep.

PostgreSQL refuses NUL (U+0000) in text, and an unpaired surrogate (U+D800–U+DFFF, which JSON's
``\\ud800`` escapes can spell) has no UTF-8 form: stored, it makes every later answer that
echoes it fail to encode. Every string of a body (dictionary keys and nested values included)
is checked before the route runs, so such a request is a 422 naming the field
(``body.mapping``), never a 500 nor a stored row that breaks the pages showing it. Paths and
query strings get the same check in :mod:`mocapqa.api.http_guards`.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, field_validator

__all__ = ["RequestModel", "unstorable_text"]


def unstorable_text(text: str) -> str | None:
    """Why ``text`` cannot be stored (an "Expected …, got …" message), or None when it can."""
    if "\x00" in text:
        return "Expected text without NUL (U+0000) characters, got one"
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return "Expected text without unpaired surrogate (U+D800–U+DFFF) characters, got one"
    return None


def _check(value: Any) -> None:
    if isinstance(value, str):
        problem = unstorable_text(value)
        if problem is not None:
            raise ValueError(problem)
    elif isinstance(value, dict):
        for key, item in value.items():
            _check(key)
            _check(item)
    elif isinstance(value, list | tuple):
        for item in value:
            _check(item)


class RequestModel(BaseModel):
    """A JSON request body whose every string can be stored and echoed (see the module), and
    whose every field is known: an unknown one is a 422 naming it, not silently dropped (a
    token request naming another ``user`` used to mint one for the caller)."""

    model_config = ConfigDict(extra="forbid")

    @field_validator("*", mode="before")
    @classmethod
    def _storable(cls, value: Any) -> Any:
        _check(value)
        return value
