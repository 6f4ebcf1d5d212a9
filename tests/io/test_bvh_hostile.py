"""Takes users bring, made from real corpus files in the test (``tests/io/bvh_variants.py``).

Unusual but valid files read to the same poses as their source, checked through forward
kinematics; malformed, huge and hostile ones raise a ParseError naming the file and line (or
field). The commands that read a BVH are run on a few key variants of each kind: a bad file
ends in one line on stderr and exit code 3, never a traceback; an unusual one gives the same
findings as its source.
"""

from __future__ import annotations

import codecs
import csv
import json
import re
import tracemalloc
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from tests.io.bvh_variants import (
    BANDAI,
    CHARACTER_CREATOR,
    WALK,
    Z_UP_TURN,
    Take,
    chain,
    fan,
    garbage,
    mixed_case,
    padded,
    positions_everywhere,
    reordered,
    scientific,
    tabs,
    without_channels,
    z_up,
)

from mocapqa.cli.main import main
from mocapqa.core.motion import Motion
from mocapqa.core.rig import find_roles
from mocapqa.errors import ParseError
from mocapqa.io.bvh import NumberReader, parse_bvh
from mocapqa.io.bvh_hierarchy import MAX_JOINTS
from mocapqa.io.bvh_write import format_bvh
from mocapqa.io.formats import detect_format, read_take
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.render.scene import track_from_motion

READERS: tuple[NumberReader, ...] = ("arrow", "python")
RIGS = ("walk", "bandai", "cc")


@pytest.fixture(scope="module")
def takes(corpus_dir: Path) -> dict[str, Take]:
    """Six frames of each rig, from the middle of the take (the CMU walk's frame 0 is a
    T-pose)."""
    return {
        "walk": Take.load(corpus_dir / WALK, 6, start=100),
        "bandai": Take.load(corpus_dir / BANDAI, 6, start=60),
        "cc": Take.load(corpus_dir / CHARACTER_CREATOR, 6, start=20),
    }


def positions(motion: Motion) -> np.ndarray:
    """World joint positions ``(F, J, 3)``."""
    return forward_kinematics(motion)[1]


def assert_same_poses(variant: Motion, source: Motion, turn: np.ndarray | None = None) -> None:
    """The same joints in the same world positions (turned by ``turn`` when given)."""
    assert variant.skeleton.names == source.skeleton.names
    assert variant.n_frames == source.n_frames
    expected = positions(source)
    if turn is not None:
        expected = expected @ turn.T
    scale = float(np.abs(expected).max())
    np.testing.assert_allclose(positions(variant), expected, rtol=0, atol=1e-9 * scale)


def assert_same_take(variant: Motion, source: Motion) -> None:
    """The same hierarchy, channels, rotations and translations."""
    a, b = variant.skeleton, source.skeleton
    assert (a.names, a.channels, a.end_sites) == (b.names, b.channels, b.end_sites)
    np.testing.assert_array_equal(a.parents, b.parents)
    np.testing.assert_array_equal(a.offsets, b.offsets)
    assert variant.fps == source.fps
    np.testing.assert_allclose(variant.quats, source.quats, rtol=0, atol=1e-12)
    np.testing.assert_allclose(variant.translations, source.translations, rtol=1e-12, atol=0)


def brace_on_joint_line(take: Take) -> bytes:
    """``JOINT Name {`` on one line, as some exporters write it."""
    lines: list[str] = []
    for line in take.hierarchy:
        if line.strip() == "{" and lines and re.match(r"\s*(ROOT|JOINT)\s", lines[-1]):
            lines[-1] += " {"
        else:
            lines.append(line)
    return replace(take, hierarchy=tuple(lines)).data()


