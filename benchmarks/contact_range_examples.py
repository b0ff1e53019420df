"""The contact's range for every example: adhesion regime and the size of concurrent slip.

``python -m benchmarks.contact_range_examples RUNS_DIR`` reads ``RUNS_DIR/NAME/06-contact/
summary.json`` of every run under RUNS_DIR (made with ``flatcontact run examples/NAME.yaml
--out RUNS_DIR/NAME``) and prints the markdown table of examples/README.md's section "The
contact's range": per example the structure kind, γ_us and b of the sliding path, the Tabor
parameter and adhesion regime, and at each p0 the contact radius a against the critical size
(a_c, commensurate; a_el, twisted/approximant) with the regime the example's 5 µm tip is in.
Nothing is recomputed: the numbers are the runs' own.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def row(name: str, summary: dict) -> str:
    """One markdown row of the table from a run's contact ``summary.json``."""
    adh = summary.get("adhesion_regime") or {}
    slip = summary.get("slip_size") or {}
    res = adh.get("results") or []
    regimes = "/".join(dict.fromkeys(r["regime"] for r in res)) or "—"
    pull = ", ".join(f"{r['pull_off_over_load']:.3g}" for r in res) or "—"
    tabor = adh.get("tabor_parameter")
    z0 = adh.get("equilibrium_separation_angstrom")
    if not slip:
        return f"| {name} | — | — | — | {tabor:.3g} ({z0:.3g} Å) | {regimes} | {pull} | — | — |"
    sizes = "; ".join(
        f"{r['p0_gpa']:g}: {r['contact_radius_nm']:.0f} / {r['critical_radius_nm']:.3g}"
        for r in slip["results"]
    )
    verdict = ", ".join(
        (
            f"size-limited ({r['size_limited_strength_mpa']:.3g} of {r['concurrent_strength_mpa']:.3g} MPa)"
            if r["exceeded"] and r["size_limited_strength_mpa"] is not None
            else "past a_el (lower bound)"
            if r["exceeded"]
            else "concurrent"
        )
        for r in slip["results"]
    )
    gus = slip.get("unstable_stacking_j_m2")
    b = slip.get("burgers_angstrom")
    return (
        f"| {name} | {slip['structure']} | {1e3 * gus:.3g} | {b:.3g} | {tabor:.3g} ({z0:.3g} Å) | "
        f"{regimes} | {pull} | {sizes} | {verdict} |"
    )


HEADER = (
    "| example | structure | γ_us (mJ/m²) | b (Å) | Tabor μ_T (z0) | adhesion regime | "
    "pull-off / load | p0 (GPa): a / critical size (nm) | 5 µm tip |\n"
    "|---|---|---|---|---|---|---|---|---|"
)


def main(runs: Path) -> None:
    print(HEADER)
    for summary in sorted(runs.glob("*/06-contact/summary.json")):
        print(row(summary.parent.parent.name, json.loads(summary.read_text())))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
