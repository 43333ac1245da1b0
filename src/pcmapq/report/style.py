"""What every picture shares, defined once and loadable without matplotlib (the command line
reads its ``--arrow-scale`` default here): the arrow scale, colours, sizes.

Sizes are chosen for the HTML report: a figure is at most :data:`FIGURE_WIDTH_PX` pixels wide
at :data:`DPI`, the width the report shows it at, unscaled, so a font of ``s`` points reads as
``s * DPI / 72`` pixels there (9 pt: 16 px).
"""

from __future__ import annotations

#: Displacement arrows are drawn this many times longer than the displacement, in every panel
#: of every run (``--arrow-scale``): a 0.1 m displacement is a 1 m arrow on the map's axes.
ARROW_SCALE = 10.0
#: Dots per inch of the PNGs; rasters are pooled to the pixels their panel has at this
#: resolution (saved at fewer dpi, matplotlib skips some of their rows again).
DPI = 130
#: Widest figure, pixels at DPI: the width the HTML report gives a figure.
FIGURE_WIDTH_PX = 1350
#: Font sizes, points: titles, everything else (tick labels, legend, colour bar).
TITLE_PT, TEXT_PT = 10.0, 9.0
#: The truth's walls, dark, drawn over the aligned map's, light, so both show where they meet.
TRUTH_DARK, MAP_LIGHT = (0.16, 0.16, 0.16), (0.55, 0.76, 1.0)
#: Features and the footprint outline.
MATCHED, MISSING, EXTRA, FOOTPRINT = "#1a9850", "#d73027", "#f28e2b", "#7b3294"
#: Markers of one kind are thinned to at most one per square of this many pixels: walls, and
#: the density of two LiDAR clouds (thousands of features over sparse points: wider squares
#: leave the points visible).
THIN_PX, THIN_PX_DENSITY = 8, 20
