"""filter_keypoints, filter_motion, the registry and the CLI on the real data."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from mocapqa.cli.main import main
from mocapqa.core.keypoints import KeypointSequence
from mocapqa.errors import InputError, OptionError
from mocapqa.filters.apply import data_scale, filter_keypoints, filter_motion
from mocapqa.filters.registry import FILTERS, DataScale
from mocapqa.io.bvh import read_bvh
from mocapqa.io.formats import read_take
from mocapqa.metrics.smoothness import mean_abs_jerk

BALANCING = (
    "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose-3d/S00_P00_T01_BalancingTrial_0-100.trc"
)
BANDAI = "bvh/bandai/dataset-2_wave-right-hand_active_001.bvh"


@pytest.fixture(scope="module")
def trc(corpus_dir: Path) -> KeypointSequence:
    take = read_take(corpus_dir / BALANCING)
    assert isinstance(take, KeypointSequence)
    return take


@pytest.mark.parametrize("method", ["adaptive", "kalman", "one-euro", "ema", "butterworth"])
@pytest.mark.parametrize("preset", ["default", "note"])
def test_every_keypoint_method_smooths_real_trc_without_nan(
    trc: KeypointSequence, method: str, preset: str
) -> None:
    if preset not in FILTERS[method].presets:
        with pytest.raises(InputError, match="Expected a preset"):
            filter_keypoints(trc, method, preset)
        return
    res = filter_keypoints(trc, method, preset)
    out = res.sequence
    assert out.positions.shape == trc.positions.shape
    assert out.length_unit == "m"
    assert not np.isnan(out.positions).any()
    assert mean_abs_jerk(out.positions, out.fps) < mean_abs_jerk(trc.positions, trc.fps)
    assert res.bridged.shape == (trc.n_frames, trc.n_keypoints)
    if method == "adaptive":
        assert res.weights is not None
        assert res.weights.shape == (trc.n_frames, trc.n_keypoints, 3)
        assert res.weight_names == ("kalman", "one_euro", "ema")
    report = res.to_json(max_points=10)
    assert len(report["timeline_frames"]) <= 10
    json.dumps(report)


def test_presets_follow_the_data_units(trc: KeypointSequence) -> None:
    metres = data_scale("m", 60.0)
    millimetres = data_scale("mm", 60.0)
    k_m = FILTERS["kalman"].preset("default", metres)
    k_mm = FILTERS["kalman"].preset("default", millimetres)
    assert k_mm.measurement_noise == pytest.approx(k_m.measurement_noise * 1e6)
    # The note's thresholds: 1.0 normalised unit/s = 2.0 m/s (stated assumption).
    assert FILTERS["adaptive"].preset("note", metres).fast_speed == pytest.approx(2.0)
    assert FILTERS["adaptive"].preset("note", data_scale("normalized", 30.0)).fast_speed == 1.0
    # Pixels: scale from the body extent, so the same take in mm and "px" filters alike.
    px = dataclasses.replace(trc, positions=trc.positions * 1000.0, length_unit="px")
    assert data_scale("px", 60.0, px.positions).units_per_metre == pytest.approx(
        1000.0 * data_scale("unknown", 60.0, trc.positions).units_per_metre
    )
    with pytest.raises(InputError, match="Expected metric units or keypoints"):
        data_scale("px", 60.0)


def test_missing_keypoint_is_bridged_and_an_empty_one_stays_a_marked_gap(
    trc: KeypointSequence,
) -> None:
    pos = trc.positions.copy()
    conf = trc.confidence.copy()
    pos[:5, 0] = np.nan
    pos[40:50, 1] = np.nan
    pos[:, 2] = np.nan
    seq = dataclasses.replace(trc, positions=pos, confidence=conf)
    res = filter_keypoints(seq, "adaptive")
    out = res.sequence.positions
    assert not np.isnan(out[:, :2]).any()
    assert np.isnan(out[:, 2]).all()
    assert res.bridged[:5, 0].all()
    assert res.bridged[40:50, 1].all()
    assert res.bridged[:, 2].all()


def test_unknown_method_preset_and_parameter_are_refused(trc: KeypointSequence) -> None:
    with pytest.raises(InputError, match="Expected a filter method"):
        filter_keypoints(trc, "median")
    with pytest.raises(InputError, match="Expected a keypoint filter method"):
        filter_keypoints(trc, "quat-pd")
    with pytest.raises(InputError, match="Expected a parameter in"):
        filter_keypoints(trc, "kalman", params={"speed": "1"})
    with pytest.raises(InputError, match="Expected a number"):
        filter_keypoints(trc, "kalman", params={"process_noise": "fast"})
    res = filter_keypoints(trc, "adaptive", params={"kalman.gate_sigma": "3.5"})
    assert res.params.kalman.gate_sigma == 3.5


def test_registry_describes_every_method() -> None:
    for name, entry in FILTERS.items():
        assert entry.name == name
        assert entry.kind in ("keypoints", "rotations", "both")
        infos = entry.describe(DataScale(100.0, 200.0, 30.0))
        assert infos
        names = [i.name for i in infos]
        assert len(names) == len(set(names))
        assert isinstance(entry.preset("default", DataScale()), entry.params)
    units = {i.name: i.unit for i in FILTERS["adaptive"].describe()}
    assert units["kalman.process_noise"] == "unit²/s⁴"
    assert units["one_euro.min_cutoff_hz"] == "Hz"
    assert units["window_s"] == "s"


@pytest.mark.parametrize("method", ["quat-pd", "quat-one-euro", "euler-pd", "butterworth"])
def test_filter_motion_keeps_unit_rotations_on_a_real_take(corpus_dir: Path, method: str) -> None:
    motion = read_bvh(corpus_dir / BANDAI, length_unit="cm")
    out = filter_motion(motion, method)
    assert out.quats.shape == motion.quats.shape
    np.testing.assert_allclose(np.linalg.norm(out.quats, axis=-1), 1.0, atol=1e-9)
    assert np.isfinite(out.translations).all()
    with pytest.raises(InputError, match="Expected a rotation filter method"):
        filter_motion(motion, "adaptive")


def test_cli_filters_trc_to_csv_with_a_report(corpus_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    report = tmp_path / "report.json"
    argv = ["filter", str(corpus_dir / BALANCING), "-o", str(out), "--method", "adaptive"]
    code = main([*argv, "--param", "window_s=0.2", "--report", str(report)])
    assert code == 0
    back = read_take(out, fps=60.0)
    assert isinstance(back, KeypointSequence)
    assert back.positions.shape[1] == 21
    data = json.loads(report.read_text())
    assert data["weight_names"] == ["kalman", "one_euro", "ema"]
    assert len(data["per_keypoint"]) == 21
    # The CSV written is read back and filtered again (long format in and out).
    assert main(["filter", str(out), "-o", str(tmp_path / "again.csv"), "--fps", "60"]) == 0


def test_cli_filters_a_bvh_and_refuses_bad_parameters(corpus_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.bvh"
    assert main(["filter", str(corpus_dir / BANDAI), "-o", str(out), "--method", "quat-pd"]) == 0
    assert read_bvh(out).n_frames == read_bvh(corpus_dir / BANDAI).n_frames
    bad = ["filter", str(corpus_dir / BANDAI), "-o", str(out), "--param", "natural_frequency_hz=9"]
    assert main(bad) == 3
    assert main([*bad[:4], "--param", "oops"]) == 3


@pytest.mark.parametrize(
    ("method", "param", "value", "message"),
    [
        ("adaptive", "window_s", "inf", "0.0001 to 60 s"),  # was an OverflowError
        ("adaptive", "window_s", "1e9", "0.0001 to 60 s"),  # was a MemoryError
        ("adaptive", "confidence_threshold", "nan", "0 to 1"),  # was accepted
        ("adaptive", "innovation_power", "100", "at most 10"),  # was all-NaN output
        ("adaptive", "kalman.process_noise", "1e400", "1e-24 to 1e+24"),
        ("adaptive", "kalman.gate_sigma", "1e300", "0 to 1000"),  # was an OverflowError
        ("one-euro", "min_cutoff_hz", "inf", "0.001 to 10000 Hz"),  # was all-NaN output
        ("one-euro", "beta", "inf", "0 to 1e+20"),
        ("kalman", "measurement_noise", "inf", "1e-24 to 1e+24"),
        ("kalman", "process_noise", "1e400", "1e-24 to 1e+24"),
        ("ema", "time_constant_s", "-inf", "0.0001 to 60 s"),
        ("butterworth", "cutoff_hz", "nan", "0.001 to 10000 Hz"),
    ],
)
def test_every_filter_parameter_is_finite_and_in_its_range(
    trc: KeypointSequence, method: str, param: str, value: str, message: str
) -> None:
    with pytest.raises(OptionError, match=re.escape(message)) as raised:
        filter_keypoints(trc, method, "default", {param: value})
    assert raised.value.field == param
    # The same override as a number (the API's JSON) is refused the same way.
    with pytest.raises(OptionError, match=re.escape(message)):
        filter_keypoints(trc, method, "default", {param: float(value)})


def test_rotation_filter_parameters_are_in_their_range(corpus_dir: Path) -> None:
    motion = read_bvh(corpus_dir / BANDAI)
    with pytest.raises(OptionError, match=r"`natural_frequency_hz` 0\.001 to 10000 Hz, got inf"):
        filter_motion(motion, "quat-pd", {"natural_frequency_hz": "inf"})
    with pytest.raises(OptionError, match="`beta`"):
        filter_motion(motion, "quat-one-euro", {"beta": "nan"})


@pytest.mark.parametrize("extent", [1e-8, 1.0, 1e9])
def test_presets_stay_in_range_for_any_unit_and_the_bounds_filter_finitely(
    trc: KeypointSequence, extent: float
) -> None:
    # Data of unknown unit and any size: the presets convert to its scale within the ranges,
    # and the extreme values of the ranges still give finite output.
    scale = extent / float(np.nanmax(np.abs(trc.positions)))
    seq = dataclasses.replace(trc, positions=trc.positions * scale, length_unit="unknown")
    for method in ("adaptive", "kalman", "one-euro", "ema", "butterworth"):
        for preset in FILTERS[method].presets:
            assert np.isfinite(filter_keypoints(seq, method, preset).sequence.positions).all()
    for noise in ("1e-24", "1e24"):
        extremes = {
            "kalman.measurement_noise": noise, "kalman.process_noise": noise,
            "innovation_power": "10", "kalman.gate_sigma": "1000",
        }  # fmt: skip
        out = filter_keypoints(seq, "adaptive", "default", extremes).sequence.positions
        assert np.isfinite(out).all()


def test_cli_filter_refuses_out_of_range_parameters_naming_them(
    corpus_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.trc"
    argv = ["filter", str(corpus_dir / BALANCING), "-o", str(out)]
    for extra in (
        ["--param", "window_s=inf"],
        ["--param", "window_s=1e9"],
        ["--method", "one-euro", "--param", "beta=inf"],
        ["--method", "kalman", "--param", "measurement_noise=inf"],
        ["--param", "confidence_threshold=nan"],
        ["--fps", "inf"],
    ):
        assert main([*argv, *extra]) == 3, extra
        err = capsys.readouterr().err
        assert "Traceback" not in err
        assert extra[-1].split("=")[0] in err or "--fps" in err, err
    assert not out.exists()
    assert main([*argv, "--fps", "inf"]) == 3
    assert "Expected --fps finite, at least 0.1" in capsys.readouterr().err


PBTXT = "keypoints/mediapipe/google_mediapipe_testdata/pose_landmarks.pbtxt"


def _strict_json(text: str) -> Any:
    """JSON as other tools read it: NaN and Infinity are not JSON."""

    def refuse(token: str) -> None:
        raise ValueError(f"Expected strict JSON, got {token}")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize("method", ["adaptive", "kalman", "one-euro", "ema", "butterworth"])
def test_cli_filters_a_one_frame_pbtxt_and_reports_short_take_metrics_as_unavailable(
    corpus_dir: Path, tmp_path: Path, method: str
) -> None:
    # MediaPipe's golden pbtxt is one frame; lag_frames raised ValueError after the output
    # was written.
    source = corpus_dir / PBTXT
    take = read_take(source)
    assert isinstance(take, KeypointSequence)
    assert take.n_frames == 1
    out, report = tmp_path / "one.json", tmp_path / "one.report.json"
    argv = ["filter", str(source), "-o", str(out), "--method", method, "--report", str(report)]
    assert main(argv) == 0
    back = read_take(out)
    assert isinstance(back, KeypointSequence)
    np.testing.assert_allclose(back.positions, take.positions, rtol=0, atol=1e-12)
    data = _strict_json(report.read_text(encoding="utf-8"))
    rows = data["per_keypoint"]
    assert [r["keypoint"] for r in rows] == list(take.names)
    for row in rows:
        assert row["jerk_raw"] is None
        assert row["jerk_filtered"] is None
        assert row["lag_frames_vs_input"] is None
    assert "not available" in " ".join(data["notes"])


def test_cli_filter_writes_no_output_when_its_metrics_fail(
    corpus_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import mocapqa.metrics.smoothness as smoothness

    def broken(*args: Any, **kwargs: Any) -> float:
        raise RuntimeError("metric failed")

    monkeypatch.setattr(smoothness, "lag_frames", broken)
    out = tmp_path / "out.csv"
    with pytest.raises(RuntimeError, match="metric failed"):
        main(["filter", str(corpus_dir / BALANCING), "-o", str(out)])
    assert not out.exists()


OPENPOSE_CAM01 = "keypoints/pose2sim/S00_P00_T01_BalancingTrial/pose/cam01_json"


@pytest.fixture(scope="module")
def openpose(corpus_dir: Path) -> KeypointSequence:
    take = read_take(corpus_dir / OPENPOSE_CAM01)
    assert isinstance(take, KeypointSequence)
    return take


def _detection_range(seq: KeypointSequence) -> tuple[np.ndarray, np.ndarray]:
    seen = ~seq.missing[..., None]
    low = np.where(seen, seq.positions, np.inf).min(axis=0)
    high = np.where(seen, seq.positions, -np.inf).max(axis=0)
    return low, high


@pytest.mark.parametrize("method", ["adaptive", "kalman", "one-euro", "ema", "butterworth"])
def test_bridged_keypoints_stay_within_their_detections(
    openpose: KeypointSequence, method: str
) -> None:
    # The Kalman bridge extrapolated: cam01's LEar, never detected beyond x = 768 px, was
    # placed at x = 866 px in its 50-frame gap (the 'kalman' method: LElbow, RKnee).
    res = filter_keypoints(openpose, method)
    out = res.sequence.positions
    low, high = _detection_range(openpose)
    inside = (out >= low - 1e-9) & (out <= high + 1e-9)
    bridged = res.bridged & ~openpose.missing.all(axis=0)
    assert bridged.sum() >= 90
    outside = np.argwhere(bridged[..., None] & ~inside)
    assert outside.size == 0, [(openpose.names[k], f, out[f, k]) for f, k, _ in outside[:5]]


def test_a_gap_inside_the_take_is_interpolated_and_one_at_its_end_held(
    openpose: KeypointSequence,
) -> None:
    ear = openpose.names.index("LEar")
    missing = openpose.missing[:, ear]
    # The README's cam01: LEar is missing on frames 38-87 (inside) and 91-99 (the end).
    assert missing[38:88].all()
    assert not missing[[37, 88, 90]].any()
    assert missing[91:].all()
    res = filter_keypoints(openpose, "adaptive")
    out = res.sequence.positions[:, ear]
    assert res.bridged[38:88, ear].all()
    assert res.bridged[91:, ear].all()
    ramp = np.linspace(0.0, 1.0, 52)[1:-1, None]
    np.testing.assert_allclose(out[38:88], out[37] + ramp * (out[88] - out[37]), atol=1e-9)
    np.testing.assert_array_equal(out[91:], np.repeat(out[90:91], 9, axis=0))
    detected = openpose.positions[:, ear, 0]
    assert np.nanmax(detected) == pytest.approx(768.0, abs=1.0)
    assert np.nanmax(out[:, 0]) <= np.nanmax(detected)
    # The first detection after the gap is not pulled toward an extrapolated position.
    assert abs(out[88, 0] - detected[88]) < 10.0
