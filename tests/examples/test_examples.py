"""The example configurations (``examples/*.yaml``) against independent numbers.

Fast: every example loads as ``flatcontact config --check`` reads it and its model knows every
element of its interface; the graphene (REBO + KC) example's ISPES at one thickness equals, point
by point, a plain LAMMPS input written here (``tests/potentials/plain_lammps.py``: atoms by
``create_atoms``, molecule ids by ``set atom``, the pair commands verbatim) on the rigid geometry
built here from the interface file (slab 2 translated by the shift, its layer put at the
thickness); bad inputs are refused in one line naming the field before any work.

Slow (end to end, ``flatcontact run examples/NAME.yaml``): the 2D examples' named stacking
energies at P = 0 equal the plain-LAMMPS constant-load values (each stacking's rigid E(z)
minimised over z with scipy), symmetry-equivalent stackings are equal to round-off, and the
Cu(111) zero-load ISPES has the intrinsic stacking-fault energy of Mishin et al. (2001); the
H-terminated diamond(111)/graphene work of separation equals a plain-LAMMPS AIREBO energy
difference and its ISPES has the H over the hexagon centre at the minimum, over a C at the maxima.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from tests.potentials.plain_lammps import lammps_energy

from flatcontact.config import load_config
from flatcontact.foundation.errors import InputError
from flatcontact.potentials.lammps_runtime import lammps_potential_file

EXAMPLES = Path(__file__).parents[2] / "examples"
ALL = sorted(EXAMPLES.glob("*.yaml"))
MEV = 1000.0


def f(name: str) -> str:
    return str(lammps_potential_file(name))


# plain LAMMPS pair commands per example (types: one per element and layer, see _types)
KC = [
    "pair_style hybrid/overlay rebo kolmogorov/crespi/full 16.0 1",
    f"pair_coeff * * rebo {f('CH.rebo')} C C",
    f"pair_coeff * * kolmogorov/crespi/full {f('CH_taper.KC')} C C",
]
ILP = [
    "pair_style hybrid/overlay rebo ilp/graphene/hbn 16.0 1",
    f"pair_coeff * * rebo {f('CH.rebo')} C C",
    f"pair_coeff * * ilp/graphene/hbn {f('BNCH.ILP')} C C",
]
HBN = [  # LAMMPS example in.bilayer-hBN: Tersoff + ILP, shielded Coulomb across the layers
    "pair_style hybrid/overlay tersoff ilp/graphene/hbn 16.0 1 coul/shield 16.0 1",
    f"pair_coeff * * tersoff {f('BNC.tersoff')} B N B N",
    f"pair_coeff * * ilp/graphene/hbn {f('BNCH.ILP')} B N B N",
    "pair_coeff 1 3 coul/shield 0.70",
    "pair_coeff 1 4 coul/shield 0.69498201415576216335",
    "pair_coeff 2 3 coul/shield 0.69498201415576216335",
    "pair_coeff 2 4 coul/shield 0.69",
    "set type 1 charge 0.42",
    "set type 3 charge 0.42",
    "set type 2 charge -0.42",
    "set type 4 charge -0.42",
]
PLAIN = {
    "graphene-bilayer-kc": (KC, ("C",)),
    "graphene-bilayer-ilp": (ILP, ("C",)),
    "hbn-bilayer-ilp": (HBN, ("B", "N")),
}


def _types(atoms, order) -> list[int]:
    """LAMMPS type per atom: element index within ``order``, one set of types per layer."""
    layer = atoms.arrays["layer"]
    return [
        (int(k) - 1) * len(order) + order.index(s) + 1
        for k, s in zip(layer, atoms.get_chemical_symbols(), strict=True)
    ]


def rigid_geometry(reference, shift, thickness):
    """The reference bilayer with slab 2 translated by ``shift`` (fractions of a1, a2) and its
    layer's mean height put ``thickness`` above slab 1's (the interface contract's z)."""
    atoms = reference.copy()
    top = atoms.arrays["slab"] == 2
    cell = atoms.cell.array
    atoms.positions[top, :2] += np.asarray(shift) @ cell[:2, :2]
    z = atoms.positions[:, 2]
    atoms.positions[top, 2] += thickness - (z[top].mean() - z[~top].mean())
    return atoms


def plain_energy_per_area(reference, shift, thickness, name) -> float:
    commands, order = PLAIN[name]
    atoms = rigid_geometry(reference, shift, thickness)
    e = lammps_energy(atoms, _types(atoms, order), commands, list(atoms.arrays["layer"]))
    return e / abs(np.linalg.det(reference.cell.array[:2, :2]))


def _aa_shift(reference) -> np.ndarray:
    """The shift (fractions of a1, a2) that puts every slab-2 atom over a slab-1 atom of its
    element: the eclipsed (AA) registry, found from the geometry alone."""
    cell = reference.cell.array[:2, :2]
    top = reference.arrays["slab"] == 2
    sym = np.array(reference.get_chemical_symbols())
    p1, p2 = reference.positions[~top, :2], reference.positions[top, :2]
    for j in range(len(p1)):
        d = np.linalg.solve(cell.T, p1[j] - p2[0])
        moved = (np.linalg.solve(cell.T, p2.T).T + d) % 1.0
        target = np.linalg.solve(cell.T, p1.T).T % 1.0
        ok = all(
            any(
                sym[~top][m] == sym[top][i]
                and np.allclose((moved[i] - target[m] + 0.5) % 1.0 - 0.5, 0, atol=1e-6)
                for m in range(len(p1))
            )
            for i in range(len(p2))
        )
        if ok:
            return d % 1.0
    raise AssertionError("no eclipsed registry")


def _fractional(reference, vector_xy) -> np.ndarray:
    return np.linalg.solve(reference.cell.array[:2, :2].T, vector_xy) % 1.0


def _sp_shift(reference) -> np.ndarray:
    """The saddle (SP) registry: half the shortest step from AB to BA, the AA vector turned
    by 60° (AB, BA, AA form a triangular lattice of spacing a/√3 in translation space)."""
    aa = _aa_shift(reference)
    v = ((aa + 0.5) % 1.0 - 0.5) @ reference.cell.array[:2, :2]
    c, s = np.cos(np.pi / 3), np.sin(np.pi / 3)
    return _fractional(reference, 0.5 * np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]]))


