"""Data types shared by every layer: skeletons, motions, keypoint sequences, rig roles."""
