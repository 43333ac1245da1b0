"""Rooms: pcmapq's room segmentation against the IPA benchmark's ground-truth rooms (20 plans,
each plain and furnished), beside the published per-map results of ROSE² and MAORIS, and
against the hand-made room labels of three real robot maps of one office floor in Bonn."""

from __future__ import annotations

import re
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from pcmapq.core.cells import FREE
from pcmapq.core.grid import MetricGrid
from pcmapq.features import walls_of
from pcmapq.features.room_segmentation import Params, segment
from pcmapq.features.rooms import detect
from pcmapq.io import load_map
from pcmapq.match.rooms import match

from .common import Case, Record, Section, header, row

#: The benchmark's plans (rooms/README.md), nominally 0.05 m a pixel.
MAPS = ("lab_ipa", "lab_a_scan", "lab_b_scan", "lab_c_scan", "lab_d_scan", "lab_f_scan",
        "lab_intel", "Freiburg52_scan", "Freiburg79_scan", "Freiburg101_scan", "NLB",
        *(f"office_{c}" for c in "abcdefghi"))
RESOLUTION = 0.05
#: The benchmark's evaluation: free is grey > 250 in the ground truth (>= 250 in the maps),
#: rooms are its 8-connected regions of more than 100 pixels.
GT_FREE, MAP_FREE, GT_SMALLEST = 250, 250, 100
MIN_IOU = 0.5
#: The Bonn floor's maps (plans/bonn_youbot_tmcl/): map, its room labels (1-12; 0 walls, 205
#: unknown, 252-255 unlabelled free cells) and the labels' channel (None: grey).
BONN = (("FMap (reference)", "Faro/FMap.yaml", "Faro/FMapRoomSeg.png", None),
        ("GMap (robot, cluttered)", "GMap/GMap.yaml", "GMap/GMapRoomSeg.png", None),
        ("YouBotMap (robot)", "2021_10_27/YouBotMap.yaml", "2021_10_27/YouBotMapRoomSeg.png", 2))


def grey(path: Path) -> np.ndarray:
    """An image as OpenCV's greyscale reading (the benchmark's own)."""
    image = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if image is None:
        raise FileNotFoundError(path)
    return image


def truth_rooms(path: Path) -> np.ndarray:
    """The ground-truth rooms of a ``*_gt_segmentation.png`` as labels (0 none)."""
    free = (grey(path) > GT_FREE).view(np.uint8)
    n, label, stats, _ = cv2.connectedComponentsWithStats(free, connectivity=8)
    keep = stats[:, cv2.CC_STAT_AREA] > GT_SMALLEST
    keep[0] = False
    number = np.zeros(n, np.int32)
    number[keep] = np.arange(1, int(keep.sum()) + 1)
    return number[label]


@dataclass(frozen=True)
class Segmented:
    """One plan's segmentation against its ground truth."""

    name: str
    truth: int
    found: int
    precision_micro: float
    recall_micro: float
    precision_iou: float
    recall_iou: float
    precision_maoris: float
    recall_maoris: float
    seconds: float

    def summary(self) -> dict:
        return {"truth_rooms": self.truth, "rooms": self.found,
                "precision_micro": round(self.precision_micro, 6),
                "recall_micro": round(self.recall_micro, 6),
                "precision_iou50": round(self.precision_iou, 6),
                "recall_iou50": round(self.recall_iou, 6),
                "precision_maoris": round(self.precision_maoris, 6),
                "recall_maoris": round(self.recall_maoris, 6)}


