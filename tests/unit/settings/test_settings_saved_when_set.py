"""A setting only some inputs use is saved only when it is not its default, so the results of
the other inputs stay as they were: the 3D consistency map's tile (two 3D clouds)."""

from __future__ import annotations

from pcmapq.settings import AlignmentConfig, Settings


def test_the_3d_tile_is_saved_only_when_set():
    assert "tile_3d" not in Settings().to_dict()["alignment"]
    given = Settings(alignment=AlignmentConfig(tile_3d=12.0))
    assert given.to_dict()["alignment"]["tile_3d"] == 12.0
    assert Settings.from_dict(given.to_dict()) == given
    assert Settings.from_dict(Settings().to_dict()).alignment.tile_3d == 8.0
