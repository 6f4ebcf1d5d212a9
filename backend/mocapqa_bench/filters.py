"""``mocapqa bench filters``: keypoint filters on real takes with seeded vision-like noise.

Ground truth is the forward-kinematics joint positions of the Bandai Namco takes (centimetres,
30 fps); the noise is :func:`mocapqa_bench.noise.keypoint_noise`. Every third take (sorted by
name) is the training subset on which each method's parameters are tuned by a small grid
search on RMSE; the figures are reported on the other takes. The real Pose2Sim raw TRC files
(no truth) are compared with the Butterworth-filtered files beside them. Rotation filters are in
:mod:`mocapqa_bench.rotation_filters`.
"""

from __future__ import annotations

import dataclasses
import itertools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.arrays import FloatArray
from mocapqa.core.motion import Motion
from mocapqa.errors import InputError
from mocapqa.filters.adaptive import AdaptiveFilter, AdaptiveParams, adaptive_filter
from mocapqa.filters.butterworth import ButterworthParams, butterworth_filter
from mocapqa.filters.ema import EmaParams, ema_filter
from mocapqa.filters.kalman import KalmanParams, kalman_filter
from mocapqa.filters.one_euro import OneEuroParams, one_euro_filter
from mocapqa.filters.registry import FILTERS, DataScale
from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.metrics.smoothness import lag_frames, mean_abs_jerk, rmse
from mocapqa_bench.noise import NoisyKeypoints, keypoint_noise

__all__ = [
    "KeypointCase",
    "Row",
    "Take",
    "keypoint_cases",
    "keypoint_table",
    "load_takes",
    "note_table",
    "pose2sim_table",
    "speed_table",
    "split_takes",
]

CM_PER_MM = 0.1
BANDAI_SCALE = DataScale(units_per_metre=100.0, units_per_normalised=200.0, fps=30.0)

Method = Callable[[FloatArray, FloatArray, float], FloatArray]
Row = dict[str, Any]
"""One row of a printed table: column name → value."""


@dataclass(frozen=True, slots=True)
class Take:
    """A real take: its name, motion and FK joint positions ``(F, J, 3)``."""

    name: str
    motion: Motion
    positions: FloatArray


@dataclass(frozen=True, slots=True)
class KeypointCase:
    """A take's true positions and a seeded noisy copy."""

    name: str
    fps: float
    truth: FloatArray
    noisy: NoisyKeypoints


def load_takes(data_dir: Path, limit: int | None = None) -> list[Take]:
    """Bandai takes of ``data_dir`` (the corpus root), sorted by name, with FK positions."""
    paths = sorted((data_dir / "bvh" / "bandai").glob("*.bvh"))[:limit]
    takes = []
    for p in paths:
        motion = read_bvh(p, length_unit="cm")
        takes.append(Take(p.stem, motion, forward_kinematics(motion)[1]))
    return takes


def split_takes(takes: Sequence[Take]) -> tuple[list[Take], list[Take]]:
    """Training subset (every third take) and test subset (the rest)."""
    return [t for i, t in enumerate(takes) if i % 3 == 0], [t for i, t in enumerate(takes) if i % 3]


def keypoint_cases(takes: Sequence[Take], seed: int) -> list[KeypointCase]:
    """One noisy copy per take, seeded by ``seed`` and the take's index."""
    out = []
    for i, take in enumerate(takes):
        rng = np.random.default_rng([seed, i])
        noisy = keypoint_noise(take.positions, take.motion.fps, rng, CM_PER_MM)
        out.append(KeypointCase(take.name, take.motion.fps, take.positions, noisy))
    return out


def _conf3(conf: FloatArray) -> FloatArray:
    return np.repeat(conf[:, :, None], 3, axis=2)


def kalman_method(p: KalmanParams) -> Method:
    """A keypoint method running the Kalman filter with ``p``."""
    return lambda x, c, fps: kalman_filter(x, fps, p, _conf3(c)).values


