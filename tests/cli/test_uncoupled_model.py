"""A per-slab model with ``coupling: none`` is refused before any work: its two slabs do not
interact, so every stacking has the same energy and no load between them (a flat ISPES, τ = 0).

The refusal is checked against the physics it claims: with such a model the interface's energy
is the same at every lateral shift of slab 2 and slab 2 feels no net normal force, while an ASE
calculator over the whole interface (whose ``coupling: none`` only says it sees both slabs)
corrugates the energy and keeps working through ``config --check``.
"""

from __future__ import annotations

import numpy as np
import pytest
from ase.build import fcc111
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact import notebook
from flatcontact.foundation.errors import InputError
from flatcontact.potentials.engines import make_calculator
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.assemble import make_interface

EMT = "ase.calculators.emt:EMT"
CU = "structure: {kind: fcc111, element: Cu, layers: 3}\n"
MODULI = "contact: {contact_modulus_gpa: 70, shear_modulus_gpa: 40}\n"
PER_SLAB_EMT = {"calculator": {"target": EMT, "scope": "slab"}, "coupling": "none"}


@pytest.fixture(scope="module")
def interface():
    slab = fcc111("Cu", size=(1, 1, 3), a=3.59, orthogonal=False, periodic=True)
    return make_interface(slab, gap_angstrom=2.1, face_atoms=1)


def _shifted(interface, frac_a: float, frac_b: float):
    atoms = interface.copy()
    atoms.positions[atoms.arrays["slab"] == 2] += frac_a * atoms.cell[0] + frac_b * atoms.cell[1]
    return atoms


def _energy_and_load(model: InteractionModel, atoms) -> tuple[float, float]:
    """Energy (eV) and net z-force on slab 2 (eV/Å) of ``atoms`` with ``model``."""
    atoms.calc = make_calculator(model, atoms)
    energy = atoms.get_potential_energy()
    return energy, float(atoms.get_forces()[atoms.arrays["slab"] == 2, 2].sum())


def test_the_refused_model_is_flat_and_the_whole_interface_calculator_is_not(interface):
    """The property the refusal rests on, computed: per-slab EMT with nothing across gives the
    same energy at three stackings (to round-off) and no load; EMT over the whole interface at
    the same 2.1 Å gap differs between stackings by far more and presses the slabs."""
    flat = InteractionModel(**PER_SLAB_EMT)
    whole = InteractionModel(calculator={"target": EMT})
    assert (flat.couples_slabs, whole.couples_slabs) == (False, True)
    assert whole.coupling == "none"  # the calculator's: it sees both slabs
    shifts = [(0.0, 0.0), (1 / 3, 1 / 3), (0.5, 0.0)]
    flat_el = np.array([_energy_and_load(flat, _shifted(interface, *s)) for s in shifts])
    whole_el = np.array([_energy_and_load(whole, _shifted(interface, *s)) for s in shifts])
    assert np.ptp(flat_el[:, 0]) < 1e-9 and np.abs(flat_el[:, 1]).max() < 1e-9
    assert np.ptp(whole_el[:, 0]) > 1e-2 and np.abs(whole_el[:, 1]).max() > 1e-2


@pytest.mark.parametrize(
    "potential",
    [
        "{preset: cu-eam, coupling: none}",  # LAMMPS EAM per slab, nothing across
        f'{{calculator: {{target: "{EMT}", scope: slab}}, coupling: none}}',
    ],
    ids=["lammps-per-slab", "ase-per-slab"],
)
def test_every_door_refuses_a_per_slab_model_without_coupling(
    potential, tmp_path, capsys, monkeypatch
):
    """config --check, build --config, scan CONFIG and run CONFIG: one line naming the
    file's potential.coupling and what was expected, nothing written."""
    monkeypatch.chdir(tmp_path)
    config = tmp_path / "flat.yaml"
    config.write_text(CU + f"potential: {potential}\n" + MODULI)
    out = tmp_path / "out"
    for argv in (
        ["config", "--check", str(config)],
        ["build", "--config", str(config), "--out", str(out)],
        ["scan", str(config), "--out", str(out)],
        ["run", str(config), "--out", str(out)],
    ):
        line = one_error_line(*run_cli(argv, capsys)[::2])
        assert line.startswith(
            f"error: {config}: potential.coupling: 'none' with the per-slab model "
        )
        assert "same energy and no normal load" in line
        assert line.endswith(
            "expected lj, same or interlayer, or an ASE calculator over the whole interface "
            "(calculator.scope: interface)"
        ), line
        assert not out.exists(), argv
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flat.yaml"]


def test_scan_of_a_given_interface_refuses_it_too(interface, tmp_path, capsys, monkeypatch):
    """``flatcontact scan CONFIG --interface FILE`` checks the model on that interface
    (another path than the recipe's): the same line, before the scan writes anything."""
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "interface.extxyz"
    interface.write(path)
    config = tmp_path / "flat.yaml"
    config.write_text(
        f"potential: {{calculator: {{target: '{EMT}', scope: slab}}, coupling: none}}\n"
    )
    out = tmp_path / "out"
    argv = ["scan", str(config), "--interface", str(path), "--out", str(out)]
    line = one_error_line(*run_cli(argv, capsys)[::2])
    assert line.startswith(f"error: {config}: potential.coupling: 'none' with the per-slab model ")
    assert not out.exists()


def test_a_whole_interface_calculator_with_its_coupling_none_passes_the_check(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    config = tmp_path / "emt.yaml"
    config.write_text(CU + f'potential: {{calculator: {{target: "{EMT}"}}}}\n' + MODULI)
    code, _, err = run_cli(["config", "--check", str(config)], capsys)
    assert code in (0, None), err


def test_the_notebook_door_refuses_such_a_model(interface, tmp_path):
    """scan_interface(..., InteractionModel(...)) names its parameter, before any point."""
    with pytest.raises(InputError) as info:
        notebook.scan_interface(
            interface,
            InteractionModel(**PER_SLAB_EMT),
            grid=(3, 3),
            thickness_angstrom=[10.3],
            out=tmp_path / "nb",
        )
    assert str(info.value).startswith("calculator.coupling: 'none' with the per-slab model ")
    assert not (tmp_path / "nb").exists()


def test_build_with_an_intra_flag_names_the_files_coupling(tmp_path, capsys, monkeypatch):
    """``--potential vashishta`` replaces the intra model and keeps the file's coupling: the
    refusal names the file's potential.coupling, not the flag; a preset's own coupling
    (cu-eam: the same EAM across) replaces it and the build goes on."""
    monkeypatch.chdir(tmp_path)
    config = tmp_path / "flat.yaml"
    config.write_text(CU + f"potential: {PER_SLAB_EMT}\n".replace("'", '"'))
    out = tmp_path / "out"
    argv = ["build", "--config", str(config), "--potential", "vashishta", "--out", str(out)]
    line = one_error_line(*run_cli(argv, capsys)[::2])
    assert line.startswith(
        f"error: {config}: potential.coupling: 'none' with the per-slab model vashishta: "
    )
    assert not out.exists()
    argv[4] = "cu-eam"
    code, _, err = run_cli([*argv, "--no-svg"], capsys)
    assert code in (0, None), err
    assert (out / "interface.extxyz").is_file()
