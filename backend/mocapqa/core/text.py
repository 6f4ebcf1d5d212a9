"""Text shown to people: names echoed by the API and the UI, cleaned of invisible controls."""

from __future__ import annotations

import unicodedata

__all__ = ["display_name"]


def display_name(text: str, max_length: int = 255) -> str:
    """``text`` without control (Cc) and format (Cf) characters, trimmed, at most
    ``max_length`` characters.

    Format characters include the bidirectional overrides and isolates (U+202A–U+202E,
    U+2066–U+2069) that make ``exe.txt`` read as ``txt.exe``, and zero-width characters; tabs
    and newlines become spaces.

    Parameters
    ----------
    text : str
        A client-given name (a file name, a reviewer).
    max_length : int
        Longest result, characters.

    Returns
    -------
    str
        The cleaned name (possibly empty).
    """
    kept = (
        " " if ch in "\t\n\r" else ch
        for ch in text
        if ch in "\t\n\r" or unicodedata.category(ch) not in ("Cc", "Cf", "Cs", "Co", "Cn")
    )
    return "".join(kept).strip()[:max_length]
