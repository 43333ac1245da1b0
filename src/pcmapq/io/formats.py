"""The loaders' registry of file suffixes, in one place: each loader reads its suffixes from
here, and the command line's help, the unsupported-format message and the docs are written from
it, so no list of formats can go stale. Imports nothing: ``pcmapq eval --help`` reads it
without loading a loader."""

from __future__ import annotations

#: Occupancy images (map_server's formats) and their map_server YAML.
IMAGE_SUFFIXES = (".png", ".pgm", ".jpg", ".jpeg", ".bmp")
YAML_SUFFIXES = (".yaml", ".yml")
#: Point clouds: PLY, PCD, text (x y z per line), NumPy arrays, KITTI's float32 .bin.
POINT_SUFFIXES = (".ply", ".pcd", ".xyz", ".txt", ".npy", ".bin")
#: Survey clouds: LAS and LAZ (laspy), E57 (pye57).
LAS_SUFFIXES, E57_SUFFIXES = (".las", ".laz"), (".e57",)
#: Every cloud suffix ``load_map`` reads.
CLOUD_SUFFIXES = POINT_SUFFIXES + LAS_SUFFIXES + E57_SUFFIXES
#: CARMEN laser logs (file name endings, lower case).
CARMEN_SUFFIXES = (".log", ".log.gz")
#: ROS recordings: ROS 1 bags, ROS 2 storage files (alone or in their bag folder), MCAP.
BAG_SUFFIXES = (".bag", ".db3", ".mcap")
#: ROS 2 storage files compressed whole with zstd (rosbag2's file compression, or ``zstd
#: FILE``), read from a decompressed copy (:mod:`pcmapq.io.bag_files`).
COMPRESSED_SUFFIXES = tuple(f"{storage}{zstd}" for storage in (".mcap", ".db3")
                            for zstd in (".zstd", ".zst"))
#: The scan files of a scan folder (``--scans``, ``pcmapq map``).
SCAN_SUFFIXES = (".bin", ".ply", ".pcd", ".npy")

#: Each kind of map input as a user names it, with its suffixes, in the order help lists them.
MAP_KINDS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("image", IMAGE_SUFFIXES),
    ("map_server YAML", YAML_SUFFIXES),
    ("cloud", POINT_SUFFIXES),
    ("LAS/LAZ", LAS_SUFFIXES),
    ("E57", E57_SUFFIXES),
    ("CARMEN log", CARMEN_SUFFIXES),
    ("ROS recording", BAG_SUFFIXES + COMPRESSED_SUFFIXES),
)
#: Every suffix ``load_map`` reads, in :data:`MAP_KINDS`' order.
MAP_SUFFIXES = tuple(s for _, suffixes in MAP_KINDS for s in suffixes)
#: What a ROS 2 bag is besides its files.
BAG_FOLDER = "a ROS 2 bag folder"


def map_formats() -> str:
    """Every map format, for help and messages: ``image (.png/.pgm/...), ..., ROS recording
    (.bag/.db3/.mcap, or a ROS 2 bag folder)``."""
    parts = [f"{kind} ({'/'.join(suffixes)}" + (f", or {BAG_FOLDER})" if kind == "ROS recording"
                                                else ")")
             for kind, suffixes in MAP_KINDS]
    return ", ".join(parts)


def scan_formats() -> str:
    """A scan folder's formats, for help: ``.bin/.ply/.pcd/.npy``."""
    return "/".join(SCAN_SUFFIXES)
