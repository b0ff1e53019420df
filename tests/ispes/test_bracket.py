"""Loads that always bracket (issue 20): the merge of close thicknesses, folds named with
z, p and the loads refused, the grid's own check, and lists main chose left unchanged."""

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.grid_bracket import check_grid, node_loads_gpa
from flatcontact.ispes.probe import ColumnProbe
from flatcontact.ispes.thicknesses import (
    MIN_THICKNESS_SPACING_ANGSTROM,
    merge_close_thicknesses,
    thicknesses_spanning_columns,
)

DATA = Path(__file__).parent / "data"


# ------------------------------------------------------------------ merging


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(5.0, 30.0, allow_nan=False), min_size=1, max_size=40))
def test_merge_spacing_outer_kept_and_idempotent(z):
    merged = merge_close_thicknesses(z)
    if np.ptp(z) >= MIN_THICKNESS_SPACING_ANGSTROM:  # else only the two ends remain
        assert np.all(np.diff(merged) >= MIN_THICKNESS_SPACING_ANGSTROM)
    else:
        assert merged.size <= 2
    assert merged[0] == min(z) and merged[-1] == max(z)  # the bracket never shrinks
    assert set(merged) <= set(z)
    np.testing.assert_array_equal(merge_close_thicknesses(merged), merged)
    # every dropped thickness lies within the minimum of a kept one
    gap = np.min(np.abs(np.asarray(z)[:, None] - merged[None, :]), axis=1)
    assert np.all(gap < MIN_THICKNESS_SPACING_ANGSTROM + 1e-12)


def test_a_list_that_respects_the_minimum_is_unchanged():
    z = np.array([10.0, 10.03, 10.5, 11.0])
    np.testing.assert_array_equal(merge_close_thicknesses(z[::-1]), z)


def _probe(z, p, shift=(0.0, 0.0)):
    z, p = np.asarray(z, float), np.asarray(p, float)
    e = -np.concatenate([[0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(z))])
    return ColumnProbe(shift, z, e / EV_PER_A3_TO_GPA * 10.0, p, 1, 10.0)


def _exponential_probe(z0, shift=(0.0, 0.0), tension=-1.0):
    """p(z) = A(e^{-2a(z-z0)} - e^{-a(z-z0)}) (a Morse force), sampled from compression to
    far beyond the tensile maximum (which is ``tension``, GPa, at z0 + ln2/a)."""
    a = 2.0
    z = np.linspace(z0 - 0.6, z0 + 4.0, 93)
    x = np.exp(-a * (z - z0))
    return _probe(z, -4 * tension * (x**2 - x), shift)


@settings(max_examples=60, deadline=None)
@given(
    shifts=st.lists(st.floats(-0.3, 0.3), min_size=1, max_size=4),
    lo=st.floats(-0.5, 0.8),
    hi=st.floats(1.0, 4.0),
    n=st.integers(2, 9),
)
def test_chosen_thicknesses_bracket_every_load_and_p0_with_minimum_spacing(shifts, lo, hi, n):
    probes = [_exponential_probe(12.0 + d, (0.1 * k, 0.0)) for k, d in enumerate([0.0, *shifts])]
    c = thicknesses_spanning_columns(probes, lo, hi, n)
    z = c.thickness_angstrom
    assert np.all(np.diff(z) >= MIN_THICKNESS_SPACING_ANGSTROM)
    lo_eff = max(lo, -1.0)
    for pr in probes:
        zs, ps = pr.thickness_angstrom, pr.normal_stress_gpa
        m = int(np.argmin(ps))
        p_at = np.interp(z, zs[: m + 1], ps[: m + 1])
        slack = 0.01 * (hi - lo_eff) + 0.01  # BRACKET_RTOL + linear interpolation (h = 0.05 Å)
        assert p_at.max() >= hi - slack
        assert p_at.min() <= min(lo_eff, 0.0) + slack  # P = 0 bracketed even when LO > 0


# ------------------------------------------------------------------ folds


