"""Synthetic CARMEN logs: one FLASER line per scan, its pose as laser and odometry pose."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def flaser_log(path: Path, ranges: np.ndarray, poses: np.ndarray, period: float = 0.25) -> Path:
    """A CARMEN log of one FLASER line per scan: ``ranges`` (K, beams) metres seen from
    ``poses`` (K, 3: x, y metres, theta radians), ``period`` seconds apart."""
    lines = ["# message formats defined: PARAM SYNC ODOM FLASER RLASER\n"]
    for i, (r, (x, y, theta)) in enumerate(zip(ranges, poses.tolist(), strict=True)):
        t = period * i
        lines.append(f"FLASER {len(r)} {' '.join(f'{v:.6f}' for v in r)} {x!r} {y!r} "
                     f"{theta!r} {x!r} {y!r} {theta!r} {t:.3f} synth {t:.3f}\n")
    path.write_text("".join(lines))
    return path
