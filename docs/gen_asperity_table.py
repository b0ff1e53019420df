"""Rewrite docs/asperity.md's measured table from the stored runs (docs/measured/asperity/).

    python docs/gen_asperity_table.py          # rewrites the table in docs/asperity.md
    python docs/gen_asperity_table.py --check  # exit 1 if the page's table is stale

Each case folder holds the run's ``asperity.json``, its ``config.yaml`` and ``wall.txt``
(the wall time of the run); the table is one row per folder
(:func:`flatcontact.report.sections.asperity.measured_row`), cylinders then spheres, each by
interface and radius. ``tests/asperity/test_docs_measured.py`` fails when the page is stale.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent
PAGE = ROOT / "asperity.md"
MEASURED = ROOT / "measured" / "asperity"
#: folder prefix -> the row's label, in the table's order
CASES = {
    "cu-lj-R": "Cu(111), LJ across",
    "cu-eam-R": "Cu(111), EAM across (bonded)",
    "cu-lj-sphere-R": "Cu(111), LJ across",
}
BEGIN = "<!-- measured table: python docs/gen_asperity_table.py -->"
END = "<!-- end of the measured table -->"


def folders() -> list[tuple[str, Path]]:
    """(label, folder) of every stored case, in the table's order."""
    out = []
    for prefix, label in CASES.items():
        found = [p for p in MEASURED.glob(f"{prefix}*") if p.name[len(prefix) :].isdigit()]
        out += [(label, p) for p in sorted(found, key=lambda p: int(p.name[len(prefix) :]))]
    return out


def render() -> str:
    """The table, between its markers."""
    from flatcontact.report.sections.asperity import markdown_table, measured_row

    rows = []
    for label, folder in folders():
        doc = json.loads((folder / "asperity.json").read_text())
        wall = float((folder / "wall.txt").read_text().split()[0])
        rows.append(measured_row(label, doc, wall))
    return f"{BEGIN}\n{markdown_table(rows)}\n{END}"


def page_with_table(text: str) -> str:
    """``text`` with the block between the markers replaced by :func:`render`."""
    start, stop = text.index(BEGIN), text.index(END) + len(END)
    return text[:start] + render() + text[stop:]


if __name__ == "__main__":
    text = PAGE.read_text(encoding="utf-8")
    new = page_with_table(text)
    if "--check" in sys.argv[1:]:
        sys.exit(0 if new == text else 1)
    PAGE.write_text(new, encoding="utf-8")
