"""The ``Content-Disposition`` of a download: the user's own name for the file.

A take keeps the name it was uploaded under (``take["name"]``, any script) besides the file
name it is stored under (``file_name``, made safe for file systems). A download is named after
the former, sent twice as RFC 6266 asks: an ASCII ``filename`` for old clients and a UTF-8
``filename*`` (RFC 5987) that browsers prefer, so ``ünïcödé 日本.bvh`` downloads as
``ünïcödé 日本.corrected.bvh`` rather than ``_n_c_d_.corrected.bvh``.
"""

from __future__ import annotations

from typing import Any
from urllib.parse import quote

__all__ = ["attachment", "download_stem"]


def download_stem(take: dict[str, Any]) -> str:
    """The take's uploaded name without its extension (its stored file name's if it has none)."""
    name = str(take.get("name") or take["file_name"])
    return name.rsplit(".", 1)[0] if "." in name else name


def attachment(filename: str) -> dict[str, str]:
    """The header naming a download ``filename`` (any characters)."""
    fallback = "".join(c if c.isascii() and (c.isalnum() or c in "-_. ") else "_" for c in filename)
    return {
        "Content-Disposition": (
            f"attachment; filename=\"{fallback}\"; filename*=UTF-8''{quote(filename, safe='')}"
        )
    }
