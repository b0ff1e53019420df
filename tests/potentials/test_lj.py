"""TS C6 combination rule, the C6 -> (ε, σ) mapping, cutoff shift, spec validation."""

import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import InteractionModel, LJSpec
from flatcontact.potentials.lj import (
    BOHR_TO_ANGSTROM,
    HARTREE_BOHR6_TO_EV_A6,
    TS_FREE_ATOM,
    lj_energy,
    lj_from_c6,
    lj_table,
    ts_combined_c6,
    ts_free_atom,
)


def test_ts_free_atom_values_and_units():
    table = lj_table(["O", "Si"], ["O", "Si"])
    # Chu & Dalgarno / TS 2009: C6(O) = 15.6, C6(Si) = 305 Ha·bohr^6
    assert table["O-O"].c6_ev_a6 == pytest.approx(15.6 * HARTREE_BOHR6_TO_EV_A6)
    assert table["Si-Si"].c6_ev_a6 == pytest.approx(305 * HARTREE_BOHR6_TO_EV_A6)
    assert HARTREE_BOHR6_TO_EV_A6 == pytest.approx(0.5974, rel=1e-3)
    # combination rule by hand: 2·305·15.6/((5.4/37)·305 + (37/5.4)·15.6) Ha·bohr^6
    c6_sio = 2 * 305 * 15.6 / ((5.4 / 37) * 305 + (37 / 5.4) * 15.6)
    assert table["O-Si"].c6_ev_a6 == pytest.approx(c6_sio * HARTREE_BOHR6_TO_EV_A6)
    # σ from the vdW radii: LJ minimum at R0(O) + R0(Si) = (3.19 + 4.20) bohr
    rmin = 2 ** (1 / 6) * table["O-Si"].sigma_angstrom
    assert rmin == pytest.approx((3.19 + 4.20) * BOHR_TO_ANGSTROM)


def test_free_atom_values_are_ases_table_where_ase_has_the_element():
    """ts_free_atom holds ASE's vdWDB_alphaC6 differences itself (no import of
    ase.calculators.vdwcorrection in a scan worker): for every element the values, bit for
    bit, that a lookup in ASE's own table gives, and TS_FREE_ATOM's for the others."""
    from ase.calculators.vdwcorrection import vdWDB_alphaC6

    assert set(vdWDB_alphaC6) <= set(TS_FREE_ATOM)
    for symbol in TS_FREE_ATOM:
        alpha, c6 = vdWDB_alphaC6.get(symbol, TS_FREE_ATOM[symbol][:2])
        assert ts_free_atom(symbol) == (c6 * HARTREE_BOHR6_TO_EV_A6, float(alpha)), symbol


@given(
    c6a=st.floats(1.0, 1e3),
    c6b=st.floats(1.0, 1e3),
    aa=st.floats(1.0, 100.0),
    ab=st.floats(1.0, 100.0),
)
def test_combination_rule_limits(c6a, c6b, aa, ab):
    # symmetric, and the like-pair limit returns the like-pair value
    assert ts_combined_c6(c6a, aa, c6b, ab) == pytest.approx(ts_combined_c6(c6b, ab, c6a, aa))
    assert ts_combined_c6(c6a, aa, c6a, aa) == pytest.approx(c6a)
    # bounded by the geometric mean (Cauchy–Schwarz-like inequality of the London formula)
    assert ts_combined_c6(c6a, aa, c6b, ab) <= np.sqrt(c6a * c6b) * (1 + 1e-12)


@given(c6=st.floats(0.1, 500.0), ra=st.floats(1.0, 3.0), rb=st.floats(1.0, 3.0))
def test_mapping_reproduces_c6_tail_and_minimum(c6, ra, rb):
    pair = lj_from_c6(c6, ra, rb)
    assert 4 * pair.epsilon_ev * pair.sigma_angstrom**6 == pytest.approx(c6)
    rmin = ra + rb
    r = np.array([0.98, 1.0, 1.02]) * rmin
    e = lj_energy(r, pair, cutoff_angstrom=1e6)
    assert e[1] < e[0] and e[1] < e[2]
    assert e[1] == pytest.approx(-pair.epsilon_ev, rel=1e-9)
    # far tail is −C6/r^6
    far = 50 * rmin
    assert lj_energy(np.array([far]), pair, 1e6)[0] == pytest.approx(-c6 / far**6, rel=1e-6)


def test_cutoff_shift_makes_energy_continuous():
    pair = lj_from_c6(30.0, 1.7, 2.2)
    rc = 8.0
    e = lj_energy(np.array([rc - 1e-9, rc, rc + 1.0]), pair, rc)
    assert abs(e[0]) < 1e-12 and e[1] == 0.0 and e[2] == 0.0


def test_user_c6_and_hirshfeld_scaling():
    user = lj_table(["O"], ["Si"], c6_ev_a6={"Si-O": 20.0})
    assert user["O-Si"].c6_ev_a6 == 20.0
    scaled = lj_table(["O"], ["O"], volume_ratio={"O": 0.8})
    free = lj_table(["O"], ["O"])
    assert scaled["O-O"].c6_ev_a6 == pytest.approx(0.8**2 * free["O-O"].c6_ev_a6)
    assert scaled["O-O"].sigma_angstrom == pytest.approx(
        0.8 ** (1 / 3) * free["O-O"].sigma_angstrom
    )
    with pytest.raises(InputError, match="c6_ev_a6 lacks"):
        LJSpec(c6_source="user", c6_ev_a6={"O-O": 1.0}).table(["O", "Si"], ["O", "Si"])
    with pytest.raises(InputError, match="La"):  # the TS table has no lanthanides
        lj_table(["La"], ["O"])


