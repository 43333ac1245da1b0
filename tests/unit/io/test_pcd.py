"""PCD without Open3D: the fields of a binary record, the values Open3D's readers give, ASCII
values separated by spaces, tabs or commas, a truncated file refused, and the files left to
Open3D (compressed); coordinates named ``x y z`` or ``X Y Z``, and a file with neither refused
naming the fields it has."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import open3d as o3d
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import load_map, pcd
from pcmapq.mapping.scans import read_scan

#: Coordinates that float32 stores exactly and some it rounds; a NaN row (dropped).
XYZ = np.array([[0.0, 1.0, 2.0], [1.5, -2.0, 0.25], [3.1, 4.7, -1.3], [1e5 / 3, -7.77, 0.1],
                [np.nan, 0.0, 0.0]])


def write_pcd(path: Path, fields: list[tuple[str, str, int, int]], records: np.ndarray) -> Path:
    """A binary PCD whose records have ``fields`` (name, TYPE, SIZE, COUNT) holding
    ``records`` (as stored)."""
    def row(i: int) -> str:
        return " ".join(str(f[i]) for f in fields)
    head = (f"# .PCD v0.7 - made by a test\nVERSION 0.7\nFIELDS {row(0)}\nSIZE {row(2)}\n"
            f"TYPE {row(1)}\nCOUNT {row(3)}\nWIDTH {len(records)}\nHEIGHT 1\n"
            f"VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(records)}\nDATA binary\n")
    path.write_bytes(head.encode() + records.tobytes())
    return path


def tensor_scan(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Points and times as Open3D's tensor reader gives them (what scans were read by)."""
    cloud = o3d.t.io.read_point_cloud(str(path))
    stamps = cloud.point["t"].numpy().reshape(-1) if "t" in cloud.point else np.empty(0)
    return cloud.point.positions.numpy(), stamps


def records_of(dtype: list[tuple], times: np.ndarray) -> np.ndarray:
    """Records of :data:`XYZ` with ``times`` in ``t`` and every other field 255."""
    records = np.zeros(len(XYZ), dtype=dtype)
    for name in records.dtype.names:
        records[name] = 255
    for axis, name in enumerate("xyz"):
        records[name] = XYZ[:, axis]
    records["t"] = times
    return records


@pytest.mark.unit
@pytest.mark.parametrize("size", [4, 8])
def test_coordinates_and_times_as_open3d_reads_them(tmp_path: Path, size: int) -> None:
    """Padding of 4 values between the coordinates, a ring and a time field after them; a map
    of double coordinates reads as stored (Open3D's legacy reader gives zeros)."""
    fields = [("x", "F", size, 1), ("_", "U", 1, 4), ("y", "F", size, 1), ("z", "F", size, 1),
              ("ring", "U", 2, 1), ("t", "U", 4, 1)]
    dtype = [("x", f"<f{size}"), ("_", "u1", (4,)), ("y", f"<f{size}"), ("z", f"<f{size}"),
             ("ring", "<u2"), ("t", "<u4")]
    times = np.arange(len(XYZ)) * 1000
    path = write_pcd(tmp_path / "scan.pcd", fields, records_of(dtype, times))
    header = pcd.check_size(path)
    assert header.fields["y"] == pcd.PcdField(f"<f{size}", size + 4)
    assert header.fields["_"] == pcd.PcdField(None, size)  # 4 values: not read here
    table = pcd.read_fields(path, ("x", "y", "z", "t", "time"))
    assert table is not None and list(table) == ["x", "y", "z", "t"]
    points, stamps = read_scan(path)
    want_points, want_stamps = tensor_scan(path)
    keep = np.isfinite(want_points).all(axis=1)
    np.testing.assert_array_equal(points, want_points[keep])
    np.testing.assert_array_equal(stamps, want_stamps[keep])
    np.testing.assert_array_equal(stamps, times[:4])
    np.testing.assert_array_equal(load_map(path).points, XYZ[:4].astype(f"<f{size}"))


