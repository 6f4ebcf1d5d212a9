"""Limits model files and the shipped models.

File format (safe to load from users: no pickle)
-------------------------------------------------
One ``.npz`` archive read with ``allow_pickle=False``. The array ``meta`` holds UTF-8 JSON::

    {"format": "mocapqa-limits", "format_version": 1, "mocapqa_version": "0.1.0",
     "rig_family": "bandai", "fingerprint": {"left_upper_arm": ["UpperArm_L", "+x"], ...},
     "bin_deg": 5.0, "occupancy": {...OccupancyParams...}, "reference": "mean",
     "corpus_hash": "<sha256>", "takes": [...], "n_frames": 9000,
     "joints": [{"role": "left_upper_arm", "name": "UpperArm_L", "n_samples": 9000,
                 "activation": "relu", "scores": {"accuracy": ...} | null}, ...]}

and, for joint ``k`` of ``joints``, arrays ``k/axis`` (3,), ``k/reference`` (4,),
``k/occupied`` (N, N) bool, ``k/tau_min`` and ``k/tau_max`` (N, N) float32 radians, and when a
network was trained ``k/hidden_weights`` (3, H), ``k/hidden_biases`` (H,),
``k/output_weights`` (H,), ``k/output_bias`` (1,). Anything else, a missing array, a bad shape
or another format version raises :class:`~mocapqa.errors.LimitsFileError`.

Shipped models
--------------
``mocapqa/data/limits/*.npz``. :func:`load_default_model` picks the canonical model except for
the rigs in :data:`PREFERRED_RIG_MODELS`.
"""

from __future__ import annotations

import functools
import io
import json
import zipfile
from collections.abc import Iterator, Mapping
from dataclasses import asdict
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from mocapqa.core.motion import Skeleton
from mocapqa.errors import LimitsFileError, MocapQAError
from mocapqa.limits.discriminator import DiscriminatorScores, Network
from mocapqa.limits.model import JointLimits, LimitsModel, StoredFrames, check_rig
from mocapqa.limits.occupancy import OccupancyMap, OccupancyParams
from mocapqa.limits.rig import fingerprint_mismatches, rig_family

__all__ = [
    "FORMAT_VERSION",
    "PREFERRED_RIG_MODELS",
    "default_model_paths",
    "load_default_model",
    "load_model",
    "model_bytes",
    "save_model",
]

# Per-rig shipped models used instead of the canonical one on their own rig: only where
# measurably better (`mocapqa bench limits`, docs/limits.md). Character Creator's own model
# flags 100 % of injected ≥ 60° errors on its held-back takes against the canonical model's
# ~81 %: that rig keeps its forearm pronation on twist bones, so the pooled forearm and upper
# leg twist ranges of the other rigs hide its errors.
PREFERRED_RIG_MODELS: frozenset[str] = frozenset({"character_creator"})
# Version of the .npz model layout; files of another version are refused.
FORMAT_VERSION = 1
_FORMAT = "mocapqa-limits"


def _meta(model: LimitsModel) -> dict[str, Any]:
    return {
        "format": _FORMAT,
        "format_version": FORMAT_VERSION,
        "mocapqa_version": model.version,
        "rig_family": model.rig_family,
        "fingerprint": {k: list(v) for k, v in model.fingerprint.items()},
        "bin_deg": model.occupancy_params.bin_deg,
        "occupancy": asdict(model.occupancy_params),
        "reference": model.reference,
        "corpus_hash": model.corpus_hash,
        "takes": list(model.takes),
        "n_frames": model.n_frames,
        "frame": model.frame,
        "rigs": [
            {
                "key": key,
                "family": f.family,
                "roles": list(f.roles),
                "joints": list(f.joints),
                "parents": list(f.parents),
            }
            for key, f in model.rig_frames.items()
        ],
        "joints": [
            {
                "role": j.role,
                "name": j.name,
                "n_samples": j.n_samples,
                "activation": j.network.activation if j.network else None,
                "scores": asdict(j.scores) if j.scores else None,
            }
            for j in model.joints
        ],
    }


