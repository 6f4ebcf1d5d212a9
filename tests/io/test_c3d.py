"""C3D: every corpus file read or refused cleanly, round trips re-read by ezc3d, hostile files."""

from __future__ import annotations

import csv
import json
import struct
from pathlib import Path

import ezc3d
import numpy as np
import opensim
import pytest

from mocapqa.cli.main import main
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError, ParseError, TooLargeError
from mocapqa.io.c3d import MarkerTake, read_c3d, write_c3d
from mocapqa.io.formats import detect_format, read_take, require_frames
from mocapqa.io.guards import ReadLimits

NICK = "c3d/vicon/nick_freeform_001.c3d"
PIG = "c3d/btk/PiG_Motion-FlatFoot-Full.c3d"
CMU = "c3d/cmu/cmu_02_05.c3d"
EMG = "c3d/btk/1123x01EMG.c3d"
DRIBBLE = "c3d/cmu/cmu_dribble_shoot_basketball.c3d"
# What no reader takes, and why (shared/data/README.md, "c3d/").
REFUSED = {
    "Empty.c3d": "empty file",
    "MACsample.c3d": "MIPS processor type not supported; py-c3d: inconsistent scale factor",
}


def _manifest(corpus_dir: Path) -> dict[str, list[str]]:
    with (corpus_dir / "MANIFEST.tsv").open(encoding="utf-8") as handle:
        return {row[0]: row for row in csv.reader(handle, delimiter="\t") if row}


def _c3d_files(corpus_dir: Path) -> list[Path]:
    files = sorted(p for p in (corpus_dir / "c3d").rglob("*") if p.suffix.lower() == ".c3d")
    assert len(files) == 18
    return files


def test_every_corpus_c3d_is_read_or_refused_cleanly(corpus_dir: Path) -> None:
    # MANIFEST.tsv: frames, rate and points as ezc3d 1.7.2 reads them ("-" where it cannot).
    manifest = _manifest(corpus_dir)
    readers = {}
    for path in _c3d_files(corpus_dir):
        name = path.name
        if name in REFUSED:
            with pytest.raises(ParseError, match=REFUSED[name]) as caught:
                read_c3d(path)
            assert str(path) in str(caught.value)
            continue
        take = read_c3d(path)
        readers[name] = take.reader
        seq = take.points
        assert seq.source_format == "c3d"
        assert take.residuals.shape == take.camera_masks.shape == seq.positions.shape[:2]
        missing = np.isnan(seq.positions).any(axis=2)
        assert np.array_equal(missing, take.residuals < 0), name
        assert np.all(take.residuals[missing] == -1)
        assert np.all(take.camera_masks[missing] == 0)
        assert np.array_equal(seq.confidence, (~missing).astype(float))
        assert len(take.descriptions) == seq.n_keypoints
        row = manifest[str(path.relative_to(corpus_dir))]
        if row[3] != "-":
            frames, rate, points = int(row[3]), float(row[4]), int(row[5])
            assert (seq.n_frames, seq.n_keypoints) == (frames, points), name
            assert seq.fps == pytest.approx(rate), name
    # ezc3d 1.7.2 refuses Dance.c3d (a FLOAT ANALOG:OFFSET); py-c3d reads it.
    assert readers.pop("Dance.c3d") == "py-c3d"
    assert set(readers.values()) == {"ezc3d"}


def test_the_cmu_take_reads_as_the_readme_says(corpus_dir: Path) -> None:
    take = read_c3d(corpus_dir / CMU)
    seq = take.points
    assert (seq.n_frames, seq.n_keypoints, seq.fps) == (1854, 41, 120.0)
    assert seq.length_unit == "mm"
    assert seq.names[0] == "TakeoMonday:RBWT"
    assert take.first_frame == 1
    assert take.analog_rate is None
    assert take.analog_labels == ()
    # CMU's files hold camera contributions.
    assert take.camera_masks.max() > 0