@pytest.mark.unit
def test_repeated_padding_fields(tmp_path: Path) -> None:
    """Padding fields share the name ``_``: the fields after them are read where they are
    (Open3D 0.20's tensor reader reads them from the wrong bytes, or crashes)."""
    fields = [("x", "F", 4, 1), ("y", "F", 4, 1), ("z", "F", 4, 1), ("_", "U", 1, 4),
              ("_", "U", 1, 2), ("t", "F", 8, 1)]
    dtype = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("p", "u1", (4,)), ("q", "u1", (2,)),
             ("t", "<f8")]
    times = 1.7e9 + np.arange(len(XYZ)) * 0.1
    path = write_pcd(tmp_path / "scan.pcd", fields, records_of(dtype, times))
    points, stamps = read_scan(path)
    np.testing.assert_array_equal(points, XYZ[:4].astype("<f4"))
    np.testing.assert_array_equal(stamps, times[:4])


@pytest.mark.unit
def test_a_float_map_reads_as_open3d_reads_it(tmp_path: Path) -> None:
    path = tmp_path / "map.pcd"
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(XYZ[:4]))
    assert o3d.io.write_point_cloud(str(path), cloud)
    assert pcd.read_header(path).data == "binary"
    np.testing.assert_array_equal(load_map(path).points,
                                  np.asarray(o3d.io.read_point_cloud(str(path)).points))


@pytest.mark.unit
@pytest.mark.parametrize("kind", ["ascii", "compressed"])
def test_ascii_and_compressed_files_read_as_open3d_reads_them(tmp_path: Path, kind: str) -> None:
    """An ASCII file read here (:func:`pcmapq.io.pcd.read_ascii`), a compressed one by
    Open3D."""
    path = tmp_path / "map.pcd"
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(XYZ[:4]))
    assert o3d.io.write_point_cloud(str(path), cloud, write_ascii=kind == "ascii",
                                    compressed=kind == "compressed")
    assert pcd.read_fields(path, ("x", "y", "z")) is None
    np.testing.assert_allclose(load_map(path).points, XYZ[:4], atol=1e-6)
    np.testing.assert_allclose(read_scan(path)[0], XYZ[:4], atol=1e-6)


@pytest.mark.unit
def test_a_field_numpy_does_not_hold_is_left_to_open3d(tmp_path: Path) -> None:
    """A time field of two values: not read here (Open3D decides what it is)."""
    records = np.zeros(2, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("t", "<f4", (2,))])
    path = write_pcd(tmp_path / "scan.pcd", [("x", "F", 4, 1), ("y", "F", 4, 1),
                                             ("z", "F", 4, 1), ("t", "F", 4, 2)], records)
    assert pcd.read_fields(path, ("x", "y", "z", "t")) is None
    assert pcd.read_fields(path, ("x", "y", "z")) is not None


@pytest.mark.unit
def test_a_truncated_scan_is_refused(tmp_path: Path) -> None:
    records = np.zeros(10, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4")])
    path = write_pcd(tmp_path / "scan.pcd", [(a, "F", 4, 1) for a in "xyz"], records)
    path.write_bytes(path.read_bytes()[:-6])
    with pytest.raises(InputError, match="declares 10 points, the file holds 9"):
        read_scan(path)


def pdal_style(path: Path, data: str, records: np.ndarray | None = None,
               fields: str = "X Y Z") -> Path:
    """A PCD as PDAL writes one: fields ``X Y Z`` (float32), ``data`` ascii (``records`` as
    lines of text) or binary (``records`` as float32 rows)."""
    rows = XYZ[:4] if records is None else records
    head = (f"VERSION 0.7\nFIELDS {fields}\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
            f"WIDTH {len(rows)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(rows)}\n"
            f"DATA {data}\n")
    body = (rows.astype("<f4").tobytes() if data == "binary" else
            "".join(" ".join(repr(float(v)) for v in row) + "\n" for row in rows).encode())
    path.write_bytes(head.encode() + body)
    return path


@pytest.mark.unit
@pytest.mark.parametrize("data", ["ascii", "binary"])
def test_capital_coordinate_fields_are_read(tmp_path: Path, data: str) -> None:
    """PDAL names the coordinates ``X Y Z`` (Open3D reads such a file as no points)."""
    got = load_map(pdal_style(tmp_path / "pdal.pcd", data)).points
    np.testing.assert_array_equal(got, XYZ[:4].astype("<f4") if data == "binary" else XYZ[:4])


@pytest.mark.unit
def test_a_compressed_file_of_capital_fields_goes_to_open3d_renamed(tmp_path: Path) -> None:
    """Open3D reads a copy whose FIELDS line names them in small letters; the file itself is
    not changed."""
    path = tmp_path / "map.pcd"
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(XYZ[:4]))
    assert o3d.io.write_point_cloud(str(path), cloud, compressed=True)
    data = path.read_bytes().replace(b"FIELDS x y z", b"FIELDS X Y Z")
    path.write_bytes(data)
    np.testing.assert_allclose(load_map(path).points, XYZ[:4], atol=1e-6)
    assert path.read_bytes() == data


