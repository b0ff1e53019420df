"""A symmetry-reduced scan and the rows of its store (issue 34, the last "result files read
back as if true" case).

A reduced scan relaxes one registry per orbit of the shift-space group (and a few verified
points) and writes ``ispes.nc`` declaring the group; every other point takes its
representative's values. A ``points.db`` row planted at such a mapped point (SQLite, through
ase.db, the store's own row format) was used by the assembly: the point moved by the planted
0.017 eV while the file still declared order 6. Now the mapped point's value is its
representative's whatever the store holds there, the row is named in ``scan.json``'s
``symmetry.rows_not_used`` and in one note; and a fallback to the full grid (the relaxation
broke the symmetry) is final: later rounds of the grid and resumed scans compute every point
too, so rows computed in a fallback are used, never left out nor refused.
"""

from __future__ import annotations

import ase.db
import numpy as np
import pytest
from ase.calculators.singlepoint import SinglePointCalculator

from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.reduction import SymmetrySettings, plan_reduction
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan, scan_settings
from flatcontact.ispes.scan_symmetry import FALLBACK_KEY
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.ispes.store import PointStore
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.interface_contract import thickness
from flatcontact.structures.toy import toy_interface

VARIABLES = ("energy", "normal_stress", "converged", "mapped", "force_calls")
PLANTED_EV = 0.017  # the planted difference


@pytest.fixture(scope="module")
def toy():
    return toy_interface(layers=3)


@pytest.fixture(scope="module")
def factory():
    return calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )


def _grid(toy, p_range=False):
    if p_range:
        return GridSpec(3, 3, p_range_gpa=(-0.2, 1.5, 4))
    z0 = thickness(toy)
    return GridSpec(3, 3, thickness_angstrom=(z0 - 0.2, z0 + 0.3))


def _scan(toy, factory, out, symmetry, p_range=False, loads=(0.0, 0.5, 1.0)):
    return run_scan(
        toy,
        factory,
        _grid(toy, p_range),
        out,
        RelaxSettings(mode="normal"),
        executor=SerialExecutor(),
        symmetry=symmetry,
        bracket_loads_gpa=list(loads) if p_range else None,
    )


def _plant(db_path, target, source, energy_ev):
    """Write a row at grid index ``target`` into the SQLite store: the row of ``source`` with
    the target's index and shifts (so it passes every row check) and ``energy_ev``."""
    db = ase.db.connect(str(db_path), type="db", append=True, use_lock_file=False)
    row = next(db.select(i_a=source[0], i_b=source[1], i_z=source[2]))
    kvp = dict(row.key_value_pairs)
    kvp.update(i_a=target[0], i_b=target[1], shift_a=target[0] / 3, shift_b=target[1] / 3)
    atoms = row.toatoms()
    atoms.calc = SinglePointCalculator(atoms, energy=energy_ev)
    db.write(atoms, key_value_pairs=kvp)


def test_a_planted_row_at_a_mapped_point_is_not_used(tmp_path, toy, factory):
    """The planted row changes nothing in ispes.nc (bit for bit), the point keeps the
    value of every member of its orbit (the group computed here from the atoms), and the
    row is named in the record and a note with the file."""
    settings = SymmetrySettings(verify_points=2)
    clean = _scan(toy, factory, tmp_path / "clean", settings)
    out = tmp_path / "planted"
    first = _scan(toy, factory, out, settings)
    sym = first.symmetry
    assert sym["order"] == 6 and not sym["computed_in_full"]
    mapped = np.argwhere(first.dataset["mapped"].values)
    target = tuple(int(i) for i in mapped[0])
    # its orbit, from the atoms' group (independent of the scan's mapping)
    group = shift_space_group(toy).for_grid(3, 3)
    images = group.grid_images(3, 3)
    orbit = {tuple(int(v) for v in images[k, target[0], target[1]]) for k in range(group.order)}
    e = first.dataset["energy"].values
    verified = {tuple(v) for v in sym["verify_points"]}
    source = next(  # the orbit's representative: relaxed, not a verified point
        (a, b, target[2])
        for a, b in sorted(orbit)
        if not first.dataset["mapped"].values[a, b, target[2]] and (a, b, target[2]) not in verified
    )
    _plant(out / "points.db", target, source, float(e[source]) + PLANTED_EV)

    again = _scan(toy, factory, out, settings)
    assert again.points_computed == 0
    ds = again.dataset
    for name in VARIABLES:
        np.testing.assert_array_equal(ds[name].values, clean.dataset[name].values, err_msg=name)
    assert int(ds.attrs["symmetry_order"]) == 6
    assert ds.attrs["computed_points"] == clean.dataset.attrs["computed_points"]
    assert bool(ds["mapped"].values[target])
    for a, b in orbit:  # every member of the orbit but a verified one holds one value
        if (a, b, target[2]) not in verified:
            assert ds["energy"].values[a, b, target[2]] == ds["energy"].values[target]
    left = again.symmetry["rows_not_used"]
    assert left["points"] == [list(target)]
    assert left["reason"] in again.notes
    assert str(out / "points.db") in left["reason"] and str(target) in left["reason"]
    # the note states how far the row is from its representative: the planted 0.017 eV
    area = float(ds.attrs["area"])
    assert f"{PLANTED_EV / area * 1e3:.3g} meV/Å²" in left["reason"]


