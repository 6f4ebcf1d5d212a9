"""Every command that writes files refuses to destroy its inputs, devices or its own outputs.

A hostile pass found ``refine in.bvh -o in.bvh`` (and the same with ``filter``, ``report``,
``render``, ``limits build`` and ``batch``) replacing the input and exiting 0, a write to
``/dev/full`` turning it into a regular file, failed writes leaving half-written files, and
``render -o r.txt`` writing a PNG. These tests run each command on copies in ``tmp_path``; no
test writes to ``/dev/null`` or ``/dev/full`` (the machine is shared): a FIFO and a folder in
``tmp_path`` stand for "not a regular file".
"""

from __future__ import annotations

import os
import resource
import shutil
import stat
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from mocapqa.cli.main import main

OPENPOSE = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose/cam01_json"
TRC = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"


@pytest.fixture
def take(cmu_walk: Path, tmp_path: Path) -> Path:
    """A copy of the CMU walk in ``tmp_path`` (so nothing of the corpus can be touched)."""
    path = tmp_path / "in.bvh"
    shutil.copyfile(cmu_walk, path)
    return path


@pytest.fixture
def keypoints(corpus_dir: Path, tmp_path: Path) -> Path:
    """A copy of a Pose2Sim TRC in ``tmp_path``."""
    path = tmp_path / "kp.trc"
    shutil.copyfile(corpus_dir / TRC, path)
    return path


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err
    return code, err


def _unchanged(path: Path) -> Callable[[], None]:
    """A check that ``path`` still holds what it holds now."""
    before = path.read_bytes()

    def check() -> None:
        assert path.read_bytes() == before, f"{path} was changed"

    return check


SAME_FILE: dict[str, list[str]] = {
    "refine -o IN": ["refine", "{in}", "-o", "{in}"],
    "filter -o IN": ["filter", "{in}", "-o", "{in}"],
    "refine --report IN": ["refine", "{in}", "-o", "{dir}/o.bvh", "--report", "{in}"],
    "filter --report IN": ["filter", "{in}", "-o", "{dir}/o.bvh", "--report", "{in}"],
    "refine --mapping = -o": ["refine", "{in}", "-o", "{dir}/m.bvh", "--mapping", "{dir}/m.bvh"],
    "convert -o IN": ["convert", "{in}", "-o", "{in}"],
    "convert -o link to IN": ["convert", "{in}", "-o", "{dir}/link.bvh"],
    "report -o hard link to IN": ["report", "{in}", "-o", "{dir}/hard.html"],
    "render -o hard link to IN": ["render", "{in}", "-o", "{dir}/hard.png", "--frame", "0"],
    "report --options = -o": ["report", "{in}", "-o", "{dir}/o.html", "--options", "{dir}/o.html"],
}


@pytest.mark.parametrize("case", sorted(SAME_FILE))
def test_an_output_that_is_an_input_is_refused_naming_both(
    case: str, take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "link.bvh").symlink_to(take.name)
    os.link(take, tmp_path / "hard.html")
    os.link(take, tmp_path / "hard.png")
    (tmp_path / "m.bvh").write_text('{"left_upper_arm": "LeftArm"}', encoding="utf-8")
    (tmp_path / "o.html").write_text("{}", encoding="utf-8")
    checks = [_unchanged(p) for p in (take, tmp_path / "m.bvh", tmp_path / "o.html")]
    argv = [a.format(**{"in": take, "dir": tmp_path}) for a in SAME_FILE[case]]
    code, err = _run(argv, capsys)
    assert code == 3, err
    assert len(err.splitlines()) == 1, err
    assert "the same file as the input" in err, err
    output = argv[argv.index("--report" if "--report" in case else "-o") + 1]
    assert output in err, err
    for check in checks:
        check()
    assert not (tmp_path / "o.bvh").exists()


