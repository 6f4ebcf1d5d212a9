"""Unusual and hostile variants of real BVH takes, built from corpus files inside the tests.

:class:`Take` splits a corpus file into its hierarchy lines, frame time and frame rows, cut to a
few frames so each variant reads quickly; the functions here rewrite it the ways real exporters
(and broken or hostile files) do. Nothing is copied into the project: every variant is made
from the corpus at test time, with a seeded generator where anything is random.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

WALK = "bvh/cmu/cmu_12_01_walk.bvh"
"""CMU 12_01: 31 joints, ZYX, tabs, mixed CRLF/LF, 120 fps."""
BANDAI = "bvh/bandai/dataset-1_bow_sad_001.bvh"
"""Bandai: 22 joints with 6 channels each (position channels on every joint), ZXY, 30 fps."""
CHARACTER_CREATOR = "bvh/cmu/iclone/002_03.bvh"
"""Character Creator, the ``RL_BoneRoot`` variant: 100 joints, a Z-up hip turned Y-up by the
root's -90° X rotation."""


@dataclass(frozen=True)
class Take:
    """A BVH file as hierarchy lines (before ``MOTION``), frame time text and frame rows."""

    hierarchy: tuple[str, ...]
    frame_time: str
    rows: tuple[str, ...]

    @classmethod
    def load(cls, path: Path, n_frames: int, start: int = 0) -> Take:
        """``n_frames`` frames of a BVH file from frame ``start`` (blank lines dropped)."""
        return cls.parse(path.read_text(encoding="utf-8"), n_frames, start)

    @classmethod
    def parse(cls, text: str, n_frames: int | None = None, start: int = 0) -> Take:
        """``n_frames`` frames (all when None) of BVH text from frame ``start``."""
        lines = text.splitlines()
        motion = next(i for i, line in enumerate(lines) if line.strip() == "MOTION")
        body = [line.strip() for line in lines[motion + 1 :] if line.strip()]
        assert body[0].startswith("Frames:")
        assert body[1].startswith("Frame Time:")
        frame_time = body[1].split(":", 1)[1].strip()
        stop = len(body) if n_frames is None else 2 + start + n_frames
        rows = tuple(body[2 + start : stop])
        assert n_frames is None or len(rows) == n_frames
        return cls(tuple(line.rstrip() for line in lines[:motion]), frame_time, rows)

    def text(self, newline: str = "\n", frames: int | None = None) -> str:
        """The BVH text; ``frames`` overrides the ``Frames:`` count written."""
        count = len(self.rows) if frames is None else frames
        lines = [
            *self.hierarchy,
            "MOTION",
            f"Frames: {count}",
            f"Frame Time: {self.frame_time}",
            *self.rows,
        ]
        return newline.join(lines) + newline

    def data(self, newline: str = "\n", frames: int | None = None) -> bytes:
        """:meth:`text` as UTF-8 bytes."""
        return self.text(newline, frames).encode("utf-8")

    def with_rows(self, rows: list[str]) -> Take:
        """The same hierarchy with other frame rows."""
        return replace(self, rows=tuple(rows))

    def joint_names(self) -> list[str]:
        """The ROOT and JOINT names in file order."""
        return [m.group(2) for line in self.hierarchy if (m := _JOINT_LINE.match(line))]

    def renamed(self, names: dict[str, str]) -> Take:
        """Joints renamed (``old -> new``) on their ROOT/JOINT lines."""

        def rename(line: str) -> str:
            match = _JOINT_LINE.match(line)
            if match is None or match.group(2) not in names:
                return line
            return f"{match.group(1)}{names[match.group(2)]}"

        return replace(self, hierarchy=tuple(map(rename, self.hierarchy)))


_JOINT_LINE = re.compile(r"^(\s*(?:ROOT|JOINT)\s+)(\S+)\s*$")

KEYWORDS_MIXED_CASE = {
    "HIERARCHY": "Hierarchy",
    "ROOT": "root",
    "JOINT": "Joint",
    "OFFSET": "offset",
    "CHANNELS": "Channels",
    "End Site": "END SITE",
    "position": "POSITION",
    "rotation": "Rotation",
}
"""Keyword spellings of hand-edited and odd exporters' files."""


