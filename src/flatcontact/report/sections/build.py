"""The report's section on the build stage: the interface, its relaxation and Fig. 1."""

from __future__ import annotations

from pathlib import Path

from ase import Atoms

from flatcontact.layout import BUILD_FIGURE, png
from flatcontact.report.format import fmt
from flatcontact.report.html import Figure, Section


def interface_material(atoms: Atoms) -> str:
    """The material of the run's interface (``info['material']`` of ``interface.extxyz``;
    its formula when the file names none)."""
    return str(atoms.info.get("material") or atoms.get_chemical_formula(mode="hill"))


def interface_section(cfg, build: dict, folder: Path) -> Section:
    """Section 1: atoms, thickness and relaxation of the interface (``build``: the build
    stage's ``build.json``) and Fig. 1 from ``folder``."""
    rel = build.get("interface_relaxation", {})
    checks = build.get("interface_verification") or {}
    verified = bool(checks) and all(v.get("dense") for v in checks.values())
    return Section(
        "1. Interface",
        paragraphs=[
            f"{build.get('n_atoms', '?')} atoms; reference thickness z = {fmt(build.get('thickness_angstrom'))} Å"
            + (
                f"; interface relaxation {'converged' if rel.get('converged') else 'NOT converged'}"
                f" in {rel.get('steps', '?')} steps to "
                f"{getattr(cfg.structure, 'fmax_ev_per_angstrom', float('nan')):g} eV/Å"
                if rel
                else ""
            )
            + (
                "; the dense surface verified on both slabs after the interface relaxation"
                if verified
                else ""
            )
            + ". Surfaces 1 and 4 (outer faces) are held fixed during the scan; surfaces 2, 3 and the "
            "inner atoms relax at every grid point.",
        ],
        figures=[
            Figure(
                folder / png(BUILD_FIGURE),
                "Fig. 1 style: side view and the top view of the inner face.",
            )
        ],
    )
