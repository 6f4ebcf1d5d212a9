"""C3D marker takes: read through ezc3d (py-c3d where ezc3d refuses), written through ezc3d.

The names are defined by one module per job and gathered here: the take
(:mod:`mocapqa.io.c3d_take`), the checked header and parameter section
(:mod:`mocapqa.io.c3d_layout`), the parameters of either reader
(:mod:`mocapqa.io.c3d_parameters`), reading (:mod:`mocapqa.io.c3d_read`) and writing
(:mod:`mocapqa.io.c3d_write`).

Conventions
-----------
* :func:`read_c3d` returns a :class:`MarkerTake`: the points as a
  :class:`~mocapqa.core.keypoints.KeypointSequence` ``(F, M, 3)`` in the file's unit
  (``POINT:UNITS``, never rescaled), at ``POINT:RATE``, NaN where a sample is missing, with the
  file's residuals ``(F, M)`` (−1 missing, 0 interpolated or filled, > 0 measured) and camera
  contribution bits beside them. Names are the point labels (``LABELS`` then ``LABELS2``…);
  an empty label is named ``*<index>`` (0-based, as Vicon names unlabelled trajectories) and a
  repeated one ``<label>#<n>`` (its n-th use), each recorded as an assumption.
* A sample is missing when its residual is negative or a coordinate is NaN (OptiTrack writes
  NaN with residual 0); its residual is −1 in the take either way.
* Before any reader sees the file, :func:`inspect_c3d` checks the header and walks the parameter
  section in Python: the magic byte, the processor type, every parameter record inside the
  section, and that the data the header declares fit in the file. ezc3d is C++: on malformed
  parameter records it can crash the process or loop for ever (found by corrupting real files),
  so it is given only files that pass these and :func:`check_for_ezc3d`; the others go to
  py-c3d, which raises instead.
* ezc3d 1.7.2 refuses MIPS (big-endian) files and some non-standard parameters (a FLOAT
  ``ANALOG:OFFSET``); those are read by py-c3d (``c3d`` on PyPI, pure Python), which reads
  both kinds but checks that header and parameters agree. A file neither reads is refused with a
  :class:`~mocapqa.errors.ParseError` giving both reasons.
* :func:`write_c3d` writes a missing sample as the standard says: zero coordinates with
  residual −1. Residuals are stored as multiples of ``|POINT:SCALE|``; a measured residual
  smaller than that step is written as one step, so 0 keeps meaning "filled". With ``source``,
  the source file is opened again and only its point data, labels, descriptions, units, rate
  and first frame are replaced: analogs, force plates, events and every other group are
  written as they were read.
"""

from __future__ import annotations

from mocapqa.io.c3d_layout import C3DLayout, check_for_ezc3d, inspect_c3d
from mocapqa.io.c3d_read import read_c3d
from mocapqa.io.c3d_take import C3DEvent, MarkerTake
from mocapqa.io.c3d_write import write_c3d

__all__ = [
    "C3DEvent",
    "C3DLayout",
    "MarkerTake",
    "check_for_ezc3d",
    "inspect_c3d",
    "read_c3d",
    "write_c3d",
]
