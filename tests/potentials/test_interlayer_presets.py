"""2D bilayers (and graphene/h-BN, strained to one cell) with the interlayer presets against a plain LAMMPS input and the literature.

For each preset (graphene REBO+KC, graphene REBO+ILP, h-BN Tersoff+ILP, MoS₂ SW+ILP) a
bilayer of two primitive cells is built here at a fixed interlayer distance in the AA, AB,
BA and SP registries; its energy through flatcontact's interaction model is compared with a
LAMMPS input written in this test (the examples' style: one REBO/Tersoff instance for both
layers or one SW per layer, molecule ids set by hand), and the energy differences with the
magnitudes the potentials' papers report.
"""

import numpy as np
import pytest
from ase import Atoms
from ase.build import mx2
from tests.potentials.plain_lammps import lammps_energy

from flatcontact.potentials import InteractionModel, make_calculator
from flatcontact.potentials.engines import bulk_calculator
from flatcontact.potentials.lammps_runtime import lammps_potential_file

SHIFTS = {"AA": (0.0, 0.0), "AB": (1 / 3, 1 / 3), "BA": (2 / 3, 2 / 3), "SP": (0.5, 0.5)}


def hexagonal_bilayer(a, d, shift, bottom=("C", "C"), top=None):
    """Two honeycomb layers (2 atoms each) at distance d, the top one shifted by shift·(a1, a2)."""
    cell = np.array([[a, 0, 0], [a / 2, a * np.sqrt(3) / 2, 0], [0, 0, 40.0]])
    sites = np.array([[0, 0], [1 / 3, 1 / 3]])
    top = top or bottom
    pos, sym = [], []
    for z, species, offset in ((10.0, bottom, 0.0), (10.0 + d, top, np.asarray(shift))):
        for frac, s in zip(sites + offset, species, strict=True):
            pos.append([*(frac @ cell[:2, :2]), z])
            sym.append(s)
    atoms = Atoms(sym, positions=pos, cell=cell, pbc=(True, True, False))
    atoms.arrays["slab"] = np.array([1, 1, 2, 2])
    atoms.arrays["layer"] = np.array([1, 1, 2, 2])
    return atoms


def mos2_bilayer(d, shift):
    """Two 2H-MoS₂ monolayers (a = 3.18 Å), Mo–Mo distance d, the top one shifted."""
    mono = mx2("MoS2", kind="2H", a=3.18, thickness=3.13, vacuum=0.0)
    top = mono.copy()
    top.positions[:, :2] += np.asarray(shift) @ mono.cell.array[:2, :2]
    top.positions[:, 2] += d
    atoms = mono + top
    atoms.cell[2] = [0, 0, 40.0]
    atoms.pbc = (True, True, False)
    atoms.positions[:, 2] += 10.0
    atoms.arrays["slab"] = np.array([1, 1, 1, 2, 2, 2])
    atoms.arrays["layer"] = atoms.arrays["slab"].copy()
    return atoms


def tool_energy(model, atoms):
    a = atoms.copy()
    a.calc = make_calculator(model, a)
    return a.get_potential_energy()


def f(name):
    return str(lammps_potential_file(name))


