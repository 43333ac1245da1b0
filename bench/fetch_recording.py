"""Download a small public ROS recording of a 2D SLAM run (and its ground-truth map) and list its
topics, for trying pcmapq on a real recording. Standard library + rosbags only.

    python bench/fetch_recording.py [--out DIR] [--name NAME] [--list]

DIR defaults to ../shared/recordings when ../shared is writable, else /tmp/pcmapq-recordings.
Each file is checked against its size and checksum (SHA-256, or the MD5 its upstream CMake
file gives) and skipped when already there and correct.

Recordings (``--name``; default ``willow-stage``):

``willow-stage`` - the Willow Garage office in the Stage simulator, the amcl test recording.
    ``basic_localization_stage_indexed.bag`` (ROS 1), from
    http://download.ros.org/data/amcl/basic_localization_stage_indexed.bag; the MD5 comes from
    ros-planning/navigation amcl/CMakeLists.txt (catkin_download_test_data). It has a
    Hokuyo-like ``/base_scan`` (sensor_msgs/LaserScan, 1081 beams, 270 deg, 30 m) and ``/tf``
    (odom -> base_link -> base_laser), as third-party code describes it (not checked here).
    It has no /map, and maybe no nav_msgs/Odometry topic.
    Ground truth: ``willow-full.pgm``, the bitmap Stage simulated the laser against
    (ros-simulation/stage_ros world/willow-full.pgm, BSD). It is 540 x 587 px; willow-erratic.world
    sizes it 54.0 x 58.7 m, so 0.1 m per pixel. amcl's test serves it at 0.1 too. This script
    writes ``willow-full.yaml`` beside it: resolution 0.1, origin (0, 0). The pgm is grey-level
    (GIMP anti-aliased); map_server's thresholds apply.
    Licence: the bag is Willow Garage test data of the navigation stack (BSD; amcl LGPL-2.1).
    No data licence is stated. The world bitmap is BSD (stage_ros package.xml).

        pcmapq info DIR/willow-stage/basic_localization_stage_indexed.bag
        pcmapq map  DIR/willow-stage/basic_localization_stage_indexed.bag --scan-topic /base_scan \\
            --out out/willow_kiss.ply --tum-out out/willow_kiss.tum            # KISS-ICP poses
        pcmapq eval out/willow_kiss.ply DIR/willow-stage/willow-full.yaml --json out/willow.json
        pcmapq track DIR/willow-stage/basic_localization_stage_indexed.bag \\
            DIR/willow-stage/willow-full.yaml --out out/willow_track/
      and, if ``pcmapq info`` lists an Odometry topic (Stage publishes /odom and
      /base_pose_ground_truth):
        pcmapq map ... --scan-topic /base_scan --pose-topic /base_pose_ground_truth --out out/gt.ply

``turtlebot`` - a real TurtleBot 2 (Kinect fake laser) recording, gmapping's test bag.
    https://github.com/ros-perception/slam_gmapping_test_data (test_turtlebot.bag, 3.0 MB,
    27.5 s). ``/scan`` LaserScan (819 scans, 640 beams, 57 deg, 10 m) and ``/tf`` (map -> odom ->
    base_footprint). No Odometry topic, no /map, no ground truth. Checked here: opened with
    rosbags; its MD5 matches slam_gmapping's CMakeLists.txt. No licence is stated in that
    repository (slam_gmapping is BSD).

        pcmapq info DIR/turtlebot/test_turtlebot.bag
        pcmapq map DIR/turtlebot/test_turtlebot.bag --out out/tb.ply --tum-out out/tb.tum
        pcmapq inspect out/tb.ply           # no-reference figures only: there is no truth

``replay-crash`` - gmapping's 5 s test bag with ``/odom``, ``/scan`` (381 beams) and ``/tf``,
    0.19 MB. It is the smallest real recording here with a nav_msgs/Odometry topic. Same source
    and licence as ``turtlebot``.

        pcmapq map DIR/replay-crash/test_replay_crash.bag --scan-topic /scan --pose-topic /odom \\
            --out out/crash.ply
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import urllib.request
from dataclasses import dataclass
from pathlib import Path

STAGE_ROS = ("https://raw.githubusercontent.com/ros-simulation/stage_ros/"
             "c3abc19b9e9713fe450597ca33b6f5399d1691ca/world/")
GMAPPING_DATA = ("https://raw.githubusercontent.com/ros-perception/slam_gmapping_test_data/"
                 "611eef354ec9560def9adda19eb20e72c7512e78/")

#: map_server YAML for Stage's willow-full.pgm: 540 x 587 px over 54.0 x 58.7 m.
WILLOW_YAML = """image: willow-full.pgm
resolution: 0.1
origin: [0.0, 0.0, 0.0]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196
"""


@dataclass(frozen=True)
class Remote:
    """One file to download: where from, and what it must be (any of size, SHA-256, MD5)."""

    name: str
    url: str
    size: int | None = None
    sha256: str | None = None
    md5: str | None = None


CATALOGUE: dict[str, tuple[list[Remote], dict[str, str]]] = {
    "willow-stage": (
        [Remote("basic_localization_stage_indexed.bag",
                "http://download.ros.org/data/amcl/basic_localization_stage_indexed.bag",
                md5="41fe43af189ec71e5e48eb9ed661a655"),
         Remote("willow-full.pgm", STAGE_ROS + "willow-full.pgm", size=317018,
                sha256="6ca11ef810d13d981dca36fd6592114a1abb4225008ba7affc549243b2cc5d2f")],
        {"willow-full.yaml": WILLOW_YAML},
    ),
    "turtlebot": (
        [Remote("test_turtlebot.bag", GMAPPING_DATA + "test_turtlebot.bag", size=3003517,
                sha256="131eb17214cf0358147dfbd57b9d311190cd861b4c028a27533a9f9fc0a4f348")],
        {},
    ),
    "replay-crash": (
        [Remote("test_replay_crash.bag", GMAPPING_DATA + "test_replay_crash.bag", size=191247,
                sha256="38cc527fc1996e062105997fd0403dda555244a2b8af02b38aa153d175724cce")],
        {},
    ),
}


def default_out() -> Path:
    """../shared/recordings from the project root when ../shared is writable, else /tmp."""
    shared = Path(__file__).resolve().parents[1].parent / "shared"
    if shared.is_dir() and _writable(shared):
        return shared / "recordings"
    return Path("/tmp/pcmapq-recordings")


def _writable(folder: Path) -> bool:
    probe = folder / ".pcmapq-write-probe"
    try:
        probe.touch()
        probe.unlink()
    except OSError:
        return False
    return True


def problem(path: Path, remote: Remote) -> str | None:
    """Why ``path`` is not ``remote`` (size or checksum), or None when it is."""
    size = path.stat().st_size
    if remote.size is not None and size != remote.size:
        return f"{size} bytes, expected {remote.size}"
    for algo, want in (("sha256", remote.sha256), ("md5", remote.md5)):
        if want:
            digest = hashlib.new(algo)
            with path.open("rb") as handle:
                for block in iter(lambda: handle.read(1 << 20), b""):
                    digest.update(block)
            if digest.hexdigest() != want:
                return f"{algo} {digest.hexdigest()}, expected {want}"
    return None


def download(remote: Remote, folder: Path) -> Path:
    """``remote`` in ``folder``, downloaded unless already there and correct."""
    path = folder / remote.name
    if path.is_file() and problem(path, remote) is None:
        print(f"have {path}")
        return path
    part = path.with_name(path.name + ".part")
    print(f"downloading {remote.url}")
    request = urllib.request.Request(remote.url, headers={"User-Agent": "pcmapq-fetch"})
    with urllib.request.urlopen(request, timeout=60) as response, part.open("wb") as out:
        total = int(response.headers.get("Content-Length") or 0)
        done = 0
        for block in iter(lambda: response.read(1 << 20), b""):
            out.write(block)
            done += len(block)
            if total:
                print(f"\r  {done / 1e6:.1f} / {total / 1e6:.1f} MB", end="", file=sys.stderr)
        print(file=sys.stderr)
    why = problem(part, remote)
    if why is not None:
        raise RuntimeError(f"{remote.url}: {why} (kept as {part})")
    part.replace(path)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    print(f"wrote {path}: {path.stat().st_size} bytes, sha256 {digest}")
    return path


def print_topics(path: Path) -> None:
    """A recording's topics, types, counts and span, as rosbags reads them."""
    try:
        from rosbags.highlevel import AnyReader
    except ImportError:
        print("  (install rosbags to list the topics: pip install rosbags)")
        return
    with AnyReader([path]) as reader:
        print(f"{path.name}: {reader.duration / 1e9:.1f} s")
        for conn in sorted(reader.connections, key=lambda c: c.topic):
            print(f"  {conn.topic}: {conn.msgtype}, {conn.msgcount} messages")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=None,
                        help="folder for the recordings (default: ../shared/recordings if "
                             "writable, else /tmp/pcmapq-recordings)")
    parser.add_argument("--name", choices=sorted(CATALOGUE), default="willow-stage",
                        help="which recording (default: willow-stage)")
    parser.add_argument("--list", action="store_true", help="list the recordings and exit")
    args = parser.parse_args(argv)
    if args.list:
        for name, (remotes, _) in CATALOGUE.items():
            print(name + ": " + ", ".join(r.url for r in remotes))
        return 0
    remotes, extra = CATALOGUE[args.name]
    folder = (args.out or default_out()) / args.name
    folder.mkdir(parents=True, exist_ok=True)
    try:
        paths = [download(remote, folder) for remote in remotes]
    except (OSError, RuntimeError) as exc:  # urllib's errors are OSErrors
        print(f"error: {exc}", file=sys.stderr)
        return 1
    for name, text in extra.items():
        (folder / name).write_text(text)
        print(f"wrote {folder / name}")
    for path in paths:
        if path.suffix in (".bag", ".db3", ".mcap"):
            print_topics(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
