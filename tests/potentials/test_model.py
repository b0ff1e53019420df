"""The InteractionModel API: data in, calculators out, refusals before any work."""

import json
import pickle

import numpy as np
import pytest
from ase import Atoms
from ase.build import bulk
from ase.calculators.lj import LennardJones

from flatcontact.config import build_config, load_config
from flatcontact.foundation.errors import InputError
from flatcontact.potentials import PRESETS, InteractionModel, make_calculator, parse_kwargs
from flatcontact.potentials.engines import bulk_calculator, calculator_factory
from flatcontact.potentials.lj import lj_cross_energy_forces, lj_table


def carbon_bilayer(d=3.4, shift=(1 / 3, 1 / 3)):
    a = 2.46
    cell = np.array([[a, 0, 0], [a / 2, a * np.sqrt(3) / 2, 0], [0, 0, 40.0]])
    frac = np.array([[0, 0], [1 / 3, 1 / 3], [0, 0], [1 / 3, 1 / 3]], dtype=float)
    frac[2:] += shift
    z = [10.0, 10.0, 10.0 + d, 10.0 + d]
    atoms = Atoms("C4", positions=np.column_stack([frac @ cell[:2, :2], z]), cell=cell)
    atoms.pbc = (True, True, False)
    atoms.arrays["slab"] = np.array([1, 1, 2, 2])
    atoms.arrays["layer"] = np.array([1, 1, 2, 2])
    return atoms


def energy(model, atoms):
    atoms = atoms.copy()
    atoms.calc = make_calculator(model, atoms)
    return atoms.get_potential_energy(), atoms.get_forces()


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_round_trip_pickle_and_fingerprint_by_content(name):
    model = InteractionModel(preset=name)
    again = InteractionModel.model_validate_json(model.model_dump_json())
    assert again == model and hash(again) == hash(model)
    assert pickle.loads(pickle.dumps(model)) == model
    factory = calculator_factory(model)
    clone = pickle.loads(pickle.dumps(factory))
    assert clone.fingerprint == factory.fingerprint and clone.label == model.label
    fp = model.fingerprint()
    text = json.dumps(fp)
    for path in model.input_files():  # files by name only, no directory of this machine
        assert str(path.parent) not in text and path.name in text
    assert set(fp["files_sha256"]) == {p.name for p in model.input_files()}
    assert model.elements and model.name == name


def test_fingerprint_follows_file_content_not_path(tmp_path):
    from flatcontact.potentials.lammps_runtime import lammps_potential_file

    text = lammps_potential_file("Cu_mishin1.eam.alloy").read_text()
    first = tmp_path / "a" / "Cu.eam.alloy"
    second = tmp_path / "b" / "Cu.eam.alloy"
    for path in (first, second):
        path.parent.mkdir()
        path.write_text(text)
    models = [
        InteractionModel(
            intra=[{"pair_style": "eam/alloy", "pair_coeff": [str(p)]}], coupling="same"
        )
        for p in (first, second)
    ]
    assert models[0].fingerprint() == models[1].fingerprint()
    second.write_text(text.replace("Mishin", "Mishin edited"))
    assert models[0].fingerprint() != models[1].fingerprint()


def test_element_the_model_lacks_is_refused_naming_both_before_lammps(monkeypatch):
    import flatcontact.potentials.lammps_engine as engine

    def no_lammps():
        raise AssertionError("a LAMMPS instance was created before the element check")

    monkeypatch.setattr(engine, "new_lammps", no_lammps)
    atoms = carbon_bilayer()
    atoms.symbols[3] = "Si"
    for name in ("graphene-rebo-kc", "cu-eam", "mos2-sw-ilp"):
        model = InteractionModel(preset=name)
        with pytest.raises(InputError, match=rf"'{name}'.*'Si'") as info:
            model.check_atoms(atoms)
        assert "\n" not in str(info.value)
        with pytest.raises(InputError, match="Si"):
            make_calculator(model, atoms)


