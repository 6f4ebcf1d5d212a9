"""The twist data files shipped with the package (``mocapqa/data/twist``)."""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

__all__ = ["shipped_json"]


def shipped_json(name: str) -> tuple[Any, str]:
    """The parsed content of the shipped file ``name`` and where it was read (for messages)."""
    resource = resources.files("mocapqa") / "data" / "twist" / name
    return json.loads(resource.read_text(encoding="utf-8")), str(resource)
