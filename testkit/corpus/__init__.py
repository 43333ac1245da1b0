"""A labelled corpus for "same place, another place": (map, truth) pairs, each labelled with
whether the map shows the truth's place (``same``), a ``kind`` (clean, a degradation ladder, or
which other place) and a ``level`` on that ladder, scored as the same-place pairs are
(:mod:`testkit.realdata.same_place`: ``force`` and no detectors); then how well a figure
of the result (the confidence by default) tells the two labels apart.

Same place:

- clean: synthetic plans (``synth.building_plan`` seeds 0-4) as 2D point clouds (walls' faces
  5 cm apart) and as rendered images (0.05 m per pixel, walls 0.15 m thick), each in a map frame
  turned and shifted by a known similarity (``p_truth = tf(p_map)``, :func:`frame`); the shipped
  sample (``data/sample/scan.ply`` vs ``truth.png``, its pose from ``tools/make_sample.py``);
  the real same-place pairs (Intel and Freiburg 079 maps vs their plans, four Halmstad maps vs
  their layouts, Gazebo).
- degraded, on plan seeds 0-2, as points and as images (same frames as the clean ones):
  wall noise sigma 0.03 / 0.06 / 0.10 m (points: Gaussian noise of each point; images: see
  :func:`draw`: ragged walls drawn from noisy points, so their thickness jitters, plus speckle:
  a share sigma / (1 m) / 10 of the free cells marked occupied, 0.3 / 0.6 / 1 %); missing walls
  (``drop_walls`` 0.2 / 0.4 / 0.6 of the inner walls); a slow bend (``bend_segments`` about the
  plan's lower-left corner, see :data:`BENDS`: the far corner (24, 16) m moves 0.2 / 0.5 / 1.0 m,
  the far end of the bottom wall (24, 0) 0.83 times that); clutter (``clutter`` 200 / 400 / 800
  boxes of 0.5 m); a broken half (the walls right of x = 12 m turned by 5 / 10 / 15 degrees about
  the plan's middle (12, 8) m); a doubled half (those walls drawn again 0.5 / 1 / 2 m higher);
  a partial view (the walls in the left 0.6 / 0.45 / 0.3 of the plan's width).
- CARMEN drift: the first :data:`DRIFT_SCANS` scans of the intel, fhw and aces logs placed along
  their poses re-integrated with drift 1 / 2 / 3 / 4 % (the unit of :mod:`testkit.drift`:
  relative gain errors of the rotation and translation increments, ``1 + e * (1 + z)``,
  z ~ N(0, 1), seed 0) against the same scans at their corrected poses (readings up to 30 m);
  and the full-log drifted maps of the same-place pairs (intel 0.1 and 0.5 %, fhw 0.5 %)
  against the corrected log.

Another place: the 44 other-place pairs of the same-place table (30 CARMEN buildings against each
other, 12 Halmstad maps against the other layouts, Intel's and Freiburg's maps against each
other's plan); synthetic layouts that differ from the 24 x 16 m plans (:data:`OTHER_SIZES`:
``building_plan(seed, width, height)`` of other outlines, so other corridor heights, with seeds
10-34, so other rooms) as maps against plans 0-4 (points and images); the three round rooms of
``tests/e2e/test_same_place.py`` against plans 0-4; each degradation's strongest level of plans
0-2 (the ladders' maps) against two of those other layouts.

Plans of one size share much of their walls (85 % of plan 0's wall points lie within 0.1 m of
plan 1's), so every synthetic other-place pair is screened (:func:`screen`): its two layouts,
clean, are aligned by the same global search (the map's layout as points), and the pair is
dropped, not scored, when at that best pose more than :data:`MAX_SHARED` of either layout's
wall points lie within :data:`SHARED_M` of the other's walls.

Every map and truth is built lazily (a callable given a scratch folder) and deterministically
(seeded): :mod:`.maps` draws them, :mod:`.pairs` labels them, :mod:`.records` analyses what a
run recorded (``roc``, ``acceptance``, ``verdict_groups``). ``python -m bench.validation.corpus``
scores the pairs and writes the corpus's section of docs/validation.md.
"""

from pcmapq.results.result import INCONSISTENT, OTHER, SAME

from .maps import (
    BEND,
    BENDS,
    BROKEN,
    CLUTTER,
    HEIGHT,
    MAX_SHARED,
    MISSING,
    NOISE,
    OTHER_SEED,
    OTHER_SIZES,
    RESOLUTION,
    ROOMS_FRAME,
    SHARED_M,
    SHARED_STEP,
    SPACING,
    THICKNESS,
    WIDTH,
    Layout,
    Screened,
    bend_note,
    bend_rate,
    broken,
    cloud,
    degrade,
    draw,
    frame,
    hull,
    moved,
    screen,
    shared,
    slug,
    synthetic_map,
    truth_layout,
    truth_plan,
    wall_samples,
)
from .pairs import (
    CLEAN_SEEDS,
    CURRENT,
    DRIFT_LEVELS,
    DRIFT_LOGS,
    DRIFT_SCANS,
    DRIFT_SEED,
    KINDS,
    LADDER_SEEDS,
    LADDERS,
    RIGID,
    SAMPLE_POSE,
    SYNTHETIC_OTHER,
    Pair,
    degraded_truths,
    drift_map,
    drift_note,
    drift_offset,
    drift_pairs,
    drift_truth,
    other_layouts,
    pairs,
    real_pairs,
    synthetic_pairs,
    trajectory_error,
)
from .records import (
    THRESHOLDS,
    Group,
    Point,
    Record,
    Verdicts,
    acceptance,
    accepted,
    agreeing,
    kept,
    load,
    offsets,
    pose_wrong,
    rising,
    roc,
    safe,
    scored,
    value,
    verdict_groups,
)

__all__ = [
    "INCONSISTENT",
    "OTHER",
    "SAME",
    "BEND",
    "BENDS",
    "BROKEN",
    "CLEAN_SEEDS",
    "CLUTTER",
    "CURRENT",
    "DRIFT_LEVELS",
    "DRIFT_LOGS",
    "DRIFT_SCANS",
    "DRIFT_SEED",
    "Group",
    "HEIGHT",
    "KINDS",
    "LADDERS",
    "LADDER_SEEDS",
    "Layout",
    "MAX_SHARED",
    "MISSING",
    "NOISE",
    "OTHER_SEED",
    "OTHER_SIZES",
    "Pair",
    "Point",
    "RESOLUTION",
    "RIGID",
    "ROOMS_FRAME",
    "Record",
    "SAMPLE_POSE",
    "SHARED_M",
    "SHARED_STEP",
    "SPACING",
    "SYNTHETIC_OTHER",
    "Screened",
    "THICKNESS",
    "THRESHOLDS",
    "Verdicts",
    "WIDTH",
    "acceptance",
    "accepted",
    "agreeing",
    "bend_note",
    "bend_rate",
    "broken",
    "cloud",
    "degrade",
    "degraded_truths",
    "draw",
    "drift_map",
    "drift_note",
    "drift_offset",
    "drift_pairs",
    "drift_truth",
    "frame",
    "hull",
    "kept",
    "load",
    "moved",
    "offsets",
    "other_layouts",
    "pairs",
    "pose_wrong",
    "real_pairs",
    "rising",
    "roc",
    "safe",
    "scored",
    "screen",
    "shared",
    "slug",
    "synthetic_map",
    "synthetic_pairs",
    "trajectory_error",
    "truth_layout",
    "truth_plan",
    "value",
    "verdict_groups",
    "wall_samples",
]