FALLBACK = SymmetrySettings(verify_points=2, energy_tolerance_mev_per_a2=1e-15)
#: loads to bracket beyond the grid's HI (1.5 GPa): the driver must add a thinner z after the
#: first round whatever the relaxations give (0, 0.5, 1 GPa alone made a second round only
#: along some relaxation paths of the toy, bistable in tension)
FALLBACK_LOADS = (0.0, 0.5, 1.0, 2.0)


@pytest.fixture(scope="module")
def fallback(tmp_path_factory, toy, factory):
    """A tolerance no relaxation meets (the fallback test of tests/ispes) on a pressure-range
    grid that the scan extends after its first round: (its folder, the scan's result)."""
    out = tmp_path_factory.mktemp("fallback") / "scan"
    return out, _scan(toy, factory, out, FALLBACK, p_range=True, loads=FALLBACK_LOADS)


def _store(out, toy, factory):
    grid = _grid(toy, p_range=True)
    settings = scan_settings(toy, factory, grid, RelaxSettings(mode="normal"), FALLBACK)
    return PointStore(out / "points.db", settings, toy)


def test_a_fallback_round_is_final_and_its_rows_are_used(fallback, toy, factory):
    """Round 1 falls back to the full grid and records it in the store; the round added to
    bracket the loads computes every point too (not reduced again); every stored row is
    used, none left out; the rerun computes nothing and gives the same grid."""
    out, first = fallback
    ds = first.dataset
    n_z = ds.sizes["thickness"]
    assert any("added z" in n for n in first.notes), first.notes  # a second round ran
    sym = first.symmetry
    assert sym["computed_in_full"] and "rows_not_used" not in sym
    assert sym["computed_in_full_reason"] in first.notes
    assert first.points_stored == 9 * n_z and not ds["mapped"].values.any()
    assert int(ds.attrs["symmetry_order"]) == 1
    with _store(out, toy, factory) as store:
        recorded = store.resolved[FALLBACK_KEY]
    assert recorded["reason"] == sym["computed_in_full_reason"]
    again = _scan(toy, factory, out, FALLBACK, p_range=True, loads=FALLBACK_LOADS)
    assert again.points_computed == 0 and again.symmetry["computed_in_full"]
    assert again.symmetry["verification"] == sym["verification"]
    for name in VARIABLES:
        np.testing.assert_array_equal(again.dataset[name].values, ds[name].values, err_msg=name)


def test_a_fallback_then_reduced_history_still_assembles(fallback, toy, factory):
    """The rows a fallback computed, assembled under a later reduced plan (the history of a
    store written before a fallback was final, whose next round was reduced again): it
    assembles, every mapped point takes its representative's values, and the rows it
    leaves out are listed, not refused."""
    out, full = fallback
    group = shift_space_group(toy, spread_compression=True, modulo_translations=True)
    with _store(out, toy, factory) as store:
        z = np.asarray(store.resolved["thickness_angstrom"])
        shape = (3, 3, z.size)
        visiting = [(a, b, iz) for iz in range(z.size) for a in range(3) for b in range(3)]
        reduction = plan_reduction(group.for_grid(3, 3), shape, visiting)
        record = {**reduction.to_json(), "verification": None, "computed_in_full": False}
        ds = store.assemble(reduction.representative, record)
        left = store.rows_outside_plan(reduction.representative, record)
    reps = set(reduction.representative.values())
    assert sorted(left) == sorted(set(reduction.representative) - reps)
    assert int(ds.attrs["symmetry_order"]) == 6
    assert int(ds.attrs["computed_points"]) == len(reps)
    rank = np.argsort(np.argsort(z))  # i_z (the store's order) -> position in ispes.nc
    e, e_full = ds["energy"].values, full.dataset["energy"].values
    for (a, b, iz), (ra, rb, _) in reduction.representative.items():
        k = int(rank[iz])
        assert e[a, b, k] == e_full[ra, rb, k]
        assert bool(ds["mapped"].values[a, b, k]) == ((a, b) != (ra, rb))


def test_a_recorded_fallback_keeps_later_rounds_in_full(tmp_path, toy, factory):
    """A reduced scan whose verification passes, then the store's record of a fallback (as
    an earlier round writes it before the grid grows): the next run of the grid does not
    map points again but computes every point, stating the recorded reason."""
    settings = SymmetrySettings(verify_points=2)
    out = tmp_path / "later"
    first = _scan(toy, factory, out, settings)
    assert not first.symmetry["computed_in_full"] and first.points_stored < 18
    grid = _grid(toy)
    fingerprint = scan_settings(toy, factory, grid, RelaxSettings(mode="normal"), settings)
    reason = "symmetry: the check of an earlier round failed (recorded)"
    with PointStore(out / "points.db", fingerprint, toy) as store:
        store.set_resolved(
            {**store.resolved, FALLBACK_KEY: {"reason": reason, "verification": None}}
        )
    later = _scan(toy, factory, out, settings)
    assert later.symmetry["computed_in_full"]
    assert later.symmetry["computed_in_full_reason"] == reason and reason in later.notes
    assert later.points_computed == 18 - first.points_stored
    assert later.points_stored == 18 and not later.dataset["mapped"].values.any()
    assert int(later.dataset.attrs["symmetry_order"]) == 1
