"""A drift ladder on a CARMEN log: does pcmapq rank maps by how much their poses drifted?

From one log it builds the reference map (the laser endpoints at the log's corrected poses)
and worse maps: the same scans placed along trajectories with simulated odometry drift. The
relative motion between consecutive corrected poses (in the frame of the earlier pose) is
integrated again from the first pose with multiplicative gain errors: at drift level e, the
rotation and translation increments of step k are multiplied by ``1 + e * (1 + z_k)``
(z ~ N(0, 1), seeded, independent for rotation and translation): a systematic gain error e
plus a per-step random one of standard deviation e. Each map is written as a .npy point cloud
and scored with ``pcmapq.evaluation.pipeline.evaluate(map, reference)``
(``Settings(alignment=AlignmentConfig(force=True))``).

``python -m bench.validation.drift`` prints the ladder of real logs; docs/validation.md's
CARMEN section (``bench/validation/carmen.py``) and the tests use it too.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from pcmapq.core.errors import Refused
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.report.text import number, score
from pcmapq.settings import AlignmentConfig, Settings

from .runs import f_at, timed_evaluate

#: Drift levels: relative gain errors of the rotation and translation increments.
DEFAULT_LEVELS = (0.0, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.04)


@dataclass(frozen=True)
class Rung:
    """One drift level's scores against the reference. Lengths in metres, angles in degrees.

    pose_error_m: largest distance between a drifted and a corrected laser position (both in
        the world frame, unaligned: drift starts at the first pose); yaw_error_deg: largest
        heading difference; verdict: the settings' verdict (scored forced when it is "another
        place"); figures: what the rung's reference keeps of its result.
    """

    level: float
    verdict: str
    pose_error_m: float
    yaw_error_deg: float
    fitness: float
    quality: dict[str, float | None]
    precision: dict[str, float | None]
    f1: dict[str, float | None]
    accuracy_mean_m: float | None
    completeness_mean_m: float | None
    chamfer_m: float | None
    f_at_01: float | None
    seconds: float
    figures: dict = field(default_factory=dict)

    def summary(self) -> dict:
        return self.figures


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi), radians."""
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def increments(poses: np.ndarray) -> np.ndarray:
    """(K-1, 3) relative motions between consecutive poses: dx, dy (metres, in the frame of the
    earlier pose) and dtheta (radians, wrapped). ``poses``: (K, 3) x, y, theta, world frame."""
    c, s = np.cos(poses[:-1, 2]), np.sin(poses[:-1, 2])
    d = np.diff(poses[:, :2], axis=0)
    return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1],
                            wrap(np.diff(poses[:, 2]))])