def test_two_outputs_of_one_command_must_differ(
    take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "o.bvh"
    code, err = _run(["refine", str(take), "-o", str(out), "--report", str(out)], capsys)
    assert code == 3, err
    assert f"Expected -o and --report to name different files, got {out} and {out}" in err
    assert not out.exists()


def test_limits_build_refuses_a_take_of_its_folder(
    take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    check = _unchanged(take)
    code, err = _run(["limits", "build", str(tmp_path), "-o", str(take)], capsys)
    assert code == 3, err
    assert "Expected -o ending in .npz" in err
    check()


def test_batch_refuses_a_table_that_is_one_of_its_takes(
    keypoints: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    monkeypatch.setenv("MOCAPQA_DATA_DIR", str(tmp_path / "data"))
    folder = tmp_path / "takes"
    folder.mkdir()
    csv = folder / "kp.csv"
    assert main(["convert", str(keypoints), "-o", str(csv)]) == 0
    checks = [_unchanged(csv), _unchanged(folder / "kp.csv.meta.json")]
    # An input CSV of the folder, a file the batch would read next time, the CSV named alone.
    for table, paths in ((csv, [folder]), (folder / "sub" / "new.csv", [folder]), (csv, [csv])):
        code, err = _run(["batch", *map(str, paths), "--output", str(table)], capsys)
        assert code == 3, err
        assert str(table) in err, err
        assert str(paths[0]) in err, err
    assert not (folder / "sub").exists()
    for check in checks:
        check()
    assert not (tmp_path / "data").exists()  # refused before the database was opened


def test_convert_refuses_to_overwrite_an_input_csv_sidecar_or_an_openpose_frame(
    keypoints: Path, corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    csv = tmp_path / "kp.csv"
    assert main(["convert", str(keypoints), "-o", str(csv)]) == 0
    sidecar = tmp_path / "kp.csv.meta.json"
    check = _unchanged(sidecar)
    code, err = _run(["convert", str(csv), "-o", str(sidecar)], capsys)
    assert code == 3, err
    assert "the same file as the input" in err, err
    assert str(sidecar) in err, err
    check()
    frames = tmp_path / "frames"
    frames.mkdir()
    for source in sorted((corpus_dir / OPENPOSE).glob("*.json"))[:3]:
        shutil.copyfile(source, frames / source.name)
    first = sorted(frames.iterdir())[0]
    check = _unchanged(first)
    code, err = _run(["convert", str(frames), "--fps", "30", "-o", str(first)], capsys)
    assert code == 3, err
    assert f"outside the files read from the input folder {frames}" in err, err
    check()


KEYPOINT_EXTENSIONS = ".trc or .csv or .npy or .npz or .json or .c3d"
WRONG_EXTENSION: dict[str, tuple[str, str]] = {
    "render still": ("render {in} --frame 0 -o {dir}/r.txt", ".png"),
    "render clip": ("render {in} --interval LeftArm:0-3 -o {dir}/r.png", ".gif or .mp4"),
    "render sheet": ("render {in} --contact-sheet -o {dir}/r.gif", ".png"),
    "report": ("report {in} -o {dir}/r.txt", ".html or .htm"),
    "report --pdf": ("report {in} -o {dir}/r.html --pdf {dir}/r.html", ".pdf"),
    "filter bvh": ("filter {in} -o {dir}/x.trc", ".bvh"),
    "filter keypoints": ("filter {kp} -o {dir}/x.bvh", KEYPOINT_EXTENSIONS),
    "refine": ("refine {in} -o {dir}/x.trc", ".bvh"),
    "limits build": ("limits build {dir} -o {dir}/m.txt", ".npz"),
    "limits show": ("limits show {dir}/m.npz --joint LeftArm -o {dir}/m.txt", ".png"),
}
"""Command lines (split on spaces; pytest's tmp_path has none) and the extensions expected."""


@pytest.mark.parametrize("case", sorted(WRONG_EXTENSION))
def test_an_output_extension_that_does_not_match_what_is_written_is_refused(
    case: str, take: Path, keypoints: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line, expected = WRONG_EXTENSION[case]
    argv = [a.format(**{"in": take, "kp": keypoints, "dir": tmp_path}) for a in line.split()]
    before = sorted(p.name for p in tmp_path.iterdir())
    code, err = _run(argv, capsys)
    assert code == 3, err
    assert f"ending in {expected} for " in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written


@pytest.mark.parametrize("kind", ["fifo", "directory"])
@pytest.mark.parametrize("command", ["refine", "convert", "filter"])
def test_a_fifo_or_folder_output_is_refused_and_kept(
    command: str, kind: str, take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "out.bvh"
    os.mkfifo(target) if kind == "fifo" else target.mkdir()
    code, err = _run([command, str(take), "-o", str(target)], capsys)
    assert code == 3, err
    assert str(target) in err, err
    assert ("FIFO" if kind == "fifo" else "directory") in err, err
    mode = target.lstat().st_mode
    assert stat.S_ISFIFO(mode) if kind == "fifo" else stat.S_ISDIR(mode)


def test_a_symlink_output_is_written_through_and_kept(
    take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    real = tmp_path / "refined.bvh"
    real.write_text("old", encoding="utf-8")
    link = tmp_path / "latest.bvh"
    link.symlink_to(real.name)
    code, err = _run(["refine", str(take), "-o", str(link)], capsys)
    assert code == 0, err
    assert link.is_symlink()
    assert real.read_text(encoding="utf-8").startswith("HIERARCHY")


def _limit_file_size() -> None:
    """In the child only: files of at most 20 KiB, as ``ulimit -f 20`` (Python ignores
    SIGXFSZ, so a larger write fails with EFBIG)."""
    _, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (20 * 1024, hard))


@pytest.mark.parametrize(
    ("command", "name"),
    [("convert", "out.bvh"), ("refine", "out.bvh"), ("filter", "out.bvh"), ("report", "out.html")],
)
def test_a_write_that_fails_leaves_the_old_file_and_names_it(
    command: str, name: str, take: Path, tmp_path: Path
) -> None:
    out = tmp_path / name
    out.write_text("a good file from an earlier run", encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "mocapqa.cli.main", command, str(take), "-o", str(out)],
        capture_output=True, text=True, timeout=300, preexec_fn=_limit_file_size,
        env={**os.environ, "MOCAPQA_DATA_DIR": str(tmp_path / "data")},
    )  # fmt: skip
    assert done.returncode == 3, done.stderr
    assert done.stderr.strip().endswith(
        f"error: Expected a writable output path, got File too large: {out}"
    ), done.stderr
    assert out.read_text(encoding="utf-8") == "a good file from an earlier run"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["in.bvh", name])