# --------------------------------------------------------------------------- fast
@pytest.mark.parametrize("path", ALL, ids=[p.stem for p in ALL])
def test_every_example_loads_and_its_model_knows_its_elements(path):
    """``config --check`` semantics: valid, moduli source accepted, elements known."""
    from flatcontact.stages.contact import check_moduli_source
    from flatcontact.structures.construct import build_interface

    cfg = load_config(path)
    assert cfg.structure.kind in ("quartz-dense", "sheets", "fcc111", "crystal")
    if cfg.structure.kind == "quartz-dense":
        assert {"Si", "O"} <= set(cfg.potential.elements or {"Si", "O"})
        check_moduli_source(cfg)
        return
    atoms, _ = build_interface(cfg.structure)  # ideal geometry: no relaxation, no calculator
    cfg.potential.check_atoms(atoms)
    check_moduli_source(cfg, set(atoms.get_chemical_symbols()))
    assert atoms.info["material"]


def test_expected_examples_are_present():
    names = {p.stem for p in ALL}
    assert names >= {
        "graphene-bilayer-kc",
        "graphene-bilayer-ilp",
        "hbn-bilayer-ilp",
        "mos2-bilayer-ilp",
        "cu111-eam",
        "au111-cif-eam",
        "quartz-paper",
        "graphene-hbn-ilp",
        "diamond111-h-graphene-airebo",
    }


def test_quartz_example_is_the_default_run():
    assert load_config(EXAMPLES / "quartz-paper.yaml").to_dict() == load_config().to_dict()


