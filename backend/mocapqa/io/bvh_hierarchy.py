"""Reading the HIERARCHY section of a BVH file (the frames are :mod:`mocapqa.io.bvh_frames`).

Conventions
-----------
* Keywords (``HIERARCHY``, ``ROOT``, ``JOINT``, ``OFFSET``, ``CHANNELS``, ``End Site``) and
  channel names are read in any case (``Xrotation``, ``XROTATION``, ``xRotation``); channel
  names are kept in the usual spelling (``Xrotation``).
* A joint's name is the rest of its ``ROOT``/``JOINT`` line, so names with spaces
  (``Bip01 L UpperArm``) read whole, with runs of whitespace as one space; a ``{`` ending the
  line opens the joint. A name alone on the next line is read too.
* Tokens are read lazily and the parser stops at the first error or at :data:`MAX_JOINTS`, so
  a hostile header costs no more than the joints it is allowed.
* Every problem raises :class:`~mocapqa.errors.ParseError` with the 1-based line.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass

from mocapqa.core.bounds import MAX_MAGNITUDE
from mocapqa.core.motion import POSITION_CHANNELS, ROTATION_CHANNELS, EndSite
from mocapqa.errors import ParseError
from mocapqa.io.bvh_frames import quoted

__all__ = ["MAX_JOINTS", "MAX_NAME_CHARS", "Hierarchy", "parse_hierarchy"]

MAX_JOINTS = 1000
"""Largest joint count accepted; more means a corrupt or hostile file."""
MAX_NAME_CHARS = 255
"""Longest joint name accepted (real rigs' longest are under 100 characters)."""
_CHANNELS = {name.lower(): name for name in (*POSITION_CHANNELS, *ROTATION_CHANNELS)}


@dataclass(slots=True)
class Hierarchy:
    """The joints of a BVH hierarchy, in file (depth-first) order."""

    names: list[str]
    parents: list[int]
    offsets: list[tuple[float, float, float]]
    channels: list[tuple[str, ...]]
    end_sites: list[EndSite]


_Token = tuple[str, int]
"""A word of the hierarchy and its 1-based line."""
_LINES_PER_FILL = 512


class _Parser:
    def __init__(self, lines: Iterable[str], path: str, end: str) -> None:
        self.lines = enumerate(lines, start=1)
        self.tokens: list[_Token] = []
        self.pos = 0
        self.last_line = 1
        self.path = path
        self.end = end
        self.hierarchy = Hierarchy([], [], [], [], [])
        self.name_set: set[str] = set()

    def _fail(self, message: str, line: int) -> ParseError:
        return ParseError(message, self.path, line)

    def _fill(self) -> bool:
        """Tokenise the next lines (a few hundred at a time); False when none are left."""
        del self.tokens[: self.pos]
        self.pos = 0
        while not self.tokens:
            chunk = list(itertools.islice(self.lines, _LINES_PER_FILL))
            if not chunk:
                return False
            self.tokens = [(text, number) for number, line in chunk for text in line.split()]
        return True

    def _peek(self) -> _Token | None:
        if self.pos >= len(self.tokens) and not self._fill():
            return None
        return self.tokens[self.pos]

    def _take(self) -> _Token | None:
        if self.pos >= len(self.tokens) and not self._fill():
            return None
        token = self.tokens[self.pos]
        self.pos += 1
        self.last_line = token[1]
        return token

    def _next(self, what: str) -> _Token:
        if self.pos >= len(self.tokens) and not self._fill():
            raise self._fail(f"Expected {what}, got {self.end}", self.last_line)
        token = self.tokens[self.pos]
        self.pos += 1
        self.last_line = token[1]
        return token

    def _expect(self, word: str) -> _Token:
        token = self._next(repr(word))
        if token[0].upper() != word.upper():
            raise self._fail(f"Expected {word!r}, got {quoted(token[0])}", token[1])
        return token

    def _number(self, what: str) -> float:
        text, line = self._next(what)
        try:
            value = float(text)
        except ValueError:
            raise self._fail(f"Expected a number for {what}, got {quoted(text)}", line) from None
        if not math.isfinite(value):
            raise self._fail(f"Expected a finite number for {what}, got {quoted(text)}", line)
        if abs(value) > MAX_MAGNITUDE:
            raise self._fail(
                f"Expected {what} within ±{int(MAX_MAGNITUDE):,}, got {quoted(text)}", line
            )
        return value

    def parse(self) -> Hierarchy:
        first = self._take()
        if first is None:
            raise self._fail("Expected a BVH file starting with 'HIERARCHY', got an empty file", 1)
        if first[0].upper() != "HIERARCHY":
            raise self._fail(f"Expected 'HIERARCHY', got {quoted(first[0])}", first[1])
        token: _Token | None = self._next("'ROOT'")
        while token is not None and token[0].upper() == "ROOT":
            self._joint(token, parent=-1)
            token = self._take()
        if token is not None:
            expected = "'ROOT' or 'MOTION'" if self.hierarchy.names else "'ROOT'"
            raise self._fail(f"Expected {expected}, got {quoted(token[0])}", token[1])
        return self.hierarchy

    def _name(self, keyword: _Token) -> tuple[str, bool]:
        """The joint name after ``keyword`` and whether its line also opened the joint."""
        words: list[str] = []
        while (token := self._peek()) is not None and token[1] == keyword[1]:
            words.append(token[0])
            self.pos += 1
        opened = len(words) > 1 and words[-1] == "{"
        if opened:
            words.pop()
        if not words:  # the name on a line of its own
            words = [self._next("a joint name")[0]]
        name = " ".join(words)
        if name == "{":
            raise self._fail("Expected a joint name, got '{'", keyword[1])
        return name, opened

    def _open_joint(self, keyword: _Token, parent: int) -> int:
        name, opened = self._name(keyword)
        hierarchy = self.hierarchy
        if len(name) > MAX_NAME_CHARS:
            raise self._fail(
                f"Expected a joint name of at most {MAX_NAME_CHARS} characters, got {len(name)}",
                keyword[1],
            )
        if name in self.name_set:
            raise self._fail(f"Expected unique joint names, got {quoted(name)} twice", keyword[1])
        if len(hierarchy.names) >= MAX_JOINTS:
            raise self._fail(f"Expected at most {MAX_JOINTS} joints, got more", keyword[1])
        index = len(hierarchy.names)
        hierarchy.names.append(name)
        self.name_set.add(name)
        hierarchy.parents.append(parent)
        hierarchy.offsets.append((0.0, 0.0, 0.0))
        hierarchy.channels.append(())
        if not opened:
            self._expect("{")
        return index

    def _channels(self) -> tuple[str, ...]:
        count_text, count_line = self._next("a channel count")
        try:
            count = int(count_text)
        except ValueError:
            raise self._fail(
                f"Expected a channel count, got {quoted(count_text)}", count_line
            ) from None
        if not 0 <= count <= 6:
            raise self._fail(f"Expected 0 to 6 channels, got {count}", count_line)
        names = []
        for _ in range(count):
            text, line = self._next("a channel name")
            channel = _CHANNELS.get(text.lower())
            if channel is None:
                raise self._fail(
                    f"Expected a channel name like 'Xrotation', got {quoted(text)}", line
                )
            names.append(channel)
        rotations = [c for c in names if c in ROTATION_CHANNELS]
        if len(set(names)) != len(names) or len(rotations) not in (0, 3):
            raise self._fail(
                f"Expected 0 or 3 distinct rotation channels, got {' '.join(names)}", count_line
            )
        return tuple(names)

    def _end_site(self, index: int) -> None:
        self._expect("Site")
        self._expect("{")
        self._expect("OFFSET")
        offset = (
            self._number("End Site x"),
            self._number("End Site y"),
            self._number("End Site z"),
        )
        self._expect("}")
        self.hierarchy.end_sites.append(EndSite(index, offset))

    def _joint(self, keyword: _Token, parent: int) -> None:
        """Parse a joint and its descendants; iterative, so deep chains cannot overflow."""
        hierarchy = self.hierarchy
        stack: list[tuple[int, _Token, bool]] = [
            (self._open_joint(keyword, parent), keyword, False)
        ]
        while stack:
            index, opened_by, seen_offset = stack[-1]
            token = self._next("'OFFSET', 'CHANNELS', 'JOINT', 'End' or '}'")
            word = token[0].upper()
            if word == "OFFSET":
                hierarchy.offsets[index] = (
                    self._number("OFFSET x"),
                    self._number("OFFSET y"),
                    self._number("OFFSET z"),
                )
                stack[-1] = (index, opened_by, True)
            elif word == "CHANNELS":
                hierarchy.channels[index] = self._channels()
            elif word == "JOINT":
                stack.append((self._open_joint(token, index), token, False))
            elif word == "END":
                self._end_site(index)
            elif word == "}":
                if not seen_offset:
                    name = hierarchy.names[index]
                    raise self._fail(f"Expected an OFFSET for joint {quoted(name)}", opened_by[1])
                stack.pop()
            else:
                expected = "'OFFSET', 'CHANNELS', 'JOINT', 'End' or '}'"
                raise self._fail(f"Expected {expected}, got {quoted(token[0])}", token[1])


def parse_hierarchy(lines: Iterable[str], path: str, end: str) -> Hierarchy:
    """Parse the hierarchy from the lines before ``MOTION``.

    Parameters
    ----------
    lines : iterable of str
        The file's lines before the ``MOTION`` line (or all of them when it has none), read
        only as far as needed.
    path : str
        File name for error messages.
    end : str
        What running out of lines means, for the message (e.g. ``"end of hierarchy
        (truncated file?)"``).

    Returns
    -------
    Hierarchy

    Raises
    ------
    ParseError
        On any malformed hierarchy, with the 1-based line.
    """
    return _Parser(lines, path, end).parse()