FORMATTING: dict[str, Callable[[Take], bytes]] = {
    "CRLF": lambda take: take.data("\r\n"),
    "CR only": lambda take: take.data("\r"),
    "tabs": tabs,
    "mixed-case keywords": mixed_case,
    "scientific notation": scientific,
    "trailing spaces and blank lines": padded,
    "UTF-8 byte order mark": lambda take: codecs.BOM_UTF8 + take.data(),
    "UTF-16 with byte order mark": lambda take: take.text().encode("utf-16"),
    "brace on the joint line": brace_on_joint_line,
}


@pytest.mark.parametrize("reader", READERS)
@pytest.mark.parametrize("variant", sorted(FORMATTING))
@pytest.mark.parametrize("rig", RIGS)
def test_formatting_variants_read_the_same_take(
    takes: dict[str, Take], rig: str, variant: str, reader: NumberReader
) -> None:
    take = takes[rig]
    source = parse_bvh(take.data(), number_reader=reader)
    assert_same_take(parse_bvh(FORMATTING[variant](take), number_reader=reader), source)


@pytest.mark.parametrize("variant", ["mixed-case keywords", "UTF-16 with byte order mark"])
def test_a_variant_without_the_bvh_extension_is_known_by_its_content(
    takes: dict[str, Take], tmp_path: Path, variant: str
) -> None:
    path = tmp_path / "take.txt"
    path.write_bytes(FORMATTING[variant](takes["walk"]))
    assert detect_format(path) == "bvh"
    assert_same_take(read_take(path), parse_bvh(takes["walk"].data()))  # type: ignore[arg-type]


BIPED = {
    "Hips": "Bip01 Pelvis",
    "Spine": "Bip01 Spine",
    "Neck": "Bip01 Neck",
    "Head": "Bip01 Head",
    **{
        f"{side}{cmu}": f"Bip01 {side[0]} {biped}"
        for side in ("Left", "Right")
        for cmu, biped in (
            ("UpLeg", "Thigh"),
            ("Leg", "Calf"),
            ("Foot", "Foot"),
            ("ToeBase", "Toe0"),
            ("Shoulder", "Clavicle"),
            ("Arm", "UpperArm"),
            ("ForeArm", "Forearm"),
            ("Hand", "Hand"),
        )
    },
}
"""The CMU walk's joints renamed as 3ds Max Biped names them (with spaces)."""


def test_joint_names_with_spaces_read_whole_and_find_their_roles(takes: dict[str, Take]) -> None:
    source = parse_bvh(takes["walk"].data())
    motion = parse_bvh(takes["walk"].renamed(BIPED).data())
    assert motion.skeleton.names == tuple(BIPED.get(n, n) for n in source.skeleton.names)
    assert_same_take(replace(motion, skeleton=source.skeleton), source)
    roles = find_roles(motion.skeleton)
    assert motion.skeleton.names[roles.joint("left", "upper_arm")] == "Bip01 L UpperArm"  # type: ignore[index]
    assert motion.skeleton.names[roles.joint("right", "lower_leg")] == "Bip01 R Calf"  # type: ignore[index]
    again = parse_bvh(format_bvh(motion))
    assert again.skeleton.names == motion.skeleton.names


def test_non_ascii_joint_names_read_and_write_back(takes: dict[str, Take]) -> None:
    names = {"LeftArm": "Linker Oberarm ü", "Head": "頭", "Spine": "Позвоночник"}
    motion = parse_bvh(takes["walk"].renamed(names).data())
    assert set(names.values()) <= set(motion.skeleton.names)
    assert parse_bvh(format_bvh(motion).encode()).skeleton.names == motion.skeleton.names


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
@pytest.mark.parametrize("rig", RIGS)
def test_any_channel_order_gives_the_same_world_poses(
    takes: dict[str, Take], rig: str, order: str
) -> None:
    """Angles re-expressed by SciPy in another order (position channels after the rotations
    for half of them) pose every joint where the source does."""
    take = takes[rig]
    variant = reordered(take, order, positions_last=order[0] in "XY")
    motion = parse_bvh(variant.data())
    rotating = [c for c in motion.skeleton.channels if any(n.endswith("rotation") for n in c)]
    assert {"".join(n[0] for n in c if n.endswith("rotation")) for c in rotating} == {order}
    assert_same_poses(motion, parse_bvh(take.data()))


