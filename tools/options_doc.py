"""Write the settings options of every command page (docs/commands/*.md) from the option
table, the figures' names in docs/ci.md from the table of figures, and the result's JSON
Schema (docs/result.schema.json) from its models: ``python tools/options_doc.py``.
tests/unit/settings/test_option_table.py and tests/unit/results/test_schema.py check they are
current."""

from __future__ import annotations

from pathlib import Path

from pcmapq.report.docs_tables import update
from pcmapq.results.schema import schema_text

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = [*sorted((DOCS / "commands").glob("*.md")), DOCS / "ci.md"]
SCHEMA = DOCS / "result.schema.json"

if __name__ == "__main__":
    for page in PAGES:
        text = page.read_text()
        if update(text) != text:
            page.write_text(update(text))
            print(f"wrote {page}")
    if not SCHEMA.exists() or SCHEMA.read_text() != schema_text():
        SCHEMA.write_text(schema_text())
        print(f"wrote {SCHEMA}")
