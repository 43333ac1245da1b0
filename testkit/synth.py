"""Synthetic building plans with known geometry, for the shipped sample and for tests.

Walls are segments ``(N, 4)``: ``x0, y0, x1, y1`` in metres, in the plan's own frame. Every
degradation (transform, moved wall, missing walls, bend, clutter, noise) acts on that geometry,
so a test knows the right answer exactly.
"""

from __future__ import annotations

import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D

#: ROS map_server pixel values (negate = 0): occupied, free, unknown.
OCCUPIED, FREE, UNKNOWN = 0, 254, 205


def _split_wall(x0: float, x1: float, y: float, doors: list[tuple[float, float]]) -> list:
    """A horizontal wall from x0 to x1 at height y, with door gaps (start, end) cut out."""
    pieces, start = [], x0
    for a, b in sorted(doors):
        if a > start:
            pieces.append((start, y, a, y))
        start = max(start, b)
    if x1 > start:
        pieces.append((start, y, x1, y))
    return pieces


def building_plan(seed: int = 0, width: float = 24.0, height: float = 16.0) -> np.ndarray:
    """A floor plan: outer walls, a corridor with rooms of random widths on both sides, doors,
    an L-shaped inner wall and pillars. Asymmetric by construction, so alignment is unique.

    Returns wall segments (N, 4) in metres, with the plan's lower-left corner at (0, 0).
    """
    rng = np.random.default_rng(seed)
    walls = [(0, 0, width, 0), (width, 0, width, height), (width, height, 0, height),
             (0, height, 0, 0)]
    c0, c1 = 0.42 * height, 0.42 * height + 2.2  # corridor between these y values
    for y_lo, y_hi, wall_y, hall_end in ((0.0, c0, c0, 0.75), (c1, height, c1, 0.55)):
        x, doors = 0.0, []
        stop = hall_end * width  # rooms up to here, an open hall beyond
        while True:
            w = float(rng.uniform(3.0, 6.0))
            if x + w > stop - 2.0:
                w = stop - x
            door = x + float(rng.uniform(0.4, w - 1.4))
            doors.append((door, door + 0.9))
            x += w
            walls.append((x, y_lo, x, y_hi))
            if x >= stop - 1e-9:
                break
        walls += _split_wall(0.0, stop, wall_y, doors)
    # An L-shaped wall and two pillars in the open halls.
    hx = 0.75 * width + 1.5
    walls += [(hx, 1.5, hx, 4.0), (hx, 4.0, hx + 2.5, 4.0)]
    for px, py in ((0.55 * width + 2.0, height - 2.5), (0.85 * width, c1 + 2.5)):
        s = 0.2
        walls += [(px - s, py - s, px + s, py - s), (px + s, py - s, px + s, py + s),
                  (px + s, py + s, px - s, py + s), (px - s, py + s, px - s, py - s)]
    return np.asarray(walls, dtype=np.float64)


def campus(columns: int, rows: int, seed: int = 0, gap: float = 4.0) -> np.ndarray:
    """A campus: ``columns`` x ``rows`` copies of :func:`building_plan` (24 x 16 m) on a lattice
    with ``gap`` metres between them, lower-left corner at (0, 0). A large map of repeated
    structure: only the campus's outline tells one copy from the next. (N, 4) metres."""
    one = building_plan(seed)
    i, j = np.meshgrid(np.arange(columns), np.arange(rows), indexing="ij")
    shifts = np.column_stack([i.ravel() * (24.0 + gap), j.ravel() * (16.0 + gap)])
    return (one[None, :, :] + np.tile(shifts, 2)[:, None, :]).reshape(-1, 4)


def placed_campus(columns: int, rows: int
                  ) -> tuple[Similarity2D, np.ndarray, np.ndarray]:
    """A :func:`campus` and its map: (T_true, map points, truth points). The map's walls are
    turned -12 degrees and moved (T_true takes them back), sampled every 10 cm with 3 cm noise;
    the truth's every 10 cm, no noise. Points (N, 2), metres."""
    walls = campus(columns, rows)
    t_true = Similarity2D(31.0, -17.0, np.radians(-12.0))
    map_xy = wall_points(transform_segments(walls, t_true.inverse()), 0.1, noise=0.03)
    return t_true, map_xy, wall_points(walls, 0.1)


