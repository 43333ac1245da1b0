"""Run the ratio benchmarks (:mod:`bench.ratios`) and print their table.

    python -m bench [--only noref,kitti,clouds,campus,structures,peer3d,large3d] [--repeat 2]
                    [--check] [--save] [--doc] [--cache DIR]

--check: exit 1 when a ratio is worse than its stored one (bench/ratios.json) by more
than 20 %. --save: store the ratios measured. --doc: write them into docs/benchmarks.md's
table (the rows of ratios this run does not measure are kept). The cases of ``OPT_IN``
(large3d50: many minutes a run) run only when named.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from bench.ratios import CASES, OPT_IN, compare, table

ROOT = Path(__file__).resolve().parents[1]
STORED = ROOT / "bench" / "ratios.json"
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- ratios -->", "<!-- /ratios -->"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=",".join(c for c in CASES if c not in OPT_IN),
                        help=f"cases, comma-separated (run only when named: {', '.join(OPT_IN)})")
    parser.add_argument("--repeat", type=int, default=2, help="runs of each side (best kept)")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--save", action="store_true")
    parser.add_argument("--doc", action="store_true")
    parser.add_argument("--cache", type=Path, default=Path("/tmp/pcmapq-bench"))
    args = parser.parse_args()
    unknown = set(args.only.split(",")) - set(CASES)
    if unknown:
        parser.error(f"unknown cases {sorted(unknown)}; choose from {list(CASES)}")
    args.cache.mkdir(parents=True, exist_ok=True)
    found = []
    for name in args.only.split(","):
        found += CASES[name](args.cache, args.repeat)
        print(table(found), file=sys.stderr, flush=True)
    print(table(found))
    stored = json.loads(STORED.read_text()) if STORED.exists() else {}
    if args.save:
        stored.update({r.name: round(r.value, 3) for r in found})
        STORED.write_text(json.dumps(dict(sorted(stored.items())), indent=1) + "\n")
    if args.doc:
        text = DOC.read_text()
        head, rest = text.split(BEGIN, 1)
        shown, tail = rest.split(END, 1)
        DOC.write_text(head + BEGIN + "\n" + table(found, shown) + "\n" + END + tail)
    if args.check:
        worse = compare(found, stored)
        print("\n".join(worse) if worse else f"{len(found)} ratios within 20 % of those stored")
        return 1 if worse else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
