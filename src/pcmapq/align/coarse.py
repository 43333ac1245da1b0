"""Global 2D alignment without an initial guess: rotate the map, correlate rasters.

For every yaw of a sweep the map is drawn as a binary template around its centroid and slid over
a likelihood field of the truth, ``exp(-d^2 / 2 sigma^2)`` of the distance ``d`` to the nearest
truth wall (cv2.matchTemplate, TM_CCORR). Dividing by the template's cell count gives the mean
field value under the map's cells, in [0, 1]: a soft share of the map that lies on truth walls.
The field saturates at 1 on a wall, so dense or cluttered truth regions cannot outscore the right
place, and cells of a partial map that overhang the truth simply score 0.

:func:`similarity_search` adds a sweep over the map's scale (the truth's field is computed
once; only the map's points are scaled before rasterising). The mean field value would favour a
map shrunk onto a dense knot of walls, so there every cell scores its field value minus the mean
field over the truth's bounding box: the summed excess, in truth cells, is what a random
placement earns nothing for, and it grows with the length of wall the map lays on truth walls.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pcmapq.align import free_space
from pcmapq.align.free_space import FreeSpace
from pcmapq.core.bounds import bounds
from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import distance_to
from pcmapq.core.transform import Similarity2D, wrapped
from pcmapq.core.voxels import voxel_centroids
from pcmapq.raster.draw import hit_counts


@dataclass(frozen=True)
class Candidate:
    """A coarse pose: map frame -> truth frame, with its score: the mean field under the map in
    [0, 1] (:func:`coarse_search`), or the summed field excess in truth cells
    (:func:`similarity_search`)."""

    transform: Similarity2D
    score: float


@dataclass(frozen=True)
class Search:
    """A global search: its candidates, best first, and every peak it scored.

    poses: (K, 4) rows (score, yaw rad, x, y) of the per-yaw peaks (rigid search), or (K, 5)
    with a fifth column, the log of the scale (similarity search); sorted by score, descending.
    x, y: where the map's centroid lands, truth units. centre: the map's centroid, map frame;
    radius: the map's largest distance from it, map units. cell: the raster cell, truth units;
    yaw_step: the yaw step, radians (rigid search). plain: when the scores weigh the map's free
    space, the per-yaw peaks of the walls' score alone, rows as ``poses``; None otherwise.
    """

    candidates: list[Candidate]
    poses: np.ndarray
    centre: np.ndarray
    radius: float
    cell: float = 0.0
    yaw_step: float = 0.0
    plain: np.ndarray | None = None


#: Poses within these of the final one are "near" it (see :func:`distinctiveness`): yaw,
#: degrees; position, share of the (scaled) map's radius; scale, ratio.
NEAR_DEG, NEAR_RADIUS, NEAR_SCALE = 15.0, 0.2, 1.15


def distinctiveness(search: Search, tf: Similarity2D) -> float:
    """How distinct the pose ``tf`` (map -> truth, usually the refined winner) is in the
    search's scores, in [0, 1]: 1 - (best score of the poses far from ``tf``) / (best score of
    the poses near it). Near: within NEAR_DEG degrees, NEAR_RADIUS map radii of centroid
    position and (similarity search) a scale ratio of NEAR_SCALE. 0 when the search scored no
    pose near ``tf`` higher than one elsewhere (refinement left the search's peak, or another
    pose scores as well); 1 when nothing elsewhere scores above zero. The scores are the
    walls' alone (``search.plain`` where the search weighed free space): the free space's
    cost falls on nearly every pose of a map laid over another place, so the one it spares
    would stand out (docs/validation.md: maps of other offices)."""
    poses = search.poses if search.plain is None else search.plain
    if len(poses) == 0:
        return 0.0
    centre = tf.apply(search.centre.reshape(1, 2))[0]
    dyaw = np.abs(wrapped(poses[:, 1] - tf.yaw))
    dxy = np.hypot(poses[:, 2] - centre[0], poses[:, 3] - centre[1])
    near = (dyaw < np.radians(NEAR_DEG)) & (dxy < NEAR_RADIUS * tf.scale * search.radius)
    if poses.shape[1] > 4:
        near &= np.abs(poses[:, 4] - np.log(tf.scale)) < np.log(NEAR_SCALE)
    peak = float(poses[near, 0].max()) if near.any() else 0.0
    elsewhere = float(poses[~near, 0].max()) if (~near).any() else 0.0
    if peak <= 0.0:
        return 0.0
    return float(np.clip(1.0 - max(elsewhere, 0.0) / peak, 0.0, 1.0))


def likelihood_field(truth_xy: np.ndarray, grid: MetricGrid, sigma: float) -> np.ndarray:
    """``exp(-d^2 / 2 sigma^2)`` on ``grid``, d = metres to the nearest cell holding a truth point
    (N, 2, metres). (rows, cols) float32 in [0, 1]."""
    dist = distance_to(hit_counts(truth_xy, grid) > 0) * grid.resolution
    return np.exp(-0.5 * (dist / sigma) ** 2).astype(np.float32)


def _template_grid(half: int, resolution: float) -> MetricGrid:
    """A (2 half + 1)-cell square grid whose centre cell is centred on (0, 0)."""
    corner = -(half + 0.5) * resolution
    return MetricGrid(resolution, (corner, corner, 0.0), (2 * half + 1, 2 * half + 1))


def _rotation(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s], [s, c]])


def _peaks(response: np.ndarray, count: int, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns of the ``count`` highest local maxima (within ``radius`` pixels)."""
    size = 2 * radius + 1
    local = cv2.dilate(response, np.ones((size, size), np.uint8))
    v, u = np.nonzero(response >= local)
    best = np.argsort(-response[v, u], kind="stable")[:count]
    return v[best], u[best]


