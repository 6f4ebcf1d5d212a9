"""The bounds every take's numbers keep, defined once for readers, the CLI and the server.

A frame rate and a coordinate come from files, command-line options, upload forms and live
stream messages; each of those refuses a value outside these bounds where it arrives, naming
it, so no filter or analysis meets one. The bounds are far beyond any capture system and far
enough inside the float range that the filters' arithmetic stays finite: a Kalman filter
raises its frame time to the fourth power (``1e-300`` fps overflowed it), third differences
multiply coordinates by the frame rate cubed.
"""

from __future__ import annotations

__all__ = ["MAX_FPS", "MAX_MAGNITUDE", "MIN_FPS"]

MIN_FPS = 0.1
"""Lowest frame rate a take may have, frames per second: one frame every 10 s (a BVH's
longest ``Frame Time``), far below any capture system."""
MAX_FPS = 100_000.0
"""Highest frame rate a take may have, frames per second: far above any capture system, low
enough that per-second rates stay finite."""
MAX_MAGNITUDE = 1e9
"""Largest |value| of a coordinate, BVH channel or OFFSET, in file units or degrees.

Far beyond any real take (a kilometre in micrometres, 2.8 million turns), and far enough
below the float range that sums along a 1000-joint chain, squares and third differences at
100,000 fps stay finite: a file with 1e308 in it is refused where it is read, not turned into
NaN later.
"""