def round_rooms() -> np.ndarray:
    """Three round rooms (radii 5, 4 and 3 m), nothing like :func:`building_plan`: wall
    segments (N, 4), metres, 60 to a room."""
    ring = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    rooms = []
    for cx, cy, r in ((6, 6, 5), (16, 8, 4), (11, 15, 3)):
        p = np.column_stack([cx + r * np.cos(ring), cy + r * np.sin(ring)])
        rooms.append(np.hstack([p, np.roll(p, -1, axis=0)]))
    return np.vstack(rooms)


def transform_segments(segments: np.ndarray, tf: Similarity2D) -> np.ndarray:
    """Apply a similarity to both endpoints of every segment."""
    return tf.apply(segments.reshape(-1, 2)).reshape(-1, 4)


def densify(segments: np.ndarray, step: float = 0.1) -> np.ndarray:
    """Cut segments into pieces at most ``step`` metres long, so a non-rigid warp can bend them."""
    lengths = np.hypot(segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1])
    counts = np.maximum(1, np.ceil(lengths / step).astype(int))
    idx = np.repeat(np.arange(len(segments)), counts)
    k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    t0, t1 = k / counts[idx], (k + 1) / counts[idx]
    a, b = segments[idx, :2], segments[idx, 2:]
    return np.hstack([a + (b - a) * t0[:, None], a + (b - a) * t1[:, None]])