def test_a_compressive_fold_is_named_and_the_loads_beyond_it_refused():
    # p falls to 0.8, jumps to 1.5 (a plane slipped) and falls through 0 to the tension
    z = np.arange(10) * 0.1 + 10.0
    p = np.array([3.0, 2.0, 0.8, 1.5, 1.0, 0.5, 0.0, -0.5, -0.6, -0.4])
    c = thicknesses_spanning_columns([_probe(z, p, (0.5, 0.0))], 0.0, 2.0, 5, ["lowest energy"])
    assert len(c.load_folds) == 1
    fold = c.load_folds[0]
    rec = fold.record()
    assert rec == {
        "column": "lowest energy column at shift (0.5, 0)",
        "z_angstrom": pytest.approx(10.3),
        "p_gpa": 1.5,
        "loads_refused_gpa": [2.0],
    }
    line = fold.message()
    assert "\n" not in line and "z = 10.2" in line and "0.8 GPa" in line and "1.5 GPa" in line
    assert "relax_mode: normal" in line and "scan.fmax_ev_per_angstrom" in line
    assert any(line == note for note in c.notes)
    assert c.hi_gpa == 1.5
    zz = c.thickness_angstrom  # all on the tensile side of the fold
    assert zz.min() >= 10.3 - 1e-12 and np.interp(zz.max(), z[3:9], p[3:9]) <= 1e-12


def test_a_second_tensile_well_is_not_a_fold():
    """diamond(111)/graphite, full relaxation: p reaches -1.446 GPa, rises to -1.437 and
    falls further (a second gap opening); the first well carries P = 0, no load refused."""
    z = np.arange(8) * 0.1 + 13.0
    p = np.array([2.5, 1.0, 0.0, -1.0, -1.446, -1.437, -1.8, -1.2])
    c = thicknesses_spanning_columns([_probe(z, p)], 0.0, 2.0, 4)
    assert c.load_folds == [] and c.thickness_angstrom.max() <= z[2] + 1e-12


def test_a_fold_below_every_requested_load_gives_up_in_one_line():
    z = np.arange(6) * 0.1 + 10.0
    p = np.array([3.0, 1.0, 0.2, 0.6, -0.5, -0.2])  # loads above 0.6 GPa folded away
    with pytest.raises(InputError) as err:
        thicknesses_spanning_columns([_probe(z, p, (0.25, 0.5))], 1.0, 2.0, 4, ["most repulsive"])
    line = str(err.value)
    assert "\n" not in line and "most repulsive column at shift (0.25, 0.5)" in line
    assert "z = 10.2" in line and "0.2 GPa" in line and "0.6 GPa" in line and "relax_mode" in line


# ------------------------------------------------------------------ the grid's own check


def _grid_column(z, p_of):
    """Energy (eV) and stress (GPa) of a column with load ``p_of(z)`` on a 10 Å² cell."""
    zz = np.linspace(z[0], z[-1], 4001)
    pp = p_of(zz) / EV_PER_A3_TO_GPA
    e = -np.concatenate([[0], np.cumsum(0.5 * (pp[1:] + pp[:-1]) * np.diff(zz))]) * 10.0
    return np.interp(z, zz, e), p_of(z)


def test_node_loads_are_the_derivative_of_the_energy():
    z = np.linspace(10.0, 11.0, 9)
    e, s = _grid_column(z, lambda x: 3.0 * np.exp(-3 * (x - 10.0)) - 1.0)
    p = node_loads_gpa(z, e[None], s[None], 10.0)[0]
    np.testing.assert_allclose(p, s, atol=5e-3)


def test_a_column_short_of_p0_asks_for_a_thickness_beyond_the_largest():
    z = np.linspace(10.0, 11.0, 6)
    e, s = _grid_column(z, lambda x: 4.0 * (11.05 - x))  # still 0.2 GPa at z = 11
    verdict = check_grid(z, e[None], s[None], 10.0, [(0.0, 0.0)], (0.0, 2.0, 4), [0.0, 1.0])
    assert verdict.folds == [] and verdict.short == []
    # aimed a margin past P = 0 along the last slope: 11 + (0.2 + 0.0667)/4
    assert verdict.z_above == pytest.approx(11.0 + (0.2 + 2 / 3 * 0.1) / 4.0, rel=1e-2)
    e2, s2 = _grid_column(z, lambda x: 4.0 * (10.9 - x))  # P = 0 inside: nothing to add
    assert check_grid(z, e2[None], s2[None], 10.0, [(0.0, 0.0)], (0.0, 2.0, 4)).z_above is None


