"""Where a source checkout keeps what tests and benchmarks read: the shipped sample, the stored
references (``tests/reference``) and the real data of ``../shared/data``. testkit lives in the
checkout, not in the installed package (tests/, bench/ and tools/ import it from the checkout's
root), so these are the checkout's folders."""

from __future__ import annotations

from pathlib import Path

#: The checkout: this file is testkit/paths.py in it.
REPO = Path(__file__).resolve().parents[1]
#: The shipped sample: scan.ply, truth.png and truth.yaml.
SAMPLE = REPO / "data" / "sample"
#: Stored references: the sample's result (sample.json) and the validation's cases.
REFERENCES = REPO / "tests" / "reference"
#: The real data sets, beside the checkout (absent on a machine without them).
SHARED_DATA = REPO.parent / "shared" / "data"


def shared(*parts: str) -> Path:
    """A file of ../shared/data, or skip the calling test saying it is absent."""
    import pytest  # a test's helper: pytest is there when a test calls it

    path = SHARED_DATA.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"{path} is absent (real data lives in ../shared/data)")
    return path
