"""Measure the validation on ../shared/data: print its sections, write docs/validation.md, or
compare every case with its stored reference.

    python -m bench.validation [--only SECTION]... [--data DIR] [--check] [--write]
        [--save-references]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from testkit import reference

from .common import DATA, Record
from .document import DOC, SECTIONS, write, write_one


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.validation",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=SECTIONS, action="append",
                        help="this section only; repeated, these sections, in this order")
    parser.add_argument("--data", type=Path, default=DATA,
                        help="the shared data folder (default: %(default)s)")
    parser.add_argument("--check", action="store_true",
                        help="compare every case run with its stored reference; exit 1 if any "
                        "differs")
    parser.add_argument("--write", action="store_true",
                        help=f"write {DOC.relative_to(DOC.parents[1])} whole; with --only, that "
                        "section in place")
    parser.add_argument("--save-references", action="store_true",
                        help="store the figures of every case run as its reference")
    args = parser.parse_args(argv)
    if not args.data.is_dir():
        print(f"{args.data}: absent (real data lives in ../shared/data)", file=sys.stderr)
        return 2
    record: Record = {}
    sections = []
    for name in args.only or SECTIONS:
        start = time.perf_counter()
        sections.append(SECTIONS[name].section(args.data, record))
        print(f"{name}: {time.perf_counter() - start:.0f} s", file=sys.stderr, flush=True)
        if not (args.write or args.check):  # each section as soon as it is measured
            print(("\n" if len(sections) > 1 else "") + sections[-1].text, flush=True)
    if args.write and args.only:
        for name, section in zip(args.only, sections, strict=True):
            write_one(name, section)
    elif args.write:
        write(sections)
    if args.save_references:
        reference.store(record)
    if args.check:
        found = [d for case, figures in record.items() for d in reference.compare(case, figures)]
        print("\n".join(found) if found else f"{len(record)} cases equal their references")
        return 1 if found else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
