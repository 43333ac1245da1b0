"""The metrics' defaults, apart from the code that uses them (which loads SciPy, Numba and
fastcluster), so the settings and the command line's help read them without it. Each metric's
module re-exports its own."""

from __future__ import annotations

#: Default distance thresholds of the F-score, metres.
DEFAULT_TAUS = (0.05, 0.1, 0.2, 0.5)

#: map-metrics' presets (metres, neighbour counts): ``LidarConfig`` and ``DepthConfig``.
LIDAR_RADIUS = 1.0
DEPTH_RADIUS = 0.2
MIN_KNN = 5
MAX_NN = 30

#: Ward clustering takes N^2 time: more planar points than this are
#: clustered through an evenly spaced sample of this many. A single scan's planar points stay
#: below it, so an extraction from a scan is map-metrics' own.
MAX_WARD_POINTS = 10_000

#: MapEval's AWD and SCS (Cloud_Map_Evaluation's ``vmd_voxel_size``, the points a voxel needs
#: in both maps, and SCS's neighbourhood in voxels along each axis).
AWD_VOXEL = 3.0
AWD_MIN_POINTS = 100
SCS_RADIUS = 5
