"""The bottom layer every stage shares, importing nothing else of pcmapq: metric grids and
boxes (:mod:`~pcmapq.core.grid`, :mod:`~pcmapq.core.bounds`), cell states, 2D similarities
and the frame chain (:mod:`~pcmapq.core.transform`, :mod:`~pcmapq.core.frames`), voxels,
statistics, raster morphology, the memory estimate and the errors users see."""
