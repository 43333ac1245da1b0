"""Comments and docs say what the code does and why, not a lab notebook's history: no run's
timings or memory peaks in the package's comments and docstrings, no data set named as the
evidence for a choice (the measurements live in docs/validation.md and docs/benchmarks.md), and
the user docs cite the paper by its reference, not by a path users do not have."""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "src" / "pcmapq"
#: Packages whose comments are being rewritten on their own.
PENDING = ("cli", "settings", "testing", "track")
#: What a lab notebook's line looks like: a measured size or time set against another, a
#: peak, a speed-up, a timing in parentheses, a result on a named data set.
NOTEBOOK = [r"\d(\.\d+)? ?(ms|s|kB|MB|GB)\b[^.;]{0,40}\bagainst \d", r"\bmeasured on [A-Z]",
            r"\bpeak(s|ed)? (at )?(under )?\d", r"\braised the peak\b",
            r"\b(Intel|FHW|fr079|Freiburg 079)\b", r"(?<![`\w])\d+(\.\d+)? ?(ms|s)\)",
            r"\btimes (faster|slower)\b", r"\b\d+ to \d+ times\b"]


def texts(path: Path) -> list[tuple[int, str]]:
    """The comments and the longer string constants (docstrings) of a module, by line."""
    source = path.read_text()
    found = [(t.start[0], t.string) for t in
             tokenize.generate_tokens(io.StringIO(source).readline) if t.type == tokenize.COMMENT]
    found += [(n.lineno, n.value) for n in ast.walk(ast.parse(source))
              if isinstance(n, ast.Constant) and isinstance(n.value, str) and len(n.value) > 30]
    return found


def modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py")
                  if p.relative_to(PACKAGE).parts[0] not in PENDING)


@pytest.mark.unit
def test_comments_hold_no_measurements():
    found = [f"{path.relative_to(REPO)}:{line}: {' '.join(text.split())[:120]}"
             for path in modules() for line, text in texts(path)
             if any(re.search(p, " ".join(text.split())) for p in NOTEBOOK)]
    assert not found, "\n".join(found)


@pytest.mark.unit
def test_the_docs_cite_the_paper_by_its_reference():
    pages = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
    assert not [p.name for p in pages if "shared/paper" in p.read_text()]
    for page in (REPO / "README.md", REPO / "docs" / "method.md"):
        assert '"Map Quality Assessment"' in " ".join(page.read_text().split()), page