def integrate(start: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """(K, 3) world poses from a start pose (3,) and (K-1, 3) relative motions (see
    :func:`increments`). The headings are a cumulative sum; the positions a cumulative sum of
    the increments turned into the world frame: no Python loop."""
    theta = start[2] + np.concatenate([[0.0], np.cumsum(steps[:, 2])])
    c, s = np.cos(theta[:-1]), np.sin(theta[:-1])
    dxy = np.column_stack([c * steps[:, 0] - s * steps[:, 1], s * steps[:, 0] + c * steps[:, 1]])
    xy = start[:2] + np.vstack([[0.0, 0.0], np.cumsum(dxy, axis=0)])
    return np.column_stack([xy, theta])


def drifted(poses: np.ndarray, level: float, seed: int = 0) -> np.ndarray:
    """The trajectory ``poses`` (K, 3; x, y metres, theta radians, world frame) integrated again
    from its first pose with rotation and translation gain errors ``1 + level * (1 + z)``,
    z ~ N(0, 1) per step, seeded. ``level`` 0 gives ``poses`` back (up to rounding)."""
    steps = increments(poses)
    rng = np.random.default_rng(seed)
    z = rng.standard_normal((len(steps), 2))
    gain_rot = 1.0 + level * (1.0 + z[:, 0])
    gain_trans = 1.0 + level * (1.0 + z[:, 1])
    steps = steps * np.column_stack([gain_trans, gain_trans, gain_rot])
    return integrate(poses[0], steps)


def save_cloud(xy: np.ndarray, path: Path) -> Path:
    """Save (N, 2) metres as an (N, 3) .npy cloud with z = 0."""
    np.save(path, np.column_stack([xy, np.zeros(len(xy))]))
    return path


@lru_cache(maxsize=2)
def _scans(log: Path, scans: int | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The log's first ``scans`` poses, ranges and angles (read once)."""
    poses, ranges, angles = read_flaser(log)
    return poses[:scans], ranges[:scans], angles[:scans]


def rung(log: Path, level: float, seed: int = 0, max_range: float = DEFAULT_MAX_RANGE,
         settings: Settings | None = None, scans: int | None = None) -> Rung:
    """Score the map of ``log`` at one drift level against its corrected map, both made of its
    first ``scans`` scans (all by default) and their readings up to ``max_range`` metres, with
    ``settings`` (default: forced); a map those settings refuse is scored forced, its verdict
    kept."""
    settings = Settings(alignment=AlignmentConfig(force=True)) if settings is None else settings
    poses, ranges, angles = _scans(log, scans)
    path_poses = drifted(poses, level, seed)
    with tempfile.TemporaryDirectory(prefix="carmen_drift_") as tmp:
        reference = save_cloud(endpoints(poses, ranges, angles, max_range),
                               Path(tmp) / "reference.npy")
        cloud = save_cloud(endpoints(path_poses, ranges, angles, max_range),
                           Path(tmp) / f"drift_{level:g}.npy")
        try:
            run = timed_evaluate(cloud, reference, settings)
            verdict = run.result.overlap.verdict
        except Refused as refused:
            forced = replace(settings, alignment=replace(settings.alignment, force=True))
            run, verdict = timed_evaluate(cloud, reference, forced), refused.verdict
    result, dist = run.result, run.result.distances
    return Rung(
        level=level, verdict=verdict,
        pose_error_m=float(np.max(np.linalg.norm(path_poses[:, :2] - poses[:, :2], axis=1))),
        yaw_error_deg=float(np.degrees(np.max(np.abs(wrap(path_poses[:, 2] - poses[:, 2]))))),
        fitness=result.alignment.fitness,
        quality={k: d.matching.quality for k, d in result.detectors.items()},
        precision={k: d.matching.precision for k, d in result.detectors.items()},
        f1={k: d.matching.f1 for k, d in result.detectors.items()},
        accuracy_mean_m=dist.accuracy.mean, completeness_mean_m=dist.completeness.mean,
        chamfer_m=dist.chamfer_m, f_at_01=f_at(result, 0.1), seconds=run.seconds,
        figures={**run.summary(), "verdict": verdict})


def ladder(log: Path, levels: tuple[float, ...] = DEFAULT_LEVELS, seed: int = 0,
           max_range: float = DEFAULT_MAX_RANGE, settings: Settings | None = None,
           scans: int | None = None) -> list[Rung]:
    """:func:`rung` at each drift level."""
    return [rung(log, level, seed, max_range, settings, scans) for level in levels]


def markdown(rungs: list[Rung]) -> str:
    """The ladder as a markdown table."""
    names = list(rungs[0].quality) if rungs else []
    head = (["drift %", "max pose err m", "max yaw err deg", "verdict", "fitness"]
            + [f"q {n}" for n in names] + [f"prec {n}" for n in names]
            + [f"f1 {n}" for n in names]
            + ["acc mean m", "comp mean m", "Chamfer m", "F@0.1", "s"])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rungs:
        cells = ([f"{100 * r.level:g}", number(r.pose_error_m, 2), number(r.yaw_error_deg, 1),
                  r.verdict, number(r.fitness)] + [score(r.quality[n]) for n in names]
                 + [score(r.precision[n]) for n in names] + [score(r.f1[n]) for n in names]
                 + [number(r.accuracy_mean_m), number(r.completeness_mean_m), number(r.chamfer_m),
                    number(r.f_at_01), f"{r.seconds:.1f}"])
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def not_falling(rungs: list[Rung]) -> list[tuple[str, float, float, float, float]]:
    """The steps of the ladder where a detector's f1 does not fall: (detector, level before,
    level after, f1 before, f1 after), in ladder order. An undefined f1 (None) is skipped."""
    out = []
    for name in rungs[0].f1 if rungs else []:
        for a, b in zip(rungs, rungs[1:], strict=False):
            fa, fb = a.f1[name], b.f1[name]
            if fa is not None and fb is not None and not fb < fa:
                out.append((name, a.level, b.level, fa, fb))
    return out


def falls_text(rungs: list[Rung]) -> str:
    """One line: does every detector's f1 fall at every step of the ladder?"""
    steps = not_falling(rungs)
    if not steps:
        return "f1 falls at every step for every detector."
    return "f1 does not fall: " + "; ".join(
        f"{n} from {100 * a:g} to {100 * b:g} % ({fa:.3f}, {fb:.3f})" for n, a, b, fa, fb in steps
    ) + "."
