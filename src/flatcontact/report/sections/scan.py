"""The report's section on the scan stage: grid, convergence, adhesion and the p(z), U(z) figure."""

from __future__ import annotations

from pathlib import Path

from flatcontact.foundation.layout import SCAN_FIGURE, png
from flatcontact.report.format import fmt, grouped_warnings
from flatcontact.report.html import Figure, Section, Table


def _symmetry_rows(scan: dict) -> list[tuple[str, str]]:
    """The reduced scan's rows: relaxed points and the shift-space group (none for a full scan
    or a ``scan.json`` written before irreducible registries)."""
    sym = scan.get("symmetry") or {}
    order = int(sym.get("order", 1))
    if order <= 1 or "computed_points" not in scan:
        return []
    if sym.get("computed_in_full"):
        how = "every point relaxed: the verification found the symmetry broken (see the notes)"
    else:
        how = f"{scan['computed_points']} relaxed, the others mapped by symmetry"
    return [("shift-space group order", str(order)), ("relaxed points", how)]


def scan_section(scan: dict, folder: Path) -> Section:
    """Section 2: the scan's counts, thicknesses and adhesion (``scan``: the scan stage's
    ``scan.json``), its notes and warnings, and its figure from ``folder``."""
    adh = scan.get("adhesion") or {}
    scan_rows = [
        ("grid points", f"{scan['points_done']} of {scan['points_total']}"),
        *_symmetry_rows(scan),
        ("converged", str(scan["converged"])),
        ("force calls (total)", str(scan["force_calls_total"])),
        ("thicknesses z (Å)", ", ".join(f"{z:.4f}" for z in scan["thickness_angstrom"])),
    ]
    for key, label in (
        ("equilibrium_thickness_angstrom", "z at p = 0 (Å)"),
        ("max_tension_gpa", "maximum tension (GPa)"),
        ("work_of_separation_j_per_m2", "work of separation, slabs apart vs zero load (J/m²)"),
        ("pull_off_work_j_per_m2", "probe pull-off work, energy (J/m², may open two gaps)"),
        ("pull_off_work_integral_j_per_m2", "probe pull-off work, −∫p dz (J/m²)"),
    ):
        if key in adh:
            scan_rows.append((label, fmt(adh[key])))
        if key == "work_of_separation_j_per_m2" and "work_of_separation_stacking" in adh:
            scan_rows.append(
                ("work of separation taken at", str(adh["work_of_separation_stacking"]))
            )
    return Section(
        "2. ISPES scan",
        tables=[Table(("quantity", "value"), scan_rows)],
        notes=grouped_warnings([*scan.get("notes", []), *scan.get("warnings", [])]),
        figures=[
            Figure(
                folder / png(SCAN_FIGURE),
                "p(z) and U(z) at every lateral shift: the load rises as the slabs are pressed together.",
            )
        ],
    )