def maoris_micro(truth: np.ndarray, found: np.ndarray) -> tuple[float, float]:
    """Precision and recall micro (fractions) as MAORIS's own evaluation computes them
    (``compare_images`` in its ``Evaluation.cpp``): only the cells both label count, and each
    room's share is a whole percent, rounded down."""
    both = (truth > 0) & (found > 0)
    overlap = np.zeros((truth.max() + 1, found.max() + 1), np.int64)
    np.add.at(overlap, (truth[both], found[both]), 1)
    overlap = overlap[1:, 1:]

    def mean_share(o: np.ndarray) -> float:
        size = o.sum(axis=1)
        return float(np.mean(100 * o.max(axis=1)[size > 0] // size[size > 0])) / 100

    return mean_share(overlap.T), mean_share(overlap)


def measure(data: Path, name: str, furnished: bool) -> Segmented:
    """Segment ``name`` (its furnished variant with ``furnished``) and score it the
    benchmark's way (each room's best overlap: micro means over rooms) and by rooms matched
    one to one at an IoU of at least 0.5."""
    folder = data / "rooms"
    image = grey(folder / f"{name}{'_furnitures' if furnished else ''}.png")
    start = time.perf_counter()
    found = segment(image >= MAP_FREE, RESOLUTION, Params()).labels
    seconds = time.perf_counter() - start
    truth = truth_rooms(folder / f"{name}_gt_segmentation.png")
    m = match(truth, found, MIN_IOU)
    t_cells = np.bincount(truth.ravel())[1:]
    f_cells = np.bincount(found.ravel(), minlength=m.overlap.shape[1] + 1)[1:]
    best_t = m.overlap.max(axis=1) / t_cells
    best_f = m.overlap.max(axis=0, initial=0) / np.maximum(f_cells, 1)
    return Segmented(name + (" (furnished)" if furnished else ""), len(t_cells),
                     len(f_cells), float(best_f.mean()), float(best_t.mean()),
                     m.matched / max(len(f_cells), 1), m.matched / len(t_cells),
                     *maoris_micro(truth, found), seconds)


@dataclass(frozen=True)
class Labelled:
    """One robot map's rooms against its hand-made labels."""

    name: str
    truth_status: tuple[str, ...]
    map_status: tuple[str, ...]
    seconds: float

    def summary(self) -> dict:
        return {"truth_status": list(self.truth_status), "map_status": list(self.map_status)}

    def count(self, statuses: tuple[str, ...], status: str) -> int:
        return sum(s == status for s in statuses)


def labelled(data: Path, name: str, map_file: str, labels_file: str,
             channel: int | None) -> Labelled:
    """Segment a Bonn map's free cells (as pcmapq reads the map with its YAML) and match its
    rooms to the hand-made labels."""
    folder = data / "plans" / "bonn_youbot_tmcl"
    loaded = load_map(folder / map_file)
    image = cv2.imread(str(folder / labels_file), cv2.IMREAD_UNCHANGED)
    if image.ndim == 3:
        image = image[:, :, 0 if channel is None else channel]
    truth = np.where((image >= 1) & (image <= 12), image, 0).astype(np.int32)
    start = time.perf_counter()
    found = segment(loaded.state == FREE, loaded.grid.resolution, Params()).labels
    seconds = time.perf_counter() - start
    m = match(truth, found, MIN_IOU)
    return Labelled(name, tuple(map(str, m.truth_status)), tuple(map(str, m.map_status)),
                    seconds)


@dataclass(frozen=True)
class Furnished(Labelled):
    """One IPA plan's furnished variant scored against its plain plan by the rooms detector."""


def furnished(data: Path, name: str) -> Furnished:
    """The rooms detector on a plan and on its furnished variant (each plan's obstacle cells,
    grey under 250, as the walls every detector sees), the furnished plan's rooms matched to
    the plain plan's one to one: the furniture is all that differs."""
    folder = data / "rooms"
    start = time.perf_counter()
    labels = []
    for suffix in ("", "_furnitures"):
        image = grey(folder / f"{name}{suffix}.png")
        grid = MetricGrid(RESOLUTION, (0.0, 0.0, 0.0), image.shape)
        labels.append(detect(walls_of(image < MAP_FREE, grid), Params()).labels)
    seconds = time.perf_counter() - start
    m = match(labels[0], labels[1], MIN_IOU)
    return Furnished(name, tuple(map(str, m.truth_status)), tuple(map(str, m.map_status)),
                     seconds)


def published(data: Path) -> dict[str, dict[str, tuple[float, float]]]:
    """Published per-map (precision, recall) micro, percent: ROSE² without and with furniture,
    MAORIS without.

    MAORIS's file gives, after the map's name, its recall and then its precision, as its own
    evaluation (:func:`maoris_micro`) computes them: the first figure is a mean of whole
    percents over the truth's rooms and the second over the segments. Times the plan's number
    of truth rooms, the first is a whole number on 14 of the 17 plans (lab_a_scan: 98.0652 x
    46 = 4511; the other three count their truth rooms otherwise), the second on 5.
    """
    folder = data / "rooms" / "third_party_results"
    out: dict[str, dict[str, tuple[float, float]]] = {}
    for method, file in (("ROSE²", "ROSE2_bormann_average_evaluation.txt"),
                         ("ROSE² (furnished)", "ROSE2_bormann_furnitures_average_evaluation.txt")):
        table = {}
        for line in (folder / file).read_text().splitlines():
            cells = [c.strip() for c in line.split("&")]
            name = cells[0].replace("\\_", "_").removesuffix("_furnitures")
            if name in MAPS and len(cells) >= 4:
                table[name] = (float(cells[1]), float(cells[3]))
        out[method] = table
    maoris = {}
    for line in (folder / "maoris_maorisRobotMap.dat").read_text().splitlines():
        parts = re.split(r"\s+", line.strip())
        if len(parts) >= 3 and parts[0] in MAPS:
            maoris[parts[0]] = (float(parts[2]), float(parts[1]))
    out["MAORIS"] = maoris
    return out


def cases(data: Path) -> list[Case]:
    return [Case(f"rooms-{name}{'-furnished' if furnished else ''}",
                 lambda name=name, furnished=furnished: measure(data, name, furnished))
            for furnished in (False, True) for name in MAPS] + \
        [Case(f"rooms-bonn-{file.split('/')[-1].split('.')[0].lower()}",
              lambda b=(name, file, labels, channel): labelled(data, *b))
         for name, file, labels, channel in BONN] + \
        [Case(f"rooms-furniture-{name}", lambda name=name: furnished(data, name))
         for name in MAPS]


def _f1(pairs: np.ndarray) -> np.ndarray:
    """Each plan's f1, the harmonic mean of its (precision, recall) row."""
    return 2 * pairs[:, 0] * pairs[:, 1] / (pairs[:, 0] + pairs[:, 1])


def _pct(value: float) -> str:
    return f"{100 * value:.1f}"


def section(data: Path, record: Record) -> Section:
    """Per plan, and on average beside the published methods on the same plans."""
    measured = [case.run(record) for case in cases(data)]
    runs = [m for m in measured if isinstance(m, Segmented)]
    bonn = [m for m in measured if type(m) is Labelled]
    furn = [m for m in measured if isinstance(m, Furnished)]
    statuses = ("matched", "merged", "split", "missing")
    furn_lines = [row([f.name, str(len(f.truth_status)),
                       *(str(f.count(f.truth_status, s)) for s in statuses),
                       str(f.count(f.map_status, "extra")),
                       f"{f.count(f.truth_status, 'matched') / len(f.truth_status):.3f}",
                       f"{f.seconds:.2f}"]) for f in furn]
    totals = [sum(f.count(f.truth_status, s) for f in furn) for s in statuses]
    truth_total = sum(len(f.truth_status) for f in furn)
    furn_lines.append(row(["**all**", str(truth_total), *map(str, totals),
                           str(sum(f.count(f.map_status, "extra") for f in furn)),
                           f"{totals[0] / truth_total:.3f}", ""]))
    bonn_lines = [row([b.name, str(len(b.truth_status)), str(len(b.map_status)),
                       *(str(b.count(b.truth_status, s)) for s in
                         ("matched", "merged", "split", "missing")),
                       str(b.count(b.map_status, "extra")), f"{b.seconds:.2f}"])
                  for b in bonn]
    others = published(data)
    lines = []
    for run in runs:
        lines.append(row([run.name, str(run.truth), str(run.found), _pct(run.precision_micro),
                          _pct(run.recall_micro), _pct(run.precision_iou),
                          _pct(run.recall_iou), f"{run.seconds:.2f}"]))
    compare = []
    for method, furnished, own in (("ROSE²", False, False), ("ROSE² (furnished)", True, False),
                                   ("MAORIS", False, True), ("MAORIS", False, False)):
        table = others[method]
        ours = [r for r in runs if r.name.endswith("(furnished)") == furnished
                and r.name.split(" ")[0] in table]
        theirs = np.array([table[r.name.split(" ")[0]] for r in ours])
        mine = 100 * np.array([(r.precision_maoris, r.recall_maoris) if own else
                               (r.precision_micro, r.recall_micro) for r in ours])
        compare.append(row([
            method, str(len(ours)), f"{theirs[:, 0].mean():.1f}", f"{theirs[:, 1].mean():.1f}",
            f"{_f1(theirs).mean():.1f}", "MAORIS's" if own else "the benchmark's",
            f"{mine[:, 0].mean():.1f}", f"{mine[:, 1].mean():.1f}", f"{_f1(mine).mean():.1f}"]))
    plain = [r for r in runs if not r.name.endswith("(furnished)")]
    furn = [r for r in runs if r.name.endswith("(furnished)")]
    averages = [row([label, _pct(np.mean([r.precision_micro for r in rs])),
                     _pct(np.mean([r.recall_micro for r in rs])),
                     _pct(np.mean([r.precision_iou for r in rs])),
                     _pct(np.mean([r.recall_iou for r in rs]))])
                for label, rs in (("plain", plain), ("furnished", furn))]
    return Section("\n".join([
        "## Rooms: the IPA room-segmentation benchmark", "",
        "`rooms/`: the 20 plans of Bormann et al. (ICRA 2016), each also with furniture, and "
        "their ground-truth rooms read the benchmark's way (grey above 250, 8-connected "
        "regions of more than 100 pixels; a furnished plan is scored against its plain "
        "plan's rooms). pcmapq segments each plan's free cells (grey 250 and above) at the "
        f"nominal {RESOLUTION} m a pixel with the rooms' default parameters "
        "(`pcmapq.features.rooms.Params`). **Precision / recall micro** are the benchmark's: "
        "the mean over found rooms of the share of each lying in its best-overlapping truth "
        "room, and the mean over truth rooms of the share of each covered by its best "
        "found room. **IoU 0.5** counts rooms matched one to one (Hungarian on IoU) at an IoU "
        "of at least 0.5: matched / found rooms and matched / truth rooms.", "",
        "On average:", "",
        header(["plans", "precision micro %", "recall micro %", "precision IoU 0.5 %",
                "recall IoU 0.5 %"]),
        *averages, "",
        "Beside the published per-map results (`rooms/third_party_results/`), averaged over "
        "the plans each method reports (f1: each plan's harmonic mean of its precision and "
        "recall micro, averaged). ROSE²'s tables give the benchmark's figures by name "
        "(precision and recall, micro and macro); MAORIS's come from its own "
        "(`compare_images` in its `Evaluation.cpp`), which counts only the cells both "
        "segmentations label and rounds each room's share down to a whole percent, "
        "so pcmapq is scored both ways beside it. MAORIS's file lists each plan's recall "
        "before its precision: the first figure is the mean over the truth's rooms.", "",
        header(["method", "plans", "its precision %", "its recall %", "its f1 %",
                "pcmapq scored by", "pcmapq precision %", "pcmapq recall %", "pcmapq f1 %"]),
        *compare, "",
        "### Real robot maps against hand-made room labels", "",
        "`plans/bonn_youbot_tmcl/`: one office floor, 12 rooms with the corridor, labelled "
        "by hand on each of three maps (a clean reference map and two gmapping maps of the "
        "robot, one cluttered with furniture). pcmapq reads each map with its YAML and "
        "segments its free cells; its rooms are matched to the labels one to one at an IoU "
        "of at least 0.5 (`pcmapq.match.rooms`), and every truth room gets its status.", "",
        header(["map", "truth rooms", "rooms", "matched", "merged", "split", "missing",
                "extra rooms", "s"]),
        *bonn_lines, "",
        "### Furniture a plan lacks", "",
        "Each IPA plan's furnished variant scored against the plain plan by the rooms "
        "detector, as `pcmapq eval` scores a map: both plans' obstacle cells (grey under 250) "
        "drawn as the walls every detector sees, their rooms found and matched one to one "
        "(`pcmapq.features.rooms`, `pcmapq.match.rooms`). Only the furniture differs, so every "
        "room not matched is one the furniture cut (split), hid or walled in; **quality** is "
        "the rooms detector's, matched / truth rooms.", "",
        header(["plan", "truth rooms", "matched", "merged", "split", "missing", "extra rooms",
                "quality", "s"]),
        *furn_lines, "",
        "### Each IPA plan", "",
        header(["plan", "truth rooms", "rooms", "precision micro %", "recall micro %",
                "precision IoU 0.5 %", "recall IoU 0.5 %", "s"]),
        *lines,
    ]))
