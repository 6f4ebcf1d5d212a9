"""On a long take with real twist errors, the plotted series keep every flip the run reports."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from mocapqa.core.decimate import sample_frames
from mocapqa.io.bvh import read_bvh
from mocapqa.pipeline.analyze import analyze
from mocapqa.pipeline.options import AnalysisOptions
from mocapqa.twist.analysis import analyze_twist
from mocapqa_bench.natural import natural_jumps


def test_a_long_take_keeps_every_reported_flip_at_full_resolution(corpus_dir: Path) -> None:
    knee = read_bvh(corpus_dir / "bvh/cmu/iclone/005_05.bvh")
    reps = -(-20_000 // knee.n_frames)  # 44 copies, 20,152 frames: ten times max_points
    tiled = replace(
        knee,
        quats=np.tile(knee.quats, (reps, 1, 1)),
        translations=np.tile(knee.translations, (reps, 1, 1)),
        euler_hint_deg=None,
    )
    options = AnalysisOptions()
    report = analyze(tiled, options).report
    series = report["series"]
    frames = np.asarray(series["frames"])
    assert len(frames) <= options.max_points < tiled.n_frames // 10
    assert series["twist"]["frames"] == series["limits"]["frames"] == series["frames"]

    twist = [f for f in report["findings"] if f["kind"] == "twist"]
    assert len(twist) >= reps
    assert np.isin([f["start_frame"] for f in twist], frames).all()

    # The real errors: counter-rotated roll jumps over 20° inside a reported interval.
    analysis = analyze_twist(tiled, method=options.twist_method, apply=options.twist_apply)
    assert [c["joint"] for c in series["twist"]["chains"]] == [
        analysis.joint_names[g.chain.parent] for g in analysis.chains
    ]
    theta = np.round(np.rad2deg(analysis.parent_twist_rad), 3)
    plotted = np.asarray([c["theta_p_deg"] for c in series["twist"]["chains"]]).T
    checked = []
    for frame, chain in zip(*np.nonzero(natural_jumps(tiled, analysis)), strict=True):
        joint = series["twist"]["chains"][chain]["joint"]
        if any(
            f["joint"] == joint and f["start_frame"] <= frame <= f["end_frame"] + 1 for f in twist
        ):
            checked.append((frame, chain))
    assert len(checked) >= reps
    jump_frames = np.array([f for f, _ in checked])
    assert np.isin(jump_frames, frames).all()
    for frame, chain in checked:
        k = int(np.searchsorted(frames, frame))
        assert plotted[k, chain] == theta[frame, chain], (frame, chain)
    # The evenly spaced frames the series had before drop most of them.
    assert np.isin(jump_frames, sample_frames(tiled.n_frames, options.max_points)).mean() < 0.5
