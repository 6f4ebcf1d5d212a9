"""Rig mapping files: which joint takes which role, when the names do not say.

A mapping file is JSON or TOML (by its ``.toml`` suffix) holding role key → joint name::

    {"left_upper_arm": "LeftShoulder", "left_forearm": "LeftElbow"}

    # rig.toml
    left_upper_arm = "LeftShoulder"
    left_forearm = "LeftElbow"

Files written the older way round (joint name → role key) are read too. Roles a file does not
name are still found from the joint names and the skeleton's structure.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

from mocapqa.core.json_keys import RepeatedKeyError, unique_keys
from mocapqa.core.rig import normalise_mapping
from mocapqa.errors import InputError, ParseError

__all__ = ["read_mapping"]


def read_mapping(path: Path) -> dict[str, str]:
    """Read a rig mapping file (JSON, or TOML for a ``.toml`` file).

    Returns
    -------
    dict
        Role key → joint name.

    Raises
    ------
    ParseError
        If the file cannot be read, is not valid JSON/TOML, or is not a table of strings whose
        keys (or values) are role keys.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise ParseError(f"Expected a readable UTF-8 mapping file, got {e}", path) from e
    data: object
    if path.suffix.lower() == ".toml":
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise ParseError(f"Expected TOML, got {e}", path) from e
    else:
        try:
            data = json.loads(text, object_pairs_hook=unique_keys)
        except json.JSONDecodeError as e:
            raise ParseError(f"Expected JSON, got {e.msg}", path, e.lineno) from e
        except RepeatedKeyError as e:  # the last would silently win
            raise ParseError(str(e), path) from e
    if not isinstance(data, dict):
        raise ParseError(
            'Expected a table of role → joint name, e.g. {"left_upper_arm": "LeftArm"}, '
            f"got {type(data).__name__}",
            path,
        )
    for key, value in data.items():
        if not isinstance(value, str):
            raise ParseError(
                f"Expected a joint name (a string) for {key!r}, got {type(value).__name__}",
                path,
                field=key,
            )
    try:
        return normalise_mapping(data)
    except InputError as e:
        raise ParseError(str(e), path) from e
