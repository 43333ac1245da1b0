"""A result's CSV files: the vectorial map (``--vectors``) and the consistency map
(``--regions``), truth frame, metres and degrees."""

from __future__ import annotations

import io

import numpy as np

from pcmapq.results.blocks import DECIMALS, Findings
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
    out = io.StringIO()
    out.write(",".join(REGION_COLUMNS) + "\n")
    for region in consistency_block(result.consistency).regions:
        row = region.model_dump()
        out.write(",".join(str(int(v)) if isinstance(v, bool | int) else f"{v:.{DECIMALS}f}"
                           for v in (row[k] for k in REGION_COLUMNS)) + "\n")
    return out.getvalue()