# preset -> (builder, plain LAMMPS types, molecule ids, pair commands)
GRAPHENE = (lambda s, d=3.4: hexagonal_bilayer(2.46, d, s), [1, 1, 2, 2], [1, 1, 2, 2])
HBN = (lambda s, d=3.3: hexagonal_bilayer(2.51, d, s, ("B", "N")), [1, 2, 3, 4], [1, 1, 2, 2])
CASES = {
    "graphene-rebo-kc": (
        *GRAPHENE,
        [
            "pair_style hybrid/overlay rebo kolmogorov/crespi/full 16.0 1",
            f"pair_coeff * * rebo {f('CH.rebo')} C C",
            f"pair_coeff * * kolmogorov/crespi/full {f('CH_taper.KC')} C C",
        ],
    ),
    "graphene-rebo-ilp": (
        *GRAPHENE,
        [
            "pair_style hybrid/overlay rebo ilp/graphene/hbn 16.0 1",
            f"pair_coeff * * rebo {f('CH.rebo')} C C",
            f"pair_coeff * * ilp/graphene/hbn {f('BNCH.ILP')} C C",
        ],
    ),
    "hbn-tersoff-ilp": (
        *HBN,
        [  # as in the LAMMPS example in.bilayer-hBN: Coulomb only across the layers
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
        ],
    ),
    "graphene-hbn-ilp": (
        lambda s, d=3.35: hexagonal_bilayer(2.48, d, s, ("C", "C"), ("B", "N")),
        [1, 1, 2, 3],
        [1, 1, 2, 2],
        [
            "pair_style hybrid/overlay rebo tersoff ilp/graphene/hbn 16.0 1 coul/shield 16.0 1",
            f"pair_coeff * * rebo {f('CH.rebo')} C NULL NULL",
            f"pair_coeff * * tersoff {f('BNC.tersoff')} NULL B N",
            f"pair_coeff * * ilp/graphene/hbn {f('BNCH.ILP')} C B N",
            "pair_coeff 2 2 coul/shield 0.70",
            "pair_coeff 2 3 coul/shield 0.69498201415576216335",
            "pair_coeff 3 3 coul/shield 0.69",
            "set type 2 charge 0.42",
            "set type 3 charge -0.42",
        ],
    ),
    "mos2-sw-ilp": (
        lambda s, d=6.15: mos2_bilayer(d, s),
        # mx2 order: Mo, S(top), S(bottom); types Mo, S-top, S-bottom per layer
        [1, 2, 3, 4, 5, 6],
        [1, 1, 1, 2, 2, 2],
        [
            "pair_style hybrid/overlay sw/mod sw/mod ilp/tmd 16.0 1",
            f"pair_coeff * * sw/mod 1 {f('tmd.sw.mod')} Mo S S NULL NULL NULL",
            f"pair_coeff * * sw/mod 2 {f('tmd.sw.mod')} NULL NULL NULL Mo S S",
            f"pair_coeff * * ilp/tmd {f('MoS2.ILP')} Mo S S Mo S S",
        ],
    ),
}


@pytest.mark.parametrize("preset", list(CASES))
def test_stackings_match_a_plain_lammps_input(preset):
    build, types, molecules, commands = CASES[preset]
    model = InteractionModel(preset=preset)
    tool = {k: tool_energy(model, build(s)) for k, s in SHIFTS.items()}
    plain = {k: lammps_energy(build(s), types, commands, molecules) for k, s in SHIFTS.items()}
    for key in SHIFTS:
        assert tool[key] == pytest.approx(plain[key], abs=1e-8), key
    # the differences the ISPES is made of agree to round-off as well
    for key in ("AA", "SP", "BA"):
        assert tool[key] - tool["AB"] == pytest.approx(plain[key] - plain["AB"], abs=1e-9)


@pytest.mark.parametrize("preset", ["graphene-rebo-kc", "graphene-rebo-ilp", "hbn-tersoff-ilp"])
def test_binding_and_corrugation_have_the_literature_magnitudes(preset):
    """Graphite-like binding (KC 2005, ILP 2016: 20–25 meV/atom near 3.4 Å); AA−AB of a
    few meV/atom (KC: ≈ 6–7, ILP ≈ 7; h-BN parallel stacking ≈ 10); SP barely above AB
    (≈ 0.5–1.5 meV/atom), per atom of the bilayer at a fixed interlayer distance."""
    build = CASES[preset][0]
    model = InteractionModel(preset=preset)
    far = tool_energy(model, build(SHIFTS["AA"], 30.0))
    e = {k: (tool_energy(model, build(s)) - far) / 4 * 1e3 for k, s in SHIFTS.items()}
    assert -30.0 < e["AB"] < -18.0
    assert 3.0 < e["AA"] - e["AB"] < 13.0
    assert 0.2 < e["SP"] - e["AB"] < 2.0


def test_symmetry_equivalent_stackings_are_equal_to_round_off():
    """Graphene: AB ≡ BA (inversion) and the three SP points ≡ (3-fold axis)."""
    model = InteractionModel(preset="graphene-rebo-kc")
    build = CASES["graphene-rebo-kc"][0]
    assert tool_energy(model, build(SHIFTS["AB"])) == pytest.approx(
        tool_energy(model, build(SHIFTS["BA"])), abs=1e-10
    )
    sp = [tool_energy(model, build(s)) for s in ((0.5, 0.0), (0.0, 0.5), (0.5, 0.5))]
    assert max(sp) - min(sp) < 1e-10