@pytest.mark.unit
@pytest.mark.parametrize("separator", [" ", "\t", ",", ", "])
def test_ascii_values_may_be_separated_by_spaces_tabs_or_commas(tmp_path: Path,
                                                                separator: str) -> None:
    path = pdal_style(tmp_path / "map.pcd", "ascii")
    head, body = path.read_text().split("DATA ascii\n")
    path.write_text(head + "DATA ascii\n" + body.replace(" ", separator))
    np.testing.assert_array_equal(load_map(path).points, XYZ[:4])


@pytest.mark.unit
def test_ascii_coordinates_after_a_field_of_several_values(tmp_path: Path) -> None:
    """``normal`` (COUNT 3) before x, y, z: the coordinates are the 4th to 6th values."""
    head = ("VERSION 0.7\nFIELDS normal x y z rgb\nSIZE 4 4 4 4 4\nTYPE F F F F U\n"
            "COUNT 3 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n")
    path = tmp_path / "map.pcd"
    path.write_text(head + "0 0 1 1.5 2.5 3.5 4278190080\n0 1 0 -1 -2 -3 0\n")
    np.testing.assert_array_equal(load_map(path).points, [[1.5, 2.5, 3.5], [-1, -2, -3]])


@pytest.mark.unit
def test_a_file_without_coordinates_names_its_fields(tmp_path: Path) -> None:
    path = pdal_style(tmp_path / "map.pcd", "ascii", fields="rgb intensity label")
    with pytest.raises(InputError, match=r"map.pcd: no x, y, z fields; its fields: rgb, "
                                         r"intensity, label$"):
        load_map(path)


@pytest.mark.unit
def test_an_ascii_value_that_is_no_number_is_refused_in_one_line(tmp_path: Path) -> None:
    path = pdal_style(tmp_path / "map.pcd", "ascii")
    path.write_text(path.read_text().replace("1.5", "one and a half"))
    with pytest.raises(InputError, match=r"map.pcd: bad ASCII PCD data: ") as raised:
        load_map(path)
    assert "\n" not in str(raised.value)


@pytest.mark.unit
def test_blank_ascii_lines_are_skipped_as_pcl_skips_them(tmp_path: Path) -> None:
    """Found by the fuzzer: NumPy warned of blank lines. They are skipped, silently; lines
    fewer than the points declared are a truncated file."""
    path = pdal_style(tmp_path / "map.pcd", "ascii")
    head, body = path.read_text().split("DATA ascii\n")
    path.write_text(head + "DATA ascii\n" + body.replace("\n", "\n\n", 2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(load_map(path).points, XYZ[:4])
    path.write_text(head + "DATA ascii\n\n\n" + "".join(body.splitlines(True)[:3]))
    with pytest.raises(InputError, match="truncated: header declares 4 points, the file holds 3"):
        load_map(path)
