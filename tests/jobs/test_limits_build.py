"""``mocapqa limits build`` on Dask, canonical and per-rig: the same model as in one process, on
a real local cluster."""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.errors import InputError
from mocapqa.jobs.engine import Engine
from mocapqa.jobs.limits_build import build_on_engine
from mocapqa.limits import canonical
from mocapqa.limits.build import DEFAULT_BUILD, build_canonical_model, build_model
from mocapqa.limits.discriminator import DiscriminatorParams
from mocapqa.limits.model import LimitsModel
from mocapqa.limits.storage import load_model, model_bytes
from mocapqa_bench.limits import canonical_takes, rig_takes

# Five Bandai clips of two rigs (dataset-1 and dataset-2 joint frames; the second clip is held
# back by the split), two Character Creator takes (the second held back), the single CMU-style
# walk and a take of another rig family ("other", not split).
TAKES = (
    "bandai/dataset-1_dash_chimpira_001.bvh",
    "bandai/dataset-1_dash_normal_001.bvh",
    "bandai/dataset-1_run_giant_001.bvh",
    "bandai/dataset-2_raise-up-left-hand_active_001.bvh",
    "bandai/dataset-2_wave-left-hand_active_011.bvh",
    "cmu/iclone/002_03.bvh",
    "cmu/iclone/007_12.bvh",
    "cmu/cmu_12_01_walk.bvh",
    "misc/bvh_test2.bvh",
)
# Small networks: the test is about the data reaching the training, not their accuracy.
SETTINGS = replace(
    DEFAULT_BUILD,
    discriminator=DiscriminatorParams(n_valid=300, hidden_sizes=(6, 4), max_iter=40),
)


@pytest.fixture(scope="module")
def engine() -> Iterator[Engine]:
    with Engine(workers=2) as local:
        yield local


@pytest.fixture
def corpus(corpus_dir: Path, tmp_path: Path) -> Path:
    folder = tmp_path / "takes"
    for name in TAKES:
        link = folder / name
        link.parent.mkdir(parents=True, exist_ok=True)
        link.symlink_to(corpus_dir / "bvh" / name)
    return folder


def _contents(model: LimitsModel) -> tuple[dict[str, object], dict[str, np.ndarray]]:
    """A model's file content: its metadata and every array."""
    with np.load(io.BytesIO(model_bytes(model))) as data:
        arrays = {key: data[key] for key in data.files}
    meta = json.loads(arrays.pop("meta").tobytes().decode("utf-8"))
    return meta, arrays


def _assert_same(a: LimitsModel, b: LimitsModel) -> None:
    meta_a, arrays_a = _contents(a)
    meta_b, arrays_b = _contents(b)
    assert meta_a == meta_b
    assert arrays_a.keys() == arrays_b.keys()
    for key, value in arrays_a.items():
        np.testing.assert_array_equal(value, arrays_b[key], err_msg=key)


