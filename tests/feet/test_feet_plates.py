"""Force plates as ground truth: the plate contacts of real C3D gait trials, the marker contact
detector against them, foot markers by name, and C3D takes through ``mocapqa feet check``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError
from mocapqa.feet.markers import MARKER_PARAMS, marker_foot_points
from mocapqa.feet.plates import over_plates, plate_contacts
from mocapqa.io.c3d_plates import read_force_plates
from mocapqa_bench.feet_plates import (
    MARKER_GRID,
    PlateTrial,
    marker_params_by_leave_one_out,
    plate_trial,
    score_plate_trial,
)

PIG = "c3d/btk/PiG_Motion-FlatFoot-Full.c3d"
GAIT = (PIG, "c3d/btk/Eb015pr.c3d", "c3d/btk/DEC_INT.C3D")


@pytest.fixture(scope="module")
def trials(corpus_dir: Path) -> dict[str, PlateTrial]:
    found = {}
    for name in GAIT:
        trial = plate_trial(corpus_dir / name, name)
        assert trial is not None
        found[name] = trial
    return found


@pytest.mark.parametrize(
    ("name", "strikes"),
    [
        (PIG, [(0, "right", 108), (1, "left", 158)]),
        ("c3d/btk/Eb015pr.c3d", [(1, "right", 136), (0, "right", 269)]),
        ("c3d/btk/DEC_INT.C3D", [(1, "right", 18), (0, "left", 41)]),
    ],
)
def test_each_plate_strike_goes_to_the_foot_standing_on_it(
    trials: dict[str, PlateTrial], name: str, strikes: list[tuple[int, str, int]]
) -> None:
    trial = trials[name]
    assert trial.note == ""
    assert [(t.plate, t.foot, t.start) for t in trial.truth] == strikes
    for t in trial.truth:
        # The swing foot crossing the plate low does not count as standing on it.
        assert min(t.over) == 0.0
        assert max(t.over) > 0.8
        assert not t.cut_start
        assert not t.cut_end


def test_the_pig_trial_s_plates_load_for_about_0_6_s(trials: dict[str, PlateTrial]) -> None:
    durations = [t.end_s - t.start_s for t in trials[PIG].truth]
    assert durations == pytest.approx([0.605, 0.608], abs=0.01)


def test_the_marker_detector_finds_the_strikes_within_tolerance(
    trials: dict[str, PlateTrial],
) -> None:
    for name, trial in trials.items():
        score = score_plate_trial(trial, MARKER_PARAMS)
        assert score is not None
        assert (score.found, score.right, score.judged) == (2, 2, 2), name
        tolerance = 40.0 if name == PIG else 60.0  # 100 fps against 50 fps (20 ms frames)
        assert np.all(np.abs(score.onset_ms) <= tolerance), (name, score.onset_ms)
        assert np.all(np.abs(score.offset_ms) <= tolerance), (name, score.offset_ms)


def test_the_bench_s_choice_on_all_trials_is_the_marker_default(
    trials: dict[str, PlateTrial],
) -> None:
    rows, chosen = marker_params_by_leave_one_out(list(trials.values()))
    # The contact fields of the grid; the skate fields of marker takes are set apart.
    for name in MARKER_GRID[0]:
        assert getattr(chosen, name) == getattr(MARKER_PARAMS, name), name
    assert all(row.score is not None and row.score.recall == 1.0 for row in rows)


def test_held_out_edges_moved_to_the_kinematic_events_are_closer_to_the_plates(
    trials: dict[str, PlateTrial],
) -> None:
    rows, _ = marker_params_by_leave_one_out(list(trials.values()))
    onsets = np.concatenate([r.score.onset_ms for r in rows if r.score is not None])
    offsets = np.concatenate([r.score.offset_ms for r in rows if r.score is not None])
    assert onsets.size == 6
    assert np.median(np.abs(onsets)) <= 20.0
    assert np.median(np.abs(offsets)) <= 25.0
    # Without the event window (every candidate's edges as detected) onsets are later or
    # earlier by more.
    still = [g for g in MARKER_GRID if g["event_before_s"] == g["event_after_s"] == 0.0]
    rows, _ = marker_params_by_leave_one_out(list(trials.values()), still)
    plain = np.concatenate([r.score.onset_ms for r in rows if r.score is not None])
    assert np.median(np.abs(plain)) > 30.0


def test_the_plates_baseline_is_removed_and_a_dead_plate_is_flat(corpus_dir: Path) -> None:
    gait = read_force_plates(corpus_dir / "c3d/btk/Eb015pr.c3d")
    assert gait.analog_rate == 200.0
    assert gait.samples_per_frame == 4
    for plate in gait.plates:
        assert abs(float(np.median(plate.load[:40]))) < 3.0  # read 21–32 N unloaded
        assert plate.load.max() > 800.0
    dead = read_force_plates(corpus_dir / "c3d/btk/parameterOverflow.c3d")
    assert [p.flat for p in dead.plates] == [False, False, True]


def test_a_foot_over_a_plate_only_when_inside_low_and_still() -> None:
    corners = np.array([[[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [100.0, 50.0, 0.0], [0.0, 50.0, 0.0]]])
    positions = np.array(
        [[[50.0, 25.0, 2.0], [150.0, 25.0, 2.0], [50.0, 25.0, 30.0]]] * 3
    )  # inside, outside, too high
    positions[:, 0] += np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [20.0, 0.0, 0.0]])
    on = over_plates(positions, corners, max_height=10.0, fps=1.0, max_speed=5.0)
    assert on[:, :, 0].tolist() == [[False, False, False]] * 3  # the inside point moves
    on = over_plates(positions, corners, max_height=10.0, fps=1.0, max_speed=20.0)
    assert on[:, :, 0].tolist() == [[True, False, False]] * 3
    loads = np.zeros((30, 1))
    loads[5:20] = 300.0
    contacts = plate_contacts(loads, 10.0, 10, on, ("left", "right", "right"))
    assert len(contacts) == 1
    assert contacts[0].foot == "left"
    assert (contacts[0].start_s, contacts[0].end_s) == (0.5, 1.9)
    assert (contacts[0].start, contacts[0].end) == (0, 1)


def _markers(names: tuple[str, ...], frames: int = 4) -> KeypointSequence:
    rng = np.random.default_rng(0)
    positions = rng.normal(size=(frames, len(names), 3)) * 10.0
    return KeypointSequence(
        names=names,
        positions=positions,
        confidence=np.ones((frames, len(names))),
        fps=100.0,
        length_unit="mm",
        source_format="c3d",
    )


def test_foot_markers_are_found_by_name_behind_a_subject_prefix() -> None:
    names = tuple(
        f"TakeoMonday:{n}"
        for n in ("LFWT", "RFWT", "LKNE", "RKNE", "LANK", "RANK", "LHEE", "RHEE", "LTOE", "RTOE")
    )
    points = marker_foot_points(_markers(names))
    assert points.names == tuple(f"TakeoMonday:{n}" for n in ("LHEE", "LTOE", "RHEE", "RTOE"))
    assert points.parts == ("heel", "toe", "heel", "toe")
    assert points.sides == ("left", "left", "right", "right")


def test_a_take_without_foot_markers_is_an_input_error() -> None:
    with pytest.raises(InputError, match="got none for the left and right foot"):
        marker_foot_points(_markers(("PT00", "PT01", "PT02")))


def test_feet_check_of_a_c3d_gait_trial_keeps_the_contract(
    corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["feet", "check", str(corpus_dir / PIG), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["up_axis"] == "Z"
    assert data["length_unit"] == "mm"
    assert [p["name"] for p in data["points"]] == ["LHEE", "LTOE", "RHEE", "RTOE"]
    contacts = data["contacts"]
    assert [c["foot"] for c in contacts] == ["left", "right"] * 3 + ["left"]
    assert all(0 <= c["start"] <= c["end"] < 315 for c in contacts)
    assert isinstance(data["findings"], list)


def test_feet_check_of_a_c3d_without_foot_markers_exits_with_the_input_error_code(
    corpus_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["feet", "check", str(corpus_dir / "c3d/btk/FP1.C3D"), "--json"]) == 3
    err = capsys.readouterr().err
    assert "Expected heel, toe or ankle markers on both feet" in err
    assert "PT00" in err
