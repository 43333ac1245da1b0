"""The arrows of the vectorial map (report/arrows.py, report/plot.py): one convention (from the
truth to where the map has it) and one scale in every panel, the scale a round number that
keeps the longest arrow within a share of the panel, stated in the legend; ``--arrow-scale``
overrides it everywhere. Known answers: the shipped sample's wall 0.3 m east of the plan's, a
synthetic wall moved 0.5 m east."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.report.plot import vectorial_figure
from pcmapq.report.style import ARROW_SHARE, MAX_ARROW_SCALE
from pcmapq.settings import MatchingConfig, Settings
from testkit import synth
from testkit.files import write_image_map

#: Where the sample's moved wall's arrows start (truth frame, metres: x0, x1, y0, y1): its
#: features on the plan's wall at x = 8.0 m (SIFT's a little either side), and the regions of
#: the tiles holding it (x 8-12 m), whose arrows start where they fit the truth.
SAMPLE_WALL = (7.3, 10.0, -0.5, 7.0)


@pytest.fixture(scope="module")
def moved_result(plan, truth_png, tmp_path_factory):
    """A map whose L-shaped wall stands 0.5 m east of the truth's."""
    moved = synth.move_wall(synth.move_wall(plan, 20, (0.5, 0.0)), 21, (0.5, 0.0))
    path = write_image_map(moved, tmp_path_factory.mktemp("moved") / "moved.png")
    return evaluate(path, truth_png, Settings(matching=MatchingConfig(threshold=1.0)))


def arrows(fig) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """Each panel's drawn arrows by its title's first words: (tails (N, 2), vectors (N, 2),
    metres, and how many times its length an arrow is drawn)."""
    out = {}
    for ax in fig.axes:
        quivers = [c for c in ax.collections if hasattr(c, "scale_units")]
        if quivers:
            assert {(q.scale_units, q.angles) for q in quivers} == {("xy", "xy")}
            gains = {round(1.0 / q.scale, 9) for q in quivers}
            assert len(gains) == 1, gains
            out[ax.get_title().split(":")[0]] = (
                np.vstack([np.column_stack([q.X, q.Y]) for q in quivers]),
                np.vstack([np.column_stack([q.U, q.V]) for q in quivers]), gains.pop())
    return out


def legend_texts(fig) -> list[str]:
    legend = (fig.legends or [ax.get_legend() for ax in fig.axes if ax.get_legend()])[0]
    return [legend.get_title().get_text().replace("\n", " ")] + \
        [t.get_text() for t in legend.get_texts()]


def test_every_arrow_of_the_samples_moved_wall_points_east(sample_result):
    """The sample's wall stands 0.3 m east of the plan's: in every panel, features and regions
    alike, each arrow of it longer than 0.25 m points east (0.3 m, within 5 cm), from the
    truth to where the map has it; the legend says which way arrows go."""
    fig = vectorial_figure(sample_result)
    drawn = arrows(fig)
    assert {"harris", "hough", "sift", "same place"} <= set(drawn)
    x0, x1, y0, y1 = SAMPLE_WALL
    for panel, (tails, vectors, _) in drawn.items():
        on_wall = ((tails[:, 0] >= x0) & (tails[:, 0] < x1) & (tails[:, 1] >= y0)
                   & (tails[:, 1] <= y1) & (np.hypot(*vectors.T) > 0.25))
        if panel == "rooms":
            continue  # a room's centroid moves by a share of the wall's move
        assert on_wall.any(), panel
        np.testing.assert_allclose(vectors[on_wall], [[0.3, 0.0]] * int(on_wall.sum()),
                                   atol=0.05, err_msg=panel)
    assert any("from the truth to where the map has it" in t for t in legend_texts(fig))


def test_the_synthetic_moved_wall_points_east_in_every_feature_panel(moved_result):
    """The L wall moved 0.5 m east: every arrow starting on the L's truth position points
    east by 0.5 m, in every detector's panel."""
    for panel, (tails, vectors, _) in arrows(vectorial_figure(moved_result)).items():
        on_l = ((tails[:, 0] > 19.3) & (tails[:, 0] < 22.1) & (tails[:, 1] > 1.3)
                & (tails[:, 1] < 4.1) & (np.hypot(*vectors.T) > 0.1))
        if panel in ("rooms", "same place"):
            continue  # a room's centroid and a region's fit move by a share of it
        assert on_l.any(), panel
        np.testing.assert_allclose(vectors[on_l], [[0.5, 0.0]] * int(on_l.sum()), atol=0.02)


def _scaled(result, factor: float):
    """``result`` with every matched displacement ``factor`` times as long (map features
    moved off their truth features alike)."""
    return replace(result, detectors={
        name: replace(det, matching=replace(det.matching,
                                            displacement=det.matching.displacement * factor))
        for name, det in result.detectors.items()})


def _round(value: float) -> bool:
    """Whether ``value`` is 1, 2 or 5 times a power of ten."""
    mantissa = value / 10.0 ** np.floor(np.log10(value) + 1e-9)
    return any(np.isclose(mantissa, m) for m in (1, 2, 5))


@pytest.mark.parametrize("case", ["sample", "moved", "moved x10", "moved x0.01"])
def test_one_round_scale_keeps_the_longest_arrow_within_its_share(case, sample_result,
                                                                  moved_result):
    """The sample (a 26 m panel, 0.51 m at most: x5, not x10 and the regions' own x7.85), the
    synthetic map, its displacements ten times as long (5 m arrows on a 26 m panel: x1) and a
    hundredth as long: one scale in every panel, a round number from 1 to MAX_ARROW_SCALE, the
    largest that draws the longest arrow within ARROW_SHARE of the panel's larger side (at
    scale 1 it may be longer); the legend states it."""
    result = {"sample": sample_result, "moved": moved_result,
              "moved x10": _scaled(moved_result, 10.0),
              "moved x0.01": _scaled(moved_result, 0.01)}[case]
    fig = vectorial_figure(result)
    drawn = arrows(fig)
    gains = {gain for _, _, gain in drawn.values()}
    assert len(gains) == 1, gains
    gain = gains.pop()
    assert 1 <= gain <= MAX_ARROW_SCALE and _round(gain)
    ax = fig.axes[0]
    side = max(np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim()))
    longest = max(np.hypot(*v.T).max() for _, v, _ in drawn.values())
    assert gain == 1 or gain * longest <= ARROW_SHARE * side + 1e-9
    larger = [g for g in (2 * gain, 2.5 * gain) if _round(g)][0]  # the next round scale
    assert gain == MAX_ARROW_SCALE or larger * longest > ARROW_SHARE * side
    expected = {"sample": 5, "moved x10": 1, "moved x0.01": MAX_ARROW_SCALE}.get(case)
    assert expected is None or gain == expected
    assert f"displacement x{gain:g} (0.1 m drawn {0.1 * gain:g} m), truth to map" in \
        legend_texts(fig)


def test_arrow_scale_overrides_every_panel_and_the_report(sample_result):
    """``--arrow-scale 3``: every panel's arrows, features and regions, three times their
    length, said in the legend; the report's interactive map uses the figure's scale."""
    drawn = arrows(fig := vectorial_figure(sample_result, 3.0))
    assert {gain for _, _, gain in drawn.values()} == {3.0}
    assert "displacement x3 (0.1 m drawn 0.3 m), truth to map" in legend_texts(fig)
    assert "Arrows: 5 times the displacement" in report_html(sample_result)
    assert "Arrows: 3 times the displacement" in report_html(sample_result, 3.0)