def one_euro_method(p: OneEuroParams) -> Method:
    """A keypoint method running the One Euro filter with ``p``."""
    return lambda x, c, fps: one_euro_filter(x, fps, p, _conf3(c))[0]


def ema_method(p: EmaParams) -> Method:
    """A keypoint method running the EMA with ``p``."""
    return lambda x, c, fps: ema_filter(x, fps, p, _conf3(c))[0]


def adaptive_method(p: AdaptiveParams) -> Method:
    """A keypoint method running the adaptive blend with ``p``."""
    return lambda x, c, fps: adaptive_filter(x, fps, p, c).values


def _score(method: Method, cases: Sequence[KeypointCase]) -> Row:
    sq, sq_clean, n, n_clean = 0.0, 0.0, 0, 0
    jerk, jerk_truth, lags, elapsed, samples = [], [], [], 0.0, 0
    for case in cases:
        x, c = case.noisy.positions, case.noisy.confidence
        start = time.perf_counter()
        out = method(x, c, case.fps)
        elapsed += time.perf_counter() - start
        samples += x.shape[0] * x.shape[1]
        d2 = np.sum((out - case.truth) ** 2, axis=-1)
        clean = ~(case.noisy.outliers | case.noisy.dropouts)
        sq += float(np.nansum(d2))
        n += d2.size
        sq_clean += float(np.nansum(d2[clean]))
        n_clean += int(clean.sum())
        jerk.append(mean_abs_jerk(out, case.fps))
        jerk_truth.append(mean_abs_jerk(case.truth, case.fps))
        lags.append(lag_frames(case.truth, out))
    return {
        "rmse": float(np.sqrt(sq / n)),
        "rmse_clean": float(np.sqrt(sq_clean / n_clean)),
        "jerk_ratio": float(np.mean(jerk) / np.mean(jerk_truth)),
        "lag_frames": float(np.mean(lags)),
        "msamples_per_s": samples / elapsed / 1e6,
    }


def _tune(
    build: Callable[..., Method], grid: dict[str, Sequence[Any]], cases: Sequence[KeypointCase]
) -> tuple[dict[str, Any], Row]:
    best: tuple[dict[str, Any], Row] | None = None
    for values in itertools.product(*grid.values()):
        kwargs = dict(zip(grid, values, strict=True))
        row = _score(build(**kwargs), cases)
        if best is None or row["rmse"] < best[1]["rmse"]:
            best = (kwargs, row)
    if best is None:
        raise InputError("Expected a non-empty parameter grid, got none")
    return best


