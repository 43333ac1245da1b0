"""Loaders: occupancy images with map_server YAML, point clouds, bad inputs, atomic writes."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import cv2
import numpy as np
import open3d as o3d
import pytest

from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.io import OccupancyMap, PointMap, load_map, writers
from pcmapq.io.writers import write_atomic
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN
from testkit.files import write_png


def write_yaml(path: Path, image: str = "map.png", **keys: object) -> Path:
    """A map_server YAML with defaults resolution 0.05, origin [-1, 2, 0]; None drops a key."""
    fields = {"image": image, "resolution": 0.05, "origin": [-1.0, 2.0, 0.0], **keys}
    path.write_text("".join(f"{k}: {v}\n" for k, v in fields.items() if v is not None))
    return path


# --- occupancy images ---------------------------------------------------------------------------

# Default thresholds: occupied if (255 - v)/255 > 0.65 (v <= 89), free if < 0.196 (v >= 206).
TRINARY = [[0, 89, 90, 128], [205, 206, 254, 255]]
TRINARY_STATE = [[OCCUPIED, OCCUPIED, UNKNOWN, UNKNOWN], [UNKNOWN, FREE, FREE, FREE]]


def test_yaml_png_pair(tmp_path: Path) -> None:
    write_png(tmp_path / "map.png", TRINARY)
    m = load_map(write_yaml(tmp_path / "map.yaml"))
    assert isinstance(m, OccupancyMap) and m.kind == "image"
    assert m.state.dtype == np.int8
    np.testing.assert_array_equal(m.state, TRINARY_STATE)
    assert m.grid.resolution == 0.05
    assert m.grid.origin == (-1.0, 2.0, 0.0)
    assert m.grid.shape == (2, 4)


def test_negate(tmp_path: Path) -> None:
    # negate: p = v/255; occupied if v >= 166, free if v <= 49
    write_png(tmp_path / "map.png", [[0, 49, 50, 165, 166, 255]])
    m = load_map(write_yaml(tmp_path / "map.yaml", negate=1))
    np.testing.assert_array_equal(m.state, [[FREE, FREE, UNKNOWN, UNKNOWN, OCCUPIED, OCCUPIED]])


def test_thresholds_are_strict(tmp_path: Path) -> None:
    # p = 153/255 = 0.6 exactly is not > 0.6; p = 51/255 = 0.2 is not < 0.2
    write_png(tmp_path / "map.png", [[101, 102, 203, 204, 205]])
    m = load_map(write_yaml(tmp_path / "map.yaml", occupied_thresh=0.6, free_thresh=0.2))
    np.testing.assert_array_equal(m.state, [[OCCUPIED, UNKNOWN, UNKNOWN, UNKNOWN, FREE]])


def test_scale_mode_is_trinary_and_raw_mode_is_percent(tmp_path: Path) -> None:
    write_png(tmp_path / "map.png", TRINARY)
    scale = load_map(write_yaml(tmp_path / "map.yaml", mode="scale"))
    np.testing.assert_array_equal(scale.state, TRINARY_STATE)
    write_png(tmp_path / "raw.png", [[0, 19, 50, 66, 100, 101, 255]])
    raw = load_map(write_yaml(tmp_path / "raw.yaml", image="raw.png", mode="raw"))
    np.testing.assert_array_equal(
        raw.state, [[FREE, FREE, UNKNOWN, OCCUPIED, OCCUPIED, UNKNOWN, UNKNOWN]])


def test_colour_alpha_and_16_bit(tmp_path: Path) -> None:
    bgra = np.zeros((1, 3, 4), dtype=np.uint8)
    bgra[0, 0] = (0, 0, 255, 255)  # mean 85: occupied
    bgra[0, 1] = (0, 0, 0, 0)  # black but transparent: unknown
    bgra[0, 2] = (254, 254, 254, 255)  # free
    cv2.imwrite(str(tmp_path / "c.png"), bgra)
    colour = load_map(tmp_path / "c.png", resolution=0.1)
    np.testing.assert_array_equal(colour.state, [[OCCUPIED, UNKNOWN, FREE]])
    deep = np.array([[0, 100 * 257, 65535]], dtype=np.uint16)
    cv2.imwrite(str(tmp_path / "d.png"), deep)
    np.testing.assert_array_equal(load_map(tmp_path / "d.png", resolution=0.1).state,
                                  [[OCCUPIED, UNKNOWN, FREE]])


def test_cell_centre_convention(tmp_path: Path) -> None:
    write_png(tmp_path / "map.png", np.full((3, 5), 254))
    m = load_map(write_yaml(tmp_path / "map.yaml", resolution=0.2, origin=[1.0, -2.0]))
    assert m.grid.origin == (1.0, -2.0, 0.0)
    centre = m.grid.pixels_to_xy(np.array([[0, 0]]))[0]
    np.testing.assert_allclose(centre, [1.0 + 0.5 * 0.2, -2.0 + (3 - 0.5) * 0.2])
    # the last row, last column is the lower-right cell
    np.testing.assert_allclose(m.grid.pixels_to_xy(np.array([[4, 2]]))[0], [1.9, -1.9])


def test_image_finds_yaml_beside_it(tmp_path: Path) -> None:
    png = write_png(tmp_path / "x.png", TRINARY)
    write_yaml(tmp_path / "x.yaml", image="x.png", resolution=0.25, origin=[3, 4, 0.5])
    m = load_map(png)
    assert m.path == png
    assert m.grid.resolution == 0.25 and m.grid.origin == (3.0, 4.0, 0.5)
    np.testing.assert_array_equal(m.state, TRINARY_STATE)
    # an explicit resolution overrides the YAML's and keeps its origin
    assert load_map(png, resolution=0.1).grid == MetricGrid(0.1, (3.0, 4.0, 0.5), (2, 4))


def test_yaml_beside_an_image_may_name_another_file(tmp_path: Path) -> None:
    png = write_png(tmp_path / "copy.png", TRINARY)
    write_yaml(tmp_path / "copy.yaml", image="original.png", negate="true")
    with pytest.warns(UserWarning, match=r"copy\.yaml: names image 'original\.png'"):
        state = load_map(png).state
    np.testing.assert_array_equal(state, [[FREE, UNKNOWN, UNKNOWN, UNKNOWN],
                                          [OCCUPIED, OCCUPIED, OCCUPIED, OCCUPIED]])


def test_yaml_beside_an_image_naming_another_image_is_warned_about(tmp_path: Path) -> None:
    """a.png with a.yaml beside it saying ``image: b.png`` (b.png exists and differs): a.png is
    read with a.yaml's numbers, and one warning names both files and the one read; the YAML
    given reads b.png, as map_server does, and says nothing."""
    a = write_png(tmp_path / "a.png", TRINARY)
    write_png(tmp_path / "b.png", np.full((3, 5), 254))
    yml = write_yaml(tmp_path / "a.yaml", image="b.png", resolution=0.25, origin=[3, 4, 0])
    with pytest.warns(UserWarning) as warned:
        m = load_map(a)
    assert [str(w.message) for w in warned] == [
        f"{yml}: names image 'b.png', not a.png; a.png read with this YAML's resolution, "
        "origin and thresholds (give the YAML itself to read the image it names)"]
    assert warned[0].filename.endswith("occupancy.py")  # pcmapq's: shown on the command line
    assert m.path == a and m.grid == MetricGrid(0.25, (3.0, 4.0, 0.0), (2, 4))
    np.testing.assert_array_equal(m.state, TRINARY_STATE)
    with pytest.warns(UserWarning, match=r"a\.yaml: names image 'b\.png', not a\.png; a\.png "
                      r"read with this YAML's origin and thresholds \("):
        load_map(a, resolution=0.1)  # the resolution given is not the YAML's
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        given = load_map(yml)
    assert given.path == yml and given.grid == MetricGrid(0.25, (3.0, 4.0, 0.0), (3, 5))
    assert (given.state == FREE).all()


@pytest.mark.parametrize("named", ["a.png", "./a.png", "../maps/a.png", "ABSOLUTE", "link.png"])
def test_yaml_beside_an_image_naming_that_image_says_nothing(tmp_path: Path, named: str) -> None:
    """The YAML's image is the image given, however written (relative, absolute, through a
    link): no warning."""
    (tmp_path / "maps").mkdir()
    a = write_png(tmp_path / "maps" / "a.png", TRINARY)
    (tmp_path / "maps" / "link.png").symlink_to(a)
    write_yaml(tmp_path / "maps" / "a.yaml", image=str(a) if named == "ABSOLUTE" else named)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = load_map(a)
        load_map(tmp_path / "maps" / "a.yaml")
    np.testing.assert_array_equal(m.state, TRINARY_STATE)


def test_yaml_warning_is_not_swallowed_by_a_capture_on_another_thread(
        tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """The truth is read (its library's stderr captured) while the map is: the map's warning,
    printed meanwhile, waits for that capture to end rather than landing in it."""
    import threading
    import time

    from pcmapq.io.stderr import stderr_captured

    a = write_png(tmp_path / "a.png", TRINARY)
    write_png(tmp_path / "b.png", TRINARY)
    write_yaml(tmp_path / "a.yaml", image="b.png")
    capturing, captured = threading.Event(), []

    def read_truth() -> None:
        with stderr_captured() as lines:
            capturing.set()
            time.sleep(0.3)
        captured.extend(lines)

    def to_descriptor_2(message: Warning | str, *_: object) -> None:
        os.write(2, f"pcmapq: warning: {message}\n".encode())

    truth = threading.Thread(target=read_truth)
    truth.start()
    capturing.wait()
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = to_descriptor_2
        load_map(a)
    truth.join()
    assert captured == []
    assert "a.yaml: names image 'b.png', not a.png" in capfd.readouterr().err


def test_image_with_resolution_only(tmp_path: Path) -> None:
    m = load_map(write_png(tmp_path / "m.pgm", TRINARY), resolution=0.5)
    assert m.grid.resolution == 0.5 and m.grid.origin == (0.0, 0.0, 0.0)
    np.testing.assert_array_equal(m.state, TRINARY_STATE)


def test_inputs_are_not_modified(tmp_path: Path) -> None:
    png = write_png(tmp_path / "map.png", TRINARY)
    yml = write_yaml(tmp_path / "map.yaml")
    before = {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in (png, yml)}
    load_map(yml)
    load_map(png, resolution=1.0)
    assert {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in (png, yml)} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.png", "map.yaml"]


# --- point clouds -------------------------------------------------------------------------------

CLOUD = np.array([[0.0, 1.0, 2.0], [1.5, -2.0, 0.25], [3.0, 4.0, -1.0]])


@pytest.mark.parametrize("suffix", [".ply", ".pcd"])
def test_open3d_round_trip(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"scan{suffix}"
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(CLOUD))
    assert o3d.io.write_point_cloud(str(path), cloud)
    m = load_map(path)
    assert isinstance(m, PointMap) and m.kind == "cloud" and m.is_3d
    np.testing.assert_allclose(m.points, CLOUD, atol=1e-6)


def test_text_cloud(tmp_path: Path) -> None:
    path = tmp_path / "scan.xyz"
    path.write_text("# x y z intensity\n0 1 2 9\n1.5,-2,0.25,9\n\n3\t4 -1 9  # last\nnan 0 0 1\n")
    m = load_map(path)
    assert m.points.dtype == np.float64 and m.is_3d
    np.testing.assert_allclose(m.points, CLOUD)


def test_two_column_text_is_2d(tmp_path: Path) -> None:
    path = tmp_path / "scan.txt"
    path.write_text("0, 1\n2, 3\n")
    m = load_map(path)
    assert not m.is_3d
    np.testing.assert_array_equal(m.points, [[0, 1, 0], [2, 3, 0]])


def test_flat_3d_cloud_is_2d_with_zero_z(tmp_path: Path) -> None:
    path = tmp_path / "flat.npy"
    np.save(path, np.array([[0.0, 1.0, 1.2], [2.0, 3.0, 1.2]]))
    m = load_map(path)
    assert not m.is_3d and np.all(m.points[:, 2] == 0.0)


@pytest.mark.parametrize("cols", [2, 3, 4])
def test_npy(tmp_path: Path, cols: int) -> None:
    table = np.arange(5 * cols, dtype=np.float32).reshape(5, cols)
    table[:, min(cols, 3) - 1] **= 1.5  # z (or y) not constant
    np.save(tmp_path / "scan.npy", table)
    m = load_map(tmp_path / "scan.npy")
    assert m.points.shape == (5, 3) and m.points.dtype == np.float64
    np.testing.assert_allclose(m.points[:, : min(cols, 3)], table[:, :3])
    assert m.is_3d == (cols >= 3)


def test_kitti_bin(tmp_path: Path) -> None:
    records = np.column_stack([CLOUD, [0.1, 0.2, 0.3]]).astype(np.float32)
    records[1, 0] = np.inf  # dropped
    records.tofile(tmp_path / "000000.bin")
    m = load_map(tmp_path / "000000.bin")
    np.testing.assert_allclose(m.points, CLOUD[[0, 2]], atol=1e-6)


# --- bad inputs ---------------------------------------------------------------------------------


def _garbage(path: Path) -> None:
    path.write_bytes(bytes(range(256)) * 3)


BAD_INPUTS = {
    "missing.png": lambda d: None,
    "garbage.png": lambda d: _garbage(d / "garbage.png"),
    "garbage.pgm": lambda d: _garbage(d / "garbage.pgm"),
    "nores.yaml": lambda d: (write_png(d / "map.png", TRINARY),
                             write_yaml(d / "nores.yaml", resolution=None)),
    "negres.yaml": lambda d: (write_png(d / "map.png", TRINARY),
                              write_yaml(d / "negres.yaml", resolution=-0.05)),
    "nanres.yaml": lambda d: (write_png(d / "map.png", TRINARY),
                              write_yaml(d / "nanres.yaml", resolution=".nan")),
    "badorigin.yaml": lambda d: (write_png(d / "map.png", TRINARY),
                                 write_yaml(d / "badorigin.yaml", origin=[1, 2, 3, 4])),
    "badmode.yaml": lambda d: (write_png(d / "map.png", TRINARY),
                               write_yaml(d / "badmode.yaml", mode="fancy")),
    "noimage.yaml": lambda d: write_yaml(d / "noimage.yaml", image="gone.png"),
    "syntax.yaml": lambda d: (d / "syntax.yaml").write_text("image: [unclosed\n"),
    "list.yaml": lambda d: (d / "list.yaml").write_text("- 1\n- 2\n"),
    "lonely.png": lambda d: write_png(d / "lonely.png", TRINARY),
    "short.bin": lambda d: (d / "short.bin").write_bytes(b"\0" * 20),
    "empty.bin": lambda d: (d / "empty.bin").write_bytes(b""),
    "empty.xyz": lambda d: (d / "empty.xyz").write_text("# only a comment\n"),
    "words.xyz": lambda d: (d / "words.xyz").write_text("x y z\n1 2 3\n"),
    "ragged.txt": lambda d: (d / "ragged.txt").write_text("1 2 3\n1 2\n"),
    "one.txt": lambda d: (d / "one.txt").write_text("1\n2\n"),
    "binary.xyz": lambda d: _garbage(d / "binary.xyz"),
    "garbage.ply": lambda d: _garbage(d / "garbage.ply"),
    "garbage.pcd": lambda d: _garbage(d / "garbage.pcd"),
    "garbage.npy": lambda d: _garbage(d / "garbage.npy"),
    "strings.npy": lambda d: np.save(d / "strings.npy", np.array([["a", "b", "c"]])),
    "flat.npy": lambda d: np.save(d / "flat.npy", np.arange(6.0)),
    "empty.npy": lambda d: np.save(d / "empty.npy", np.zeros((0, 3))),
    "foo.abc": lambda d: (d / "foo.abc").write_text("1 2 3\n"),
    "folder.ply": lambda d: (d / "folder.ply").mkdir(),
}


@pytest.mark.parametrize("name", sorted(BAD_INPUTS))
def test_bad_input_is_one_line_naming_the_file(tmp_path: Path, name: str) -> None:
    BAD_INPUTS[name](tmp_path)
    with pytest.raises(InputError) as info:
        load_map(tmp_path / name)
    message = str(info.value)
    assert name in message and "\n" not in message, message


@pytest.mark.parametrize(("name", "expected"), [
    ("missing.png", "missing.png: not found"),
    ("garbage.png", "garbage.png: cannot be read as an image"),
    ("nores.yaml", "nores.yaml: no 'resolution' key"),
    ("lonely.png", "lonely.png: no resolution: give --map-resolution or a YAML beside it"),
    ("empty.xyz", "empty.xyz: no points"),
    ("foo.abc", "foo.abc: unsupported format '.abc' (expected .png, .pgm, .jpg, .jpeg, .bmp, "
                ".yaml, .yml, .ply, .pcd, .xyz, .txt, .npy, .bin, .las, .laz, .e57, .log, "
                ".log.gz, .bag, .db3, .mcap, .mcap.zstd, .mcap.zst, .db3.zstd, .db3.zst, or a "
                "ROS 2 bag folder)"),
])
def test_bad_input_messages(tmp_path: Path, name: str, expected: str) -> None:
    BAD_INPUTS[name](tmp_path)
    with pytest.raises(InputError) as info:
        load_map(tmp_path / name)
    assert str(info.value).endswith(expected)


def test_bad_resolution_argument(tmp_path: Path) -> None:
    png = write_png(tmp_path / "map.png", TRINARY)
    for bad in (0.0, -1.0, float("inf")):
        with pytest.raises(InputError, match="map.png: 'resolution' must be"):
            load_map(png, resolution=bad)


# --- atomic writes ------------------------------------------------------------------------------


def test_write_atomic(tmp_path: Path) -> None:
    target = tmp_path / "out.json"
    write_atomic(target, "{}\n")
    write_atomic(target, b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask


@pytest.mark.parametrize("broken", ["replace", "fsync"])
def test_failed_write_keeps_old_content(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                        broken: str) -> None:
    target = tmp_path / "out.csv"
    target.write_text("old\n")

    def fail(*args: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(writers.os, broken, fail)
    with pytest.raises(InputError, match="out.csv: cannot write: No space left on device"):
        write_atomic(target, "new\n")
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]


def test_unwritable_destination(tmp_path: Path) -> None:
    target = tmp_path / "no" / "such" / "dir" / "out.json"
    with pytest.raises(InputError) as info:
        write_atomic(target, "x")
    assert str(info.value).startswith(f"{target}: cannot write: ")


def test_stderr_captures_in_threads_at_once_restore_descriptor_2():
    """The map and the truth are read on two threads: their captures take turns, each gets its
    own lines, and descriptor 2 ends where it started."""
    import os
    import threading
    import time

    from pcmapq.io.stderr import stderr_captured

    before = os.fstat(2)
    got: dict[int, list[str]] = {}

    def read(k: int) -> None:
        with stderr_captured() as lines:
            os.write(2, f"library says {k}\n".encode())
            time.sleep(0.01)
        got[k] = lines

    threads = [threading.Thread(target=read, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    after = os.fstat(2)
    assert (after.st_dev, after.st_ino) == (before.st_dev, before.st_ino)
    assert got == {k: [f"library says {k}"] for k in range(8)}


def test_map_saver_unknown_read_as_unknown(tmp_path: Path) -> None:
    """An image of map_saver's three values beside a trinary YAML with free_thresh 0.25 (as
    Nav2's map_saver wrote them): 205 reads as unknown, with a warning naming the file; given
    thresholds read it as map_server does (free), and so does an image with other greys."""
    from pcmapq.io.map_yaml import Thresholds

    write_png(tmp_path / "map.png", [[0, 205, 254, 254]])
    path = write_yaml(tmp_path / "map.yaml", mode="trinary", free_thresh=0.25)
    with pytest.warns(UserWarning, match=r"map\.yaml: free_thresh 0\.25 reads map_saver"):
        m = load_map(path)
    np.testing.assert_array_equal(m.state, [[OCCUPIED, UNKNOWN, FREE, FREE]])
    given = load_map(path, thresholds=Thresholds(free=0.25))
    np.testing.assert_array_equal(given.state, [[OCCUPIED, FREE, FREE, FREE]])
    write_png(tmp_path / "grey.png", [[0, 205, 254, 128]])
    grey = load_map(write_yaml(tmp_path / "grey.yaml", image="grey.png", free_thresh=0.25))
    np.testing.assert_array_equal(grey.state, [[OCCUPIED, FREE, FREE, UNKNOWN]])
