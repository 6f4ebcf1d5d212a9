"""``mocapqa limits build|check|show`` on real takes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mocapqa.cli.main import main
from mocapqa.limits.storage import load_model


def test_check_prints_json_with_the_flagged_fraction(
    corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    take = corpus_dir / "bvh" / "bandai" / "dataset-1_kick_normal_001.bvh"
    assert main(["limits", "check", str(take), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert 0.0 <= data["flagged_fraction"] <= 1.0
    assert {j["name"] for j in data["joints"]} >= {"UpperArm_L", "LowerLeg_R"}
    assert all("worst_frames" in j for j in data["joints"])


def test_build_then_show_writes_a_model_and_an_image(corpus_dir: Path, tmp_path: Path) -> None:
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    for name in ("dataset-1_walk_normal_001.bvh", "dataset-1_kick_normal_001.bvh"):
        (corpus / name).symlink_to(corpus_dir / "bvh" / "bandai" / name)
    model = tmp_path / "model.npz"
    assert main(["limits", "build", str(corpus), "-o", str(model), "--no-networks"]) == 0
    assert load_model(model).takes == ("dataset-1_kick_normal_001.bvh",)
    image = tmp_path / "map.png"
    assert main(["limits", "show", str(model), "--joint", "left_forearm", "-o", str(image)]) == 0
    assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_check_with_a_model_of_another_rig_exits_with_the_limits_code(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mocapqa.limits.storage import default_model_paths

    bandai = next(p for p in default_model_paths() if p.name == "bandai.npz")
    code = main(["limits", "check", str(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh"),
                 "--model", str(bandai)])  # fmt: skip
    assert code == 6
    assert "Expected a skeleton of the 'bandai' rig" in capsys.readouterr().err


def test_build_takes_a_folder_of_several_rigs_and_check_reads_out_anatomy(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    corpus = tmp_path / "mixed"
    corpus.mkdir()
    (corpus / "walk.bvh").symlink_to(
        corpus_dir / "bvh" / "bandai" / "dataset-1_walk_normal_001.bvh"
    )
    (corpus / "jump.bvh").symlink_to(corpus_dir / "bvh" / "cmu" / "iclone" / "002_04.bvh")
    model = tmp_path / "canonical.npz"
    assert main(["limits", "build", str(corpus), "-o", str(model), "--no-networks"]) == 0
    built = load_model(model)
    assert built.frame == "canonical"
    assert set(built.takes) == {"walk.bvh", "jump.bvh"}
    assert {f.family for f in built.rig_frames.values()} == {"bandai", "character_creator"}
    capsys.readouterr()
    # A rig the model has not seen (CMU names, world-aligned T-pose offsets).
    take = corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh"
    assert main(["limits", "check", str(take), "--model", str(model), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["rig_family"] == "canonical"
    assert "Head" in data["not_checked"]
    assert {j["role"] for j in data["joints"]} >= {"left_forearm", "right_lower_leg"}
    side_words = [w["readout"].split()[0] for j in data["joints"] for w in j["worst_frames"]]
    assert side_words
    assert set(side_words) <= {"left", "right"}


def test_a_mapping_decides_which_joint_the_canonical_model_checks(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    take = corpus_dir / "bvh" / "bandai" / "dataset-1_walk_normal_001.bvh"
    assert main(["limits", "check", str(take), "--json"]) == 0
    before = json.loads(capsys.readouterr().out)
    assert before["rig_family"] == "canonical"
    names = {j["role"]: j["name"] for j in before["joints"]}
    assert names["left_hand"] == "Hand_L"
    # Declare the toes the left foot: the canonical model then checks Toes_L, not Foot_L.
    mapping = tmp_path / "roles.json"
    mapping.write_text(json.dumps({"left_foot": "Toes_L"}), encoding="utf-8")
    assert main(["limits", "check", str(take), "--json", "--mapping", str(mapping)]) == 0
    after = json.loads(capsys.readouterr().out)
    mapped = {j["role"]: j["name"] for j in after["joints"]}
    assert mapped["left_foot"] == "Toes_L"
    assert "Foot_L" in after["not_checked"]


def test_check_frames_an_unseen_rig_from_a_folder_of_its_takes(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mocapqa.io.bvh import read_bvh
    from mocapqa.limits.analysis import check_limits
    from mocapqa.limits.build import with_rig_frames
    from mocapqa.limits.canonical import rig_key

    bandai = tmp_path / "bandai"
    bandai.mkdir()
    (bandai / "walk.bvh").symlink_to(
        corpus_dir / "bvh" / "bandai" / "dataset-1_walk_normal_001.bvh"
    )
    model_path = tmp_path / "model.npz"
    # A tight map (5° bins, no widening), so that the frames' small differences show.
    build = ["limits", "build", str(bandai), "-o", str(model_path), "--no-networks"]
    assert main([*build, "--bin-deg", "5", "--dilation", "0", "--margin-deg", "0"]) == 0
    folder = tmp_path / "character_creator"
    folder.mkdir()
    iclone = corpus_dir / "bvh" / "cmu" / "iclone"
    takes = [iclone / n for n in ("003_02.bvh", "002_09.bvh", "005_12.bvh")]
    for take_path in takes:
        (folder / take_path.name).symlink_to(take_path)
    take = str(takes[0])
    capsys.readouterr()
    assert main(["limits", "check", take, "--model", str(model_path), "--json",
                 "--frame-from", str(folder)]) == 0  # fmt: skip
    framed = json.loads(capsys.readouterr().out)
    model = load_model(model_path)
    motions = [read_bvh(t) for t in takes]
    assert rig_key(motions[0]) not in model.rig_frames
    expected = check_limits(motions[0], with_rig_frames(model, motions, [t.name for t in takes]))
    assert framed["flagged_fraction"] == pytest.approx(expected.flagged_fraction)
    alone = check_limits(motions[0], model)  # framed from the take itself
    assert alone.flagged_fraction != pytest.approx(expected.flagged_fraction)
    # A folder without a take of the rig is refused, naming the folder.
    assert main(["limits", "check", take, "--model", str(model_path),
                 "--frame-from", str(bandai)]) == 3  # fmt: skip
    assert "got none" in capsys.readouterr().err


def test_register_list_and_check_by_name(
    corpus_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    """A registered model is listed and checked by name; bad names and files exit non-zero."""
    from mocapqa.limits.storage import default_model_paths

    monkeypatch.setenv("MOCAPQA_DATA_DIR", str(tmp_path / "data"))
    cmu = next(p for p in default_model_paths() if p.name == "cmu.npz")
    walk = str(corpus_dir / "bvh" / "cmu" / "cmu_12_01_walk.bvh")
    assert main(["limits", "register", str(cmu), "walks"]) == 0
    assert (tmp_path / "data" / "limits_models" / "walks.npz").read_bytes() == cmu.read_bytes()
    capsys.readouterr()
    assert main(["limits", "models"]) == 0
    listed = capsys.readouterr().out
    assert "walks" in listed
    assert "registered" in listed
    assert main(["limits", "check", walk, "--model", "walks", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rig_family"] == "cmu"
    # taken names, shipped names, malformed names, unknown names, files that are no model
    assert main(["limits", "register", str(cmu), "walks"]) == 5
    assert "--replace" in capsys.readouterr().err
    assert main(["limits", "register", str(cmu), "walks", "--replace"]) == 0
    assert main(["limits", "register", str(cmu), "canonical"]) == 3
    assert main(["limits", "register", str(cmu), "Walks!"]) == 3
    assert main(["limits", "check", walk, "--model", "nope"]) == 3
    assert "Expected one of the limits models" in capsys.readouterr().err
    junk = tmp_path / "junk.bin"
    junk.write_bytes(b"not a model")
    assert main(["limits", "register", str(junk), "junk"]) == 6
    assert not (tmp_path / "data" / "limits_models" / "junk.npz").exists()
    # a per-rig model of another rig: the limits exit code, naming the rig
    bandai = next(p for p in default_model_paths() if p.name == "bandai.npz")
    assert main(["limits", "register", str(bandai), "studio-b"]) == 0
    assert main(["limits", "check", walk, "--model", "studio-b"]) == 6


def test_build_tries_the_hidden_sizes_asked_for(corpus_dir: Path, tmp_path: Path) -> None:
    """``--hidden`` sets the networks tried per joint (here one tiny size on a tiny set)."""
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    name = "dataset-1_kick_normal_001.bvh"
    (corpus / name).symlink_to(corpus_dir / "bvh" / "bandai" / name)
    model = tmp_path / "model.npz"
    args = ["limits", "build", str(corpus), "-o", str(model), "--all-takes", "--n-valid", "40"]
    assert main([*args, "--hidden", "3"]) == 0
    sizes = {j.scores.hidden_size for j in load_model(model).joints if j.scores is not None}
    assert sizes == {3}
    assert main([*args, "--hidden", "0"]) == 3  # refused before any take is read


def test_build_and_check_refuse_bad_numbers_before_working(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    take = corpus_dir / "bvh" / "bandai" / "dataset-1_kick_normal_001.bvh"
    (corpus / take.name).symlink_to(take)
    model = tmp_path / "model.npz"
    # 1e-6 divides 360: the build asked for 921 PiB.
    build = ["limits", "build", str(corpus), "-o", str(model), "--no-networks"]
    assert main([*build, "--bin-deg", "1e-6"]) == 3
    assert "Expected `bin_deg` from 0.5 to 360 degrees, got 1e-06" in capsys.readouterr().err
    assert main([*build, "--workers", "-1"]) == 2  # a usage error, as Typer reports it
    assert "'--workers': -1 is not in the range x>=0" in capsys.readouterr().err
    assert not model.exists()
    missing = tmp_path / "missing_dir"
    assert main(["limits", "check", str(take), "--frame-from", str(missing)]) == 3
    err = capsys.readouterr().err
    assert "--frame-from" in err
    assert "got a path that does not exist" in err


def test_batch_refuses_a_negative_worker_count(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["batch", str(tmp_path), "--workers", "-1"]) == 2
    assert "'--workers': -1 is not in the range x>=0" in capsys.readouterr().err
