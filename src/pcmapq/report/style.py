"""What every picture shares, defined once and loadable without matplotlib: the rule of the
arrows' scale, colours, sizes.

Sizes are chosen for the HTML report: a figure is at most :data:`FIGURE_WIDTH_PX` pixels wide
at :data:`DPI`, the width the report shows it at, unscaled, so a font of ``s`` points reads as
``s * DPI / 72`` pixels there (9 pt: 16 px).
"""

from __future__ import annotations

#: Displacement arrows go from the truth's feature (or region) to where the map has it: the
#: map's error. One scale holds for every panel of a figure: unless ``--arrow-scale`` sets it,
#: the largest of 1, 2 or 5 times a power of ten, from 1 to MAX_ARROW_SCALE, that draws the
#: longest arrow no longer than ARROW_SHARE of a panel's larger side.
ARROW_SHARE, MAX_ARROW_SCALE = 0.12, 100.0
#: Dots per inch of the PNGs; rasters are pooled to the pixels their panel has at this
#: resolution (saved at fewer dpi, matplotlib skips some of their rows again).
DPI = 130
#: Widest figure: pixels at DPI (the width the HTML report gives a figure), and inches.
FIGURE_WIDTH_PX = 1350
WIDTH_IN = FIGURE_WIDTH_PX / DPI
#: Font sizes, points: titles, everything else (tick labels, legend, colour bar).
TITLE_PT, TEXT_PT = 10.0, 9.0
#: The truth's walls, dark, drawn over the aligned map's, light, so both show where they meet.
TRUTH_DARK, MAP_LIGHT = (0.16, 0.16, 0.16), (0.55, 0.76, 1.0)
#: The Okabe-Ito palette (Okabe and Ito, "Color Universal Design", 2008): told apart with
#: every common colour-vision deficiency. Black, orange, sky blue, bluish green, yellow, blue,
#: vermillion, reddish purple.
OKABE_ITO = ("#000000", "#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00",
             "#CC79A7")
#: Each detector's colour wherever detectors are told apart by colour (the compare figure,
#: the track curves): one Okabe-Ito colour each, of those that read on white (no yellow, no
#: black) four no two of which are closer than 147 in RGB (0-255 a channel; none closer).
DETECTOR_COLOURS = {"harris": OKABE_ITO[2], "hough": OKABE_ITO[6], "sift": OKABE_ITO[3],
                    "rooms": OKABE_ITO[7]}
#: Colours of the other curves beside the detectors' (the palette's rest, then grey).
OTHER_COLOURS = (OKABE_ITO[0], OKABE_ITO[1], OKABE_ITO[5], "#999999", OKABE_ITO[4])
#: Features and the footprint outline.
MATCHED, MISSING, EXTRA, FOOTPRINT = "#1a9850", "#d73027", "#f28e2b", "#7b3294"
#: Markers of one kind are thinned to at most one per square of this many pixels: walls, and
#: the density of two LiDAR clouds (thousands of features over sparse points: wider squares
#: leave the points visible).
THIN_PX, THIN_PX_DENSITY = 8, 20
