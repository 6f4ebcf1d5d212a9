"""mocapqa: a motion-capture QA workbench.

Finds and fixes axial twist errors in BVH takes, flags joint-limit violations, and filters
noisy keypoint and rotation streams.
"""

__all__ = ["__version__"]

__version__ = "0.1.0"
"""The package version, stored with every run for reproducibility."""