def test_a_grid_fold_is_recorded_with_the_loads_refused():
    z = np.linspace(10.0, 11.0, 11)
    s = np.array([3.0, 2.2, 1.6, 1.0, 1.4, 0.9, 0.5, 0.1, -0.3, -0.6, -0.8])
    e = -np.concatenate([[0], np.cumsum(0.5 * (s[1:] + s[:-1]) * np.diff(z))]) * 10.0
    e = e / EV_PER_A3_TO_GPA
    verdict = check_grid(z, e[None], s[None], 10.0, [(0.5, 0.5)], (0.0, 2.0, 3))
    assert len(verdict.folds) == 1
    rec = verdict.folds[0].record()
    assert "grid column at shift (0.5, 0.5)" in rec["column"]
    assert rec["loads_refused_gpa"] == [2.0] and 1.0 < rec["p_gpa"] < 2.0


# ------------------------------------------------------------------ unchanged where it brackets


def test_quartz_quick_preset_thicknesses_are_mains():
    """The quick preset's probed columns (stored from a `make run` on main before this
    change, with the list main chose): the rule gives the same list, bit for bit."""
    data = json.loads((DATA / "quartz_quick_probes.json").read_text())
    probes = [
        ColumnProbe.from_dict({k: v for k, v in d.items() if k != "role"}) for d in data["probes"]
    ]
    lo, hi, n = data["p_range_gpa"]
    c = thicknesses_spanning_columns(probes, lo, hi, n, [d["role"] for d in data["probes"]])
    assert c.thickness_angstrom.tolist() == data["thickness_angstrom"]
    assert c.notes == data["notes"] and c.load_folds == []


# ------------------------------------------------------------------ the driver's extension


def test_the_scan_extends_its_grid_until_every_column_brackets(
    tmp_path, toy_reference, toy_factory
):
    """Toy LJ grid with loads to analyse beyond its HI: the driver adds a thickness below
    the smallest (appended to the store's list, so stored points keep their index) and
    one beyond the largest; ispes.nc is ascending, every column brackets the loads as the
    analysis reads them, and a rerun on the store computes nothing and gives the same grid."""
    from flatcontact.analysis.constant_pressure import invert_columns
    from flatcontact.ispes.executors import SerialExecutor
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    grid = GridSpec(2, 2, p_range_gpa=(0.0, 0.3, 4))
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-4)
    loads = [-0.01, 0.0, 0.2, 0.4]  # below P = 0 and above HI = 0.3 GPa
    first = run_scan(
        toy_reference,
        toy_factory,
        grid,
        tmp_path / "s",
        settings,
        executor=SerialExecutor(),
        bracket_loads_gpa=loads,
    )
    ds = first.dataset
    z = ds.thickness.values
    assert np.all(np.diff(z) >= MIN_THICKNESS_SPACING_ANGSTROM)
    assert first.points_done == first.points_total == 4 * z.size
    assert any("ends below 0.4 GPa" in n for n in first.notes), first.notes
    assert any("ends above -0.01 GPa" in n for n in first.notes), first.notes
    area = float(ds.attrs["area"])
    e = ds.energy.values.reshape(-1, z.size) / area
    s = ds.normal_stress.values.reshape(-1, z.size) / EV_PER_A3_TO_GPA
    inv = invert_columns(z, e, s, np.asarray(loads) / EV_PER_A3_TO_GPA)
    assert np.all(np.isfinite(inv.thickness_angstrom))
    again = run_scan(
        toy_reference,
        toy_factory,
        grid,
        tmp_path / "s",
        settings,
        executor=SerialExecutor(),
        bracket_loads_gpa=loads,
    )
    assert again.points_computed == 0
    np.testing.assert_array_equal(again.dataset.energy.values, ds.energy.values)
    np.testing.assert_array_equal(again.dataset.thickness.values, z)