def test_events_first_frame_and_analogs_of_a_plug_in_gait_trial(corpus_dir: Path) -> None:
    take = read_c3d(corpus_dir / PIG)
    assert take.first_frame == 148  # TRIAL:ACTUAL_START_FIELD
    assert take.analog_rate == 1000.0
    assert len(take.analog_labels) == 38
    assert len(take.events) == 12
    strike = take.events[1]
    assert (strike.label, strike.context) == ("Foot Strike", "Left")
    assert strike.time_s == pytest.approx(2.02)
    # Frame numbers count from 1 at time 0: 2.02 s at 100 Hz is frame 203, index 55 from 148.
    assert strike.frame == 55
    assert all(0 <= e.frame < take.points.n_frames for e in take.events)


def _written_and_source(source: Path, out: Path) -> tuple[ezc3d.c3d, ezc3d.c3d]:
    return ezc3d.c3d(str(source)), ezc3d.c3d(str(out))


def _labels(c3d: ezc3d.c3d) -> list[str]:
    point = c3d["parameters"]["POINT"]
    labels = list(point["LABELS"]["value"])
    extra = 2
    while f"LABELS{extra}" in point:
        labels += list(point[f"LABELS{extra}"]["value"])
        extra += 1
    return labels


@pytest.mark.parametrize("name", [NICK, PIG])
def test_convert_c3d_to_c3d_keeps_what_ezc3d_reads(
    name: str, corpus_dir: Path, tmp_path: Path
) -> None:
    source, out = corpus_dir / name, tmp_path / "out.c3d"
    assert main(["convert", str(source), "-o", str(out)]) == 0
    before, after = _written_and_source(source, out)
    points_a, points_b = before["data"]["points"], after["data"]["points"]
    assert points_a.shape == points_b.shape
    assert np.array_equal(np.isnan(points_a), np.isnan(points_b))
    np.testing.assert_allclose(points_b, points_a, rtol=2**-23, equal_nan=True)  # float32
    res_a = before["data"]["meta_points"]["residuals"]
    res_b = after["data"]["meta_points"]["residuals"]
    assert np.array_equal(np.sign(res_a), np.sign(res_b))
    assert (res_a < 0).any()  # both takes have gaps: missing stays −1
    assert np.all(res_b[res_a < 0] == -1)
    assert _labels(after) == _labels(before)
    for key in ("RATE", "UNITS"):
        assert list(after["parameters"]["POINT"][key]["value"]) == list(
            before["parameters"]["POINT"][key]["value"]
        )
    assert after["header"]["points"]["first_frame"] == before["header"]["points"]["first_frame"]
    # Analogs bit for bit, and the other groups (force plates, events) as they were.
    assert np.array_equal(before["data"]["analogs"], after["data"]["analogs"])
    for group in before["parameters"]:
        assert group in after["parameters"]
    if name == PIG:
        assert before["data"]["analogs"].shape == (1, 38, 3150)
        for group, key in (("FORCE_PLATFORM", "CORNERS"), ("EVENT", "TIMES")):
            assert np.array_equal(
                before["parameters"][group][key]["value"], after["parameters"][group][key]["value"]
            )
        assert (
            after["parameters"]["EVENT"]["LABELS"]["value"]
            == (before["parameters"]["EVENT"]["LABELS"]["value"])
        )


def _first_sample_words(path: Path, frame: int, point: int) -> tuple[float, ...]:
    """The four float words of a point sample as stored (Intel float storage)."""
    raw = path.read_bytes()
    n_points, analog = struct.unpack_from("<HH", raw, 2)
    (data_block,) = struct.unpack_from("<H", raw, 16)
    offset = (data_block - 1) * 512 + frame * (4 * n_points + analog) * 4 + point * 16
    return struct.unpack_from("<4f", raw, offset)


