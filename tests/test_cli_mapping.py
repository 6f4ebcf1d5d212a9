"""``--mapping FILE`` on every command that reads a BVH, and the warning naming missing roles."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from mocapqa.cli.main import main
from mocapqa.errors import InputError
from mocapqa.io.bvh import read_bvh
from mocapqa.io.bvh_write import write_bvh
from mocapqa.io.mapping import read_mapping
from mocapqa.pipeline.options import AnalysisOptions

# The CMU walk with its toes and forearms renamed to words no convention uses.
RENAMED = {
    "LeftToeBase": "LeftDigits", "RightToeBase": "RightDigits",
    "LeftForeArm": "LeftLimbB", "RightForeArm": "RightLimbB",
}  # fmt: skip
MISSING = ["left_forearm", "left_toe", "right_forearm", "right_toe"]
MAPPING_TOML = (
    'left_toe = "LeftDigits"\nright_toe = "RightDigits"\n'
    'left_forearm = "LeftLimbB"\nright_forearm = "RightLimbB"\n'
)


@pytest.fixture
def odd_walk(cmu_walk: Path, tmp_path: Path) -> Path:
    motion = read_bvh(cmu_walk)
    names = tuple(RENAMED.get(n, n) for n in motion.skeleton.names)
    renamed = replace(motion, skeleton=replace(motion.skeleton, names=names))
    path = tmp_path / "odd_walk.bvh"
    write_bvh(path, renamed)
    return path


@pytest.fixture
def mapping_file(tmp_path: Path) -> Path:
    path = tmp_path / "rig.toml"
    path.write_text(MAPPING_TOML, encoding="utf-8")
    return path


def commands(take: Path, out: Path) -> list[list[str]]:
    return [
        ["info", str(take)],
        ["convert", str(take), "-o", str(out / "copy.bvh")],
        ["filter", str(take), "-o", str(out / "filtered.bvh")],
        ["detect", str(take)],
        ["refine", str(take), "-o", str(out / "refined.bvh")],
        ["limits", "check", str(take)],
    ]


def test_every_bvh_command_names_the_missing_roles(
    odd_walk: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for args in commands(odd_walk, tmp_path):
        code = main(args)
        err = capsys.readouterr().err
        assert "rig roles not found: " + ", ".join(MISSING) in " ".join(err.split()), args
        assert code in (0, 6), args  # limits check: no shipped model for a renamed rig


def test_every_bvh_command_takes_a_mapping(
    odd_walk: Path, mapping_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for args in commands(odd_walk, tmp_path):
        code = main([*args, "--mapping", str(mapping_file)])
        err = capsys.readouterr().err
        assert "rig roles not found" not in err, args
        assert code in (0, 6), args


def test_the_mapping_reaches_the_twist_check(
    odd_walk: Path, mapping_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["detect", str(odd_walk), "--json"]) == 0
    without = json.loads(capsys.readouterr().out)
    assert without["missing_roles"] == MISSING
    assert main(["detect", str(odd_walk), "--json", "--mapping", str(mapping_file)]) == 0
    with_mapping = json.loads(capsys.readouterr().out)
    assert with_mapping["missing_roles"] == []
    # Without forearms no arm chain is checked, without toes no foot chain: only the thighs.
    assert [j["segment"] for j in without["joints"]] == ["upper_leg", "upper_leg"]
    assert len(with_mapping["joints"]) == 10


def test_a_mapping_naming_an_unknown_joint_exits_3(
    odd_walk: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text('{"left_toe": "NoSuchJoint"}', encoding="utf-8")
    assert main(["detect", str(odd_walk), "--mapping", str(bad)]) == 3
    assert "to be a joint of this skeleton, got 'NoSuchJoint'" in capsys.readouterr().err


def test_mapping_files_in_json_and_toml_either_way_round(tmp_path: Path) -> None:
    as_json = tmp_path / "rig.json"
    as_json.write_text('{"LeftDigits": "left_toe"}', encoding="utf-8")
    as_toml = tmp_path / "rig.toml"
    as_toml.write_text('left_toe = "LeftDigits"\n', encoding="utf-8")
    assert read_mapping(as_json) == read_mapping(as_toml) == {"left_toe": "LeftDigits"}


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        # JSON keeps the last of a key given twice: one of the two roles was dropped unseen.
        ('{"left_upper_arm": "LeftArm", "left_upper_arm": "RightArm"}', "'left_upper_arm' twice"),
        ('{"left_upper_arm": {"joint": "LeftArm"}}', "for 'left_upper_arm', got dict"),
        ('{"left_upper_arm": "LeftArm", "right_upper_arm": "LeftArm"}', "one role per joint"),
    ],
)
def test_a_mapping_file_that_contradicts_itself_names_the_fault(
    text: str, pattern: str, tmp_path: Path
) -> None:
    path = tmp_path / "rig.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=pattern) as raised:
        read_mapping(path)
    assert "rig.json" in str(raised.value)


def test_run_options_carry_the_mapping() -> None:
    options = AnalysisOptions.from_json({"mapping": {"left_toe": "LeftDigits"}})
    assert options.mapping == {"left_toe": "LeftDigits"}
    assert AnalysisOptions.from_json(options.to_json()) == options
    with pytest.raises(InputError, match="mapping: Expected a role in"):
        AnalysisOptions.from_json({"mapping": {"left_toes": "LeftDigits"}})
    with pytest.raises(InputError, match="Expected mapping to be an object"):
        AnalysisOptions.from_json({"mapping": ["left_toe"]})


def test_a_run_reports_its_roles_and_uses_the_mapping(odd_walk: Path) -> None:
    from mocapqa.pipeline.analyze import analyze

    motion = read_bvh(odd_walk)
    plain = analyze(motion, AnalysisOptions(checks=("twist",), max_points=100)).report
    assert plain["summary"]["missing_roles"] == MISSING
    assert "roles not found, not checked: left_forearm" in plain["steps"]["twist"]["message"]
    mapped = analyze(
        motion,
        AnalysisOptions(checks=("twist",), max_points=100, mapping=read_mapping_text()),
    ).report
    assert mapped["summary"]["missing_roles"] == []
    assert mapped["summary"]["roles"]["left_toe"] == "LeftDigits"
    assert mapped["options"]["mapping"]["right_forearm"] == "RightLimbB"
    assert "10 chain(s)" in mapped["steps"]["twist"]["message"]


def read_mapping_text() -> dict[str, str]:
    import tomllib

    return dict(tomllib.loads(MAPPING_TOML))


@pytest.fixture
def odd_folder(odd_walk: Path, tmp_path: Path) -> Path:
    """A folder holding the renamed walk, as ``limits build`` reads takes."""
    folder = tmp_path / "takes"
    folder.mkdir()
    (folder / "odd_walk.bvh").symlink_to(odd_walk)
    return folder


def test_limits_build_takes_a_mapping_and_stores_it_with_the_rig(
    odd_walk: Path, odd_folder: Path, mapping_file: Path, tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    from mocapqa.limits.storage import load_model

    folder = odd_folder
    without, with_mapping = tmp_path / "without.npz", tmp_path / "with.npz"
    build = ["limits", "build", str(folder), "--no-networks", "--all-takes"]
    assert main([*build, "-o", str(without)]) == 0
    assert main([*build, "-o", str(with_mapping), "--mapping", str(mapping_file)]) == 0
    # By name the renamed forearms are not found, so neither are the hands below them.
    assert not {"left_forearm", "left_hand"} & {j.role for j in load_model(without).joints}
    mapped = load_model(with_mapping)
    assert {"left_forearm", "right_forearm", "left_hand"} <= {j.role for j in mapped.joints}
    (stored,) = mapped.rig_frames.values()
    assert stored.joints[stored.roles.index("left_forearm")] == "LeftLimbB"
    # A take of the rig is checked with the roles stored for it.
    capsys.readouterr()
    assert main(["limits", "check", str(odd_walk), "--model", str(with_mapping), "--json"]) == 0
    checked = {j["role"] for j in json.loads(capsys.readouterr().out)["joints"]}
    assert {"left_forearm", "right_forearm"} <= checked


def test_limits_build_refuses_a_mapping_it_cannot_use(
    odd_folder: Path, mapping_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = odd_folder
    out = ["-o", str(tmp_path / "m.npz"), "--no-networks", "--all-takes"]
    # A per-rig model matches its joints by name.
    per_rig = ["limits", "build", str(folder), *out, "--rig", "cmu", "--mapping", str(mapping_file)]
    assert main(per_rig) == 3
    assert "matches its joints by name" in capsys.readouterr().err
    other = tmp_path / "other.json"
    other.write_text('{"left_forearm": "L_Elbow"}', encoding="utf-8")
    assert main(["limits", "build", str(folder), *out, "--mapping", str(other)]) == 3
    assert "every joint the mapping names (L_Elbow)" in " ".join(capsys.readouterr().err.split())
    assert not (tmp_path / "m.npz").exists()


def test_a_rig_named_only_by_its_mapping_gets_the_limits_check(cmu_walk: Path) -> None:
    from mocapqa.core.rig import find_roles
    from mocapqa.pipeline.analyze import analyze

    motion = read_bvh(cmu_walk)
    roles = find_roles(motion.skeleton).roles
    # Every joint renamed to a number: no name rule finds a role.
    names = tuple(f"j{k}" for k in range(motion.skeleton.n_joints))
    anonymous = replace(motion, skeleton=replace(motion.skeleton, names=names))
    mapping = {key: names[joint] for key, joint in roles.items()}
    options = {"checks": ("limits",), "max_points": 100}
    plain = analyze(anonymous, AnalysisOptions(**options)).report  # type: ignore[arg-type]
    assert plain["steps"]["limits"]["state"] == "no_model"
    assert "name them with a mapping" in plain["steps"]["limits"]["message"]
    mapped = analyze(anonymous, AnalysisOptions(**options, mapping=mapping)).report  # type: ignore[arg-type]
    assert mapped["steps"]["limits"]["state"] == "done", mapped["steps"]["limits"]
    named = analyze(motion, AnalysisOptions(**options)).report  # type: ignore[arg-type]
    # The same walk checked under its own names and under numbers with the mapping alike.
    assert mapped["steps"]["limits"]["message"] == named["steps"]["limits"]["message"]
    assert mapped["findings"] == [
        {**f, "joint": names[motion.skeleton.index(f["joint"])]} for f in named["findings"]
    ]


def test_a_take_no_check_could_read_is_not_scored_as_clean(cmu_walk: Path) -> None:
    from mocapqa.pipeline.analyze import analyze
    from mocapqa.pipeline.summary import qa_summary

    motion = read_bvh(cmu_walk)
    names = tuple(f"j{k}" for k in range(motion.skeleton.n_joints))
    anonymous = replace(motion, skeleton=replace(motion.skeleton, names=names))
    result = analyze(anonymous, AnalysisOptions(checks=("twist", "limits"), max_points=100))
    twist = result.report["steps"]["twist"]
    assert twist["state"] == "no_roles"
    assert "nothing checked" in twist["message"]
    assert "left_upper_arm" in twist["message"]
    assert qa_summary(result)["score"] is None
    # The same walk under its own names is checked and scored.
    named = analyze(motion, AnalysisOptions(checks=("twist", "limits"), max_points=100))
    assert qa_summary(named)["score"] is not None
