"""``mocapqa info``, ``mocapqa convert`` and ``mocapqa bench io`` through their exit codes."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.app import app
from mocapqa.cli.main import COMMAND_MODULES, import_command_module, main, modules_for
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import channel_values
from mocapqa.io.formats import read_take
from mocapqa_bench.io import timed_in_turns

OPENPOSE = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose/cam01_json"
TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, object]:
    assert main(["info", *args, "--json"]) == 0
    return dict(json.loads(capsys.readouterr().out))


def test_info_describes_the_cmu_walk(cmu_walk: Path, capsys: pytest.CaptureFixture[str]) -> None:
    info = run_json(capsys, str(cmu_walk))
    # shared/data/README.md: 524 frames at 120 fps (Frame Time .0083333), 31 joints, ZYX.
    assert info["format"] == "bvh"
    assert info["frames"] == 524
    assert info["fps"] == pytest.approx(120.0, rel=1e-5)
    assert info["duration_s"] == pytest.approx(524 * 0.0083333)
    assert info["joints"] == 31
    assert info["end_sites"] == 7
    assert info["rotation_orders"] == {"ZYX": 31}
    assert info["root_translation"] == "replace"
    assert info["length_unit"] == "unknown"
    assert info["unmapped_roles"] == []
    roles = info["roles"]
    assert isinstance(roles, dict)
    assert roles["left_upper_arm"] == "LeftArm"
    assert "left upper_arm: LeftArm > LeftForeArm > LeftHand" in list(info["limb_chains"])  # type: ignore[call-overload]


def test_info_table_names_the_unmapped_roles(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    take = tmp_path / "legs.bvh"
    take.write_text(
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n"
        " JOINT LeftUpLeg\n {\n  OFFSET 1 0 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "  End Site\n  {\n   OFFSET 0 -1 0\n  }\n }\n}\nMOTION\nFrames: 1\n"
        "Frame Time: 0.04\n0 0 0 0 0 0\n",
        encoding="utf-8",
    )
    assert main(["info", str(take)]) == 0
    out = capsys.readouterr().out
    assert "unmapped roles" in out
    assert "right_hand" in out
    assert "left_upper_leg: LeftUpLeg" in out


def test_info_applies_a_mapping(
    cmu_walk: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mapping = tmp_path / "map.json"
    mapping.write_text(json.dumps({"LeftForeArm": "left_upper_arm"}), encoding="utf-8")
    info = run_json(capsys, str(cmu_walk), "--mapping", str(mapping))
    roles = info["roles"]
    assert isinstance(roles, dict)
    assert roles["left_upper_arm"] == "LeftForeArm"


def test_info_reports_missing_keypoints(
    corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = corpus_dir / OPENPOSE
    info = run_json(capsys, str(folder), "--fps", "30")
    assert info["format"] == "openpose"
    assert info["fps"] == 30.0
    # Independent count: OpenPose marks an undetected keypoint with confidence 0.
    frames = sorted(folder.glob("*.json"))
    missing = total = 0
    for frame in frames:
        people = json.loads(frame.read_text())["people"]
        n = int(info["keypoints"])  # type: ignore[call-overload]
        confidences = np.array(people[0]["pose_keypoints_2d"][2::3]) if people else np.zeros(n)
        missing += int(np.sum(confidences == 0))
        total += n
    assert info["frames"] == len(frames)
    assert info["missing_fraction"] == pytest.approx(missing / total)
    assert 0 < missing < total


@pytest.mark.parametrize(
    ("args", "code", "pattern"),
    [
        (["info", "nowhere.bvh"], 3, "Expected an existing file"),
        (["info", "{walk}", "--fps", "0"], 3, "Expected --fps finite, at least 0.1"),
        (["info", "{broken}"], 3, "line 2: Expected 'ROOT'"),
        (["info", "{walk}", "--mapping", "{bad_json}"], 3, "line 2: Expected JSON"),
        (["info", "{walk}", "--mapping", "{bad_role}"], 3, "Expected a role in"),
        (["convert", "{walk}", "-o", "{out}/walk.csv"], 3, "Expected a .bvh output"),
        (["convert", "{trc}", "-o", "{out}/walk.bvh"], 3, "Expected a keypoint output among"),
        (["convert", "{walk}", "-o", "{out}/missing/dir/walk.bvh"], 3, "writable output path"),
    ],
)
def test_user_errors_print_one_line_and_exit_non_zero(
    args: list[str],
    code: int,
    pattern: str,
    cmu_walk: Path,
    corpus_dir: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    broken = tmp_path / "broken.bvh"
    broken.write_text("HIERARCHY\nJOINT Hips\nMOTION\n", encoding="utf-8")
    bad_json = tmp_path / "bad.json"
    bad_json.write_text('{\n  "LeftArm": left_upper_arm\n}', encoding="utf-8")
    bad_role = tmp_path / "role.json"
    bad_role.write_text('{"LeftArm": "left_elbow"}', encoding="utf-8")
    names = {
        "walk": cmu_walk, "broken": broken, "bad_json": bad_json, "bad_role": bad_role,
        "trc": corpus_dir / TRC, "out": tmp_path,
    }  # fmt: skip
    argv = [a.format(**names) for a in args]
    assert main(argv) == code
    err = capsys.readouterr().err.strip()
    assert pattern in err
    assert "Traceback" not in err
    assert len(err.splitlines()) == 1


def test_convert_bvh_round_trip(cmu_walk: Path, tmp_path: Path) -> None:
    out = tmp_path / "walk.bvh"
    assert main(["convert", str(cmu_walk), "-o", str(out)]) == 0
    original, again = read_bvh(cmu_walk), read_bvh(out)
    assert again.skeleton.names == original.skeleton.names
    np.testing.assert_array_equal(again.skeleton.offsets, original.skeleton.offsets)
    np.testing.assert_allclose(channel_values(again), channel_values(original), atol=5e-7)


@pytest.mark.parametrize("suffix", ["csv", "npy", "npz", "json", "trc"])
def test_convert_keypoints_to_every_writable_format(
    suffix: str, corpus_dir: Path, tmp_path: Path
) -> None:
    source = corpus_dir / TRC
    original = read_take(source)
    assert isinstance(original, KeypointSequence)
    target = tmp_path / f"take.{suffix}"
    assert main(["convert", str(source), "-o", str(target)]) == 0
    converted = read_take(target, fps=original.fps)
    assert isinstance(converted, KeypointSequence)
    assert converted.n_frames == original.n_frames
    np.testing.assert_allclose(converted.positions, original.positions, rtol=0, atol=1e-9)
    if suffix != "npy":  # a bare array has no names
        assert converted.names == original.names


def test_convert_keypoints_back_and_forth_keeps_the_values(
    corpus_dir: Path, tmp_path: Path
) -> None:
    current = corpus_dir / TRC
    original = read_take(current)
    assert isinstance(original, KeypointSequence)
    for suffix in ("csv", "npz", "json", "trc"):
        target = tmp_path / f"chain.{suffix}"
        assert main(["convert", str(current), "-o", str(target)]) == 0
        current = target
    final = read_take(current)
    assert isinstance(final, KeypointSequence)
    assert final.names == original.names
    assert final.length_unit == original.length_unit
    assert final.fps == pytest.approx(original.fps)
    np.testing.assert_allclose(final.positions, original.positions, rtol=0, atol=1e-9)


def test_bench_io_prints_its_tables(
    cmu_walk: Path, corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = tmp_path / "data"
    (data / "bvh" / "bandai").mkdir(parents=True)
    shutil.copy(cmu_walk, data / "bvh" / cmu_walk.name)
    small = corpus_dir / "bvh" / "bandai" / "dataset-1_bow_sad_001.bvh"
    shutil.copy(small, data / "bvh" / "bandai" / small.name)
    argv = ["bench", "io", "--data", str(data), "--repeats", "1", "--info-runs", "1",
            "--headline-repeats", "3", "--block-runs", "2"]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr().out
    for label in ("read + FK", "write", "largest Bandai", "pybvh 0.9", "mocapqa info",
                  "right after pybvh", "time ratio"):  # fmt: skip
        assert label in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["info", "--bogus", "x.bvh"], "No such option: --bogus"),
        (["info"], "Missing argument"),
        (["no-such-command"], "No such command"),
    ],
)
def test_usage_errors_exit_2_without_a_traceback(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(args) == 2
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err


def test_help_exits_0(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    assert "info" in capsys.readouterr().out


def test_the_command_table_names_every_command_s_module() -> None:
    for module in {m for modules in COMMAND_MODULES.values() for m in modules}:
        import_command_module(module)
    commands = {}
    groups = [("", app), *((f"{g.name} ", g.typer_instance) for g in app.registered_groups)]
    for prefix, group in groups:
        assert group is not None
        for command in group.registered_commands:
            assert command.callback is not None
            name = command.name or command.callback.__name__.replace("_", "-")
            commands[prefix + name] = command.callback.__module__.rsplit(".", 1)[-1]
    for path, module in commands.items():
        assert module in modules_for(path.split()), path
    # Groups load their module for their own help; every other key is a command.
    groups_keys = {"limits", "users", "tokens", "db", "feet", "markers"}
    assert set(COMMAND_MODULES) - set(commands) == groups_keys
    assert all(path.split()[0] in groups_keys for path in set(commands) - set(COMMAND_MODULES))


def test_info_in_a_fresh_process_loads_only_what_it_needs(cmu_walk: Path, corpus_dir: Path) -> None:
    # `mocapqa info` must start fast: only its own command module (and the small shared
    # --mapping option of every BVH command), and no pyarrow for a
    # small take (the line-by-line reader is quicker than importing it); a large take
    # (3.5 MB) is worth the import.
    large = corpus_dir / "bvh" / "cmu" / "iclone" / "001_14.bvh"
    script = (
        "import sys, json\n"
        "from mocapqa.cli.main import main\n"
        "codes = [main(['info', sys.argv[1], '--json'])]\n"
        "arrow_after_small = 'pyarrow' in sys.modules\n"
        "codes.append(main(['info', sys.argv[2], '--json']))\n"
        "cli = sorted(m for m in sys.modules if m.startswith('mocapqa.cli.'))\n"
        "print(json.dumps([codes, arrow_after_small, 'pyarrow.csv' in sys.modules, cli]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, str(cmu_walk), str(large)],
        capture_output=True, text=True, check=True, timeout=120,
    )  # fmt: skip
    codes, arrow_after_small, arrow_after_large, cli = json.loads(done.stdout.splitlines()[-1])
    assert codes == [0, 0]
    assert not arrow_after_small
    assert arrow_after_large
    assert cli == [
        "mocapqa.cli.app",
        "mocapqa.cli.info",
        "mocapqa.cli.main",
        "mocapqa.cli.reading",
        "mocapqa.cli.roles",
    ]


def test_timed_works_take_turns_of_consecutive_runs() -> None:
    calls: list[str] = []
    works = {name: (lambda name=name: calls.append(name)) for name in ("a", "b")}
    times = timed_in_turns(works, repeats=5, block_runs=2)
    # One untimed run each, then three turns of two runs (5 rounded up to whole turns).
    assert calls == ["a", "b"] + (["a"] * 2 + ["b"] * 2) * 3
    assert [len(turn) for turn in times["a"]] == [2, 2, 2]
    assert all(seconds >= 0.0 for turn in times["b"] for seconds in turn)


def test_the_commands_that_read_a_take_keep_the_reading_limits(
    cmu_walk: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    # The server's limits, from the same settings: refused from the header, naming the setting,
    # before the frames are read; raised by the same variable.
    monkeypatch.setenv("MOCAPQA_MAX_FRAME_POINTS", "10000")  # the walk: 524 frames × 31 joints
    small = tmp_path / "small.npz"
    np.savez(small, positions=np.zeros((400, 33, 3)))  # 13,200 frame-points
    for args in (
        ["info", str(cmu_walk)],
        ["convert", str(small), "-o", str(tmp_path / "out.csv"), "--fps", "30"],
        ["detect", str(cmu_walk)],
        ["limits", "check", str(cmu_walk)],
        ["report", str(cmu_walk), "-o", str(tmp_path / "r.html")],
    ):
        assert main(args) != 0, args
        err = capsys.readouterr().err
        assert "max_frame_points" in err, (args, err)
        assert "Traceback" not in err
    assert not (tmp_path / "out.csv").exists()
    assert not (tmp_path / "r.html").exists()
    monkeypatch.setenv("MOCAPQA_MAX_FRAME_POINTS", "20000")
    assert main(["info", str(cmu_walk), "--json"]) == 0
    # A twist command given a keypoint file says so.
    assert main(["detect", str(small)]) != 0
    assert "Expected a BVH take, got a npz file" in capsys.readouterr().err


def test_info_and_convert_refuse_hostile_numbers_without_a_traceback(
    tmp_path: Path, corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csv = tmp_path / "kp.csv"
    assert main(["convert", str(corpus_dir / TRC), "-o", str(csv)]) == 0
    lines = csv.read_text(encoding="utf-8").splitlines()
    cells = lines[1].split(",")
    cells[3] = "1e308"  # the first x: read, and written out by convert
    lines[1] = ",".join(cells)
    huge = tmp_path / "kp_inf.csv"
    huge.write_text("\n".join(lines) + "\n", encoding="utf-8")
    garbage = tmp_path / "kp_garbage.npy"
    garbage.write_bytes(b"\x93NUMPY\x01\x00\x20\x00{'descr': '<f8', 'shape': (1, \"\"\"     \n")
    capsys.readouterr()
    cases = [
        (["info", str(huge)], "within ±1,000,000,000, got 1e+308"),
        (["convert", str(huge), "-o", str(tmp_path / "out.trc")], "within ±1,000,000,000"),
        (["info", str(garbage), "--fps", "30"], "kp_garbage.npy: Expected a NumPy array header"),
        (
            ["info", str(csv), "--fps", "inf"],
            "Expected --fps finite, at least 0.1 and at most 100000",
        ),
        (["convert", str(csv), "-o", str(tmp_path / "o.csv"), "--fps", "nan"], "finite"),
    ]
    for argv, message in cases:
        assert main(argv) == 3, argv
        err = capsys.readouterr().err
        assert message in err, err
        assert "Traceback" not in err
    assert not (tmp_path / "out.trc").exists()
