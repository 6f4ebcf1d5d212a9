"""A large corpus tiled from real BVH takes, for the batch benchmark.

Each tile is a real take's header with a seeded window of its frames: a random start and a
random length around the mean, read forwards then backwards (ping-pong) when the take is
shorter, so every frame is a recorded pose and consecutive frames stay continuous. Tiles differ
in content: a draw that repeats an earlier tile's bytes (the same source, start and length —
2 of the 2,000 default tiles did, and the batch skipped them as duplicates) is drawn again.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["TiledCorpus", "tile_corpus"]


@dataclass(frozen=True, slots=True)
class TiledCorpus:
    """What :func:`tile_corpus` wrote."""

    folder: Path
    n_takes: int
    n_frames: int
    n_bytes: int


def _split(text: str) -> tuple[str, str, list[str]]:
    head, _, motion = text.partition("\nMOTION")
    lines = motion.splitlines()
    frame_time = next(line for line in lines if line.strip().startswith("Frame Time"))
    start = lines.index(frame_time) + 1
    frames = [line for line in lines[start:] if line.strip()]
    return head + "\nMOTION\n", frame_time.strip(), frames


def tile_corpus(
    sources: list[Path], folder: Path, n_takes: int, mean_frames: int, seed: int = 0
) -> TiledCorpus:
    """Write ``n_takes`` BVH tiles of about ``mean_frames`` frames each into ``folder``.

    Parameters
    ----------
    sources : list of Path
        Real BVH takes.
    folder : Path
        Output folder (created; existing tiles of the same name are overwritten).
    n_takes : int
        Tiles to write.
    mean_frames : int
        Mean tile length; lengths are uniform in ``[mean/2, 3·mean/2]``.
    seed : int
        Seed of the choices (same seed, same corpus).
    """
    rng = np.random.default_rng(seed)
    parsed = [_split(p.read_text()) for p in sources]
    folder.mkdir(parents=True, exist_ok=True)
    total_frames = total_bytes = 0
    written: set[bytes] = set()
    for index in range(n_takes):
        while True:  # a tile equal to an earlier one is drawn again (a batch would skip it)
            which = int(rng.integers(len(parsed)))
            head, frame_time, frames = parsed[which]
            length = int(rng.integers(mean_frames // 2, mean_frames * 3 // 2 + 1))
            start = int(rng.integers(len(frames)))
            cycle = frames + frames[-2:0:-1] if len(frames) > 2 else frames
            picked = [cycle[(start + i) % len(cycle)] for i in range(length)]
            body = f"{head}Frames: {length}\n{frame_time}\n" + "\n".join(picked) + "\n"
            data = body.encode()
            digest = hashlib.sha256(data).digest()
            if digest not in written:
                written.add(digest)
                break
        name = f"tile_{index:05d}_{sources[which].stem}.bvh"
        (folder / name).write_bytes(data)
        total_frames += length
        total_bytes += len(data)
    return TiledCorpus(folder, n_takes, total_frames, total_bytes)