def test_spec_is_frozen_picklable_hashable_and_validates():
    spec = InteractionModel(
        intra="tersoff", lj=LJSpec(c6_ev_a6={"Si-O": 12.0}, cutoff_angstrom=8.0)
    )
    assert pickle.loads(pickle.dumps(spec)) == spec
    assert hash(spec) == hash(InteractionModel.model_validate_json(spec.model_dump_json()))
    assert spec.lj.c6_ev_a6 == {"O-Si": 12.0}
    assert "tersoff" in spec.label and "rc=8" in spec.label
    with pytest.raises(Exception):  # noqa: B017 - pydantic's frozen error
        spec.intra = "vashishta"
    for bad, pattern in [
        ("nonsense", "unknown potential"),
        ("snap:no-such-snap", "no bundled SNAP"),
        ("snap:/nonexistent/X.snapcoeff", "not found"),
        ("ase:no_such_module_xyz:f", "cannot be imported"),
        ("ase:justmodule", "ase:module:factory"),
    ]:
        with pytest.raises(InputError, match=pattern) as info:
            InteractionModel(intra=bad)
        assert "\n" not in str(info.value)
    with pytest.raises(InputError, match="cutoff"):
        InteractionModel(lj={"cutoff_angstrom": 0})


def test_pairwise_hamaker_constant_by_hand():
    """A = π² Σ_AB C6_AB ρ_A ρ_B (Hamaker 1937), checked term by term for α-quartz."""
    from flatcontact.potentials.lj import (
        ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3 as RHO,
    )
    from flatcontact.potentials.lj import pairwise_hamaker_constant_zj

    t = lj_table(["O", "Si"], ["O", "Si"])
    # α-quartz: 3 SiO2 in V = (√3/2)a²c = 113.1 Å³ → 26.5 Si and 53.0 O per nm³
    assert RHO["Si"] == pytest.approx(26.52, abs=0.01)
    assert RHO["O"] == pytest.approx(2 * RHO["Si"])
    rho_si, rho_o = RHO["Si"] * 1e-3, RHO["O"] * 1e-3  # Å⁻³
    by_hand_ev = np.pi**2 * (
        t["Si-Si"].c6_ev_a6 * rho_si**2
        + 2 * t["O-Si"].c6_ev_a6 * rho_si * rho_o
        + t["O-O"].c6_ev_a6 * rho_o**2
    )
    a_zj = pairwise_hamaker_constant_zj(t, RHO)
    assert a_zj == pytest.approx(by_hand_ev * 1.602176634e-19 * 1e21)
    # free-atom C6 overbind quartz: ~4.7× the Lifshitz value (≈ 88 zJ, Bergström 1997)
    assert 380 < a_zj < 440


@given(st.floats(10.0, 1000.0))
def test_hamaker_calibration_round_trip_keeps_sigma(target_zj):
    from flatcontact.potentials.lj import (
        ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3 as RHO,
    )
    from flatcontact.potentials.lj import hamaker_c6_scale, pairwise_hamaker_constant_zj

    free = lj_table(["O", "Si"], ["O", "Si"])
    scale = hamaker_c6_scale(free, RHO, target_zj)
    scaled = lj_table(["O", "Si"], ["O", "Si"], c6_scale=scale)
    assert pairwise_hamaker_constant_zj(scaled, RHO) == pytest.approx(target_zj, rel=1e-12)
    for key in free:
        assert scaled[key].sigma_angstrom == free[key].sigma_angstrom  # minima stay put
        assert scaled[key].epsilon_ev == pytest.approx(scale * free[key].epsilon_ev)
    # the spec route gives the same table
    spec = LJSpec(hamaker_zj=target_zj, number_density_per_nm3=RHO)
    via_spec = spec.table(["O", "Si"], ["O", "Si"])
    for key in free:
        assert via_spec[key].c6_ev_a6 == pytest.approx(scaled[key].c6_ev_a6, rel=1e-12)


def test_hamaker_and_scale_are_validated():
    from pydantic import ValidationError

    with pytest.raises(ValidationError, match="number_density_per_nm3"):
        LJSpec(hamaker_zj=88.0)
    with pytest.raises(ValidationError, match="either c6_scale or hamaker_zj"):
        LJSpec(hamaker_zj=88.0, c6_scale=0.5, number_density_per_nm3={"Si": 1.0, "O": 2.0})
    with pytest.raises(ValidationError, match=r"expected 0.001 <= value <= 1000, got 0"):
        LJSpec(c6_scale=0.0)  # the bounded float (flatcontact.foundation.numbers): 1e-3..1e3
    spec = LJSpec(hamaker_zj=88.0, number_density_per_nm3={"O": 53.0})
    with pytest.raises(InputError, match=r"lacks the elements \['Si'\]"):
        spec.table(["O", "Si"], ["O", "Si"])
    half = LJSpec(c6_scale=0.5).table(["O"], ["O"])["O-O"]
    assert half.c6_ev_a6 == pytest.approx(0.5 * lj_table(["O"], ["O"])["O-O"].c6_ev_a6)