def _suppress(poses: np.ndarray, top_k: int, min_angle: float, min_dist: float,
              min_log_scale: float = np.inf) -> np.ndarray:
    """Greedy non-maximum suppression over rows (score, yaw, x, y[, log scale]) sorted by score,
    descending: a pose within ``min_angle`` radians, ``min_dist`` metres and (with a fifth column)
    ``min_log_scale`` in log scale of a kept one is dropped."""
    kept: list[int] = []
    for i in range(len(poses)):
        if len(kept) == top_k:
            break
        if kept:
            k = poses[kept]
            dyaw = np.abs(wrapped(k[:, 1] - poses[i, 1]))
            dxy = np.hypot(k[:, 2] - poses[i, 2], k[:, 3] - poses[i, 3])
            near = (dyaw < min_angle) & (dxy < min_dist)
            if poses.shape[1] > 4:
                near &= np.abs(k[:, 4] - poses[i, 4]) < min_log_scale
            if np.any(near):
                continue
        kept.append(i)
    return poses[kept]


def _radius(centred: np.ndarray) -> float:
    """Largest distance, metres, of points (N, 2) from the origin."""
    return float(np.sqrt((centred**2).sum(axis=1).max()))


def auto_resolution(map_xy: np.ndarray) -> float:
    """Raster cell size, metres, for the sweep: the map's radius about its centroid over 40,
    at least 0.25 m. The template is then about 80 cells wide whatever the map's size."""
    return max(0.25, _radius(map_xy - map_xy.mean(axis=0)) / 40.0)


