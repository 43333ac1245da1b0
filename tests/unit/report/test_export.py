"""Exports for other tools (pcmapq.report.export, report.plot): figures by extension, the same
bytes every time; the cloud matrix composes the frame chain, or is the 3D registration."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.frames import Frames, Levelling
from pcmapq.core.transform import Similarity2D
from pcmapq.report.export import cloud_matrix
from pcmapq.report.plot import figure_bytes
from testkit.poses import rotation_about

#: The known map -> truth transform of these tests: p_truth = R(25 deg) p_map + (3, -2).
KNOWN = Similarity2D(3.0, -2.0, float(np.radians(25.0)))


@pytest.mark.parametrize("suffix,magic", [(".png", b"\x89PNG"), (".svg", b"<?xml"),
                                          (".pdf", b"%PDF")])
def test_figures_by_extension_and_the_same_every_time(suffix, magic, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    def drawn() -> bytes:
        fig = Figure()
        fig.add_subplot().plot([0, 1, 2], [1, 0, 1])
        return figure_bytes(fig, suffix[1:], 50)

    first = drawn()
    assert first.startswith(magic) and first == drawn()


def test_cloud_matrix_composes_the_chain():
    """A 3D truth cloud tilted by 4 degrees with its floor at z = 1.5 m, a map cloud tilted
    otherwise, floor at -0.7 m, turned and shifted: the chain takes map points onto the truth
    points they came from."""
    rng = np.random.default_rng(1)
    plan_points = np.column_stack([rng.uniform(0, 20, (50, 2)), rng.uniform(0, 3, 50)])
    tilt_t, tilt_m = rotation_about([1, 0, 0], 4.0), rotation_about([0.6, 0.8, 0], 3.0)
    # truth cloud: levelled by tilt_t, floor at 1.5 m; map cloud: levelled by tilt_m, floor -0.7
    truth = (plan_points + [0, 0, 1.5]) @ tilt_t          # tilt_t.T applied: levelling undoes it
    in_map_plan = np.column_stack([KNOWN.inverse().apply(plan_points[:, :2]),
                                   plan_points[:, 2] - 0.7])
    cloud = in_map_plan @ tilt_m
    frames = Frames(KNOWN, Levelling(tilt_m, -0.7), Levelling(tilt_t, 1.5))
    m = cloud_matrix(frames)
    np.testing.assert_allclose(cloud @ m[:3, :3].T + m[:3, 3], truth, atol=1e-9)


def test_after_a_3d_registration_the_chain_is_the_registration():
    reg = np.eye(4)
    reg[:3, :3], reg[:3, 3] = rotation_about([0.1, 0.2, 0.97], 40.0), [5.0, -3.0, 0.4]
    frames = Frames(Similarity2D(), Levelling(rotation_about([1, 0, 0], 2.0), 0.3),
                    Levelling(rotation_about([0, 1, 0], 1.0), -0.2), reg)
    np.testing.assert_allclose(cloud_matrix(frames), reg, atol=1e-12)
