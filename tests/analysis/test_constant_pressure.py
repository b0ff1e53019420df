"""Constant-pressure ISPES against the closed-form Morse model."""

import itertools
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.constant_pressure import constant_pressure, invert_columns
from flatcontact.analysis.diagnostics import (
    LoadFoldWarning,
    StressEnergyMismatchWarning,
    UnconvergedPointsWarning,
)
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import branch_run

A1, A2 = syn.hexagonal_cell()
MODEL = syn.SyntheticInterface(
    A1,
    A2,
    syn.three_cosine(A1, A2),
    depth_modulation=0.1,
    gap_modulation_angstrom=0.05,
    corrugation_ev_per_a2=-1e-3,
)
P_GPA = np.array([-0.5, 0.0, 0.5, 1.0, 2.0, 5.0])


def _frac_grid(res):
    return np.stack(np.meshgrid(res.shift_a, res.shift_b, indexing="ij"), -1)


def _errors(model, n_z, form="internal", load_source="stress"):
    z = np.linspace(24.2, 26.5, n_z)
    res = constant_pressure(model.grid(6, 6, z), P_GPA, form=form, load_source=load_source)
    s = _frac_grid(res)
    err_e, err_z = 0.0, 0.0
    for i, p in enumerate(P_GPA):
        pev = p / units.EV_PER_A3_TO_GPA
        ref = model.landscape(s, pev, form) + model.energy_offset_ev / model.area
        err_e = max(err_e, np.max(np.abs(res.energy_ev_per_a2[i] - ref)))
        err_z = max(err_z, np.max(np.abs(res.thickness_angstrom[i] - model.thickness_at(s, pev))))
    return err_e, err_z


@pytest.mark.parametrize("form", ["internal", "enthalpy"])
def test_stress_source_matches_closed_form_with_fourth_order_convergence(form):
    coarse = _errors(MODEL, 12, form)
    fine = _errors(MODEL, 24, form)
    finer = _errors(MODEL, 48, form)
    # cubic splines: error / 16 per halving of the thickness spacing (allow some slack)
    assert coarse[0] / fine[0] > 10 and fine[0] / finer[0] > 10
    assert coarse[1] / fine[1] > 10
    # and small against the lateral corrugation (13 meV/Å² peak to peak)
    assert finer[0] < 1e-7 and finer[1] < 1e-6


def test_energy_source_matches_closed_form():
    """p = -(1/A) dU/dz of the cubic spline is third-order accurate, so z* errs as h³; the
    internal form inherits it (δẽ = P δz), the enthalpy form is stationary in z (error h⁴)."""
    internal = [_errors(MODEL, n, "internal", "energy") for n in (12, 24, 48)]
    enthalpy = [_errors(MODEL, n, "enthalpy", "energy") for n in (12, 24, 48)]
    for a, b in itertools.pairwise(internal):
        assert a[0] / b[0] > 6 and a[1] / b[1] > 6  # 2³ = 8 with slack
    for a, b in itertools.pairwise(enthalpy):
        assert a[0] / b[0] > 10
    assert internal[-1][0] < 5e-7 and internal[-1][1] < 2e-5  # vs 13 meV/Å² corrugation
    assert enthalpy[-1][0] < 1e-7


def test_enthalpy_is_internal_plus_p_z():
    z = np.linspace(24.2, 26.5, 16)
    res = constant_pressure(MODEL.grid(4, 5, z), P_GPA, form="enthalpy")
    pev = P_GPA / units.EV_PER_A3_TO_GPA
    np.testing.assert_allclose(
        res.energy_ev_per_a2, res.internal_ev_per_a2 + pev[:, None, None] * res.thickness_angstrom
    )


def test_constant_energy_offset_changes_nothing_but_the_constant():
    z = np.linspace(24.2, 26.5, 12)
    ds = MODEL.grid(4, 4, z)
    base = constant_pressure(ds, P_GPA)
    moved = ds.copy()
    moved["energy"] = ds.energy + 777.0
    res = constant_pressure(moved, P_GPA)
    np.testing.assert_allclose(
        res.energy_ev_per_a2 - base.energy_ev_per_a2, 777.0 / MODEL.area, rtol=1e-9
    )
    np.testing.assert_allclose(res.thickness_angstrom, base.thickness_angstrom)


def test_adhesive_tail_and_load_range_are_reported():
    # maximum tension at u = 1/2, i.e. z = gap + ln 2 / alpha (about 25.58 Å here)
    z = np.linspace(24.2, 27.5, 34)
    res = constant_pressure(MODEL.grid(3, 3, z), [0.0])
    z_tension = MODEL.gap_angstrom + np.log(2) / MODEL.alpha_per_angstrom
    assert np.all(np.abs(res.tail_start_angstrom - z_tension) < 0.2)
    lo, hi = res.common_p_range_gpa
    tension_gpa = MODEL.alpha_per_angstrom * MODEL.well_depth_ev_per_a2 / 2 * units.EV_PER_A3_TO_GPA
    assert -tension_gpa * 1.2 < lo < -tension_gpa * 0.8 < 0 < hi
    # without the tail in the data there is none to report
    res = constant_pressure(MODEL.grid(3, 3, np.linspace(24.2, 25.3, 8)), [0.0])
    assert np.all(np.isnan(res.tail_start_angstrom))


