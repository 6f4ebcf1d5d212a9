"""Bone lists of known keypoint layouts: OpenPose BODY_25B, MediaPipe Pose 33, Pose2Sim TRC.

Conventions
-----------
Layouts are lists of (name, name) edges. Names match case-insensitively. A sequence is taken to
follow a layout when at least :data:`MATCH_SHARE` of that layout's names are present; edges
whose two ends are both present are kept. Pose2Sim's TRC markers use BODY_25B's names (its
``*_study`` markers have no edges), so one edge list serves both. Unknown layouts draw points
only, rather than guessing bones from proximity.
"""

from __future__ import annotations

import numpy as np

from mocapqa.core.arrays import IntArray

__all__ = ["BODY_25B_EDGES", "LAYOUTS", "MATCH_SHARE", "MEDIAPIPE_33_EDGES", "bones_for_keypoints"]

# Share of a layout's names that must be present for the layout to apply.
MATCH_SHARE = 0.6

# OpenPose BODY_25B bones by keypoint name (also Pose2Sim TRC markers).
BODY_25B_EDGES: tuple[tuple[str, str], ...] = (
    ("Neck", "Head"),
    ("Head", "Nose"),
    ("Nose", "LEye"),
    ("Nose", "REye"),
    ("LEye", "LEar"),
    ("REye", "REar"),
    ("Neck", "LShoulder"),
    ("Neck", "RShoulder"),
    ("LShoulder", "LElbow"),
    ("LElbow", "LWrist"),
    ("RShoulder", "RElbow"),
    ("RElbow", "RWrist"),
    ("LShoulder", "LHip"),
    ("RShoulder", "RHip"),
    ("LHip", "RHip"),
    ("LHip", "LKnee"),
    ("LKnee", "LAnkle"),
    ("LAnkle", "LHeel"),
    ("LAnkle", "LBigToe"),
    ("LBigToe", "LSmallToe"),
    ("RHip", "RKnee"),
    ("RKnee", "RAnkle"),
    ("RAnkle", "RHeel"),
    ("RAnkle", "RBigToe"),
    ("RBigToe", "RSmallToe"),
)

# MediaPipe Pose (BlazePose 33) bones by landmark name.
MEDIAPIPE_33_EDGES: tuple[tuple[str, str], ...] = (
    ("NOSE", "LEFT_EYE_INNER"),
    ("LEFT_EYE_INNER", "LEFT_EYE"),
    ("LEFT_EYE", "LEFT_EYE_OUTER"),
    ("LEFT_EYE_OUTER", "LEFT_EAR"),
    ("NOSE", "RIGHT_EYE_INNER"),
    ("RIGHT_EYE_INNER", "RIGHT_EYE"),
    ("RIGHT_EYE", "RIGHT_EYE_OUTER"),
    ("RIGHT_EYE_OUTER", "RIGHT_EAR"),
    ("MOUTH_LEFT", "MOUTH_RIGHT"),
    ("LEFT_SHOULDER", "RIGHT_SHOULDER"),
    ("LEFT_SHOULDER", "LEFT_ELBOW"),
    ("LEFT_ELBOW", "LEFT_WRIST"),
    ("LEFT_WRIST", "LEFT_PINKY"),
    ("LEFT_WRIST", "LEFT_INDEX"),
    ("LEFT_WRIST", "LEFT_THUMB"),
    ("LEFT_PINKY", "LEFT_INDEX"),
    ("RIGHT_SHOULDER", "RIGHT_ELBOW"),
    ("RIGHT_ELBOW", "RIGHT_WRIST"),
    ("RIGHT_WRIST", "RIGHT_PINKY"),
    ("RIGHT_WRIST", "RIGHT_INDEX"),
    ("RIGHT_WRIST", "RIGHT_THUMB"),
    ("RIGHT_PINKY", "RIGHT_INDEX"),
    ("LEFT_SHOULDER", "LEFT_HIP"),
    ("RIGHT_SHOULDER", "RIGHT_HIP"),
    ("LEFT_HIP", "RIGHT_HIP"),
    ("LEFT_HIP", "LEFT_KNEE"),
    ("LEFT_KNEE", "LEFT_ANKLE"),
    ("LEFT_ANKLE", "LEFT_HEEL"),
    ("LEFT_HEEL", "LEFT_FOOT_INDEX"),
    ("LEFT_ANKLE", "LEFT_FOOT_INDEX"),
    ("RIGHT_HIP", "RIGHT_KNEE"),
    ("RIGHT_KNEE", "RIGHT_ANKLE"),
    ("RIGHT_ANKLE", "RIGHT_HEEL"),
    ("RIGHT_HEEL", "RIGHT_FOOT_INDEX"),
    ("RIGHT_ANKLE", "RIGHT_FOOT_INDEX"),
)

# Every known layout by name.
LAYOUTS: dict[str, tuple[tuple[str, str], ...]] = {
    "body_25b": BODY_25B_EDGES,
    "mediapipe_33": MEDIAPIPE_33_EDGES,
}


def bones_for_keypoints(names: tuple[str, ...]) -> IntArray:
    """Bone index pairs ``(B, 2)`` for keypoint ``names``, empty when no layout matches.

    Parameters
    ----------
    names : tuple of str
        Keypoint names in sequence order.

    Returns
    -------
    ndarray, shape (B, 2)
        Index pairs into ``names``, from the best-matching layout.
    """
    index = {n.lower(): i for i, n in enumerate(names)}
    best: list[tuple[int, int]] = []
    best_share = 0.0
    for edges in LAYOUTS.values():
        layout_names = {n.lower() for edge in edges for n in edge}
        share = len(layout_names & index.keys()) / len(layout_names)
        if share >= MATCH_SHARE and share > best_share:
            best_share = share
            best = [
                (index[a.lower()], index[b.lower()])
                for a, b in edges
                if a.lower() in index and b.lower() in index
            ]
    return np.array(best, dtype=np.intp).reshape(-1, 2)