def model_bytes(model: LimitsModel) -> bytes:
    """The ``.npz`` file content of ``model`` (see the module notes for the layout)."""
    arrays: dict[str, Any] = {
        "meta": np.frombuffer(json.dumps(_meta(model)).encode("utf-8"), dtype=np.uint8)
    }
    for k, j in enumerate(model.joints):
        arrays[f"{k}/axis"] = j.axis
        arrays[f"{k}/reference"] = j.reference
        arrays[f"{k}/occupied"] = j.occupancy.occupied
        arrays[f"{k}/tau_min"] = j.occupancy.tau_min.astype(np.float32)
        arrays[f"{k}/tau_max"] = j.occupancy.tau_max.astype(np.float32)
        if j.network is not None:
            arrays[f"{k}/hidden_weights"] = j.network.hidden_weights
            arrays[f"{k}/hidden_biases"] = j.network.hidden_biases
            arrays[f"{k}/output_weights"] = j.network.output_weights
            arrays[f"{k}/output_bias"] = np.array([j.network.output_bias])
    for i, stored in enumerate(model.rig_frames.values()):
        arrays[f"rig{i}/frames"] = stored.frames
        arrays[f"rig{i}/parent_frames"] = stored.parent_frames
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue()


def save_model(model: LimitsModel, path: str | Path) -> None:
    """Write ``model`` to ``path`` as a ``.npz`` limits file."""
    Path(path).write_bytes(model_bytes(model))


def _joint_from_file(
    k: int, entry: dict[str, Any], data: Any, params: OccupancyParams
) -> JointLimits:
    network = None
    if f"{k}/hidden_weights" in data.files:
        network = Network(
            hidden_weights=data[f"{k}/hidden_weights"],
            hidden_biases=data[f"{k}/hidden_biases"],
            output_weights=data[f"{k}/output_weights"],
            output_bias=float(data[f"{k}/output_bias"][0]),
            activation=str(entry["activation"]),
        )
    scores = DiscriminatorScores(**entry["scores"]) if entry.get("scores") else None
    axis = np.asarray(data[f"{k}/axis"], dtype=np.float64)
    reference = np.asarray(data[f"{k}/reference"], dtype=np.float64)
    if axis.shape != (3,) or reference.shape != (4,):
        raise LimitsFileError(
            f"Expected joint {k} axis (3,) and reference (4,), got {axis.shape} and "
            f"{reference.shape}"
        )
    occupancy = OccupancyMap(
        params.bin_deg,
        np.asarray(data[f"{k}/occupied"], dtype=bool),
        np.asarray(data[f"{k}/tau_min"], dtype=np.float64),
        np.asarray(data[f"{k}/tau_max"], dtype=np.float64),
        params.interpolate,
    )
    return JointLimits(
        role=str(entry["role"]),
        name=str(entry["name"]),
        axis=axis,
        reference=reference,
        occupancy=occupancy,
        network=network,
        scores=scores,
        n_samples=int(entry["n_samples"]),
    )


def _model_from_npz(data: Any, where: str) -> LimitsModel:
    if "meta" not in data.files:
        raise LimitsFileError(
            f"{where}: Expected a mocapqa limits model with a 'meta' entry, got none"
        )
    meta = json.loads(bytes(np.asarray(data["meta"], dtype=np.uint8)).decode("utf-8"))
    if not isinstance(meta, dict) or meta.get("format") != _FORMAT:
        raise LimitsFileError(f"{where}: Expected format {_FORMAT!r}, got {meta.get('format')!r}")
    if meta.get("format_version") != FORMAT_VERSION:
        raise LimitsFileError(
            f"{where}: Expected format_version {FORMAT_VERSION}, got {meta.get('format_version')!r}"
        )
    params = OccupancyParams(**meta["occupancy"])
    joints = tuple(
        _joint_from_file(k, entry, data, params) for k, entry in enumerate(meta["joints"])
    )
    return LimitsModel(
        rig_family=str(meta["rig_family"]),
        fingerprint={k: (str(v[0]), str(v[1])) for k, v in meta["fingerprint"].items()},
        joints=joints,
        occupancy_params=params,
        reference=str(meta["reference"]),
        corpus_hash=str(meta["corpus_hash"]),
        takes=tuple(str(t) for t in meta["takes"]),
        n_frames=int(meta["n_frames"]),
        version=str(meta["mocapqa_version"]),
        frame=str(meta.get("frame", "rig")),
        rig_frames={
            str(entry["key"]): _stored_frames(i, entry, data)
            for i, entry in enumerate(meta.get("rigs", []))
        },
    )