def test_default_lj_takes_carbon_and_every_element_of_the_ts_table():
    """The free-atom LJ (no Hamaker constant) covers H–Kr, Mo, Ag, W, Au, …: graphite-like
    layers bind, and the LAMMPS lj/cut equals the numpy sum written for the ASE engine."""
    from ase.data import chemical_symbols

    model = InteractionModel(intra="none")  # LJ only, free-atom TS C6
    atoms = carbon_bilayer()
    e, f = energy(model, atoms)
    table = model.lj.table(["C"], ["C"])
    e_np, f_np = lj_cross_energy_forces(atoms, atoms.arrays["slab"], table, 10.0)
    assert e == pytest.approx(e_np, rel=1e-10) and np.allclose(f, f_np, atol=1e-10)
    assert e < 0
    for symbol in [*chemical_symbols[1:37], "Mo", "Ag", "W", "Au", "Pt", "Pd"]:
        pair = lj_table([symbol], ["C"])[f"{min(symbol, 'C')}-{max(symbol, 'C')}"]
        assert pair.c6_ev_a6 > 0 and 2.0 < pair.sigma_angstrom < 5.0


def test_a_hamaker_constant_without_the_densities_still_names_the_fix():
    model = InteractionModel(
        intra="none", lj={"hamaker_zj": 88.0, "number_density_per_nm3": {"Si": 26.5, "O": 53.0}}
    )
    with pytest.raises(InputError, match=r"lacks the elements \['C'\]"):
        model.check_atoms(carbon_bilayer())


def test_ase_calculator_per_slab_and_whole_interface_with_kwargs():
    """ase.calculators.lj with keyword arguments: per slab (+ TS LJ across) and whole."""
    atoms = carbon_bilayer()
    kwargs = {"sigma": 3.0, "epsilon": 0.01, "rc": 6.0, "smooth": True}
    whole = InteractionModel(
        calculator={"target": "ase.calculators.lj:LennardJones", "kwargs": kwargs}
    )
    e_whole, _ = energy(whole, atoms)
    reference = atoms.copy()
    reference.calc = LennardJones(**kwargs)
    assert e_whole == pytest.approx(reference.get_potential_energy(), rel=1e-12)
    per_slab = InteractionModel(
        calculator={"target": "ase.calculators.lj:LennardJones", "kwargs": kwargs, "scope": "slab"},
        coupling="lj",
    )
    e_slab, _ = energy(per_slab, atoms)
    parts = 0.0
    for k in (1, 2):
        part = atoms[atoms.arrays["slab"] == k]
        part.calc = LennardJones(**kwargs)
        parts += part.get_potential_energy()
    cross, _ = lj_cross_energy_forces(atoms, atoms.arrays["slab"], lj_table(["C"], ["C"]), 10.0)
    assert e_slab == pytest.approx(parts + cross, rel=1e-12)
    assert per_slab.elements is None and "per slab" in per_slab.label


def test_parse_kwargs_reads_yaml_values_and_refuses_in_one_line():
    got = parse_kwargs(["model=medium", "cutoff=5", "scale=0.5", "dispersion=true", "pair=[1, 2]"])
    assert got == {"model": "medium", "cutoff": 5, "scale": 0.5, "dispersion": True, "pair": [1, 2]}
    for bad in ("novalue", "=3", "1x=2"):
        with pytest.raises(InputError, match=f"--calculator-kwarg '{bad}'") as info:
            parse_kwargs([bad])
        assert "\n" not in str(info.value)