def test_missing_is_written_as_the_standard_says_and_fills_stay_zero(
    corpus_dir: Path, tmp_path: Path
) -> None:
    take = read_c3d(corpus_dir / NICK)
    frame, point = (int(i) for i in np.argwhere(take.residuals < 0)[0])
    # Mark a present sample as filled (residual 0) and one as measured with a tiny residual.
    present = np.argwhere(take.residuals >= 0)
    residuals = take.residuals.copy()
    (f0, p0), (f1, p1) = present[0], present[1]
    residuals[f0, p0], residuals[f1, p1] = 0.0, 1e-6
    edited = MarkerTake(**{**_fields(take), "residuals": residuals})
    for source in (corpus_dir / NICK, None):
        out = tmp_path / f"out-{source is None}.c3d"
        write_c3d(out, edited, source)
        x, y, z, residual = _first_sample_words(out, frame, point)
        assert (x, y, z, residual) == (0.0, 0.0, 0.0, -1.0)  # not zeros with a valid residual
        again = read_c3d(out)
        assert again.residuals[f0, p0] == 0.0
        assert again.residuals[f1, p1] > 0.0
        assert np.array_equal(again.residuals < 0, take.residuals < 0)
        assert np.array_equal(again.residuals == 0, residuals == 0)


def _fields(take: MarkerTake) -> dict[str, object]:
    return {name: getattr(take, name) for name in MarkerTake.__slots__}


def test_optitrack_nan_samples_are_missing_and_written_with_residual_minus_one(
    corpus_dir: Path, tmp_path: Path
) -> None:
    # OptiTrack writes NaN coordinates with residual 0; ezc3d writes them back as NaN unless
    # the residual says missing.
    take = read_c3d(corpus_dir / "c3d/optitrack/kinematics_tennis_serve_nan.c3d")
    assert take.points.missing_fraction == pytest.approx(0.0034, abs=1e-4)
    out = tmp_path / "serve.c3d"
    write_c3d(out, take)
    residuals = ezc3d.c3d(str(out))["data"]["meta_points"]["residuals"][0].T
    assert np.array_equal(residuals < 0, np.isnan(take.points.positions).any(axis=2))