def _stored_frames(i: int, entry: dict[str, Any], data: Any) -> StoredFrames:
    roles = tuple(str(r) for r in entry["roles"])
    frames = np.asarray(data[f"rig{i}/frames"], dtype=np.float64)
    parent_frames = np.asarray(data[f"rig{i}/parent_frames"], dtype=np.float64)
    if frames.shape != (len(roles), 4) or parent_frames.shape != (len(roles), 4):
        raise LimitsFileError(
            f"Expected rig {i} frames of shape ({len(roles)}, 4), got {frames.shape} and "
            f"{parent_frames.shape}"
        )
    return StoredFrames(
        family=str(entry["family"]),
        roles=roles,
        joints=tuple(str(j) for j in entry["joints"]),
        parents=tuple(str(j) for j in entry["parents"]),
        frames=frames,
        parent_frames=parent_frames,
    )


def load_model(path: str | Path) -> LimitsModel:
    """Read a limits model file (``.npz``, never unpickled).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    LimitsModel

    Raises
    ------
    LimitsFileError
        If the file is missing, not an ``.npz``, or its content is not a valid limits model.
    """
    where = str(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            return _model_from_npz(data, where)
    except LimitsFileError:
        raise
    except (
        OSError, ValueError, KeyError, TypeError, IndexError, EOFError, zipfile.BadZipFile,
        MocapQAError,
    ) as e:  # fmt: skip
        raise LimitsFileError(
            f"{where}: Expected a mocapqa limits model (.npz, format {_FORMAT!r} "
            f"v{FORMAT_VERSION}), got an unreadable or corrupt file ({type(e).__name__}: {e})"
        ) from e


def default_model_paths() -> Iterator[Path]:
    """Paths of the models shipped in ``mocapqa/data/limits``, sorted by name."""
    folder = resources.files("mocapqa") / "data" / "limits"
    for entry in sorted(folder.iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".npz"):
            yield Path(str(entry))


@functools.cache
def _shipped_models() -> tuple[LimitsModel, ...]:
    # Read once per process: the shipped files do not change while it runs.
    return tuple(load_model(path) for path in default_model_paths())


def load_default_model(skeleton: Skeleton, mapping: Mapping[str, str] | None = None) -> LimitsModel:
    """The shipped limits model for ``skeleton``: the canonical one, for any rig with roles
    (found by name, or named by ``mapping``, role key → joint name).

    A shipped per-rig model is preferred only when it is listed in :data:`PREFERRED_RIG_MODELS`
    (measured better on its rig: Character Creator today, see ``docs/limits.md``).

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    LimitsModel

    Raises
    ------
    LimitsFileError
        If the skeleton has no limb roles (or no shipped model covers it).
    """
    models = _shipped_models()
    for model in models:
        if (
            model.frame == "rig"
            and model.rig_family in PREFERRED_RIG_MODELS
            and not fingerprint_mismatches(model.fingerprint, skeleton)
        ):
            return model
    for model in models:
        if model.frame == "canonical":
            check_rig(model, skeleton, mapping)
            return model
    families = []
    for model in models:
        families.append(model.rig_family)
        if not fingerprint_mismatches(model.fingerprint, skeleton):
            return model
    covered = ", ".join(families) or "none"
    raise LimitsFileError(
        f"Expected a skeleton of a rig with a shipped limits model ({covered}), "
        f"got a {rig_family(skeleton)!r} skeleton that matches none; build one with "
        "`mocapqa limits build`"
    )
