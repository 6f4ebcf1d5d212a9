"""Keypoint name tables of common pose models.

Conventions
-----------
* Names keep the spelling of the model's own documentation: OpenPose uses CamelCase
  (``LShoulder``), MediaPipe uses its ``PoseLandmark`` enum names (``LEFT_SHOULDER``).
* BODY_25B order is the one Pose2Sim documents (Nose, LEye, REye, ...); BODY_25 is OpenPose's
  default model (Nose, Neck, RShoulder, ..., MidHip at 8); COCO-18 is OpenPose's COCO model.
* A model with no known table gets ``keypoint_0 ... keypoint_{K-1}``.
"""

from __future__ import annotations

__all__ = [
    "BODY_25B_NAMES",
    "BODY_25_NAMES",
    "COCO_18_NAMES",
    "MEDIAPIPE_33_NAMES",
    "generic_names",
]

BODY_25B_NAMES: tuple[str, ...] = (
    "Nose", "LEye", "REye", "LEar", "REar", "LShoulder", "RShoulder", "LElbow", "RElbow",
    "LWrist", "RWrist", "LHip", "RHip", "LKnee", "RKnee", "LAnkle", "RAnkle", "Neck", "Head",
    "LBigToe", "LSmallToe", "LHeel", "RBigToe", "RSmallToe", "RHeel",
)  # fmt: skip

BODY_25_NAMES: tuple[str, ...] = (
    "Nose", "Neck", "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist", "MidHip",
    "RHip", "RKnee", "RAnkle", "LHip", "LKnee", "LAnkle", "REye", "LEye", "REar", "LEar",
    "LBigToe", "LSmallToe", "LHeel", "RBigToe", "RSmallToe", "RHeel",
)  # fmt: skip

COCO_18_NAMES: tuple[str, ...] = (
    "Nose", "Neck", "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist", "RHip",
    "RKnee", "RAnkle", "LHip", "LKnee", "LAnkle", "REye", "LEye", "REar", "LEar",
)  # fmt: skip

MEDIAPIPE_33_NAMES: tuple[str, ...] = (
    "NOSE", "LEFT_EYE_INNER", "LEFT_EYE", "LEFT_EYE_OUTER", "RIGHT_EYE_INNER", "RIGHT_EYE",
    "RIGHT_EYE_OUTER", "LEFT_EAR", "RIGHT_EAR", "MOUTH_LEFT", "MOUTH_RIGHT", "LEFT_SHOULDER",
    "RIGHT_SHOULDER", "LEFT_ELBOW", "RIGHT_ELBOW", "LEFT_WRIST", "RIGHT_WRIST", "LEFT_PINKY",
    "RIGHT_PINKY", "LEFT_INDEX", "RIGHT_INDEX", "LEFT_THUMB", "RIGHT_THUMB", "LEFT_HIP",
    "RIGHT_HIP", "LEFT_KNEE", "RIGHT_KNEE", "LEFT_ANKLE", "RIGHT_ANKLE", "LEFT_HEEL",
    "RIGHT_HEEL", "LEFT_FOOT_INDEX", "RIGHT_FOOT_INDEX",
)  # fmt: skip


def generic_names(n_keypoints: int) -> tuple[str, ...]:
    """Placeholder names ``keypoint_0 ... keypoint_{K-1}`` for a model without a table.

    Parameters
    ----------
    n_keypoints : int
        Number of keypoints K.

    Returns
    -------
    tuple of str
        K unique names.
    """
    return tuple(f"keypoint_{i}" for i in range(n_keypoints))
