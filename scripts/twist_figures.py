"""Draw the real twist-error figures of docs/twist.md from the corpus take 005_05.

Usage (from the repository root, with the backend on PYTHONPATH):

    python scripts/twist_figures.py [--data ../shared/data] [--out docs/figures]

For each knee of ``bvh/cmu/iclone/005_05.bvh`` it plots, over the frames around its errors, the
calf's roll about the bone (θP, the swing–twist angle) as read and after the default refinement,
marks the counter-rotated roll jumps over 20° per frame and shades every interval found (solid
where applied, hatched where not, with its confidence), plus the foot's world roll, which the
errors leave continuous.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mocapqa.corpus import find_corpus
from mocapqa.io.bvh import read_bvh
from mocapqa.twist.analysis import analyze_twist
from mocapqa_bench.natural import natural_jumps

PANELS = (
    ("CC_Base_R_Calf", 190, 330, "twist-005_05-right-knee.png"),
    ("CC_Base_L_Calf", 270, 405, "twist-005_05-left-knee.png"),
)


def main() -> None:
    """Write the PNG figures."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--data", type=Path, default=None, help="corpus folder (MANIFEST.tsv)")
    parser.add_argument("--out", type=Path, default=Path("docs/figures"))
    args = parser.parse_args()
    corpus = args.data or find_corpus()
    if corpus is None:
        raise SystemExit("corpus not found: pass --data")
    motion = read_bvh(corpus / "bvh" / "cmu" / "iclone" / "005_05.bvh")
    analysis = analyze_twist(motion)
    after = analyze_twist(analysis.refined, apply="none")
    jumps = natural_jumps(motion, analysis)
    args.out.mkdir(parents=True, exist_ok=True)
    names = [motion.skeleton.names[g.chain.parent] for g in analysis.chains]
    for joint, lo, hi, filename in PANELS:
        c = names.index(joint)
        frames = np.arange(lo, hi)
        fig, ax = plt.subplots(figsize=(10, 3.6), dpi=110)
        ax.plot(frames, np.rad2deg(analysis.parent_twist_rad[lo:hi, c]), color="#c0392b",
                lw=1.2, label="calf roll θP as read")  # fmt: skip
        ax.plot(frames, np.rad2deg(after.parent_twist_rad[lo:hi, c]), color="#1f77b4", lw=1.6,
                label="after refine (apply confident)")  # fmt: skip
        marks = [f for f in np.flatnonzero(jumps[:, c]) if lo <= f < hi]
        ax.plot(marks, np.rad2deg(analysis.parent_twist_rad[marks, c]), "kv", ms=5,
                label="counter-rotated jump > 20°/frame")  # fmt: skip
        for interval in analysis.intervals:
            if interval.joint != joint or interval.end_frame < lo or interval.start_frame >= hi:
                continue
            ax.axvspan(interval.start_frame - 0.5, interval.end_frame + 0.5,
                       color="#2ecc71" if interval.applied else "none",
                       alpha=0.25 if interval.applied else 1.0,
                       hatch=None if interval.applied else "///", ec="#7f8c8d")  # fmt: skip
            ax.text(interval.start_frame, ax.get_ylim()[1], f"p={interval.confidence:.2f}",
                    fontsize=7, va="top")  # fmt: skip
        ax.set_xlabel(f"frame ({motion.fps:.0f} fps)")
        ax.set_ylabel("degrees")
        ax.set_title(f"005_05 {joint}: real twist errors and the default correction")
        ax.legend(fontsize=7, loc="lower left")
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(args.out / filename)
        plt.close(fig)
        print(args.out / filename)


if __name__ == "__main__":
    main()
