"""Automatic thicknesses on interfaces nobody tuned the tool for (issue 20), end to end
through ``flatcontact run``: Au(111) from a CIF with the wheel's ``Au_u3.eam``, and
diamond(111) against graphite(0001) with AIREBO in ``normal`` and ``full`` relaxation."""

import json
import re

import numpy as np
import pytest
from ase.build import bulk
from ase.io import write
from ase.lattice.hexagonal import Graphite
from tests.cli.cli_helpers import run_cli

from flatcontact.ispes.thicknesses import MIN_THICKNESS_SPACING_ANGSTROM

pytestmark = pytest.mark.slow
MODULI = "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30}\n"
#: Au(111) with Au_u3 and the default slabs: τ falls with load (k = -53.5 MPa/GPa, the whole
#: interval below 0, measured), which the negative_slope gate stops before the contact stage;
#: this test is about the thicknesses, so it lets the run through to the report.
MODULI_ACCEPT = (
    "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30, "
    "accept_untrusted: [negative_slope]}\n"
)


def _run(tmp_path, capsys, config_text, contact=MODULI):
    config = tmp_path / "run.yaml"
    config.write_text(config_text + contact)
    out = tmp_path / "out"
    code, _, err = run_cli(["run", str(config), "--out", str(out)], capsys)
    scan = json.loads((out / "02-scan" / "scan.json").read_text())
    return code, err, out, scan


def _analysis_brackets(out, loads):
    """Every requested load inside every column's branch, read independently from
    ispes.nc with the analysis's own inversion."""
    from flatcontact.analysis.constant_pressure import invert_columns
    from flatcontact.foundation.units import EV_PER_A3_TO_GPA
    from flatcontact.ispes.contract import open_ispes

    ds = open_ispes(out / "02-scan" / "ispes.nc")
    z = ds.thickness.values
    area = float(ds.attrs["area"])
    e = ds.energy.values.reshape(-1, z.size) / area
    s = ds.normal_stress.values.reshape(-1, z.size) / EV_PER_A3_TO_GPA
    inv = invert_columns(z, e, s, np.asarray(loads) / EV_PER_A3_TO_GPA)
    assert np.all(np.isfinite(inv.thickness_angstrom))
    return z


def test_au111_from_a_cif_with_au_u3_runs_with_automatic_thicknesses(tmp_path, capsys):
    """The issue's failure: two thicknesses 0.0047 Å apart (p rose between them), then
    P = 0 outside the data (0.0043 .. 4.39 GPa). Now: spacing >= the minimum, a grid
    column short of P = 0 gets a thickness beyond, and the run reaches the report."""
    write(tmp_path / "Au.cif", bulk("Au", "fcc", a=4.08, cubic=True))
    code, err, out, scan = _run(
        tmp_path,
        capsys,
        f"structure: {{kind: crystal, bulk: {tmp_path / 'Au.cif'}, miller: [1, 1, 1]}}\n"
        "potential: {intra: {pair_style: eam, pair_coeff: [Au_u3.eam], map_elements: false}, "
        "coupling: same}\n"
        "scan: {p_range_gpa: {lo_gpa: 0, hi_gpa: 2, n: 4}, relax_mode: normal}\n"
        "analysis: {p_gpa: [0.0, 0.5, 1.0, 1.5, 2.0]}\n",
        MODULI_ACCEPT,
    )
    assert code in (0, None), err
    z = np.asarray(scan["thickness_angstrom"])
    assert np.all(np.diff(z) >= MIN_THICKNESS_SPACING_ANGSTROM)
    assert scan["load_folds"] == []
    _analysis_brackets(out, [0.0, 0.5, 1.0, 1.5, 2.0])
    assert scan["adhesion"]["work_of_separation_j_per_m2"] > 0
    assert (out / "report.html").is_file()


def _diamond_graphite(tmp_path, mode, structure="lattice: file"):
    """Diamond(111) on graphite(0001) at the files' lattices (``lattice: file``): the 1×1 lock
    (graphite +2.53 %) the tests were written for. At AIREBO's own lattices (the default since
    ``structure.lattice: potential``) the pair is a 152-atom coincidence cell (12 diamond
    cells on 13 graphite cells): its build relaxation breaks the shift-lattice periodicity and
    the scan refuses it (as it should: :func:`test_the_coincidence_cell_built_unrelaxed_runs`),
    and built unrelaxed it is near-incommensurate (no fold in ``full``)."""
    write(tmp_path / "diamond.cif", bulk("C", "diamond", a=3.567, cubic=True))
    write(tmp_path / "graphite.cif", Graphite("C", latticeconstant={"a": 2.46, "c": 6.70}))
    return (
        "structure: {kind: crystal, "
        f"bulk: {tmp_path / 'diamond.cif'}, miller: [1, 1, 1], layers: 2, "
        f"slab2: {{bulk: {tmp_path / 'graphite.cif'}, miller: [0, 0, 1], layers: 2}}, "
        f"{structure}}}\n"
        "potential: {intra: {pair_style: airebo 3.0 1 1, pair_coeff: [CH.airebo, C], "
        "map_elements: false}, coupling: same}\n"
        f"scan: {{grid: [6, 6], p_range_gpa: {{lo_gpa: 0, hi_gpa: 2, n: 4}}, relax_mode: {mode}}}\n"
        "analysis: {p_gpa: [0.0, 0.5, 1.0, 1.5]}\n"
    )