def test_mos2_bilayer_binds_and_eclipsed_is_repulsive():
    """MoS₂ ILP (Ouyang et al. 2021): at d(Mo–Mo) = 6.15 Å the S-over-S AA registry is the
    highest, the best registry binds by ≈ 20 meV/atom (bilayer binding ≈ 20–25 meV/atom)."""
    model = InteractionModel(preset="mos2-sw-ilp")
    far = tool_energy(model, mos2_bilayer(30.0, (0, 0)))
    e = {k: (tool_energy(model, mos2_bilayer(6.15, s)) - far) / 6 * 1e3 for k, s in SHIFTS.items()}
    assert e["AA"] == max(e.values())
    assert -30.0 < min(e.values()) < -10.0


def test_intralayer_instances_do_not_cross_the_layers():
    """Per-layer REBO: a bilayer far apart has twice the monolayer energy, and pressing the
    layers to 1.9 Å (inside REBO's 2 Å cutoff) changes only the interlayer term."""
    model = InteractionModel(preset="graphene-rebo-kc")
    intra_only = InteractionModel(intra=model.intra, intra_scope="layer", coupling="none")
    close = hexagonal_bilayer(2.46, 1.9, SHIFTS["AA"])
    far = hexagonal_bilayer(2.46, 30.0, SHIFTS["AA"])
    assert tool_energy(intra_only, close) == pytest.approx(tool_energy(intra_only, far), abs=1e-9)
    whole = InteractionModel(intra=model.intra, coupling="same")  # one REBO over both layers
    assert abs(tool_energy(whole, close) - tool_energy(whole, far)) > 0.1


@pytest.mark.parametrize("preset", ["graphene-hbn-ilp", "mos2-sw-ilp"])
def test_forces_are_minus_the_energy_gradient(preset):
    """Rattled bilayers: the engine's forces equal central differences of its energy."""
    atoms = CASES[preset][0](SHIFTS["SP"]).repeat((2, 2, 1))
    atoms.rattle(0.05, seed=11)
    atoms.calc = make_calculator(InteractionModel(preset=preset), atoms)
    forces = atoms.get_forces()
    h = 1e-5
    for index in (0, len(atoms) - 1):
        for axis in range(3):
            x0 = atoms.positions[index, axis]
            atoms.positions[index, axis] = x0 + h
            ep = atoms.get_potential_energy()
            atoms.positions[index, axis] = x0 - h
            em = atoms.get_potential_energy()
            atoms.positions[index, axis] = x0
            assert forces[index, axis] == pytest.approx(-(ep - em) / (2 * h), abs=1e-5)


def test_bulk_graphite_binds_about_twice_the_bilayer():
    """The bulk calculator of an interlayer model finds the layers of a crystal (atomic planes)
    and keeps REBO per layer: AB graphite at c = 2d binds each atom to two neighbouring layers,
    so its binding per atom is about twice the AB bilayer's (next-nearest layers add a few %)."""
    model = InteractionModel(preset="graphene-rebo-kc")
    a, d = 2.46, 3.4

    def graphite(c):
        cell = [[a, 0, 0], [a / 2, a * np.sqrt(3) / 2, 0], [0, 0, c]]
        frac = [[0, 0, 0], [1 / 3, 1 / 3, 0], [0, 0, 0.5], [2 / 3, 2 / 3, 0.5]]
        return Atoms("C4", scaled_positions=frac, cell=cell, pbc=True)

    def bulk_energy(atoms):
        atoms.calc = bulk_calculator(model, atoms)
        return atoms.get_potential_energy() / len(atoms)

    bulk_binding = bulk_energy(graphite(2 * d)) - bulk_energy(graphite(40.0))
    build = CASES["graphene-rebo-kc"][0]
    bilayer = (
        tool_energy(model, build(SHIFTS["AB"])) - tool_energy(model, build(SHIFTS["AB"], 30.0))
    ) / 4
    assert 1.9 < bulk_binding / bilayer < 2.2