def bend(xy: np.ndarray, degrees_per_metre: float, pivot: tuple[float, float] = (0.0, 0.0)):
    """A slow bend like odometry drift: each point is turned about ``pivot`` by an angle that grows
    linearly with its x distance from the pivot. (N, 2) metres in, (N, 2) metres out."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    rel = xy - pivot
    ang = np.radians(degrees_per_metre) * rel[:, 0]
    c, s = np.cos(ang), np.sin(ang)
    return np.column_stack([c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]]) + pivot


def bend_image(image: np.ndarray, corner_shift: float, fill: int) -> np.ndarray:
    """A raster map bent as :func:`bend` bends points: each pixel turned about the lower-left
    corner of the box of the pixels that are not ``fill`` (x to the right, y up), by an angle
    that grows with its x distance from that corner, so that the box's far corner moves by
    ``corner_shift`` times the box's diagonal. (H, W) in, (H, W) out: each pixel the nearest
    of the bent map, ``fill`` where it comes from outside the image."""
    import cv2

    known = np.argwhere(image != fill)  # row, col
    bottom, (left, right) = known[:, 0].max(), (known[:, 1].min(), known[:, 1].max())
    width = max(int(right - left), 1)
    rate = 2.0 * np.arcsin(corner_shift / 2.0) / width  # radians per pixel: the chord's angle
    rows, cols = np.indices(image.shape, dtype=np.float64)
    q = np.stack([cols - left, bottom - rows])  # each output pixel, box frame
    p = q.copy()
    for _ in range(8):  # the source pixel p that bends onto q: q turned back by p's angle
        c, s = np.cos(rate * p[0]), np.sin(rate * p[0])
        p = np.stack([c * q[0] + s * q[1], -s * q[0] + c * q[1]])
    return cv2.remap(image, (left + p[0]).astype(np.float32), (bottom - p[1]).astype(np.float32),
                     cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT, borderValue=int(fill))


def bend_segments(segments: np.ndarray, degrees_per_metre: float, step: float = 0.1):
    """Densify then bend: the plan as a drifted map would draw it."""
    fine = densify(segments, step)
    return bend(fine.reshape(-1, 2), degrees_per_metre).reshape(-1, 4)


def move_wall(segments: np.ndarray, index: int, offset: tuple[float, float]) -> np.ndarray:
    """The plan with wall ``index`` shifted by ``offset`` (metres)."""
    out = segments.copy()
    out[index] += np.array([offset[0], offset[1], offset[0], offset[1]])
    return out


def drop_walls(segments: np.ndarray, fraction: float, seed: int = 0) -> np.ndarray:
    """The plan without a random ``fraction`` of its walls (outer walls kept)."""
    rng = np.random.default_rng(seed)
    inner = np.arange(4, len(segments))
    n = int(round(fraction * len(inner)))
    gone = rng.choice(inner, size=n, replace=False)
    return np.delete(segments, gone, axis=0)


def boxes(centres: np.ndarray, size: float = 0.5) -> np.ndarray:
    """The sides (4K, 4: x0, y0, x1, y1, metres) of square boxes of side ``size`` metres
    around ``centres`` (K, 2, metres), axis-aligned."""
    h = size / 2
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    squares = np.asarray(centres, dtype=np.float64).reshape(-1, 2)[:, None, :] + corners[None]
    return np.concatenate([squares, np.roll(squares, -1, axis=1)], axis=2).reshape(-1, 4)


def clutter(segments: np.ndarray, count: int, seed: int = 0, size: float = 0.5) -> np.ndarray:
    """Add ``count`` small square boxes (side ``size`` m) at random places inside the plan."""
    rng = np.random.default_rng(seed)
    lo, hi = segments.reshape(-1, 2).min(axis=0) + 1.0, segments.reshape(-1, 2).max(axis=0) - 1.0
    return np.vstack([segments, boxes(rng.uniform(lo, hi, size=(count, 2)), size)])


def wall_quads(segments: np.ndarray, thickness: float) -> np.ndarray:
    """Each segment as a rectangle ``thickness`` metres wide with square ends: (N, 4, 2) metres."""
    a, b = segments[:, :2], segments[:, 2:]
    d = b - a
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    n = np.column_stack([-d[:, 1], d[:, 0]]) * (thickness / 2)
    d = d * (thickness / 2)
    return np.stack([a - d - n, b + d - n, b + d + n, a - d + n], axis=1)


def render(segments: np.ndarray, grid: MetricGrid, thickness: float = 0.15,
           free_box: tuple[float, float, float, float] | None = None) -> np.ndarray:
    """Draw walls into an occupancy image on ``grid`` (ROS values: 0 occupied, 254 free, 205
    unknown). ``free_box`` (x0, y0, x1, y1, metres) is free space; elsewhere is unknown; default:
    the bounding box of the walls."""
    from pcmapq.raster.draw import polygon_cells

    img = np.full(grid.shape, UNKNOWN, dtype=np.uint8)
    if free_box is None:
        pts = segments.reshape(-1, 2)
        free_box = (*pts.min(axis=0), *pts.max(axis=0))
    x0, y0, x1, y1 = free_box
    img[polygon_cells(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), grid)] = FREE
    # OpenCV also fills the cells its polygon edges touch: inset by half a cell so that a cell is
    # filled when its centre is inside the wall, at any resolution
    walls = wall_quads(segments, max(thickness - grid.resolution, 1e-6))
    img[polygon_cells(walls, grid)] = OCCUPIED
    return img


def faces(occupied: np.ndarray) -> np.ndarray:
    """The one-cell inner boundary of occupied cells (bool, same shape): walls drawn as their
    two faces, the way a plan drawn as outlines (or a laser seeing both sides) draws them."""
    import cv2

    inner = cv2.erode(occupied.astype(np.uint8), np.ones((3, 3), np.uint8),
                      borderType=cv2.BORDER_CONSTANT, borderValue=0)
    return occupied & (inner == 0)


def plan_grid(segments: np.ndarray, resolution: float, margin: float = 1.0) -> MetricGrid:
    """A grid covering the plan plus a margin, in the plan's frame."""
    return MetricGrid.covering(segments.reshape(-1, 2), resolution, margin)


def binary_partial(segments: np.ndarray, box: tuple[float, float, float, float],
                   tf: Similarity2D, resolution: float = 0.05,
                   margin: float = 1.0) -> tuple[np.ndarray, MetricGrid]:
    """A binary map of part of the plan, as the paper's inputs are (black walls on white, no
    unknown value): the walls inside ``box`` (x0, y0, x1, y1, plan frame, metres), seen in a
    map frame where ``p_plan = tf(p_map)``. The image covers the box's bounding rectangle in
    the map frame plus ``margin`` metres. Returns the uint8 image (0 or 255) and its grid."""
    x0, y0, x1, y1 = box
    return _binary_within(segments, np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), tf,
                          resolution, margin, convex=True)