def coarse_search(map_xy: np.ndarray, truth_xy: np.ndarray, *,
                  resolution: float | None = None, sigma: float | None = None,
                  angle_step_deg: float | None = None, overhang: float = 2.0,
                  top_k: int = 6, per_angle: int = 3, free: FreeSpace | None = None) -> Search:
    """The ``top_k`` best distinct poses (map frame -> truth frame) of a yaw sweep over 360 degrees.

    map_xy, truth_xy: (N, 2) metres, each in its own frame.
    resolution: raster cell size, metres (default: :func:`auto_resolution`). sigma: likelihood
    field width, metres (default: the resolution). angle_step_deg: yaw step, degrees (default:
    the angle that moves the map's farthest point by sigma, clipped to [0.5, 3]). overhang: how
    far, metres, the map's centroid may lie outside the truth's bounding box. per_angle: peaks
    kept from each yaw's response.
    free: the map's free space and the truth's solid and known cells; given, and with enough
    of its points evidence at ``resolution``
    (:meth:`~pcmapq.align.free_space.FreeSpace.evidence`), each pose's score is multiplied by
    exp(-PENALTY x the cost of the map's free space there)
    (:func:`~pcmapq.align.free_space.cost`).
    Candidates come best first; yaws within three steps and positions within 4 cells of a better one
    are dropped, so near-symmetric alternatives survive to be settled by refinement.
    """
    resolution = auto_resolution(map_xy) if resolution is None else resolution
    sigma = resolution if sigma is None else sigma
    centre = map_xy.mean(axis=0)
    centred = map_xy - centre
    radius = _radius(centred)
    if angle_step_deg is None:
        angle_step_deg = float(np.clip(np.degrees(sigma / max(radius, 1e-6)), 0.5, 3.0))
    clear = (np.zeros((0, 2)) if free is None else free.evidence(map_xy, resolution)) - centre
    half = int(np.ceil(max(radius, _radius(clear) if len(clear) else 0.0) / resolution)) + 1
    tgrid = _template_grid(half, resolution)
    fgrid = MetricGrid.covering(truth_xy, resolution, margin=(half + 1) * resolution + overhang)
    field = likelihood_field(truth_xy, fgrid, sigma)
    solid = known = None
    if free is not None:
        solid = (hit_counts(free.solid_xy(), fgrid) > 0).astype(np.float32)
        known = np.maximum(solid, hit_counts(free.known_xy(resolution), fgrid) > 0
                           ).astype(np.float32)
    # Field pixel of the template's centre cell when the response peaks at (0, 0).
    offset = fgrid.pixels_to_xy(np.array([[half, half]]))[0]
    yaws = np.radians(np.arange(0.0, 360.0, angle_step_deg))
    contradicted = (free_space.contradictions(solid, known, _templates(clear / resolution,
                                                                        yaws, half))
                    if solid is not None and len(clear) else None)
    rows, plain = [], []

    def peaks(response: np.ndarray, yaw: float) -> np.ndarray:
        v, u = _peaks(response, per_angle, radius=2)
        xy = offset + np.column_stack([u, -v]) * resolution
        return np.column_stack([response[v, u], np.full(len(v), yaw), xy])

    for yaw in yaws:
        template = (hit_counts(centred @ _rotation(yaw).T, tgrid) > 0).astype(np.float32)
        response = cv2.matchTemplate(field, template, cv2.TM_CCORR) / template.sum()
        if contradicted is not None:
            plain.append(peaks(response, yaw))
            response = response * np.exp(-free_space.PENALTY * next(contradicted))
        rows.append(peaks(response, yaw))
    poses = np.vstack(rows)
    poses = poses[np.argsort(-poses[:, 0], kind="stable")]
    best = _suppress(poses, top_k, np.radians(3 * angle_step_deg), 4 * resolution)
    return Search([Candidate(_pose(yaw, xy, centre), float(score)) for score, yaw, *xy in best],
                  poses, centre, radius, resolution, float(np.radians(angle_step_deg)),
                  np.vstack(plain) if plain else None)


def _pose(yaw: float, centre_truth: np.ndarray, centre_map: np.ndarray,
          scale: float = 1.0) -> Similarity2D:
    """The transform scaling the map by ``scale`` and turning it by ``yaw`` about its centroid,
    then moving that centroid to ``centre_truth``."""
    t = np.asarray(centre_truth) - scale * (_rotation(yaw) @ centre_map)
    return Similarity2D(float(t[0]), float(t[1]), float(yaw), float(scale))


def similarity_resolution(truth_xy: np.ndarray, cells: int = 20) -> float:
    """Raster cell size, truth units, of the sweep over scale: the truth's radius about its
    centroid over ``cells``. The map's size being unknown, the truth's sets it."""
    return _radius(truth_xy - truth_xy.mean(axis=0)) / cells


def _scales(map_radius: float, truth_radius: float, resolution: float,
            scale_range: tuple[float, float], min_cells: float, max_size: float,
            step: float) -> np.ndarray:
    """Scales of the sweep: the scaled map's radius grows by ``step`` cells (of ``resolution``,
    truth units) a step, from ``min_cells`` cells to ``max_size`` times the truth's radius,
    within ``scale_range``. map_radius: map units; truth_radius: truth units."""
    lo = max(scale_range[0] * map_radius, min(min_cells * resolution, truth_radius))
    hi = max(lo, min(scale_range[1] * map_radius, max_size * truth_radius))
    return np.arange(lo, hi + 0.5 * step * resolution, step * resolution) / map_radius


