"""map_server YAMLs (pcmapq.io.map_yaml): numbers written with an exponent (``5e-2``,
``1.0e9``: text to PyYAML's YAML 1.1 resolver) read as map_server reads them, text that is no
number still refused; a YAML beside an image that is not a map_server file ignored, with a
warning, when a resolution is given; map_server's thresholds and negate given as options override
a YAML's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import Thresholds, load_map
from pcmapq.io.map_yaml import read_yaml
from pcmapq.io.occupancy import load_occupancy
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN
from testkit.files import sample_yaml
from testkit.paths import SAMPLE


@pytest.mark.parametrize(("text", "value"), [("5e-2", 0.05), ("1e-2", 0.01),
                                             ("1.0e9", 1e9), ("5E-2", 0.05), ("'0.05'", 0.05)])
def test_yaml_exponent_numbers_read_as_numbers(tmp_path: Path, text: str, value: float):
    """PyYAML reads ``5e-2`` as text (YAML 1.1); map_server reads a number: so does pcmapq."""
    meta, _ = read_yaml(sample_yaml(tmp_path, resolution=text, origin="[-1e1, 2.5e+0, 0]",
                              occupied_thresh="6.5e-1", free_thresh="2e-1", negate="0e0"))
    assert meta.resolution == pytest.approx(value)
    assert meta.origin == (-10.0, 2.5, 0.0)
    assert (meta.occupied_thresh, meta.free_thresh, meta.negate) == (0.65, 0.2, False)


def test_yaml_exponent_resolution_loads_the_map(tmp_path: Path):
    """The same map with ``resolution: 5e-2`` and ``0.05``: the same grid."""
    written = load_occupancy(sample_yaml(tmp_path, resolution="5e-2"))
    (tmp_path / "m.yaml").write_text((tmp_path / "m.yaml").read_text().replace("5e-2", "0.05"))
    plain = load_occupancy(tmp_path / "m.yaml")
    assert written.grid == plain.grid and (written.state == plain.state).all()


@pytest.mark.parametrize("text", ["abc", "5e", "e-2", "1,5", ".nan", "nan", "inf", "1e400",
                                  "'5 cm'"])
def test_yaml_non_numbers_still_refused(tmp_path: Path, text: str):
    with pytest.raises(InputError, match=r"m\.yaml: 'resolution' must be a finite number"):
        read_yaml(sample_yaml(tmp_path, resolution=text))


RESULTS_YAML = "quality: 0.93\nprecision: 0.88\nnote: scored by hand\n"

@pytest.mark.parametrize("text", [RESULTS_YAML, "{ not: yaml: at all\n", "- a list\n"])
def test_a_results_yaml_beside_an_image_is_ignored_given_a_resolution(text, tmp_path):
    png = tmp_path / "map.png"
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    (tmp_path / "map.yaml").write_text(text)
    with pytest.warns(UserWarning, match=r"map\.yaml: ignored, not a map_server YAML"):
        got = load_map(png, resolution=0.05)
    assert got.grid.resolution == 0.05 and got.grid.origin == (0.0, 0.0, 0.0)
    with pytest.raises(InputError, match=r"map\.yaml"):  # no resolution: still an error
        load_map(png)


def test_a_broken_map_server_yaml_still_stops_the_run(tmp_path):
    """A YAML that names an image is a map_server file: its mistakes are errors."""
    png = tmp_path / "map.png"
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    (tmp_path / "map.yaml").write_text("image: map.png\nresolution: -1\norigin: [0, 0, 0]\n")
    with pytest.raises(InputError, match="'resolution' must be positive"):
        load_map(png, resolution=0.05)


def test_thresholds_override_the_yaml(tmp_path):
    """Grey 127 (p = 0.50) and 230 (p = 0.10): unknown and free by ROS's defaults; occupied
    and unknown with occupied 0.4, free 0.05; negate reads v / 255 (127: p 0.498, 230: 0.90)."""
    import cv2

    cv2.imwrite(str(tmp_path / "m.png"), np.array([[127, 230, 0]], dtype=np.uint8))
    (tmp_path / "m.yaml").write_text("image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    state = load_map(tmp_path / "m.png").state
    assert state.tolist() == [[UNKNOWN, FREE, OCCUPIED]]
    state = load_map(tmp_path / "m.png", thresholds=Thresholds(0.4, 0.05)).state
    assert state.tolist() == [[OCCUPIED, UNKNOWN, OCCUPIED]]
    state = load_map(tmp_path / "m.yaml", thresholds=Thresholds(negate=True)).state
    assert state.tolist() == [[UNKNOWN, OCCUPIED, FREE]]