def binary_cut(segments: np.ndarray, polygon: np.ndarray, tf: Similarity2D,
               resolution: float = 0.05, margin: float = 1.0) -> tuple[np.ndarray, MetricGrid]:
    """:func:`binary_partial` cut by a polygon: the walls inside ``polygon`` ((M, 2) corners
    in order, plan frame, metres; convex or not, an L or a U), black on white in the map frame
    where ``p_plan = tf(p_map)``, on an image covering the polygon's bounding rectangle there
    plus ``margin`` metres. Returns the uint8 image (0 or 255) and its grid."""
    return _binary_within(segments, np.asarray(polygon, dtype=np.float64).reshape(-1, 2), tf,
                          resolution, margin, convex=False)


def _binary_within(segments: np.ndarray, corners: np.ndarray, tf: Similarity2D,
                   resolution: float, margin: float,
                   convex: bool) -> tuple[np.ndarray, MetricGrid]:
    """The walls inside the polygon ``corners`` (plan frame) as a binary image in the map
    frame; ``convex``: the polygon is convex (OpenCV's convex fill, else its general one)."""
    import cv2

    corners = tf.inverse().apply(corners)
    grid = MetricGrid.covering(corners, resolution, margin)
    walls = render(transform_segments(segments, tf.inverse()), grid) == OCCUPIED
    inside = np.zeros(grid.shape, np.uint8)
    pixels = np.round(grid.xy_to_pixels(corners)).astype(np.int32)
    if convex:
        cv2.fillConvexPoly(inside, pixels, 1)
    else:
        cv2.fillPoly(inside, [pixels], 1)
    return np.where(walls & (inside > 0), 0, 255).astype(np.uint8), grid


def wall_points(segments: np.ndarray, spacing: float = 0.02, thickness: float = 0.15,
                noise: float = 0.0, seed: int = 0) -> np.ndarray:
    """Points on both faces of every wall, ``spacing`` metres apart, with Gaussian noise of std
    ``noise`` metres: a 2D laser-like cloud (N, 2) in the plan's frame."""
    rng = np.random.default_rng(seed)
    quads = wall_quads(segments, thickness)
    edges = np.concatenate([quads, np.roll(quads, -1, axis=1)], axis=2).reshape(-1, 4)
    fine = densify(edges, spacing)
    pts = fine[:, :2]
    if noise > 0:
        pts = pts + rng.normal(0.0, noise, size=pts.shape)
    return pts


def lidar_cloud(segments: np.ndarray, *, wall_height: float = 2.6, spacing: float = 0.05,
                thickness: float = 0.15, noise: float = 0.01, outliers: int = 500,
                seed: int = 0) -> np.ndarray:
    """A 3D cloud of the building: walls to ``wall_height``, floor at z = 0 and ceiling, with
    Gaussian noise (std ``noise`` m) and uniform outliers. (N, 3) metres, plan frame, z up."""
    rng = np.random.default_rng(seed)
    face = wall_points(segments, spacing, thickness)
    levels = np.arange(0.0, wall_height + 1e-9, spacing)
    walls = np.column_stack([np.repeat(face, len(levels), axis=0),
                             np.tile(levels, len(face))])
    lo, hi = segments.reshape(-1, 2).min(axis=0), segments.reshape(-1, 2).max(axis=0)
    n_flat = int(np.prod((hi - lo) / (2 * spacing)))
    floor = np.column_stack([rng.uniform(lo, hi, size=(n_flat, 2)), np.zeros(n_flat)])
    ceiling = np.column_stack([rng.uniform(lo, hi, size=(n_flat, 2)),
                               np.full(n_flat, wall_height)])
    pts = np.vstack([walls, floor, ceiling])
    pts += rng.normal(0.0, noise, size=pts.shape)
    junk = rng.uniform([*lo, 0.0], [*hi, wall_height], size=(outliers, 3))
    return np.vstack([pts, junk])


def room_corner(seed: int) -> np.ndarray:
    """Three orthogonal 2 m walls meeting at the origin, 1500 points each, 2 mm noise."""
    rng = np.random.default_rng(seed)
    walls = []
    for axis in range(3):
        w = rng.uniform(0, 2, (1500, 3))
        w[:, axis] = rng.normal(0, 0.002, len(w))
        walls.append(w)
    return np.vstack(walls)