@pytest.mark.parametrize("rig", RIGS)
def test_position_channels_on_every_joint_pose_as_their_offsets(
    takes: dict[str, Take], rig: str
) -> None:
    motion = parse_bvh(positions_everywhere(takes[rig]).data())
    assert all(motion.skeleton.has_position_channels(j) for j in range(motion.skeleton.n_joints))
    assert_same_poses(motion, parse_bvh(takes[rig].data()))


@pytest.mark.parametrize("keep_line", [True, False], ids=["CHANNELS 0", "no CHANNELS line"])
@pytest.mark.parametrize(("rig", "joint"), [("walk", "LeftLeg"), ("cc", "CC_Base_L_Calf")])
def test_a_joint_without_channels_stays_at_its_rest_rotation(
    takes: dict[str, Take], rig: str, joint: str, keep_line: bool
) -> None:
    source = parse_bvh(takes[rig].data())
    motion = parse_bvh(without_channels(takes[rig], joint, keep_line).data())
    index = source.skeleton.index(joint)
    assert motion.skeleton.channels[index] == ()
    quats = source.quats.copy()
    quats[:, index] = [0.0, 0.0, 0.0, 1.0]
    rest = replace(source, quats=quats, skeleton=motion.skeleton)
    assert_same_poses(motion, rest)


@pytest.mark.parametrize("rig", RIGS)
def test_a_z_up_take_poses_turned_and_is_drawn_z_up(takes: dict[str, Take], rig: str) -> None:
    source = parse_bvh(takes[rig].data())
    motion = parse_bvh(z_up(takes[rig]).data())
    assert_same_poses(motion, source, turn=Z_UP_TURN)
    assert track_from_motion(source).up_axis == "+y"
    assert track_from_motion(motion).up_axis == "+z"


@pytest.mark.parametrize("n_frames", [0, 1, 2])
def test_takes_of_zero_one_and_two_frames_read(takes: dict[str, Take], n_frames: int) -> None:
    take = takes["walk"]
    motion = parse_bvh(take.with_rows(list(take.rows[:n_frames])).data())
    assert motion.n_frames == n_frames
    assert positions(motion).shape == (n_frames, 31, 3)


def test_two_roots_read_as_two_skeletons(takes: dict[str, Take]) -> None:
    """Two characters in one file: a second ROOT, its channels after the first's."""
    take = takes["walk"]
    other = take.renamed({name: f"B {name}" for name in take.joint_names()})
    rows = tuple(f"{a} {b}" for a, b in zip(take.rows, other.rows, strict=True))
    both = Take((*take.hierarchy, *other.hierarchy[1:]), take.frame_time, rows)
    motion = parse_bvh(both.data())
    assert motion.skeleton.n_joints == 62
    assert list(np.flatnonzero(motion.skeleton.parents < 0)) == [0, 31]
    world = positions(motion)
    np.testing.assert_array_equal(world[:, :31], world[:, 31:])
    np.testing.assert_allclose(world[:, :31], positions(parse_bvh(take.data())), atol=1e-9)


def test_the_deepest_and_widest_allowed_hierarchies_read() -> None:
    deep = parse_bvh(chain(MAX_JOINTS))
    np.testing.assert_allclose(positions(deep)[0, :, 1], np.arange(1, MAX_JOINTS + 1))
    wide = parse_bvh(fan(MAX_JOINTS))
    assert np.all(wide.skeleton.parents[1:] == 0)