def mixed_case(take: Take) -> bytes:
    """Keywords, channel names and the MOTION header in other cases."""

    def recase(line: str) -> str:
        for word, other in KEYWORDS_MIXED_CASE.items():
            line = re.sub(rf"\b{word}\b" if word.isupper() else word, other, line)
        return line

    text = "\n".join(map(recase, take.hierarchy))
    rows = "\n".join(take.rows)
    return (
        f"{text}\nMotion\nframes: {len(take.rows)}\nFRAME TIME: {take.frame_time}\n{rows}\n"
    ).encode()


def tabs(take: Take) -> bytes:
    """Tabs for indentation and between every value, header and frames alike."""
    lines = [re.sub(r"[ ]+", "\t", line.replace("    ", "\t")) for line in take.hierarchy]
    rows = ["\t".join(row.split()) for row in take.rows]
    return (
        "\n".join(
            [*lines, "MOTION", f"Frames:\t{len(rows)}", f"Frame Time:\t{take.frame_time}", *rows]
        ).encode()
        + b"\n"
    )


def scientific(take: Take) -> bytes:
    """Every frame value in scientific notation (``1.234560e+01``)."""
    rows = [" ".join(f"{float(v):.15e}" for v in row.split()) for row in take.rows]
    return take.with_rows(rows).data()


def padded(take: Take) -> bytes:
    """Trailing spaces and tabs on every line, blank lines around the sections and at the end."""
    lines = take.text().split("\n")
    motion = lines.index("MOTION")
    out = [line + " \t " for line in lines[:motion]]
    out += ["", "MOTION  ", "", lines[motion + 1] + "  ", lines[motion + 2] + "\t", ""]
    out += [line + "   " for line in lines[motion + 3 :] if line]
    return ("\n".join(out) + "\n\n\n").encode()


def chain(n_joints: int, angle: str = "0") -> bytes:
    """One joint per level, ``n_joints`` deep, one unit apart along +Y; one frame with every
    angle ``angle``."""
    lines = ["HIERARCHY"]
    for j in range(n_joints):
        lines += [f"{'ROOT' if j == 0 else 'JOINT'} J{j}", "{", "OFFSET 0 1 0"]
        lines.append("CHANNELS 3 Zrotation Xrotation Yrotation")
    lines += ["End Site", "{", "OFFSET 0 1 0", "}"]
    lines += ["}"] * n_joints
    lines += ["MOTION", "Frames: 1", "Frame Time: 0.04", " ".join([angle] * (3 * n_joints))]
    return ("\n".join(lines) + "\n").encode()


