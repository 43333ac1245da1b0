"""A drift ladder on real CARMEN logs (:mod:`testkit.drift`): does pcmapq rank maps by
how much their poses drifted?

    python -m bench.validation.drift LOG [LOG ...] [--levels 0,0.0005,...] [--seed 0]
        [--max-range 30] [--scans K]

Prints one markdown table per log, and the steps where a detector's f1 does not fall
(docs/validation.md's CARMEN section: :mod:`bench.validation.carmen`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pcmapq.io.carmen import DEFAULT_MAX_RANGE
from testkit.drift import DEFAULT_LEVELS, falls_text, ladder, markdown


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.validation.drift",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="+", type=Path)
    parser.add_argument("--levels", default=",".join(f"{v:g}" for v in DEFAULT_LEVELS),
                        help="drift levels, relative gain errors (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-range", type=float, default=DEFAULT_MAX_RANGE,
                        help="drop readings above this, metres (default: %(default)s)")
    parser.add_argument("--scans", type=int, default=None,
                        help="use only the first SCANS scans of each log (default: all)")
    args = parser.parse_args(argv)
    levels = tuple(float(v) for v in args.levels.split(","))
    for log in args.logs:
        print(f"\n### {log.name} (seed {args.seed}, max range {args.max_range:g} m)\n")
        rungs = ladder(log, levels, args.seed, args.max_range, scans=args.scans)
        print(markdown(rungs) + "\n\n" + falls_text(rungs), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
