"""map_server YAML numbers written with an exponent (``5e-2``, ``1.0e9``: text to PyYAML's
YAML 1.1 resolver) read as map_server reads them; text that is no number still refused."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.core.errors import InputError
from pcmapq.io.map_yaml import read_yaml
from pcmapq.io.occupancy import load_occupancy

SAMPLE = Path(__file__).resolve().parents[1] / "data" / "sample"


def _yaml(tmp_path: Path, **fields: str) -> Path:
    """A map_server YAML naming the sample's truth image, with ``fields`` written as given."""
    (tmp_path / "truth.png").write_bytes((SAMPLE / "truth.png").read_bytes())
    text = {"image": "truth.png", "resolution": "0.05", "origin": "[0.0, 0.0, 0.0]", **fields}
    path = tmp_path / "m.yaml"
    path.write_text("".join(f"{k}: {v}\n" for k, v in text.items()))
    return path


@pytest.mark.unit
@pytest.mark.parametrize(("text", "value"), [("5e-2", 0.05), ("1e-2", 0.01),
                                             ("1.0e9", 1e9), ("5E-2", 0.05), ("'0.05'", 0.05)])
def test_yaml_exponent_numbers_read_as_numbers(tmp_path: Path, text: str, value: float):
    """PyYAML reads ``5e-2`` as text (YAML 1.1); map_server reads a number: so does pcmapq."""
    meta, _ = read_yaml(_yaml(tmp_path, resolution=text, origin="[-1e1, 2.5e+0, 0]",
                              occupied_thresh="6.5e-1", free_thresh="2e-1", negate="0e0"))
    assert meta.resolution == pytest.approx(value)
    assert meta.origin == (-10.0, 2.5, 0.0)
    assert (meta.occupied_thresh, meta.free_thresh, meta.negate) == (0.65, 0.2, False)


@pytest.mark.unit
def test_yaml_exponent_resolution_loads_the_map(tmp_path: Path):
    """The same map with ``resolution: 5e-2`` and ``0.05``: the same grid."""
    written = load_occupancy(_yaml(tmp_path, resolution="5e-2"))
    (tmp_path / "m.yaml").write_text((tmp_path / "m.yaml").read_text().replace("5e-2", "0.05"))
    plain = load_occupancy(tmp_path / "m.yaml")
    assert written.grid == plain.grid and (written.state == plain.state).all()


@pytest.mark.unit
@pytest.mark.parametrize("text", ["abc", "5e", "e-2", "1,5", ".nan", "nan", "inf", "1e400",
                                  "'5 cm'"])
def test_yaml_non_numbers_still_refused(tmp_path: Path, text: str):
    with pytest.raises(InputError, match=r"m\.yaml: 'resolution' must be a finite number"):
        read_yaml(_yaml(tmp_path, resolution=text))


@pytest.mark.unit
def test_yaml_non_number_through_the_cli_is_one_line(tmp_path: Path):
    path = _yaml(tmp_path, resolution="5cm")
    got = CliRunner().invoke(app, ["eval", str(path), str(path)])
    assert got.exit_code == 2, got.output
    line, = got.stderr.strip().splitlines()
    assert "m.yaml" in line and "'resolution' must be a finite number" in line
