"""The report's summary: material, model, settings, conventions and the stages of the run."""

from __future__ import annotations

from flatcontact.report.html import Section, Table
from flatcontact.report.sections.build import plural


def summary_section(
    cfg, material: str, model: str, scan: dict, stage_rows: list[tuple[str, str, str, str]]
) -> Section:
    """The summary: ``material`` and the interaction ``model``'s label, the structure,
    preset, grid (``scan``: the scan stage's ``scan.json``) and loads of ``cfg``, and the
    table of ``stage_rows`` (stage, state, seconds, finished)."""
    return Section(
        "Summary",
        paragraphs=[
            f"Material: {material}. Interaction model: {model}. Structure: "
            f"{cfg.structure.kind}"
            + (
                f", {plural(int(cfg.structure.layers), 'layer')} per slab"
                if getattr(cfg.structure, "layers", None) is not None
                else ""
            )
            + f". Preset: {cfg.preset}. ISPES grid {cfg.scan.grid[0]}×{cfg.scan.grid[1]} lateral × "
            f"{len(scan['thickness_angstrom'])} thicknesses. Loads analysed: "
            + ", ".join(f"{p:g}" for p in cfg.analysis.p_gpa)
            + " GPa.",
            "Conventions: P > 0 is compression; z is the distance between surfaces 1 and 4; energies per "
            "area in meV/Å²; stresses in MPa; the contact model uses the paper's q0 = G*·u/(πa) "
            "(G* = 4 × Johnson's G*_J).",
        ],
        tables=[
            Table(
                ("stage", "state", "seconds (last run)", "finished (UTC)"),
                stage_rows,
                "Stages of this run directory",
            )
        ],
    )
