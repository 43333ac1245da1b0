"""A result's CSV files: the vectorial map (``--vectors``), the consistency map (``--regions``)
and two 3D clouds' 3D consistency map (``--regions-3d``), truth frame, metres and degrees."""

from __future__ import annotations

import io

import numpy as np

from pcmapq.results.blocks import DECIMALS, Findings
from pcmapq.results.blocks3d import consistency_3d_block, region_3d_columns
from pcmapq.results.document import REGION_COLUMNS, consistency_block


def vectors_csv(result: Findings) -> str:
    """One row per matched pair (the JSON's ``matches``): its truth and map features'
    positions and the displacement between them, metres (truth frame), then which of its
    two features are counted (1) or support-level (0). A pair counts towards ``matched``
    when its truth feature is counted and towards ``matched_map`` when its map feature
    is, so the rows outnumber either count when some pairs have one side uncounted."""
    out = io.StringIO()
    out.write("detector,truth_x_m,truth_y_m,map_x_m,map_y_m,dx_m,dy_m,displacement_m,"
              "truth_counted,map_counted\n")
    for name, det in result.detectors.items():
        m = det.matching
        rows = np.column_stack([det.truth_xy, det.map_xy, m.displacement, det.distances])
        counted = np.column_stack([det.truth.strong[m.truth_idx], det.map.strong[m.map_idx]])
        for row, flags in zip(rows + 0.0, counted.astype(int), strict=True):
            out.write(",".join([name, *(f"{v:.{DECIMALS}f}" for v in row),
                                *(str(f) for f in flags)]) + "\n")
    return out.getvalue()


def regions_csv(result: Findings) -> str:
    """One row per region of the consistency map (the JSON's ``consistency.regions``):
    where the region is, the offset and turn that fit it to the truth on its own, its
    points and its fitness before and after, truth frame, metres and degrees."""
    return _rows(REGION_COLUMNS, consistency_block(result.consistency).regions)


def regions_3d_csv(result: Findings) -> str:
    """One row per region of the 3D consistency map (the JSON's ``consistency_3d.regions``):
    where the region is, the map's error there (dx, dy, dz and roll, pitch, yaw: where the map
    has it from where it fits the truth on its own), its points, its fitness before and after
    and whether it is held, in the truth's levelled frame, metres and degrees; a stretch of
    the run's first and last scan when the regions are stretches. The header alone when there
    is none (not two 3D clouds)."""
    c = result.consistency_3d
    return _rows(region_3d_columns(c), [] if c is None else consistency_3d_block(c).regions)


def _rows(columns: tuple[str, ...], regions: list) -> str:
    """The CSV of ``regions`` (schema blocks): a header of ``columns``, then one row each,
    flags and counts as integers, lengths to the micrometre."""
    out = io.StringIO()
    out.write(",".join(columns) + "\n")
    for region in regions:
        row = region.model_dump()
        out.write(",".join(str(int(v)) if isinstance(v, bool | int) else f"{v:.{DECIMALS}f}"
                           for v in (row[k] for k in columns)) + "\n")
    return out.getvalue()