def test_graphene_kc_ispes_equals_plain_lammps_point_by_point(tmp_path):
    """The scan stage's energies (6×6 grid, two thicknesses, rigid sheets) are the plain
    LAMMPS energies of the geometry built here, to round-off; AB = BA exactly."""
    from flatcontact.ispes.contract import open_ispes
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import ScanInputs, scan_stage

    cfg = load_config(EXAMPLES / "graphene-bilayer-kc.yaml")
    scan = cfg.scan.model_copy(
        update={"p_range_gpa": None, "thickness_angstrom": [3.3, 3.5], "executor": "serial"}
    )
    cfg = cfg.model_copy(update={"scan": scan})
    build_stage(cfg, BuildInputs(), tmp_path / "build")
    scan_stage(cfg, ScanInputs(tmp_path / "build" / "interface.extxyz"), tmp_path / "scan")
    from flatcontact.structures.interface_io import read_interface

    reference = read_interface(tmp_path / "build" / "interface.extxyz")
    ds = open_ispes(tmp_path / "scan" / "ispes.nc")
    area = float(ds.attrs["area"])
    e = ds["energy"].values / area
    for iz, z in enumerate(ds.thickness.values):
        plain = np.array(
            [
                [
                    plain_energy_per_area(reference, (sa, sb), z, "graphene-bilayer-kc")
                    for sb in ds.shift_b.values
                ]
                for sa in ds.shift_a.values
            ]
        )
        # absolute energies: same geometry, same potential -> round-off
        np.testing.assert_allclose(e[:, :, iz], plain, atol=1e-9, rtol=0)
    aa = np.rint(_aa_shift(reference) * 6).astype(int) % 6
    ba = (-aa) % 6  # the AA step reversed lands on BA (equivalent to AB by symmetry)
    for iz in range(e.shape[2]):
        assert e[ba[0], ba[1], iz] == pytest.approx(e[0, 0, iz], abs=1e-12)
        assert e[aa[0], aa[1], iz] - e[0, 0, iz] > 1e-4  # AA is repulsive (eV/Å²)


def _one_line(exc) -> str:
    text = str(exc.value)
    assert "\n" not in text and "Traceback" not in text
    return text


def test_element_the_potential_lacks_is_refused_before_any_work(tmp_path):
    from flatcontact.pipeline import Pipeline

    path = tmp_path / "c.yaml"
    path.write_text(
        "structure: {kind: sheets, sheet: h-BN}\npotential: {preset: graphene-rebo-kc}\n"
        "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30}\n"
    )
    cfg = load_config(path)
    with pytest.raises(InputError) as exc:
        Pipeline(cfg, tmp_path / "run").build()
    text = _one_line(exc)
    assert "B" in text and "graphene-rebo-kc" in text
    assert not (tmp_path / "run" / "02-scan").exists()


def test_miller_index_giving_no_slab_names_the_field(tmp_path):
    from ase.build import bulk

    from flatcontact.stages.build import BuildInputs, build_stage

    bulk("Cu", "fcc", a=3.615).write(tmp_path / "cu.cif")
    path = tmp_path / "c.yaml"
    path.write_text(
        "structure: {kind: crystal, bulk: cu.cif, miller: [0, 0, 0]}\n"
        "potential: {preset: cu-eam}\nelastic: {enabled: true}\n"
    )
    with pytest.raises(InputError) as exc:
        build_stage(load_config(path), BuildInputs(), None)
    assert "structure.miller" in _one_line(exc)


def test_hetero_pair_without_a_match_under_the_strain_bound_names_the_field(tmp_path):
    from flatcontact.stages.build import BuildInputs, build_stage

    path = tmp_path / "c.yaml"
    path.write_text(
        "structure: {kind: sheets, sheet: graphene, slab2: {sheet: h-BN}, "
        "match: {max_strain_percent: 0.5, max_atoms: 20}}\n"
        "potential: {preset: graphene-hbn-ilp}\n"
        "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30}\n"
    )
    with pytest.raises(InputError) as exc:
        build_stage(load_config(path), BuildInputs(), None)
    text = _one_line(exc)
    assert "structure.slab2" in text and "max_strain" in text and "0.5%" in text


def test_too_many_atoms_names_the_field(tmp_path):
    from flatcontact.stages.build import BuildInputs, build_stage

    path = tmp_path / "c.yaml"
    path.write_text(
        "structure: {kind: sheets, sheet: graphene, twist: [1, 2], match: {max_atoms: 10}}\n"
        "potential: {preset: graphene-rebo-kc}\n"
        "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30}\n"
    )
    with pytest.raises(InputError) as exc:
        build_stage(load_config(path), BuildInputs(), None)
    assert "max_atoms" in _one_line(exc)


def test_non_quartz_material_without_moduli_is_refused_before_any_work(tmp_path):
    from flatcontact.pipeline import Pipeline

    path = tmp_path / "c.yaml"
    path.write_text("structure: {kind: fcc111, element: Cu}\npotential: {preset: cu-eam}\n")
    cfg = load_config(path)
    with pytest.raises(InputError) as exc:
        Pipeline(cfg, tmp_path / "run")
    text = _one_line(exc)
    assert "contact.contact_modulus_gpa" in text and "elastic.enabled" in text
    assert not (tmp_path / "run" / "01-build").exists()
    # either source of moduli is accepted
    for extra in (
        "elastic: {enabled: true}\n",
        "contact: {contact_modulus_gpa: 120, shear_modulus_gpa: 80}\n",
    ):
        path.write_text(
            path.read_text().split("\n", 2)[0] + "\n" + "potential: {preset: cu-eam}\n" + extra
        )
        from flatcontact.stages.contact import check_moduli_source

        check_moduli_source(load_config(path))


