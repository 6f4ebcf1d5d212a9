"""``mocapqa info``: what a file holds."""

from __future__ import annotations
