"""A commensurate lock that strains a slab is recorded in build.json and stated in the report."""

import json
import math
import re
from pathlib import Path

import pytest
from ase.io import read

from flatcontact.config.load import load_config
from flatcontact.report.html import render_html
from flatcontact.report.sections.build import (
    LOCK_STRAIN_NOTE_PERCENT,
    interface_section,
    lock_statement,
)
from flatcontact.stages.build import BuildInputs, build_stage
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_io import read_interface

EXAMPLES = Path(__file__).parents[2] / "examples"
HBN_ON_GRAPHENE = {
    "kind": "sheets",
    "sheet": "graphene",
    "stacking": "A",
    "slab2": {"sheet": "h-BN", "stacking": "A"},
}


def test_diamond_graphene_lock_strain_is_in_build_json_and_in_the_report(tmp_path):
    """The issue's case: H-diamond(111) against graphene, locked 1×1; graphene stretched by
    a_diamond/√2 / a_graphene − 1 (the diamond.cif lattice against graphene's 2.46 Å)."""
    cfg = load_config(EXAMPLES / "diamond111-h-graphene-airebo.yaml")
    build_stage(cfg, BuildInputs(), tmp_path / "build")
    build = json.loads((tmp_path / "build" / "build.json").read_text())
    match = build["recipe"]["match"]
    a_diamond = read(EXAMPLES / "structures" / "diamond.cif").cell.cellpar()[0]
    expected = 100 * (a_diamond / math.sqrt(2) / 2.46 - 1)  # ≈ 2.53 %
    assert match["kind"] == "coincidence"
    assert match["slab2_strain_percent"] == pytest.approx([expected, expected], abs=1e-4)
    assert match["slab1_strain_percent"] == pytest.approx([0.0, 0.0], abs=1e-9)
    atoms = read_interface(tmp_path / "build" / "interface.extxyz")
    section = interface_section(cfg, build, tmp_path / "build", atoms)
    html = re.sub(r'src="data:[^"]*"', "", render_html("lock", [section]))
    assert f"Commensurate lock, strain {expected:+.3g} % on slab 2 (graphene)" in html
    assert "limit of `flatcontact study approximants`" in html
    # the strain also stays in the paragraph on the coincidence cell
    assert f"slab 2 {expected:+.3g}, {expected:+.3g} %" in html


def test_lock_statement_names_every_slab_above_the_threshold_and_nothing_below():
    _, shared = build_interface({**HBN_ON_GRAPHENE, "match": {"strain_on": "both"}})
    text = lock_statement(shared)
    assert "+0.894 % on slab 1 (graphene)" in text and "-0.879 % on slab 2 (h-BN)" in text
    _, fine = build_interface(  # the 110-atom cell of the strain ladder: 0.046 % on h-BN
        {
            **HBN_ON_GRAPHENE,
            "match": {
                "max_atoms": 200,
                "slab1_supercell": [[4, 6], [-2, 4]],
                "slab2_supercell": [[6, 3], [3, 6]],
            },
        }
    )
    worst = max(map(abs, fine["recipe"]["match"]["slab2_strain_percent"]))
    assert 0 < worst < LOCK_STRAIN_NOTE_PERCENT and lock_statement(fine) is None
    _, twisted = build_interface({"kind": "sheets", "sheet": "graphene", "twist": [1, 2]})
    assert twisted["recipe"]["match"]["kind"] == "twist" and lock_statement(twisted) is None


def _registries(atoms, shared) -> int:
    """Distinct registries of slab 2's primitive cells on slab 1's lattice: positions of slab
    2's atoms modulo slab 1's primitive cell (from the cell and ``slab1_supercell``, rounded to
    1e-3), over the atoms per primitive cell of slab 2 (2 for graphene), counted on the atoms."""
    import numpy as np

    match = shared["recipe"].get("match") or {"slab1_supercell": [[1, 0], [0, 1]]}
    primitive = np.linalg.solve(np.asarray(match["slab1_supercell"], float), atoms.cell[:2, :2])
    top = atoms[atoms.positions[:, 2] > atoms.positions[:, 2].mean()]
    frac = np.linalg.solve(primitive.T, top.positions[:, :2].T).T
    keys = {tuple(np.round(f, 3) % 1.0) for f in np.round(frac % 1.0, 3)}
    return len(keys) // 2


@pytest.mark.parametrize(("twist", "cells"), [((1, 2), 7), ((2, 3), 19)])
def test_a_twist_cell_is_not_called_a_lock_in_one_registry(twist, cells, tmp_path):
    """A commensurate twist puts slab 2's atoms in N = m² + mn + n² registries of slab 1's
    lattice (counted here on the built atoms): the report says so instead of the 1×1 lock's
    "every atom climbs the same barrier", and the AB bilayer keeps that warning."""
    from flatcontact.report.sections.build import COMMENSURATE_WARNING, approximant_note
    from flatcontact.report.sections.experiment import lock_text

    m, n = twist
    assert cells == m * m + m * n + n * n
    atoms, shared = build_interface(
        {"kind": "sheets", "sheet": "graphene", "stacking": "A", "twist": list(twist)}
    )
    assert _registries(atoms, shared) == cells
    note = approximant_note(shared)
    assert f"twist of {cells} primitive cells" in note and f"{cells} different registries" in note
    assert "commensurate twist θ = " in lock_text(shared) and "no strain" in lock_text(shared)
    cfg = load_config(EXAMPLES / "passivated-tip-graphene-ab.yaml")
    notes = " ".join(interface_section(cfg, shared, tmp_path).notes)
    assert "different registries" in notes and "climbs the same barrier" not in notes
    ab_atoms, ab = build_interface({"kind": "sheets", "sheet": "graphene", "stacking": "AB"})
    assert _registries(ab_atoms, ab) == 1
    assert approximant_note(ab) is None
    assert interface_section(cfg, ab, tmp_path).notes == [COMMENSURATE_WARNING]