# --------------------------------------------------------------------------- slow
def _run(name: str, out: Path) -> Path:
    from flatcontact.pipeline import run

    report = run(load_config(EXAMPLES / f"{name}.yaml"), out)
    assert report.name == "report.html" and report.is_file()
    return report.parent


def _stackings(csv: Path) -> dict[float, dict[str, float]]:
    import pandas as pd

    table = pd.read_csv(csv)
    out = {}
    for p, text in zip(table.p_gpa, table.stacking_energies_mev_per_a2, strict=True):
        out[float(p)] = {k: float(v) for k, v in (item.split("=") for item in text.split(";"))}
    return out


def _constant_load_zero(reference, shift, name, bracket) -> float:
    """Min over z of the plain-LAMMPS rigid E(z) (meV/Å²): the stacking's energy at P = 0."""
    from scipy.optimize import minimize_scalar

    res = minimize_scalar(
        lambda z: plain_energy_per_area(reference, shift, z, name),
        bounds=bracket,
        method="bounded",
        options={"xatol": 1e-5},
    )
    return res.fun * MEV


@pytest.mark.slow
@pytest.mark.parametrize("name", ["graphene-bilayer-kc", "graphene-bilayer-ilp"])
def test_graphene_run_stacking_energies_match_plain_lammps_at_zero_load(tmp_path, name):
    from flatcontact.structures.interface_io import read_interface

    root = _run(name, tmp_path / name)
    named = _stackings(root / "03-analyze" / "friction.csv")[0.0]
    reference = read_interface(root / "01-build" / "interface.extxyz")
    assert named["AB"] == pytest.approx(named["BA"], abs=1e-9)  # symmetry-equivalent
    bracket = (3.0, 4.0)
    ab = _constant_load_zero(reference, (0, 0), name, bracket)
    aa = _constant_load_zero(reference, _aa_shift(reference), name, bracket)
    sp = _constant_load_zero(reference, _sp_shift(reference), name, bracket)
    # the run interpolates E(z) over its thicknesses (measured: 2e-6 relative for KC)
    assert named["AA"] - named["AB"] == pytest.approx(aa - ab, rel=1e-3)
    assert named["SP"] - named["AB"] == pytest.approx(sp - ab, rel=1e-3)


@pytest.mark.slow
def test_cu111_gamma_surface_has_mishins_stacking_fault_energy(tmp_path):
    """Zero-load ISPES of Cu(111)/Cu(111) with the same EAM across: the minimum at the
    (1/3, 2/3)-type shift is the intrinsic stacking fault; Mishin et al. (2001) report
    γ_isf = 44.4 mJ/m² for this potential."""
    root = _run("cu111-eam", tmp_path / "cu")
    named = _stackings(root / "03-analyze" / "friction.csv")[0.0]
    energies = sorted(named.values())
    assert energies[0] == pytest.approx(0.0, abs=1e-9)
    # the second-lowest stationary stacking is the fault (the fcc perfect crystal is 0)
    isf_mj_per_m2 = energies[1] * 16.021766  # meV/Å² -> mJ/m²
    assert isf_mj_per_m2 == pytest.approx(44.4, rel=0.1)


def _ase_eam_stacking_energy_mev_per_a2(potential_file: str, a_angstrom: float, shift) -> float:
    """An fcc(111) stack of 8 planes (ASE's ``fcc111``, vacuum on both sides) whose upper four
    planes are shifted by ``shift`` (fractions of a1, a2), every atom relaxed along z only
    (ASE's own EAM calculator and BFGS, not LAMMPS), energy per area above the unshifted stack."""
    from ase.build import fcc111
    from ase.calculators.eam import EAM
    from ase.constraints import FixedLine
    from ase.optimize import BFGS

    def energy_per_area(frac):
        stack = fcc111("Au", size=(1, 1, 8), a=a_angstrom, vacuum=10.0, orthogonal=False)
        cell = stack.cell.array
        upper = stack.positions[:, 2] > stack.positions[:, 2].mean()
        stack.positions[upper, :2] += frac[0] * cell[0, :2] + frac[1] * cell[1, :2]
        stack.calc = EAM(potential=potential_file)
        stack.set_constraint([FixedLine(i, [0, 0, 1]) for i in range(len(stack))])
        BFGS(stack, logfile=None).run(fmax=1e-4)
        return stack.get_potential_energy() / np.linalg.norm(np.cross(cell[0], cell[1]))

    return (energy_per_area(shift) - energy_per_area((0.0, 0.0))) * MEV