def test_pressure_outside_the_data_names_column_and_range():
    ds = MODEL.grid(3, 3, np.linspace(24.6, 26.5, 12))
    with pytest.raises(
        InputError, match=r"P = 30 GPa is outside the data of .*column \(shift_a=.*GPa"
    ):
        constant_pressure(ds, [1.0, 30.0], source="x.nc")
    with pytest.raises(InputError, match="outside the data"):
        constant_pressure(ds, [-5.0])


def test_bad_columns_are_refused():
    z = np.linspace(24.2, 26.5, 12)
    ds = MODEL.grid(3, 3, z)
    bumpy = ds.copy(deep=True)  # one bad stress next to the loads asked: a fold there
    bumpy["normal_stress"][1, 2, 3] = bumpy.normal_stress[1, 2, 1] + 1.0
    with pytest.raises(InputError, match=r"P = 0.5 GPa is at or above a fold of .*normal_stress"):
        constant_pressure(bumpy, [0.5], load_source="stress")
    constant_pressure(bumpy, [0.5], load_source="energy")  # the energy source never reads p
    dented = ds.copy(deep=True)  # a concave kink in U(z): -dU/dz turns, then falls again
    dented["energy"][1, 2, 4] = dented.energy[1, 2, 4] - 0.2
    with pytest.raises(
        InputError,
        match=r"P = 0.5 GPa is at or above a fold of .*-\(1/A\) dU/dz.*tighten "
        r"scan.fmax_ev_per_angstrom or use analysis.load_source: stress",
    ):
        constant_pressure(dented, [0.5], load_source="energy")
    with pytest.raises(InputError, match="load source"):
        constant_pressure(ds, [0.5], load_source="virial")
    with pytest.raises(InputError, match="at least 4 are needed"):
        constant_pressure(MODEL.grid(3, 3, z[:3]), [0.5])
    with pytest.raises(InputError, match="energy form"):
        constant_pressure(ds, [0.5], form="gibbs")
    with pytest.raises(InputError, match="missing variable 'normal_stress'"):
        constant_pressure(ds.drop_vars("normal_stress"), [0.5])


def test_missing_points_are_listed_or_skipped_on_request():
    z = np.linspace(24.2, 26.5, 16)
    ds = MODEL.grid(4, 4, z)
    full = constant_pressure(ds, [0.5, 2.0])
    holed = ds.copy(deep=True)
    holed["energy"][2, 1, 5] = np.nan
    holed["converged"][2, 1, 5] = False
    with pytest.raises(InputError, match=r"1 grid points are missing.*shift_a=0.5, shift_b=0.25"):
        constant_pressure(holed, [0.5], source="scan.nc")
    res = constant_pressure(holed, [0.5, 2.0], allow_missing=True)
    # the holed column is interpolated through 15 instead of 16 points: close, not equal
    np.testing.assert_allclose(res.energy_ev_per_a2, full.energy_ev_per_a2, rtol=0, atol=5e-5)
    assert not np.array_equal(res.energy_ev_per_a2[:, 2, 1], full.energy_ev_per_a2[:, 2, 1])


def test_named_warnings_for_unconverged_and_inconsistent_data():
    z = np.linspace(24.2, 26.5, 12)
    ds = MODEL.grid(3, 3, z)
    ds["converged"][0, 0, 0] = False
    with pytest.warns(UnconvergedPointsWarning, match="1 finite grid points"):
        constant_pressure(ds, [0.5])
    ds = MODEL.grid(3, 3, z)
    ds["normal_stress"] = ds.normal_stress * 1.5
    with pytest.warns(StressEnergyMismatchWarning, match="differs from -\\(1/A\\) dU/dz"):
        constant_pressure(ds, [0.5])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        constant_pressure(MODEL.grid(3, 3, z), [0.5])