def test_diamond_graphite_normal_runs_with_automatic_thicknesses(tmp_path, capsys):
    """Main stopped at the probe (p(z) not monotonic: a second tensile well at -1.44 GPa);
    the branch that carries P = 0 is read, lo_gpa stays 0, and the run completes."""
    code, err, out, scan = _run(tmp_path, capsys, _diamond_graphite(tmp_path, "normal"))
    assert code in (0, None), err
    assert scan["load_folds"] == []
    _analysis_brackets(out, [0.0, 0.5, 1.0, 1.5])
    assert (out / "report.html").is_file()


def test_diamond_graphite_full_names_the_fold_and_refuses_the_loads_beyond(tmp_path, capsys):
    """Full relaxation folds in the grid (a column's load jumps up with z where a plane
    slips): scan.json names the column, z and p and the requested loads above it, or, where
    the scan stage's re-relaxation at fmax/10 removed every fold (with the preconditioned
    relaxation, the default since 2026-11-29: 6 grid columns, 0 left), says how many it
    re-relaxed away."""
    _, _, _, scan = _run(tmp_path, capsys, _diamond_graphite(tmp_path, "full"))
    folds = scan["load_folds"]
    handled = re.findall(r"(\d+) grid column fold\(s\) re-relaxed away", " ".join(scan["notes"]))
    assert folds or (handled and int(handled[0]) > 0), scan["notes"]
    for fold in folds:
        assert set(fold) == {"column", "z_angstrom", "p_gpa", "loads_refused_gpa"}
        assert "column at shift" in fold["column"]
        assert all(p > fold["p_gpa"] for p in fold["loads_refused_gpa"])
    # the notes say it too: a fold's own line (column, p and z), or, after the scan stage
    # re-relaxed some folding columns (stages/fold_remedy.py), how many remain where
    grid = sum("grid column" in f["column"] for f in folds)
    assert any(
        ("folds: p =" in n and "z =" in n)
        or f"re-relaxed away; {grid} remain (scan.json load_folds" in n
        for n in scan["notes"]
    ), scan["notes"]


def test_the_coincidence_cell_built_unrelaxed_runs(tmp_path, capsys):
    """At AIREBO's lattices the pair is a coincidence cell whose landscape repeats on a shift
    lattice of index 156 (= 12 × 13); 156 shares factors with 6, so the scan takes the
    coprime 7 × 7 grid over the cell and re-indexes it onto one period. Built relaxed, the
    scan refuses the cell before any point (its slabs repeat only to within 0.25 Å); built
    unrelaxed, as that refusal advises, it runs through the analysis (the run's own grid
    checks expected 6 × 6 and refused the 7 × 7 landscape before). The near-incommensurate
    landscape is flat enough that the slider's rest site wanders with load, so the
    degenerate_minima gate is let through, and its laws are so small that the adhesive
    tension would dominate them (the Hertz radius is used): this test is about the grid."""
    relaxed = tmp_path / "relaxed"
    relaxed.mkdir()
    code, _, err = run_cli(
        ["run", str(_config(relaxed, "lattice: potential")), "--out", str(relaxed / "out")],
        capsys,
    )
    assert code not in (0, None)
    assert "repeats 12 times in the supercell to within 0.25 Å but 1 times" in err
    assert "build the cell unrelaxed" in err
    unrelaxed = tmp_path / "unrelaxed"
    unrelaxed.mkdir()
    code, err, out, scan = _run(
        unrelaxed,
        capsys,
        _diamond_graphite(unrelaxed, "normal", "fmax_ev_per_angstrom: 10.0"),
        "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30, contact_radius: hertz, "
        "accept_untrusted: [degenerate_minima]}\n",
    )
    assert code in (0, None), err
    record = scan["shift_lattice"]
    assert record["index"] == 156 and record["grid_requested"] == [6, 6]
    assert record["grid"] == [7, 7]
    assert scan["points_total"] == 49 * len(scan["thickness_angstrom"])
    _analysis_brackets(out, [0.0, 0.5, 1.0, 1.5])
    assert (out / "report.html").is_file()


def _config(folder, structure):
    config = folder / "run.yaml"
    config.write_text(_diamond_graphite(folder, "normal", structure) + MODULI)
    return config
