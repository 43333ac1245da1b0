"""Soak test (issue 12): many evaluations of varied inputs in one process through the Python
API (``pcmapq.evaluation.pipeline.evaluate``), cycled round-robin (the loop and its checks:
:mod:`testkit.soak`). Checks that every run's outcome equals the first run of its input
(the JSON the CLI writes, byte for byte; for an input that fails by design, the same exception
type and message), that the resident memory after the last round is within 10 % of that after
the first, and that threads and open file descriptors do not grow.

    python -m bench.soak [--runs 200] [--json out.json] [--data DIR]

Prints a markdown summary (the "Soak" section of docs/benchmarks.md); exits 1 when a check
fails. The real-data inputs come from ../shared/data and are left out, saying so, where it is
absent.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from pcmapq.core.errors import EvaluationError
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.settings import AlignmentConfig, Settings, SourceConfig
from testkit.drift import drifted, save_cloud
from testkit.soak import MAX_GROWTH, Input, Soak, rss_mb, soak, synthetic_inputs

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


def real_inputs(data: Path, folder: Path) -> list[Input]:
    """Small real cases of ../shared/data (a few seconds each): the Freiburg 079 SLAM map vs
    its plan (scale estimated, as docs/validation.md), the FHW CARMEN map from poses drifted
    by 0.5 % (seed 0) vs the log itself, and the Orebro log vs the ACES log (another place:
    refused, EvaluationError)."""
    plans, carmen = data / "floorplans", data / "carmen"
    fhw = carmen / "fhw-corrected.log.gz"
    poses, ranges, angles = read_flaser(fhw)
    drift = save_cloud(endpoints(drifted(poses, 0.005, 0), ranges, angles, DEFAULT_MAX_RANGE),
                       folder / "fhw_drift_0.5.npy")
    return [
        Input("Freiburg 079 map vs its plan", plans / "freiburg_building79.png",
              plans / "Freiburg79_scan.png",
              Settings(alignment=AlignmentConfig(scale=True),
                       truth=SourceConfig(resolution=0.05))),
        Input("CARMEN fhw drifted 0.5 % vs its log", drift, fhw),
        Input("CARMEN orebro vs aces (another place)", carmen / "orebro-corrected.log.gz",
              carmen / "aces-corrected.log.gz", fails_with=EvaluationError),
    ]


def markdown(got: Soak, data_note: str = "") -> str:
    """The soak's figures as the markdown of docs/benchmarks.md."""
    per = {name: [s for i, s in enumerate(got.seconds) if i % len(got.inputs) == k]
           for k, name in enumerate(got.inputs)}
    lines = ["| input | runs | s per run (median) | outcome |", "|---|---:|---:|---|"]
    for name, secs in per.items():
        first = got.first[name]
        kind = "result" if first.startswith("{") else first.split(":")[0]
        lines.append(f"| {name} | {len(secs)} | {float(np.median(secs)):.2f} | {kind} |")
    c = got.census
    fails = got.failures()
    lines += ["", f"{got.runs} evaluations, {len(got.inputs)} inputs round-robin "
              f"({got.rounds} full rounds), {sum(got.seconds):.0f} s. RSS in use (after "
              f"`gc.collect()` and `malloc_trim(0)`) after the first round "
              f"{got.rss_first_round():.0f} MB, after the last {got.rss_last_round():.0f} MB: "
              f"growth {100 * got.growth():+.1f} % (limit {100 * MAX_GROWTH:.0f} %); over all "
              f"runs {min(got.rss_mb):.0f}-{max(got.rss_mb):.0f} MB. RSS as the allocator left "
              f"it (before the trim): {min(got.raw_rss_mb):.0f}-{max(got.raw_rss_mb):.0f} MB, "
              f"{got.raw_rss_mb[len(got.inputs) - 1]:.0f} MB after the first round, "
              f"{got.raw_rss_mb[got.rounds * len(got.inputs) - 1]:.0f} MB after the last. "
              "Python threads "
              f"{c['start'].python_threads} / {c['first round'].python_threads} / "
              f"{c['end'].python_threads}, OS threads {c['start'].os_threads} / "
              f"{c['first round'].os_threads} / {c['end'].os_threads}, open file descriptors "
              f"{c['start'].fds} / {c['first round'].fds} / {c['end'].fds} (before the first "
              "run / after the first round / at the end). "
              + ("Every outcome equals its input's first." if not got.mismatches else
                 f"{len(got.mismatches)} outcomes differ from their input's first.")
              + (" " + data_note if data_note else ""),
              "", "Passed." if not fails else "Failed: " + "; ".join(fails) + "."]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.soak",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=200, help="evaluations (default: 200)")
    parser.add_argument("--json", type=Path, help="write the figures (every run's) here")
    parser.add_argument("--data", type=Path, default=DATA,
                        help="the shared data folder (default: %(default)s)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="pcmapq_soak_") as tmp:
        items = synthetic_inputs(Path(tmp))
        note = ""
        if args.data.is_dir():
            items += real_inputs(args.data, Path(tmp))
        else:
            note = f"{args.data} absent: real-data inputs left out."
            print(note, file=sys.stderr)

        def progress(i: int, item: Input, seconds: float) -> None:
            print(f"{i + 1}/{args.runs} {item.name}: {seconds:.2f} s, {rss_mb():.0f} MB "
                  f"in use",
                  file=sys.stderr, flush=True)

        got = soak(items, args.runs, progress)
    print(markdown(got, note))
    if args.json:
        args.json.write_text(json.dumps(got.summary(), indent=1) + "\n")
    return 1 if got.failures() else 0


if __name__ == "__main__":
    sys.exit(main())