def cut_row(take: Take) -> bytes:
    """The file cut in the middle of its last frame line."""
    text = take.text()
    return text[: len(text) - len(take.rows[-1]) // 2].encode()


def value(take: Take, row: int, text: str) -> bytes:
    """The take with the first value of frame ``row`` replaced by ``text``."""
    rows = list(take.rows)
    rows[row] = f"{text} {rows[row].split(' ', 1)[1]}"
    return take.with_rows(rows).data()


def frame_time(take: Take, text: str) -> bytes:
    return replace(take, frame_time=text).data()


def hierarchy_line(take: Take, text: str) -> int:
    """The 1-based line of the first hierarchy line containing ``text``."""
    return 1 + next(i for i, line in enumerate(take.hierarchy) if text in line)


# Each case: the bytes and the message expected, from the walk's 6 frames. H is the number of
# hierarchy lines: MOTION is on line H + 1, Frames: on H + 2, Frame Time: on H + 3 and frame
# k (0-based) on H + 4 + k.
MALFORMED: dict[str, Callable[[Take, int], tuple[bytes, str]]] = {
    "Frames: larger than the rows": lambda t, h: (
        t.data(frames=8),
        rf"line {h + 10}: Expected 8 frame lines \(Frames:\), got 6 \(truncated file\?\)",
    ),
    "Frames: smaller than the rows": lambda t, h: (
        t.data(frames=4),
        rf"line {h + 8}: Expected 4 frame lines \(Frames:\), got more",
    ),
    "a row with too few values": lambda t, h: (
        t.with_rows([*t.rows[:2], t.rows[2].rsplit(" ", 1)[0], *t.rows[3:]]).data(),
        rf"line {h + 6}: Expected 96 values on a frame line, got 95$",
    ),
    "a row with too many values": lambda t, h: (
        t.with_rows([*t.rows[:2], t.rows[2] + " 0", *t.rows[3:]]).data(),
        rf"line {h + 6}: Expected 96 values on a frame line, got 97",
    ),
    "nan": lambda t, h: (value(t, 1, "nan"), rf"line {h + 5}: Expected finite numbers"),
    "inf": lambda t, h: (value(t, 1, "-inf"), rf"line {h + 5}: Expected finite numbers"),
    "1e400": lambda t, h: (value(t, 1, "1e400"), rf"line {h + 5}: Expected finite numbers"),
    "1e308": lambda t, h: (
        value(t, 3, "1e308"),
        rf"line {h + 7}: Expected values within ±1,000,000,000, got '1e308'",
    ),
    "OFFSET 1e308": lambda t, h: (
        replace(t, hierarchy=(*t.hierarchy[:3], "\tOFFSET 1e308 0 0", *t.hierarchy[4:])).data(),
        r"line 4: Expected OFFSET x within ±1,000,000,000, got '1e308'",
    ),
    "duplicate joint names": lambda t, h: (
        t.renamed({"LeftArm": "RightArm"}).data(),
        rf"line {hierarchy_line(t, 'RightArm')}: Expected unique joint names, got 'RightArm'",
    ),
    "a 100,000-character joint name": lambda t, h: (
        t.renamed({"LeftArm": "x" * 100_000}).data(),
        rf"line {hierarchy_line(t, 'LeftArm')}: Expected a joint name of at most 255 characters, "
        "got 100000",
    ),
    "a megabyte of letters in a frame": lambda t, h: (
        value(t, 1, "z" * 1_000_000),
        rf"line {h + 5}: Expected a number, got '{'z' * 40}'…$",
    ),
    "no MOTION section": lambda t, h: (
        "\n".join(t.hierarchy).encode(),
        rf"line {h}: Expected a 'MOTION' section, got end of file",
    ),
    "no MOTION line before the frames": lambda t, h: (
        t.text().replace("MOTION\n", "").encode(),
        rf"line {h + 1}: Expected 'ROOT' or 'MOTION', got 'Frames:'",
    ),
    "cut in the middle of a frame line": lambda t, h: (
        cut_row(t),
        rf"line {h + 9}: Expected 96 values on a frame line, got \d+ \(truncated file\?\)",
    ),
    "cut in the hierarchy": lambda t, h: (
        "\n".join(t.hierarchy[:40]).encode(),
        r"line 40: Expected .*, got end of file \(truncated file\?\)",
    ),
    "cut in the middle of a word": lambda t, h: (
        t.data()[:300],
        r"line \d+: Expected .*",
    ),
    "an empty file": lambda t, h: (
        b"",
        r"line 1: Expected a BVH file starting with 'HIERARCHY', got an empty file",
    ),
    "only blank lines": lambda t, h: (
        b"\n \r\n\t\n",
        r"line 1: Expected a BVH file starting with 'HIERARCHY', got an empty file",
    ),
    "random bytes": lambda t, h: (
        garbage(4096, seed=7),
        r"line 1: Expected a text file, got binary data \(NUL bytes\)",
    ),
    "random printable text": lambda t, h: (
        bytes(np.random.default_rng(8).integers(33, 127, size=4096, dtype=np.uint8)),
        r"line 1: Expected 'HIERARCHY', got '",
    ),
    "a JSON file named .bvh": lambda t, h: (
        b'{"fps": 30, "frames": []}\n',
        r"line 1: Expected 'HIERARCHY', got '\{\"fps\":'",
    ),
    "Latin-1 joint name": lambda t, h: (
        t.renamed({"LeftArm": "LinkerOberarmü"}).text().encode("latin-1"),
        rf"line {hierarchy_line(t, 'LeftArm')}: Expected UTF-8 or ASCII text",
    ),
    "UTF-16 cut in the middle of a character": lambda t, h: (
        t.text().encode("utf-16")[:-1],
        rf"line {h + 9}: Expected UTF-16 text after its byte order mark, got undecodable",
    ),
    "5,000 joints deep": lambda t, h: (
        chain(5000),
        rf"line {2 + 4 * MAX_JOINTS}: Expected at most {MAX_JOINTS} joints, got more",
    ),
    "20,000 joints wide": lambda t, h: (
        fan(20_000),
        rf"line {6 + 9 * (MAX_JOINTS - 1)}: Expected at most {MAX_JOINTS} joints, got more",
    ),
}


BAD_FRAME_TIMES = {
    "0": r"Expected a frame time > 0 s, got '0'",
    "-0.01": r"Expected a frame time > 0 s, got '-0.01'",
    "1e-6": r"Expected a frame time from 1e-05 to 10 s, got '1e-6'$",
    "5e-324": r"Expected a frame time from 1e-05 to 10 s, got '5e-324'",
    "1000": r".* got '1000' \(a frame rate\? .* 0.001 for 1000 fps\)",
}
"""Frame Time texts and the message each gets on the Frame Time line."""
for _text, _message in BAD_FRAME_TIMES.items():
    MALFORMED[f"Frame Time: {_text}"] = lambda t, h, text=_text, message=_message: (
        frame_time(t, text),
        rf"line {h + 3}: {message}",
    )


@pytest.mark.parametrize("reader", READERS)
@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_files_name_the_file_and_line(
    takes: dict[str, Take], case: str, reader: NumberReader
) -> None:
    take = takes["walk"]
    data, pattern = MALFORMED[case](take, len(take.hierarchy))
    with pytest.raises(ParseError, match=rf"^take\.bvh, {pattern}") as info:
        parse_bvh(data, "take.bvh", number_reader=reader)
    assert info.value.line is not None


@pytest.mark.parametrize("reader", READERS)
def test_a_huge_frame_count_is_not_allocated_before_the_rows(
    takes: dict[str, Take], reader: NumberReader
) -> None:
    take = takes["walk"]
    data = take.data(frames=10_000_000_000)
    tracemalloc.start()
    try:
        with pytest.raises(ParseError, match=r"Expected 10000000000 frame lines"):
            parse_bvh(data, "take.bvh", number_reader=reader)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6, f"{peak / 1e6:.0f} MB for a 6-frame file"


def test_a_hostile_hierarchy_is_refused_at_the_joint_limit_without_reading_on() -> None:
    """20,000 joints: tokens are read as far as the 1001st joint, not the whole header."""
    data = fan(20_000)
    tracemalloc.start()
    try:
        with pytest.raises(ParseError, match="at most"):
            parse_bvh(data, "wide.bvh")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 4 * len(data) + 5e6, f"{peak / 1e6:.1f} MB for a {len(data) / 1e6:.1f} MB file"


# The commands that read a BVH, with their output arguments.
COMMANDS: dict[str, Callable[[Path, Path], list[str]]] = {
    "info": lambda take, out: ["info", str(take)],
    "detect": lambda take, out: ["detect", str(take)],
    "refine": lambda take, out: ["refine", str(take), "-o", str(out / "refined.bvh")],
    "filter": lambda take, out: ["filter", str(take), "-o", str(out / "filtered.bvh")],
    "convert": lambda take, out: ["convert", str(take), "-o", str(out / "converted.bvh")],
    "limits check": lambda take, out: ["limits", "check", str(take)],
    "report": lambda take, out: ["report", str(take), "-o", str(out / "report.html")],
    "render": lambda take, out: [
        *("render", str(take), "--frame", "0", "-o", str(out / "still.png")),
        *("--width", "96", "--height", "72"),
    ],
}
COMMAND_CASES = [
    pytest.param(name, marks=pytest.mark.render) if name == "render" else name for name in COMMANDS
]
BAD_FOR_COMMANDS: dict[str, tuple[Callable[[Take], bytes], str]] = {
    "1e308 in a frame": (lambda t: value(t, 3, "1e308"), r"line \d+: Expected values within"),
    "Frames: 0": (lambda t: t.with_rows([]).data(), r"field 'Frames': Expected at least one"),
    "random bytes": (lambda t: garbage(2048, seed=3), r"line 1: Expected a text file"),
    "cut in a frame line": (cut_row, r"line \d+: Expected 96 values .*\(truncated file\?\)"),
}
ALLOWED_ON_EMPTY = {"info", "convert"}
"""Commands that describe or copy a take, so a rig without frames is fine for them."""


@pytest.mark.parametrize("case", sorted(BAD_FOR_COMMANDS))
@pytest.mark.parametrize("command", COMMAND_CASES)
def test_every_command_refuses_a_bad_take_in_one_line(
    takes: dict[str, Take],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    command: str,
    case: str,
) -> None:
    build, pattern = BAD_FOR_COMMANDS[case]
    path = tmp_path / "bad take.bvh"
    path.write_bytes(build(takes["walk"]))
    code = main(COMMANDS[command](path, tmp_path))
    err = capsys.readouterr().err
    if case == "Frames: 0" and command in ALLOWED_ON_EMPTY:
        assert code == 0, err
        return
    assert code == 3, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert re.match(rf"error: {re.escape(str(path))}, {pattern}", lines[0]), lines[0]


@pytest.mark.parametrize(
    "command", [c for c in COMMAND_CASES if c not in ("info", "detect", "limits check")]
)
def test_an_output_in_a_missing_folder_is_one_line(
    takes: dict[str, Take], tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    path = tmp_path / "take.bvh"
    path.write_bytes(takes["walk"].data())
    missing = tmp_path / "no such folder"
    code = main(COMMANDS[command](path, missing))
    err = capsys.readouterr().err
    assert code == 3, err
    assert re.fullmatch(
        "error: Expected a writable output path, got No such file or directory: "
        rf"{re.escape(str(missing))}/\S+\n",
        err,
    ), err


@pytest.fixture(scope="module")
def odd_take(takes: dict[str, Take], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The walk as an odd exporter might write it: Biped names with spaces, XYZ order with
    position channels on every joint, mixed-case keywords, tabs and CRLF."""
    take = positions_everywhere(reordered(takes["walk"].renamed(BIPED), "XYZ"))
    path = tmp_path_factory.mktemp("odd") / "odd.bvh"
    path.write_bytes(mixed_case(Take.parse(tabs(take).decode())).replace(b"\n", b"\r\n"))
    return path


@pytest.mark.parametrize("command", COMMAND_CASES)
def test_every_command_reads_an_odd_but_valid_take(
    odd_take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    code = main(COMMANDS[command](odd_take, tmp_path))
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "Traceback" not in captured.err


def test_batch_fails_only_the_bad_takes_naming_their_lines(
    takes: dict[str, Take],
    odd_take: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    folder = tmp_path / "takes"
    folder.mkdir()
    (folder / "odd.bvh").write_bytes(odd_take.read_bytes())
    for name, (build, _) in BAD_FOR_COMMANDS.items():
        (folder / f"{name}.bvh").write_bytes(build(takes["walk"]))
    monkeypatch.setenv("MOCAPQA_DATA_DIR", str(tmp_path / "data"))
    table = tmp_path / "results.csv"
    code = main(["batch", str(folder), "--workers", "1", "--output", str(table)])
    assert code == 2, capsys.readouterr().err
    rows = {Path(row["source"]).stem: row for row in csv.DictReader(table.open())}
    assert rows.pop("odd")["status"] == "done"
    assert set(rows) == set(BAD_FOR_COMMANDS)
    for name, row in rows.items():
        assert row["status"] == "failed"
        where = re.escape(str(folder / f"{name}.bvh"))
        assert re.match(rf"{where}, {BAD_FOR_COMMANDS[name][1]}", row["error"]), row["error"]


@pytest.fixture(scope="module")
def twisted(corpus_dir: Path) -> Take:
    """One second of the walk with seeded twist errors injected, so detect has findings."""
    from mocapqa.twist.inject import inject_twist_errors

    source = parse_bvh(Take.load(corpus_dir / WALK, 120, start=100).data())
    corrupted, _ = inject_twist_errors(source, np.random.default_rng(4), max_offset_deg=170.0)
    return Take.parse(format_bvh(corrupted))


def findings(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    """A command's JSON output, without the input path."""
    assert main([*args, "--json"]) == 0
    data = dict(json.loads(capsys.readouterr().out))
    data.pop("input", None)
    return data


@pytest.mark.parametrize(
    "variant",
    [
        pytest.param(lambda t: reordered(t, "YZX", positions_last=True).data(), id="YZX order"),
        pytest.param(lambda t: z_up(t).data(), id="Z-up"),
        pytest.param(lambda t: mixed_case(positions_everywhere(t)), id="case and positions"),
    ],
)
def test_detect_and_limits_find_the_same_in_a_variant(
    twisted: Take,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    variant: Callable[[Take], bytes],
) -> None:
    source, other = tmp_path / "source.bvh", tmp_path / "variant.bvh"
    source.write_bytes(twisted.data())
    other.write_bytes(variant(twisted))
    expected = findings(capsys, "detect", str(source))
    assert expected["intervals"], "the injected errors should be found"
    got = findings(capsys, "detect", str(other))
    for a, b in zip(got["intervals"], expected["intervals"], strict=True):  # type: ignore[call-overload]
        assert a.keys() == b.keys()
        assert (a["joint"], a["start_frame"], a["end_frame"]) == (
            b["joint"],
            b["start_frame"],
            b["end_frame"],
        )
        assert a["offset_deg"] == pytest.approx(b["offset_deg"], abs=1e-6)
    expected_limits = findings(capsys, "limits", "check", str(source))
    got_limits = findings(capsys, "limits", "check", str(other))
    for a, b in zip(got_limits["joints"], expected_limits["joints"], strict=True):  # type: ignore[call-overload]
        assert a["name"] == b["name"]
        assert a["flagged_fraction"] == pytest.approx(b["flagged_fraction"], abs=1e-9)
        assert a["max_score_deg"] == pytest.approx(b["max_score_deg"], abs=1e-6)
