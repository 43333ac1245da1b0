"""pcmapq: how good a robot-made map is, measured against a ground-truth map, in metres.

Frame convention, everywhere: ``p_truth = s * R(yaw) * p_map + t``.
"""

__version__ = "0.1.0"