def test_a_new_file_with_more_than_255_markers_uses_labels2(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    names = tuple(f"M{i}" for i in range(300))
    seq = KeypointSequence(
        names=names,
        positions=rng.normal(size=(4, 300, 3)) * 100,
        confidence=np.ones((4, 300)),
        fps=240.0,
        length_unit="m",
    )
    take = MarkerTake(
        points=seq,
        residuals=np.full((4, 300), 0.5),
        camera_masks=np.full((4, 300), 5, dtype=np.intp),
        descriptions=("left heel",) + ("",) * 299,
        first_frame=11,
        events=(),
        analog_rate=None,
        analog_labels=(),
        reader="",
    )
    out = tmp_path / "many.c3d"
    write_c3d(out, take)
    written = ezc3d.c3d(str(out))["parameters"]["POINT"]
    assert len(written["LABELS"]["value"]) == 255
    assert len(written["LABELS2"]["value"]) == 45
    again = read_c3d(out)
    assert again.points.names == names
    assert (again.points.fps, again.points.length_unit, again.first_frame) == (240.0, "m", 11)
    # ezc3d 1.7.2 writes no POINT:DESCRIPTIONS for more than 255 points (docs/io.md).
    assert again.descriptions == ("",) * 300
    assert np.all(again.camera_masks == 5)
    assert np.all(again.residuals > 0)
    np.testing.assert_allclose(again.points.positions, seq.positions, rtol=2**-23)


def test_c3d_to_trc_loads_in_opensim_with_the_same_markers_and_frames(
    corpus_dir: Path, tmp_path: Path
) -> None:
    out = tmp_path / "nick.trc"
    assert main(["convert", str(corpus_dir / NICK), "-o", str(out)]) == 0
    table = opensim.TimeSeriesTableVec3(str(out))
    take = read_c3d(corpus_dir / NICK)
    assert table.getNumRows() == take.points.n_frames == 1101
    assert list(table.getColumnLabels()) == list(take.points.names)
    assert table.getTableMetaDataAsString("Units") == "mm"
    assert float(table.getTableMetaDataAsString("DataRate")) == 120.0


def test_read_take_reads_c3d_by_extension_in_any_case_and_by_content(
    corpus_dir: Path, tmp_path: Path
) -> None:
    plain = tmp_path / "take.bin"
    plain.write_bytes((corpus_dir / DRIBBLE).read_bytes())
    upper = tmp_path / "TAKE.C3D"
    upper.write_bytes(plain.read_bytes())
    for path in (corpus_dir / DRIBBLE, upper, plain):
        assert detect_format(path) == "c3d"
        take = read_take(path)
        assert isinstance(take, KeypointSequence)
        assert (take.n_frames, take.n_keypoints, take.fps) == (494, 41, 120.0)
        assert take.start_frame == 187


def test_an_analog_only_file_reads_but_is_not_analysed(corpus_dir: Path) -> None:
    take = read_take(corpus_dir / EMG)
    assert isinstance(take, KeypointSequence)
    assert take.n_keypoints == 0
    with pytest.raises(ParseError, match="Expected at least one keypoint, got 0"):
        require_frames(take, corpus_dir / EMG)


def test_limits_are_checked_from_the_header_before_parsing(corpus_dir: Path) -> None:
    with pytest.raises(TooLargeError, match=r"1854 × 41"):
        read_take(corpus_dir / CMU, limits=ReadLimits(max_frame_points=10_000))
    with pytest.raises(TooLargeError, match="max_unpacked_bytes"):
        read_c3d(corpus_dir / PIG, ReadLimits(max_unpacked_bytes=100_000))
    assert read_take(corpus_dir / CMU, limits=ReadLimits()).n_frames == 1854


def _corrupt(data: bytes, offset: int, value: bytes) -> bytes:
    return data[:offset] + value + data[offset + len(value) :]


def _parameter_offset(data: bytes, group_id: int, name: bytes) -> int:
    """Byte offset of a parameter record (its name length) in an Intel file."""
    pos = (data[0] - 1) * 512 + 4
    while data[pos]:
        length, group = struct.unpack_from("bb", data, pos)
        if data[pos + 2 : pos + 2 + abs(length)] == name and group == group_id:
            return pos
        (step,) = struct.unpack_from("<h", data, pos + 2 + abs(length))
        pos += 2 + abs(length) + step
    raise AssertionError(f"no parameter {name!r} in group {group_id}")


def _hostile_files(corpus_dir: Path, folder: Path) -> dict[str, Path]:
    pig = (corpus_dir / PIG).read_bytes()
    cube = (corpus_dir / "c3d/btk/MyCube.c3d").read_bytes()
    dribble = (corpus_dir / DRIBBLE).read_bytes()
    cases = {f"cut at {n}": pig[:n] for n in (1, 2, 511, 512, 600, 2000, 16_900, 700_000)}
    cases["MyCube cut at 1012"] = cube[:1012]  # ezc3d loops for ever on it
    cases["garbage after the magic byte"] = pig[:2] + bytes(range(256)) * 40
    cases["header claiming 65535 frames"] = _corrupt(pig, 8, struct.pack("<H", 65535))
    cases["header claiming 65535 points"] = _corrupt(pig, 2, struct.pack("<H", 65535))
    # Each of these crashed ezc3d 1.7.2 (segmentation fault) before the checks.
    scale = _parameter_offset(pig, 4, b"SCALE")
    cases["ANALOG:SCALE renamed"] = _corrupt(pig, scale + 2, b"Q")
    descriptions = _parameter_offset(dribble, 3, b"DESCRIPTIONS")
    cases["a parameter turned into a group"] = _corrupt(dribble, descriptions + 1, b"\xd9")
    rate = _parameter_offset(pig, 3, b"RATE")
    cases["POINT:RATE as characters"] = _corrupt(pig, rate + 2 + 4 + 2, b"\xff")
    units = _parameter_offset(pig, 3, b"UNITS")
    cases["POINT:UNITS without dimensions"] = _corrupt(pig, units + 2 + 5 + 2 + 1, b"\x00")
    paths = {}
    for index, (label, data) in enumerate(cases.items()):
        paths[label] = folder / f"hostile{index}.c3d"
        paths[label].write_bytes(data)
    return paths


def test_hostile_files_are_refused_or_read_without_crashing(
    corpus_dir: Path, tmp_path: Path
) -> None:
    messages, readers = {}, {}
    paths = _hostile_files(corpus_dir, tmp_path)
    for label, path in paths.items():
        try:
            readers[label] = read_c3d(path, ReadLimits()).reader
        except InputError as e:
            messages[label] = str(e)
    # What ezc3d would have crashed on goes to py-c3d, which reads it or says why not.
    assert set(readers.values()) <= {"py-c3d"}
    assert readers["ANALOG:SCALE renamed"] == "py-c3d"
    for label, message in messages.items():
        assert str(paths[label]) in message, label
    assert "Expected a 512-byte C3D header, got 511 bytes" in messages["cut at 511"]
    for label in ("cut at 16900", "cut at 700000", "header claiming 65535 frames"):
        assert "(truncated file?)" in messages[label], label
    assert "second byte 0x50" not in messages["garbage after the magic byte"]


def test_info_json_contract(corpus_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", str(corpus_dir / PIG), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["format"] == "c3d"
    assert info["reader"] == "ezc3d"
    assert (info["frames"], info["fps"], info["markers"]) == (315, 100.0, 193)
    assert (info["length_unit"], info["first_frame"]) == ("mm", 148)
    assert info["missing_fraction"] == pytest.approx(0.0995, abs=1e-4)
    assert (info["analog_channels"], info["analog_rate"]) == (38, 1000.0)
    assert info["events"][1] == {
        "label": "Foot Strike",
        "context": "Left",
        "time_s": pytest.approx(2.02),
        "frame": 55,
    }
    assert main(["info", str(corpus_dir / EMG), "--json"]) == 0
    emg = json.loads(capsys.readouterr().out)
    assert (emg["markers"], emg["analog_channels"], emg["frames"]) == (0, 8, 4564)
    assert main(["info", str(corpus_dir / "c3d/btk/Dance.c3d"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["reader"] == "py-c3d"


@pytest.mark.parametrize("name", ["c3d/btk/MACsample.c3d", "c3d/btk/Empty.c3d"])
def test_info_refuses_with_one_line_and_exit_3(
    name: str, corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["info", str(corpus_dir / name), "--json"]) == 3
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip()
    assert len(err.splitlines()) == 1
    assert Path(name).name in err
    assert "Traceback" not in err


def test_convert_of_a_file_read_by_py_c3d_and_of_an_analog_only_file(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "dance.c3d"
    assert main(["convert", str(corpus_dir / "c3d/btk/Dance.c3d"), "-o", str(out)]) == 0
    again = read_c3d(out)
    assert (again.reader, again.points.n_frames, again.points.n_keypoints) == ("ezc3d", 499, 40)
    emg = tmp_path / "emg.c3d"
    assert main(["convert", str(corpus_dir / EMG), "-o", str(emg)]) == 0
    before, after = _written_and_source(corpus_dir / EMG, emg)
    assert np.array_equal(before["data"]["analogs"], after["data"]["analogs"])
    capsys.readouterr()
    assert main(["convert", str(corpus_dir / EMG), "-o", str(tmp_path / "emg.trc")]) == 3
    assert "Expected at least one keypoint" in capsys.readouterr().err