def _templates(points: np.ndarray, yaws: np.ndarray, half: int) -> np.ndarray:
    """Binary templates (yaws, 2 half + 1, 2 half + 1) float32 of points (N, 2, in cells, about
    the centre cell) turned by each yaw (radians): as :func:`hit_counts` on
    :func:`_template_grid`, for all yaws at once."""
    c, s = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    x, y = points[:, 0], points[:, 1]
    u = np.floor(c * x - s * y + half + 0.5).astype(np.int64)
    v = np.floor(half - (s * x + c * y) + 0.5).astype(np.int64)
    size = 2 * half + 1
    flat = (np.arange(len(yaws))[:, None] * size + v) * size + u
    hits = np.bincount(flat.ravel(), minlength=len(yaws) * size * size)
    return (hits > 0).astype(np.float32).reshape(len(yaws), size, size)


def similarity_search(map_xy: np.ndarray, truth_xy: np.ndarray, *,
                      scale_range: tuple[float, float] = (0.2, 5.0),
                      resolution: float | None = None, step: float = 1.5, top_k: int = 6,
                      per_angle: int = 3, max_size: float = 1.5,
                      min_cells: float = 4.0) -> Search:
    """The ``top_k`` best distinct similarities (map frame -> truth frame) of a sweep over scale
    and yaw, with no initial guess.

    map_xy: (N, 2) in the map's own, unknown unit; truth_xy: (M, 2) truth units (metres).
    scale_range: (lowest, highest) scale, truth units per map unit. resolution: raster cell and
    field width sigma, truth units (default: :func:`similarity_resolution`).
    The scaled map's radius runs from ``min_cells`` cells to ``max_size`` times the truth's
    radius in steps of ``step`` cells; yaws step so that its farthest point moves by ``step``
    cells (0.5 to 3 degrees). Scores: summed field excess (see the module), in truth cells.
    Candidates come best first; one within 9 degrees, 4 cells and 15 % in scale of a better
    one is dropped.
    """
    truth_radius = _radius(truth_xy - truth_xy.mean(axis=0))
    resolution = similarity_resolution(truth_xy) if resolution is None else resolution
    centre = map_xy.mean(axis=0)
    centred = map_xy - centre
    map_radius = max(_radius(centred), 1e-12)
    scales = _scales(map_radius, truth_radius, resolution, scale_range, min_cells, max_size,
                     step)
    half_max = int(np.ceil(scales[-1] * map_radius / resolution)) + 1
    fgrid = MetricGrid.covering(truth_xy, resolution, margin=(half_max + 1) * resolution)
    field = likelihood_field(truth_xy, fgrid, resolution)
    (u0, v0), (u1, v1) = np.round(fgrid.xy_to_pixels(
        np.array(bounds(truth_xy)))).astype(int)
    baseline = float(field[v1:v0 + 1, u0:u1 + 1].mean())
    rows = []
    for scale in scales:
        points = voxel_centroids(centred, 0.5 * resolution / scale) * (scale / resolution)
        radius = scale * map_radius / resolution  # cells
        half = int(np.ceil(radius)) + 1
        offset = fgrid.pixels_to_xy(np.array([[half, half]]))[0]
        yaws = np.radians(np.arange(0.0, 360.0, np.clip(np.degrees(step / radius), 0.5, 3.0)))
        for yaw, template in zip(yaws, _templates(points, yaws, half), strict=True):
            response = (cv2.matchTemplate(field, template, cv2.TM_CCORR)
                        - baseline * template.sum())
            v, u = _peaks(response, per_angle, radius=2)
            xy = offset + np.column_stack([u, -v]) * resolution
            rows.append(np.column_stack([response[v, u], np.full(len(v), yaw), xy,
                                         np.full(len(v), np.log(scale))]))
    poses = np.vstack(rows)
    poses = poses[np.argsort(-poses[:, 0], kind="stable")]
    best = _suppress(poses, top_k, np.radians(9.0), 4 * resolution, np.log(1.15))
    return Search([Candidate(_pose(yaw, xy, centre, float(np.exp(log_s))), float(score))
                   for score, yaw, *xy, log_s in best], poses, centre, map_radius, resolution)