def test_bulk_calculator_stress_is_the_strain_derivative_of_the_energy():
    """σ_j = (1/V) dE/de_j (Voigt, engineering shear), by central differences written here."""
    cu = bulk("Cu", "fcc", a=3.60, cubic=True)
    cu.rattle(0.02, seed=1)
    calc = bulk_calculator(InteractionModel(preset="cu-eam"), cu)
    cu.calc = calc
    stress = cu.get_stress()
    h = 1e-5
    numerical = np.zeros(6)
    for j, (a, b) in enumerate(((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))):
        energies = []
        for sign in (1, -1):
            eps = np.zeros((3, 3))
            eps[a, b] += sign * h / (1 if a == b else 2)
            eps[b, a] = eps[a, b]
            strained = cu.copy()
            strained.set_cell(cu.cell.array @ (np.eye(3) + eps), scale_atoms=True)
            strained.calc = calc
            energies.append(strained.get_potential_energy())
        numerical[j] = (energies[0] - energies[1]) / (2 * h) / cu.get_volume()
    assert np.allclose(stress, numerical, atol=1e-6)


def test_yaml_calculator_and_new_potential_sections(tmp_path):
    old = tmp_path / "old.yaml"
    old.write_text(
        "potential:\n  calculator:\n    target: flatcontact.ispes.toy:toy_calculator\n"
        "    kwargs: {epsilon: 0.02}\nstructure: {kind: toy-lj, layers: 4}\n"
    )
    cfg = load_config(old)
    assert cfg.potential.engine == "ase-interface"
    assert cfg.calculator.target == "flatcontact.ispes.toy:toy_calculator"
    assert cfg.calculator.kwargs == {"epsilon": 0.02}
    # the top-level section of the unreleased drafts is an unknown key naming its home
    old.write_text("calculator: {target: flatcontact.ispes.toy:toy_calculator}\n")
    with pytest.raises(
        InputError, match=r"calculator: unknown field \(did you mean potential\.calculator\?\)"
    ):
        load_config(old)
    # the same model from a mapping has the same fingerprint
    new = build_config(
        {
            "potential": {
                "calculator": {
                    "target": "flatcontact.ispes.toy:toy_calculator",
                    "kwargs": {"epsilon": 0.02},
                }
            },
            "structure": {"kind": "toy-lj", "layers": 4},
        }
    )
    assert new.potential.fingerprint() == cfg.potential.fingerprint()
    # a preset replaces the default model (no quartz LJ left over); intra edits keep it
    preset = build_config({"potential": {"preset": "graphene-rebo-kc"}})
    assert preset.potential == InteractionModel(preset="graphene-rebo-kc")
    by_name = build_config({"potential": {"intra": "cu-eam"}})
    assert by_name.potential == InteractionModel(preset="cu-eam")
    edited = build_config({"potential": {"intra": "vashishta"}})
    assert edited.potential.lj.hamaker_zj == 88.0
    # the default is today's: bundled SNAP + Hamaker-calibrated LJ
    default = build_config({})
    assert default.potential.intra == "snap:sio2-snap" and default.potential.coupling == "lj"


def test_bad_model_data_is_one_line_naming_the_field():
    cases = [
        ({"preset": "graphite-magic"}, "unknown preset"),
        ({"coupling": "interlayer", "intra": "tersoff"}, "needs 'interlayer'"),
        (
            {"intra": [{"pair_style": "tersoff", "pair_coeff": ["NoSuch.tersoff"]}]},
            "NoSuch.tersoff",
        ),
        ({"intra": [{"pair_style": "hybrid/overlay tersoff"}]}, "give one style"),
        ({"calculator": {"target": "no_such_module_xyz:f"}}, "no_such_module_xyz"),
    ]
    for data, message in cases:
        with pytest.raises(InputError, match=message) as info:
            InteractionModel(**data)
        assert "\n" not in str(info.value)


def test_sio2_preset_is_todays_default_model(close_interface):
    """The sio2-snap-lj preset is the default run's model: same data, same energy and forces."""
    default = build_config({}).potential
    preset = InteractionModel(preset="sio2-snap-lj")
    assert preset.model_copy(update={"preset": None}) == default
    e_default, f_default = energy(default, close_interface)
    e_preset, f_preset = energy(preset, close_interface)
    assert e_preset == e_default and np.array_equal(f_preset, f_default)