@pytest.mark.slow
def test_au111_from_a_cif_has_the_stacking_energies_of_an_independent_ase_eam_stack(tmp_path):
    """The metal-from-a-CIF example end to end (automatic thicknesses, W from the relaxed
    slabs): its zero-load stackings equal an 8-plane Au(111) stack computed here with ASE's
    own EAM reader of the same ``Au_u3.eam`` (relaxed along z): the intrinsic stacking fault
    at (1/3, 1/3) and the on-top stacking at (2/3, 2/3). Measured: 0.2959 vs 0.2978 and
    34.511 vs 34.479 meV/Å² (the run holds its outer planes; the stack relaxes them)."""
    root = _run("au111-cif-eam", tmp_path / "au")
    named = _stackings(root / "03-analyze" / "friction.csv")[0.0]
    pot = f("Au_u3.eam")
    # the slabs are cut at the EAM's own lattice (structure.lattice: potential), not the CIF's
    build = json.loads((root / "01-build" / "build.json").read_text())
    a = build["lattice"]["slabs"]["slab1"]["in_plane_potential_angstrom"][0] * np.sqrt(2.0)
    isf = _ase_eam_stacking_energy_mev_per_a2(pot, a, (1 / 3, 1 / 3))
    on_top = _ase_eam_stacking_energy_mev_per_a2(pot, a, (2 / 3, 2 / 3))
    assert min(named.values()) == pytest.approx(0.0, abs=1e-9)
    assert named["BA"] == pytest.approx(isf, rel=0.02)
    assert named["AA"] == pytest.approx(on_top, rel=0.005)
    scan = json.loads((root / "02-scan" / "scan.json").read_text())
    # the ideal work of separation of a bonded metal is 2γ(111) > 0, never 0 or 4γ
    assert 1.0 < scan["adhesion"]["work_of_separation_j_per_m2"] < 2.0
    html = (root / "report.html").read_text()
    assert "intrinsic stacking fault" in html


def test_build_cli_takes_a_monolayer_slab_file_and_a_config(tmp_path):
    """`build --structure graphene_1L --potential graphene-rebo-kc`: the slab recipe finds the
    single layer, tags it as both faces (2 / 3) and holds it; `build --config` builds a
    recipe."""
    from ase.build import graphene
    from typer.testing import CliRunner

    from flatcontact.cli.app import app
    from flatcontact.structures.interface_io import read_interface

    graphene(a=2.46, vacuum=5.0).write(tmp_path / "g.extxyz")
    runner = CliRunner()
    args = ["build", "--structure", str(tmp_path / "g.extxyz"), "--potential", "graphene-rebo-kc"]
    result = runner.invoke(app, [*args, "--no-svg", "--out", str(tmp_path / "b")])
    assert result.exit_code == 0, result.output
    atoms = read_interface(tmp_path / "b" / "interface.extxyz")
    assert list(atoms.arrays["surface"]) == [2, 2, 3, 3]
    assert atoms.arrays["held"].all() and list(atoms.arrays["layer"]) == [1, 1, 2, 2]
    config = EXAMPLES / "cu111-eam.yaml"
    result = runner.invoke(app, ["build", "--config", str(config), "--out", str(tmp_path / "c")])
    assert result.exit_code == 0, result.output
    cu = read_interface(tmp_path / "c" / "interface.extxyz")
    assert cu.info["material"].startswith("Cu") and len(cu) == 8


def _lateral_distance_to_carbon(reference, shift) -> float:
    """Lateral distance (Å) from slab 1's H to the nearest C of slab 2 moved by ``shift``."""
    cell = reference.cell.array[:2, :2]
    sym = np.array(reference.get_chemical_symbols())
    top = reference.arrays["slab"] == 2
    h = reference.positions[(sym == "H") & ~top][0, :2]
    carbons = reference.positions[top, :2] + np.asarray(shift) @ cell
    frac = np.linalg.solve(cell.T, (carbons - h).T).T
    frac = (frac + 0.5) % 1.0 - 0.5
    return float(np.linalg.norm(frac @ cell, axis=1).min())


