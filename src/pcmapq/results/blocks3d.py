"""The 3D consistency map (:class:`~pcmapq.align.regions3d.Consistency3D`) as its JSON block
(:class:`~pcmapq.results.schema.ConsistencyMap3D`) and back, and as the rows of its CSV."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pcmapq.results import schema as s

if TYPE_CHECKING:  # the alignment modules load small_gicp; a result only holds their outputs
    from pcmapq.align.regions3d import Consistency3D

#: The columns of a 3D region, in the JSON and the ``--regions-3d`` CSV.
REGION_3D_COLUMNS = tuple(s.Region3D.model_fields)
#: Of them, the columns of a stretch of the run (null for a tile), and those of a tile.
SCAN_COLUMNS = ("first_scan", "last_scan")
TILE_COLUMNS = tuple(key for key in REGION_3D_COLUMNS if key not in SCAN_COLUMNS)


def region_3d_columns(c: Consistency3D | None) -> tuple[str, ...]:
    """The columns of the regions of ``c``: a stretch's all of them, a tile's (or none's)
    TILE_COLUMNS."""
    return REGION_3D_COLUMNS if c is not None and c.scans is not None else TILE_COLUMNS


def _at(c: Consistency3D, k: int | None) -> tuple[float, float, float] | None:
    return None if k is None else tuple(float(v) for v in c.centre[k])


def consistency_3d_block(c: Consistency3D) -> s.ConsistencyMap3D:
    """The block: the tile, the held regions' longest offset and largest |dz| and where they
    are, and every region."""
    columns = (*c.centre.T, *c.offset.T, c.offset_m, *c.angles_deg.T)
    # a tile's region and block leave out the stretches' fields: the JSON of tiles is as it was
    scans = [()] * len(c.points) if c.scans is None else c.scans.tolist()
    regions = [s.Region3D(**dict(zip(region_3d_columns(c), (*row, n, before, after, held, *span),
                                     strict=True)))
               for row, n, before, after, held, span in zip(
                   np.column_stack(columns).tolist(), c.points.astype(int).tolist(),
                   c.fit_before.tolist(), c.fit_after.tolist(), c.held.astype(bool).tolist(),
                   scans, strict=True)]
    k, dz = c.largest(), c.largest_dz()
    stretch = {} if c.scans is None else {"stretch_scans": c.stretch}
    return s.ConsistencyMap3D(
        tile_m=c.tile_m, **stretch, voxel_m=c.voxel_m, tolerance_m=c.tolerance_m,
        largest_offset_m=None if k is None else float(c.offset_m[k]), largest_at_m=_at(c, k),
        largest_dz_m=None if dz is None else abs(float(c.offset[dz, 2])),
        largest_dz_at_m=_at(c, dz), regions=regions)


def consistency_3d_of(doc: s.ConsistencyMap3D | None) -> Consistency3D | None:
    """The 3D consistency map a document holds (None when it holds none)."""
    from pcmapq.align.regions3d import Consistency3D

    if doc is None:
        return None
    table = np.array([[getattr(r, key) for key in TILE_COLUMNS] for r in doc.regions],
                     dtype=np.float64).reshape(-1, len(TILE_COLUMNS))
    scans = None if doc.stretch_scans is None else np.array(
        [[r.first_scan, r.last_scan] for r in doc.regions], dtype=int).reshape(-1, 2)
    return Consistency3D(doc.tile_m, doc.voxel_m, doc.tolerance_m, table[:, 0:3],
                         table[:, 3:6], table[:, 7:10], table[:, 10].astype(int),
                         table[:, 11], table[:, 12], table[:, 13] > 0, scans,
                         doc.stretch_scans or 0)