def keypoint_table(train: Sequence[KeypointCase], test: Sequence[KeypointCase]) -> list[Row]:
    """Per-method figures on ``test`` after tuning each causal filter on ``train``."""
    u = BANDAI_SCALE.units_per_metre

    def kal(q: float, r: float, cw: bool = False, gate: float = 0.0) -> KalmanParams:
        return KalmanParams(q * u * u, r * r * u * u, cw, gate, bridge_decay_s=0.1 if cw else 0.0)

    grids: list[tuple[str, Callable[..., Method], dict[str, Sequence[Any]]]] = [
        (
            "kalman",
            lambda q, r: kalman_method(kal(q, r)),
            {"q": [30, 100, 300, 1000, 3000], "r": [0.005, 0.01, 0.02]},
        ),
        (
            "one-euro",
            lambda fmin, beta: one_euro_method(OneEuroParams(fmin, beta / u)),
            {"fmin": [0.5, 1.0, 2.0, 4.0], "beta": [0.5, 2.0, 8.0]},
        ),
        ("ema", lambda tau: ema_method(EmaParams(tau)), {"tau": [0.02, 0.04, 0.07, 0.1, 0.15]}),
        (
            "kalman-confidence",
            lambda q, r, gate: kalman_method(kal(q, r, True, gate)),
            {"q": [100, 300, 1000, 3000], "r": [0.005, 0.0075, 0.01], "gate": [0.0, 4.0]},
        ),
    ]
    rows: list[Row] = [{"method": "raw", **_score(lambda x, c, f: x, test), "tuned": ""}]
    tuned: dict[str, dict[str, Any]] = {}
    for name, build, grid in grids:
        kwargs, _ = _tune(build, grid, train)
        tuned[name] = kwargs
        rows.append({"method": name, **_score(build(**kwargs), test), "tuned": kwargs})
    for preset in ("note", "default"):
        p = FILTERS["adaptive"].preset(preset, BANDAI_SCALE)
        rows.append(
            {"method": f"adaptive ({preset})", **_score(adaptive_method(p), test), "tuned": ""}
        )
    kc = tuned["kalman-confidence"]
    base = FILTERS["adaptive"].preset("default", BANDAI_SCALE)
    for power, window in itertools.product((1.0, 3.0), (0.15, 0.3)):
        p = dataclasses.replace(
            base,
            kalman=kal(kc["q"], kc["r"], True, kc["gate"]),
            innovation_power=power,
            window_s=window,
        )
        key = {"power": power, "window_s": window}
        train_rmse = _score(adaptive_method(p), train)["rmse"]
        rows.append(
            {
                "method": "adaptive (power/window swept)",
                "train_rmse": train_rmse,
                "params": p,
                "tuned": key,
            }
        )
    cand = [r for r in rows if r["method"] == "adaptive (power/window swept)"]
    best = min(cand, key=lambda r: r["train_rmse"])
    rows = [r for r in rows if r["method"] != "adaptive (power/window swept)"]
    rows.append(
        {
            "method": "adaptive (power/window swept)",
            **_score(adaptive_method(best["params"]), test),
            "tuned": best["tuned"],
        }
    )
    bw = ButterworthParams()
    rows.append(
        {
            "method": "butterworth (offline)",
            **_score(
                lambda x, c, f: butterworth_filter(np.where((c > 0)[:, :, None], x, np.nan), f, bw)[
                    0
                ],
                test,
            ),
            "tuned": "6 Hz, order 4",
        }
    )
    return rows


def note_table(cases: Sequence[KeypointCase]) -> list[Row]:
    """The note's table on noisy takes: mean jerk per axis for original, Kalman, adaptive."""
    note = FILTERS["adaptive"].preset("note", BANDAI_SCALE)
    rows: list[Row] = []
    outputs: dict[str, list[FloatArray]] = {"original": [], "kalman only": [], "adaptive": []}
    weights = []
    for case in cases:
        x, c = case.noisy.positions, case.noisy.confidence
        outputs["original"].append(x)
        outputs["kalman only"].append(kalman_method(note.kalman)(x, c, case.fps))
        res = adaptive_filter(x, case.fps, note, c)
        outputs["adaptive"].append(res.values)
        weights.append(res.weights.reshape(-1, 3))
    base = None
    for name, outs in outputs.items():
        jerk = np.array([[mean_abs_jerk(o[..., a], 30.0) for a in range(3)] for o in outs]).mean(
            axis=0
        )
        base = jerk if base is None else base
        err = float(
            np.sqrt(
                np.mean(
                    [
                        np.mean(np.sum((o - c.truth) ** 2, -1))
                        for o, c in zip(outs, cases, strict=True)
                    ]
                )
            )
        )
        rows.append(
            {
                "filter": name,
                "jerk_x": jerk[0],
                "jerk_y": jerk[1],
                "jerk_z": jerk[2],
                "reduction_pct": 100 * (1 - jerk / base),
                "rmse": err,
            }
        )
    w = np.concatenate(weights)
    speeds = np.concatenate(
        [
            np.linalg.norm(np.diff(c.noisy.positions, axis=0), axis=-1).reshape(-1) * c.fps
            for c in cases
        ]
    )
    rows.append(
        {
            "filter": "weights",
            "mean": w.mean(axis=0),
            "std": w.std(axis=0),
            "fast_share": float(np.mean(speeds >= note.fast_speed)),
            "slow_share": float(np.mean(speeds < note.slow_speed)),
            # The note's 1.0 unit/s read as 1.0 cm/s, with no unit conversion.
            "fast_share_unconverted": float(np.mean(speeds >= 1.0)),
        }
    )
    return rows


