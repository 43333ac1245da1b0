"""Write the settings options of every command page (docs/commands/*.md) from the option
table, and the figures' names in docs/ci.md from the table of figures:
``python tools/options_doc.py``. tests/unit/settings/test_option_table.py checks they are
current."""

from __future__ import annotations

from pathlib import Path

from pcmapq.report.docs_tables import update

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = [*sorted((DOCS / "commands").glob("*.md")), DOCS / "ci.md"]

if __name__ == "__main__":
    for page in PAGES:
        text = page.read_text()
        if update(text) != text:
            page.write_text(update(text))
            print(f"wrote {page}")