@pytest.mark.slow
def test_h_diamond_on_graphene_adhesion_and_registries(tmp_path):
    """``run examples/diamond111-h-graphene-airebo.yaml``: W equals E(slab 1) + E(slab 2) −
    E(interface) of a plain LAMMPS AIREBO input on the built interface (rigid; the tool relaxes
    each part, measured 0.3 % apart), at a van der Waals scale (graphite's interlayer binding is
    0.2–0.4 J/m²); at the zero-load thickness the ISPES minimum puts the H over the hexagon centre
    (a/√3 from every C) and the maxima put it over a C of either sublattice, equal by symmetry
    (the held sheet is rigid, the diamond relaxes along z); τ positive at every load."""
    import pandas as pd

    from flatcontact.ispes.contract import open_ispes
    from flatcontact.structures.interface_io import read_interface

    root = _run("diamond111-h-graphene-airebo", tmp_path / "ch")
    reference = read_interface(root / "01-build" / "interface.extxyz")
    ds = open_ispes(root / "02-scan" / "ispes.nc")
    area = float(ds.attrs["area"])
    commands = ["pair_style airebo 3.0 1 1", f"pair_coeff * * {f('CH.airebo')} C H"]
    slab = reference.arrays["slab"]

    def energy(atoms):
        types = [1 if s == "C" else 2 for s in atoms.get_chemical_symbols()]
        return lammps_energy(atoms, types, commands, ntypes=2)

    plain_w = energy(reference[slab == 1]) + energy(reference[slab == 2]) - energy(reference)
    plain_w_j_per_m2 = plain_w / area * 16.0217663
    w = float(ds.attrs["work_of_separation_j_per_m2"])
    assert w == pytest.approx(plain_w_j_per_m2, rel=0.02)
    assert 0.05 < w < 0.5
    iz = int(np.argmin(np.abs(ds.thickness.values - ds.attrs["equilibrium_thickness_angstrom"])))
    e = ds["energy"].values[:, :, iz]
    a = float(np.linalg.norm(reference.cell.array[0]))
    shifts = [(sa, sb) for sa in ds.shift_a.values for sb in ds.shift_b.values]
    dist = np.array([_lateral_distance_to_carbon(reference, sh) for sh in shifts])
    flat = e.ravel()
    assert dist[np.argmin(flat)] == pytest.approx(a / np.sqrt(3.0), abs=1e-6)  # hollow
    atop = np.isclose(dist, 0.0, atol=1e-6)
    assert atop.sum() == 2  # over a C of each sublattice
    assert atop[np.argmax(flat)]  # the highest point is over a C
    barrier = flat[atop] - flat.min()
    assert barrier[0] == pytest.approx(barrier[1], rel=0.01)
    table = pd.read_csv(root / "03-analyze" / "friction.csv")
    assert (table.tau_mpa > 0).all() and (table.tau_mpa < 1000).all()
    # the example's enthalpy form: a cobblestone contact (the H rides up over the saddle), so
    # dτ/dP = π Δz*/a of the sinusoidal barrier, Δz* the saddle's gap above the minimum's
    # (docs/analysis.md); measured 151 against 145-152 MPa/GPa. No gate fires.
    summary = json.loads((root / "06-contact" / "summary.json").read_text())
    assert summary["gates"]["fired"] == []
    import xarray as xr

    from flatcontact.analysis.periodic import PeriodicSurface

    with xr.open_dataset(root / "03-analyze" / "friction.nc", engine="h5netcdf") as fr:
        kinds = list(fr["stacking_kind"].values)
        m, sp = kinds.index("minimum"), kinds.index("saddle")
        dz = []
        for i in range(fr.sizes["p_gpa"]):
            gap = PeriodicSurface(fr["thickness_at_p"].values[i], fr.attrs["a1"], fr.attrs["a2"])
            xy = np.stack([fr["stacking_x"].values[i], fr["stacking_y"].values[i]], -1)
            dz.append(float(gap(xy[sp]) - gap(xy[m])))
    laws = json.loads((root / "04-laws" / "laws.json").read_text())
    assert laws["energy_form"] == "enthalpy"
    assert laws["k_mpa_per_gpa"] == pytest.approx(1000 * np.pi * np.mean(dz) / a, rel=0.05)