def pose2sim_table(data_dir: Path) -> list[Row]:
    """Real Pose2Sim raw TRC vs the Butterworth file beside it: jerk, lag and distance."""
    from mocapqa.filters.apply import filter_keypoints
    from mocapqa.io.formats import read_take

    rows: list[Row] = []
    for raw_path in sorted((data_dir / "keypoints" / "pose2sim").glob("*/pose-3d/*_0-100.trc")):
        raw = read_take(raw_path)
        ref = read_take(raw_path.with_name(raw_path.stem + "_filt_butterworth.trc"))
        if isinstance(raw, Motion) or isinstance(ref, Motion):
            raise InputError(f"Expected keypoints in {raw_path}, got a BVH motion")
        jerk_ref = mean_abs_jerk(ref.positions, ref.fps)
        for method in ("raw", "adaptive", "kalman", "one-euro", "ema", "butterworth"):
            if method == "raw":
                out = raw.positions
            else:
                out = filter_keypoints(raw, method).sequence.positions
            rows.append(
                {
                    "take": raw_path.stem,
                    "method": method,
                    "jerk_vs_butterworth_file": mean_abs_jerk(out, raw.fps) / jerk_ref,
                    "lag_frames": lag_frames(ref.positions, out),
                    "distance_mm": rmse(out, ref.positions) * 1000.0,
                }
            )
    return rows


def speed_table(n_frames: int = 2000, n_keypoints: int = 33) -> list[Row]:
    """Throughput of batch and streaming adaptive, and of the PyPI OneEuroFilter."""
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(size=(n_frames, n_keypoints, 3)), axis=0)
    c = np.full((n_frames, n_keypoints), 0.9)
    p = FILTERS["adaptive"].preset("default", BANDAI_SCALE)
    start = time.perf_counter()
    adaptive_filter(x, 30.0, p, c)
    batch = time.perf_counter() - start
    f = AdaptiveFilter(p, n_keypoints, 30.0)
    start = time.perf_counter()
    for t in range(n_frames):
        f.update(x[t], c[t])
    stream = time.perf_counter() - start
    rows: list[Row] = [
        {
            "what": "adaptive batch",
            "value": n_frames * n_keypoints / batch / 1e6,
            "unit": "M keypoint-samples/s",
        },
        {
            "what": f"adaptive streaming, {n_keypoints} keypoints",
            "value": stream / n_frames * 1e6,
            "unit": "µs/frame",
        },
    ]
    try:
        from OneEuroFilter import OneEuroFilter as PyPIOneEuro
    except ImportError:
        return rows
    one = PyPIOneEuro(30.0, 1.0, 0.007, 1.0)
    series = x[:, 0, 0]
    reps = max(1, 20000 // n_frames)
    start = time.perf_counter()
    for _ in range(reps):
        for t in range(n_frames):
            one(float(series[t]), t / 30.0)
    single = time.perf_counter() - start
    rows.append(
        {
            "what": "PyPI OneEuroFilter, one channel",
            "value": reps * n_frames / single / 1e6,
            "unit": "M samples/s",
        }
    )
    start = time.perf_counter()
    one_euro_filter(x, 30.0, OneEuroParams(), None)
    ours = time.perf_counter() - start
    rows.append(
        {
            "what": "our One Euro batch",
            "value": n_frames * n_keypoints / ours / 1e6,
            "unit": "M keypoint-samples/s",
        }
    )
    return rows