def fan(n_joints: int) -> bytes:
    """A root with ``n_joints - 1`` children, one frame."""
    lines = [
        "HIERARCHY",
        "ROOT J0",
        "{",
        "OFFSET 0 0 0",
        "CHANNELS 3 Zrotation Xrotation Yrotation",
    ]
    for j in range(1, n_joints):
        lines += [f"JOINT J{j}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
        lines += ["End Site", "{", "OFFSET 0 1 0", "}", "}"]
    lines += ["}", "MOTION", "Frames: 1", "Frame Time: 0.04", " ".join(["1"] * (3 * n_joints))]
    return ("\n".join(lines) + "\n").encode()


def garbage(size: int, seed: int) -> bytes:
    """Random bytes (seeded), as a file with a ``.bvh`` name but no text in it."""
    return np.random.default_rng(seed).integers(0, 256, size=size, dtype=np.uint8).tobytes()


@dataclass(frozen=True)
class _Joint:
    name: str
    root: bool
    offset_line: int
    channels_line: int | None
    channels: tuple[str, ...]
    first_column: int


def _joints(take: Take) -> list[_Joint]:
    """The joints of a take's hierarchy with the lines and columns that hold them."""
    joints: list[dict[str, object]] = []
    stack: list[int | None] = []  # joint index, or None for an End Site
    column = 0
    for number, line in enumerate(take.hierarchy):
        words = line.split()
        if not words:
            continue
        word = words[0].upper()
        if word in ("ROOT", "JOINT"):
            joints.append({"name": " ".join(words[1:]), "root": word == "ROOT"})
            stack.append(len(joints) - 1)
        elif word == "END":
            stack.append(None)
        elif word == "}":
            stack.pop()
        elif stack and stack[-1] is not None:
            joint = joints[stack[-1]]
            if word == "OFFSET":
                joint["offset_line"] = number
            elif word == "CHANNELS":
                joint["channels_line"] = number
                joint["channels"] = tuple(words[2:])
                joint["first_column"] = column
                column += len(words) - 2
    out = []
    for joint in joints:
        joint.setdefault("channels_line", None)
        joint.setdefault("channels", ())
        joint.setdefault("first_column", column)
        out.append(_Joint(**joint))  # type: ignore[arg-type]
    return out


def _values(take: Take) -> np.ndarray:
    return np.array([[float(v) for v in row.split()] for row in take.rows])


def _rows(values: np.ndarray) -> list[str]:
    return [" ".join(repr(float(v)) for v in row) for row in values]


def _rewritten(
    take: Take,
    joints: list[_Joint],
    layout: dict[str, tuple[str, ...]],
    columns: dict[str, np.ndarray],
) -> Take:
    """The take with some joints' CHANNELS lines and columns replaced (by joint name)."""
    hierarchy = list(take.hierarchy)
    values = _values(take)
    blocks = []
    for joint in joints:
        old = values[:, joint.first_column : joint.first_column + len(joint.channels)]
        if joint.name not in layout:
            blocks.append(old)
            continue
        channels = layout[joint.name]
        indent = hierarchy[joint.offset_line][
            : len(hierarchy[joint.offset_line]) - len(hierarchy[joint.offset_line].lstrip())
        ]
        text = f"{indent}CHANNELS {len(channels)} {' '.join(channels)}".rstrip()
        if joint.channels_line is None:
            hierarchy[joint.offset_line] += "\n" + text
        else:
            hierarchy[joint.channels_line] = text
        blocks.append(columns[joint.name])
    new_values = np.concatenate(blocks, axis=1) if blocks else values
    lines = "\n".join(hierarchy).split("\n")
    return Take(tuple(lines), take.frame_time, tuple(_rows(new_values)))


def _split(joint: _Joint, values: np.ndarray) -> tuple[np.ndarray, str, np.ndarray]:
    """A joint's position columns (X, Y, Z order, zeros if none), rotation order and angles."""
    block = values[:, joint.first_column : joint.first_column + len(joint.channels)]
    names = [c.capitalize() for c in joint.channels]
    positions = np.zeros((len(values), 3))
    for axis, name in enumerate(("Xposition", "Yposition", "Zposition")):
        if name in names:
            positions[:, axis] = block[:, names.index(name)]
    rotations = [i for i, c in enumerate(names) if c.endswith("rotation")]
    order = "".join(names[i][0] for i in rotations)
    return positions, order, block[:, rotations]


def _euler(rotation: Rotation, order: str) -> np.ndarray:
    """Intrinsic Euler angles in degrees; at gimbal lock any of the equal triples will do."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        angles: np.ndarray = rotation.as_euler(order, degrees=True)
    return angles


def reordered(take: Take, order: str, positions_last: bool = False) -> Take:
    """Every rotating joint's angles re-expressed in ``order`` (intrinsic, e.g. "XYZ") by
    SciPy, the same rotations; with ``positions_last``, position channels after rotations."""
    joints = _joints(take)
    values = _values(take)
    layout: dict[str, tuple[str, ...]] = {}
    columns: dict[str, np.ndarray] = {}
    for joint in joints:
        if not joint.channels:
            continue
        positions, old, angles = _split(joint, values)
        names = [c.capitalize() for c in joint.channels]
        position_names = tuple(n for n in ("Xposition", "Yposition", "Zposition") if n in names)
        position_values = positions[:, ["XYZ".index(n[0]) for n in position_names]]
        rotation_names: tuple[str, ...] = ()
        rotation_values = np.zeros((len(values), 0))
        if old:
            rotation_names = tuple(f"{axis}rotation" for axis in order)
            rotation_values = _euler(Rotation.from_euler(old, angles, degrees=True), order)
        if positions_last:
            layout[joint.name] = rotation_names + position_names
            columns[joint.name] = np.concatenate([rotation_values, position_values], axis=1)
        else:
            layout[joint.name] = position_names + rotation_names
            columns[joint.name] = np.concatenate([position_values, rotation_values], axis=1)
    return _rewritten(take, joints, layout, columns)


def positions_everywhere(take: Take) -> Take:
    """Position channels added to every joint without them, holding its OFFSET (so the
    skeleton poses exactly as before)."""
    joints = _joints(take)
    values = _values(take)
    layout: dict[str, tuple[str, ...]] = {}
    columns: dict[str, np.ndarray] = {}
    for joint in joints:
        if any(c.lower().endswith("position") for c in joint.channels):
            continue
        offset = [float(v) for v in take.hierarchy[joint.offset_line].split()[1:4]]
        block = values[:, joint.first_column : joint.first_column + len(joint.channels)]
        layout[joint.name] = ("Xposition", "Yposition", "Zposition", *joint.channels)
        columns[joint.name] = np.concatenate([np.tile(offset, (len(values), 1)), block], axis=1)
    return _rewritten(take, joints, layout, columns)


def without_channels(take: Take, name: str, keep_line: bool = True) -> Take:
    """Joint ``name`` with no channels: ``CHANNELS 0``, or no CHANNELS line at all."""
    joints = _joints(take)
    if keep_line:
        return _rewritten(take, joints, {name: ()}, {name: np.zeros((len(take.rows), 0))})
    joint = next(j for j in joints if j.name == name)
    assert joint.channels_line is not None
    values = np.delete(
        _values(take), np.s_[joint.first_column : joint.first_column + len(joint.channels)], axis=1
    )
    hierarchy = [line for i, line in enumerate(take.hierarchy) if i != joint.channels_line]
    return Take(tuple(hierarchy), take.frame_time, tuple(_rows(values)))


Z_UP_TURN = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
"""+90° about X: Y-up world points to Z-up ones (``Z_UP_TURN @ p``)."""


def z_up(take: Take) -> Take:
    """The whole take turned Z-up: each root's OFFSET, position channels and rotation turned
    +90° about X (the rotation re-expressed in the root's own order by SciPy)."""
    joints = _joints(take)
    values = _values(take)
    turn = Rotation.from_matrix(Z_UP_TURN)
    hierarchy = list(take.hierarchy)
    layout: dict[str, tuple[str, ...]] = {}
    columns: dict[str, np.ndarray] = {}
    for joint in joints:
        if not joint.root:
            continue
        words = hierarchy[joint.offset_line].split()
        offset = Z_UP_TURN @ np.array([float(v) for v in words[1:4]])
        indent = hierarchy[joint.offset_line][
            : len(hierarchy[joint.offset_line]) - len(hierarchy[joint.offset_line].lstrip())
        ]
        hierarchy[joint.offset_line] = f"{indent}OFFSET {' '.join(repr(float(v)) for v in offset)}"
        positions, order, angles = _split(joint, values)
        names = [c.capitalize() for c in joint.channels]
        turned_positions = positions @ Z_UP_TURN.T
        turned = _euler(turn * Rotation.from_euler(order, angles, degrees=True), order)
        block = np.empty((len(values), len(names)))
        rotation_at = 0
        for k, name in enumerate(names):
            if name.endswith("position"):
                block[:, k] = turned_positions[:, "XYZ".index(name[0])]
            else:
                block[:, k] = turned[:, rotation_at]
                rotation_at += 1
        layout[joint.name] = tuple(names)
        columns[joint.name] = block
    return _rewritten(replace(take, hierarchy=tuple(hierarchy)), joints, layout, columns)