@settings(max_examples=25, deadline=None)
@given(
    depth=st.floats(0.005, 0.05),
    alpha=st.floats(0.6, 2.0),
    p_frac=st.floats(-0.9, 1.0),
    load_source=st.sampled_from(["stress", "energy"]),
)
def test_single_column_inversion_property(depth, alpha, p_frac, load_source):
    """z*(P) of one Morse column on a fine grid agrees with the closed form."""
    z = np.linspace(-1.2, 3.0, 120)
    u = np.exp(-alpha * z)
    e = depth * (u * u - 2 * u)
    p = 2 * alpha * depth * (u * u - u)
    tension = alpha * depth / 2
    p_top = p[0]
    target = p_frac * tension if p_frac < 0 else p_frac * 0.9 * p_top
    res = invert_columns(z, e[None, :], p[None, :], np.array([target]), load_source=load_source)
    ustar = 0.5 * (1 + np.sqrt(1 + 2 * target / (alpha * depth)))
    # -dU/dz of the cubic spline is one order less accurate than the spline of p (h³ vs h⁴),
    # least so next to the ends (not-a-knot)
    tol_z, tol_e = (2e-5, 1e-6) if load_source == "stress" else (2e-4, 3e-5)
    assert res.thickness_angstrom[0, 0] == pytest.approx(-np.log(ustar) / alpha, abs=tol_z)
    exact = depth * (ustar**2 - 2 * ustar)
    assert res.energy_ev_per_a2[0, 0] == pytest.approx(exact, abs=tol_e * np.max(np.abs(e)))


def _folded(n_z: int, column: tuple[int, int] = (1, 2), nodes: int = 3):
    """The model's grid with a fold on one column's compressed side: its first ``nodes`` samples
    are the model's own energy and stress 0.35 Å further out (a plane that slipped under load:
    a consistent state on another branch, its load below the next node's)."""
    z = np.linspace(24.2, 26.5, n_z)
    ds = MODEL.grid(6, 6, z)
    i, j = column
    other = MODEL.grid(6, 6, z + 0.35)
    # the energy continuous at the first node past the fold (a plane that slipped releases
    # its strain: the load drops, the energy does not jump)
    offset = ds.energy.values[i, j, nodes] - other.energy.values[i, j, nodes]
    ds["energy"][i, j, :nodes] = other.energy.values[i, j, :nodes] + offset
    ds["normal_stress"][i, j, :nodes] = other.normal_stress.values[i, j, :nodes]
    return ds


@pytest.mark.parametrize("load_source", ["stress", "energy"])
def test_a_fold_above_the_loads_is_read_past_on_its_own_nodes(load_source):
    """Loads below a fold are read on the branch that carries P = 0, splined on the nodes past
    the fold only: the closed form to the accuracy of the same grid without the fold (a spline
    through the fold would bend the segments next to it), with a LoadFoldWarning; a load the
    compressed side also reaches is refused in one line."""
    ds = _folded(36)
    p_ok = np.array([-0.5, 0.0, 0.5, 1.0, 2.0])
    stress = ds.normal_stress[1, 2].values
    s = int(np.flatnonzero(np.diff(stress) >= 0)[0]) + 1
    assert s == 3 and np.min(stress[:s]) > p_ok.max() and stress[s + 1] > p_ok.max()
    with pytest.warns(LoadFoldWarning, match=r"folds on the compressed side"):
        res = constant_pressure(ds, p_ok, load_source=load_source)
    clean = constant_pressure(
        MODEL.grid(6, 6, np.linspace(24.2, 26.5, 36)), p_ok, load_source=load_source
    )
    sfrac = _frac_grid(res)
    for i, p in enumerate(p_ok):
        pev = p / units.EV_PER_A3_TO_GPA
        ref = MODEL.landscape(sfrac, pev) + MODEL.energy_offset_ev / MODEL.area
        err_clean = np.max(np.abs(clean.energy_ev_per_a2[i] - ref))
        err = np.abs(res.energy_ev_per_a2[i] - ref)
        assert err[1, 2] < max(10 * err_clean, 1e-7), (p, err[1, 2], err_clean)
        z_ref = MODEL.thickness_at(sfrac, pev)
        assert abs(res.thickness_angstrom[i][1, 2] - z_ref[1, 2]) < 1e-3
    with pytest.raises(InputError, match=r"at or above a fold of .*shift_a=0.1667, shift_b=0.3333"):
        constant_pressure(ds, [float(np.min(stress[:s])) + 0.1], load_source=load_source)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-3.0, 6.0, allow_nan=False), min_size=3, max_size=14, unique=True))
def test_the_branch_rule_picks_the_first_falling_run_that_carries_p_zero(values):
    """The rule the scan and the analysis share (ispes.contract.branch_run), checked against
    its statement: a falling run ending at or before the tensile maximum, bounded by rises (or
    the ends), the first one reaching p <= 0, else the last run."""
    p = np.asarray(values)
    s, e = branch_run(p)
    m = int(np.argmin(p))
    assert 0 <= s <= e <= m
    assert np.all(np.diff(p[s : e + 1]) < 0)  # falling on the run
    assert s == 0 or p[s] >= p[s - 1]  # bounded by a rise before it
    assert e == m or p[e + 1] >= p[e]  # and after it
    if p[e] <= 0:
        assert np.all(p[:s] > 0)  # no earlier run reached p <= 0
    else:
        assert np.min(p[: m + 1]) > 0 and e == m  # no run reaches 0: the last run
