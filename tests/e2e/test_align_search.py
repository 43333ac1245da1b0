"""2D alignment of a large map: the pyramid's search finds the right copy of a repeated campus."""

from __future__ import annotations

from pcmapq.align import AlignParams, align
from testkit.poses import pose_error


def test_pyramid_finds_a_repeated_campus(campus):
    """Swept at 6 m cells, the building's rooms vanish and ICP from the sweep's poses settles
    a corridor off; the descent to 0.5 m finds the right copy and turn, and ICP lands within
    0.05 m and 0.05 degrees. The map is thinned to 50 000 voxels, as a map of more than
    ``max_points`` is, so its ICP is the light one of a large map."""
    t_true, map_xy, truth_xy = campus
    sweep = align(map_xy, truth_xy, AlignParams(resolution=6.0, finest=100.0, max_points=50_000))
    assert pose_error(t_true, sweep.transform)[0] > 1.0 and sweep.fitness < 0.6
    result = align(map_xy, truth_xy, AlignParams(resolution=6.0, finest=0.5, max_points=50_000))
    dxy, dyaw = pose_error(t_true, result.transform)
    assert dxy < 0.05 and dyaw < 0.05, (dxy, dyaw)
    assert result.fitness > 0.99
