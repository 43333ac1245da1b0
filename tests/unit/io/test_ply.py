"""Binary PLY without Open3D: the header, the vertex records, truncation, and large clouds mapped
onto their file instead of read."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import open3d as o3d
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import clouds, load_map
from pcmapq.io.ply import vertex_block

#: Coordinates that float32 stores exactly and some it rounds.
XYZ = np.array([[0.0, 1.0, 2.0], [1.5, -2.0, 0.25], [3.1, 4.7, -1.3], [1e5 / 3, -7.77, 0.1]])


def write_ply(path: Path, fields: list[tuple[str, str]], records: np.ndarray) -> Path:
    """A little-endian binary PLY whose vertex element has ``fields`` (PLY type, name) holding
    ``records`` (as stored)."""
    head = ("ply\nformat binary_little_endian 1.0\ncomment made by a test\n"
            f"element vertex {len(records)}\n"
            + "".join(f"property {kind} {name}\n" for kind, name in fields) + "end_header\n")
    path.write_bytes(head.encode() + records.tobytes())
    return path


def records_of(xyz: np.ndarray, dtype: list[tuple[str, str]], **extra: float) -> np.ndarray:
    out = np.zeros(len(xyz), dtype=dtype)
    for axis, name in enumerate("xyz"):
        out[name] = xyz[:, axis]
    for name, value in extra.items():
        out[name] = value
    return out


def open3d_points(path: Path) -> np.ndarray:
    return np.asarray(o3d.io.read_point_cloud(str(path)).points)


@pytest.mark.parametrize("kind", ["float", "double"])
def test_open3d_files_read_exactly_as_open3d_reads_them(tmp_path: Path, kind: str) -> None:
    path = tmp_path / "cloud.ply"
    cloud = o3d.t.geometry.PointCloud(o3d.core.Tensor(
        XYZ.astype(np.float32 if kind == "float" else np.float64)))
    assert o3d.t.io.write_point_cloud(str(path), cloud)
    block = vertex_block(path)
    assert block is not None and block.count == len(XYZ)
    assert block.dtype["x"] == np.dtype("<f4" if kind == "float" else "<f8")
    np.testing.assert_array_equal(block.read(), open3d_points(path))
    np.testing.assert_array_equal(load_map(path).points, open3d_points(path))


def test_other_properties_big_endian_and_elements_before(tmp_path: Path) -> None:
    """Intensity and colours between the coordinates, big-endian, a 2-record element first."""
    dtype = [("i", ">f4"), ("x", ">f8"), ("red", "u1"), ("y", ">f8"), ("z", ">f8")]
    first = np.array([(7, 1.0), (8, 2.0)], dtype=[("id", ">i4"), ("w", ">f4")])
    head = ("ply\nformat binary_big_endian 1.0\nelement camera 2\nproperty int id\n"
            "property float w\nelement vertex 4\nproperty float i\nproperty double x\n"
            "property uchar red\nproperty double y\nproperty double z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n")
    path = tmp_path / "scan.ply"
    path.write_bytes(head.encode() + first.tobytes()
                     + records_of(XYZ, dtype, i=0.5, red=200).tobytes()
                     + b"\x03" + np.array([0, 1, 2], ">i4").tobytes())
    block = vertex_block(path)
    assert block is not None and block.offset == len(head) + first.nbytes
    np.testing.assert_array_equal(block.read(), XYZ)
    np.testing.assert_array_equal(block.read(1, 3), XYZ[1:3])
    assert block.mapped() is None  # x, y, z not side by side


def test_ascii_and_list_vertices_are_left_to_open3d(tmp_path: Path) -> None:
    ascii_ply = tmp_path / "ascii.ply"
    ascii_ply.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n"
                         "0 1 2\n1.5 -2 0.25\n3 4 -1\n")
    assert vertex_block(ascii_ply) is None
    np.testing.assert_allclose(load_map(ascii_ply).points, [[0, 1, 2], [1.5, -2, 0.25],
                                                            [3, 4, -1]])
    listed = tmp_path / "list.ply"
    listed.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 1\n"
                       b"property list uchar float xyz\nproperty float x\nend_header\n")
    assert vertex_block(listed) is None


def test_non_finite_vertices_are_dropped(tmp_path: Path) -> None:
    xyz = np.vstack([XYZ, [[np.nan, 0, 0], [0, np.inf, 1]]])
    fields = [("float", "x"), ("float", "y"), ("float", "z")]
    path = write_ply(tmp_path / "nan.ply", fields, xyz.astype("<f4"))
    np.testing.assert_array_equal(load_map(path).points, XYZ.astype(np.float32))


BAD = {
    "truncated.ply": (lambda p: write_ply(p, [("float", "x"), ("float", "y"), ("float", "z")],
                                          XYZ.astype("<f4")).write_bytes(p.read_bytes()[:-5]),
                      "truncated: header declares 4 points, the file holds 3"),
    "noz.ply": (lambda p: write_ply(p, [("float", "x"), ("float", "y")],
                                    XYZ[:, :2].astype("<f4")),
                "the PLY's vertices have no z"),
    "badtype.ply": (lambda p: write_ply(p, [("float", "x"), ("float", "y"), ("quad", "z")],
                                        XYZ.astype("<f4")),
                    "bad PLY header line 7 ('property quad z'): unknown type quad"),
    "noend.ply": (lambda p: p.write_bytes(b"ply\nformat binary_little_endian 1.0\n"),
                  "PLY header without end_header"),
    "twice.ply": (lambda p: write_ply(p, [("float", "x"), ("float", "x"), ("float", "z")],
                                      XYZ.astype("<f4")),
                  "bad PLY element vertex"),
    "novertex.ply": (lambda p: p.write_bytes(b"ply\nformat binary_little_endian 1.0\n"
                                             b"element face 0\nend_header\n"),
                     "no vertex element in the PLY header"),
    "empty.ply": (lambda p: write_ply(p, [("float", "x"), ("float", "y"), ("float", "z")],
                                      np.zeros((0, 3), "<f4")),
                  "empty.ply: no points"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_ply_is_one_input_error_line_naming_the_file(tmp_path: Path, name: str) -> None:
    make, expected = BAD[name]
    make(tmp_path / name)
    with pytest.raises(InputError) as info:
        load_map(tmp_path / name)
    message = str(info.value)
    assert message.startswith(str(tmp_path / name)) and "\n" not in message
    assert expected in message, message


# --- large clouds: mapped, not read -------------------------------------------------------------


@pytest.fixture
def small_map_limit(monkeypatch: pytest.MonkeyPatch) -> int:
    """Clouds of more than 10 points count as large."""
    monkeypatch.setattr(clouds, "MAP_POINTS", 10)
    monkeypatch.setattr(clouds, "CHUNK", 7)  # and are scanned 7 rows at a time
    return 10


def test_large_cloud_is_mapped_onto_its_file(tmp_path: Path, small_map_limit: int) -> None:
    xyz = np.random.default_rng(0).normal(size=(25, 3)).astype(np.float32)
    fields = [("float", "x"), ("float", "y"), ("float", "z"), ("uchar", "label")]
    dtype = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("label", "u1")]
    path = write_ply(tmp_path / "big.ply", fields, records_of(xyz, dtype, label=3))
    m = load_map(path)
    assert m.is_3d and m.points.dtype == np.float32 and not m.points.flags.writeable
    assert not m.points.flags.owndata and m.points.base is not None  # a view of the mapping
    np.testing.assert_array_equal(m.points, xyz)


@pytest.mark.parametrize("case", ["nan", "flat"])
def test_large_cloud_with_bad_rows_or_flat_is_read(tmp_path: Path, small_map_limit: int,
                                                   case: str) -> None:
    """Mapped points are all finite and 3D; other large clouds are read as small ones are."""
    xyz = np.random.default_rng(0).normal(size=(25, 3))
    if case == "nan":
        xyz[17, 1] = np.nan
    else:
        xyz[:, 2] = 1.25
    fields = [("double", "x"), ("double", "y"), ("double", "z")]
    m = load_map(write_ply(tmp_path / "big.ply", fields, xyz.astype("<f8")))
    assert m.points.dtype == np.float64 and m.points.flags.owndata
    if case == "nan":
        np.testing.assert_array_equal(m.points, np.delete(xyz, 17, axis=0))
    else:
        assert not m.is_3d and np.all(m.points[:, 2] == 0.0)


# --- the scan each point came from -----------------------------------------------------------


@pytest.mark.parametrize("suffix", [".ply", ".pcd"])
def test_a_maps_scans_are_written_and_read_back(tmp_path: Path, suffix: str) -> None:
    """``write_cloud(..., scan=)`` stores each point's scan; a PLY or binary PCD reads it back
    beside its points, rows with a non-finite coordinate dropped from both; a cloud without
    one has none."""
    from pcmapq.io.writers import write_cloud

    xyz = np.random.default_rng(0).normal(size=(40, 3))
    scan = np.repeat(np.arange(8) + 0.5, 5)
    write_cloud(tmp_path / f"m{suffix}", xyz, scan=scan)
    m = load_map(tmp_path / f"m{suffix}")
    np.testing.assert_array_equal(m.scan, scan.astype(np.float32))
    write_cloud(tmp_path / f"plain{suffix}", xyz)
    assert load_map(tmp_path / f"plain{suffix}").scan is None
    xyz[3, 0] = np.nan
    write_cloud(tmp_path / f"nan{suffix}", xyz, scan=scan)
    m = load_map(tmp_path / f"nan{suffix}")
    assert len(m.points) == len(m.scan) == 39 and m.scan[3] == scan[4]


def test_a_large_maps_scans_are_mapped_too(tmp_path: Path, small_map_limit: int) -> None:
    from pcmapq.io.writers import write_cloud

    xyz = np.random.default_rng(0).normal(size=(25, 3))
    write_cloud(tmp_path / "big.ply", xyz, scan=np.arange(25))
    m = load_map(tmp_path / "big.ply")
    assert not m.points.flags.owndata
    np.testing.assert_array_equal(m.scan, np.arange(25))


def test_scans_that_are_not_numbers_of_at_least_0_are_not_read(tmp_path: Path) -> None:
    """Another program's ``scan`` property with a negative value: the cloud is read, its
    scans are not, with a warning naming the file."""
    from pcmapq.io.writers import write_cloud

    xyz = np.random.default_rng(0).normal(size=(10, 3))
    write_cloud(tmp_path / "m.ply", xyz, scan=np.arange(10) - 1.0)
    with pytest.warns(UserWarning, match=r"m\.ply: its 'scan' values are not all numbers"):
        m = load_map(tmp_path / "m.ply")
    assert m.scan is None and len(m.points) == 10
