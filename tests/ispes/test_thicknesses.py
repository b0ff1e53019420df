"""Pressure-range thicknesses from probed columns, and the extreme columns they bracket."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.ispes.analytic_column import lj_wall_probe

from flatcontact.analysis import synthetic as syn
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.probe import (
    RigidStackings,
    extreme_stackings,
    probe_column,
    rigid_stackings,
)
from flatcontact.ispes.thicknesses import (
    MIN_THICKNESS_SPACING_ANGSTROM,
    probe_thicknesses,
    thicknesses_for_pressures,
)


def test_thicknesses_span_the_pressure_range():
    probe = lj_wall_probe()
    z, notes = thicknesses_for_pressures(probe, -0.1, 2.0, 5)
    assert notes == []
    p_at = np.interp(z, probe.thickness_angstrom, probe.normal_stress_gpa)
    np.testing.assert_allclose(np.sort(p_at)[::-1], np.linspace(-0.1, 2.0, 5)[::-1], atol=2e-3)
    _, notes = thicknesses_for_pressures(probe, -50.0, 2.0, 3)
    assert notes and "maximum adhesive tension" in notes[0]
    with pytest.raises(InputError, match="most compressed"):
        thicknesses_for_pressures(probe, 0.0, 1e4, 3)


# ------------------------------------------------------------------ extreme columns


def _morse_columns(reference, gap_modulation, grid):
    """Relax function, rigid stackings and exact p(s, z) of the closed-form Morse model.

    Hexagonal three-cosine pattern (analysis.synthetic): g = 3 at shift (0, 0), -3/2 at
    the hollows. With δ > 0 the equilibrium gap at (0, 0) is 4.5 δ wider than at the
    hollows: it is the most repulsive column at any z, the hollows the least.
    """
    a1, a2 = syn.hexagonal_cell(4.0)
    z_ref = thickness(reference)
    model = syn.SyntheticInterface(
        a1,
        a2,
        syn.three_cosine(a1, a2),
        gap_angstrom=z_ref - 0.3,
        gap_modulation_angstrom=gap_modulation,
        corrugation_ev_per_a2=1e-3,
    )

    def relax(a, b, z, start, start_z):
        s = np.array([a, b])
        e = float(model.energy_per_area(s, z)) * model.area
        p = float(model.stress_ev_per_a3(s, z)) * EV_PER_A3_TO_GPA
        return e, p, 1, None

    def p_of(s, z):
        return model.stress_ev_per_a3(s, z) * EV_PER_A3_TO_GPA

    sa, sb = grid.shifts()
    s = np.stack(np.meshgrid(sa, sb, indexing="ij"), -1)
    rigid = RigidStackings(
        model.energy_per_area(s, z_ref) * model.area, p_of(s, np.full(s.shape[:2], z_ref))
    )
    return model, relax, p_of, rigid, s


@settings(max_examples=25, deadline=None)
@given(
    delta=st.floats(0.02, 0.3),
    lo=st.floats(-0.5, 0.5),
    hi=st.floats(1.0, 4.0),
    n=st.integers(2, 8),
)
def test_thicknesses_bracket_the_loads_at_every_stacking(toy_reference, delta, lo, hi, n):
    grid = GridSpec(6, 6, p_range_gpa=(lo, hi, n))
    model, relax, p_of, rigid, s = _morse_columns(toy_reference, delta, grid)
    resolved, notes = probe_thicknesses(relax, toy_reference, rigid, grid)
    z = np.asarray(resolved["thickness_angstrom"])
    assert (0.0, 0.0) in [tuple(p["shift"]) for p in resolved["probes"]]  # g = 3: widest gap
    # every lateral grid column (not only the probed ones) brackets P = 0 and [lo_c, hi]:
    # p(z_min) >= hi and p(z_max) <= lo_c = max(min(lo, 0), the maximum tension -αD/2), up to the
    # error of linear interpolation between probe samples (h <= 0.25 Å): h²/8 max|p''|
    tension = -model.alpha_per_angstrom * model.well_depth_ev_per_a2 / 2 * EV_PER_A3_TO_GPA
    zz = np.linspace(z.min() - 0.3, z.max() + 0.3, 2001)
    cols = s.reshape(-1, 1, 2)
    pz = p_of(cols, zz[None, :])
    tol = 0.25**2 / 8 * np.max(np.abs(np.gradient(np.gradient(pz, zz, axis=1), zz, axis=1)))
    slack = 0.01 * (hi - max(lo, tension))  # thicknesses.BRACKET_RTOL of the load range
    assert np.all(p_of(cols[:, 0], z.min()) >= hi - tol - slack)
    assert np.all(p_of(cols[:, 0], z.max()) <= max(min(lo, 0.0), tension) + tol + slack)
    # the first n thicknesses are today's rule at the lowest-energy column, unchanged unless
    # an added one came closer than the minimum spacing (then the outer one is kept)
    low, _ = extreme_stackings(rigid.energy_ev, grid)
    z_old, _ = thicknesses_for_pressures(probe_column(relax, toy_reference, low, hi), lo, hi, n)
    kept = np.isin(np.round(z_old, 12), np.round(z, 12))
    gap = np.min(np.abs(z_old[:, None] - z[None, :]), axis=1)
    assert np.all(kept | (gap < MIN_THICKNESS_SPACING_ANGSTROM))
    assert kept.all() or any("closer than" in m for m in notes)
    assert np.all(np.diff(z) >= MIN_THICKNESS_SPACING_ANGSTROM)
    assert any("added" in m for m in notes) == (z.size > n or not kept.all())


def test_no_extension_when_the_lowest_column_already_spans_the_loads(toy_reference):
    # no gap modulation: every column has the same p(z) (same depth, same gap)
    grid = GridSpec(4, 4, p_range_gpa=(-0.1, 2.0, 5))
    _, relax, _, rigid, _ = _morse_columns(toy_reference, 0.0, grid)
    resolved, notes = probe_thicknesses(relax, toy_reference, rigid, grid)
    low, _ = extreme_stackings(rigid.energy_ev, grid)
    z_old, _ = thicknesses_for_pressures(probe_column(relax, toy_reference, low, 2.0), -0.1, 2.0, 5)
    np.testing.assert_array_equal(resolved["thickness_angstrom"], z_old)
    assert notes == []


def test_toy_lj_every_extreme_column_reaches_the_requested_loads(toy_reference, toy_factory):
    """Real relaxations (toy fcc(111) LJ): atop is the most repulsive stacking."""
    from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point

    calc = toy_factory(toy_reference)
    relax_settings = RelaxSettings(fmax_ev_per_angstrom=1e-4)

    def relax(a, b, z, start, start_z):
        task = PointTask((0, 0, 0), a, b, z, start, (a, b) if start is not None else None, start_z)
        r = relax_point(toy_reference, calc, task, relax_settings)
        return r.energy_ev, r.normal_stress_gpa, r.force_calls, r.positions

    lo, hi = -0.05, 0.5
    grid = GridSpec(3, 3, p_range_gpa=(lo, hi, 4))
    rigid = rigid_stackings(toy_reference, calc, grid)
    resolved, notes = probe_thicknesses(relax, toy_reference, rigid, grid)
    z = np.asarray(resolved["thickness_angstrom"])
    assert len(resolved["probes"]) >= 2 and len(z) > 4 and notes
    # independent check: relax every extreme column at the ends of the chosen thicknesses;
    # up to the linear-interpolation error of its probe, h²|p''|/8 ≈ |Δ²p|/8 of the samples
    for probe in resolved["probes"]:
        shift = tuple(probe["shift"])
        p = np.asarray(probe["normal_stress_gpa"])
        tol = np.max(np.abs(np.diff(p[: np.argmin(p) + 1], 2))) / 8 + 1e-3  # + fmax noise
        slack = 0.01 * (hi - max(lo, p.min()))  # thicknesses.BRACKET_RTOL of the load range
        assert relax(*shift, z.min(), None, None)[1] >= hi - tol - slack
        assert relax(*shift, z.max(), None, None)[1] <= max(lo, p.min()) + tol + slack


def test_bracket_all_stackings_false_is_the_lowest_column_rule(toy_reference):
    grid = GridSpec(6, 6, p_range_gpa=(-0.5, 2.0, 5), bracket_all_stackings=False)
    _, relax, _, rigid, _ = _morse_columns(toy_reference, 0.2, grid)
    resolved, notes = probe_thicknesses(relax, toy_reference, rigid, grid)
    low, _ = extreme_stackings(rigid.energy_ev, grid)
    z_old, old_notes = thicknesses_for_pressures(
        probe_column(relax, toy_reference, low, 2.0), -0.5, 2.0, 5
    )
    np.testing.assert_array_equal(resolved["thickness_angstrom"], z_old)
    assert notes == old_notes and len(resolved["probes"]) == 1
    assert grid.as_dict()["bracket_all_stackings"] is False
    assert "bracket_all_stackings" not in GridSpec(6, 6, p_range_gpa=(-0.5, 2.0, 5)).as_dict()
    # with the default the wide-gap column forces more thicknesses on the same model
    full, _ = probe_thicknesses(
        relax, toy_reference, rigid, GridSpec(6, 6, p_range_gpa=(-0.5, 2.0, 5))
    )
    assert len(full["thickness_angstrom"]) > 5
