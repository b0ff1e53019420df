"""SiO2 polymorphs built from crystallographic data: densities, stoichiometry, coordination."""

import pytest

from flatcontact.training.polymorphs import POLYMORPHS, check_polymorph


@pytest.mark.parametrize("name", sorted(POLYMORPHS))
def test_polymorph_matches_its_reference(name):
    rep = check_polymorph(name)
    assert rep["o_per_si"] == 2.0
    assert rep["density_g_cm3"] == pytest.approx(rep["density_ref_g_cm3"], rel=0.005)
    assert rep["si_coordination"] == [rep["si_coordination_ref"]]
    assert rep["o_coordination"] == [rep["si_coordination_ref"] // 2]
    # Si-O bonds 1.59-1.62 Å (tetrahedral) and 1.76-1.81 Å (octahedral, stishovite)
    assert 1.55 < rep["min_distance_angstrom"] < 1.8


def test_atom_counts():
    assert {n: check_polymorph(n)["n_atoms"] for n in POLYMORPHS} == {
        "alpha_quartz": 9,
        "cristobalite": 12,
        "coesite": 48,
        "stishovite": 6,
    }