@pytest.mark.parametrize("median_frames", [4000, 30])
def test_build_on_two_workers_equals_the_build_in_one_process(
    engine: Engine, corpus: Path, median_frames: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 30: the pooled frames of each Bandai rig (two build takes each) exceed the frame
    # estimate's sample, so each worker returns the part of the rig's evenly spaced sample
    # that falls in its take.
    monkeypatch.setattr(canonical, "_MEDIAN_FRAMES", median_frames)
    takes = canonical_takes(corpus)
    here = build_canonical_model([m for _, m in takes], [n for n, _ in takes], SETTINGS)
    steps: list[str] = []
    totals: list[int] = []
    there = build_on_engine(engine, corpus, SETTINGS, on_total=totals.append, step=steps.append)
    _assert_same(here, there)
    assert there.takes == (
        "002_03.bvh",
        "bvh_test2.bvh",
        "cmu_12_01_walk.bvh",
        "dataset-1_dash_chimpira_001.bvh",
        "dataset-1_run_giant_001.bvh",
        "dataset-2_raise-up-left-hand_active_001.bvh",
        "dataset-2_wave-left-hand_active_011.bvh",
    )
    assert all(j.network is not None for j in there.joints)
    assert len(there.rig_frames) == 4  # the four Bandai build clips are of one rig
    assert totals[0] == len(TAKES)
    assert len(steps) == len(TAKES) + 2 * len(there.takes) + len(there.joints)
    assert totals[-1] >= len(steps)


@pytest.mark.parametrize(
    ("build", "left_out", "n_takes"),
    [([], "007_12.bvh", len(TAKES) - 1), (["--rig", "bandai"], "dataset-1_run_giant_001.bvh", 4)],
    ids=["canonical", "per-rig"],
)
def test_cli_builds_on_a_local_cluster(
    corpus: Path, tmp_path: Path, build: list[str], left_out: str, n_takes: int
) -> None:
    on_dask = tmp_path / "dask.npz"
    here = tmp_path / "here.npz"
    common = [*build, "--no-networks", "--exclude", left_out, "--all-takes"]
    assert (
        main(["limits", "build", str(corpus), "-o", str(on_dask), "--workers", "2", *common]) == 0
    )
    assert main(["limits", "build", str(corpus), "-o", str(here), *common]) == 0
    _assert_same(load_model(on_dask), load_model(here))
    assert left_out not in load_model(on_dask).takes
    assert len(load_model(on_dask).takes) == n_takes


@pytest.mark.parametrize(
    ("all_takes", "exclude", "expected"),
    [
        # the fixed split holds back the second of the five Bandai clips
        (False, frozenset(), ("dataset-1_dash_chimpira_001.bvh", "dataset-1_run_giant_001.bvh",
                              "dataset-2_raise-up-left-hand_active_001.bvh",
                              "dataset-2_wave-left-hand_active_011.bvh")),
        # every take, the held-back one after the build takes, less the one excluded
        (True, frozenset({"dataset-1_run_giant_001.bvh"}),
         ("dataset-1_dash_chimpira_001.bvh", "dataset-2_raise-up-left-hand_active_001.bvh",
          "dataset-2_wave-left-hand_active_011.bvh", "dataset-1_dash_normal_001.bvh")),
    ],
)  # fmt: skip
def test_per_rig_build_on_two_workers_equals_the_build_in_one_process(
    engine: Engine, corpus: Path, all_takes: bool, exclude: frozenset[str],
    expected: tuple[str, ...],
) -> None:  # fmt: skip
    takes = rig_takes(corpus, "bandai", all_takes, exclude)
    here = build_model([m for _, m in takes], [n for n, _ in takes], SETTINGS)
    steps: list[str] = []
    totals: list[int] = []
    there = build_on_engine(
        engine, corpus, SETTINGS, "bandai", all_takes, exclude, totals.append, steps.append
    )
    _assert_same(here, there)
    assert there.rig_family == "bandai"
    assert there.frame != "canonical"
    assert there.takes == expected
    assert all(j.network is not None for j in there.joints)
    assert len(there.joints) == 14
    assert totals == [len(TAKES), len(TAKES) + len(expected) + len(there.joints)]
    assert steps == (
        ["reading takes"] * len(TAKES)
        + ["charting takes"] * len(expected)
        + [f"built {j.name}" for j in there.joints]
    )


@pytest.fixture
def character_creator(corpus_dir: Path, tmp_path: Path) -> Path:
    """A folder of two Character Creator takes (the second held back by the split)."""
    folder = tmp_path / "character_creator"
    folder.mkdir()
    for name in ("002_03.bvh", "007_12.bvh"):
        (folder / name).symlink_to(corpus_dir / "bvh" / "cmu" / "iclone" / name)
    return folder


@pytest.mark.parametrize("dask", [[], ["--workers", "2"]], ids=["in-process", "dask"])
def test_per_rig_build_without_takes_of_the_rig_is_an_input_error(
    character_creator: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
    dask: list[str],
) -> None:  # fmt: skip
    out = tmp_path / "m.npz"
    build = ["limits", "build", str(character_creator), "-o", str(out), "--no-networks", *dask]
    capsys.readouterr()
    assert main([*build, "--rig", "robot"]) == 3
    assert "Expected a rig family among bandai, character_creator, cmu, got 'robot'" in (
        capsys.readouterr().err
    )
    assert main([*build, "--rig", "bandai"]) == 3
    assert f"Expected one bandai rig with two or more takes in {character_creator}, got 0" in (
        capsys.readouterr().err
    )
    assert not out.exists()


def test_per_rig_build_with_every_take_left_out_is_an_input_error(
    engine: Engine, character_creator: Path
) -> None:
    message = "Expected takes of the character_creator rig left to build from, got none"
    left_out = {"002_03.bvh"}  # the one build take
    with pytest.raises(InputError, match=message):
        rig_takes(character_creator, "character_creator", exclude=left_out)
    with pytest.raises(InputError, match=message):
        build_on_engine(engine, character_creator, SETTINGS, "character_creator", exclude=left_out)


def test_a_folder_without_takes_with_roles_is_an_input_error(
    engine: Engine, tmp_path: Path
) -> None:
    with pytest.raises(InputError, match="got none"):
        build_on_engine(engine, tmp_path, SETTINGS)


def test_a_mapping_reaches_the_build_on_the_cluster(
    engine: Engine, corpus: Path, tmp_path: Path
) -> None:
    # The CMU walk's hands named by hand as the finger bases below them (a choice no name rule
    # makes): the frames stored for that rig show whether the mapping was used.
    mapping = {"left_hand": "LeftFingerBase", "right_hand": "RightFingerBase"}
    takes = canonical_takes(corpus, all_takes=True, mapping=mapping)
    settings = replace(SETTINGS, discriminator=None)
    here = build_canonical_model(
        [m for _, m in takes], [n for n, _ in takes], settings, mapping=mapping
    )
    there = build_on_engine(engine, corpus, settings, all_takes=True, mapping=mapping)
    _assert_same(here, there)
    walk = next(f for f in there.rig_frames.values() if "LeftFingerBase" in f.joints)
    assert walk.joints[walk.roles.index("left_hand")] == "LeftFingerBase"
    plain = build_on_engine(engine, corpus, settings, all_takes=True)
    assert not any("LeftFingerBase" in f.joints for f in plain.rig_frames.values())
    with pytest.raises(InputError, match="every joint the mapping names"):
        build_on_engine(engine, corpus, SETTINGS, mapping={"left_hand": "NoSuchJoint"})
